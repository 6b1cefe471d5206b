"""Metrics over a stated window for any waveform (issue 41): a biased sine given as a table,
with its period stated (metrics_window_s, or '# period_s = P' in a CSV), measures what the
built-in sine measures over its last period; the whole run (virgin curve included) does not."""
import json
import subprocess

import numpy as np
import pytest

import gmasim

F_HZ, PP_A, MIN_A, PERIODS, DT_S = 50.0, 8.0, -3.0, 3, 1e-5


def sine_table():
    n = int(round(PERIODS / F_HZ / DT_S))
    t = np.arange(n + 1) * DT_S
    return t, MIN_A + 0.5 * PP_A * (1.0 - np.cos(2.0 * np.pi * F_HZ * t))


def test_a_table_with_its_period_measures_the_built_in_sines_loop(mdma):
    ref = gmasim.simulate(mdma, current_pp_A=PP_A, frequency_Hz=F_HZ, current_min_A=MIN_A,
                          periods=PERIODS)["metrics"]
    t, i = sine_table()
    last = gmasim.simulate(mdma, waveform=(t, i), metrics_window_s=1.0 / F_HZ)["metrics"]
    whole = gmasim.simulate(mdma, waveform=(t, i))["metrics"]
    # The same currents at the same step times: the same loop, to the table's rounding of t.
    assert last["stroke_um"] == pytest.approx(ref["stroke_um"], rel=1e-9)
    assert last["hysteresis_um"] == pytest.approx(ref["hysteresis_um"], rel=1e-6)
    assert last["window_start_s"] == pytest.approx((PERIODS - 1) / F_HZ, rel=1e-12)
    # The whole run holds the virgin curve and the first periods' drift: another (here 1.2 %
    # wider) loop than the last period's.
    assert whole["window_start_s"] == 0.0
    assert whole["hysteresis_um"] > ref["hysteresis_um"] * (1.0 + 1e-3)
    assert whole["stroke_um"] >= ref["stroke_um"]


def test_a_csv_declares_its_period_and_the_summary_says_the_window(gmasim_bin, mdma, tmp_path):
    t, i = sine_table()
    csv = tmp_path / "sine50.csv"
    body = "\n".join(f"{a:.17g},{b:.17g}" for a, b in zip(t, i))
    csv.write_text(f"# a 50 Hz biased sine written by numpy\n# period_s = {1.0 / F_HZ:g}\nt_s,current_A\n{body}\n")
    out = subprocess.run([gmasim_bin, "simulate", "--waveform", str(csv), "--out", str(tmp_path / "s")],
                         check=True, capture_output=True, text=True).stdout
    assert "over the last 0.02 s, t 0.04..0.06 s: the waveform's period_s" in out
    m = json.loads((tmp_path / "s" / "metrics.json").read_text())
    py = gmasim.simulate(mdma, waveform=(t, i), metrics_window_s=1.0 / F_HZ)["metrics"]
    got = m["metrics"] if "metrics" in m else m
    assert got["stroke_um"] == pytest.approx(py["stroke_um"], rel=1e-12)
    plain = tmp_path / "plain.csv"
    plain.write_text(f"t_s,current_A\n{body}\n")
    out = subprocess.run([gmasim_bin, "simulate", "--waveform", str(plain), "--out", str(tmp_path / "p")],
                         check=True, capture_output=True, text=True).stdout
    assert "over the whole run; --metrics-window S for the last S seconds" in out


def test_bad_windows_are_refused(gmasim_bin, mdma, tmp_path):
    t, i = sine_table()
    with pytest.raises(ValueError, match="a biased sine's metrics are over its last period"):
        gmasim.simulate(mdma, metrics_window_s=0.01)
    with pytest.raises(ValueError, match="longer than the run"):
        gmasim.simulate(mdma, waveform=(t, i), metrics_window_s=1.0)
    bad = tmp_path / "bad.csv"
    bad.write_text("# period_s = -1\nt_s,current_A\n0,0\n0.01,1\n")
    r = subprocess.run([gmasim_bin, "simulate", "--waveform", str(bad), "--out", str(tmp_path / "b")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert "bad.csv:1: period_s = '-1': the waveform's period must be a number > 0 s" in r.stderr
