"""Results of gmasim.simulate(): a dict (keys as documented) that prints as a short summary.

``print(result)`` shows the metrics, the thermal offset and the shapes of the arrays, never
the arrays themselves; every key works as before (``result["series"]["y_um"]``).
"""
from __future__ import annotations

import functools

import numpy as np

from . import _gmasim

# The metrics the summary shows: the rows of the C++ table of Metrics with a label (those the
# `gmasim simulate` summary prints), in its order (gmasim/simulate/simulate.hpp kMetricRows).
SUMMARY_METRICS = tuple(row["name"] for row in _gmasim.metric_rows() if row["label"])


def _shape(value) -> str:
    if isinstance(value, dict):
        rows = {len(v) for v in value.values() if isinstance(v, np.ndarray)}
        return f"{len(value)} columns x {rows.pop() if len(rows) == 1 else '?'} rows"
    return repr(value)


class SimulationResult(dict):
    """The dict gmasim.simulate() returns, with a short repr (no array dumps)."""

    def __repr__(self) -> str:
        parts = []
        m = self.get("metrics") or {}
        for key in SUMMARY_METRICS:
            if key in m:
                parts.append(f"{key}={m[key]:.4g}")
        if "thermal_expansion_um" in self:
            parts.append(f"thermal_expansion_um={self['thermal_expansion_um']:.4g}")
        parts.append(f"steps={self.get('steps')}")
        parts.append(f"dt_s={self.get('dt_s', 0):.3g}")
        if "series" in self:
            parts.append(f"series=<{_shape(self['series'])}>")
        if "heating" in self:
            parts.append(f"heating=<{_shape(self['heating'])}>")
        if self.get("quantities"):
            parts.append(f"quantities=<{', '.join(self['quantities'])}>")
        return f"SimulationResult({', '.join(parts)})"

    __str__ = __repr__

    def to_frame(self, table: str = "series"):
        """gmasim.frame(self, table): the series (or another table) as a pandas DataFrame."""
        return frame(self, table)

    def _repr_pretty_(self, p, cycle):  # IPython / Jupyter
        p.text(repr(self))


def _table(data, table):
    """The dict of equal-length columns `data` names: data itself, data[table], or the one
    table of columns a result holds ('series' of simulate(), 'points' of sweep(), ...)."""
    if isinstance(data, SimulationResult) and table is None:
        table = "series"
    if table is not None:
        if not isinstance(data, dict) or table not in data:
            raise KeyError(f"gmasim.frame: no table '{table}' (tables: {', '.join(_tables(data)) or 'none'})")
        data = data[table]
    if _is_columns(data):
        return data
    names = _tables(data)
    if len(names) == 1:
        return data[names[0]]
    raise ValueError("gmasim.frame: give table= one of " + (", ".join(names) if names else
                     "(none: pass a dict of equal-length arrays)"))


def _tables(data) -> list[str]:
    if not isinstance(data, dict):
        return []
    return [k for k, v in data.items() if _is_columns(v)]


def _is_columns(v) -> bool:
    """A dict of columns: arrays, or lists (text columns: status, error)."""
    return isinstance(v, dict) and bool(v) and all(isinstance(c, (np.ndarray, list)) for c in v.values())


def frame(data, table: str | None = None):
    """A pandas DataFrame of a gmasim result's table: simulate()'s 'series' (indexed by t_s),
    sweep()'s 'points', or any dict of equal-length arrays. Column names keep their units
    (``y_um``, ``current_A``); a result's 'meta' goes to ``DataFrame.attrs['meta']``.

        df = gmasim.frame(gmasim.simulate(m, temperature_C=70))   # or result.to_frame()
        df["y_um"].plot()

    Needs pandas (Debian: python3-pandas, which scripts/install_deps.sh installs)."""
    try:
        import pandas as pd
    except ImportError as e:  # pragma: no cover - the project's scripts install it
        raise ImportError("gmasim.frame needs pandas: apt-get install python3-pandas") from e
    cols = _table(data, table)
    lengths = {name: len(v) for name, v in cols.items() if np.ndim(v) == 1}
    if len(set(lengths.values())) > 1 or len(lengths) != len(cols):
        raise ValueError("gmasim.frame: the columns are not one table of equal-length 1-D arrays ("
                         + ", ".join(f"{k}: {np.shape(v)}" for k, v in cols.items()) + ")")
    df = pd.DataFrame({name: np.asarray(v) for name, v in cols.items()})
    if "t_s" in df.columns:
        df = df.set_index("t_s")
    if isinstance(data, dict) and isinstance(data.get("meta"), dict):
        df.attrs["meta"] = dict(data["meta"])
    return df


def as_result(simulate):
    """simulate() returning a SimulationResult (its docstring and signature kept)."""

    @functools.wraps(simulate)
    def run(*args, **kwargs):
        return SimulationResult(simulate(*args, **kwargs))

    return run
