"""gmasim.sensitivity: derivatives of the paper's claims and of metric quantities with respect
to the model's parameters (the C++ run_sensitivity; docs/experiments.md, "Sensitivity")."""
from __future__ import annotations

import inspect
import tomllib
from typing import Iterable, Sequence

import numpy as np

from . import _gmasim


def fit_parameters(model, fit) -> list[tuple[str, float]]:
    """The free parameters of a fit spec (a TOML file with ``[[parameter]]`` tables, e.g.
    ``calibration/consistent.toml``) as (name, scale) pairs: scale is the width of the bounds
    for a parameter that is 0 in ``model`` (an absolute step needs one), else 0 (its value)."""
    with open(fit, "rb") as f:
        spec = tomllib.load(f)
    out = []
    for p in spec.get("parameter", []):
        name = p["name"]
        width = float(p["upper"]) - float(p["lower"])
        out.append((name, width if model.get(name) == 0.0 else 0.0))
    if not out:
        raise _gmasim.InputError(f"{fit}: no [[parameter]] table")
    return out


def _parameters(model, params, fit) -> tuple[list[str], list[float]]:
    pairs: list[tuple[str, float]] = []
    if fit is not None:
        pairs += fit_parameters(model, fit)
    if isinstance(params, str):
        params = [params]
    for p in params or []:
        if p == "all":
            pairs += [(n, 0.0) for n in _gmasim._model_parameters(model)]
        elif isinstance(p, str):
            pairs.append((p, 0.0))
        else:
            name, scale = p
            pairs.append((str(name), float(scale)))
    if not pairs:
        raise _gmasim.InputError("sensitivity: no parameter (params=[...] or fit=FILE)")
    return [n for n, _ in pairs], [s for _, s in pairs]


def sensitivity(model, params: Sequence | str | None = None, claims: Iterable[str] | None = None,
                *, fit=None, claims_file: str = "", metrics: bool = True, **settings) -> dict:
    """Sensitivities S[i, j] of quantity i to parameter j by central differences at two
    relative steps (``step_large``, ``step_small``), on all cores (``threads=0``).

    The settings (keyword arguments ``use_claims``, ``step_large``, ``step_small``,
    ``agreement``, ``floor_fraction``, ``near_null_ratio``, ``quick``, ``threads``) and their
    defaults are the C++ table's (SensitivitySettings; the signature shows them).

    Parameters
    ----------
    model : gmasim.Model
    params : list of dotted names (``"material.Ms_A_per_m"``), ``(name, scale)`` pairs (the
        scale of an absolute step, in the parameter's unit), or ``"all"`` (every number of the
        model a user would vary); added to those of ``fit``.
    claims : names of the quantities to keep (claim ids of data/claims.toml, metric names such
        as ``"stroke_um@20C_8A_10Hz"``); default every applicable claim and metric quantity.
    fit : a fit spec TOML file whose ``[[parameter]]`` names are taken.
    claims_file : a claims file instead of the built-in claims.

    Step rule: a parameter whose rule is ``> 0`` is stepped p (1 +- h) and reported as
    d q / d ln p [unit of q]; any other (it may be 0 or negative) p +- h s, reported as
    d q / d p [unit of q / unit of p], s = |p| or the given scale.

    Returns
    -------
    dict with numpy arrays:
        ``parameters``, ``parameter_units``, ``steps`` ("log"/"absolute") : list of str
        ``parameter_values``, ``parameter_scales`` : (P,) [parameter units]
        ``quantities``, ``quantity_units``, ``quantity_kinds`` ("claim"/"metric") : list of str
        ``quantity_values`` : (Q,) [quantity units]; ``quantity_scales`` : (Q,) the tolerance
            scale (NaN for a ranking claim)
        ``derivative``, ``derivative_small`` : (Q, P) d q / d ln p or d q / d p at each step
        ``scaled``, ``scaled_small`` : (Q, P) derivative x (1 or s) [quantity units]
        ``per_tolerance`` : (Q, P) scaled / quantity_scales
        ``disagreement`` : (Q, P) |scaled - scaled_small| / max(|.|)
        ``flags`` : (Q, P) str: "ok", "disagree", "nonfinite", "step_refused"
        ``identifiability`` : dict: ``jacobian`` (per tolerance), ``singular_values``,
            ``directions`` (rows: unit vectors over the parameters), ``near_null`` (below
            near_null_ratio of the largest), ``weak`` (singular value < 1 tolerance per unit),
            ``combinations`` (text), ``correlation`` (P, P), ``std_dev``, ``rank``,
            ``condition``, ``quantities`` (rows used), ``excluded``
        ``evaluations``, ``threads``, ``wall_time_s``
    """
    names, scales = _parameters(model, params, fit)
    unknown = sorted(set(settings) - set(_SETTINGS))
    if unknown:
        raise TypeError(f"sensitivity() got an unexpected keyword argument {unknown[0]!r}")
    r = _gmasim._sensitivity(model, params=names, scales=scales, only=list(claims or []),
                             claims_file=claims_file, use_metrics=metrics, **settings)
    for k in ("derivative", "derivative_small", "scaled", "scaled_small", "disagreement"):
        r[k] = np.array(r[k], dtype=float).reshape(len(r["quantities"]), len(r["parameters"]))
    r["flags"] = np.array(r["flags"], dtype=str).reshape(r["derivative"].shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        r["per_tolerance"] = r["scaled"] / r["quantity_scales"][:, None]
    ident = r["identifiability"]
    n = len(r["parameters"])
    ident["jacobian"] = np.array(ident["jacobian"], dtype=float).reshape(-1, n)
    ident["directions"] = np.array(ident["directions"], dtype=float).reshape(-1, n)
    ident["correlation"] = np.array(ident["correlation"], dtype=float).reshape(n, n)
    ident["near_null"] = np.array(ident["near_null"], dtype=bool)
    ident["weak"] = np.array(ident["weak"], dtype=bool)
    return r


# The settings' keyword arguments with their defaults, from the C++ table (one place for both).
_SETTINGS = _gmasim._sensitivity_defaults()
_sig = inspect.signature(sensitivity)
sensitivity.__signature__ = _sig.replace(parameters=[
    *(p for p in _sig.parameters.values() if p.kind != inspect.Parameter.VAR_KEYWORD),
    *(inspect.Parameter(k, inspect.Parameter.KEYWORD_ONLY, default=v) for k, v in _SETTINGS.items())])
