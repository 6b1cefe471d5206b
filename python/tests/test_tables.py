"""The C++ tables as Python sees them (issue 21, item 3): the metric keys of simulate(), of
SimulationResult's summary and of the CLI's metrics.json are the rows of kMetricRows; the
settings of sensitivity() and the keyword arguments of simulate() take their defaults from the
request tables."""
import inspect
import json
import math
import subprocess

import gmasim
from gmasim import _gmasim
from gmasim import _results


def test_metric_keys_are_the_cpp_table(mdma, gmasim_bin, tmp_path):
    rows = _gmasim.metric_rows()
    names = [r["name"] for r in rows]
    assert names[:4] == ["stroke_um", "hysteresis_um", "B_pp_T", "y_mean_um"]
    r = gmasim.simulate(mdma, current_pp_A=6.0, frequency_Hz=20.0, periods=2.0)
    assert list(r["metrics"]) == names
    # The window is the last of the 2 periods at 20 Hz: 50 ms to 100 ms (to the time step).
    assert math.isclose(r["metrics"]["window_end_s"] - r["metrics"]["window_start_s"], 0.05,
                        rel_tol=1e-3)
    assert r["metrics"]["stroke_um"] > 1.0
    # The summary shows the rows with a label, in the table's order, with their values.
    assert _results.SUMMARY_METRICS == tuple(x["name"] for x in rows if x["label"])
    text = repr(r)
    for key in _results.SUMMARY_METRICS:
        assert f"{key}={r['metrics'][key]:.4g}" in text
    # The CLI's metrics.json holds the same keys in the same order, and the same numbers.
    subprocess.run([gmasim_bin, "simulate", "--current-pp", "6", "--frequency", "20", "--periods",
                    "2", "--out", str(tmp_path)], check=True, capture_output=True)
    cli = json.loads((tmp_path / "metrics.json").read_text())["metrics"]
    assert list(cli) == names
    for k in names:
        assert math.isclose(cli[k], r["metrics"][k], rel_tol=1e-9, abs_tol=1e-12), k


def test_sensitivity_settings_defaults_are_the_table():
    defaults = _gmasim._sensitivity_defaults()
    assert list(defaults) == ["step_large", "step_small", "agreement", "floor_fraction",
                              "near_null_ratio", "quick", "use_claims", "threads"]
    assert 0.0 < defaults["step_small"] < defaults["step_large"] < 0.5
    sig = inspect.signature(gmasim.sensitivity).parameters
    for k, v in defaults.items():
        assert sig[k].default == v and sig[k].kind == inspect.Parameter.KEYWORD_ONLY


def test_simulate_keywords_keep_their_positions(mdma):
    # The first arguments keep the positions they had before the table (positional callers).
    first = _gmasim.simulate.__doc__.splitlines()[0]
    order = ["model", "temperature_C", "current_pp_A", "frequency_Hz", "periods", "current_min_A",
             "dt_s", "record_every", "kind"]
    pos = [first.index(f"{name}:") for name in order]
    assert pos == sorted(pos), first
    a = gmasim.simulate(mdma, 40.0, 6.0, 20.0, 2.0, -1.0)
    b = gmasim.simulate(mdma, temperature_C=40.0, current_pp_A=6.0, frequency_Hz=20.0, periods=2.0,
                        current_min_A=-1.0)
    assert a["metrics"] == b["metrics"]
    assert a["metrics"]["stroke_um"] > 1.0
