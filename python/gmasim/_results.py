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

    def _repr_pretty_(self, p, cycle):  # IPython / Jupyter
        p.text(repr(self))


def as_result(simulate):
    """simulate() returning a SimulationResult (its docstring and signature kept)."""

    @functools.wraps(simulate)
    def run(*args, **kwargs):
        return SimulationResult(simulate(*args, **kwargs))

    return run
