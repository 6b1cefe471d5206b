"""Your controller in the loop (issue 40, item 4): gmasim.track(..., controller=f) calls a Python
function at every sample, and examples/user_controller/user_pid.c runs the same loop by hand
through the C API. Both are checked against the built-in PID: the paper's PID written as the
callback, and written in C, give gmasim track's tracking error to the last bit."""
import json
import math
import subprocess

import numpy as np
import pytest

import gmasim
from conftest import BIN_DIR


class PaperPid:
    """The PID of gmasim track (class Pid, include/gmasim/experiments/experiments.hpp) in Python:
    positional, conditional-integration anti-windup, the gains per sample at the 10 kHz reference
    rate, the amplifier's 0.5 A per unit about the 1 A bias. The operations are the C++ ones in
    the same order, so the currents are the same doubles."""

    def __init__(self, kp=0.2, ki=0.03, kd=0.007, rate_Hz=10000.0, reference_rate_Hz=10000.0,
                 bias_A=1.0, amplifier_A_per_unit=0.5, limit_A=10.0):
        self.kp, self.ki, self.kd = kp, ki * reference_rate_Hz / rate_Hz, kd * rate_Hz / reference_rate_Hz
        self.bias_A, self.a = bias_A, amplifier_A_per_unit
        self.u_min = (-limit_A - bias_A) / amplifier_A_per_unit
        self.u_max = (limit_A - bias_A) / amplifier_A_per_unit
        self.runs = 0
        self.reset()

    def reset(self):
        self.sum, self.e_prev, self.first = 0.0, 0.0, True
        self.runs += 1

    def __call__(self, reference_um, measured_um, temperature_C):
        e = reference_um - measured_um
        de = 0.0 if self.first else e - self.e_prev
        self.first, self.e_prev = False, e
        sum_new = self.sum + e
        u_raw = self.kp * e + self.ki * sum_new + self.kd * de
        u = self.u_max if u_raw > self.u_max else (self.u_min if u_raw < self.u_min else u_raw)
        if not ((u_raw > self.u_max and e > 0.0) or (u_raw < self.u_min and e < 0.0)):
            self.sum = sum_new
        return self.bias_A + self.a * u


GRID = dict(temperatures_C=[20.0, 70.0], amplitudes_um=[10.0], frequencies_Hz=[10.0, 100.0])


def test_the_paper_pid_as_a_callback_is_the_built_in_pid_bit_for_bit(mdma):
    builtin = gmasim.track(mdma, **GRID)
    pid = PaperPid()
    user = gmasim.track(mdma, **GRID, controller=pid)
    assert pid.runs == 1 + 4  # reset at construction, then before each of the 4 runs
    for col in ("error_rms_um", "error_peak_um", "current_min_A", "current_max_A", "y_bias_um"):
        np.testing.assert_array_equal(user["points"][col], builtin["points"][col])
    assert user["meta"]["controller"].startswith("user")
    assert len(user["margins"]["temperature_C"]) == 0  # the margins are the PID's
    assert len(builtin["margins"]["temperature_C"]) == 2


def test_a_controller_sees_reference_measurement_and_temperature(mdma):
    seen = []

    def hold(reference_um, measured_um, temperature_C):
        seen.append((reference_um, measured_um, temperature_C))
        return 1.0  # the bias: the actuator stays at its operating point

    r = gmasim.track(mdma, temperatures_C=[70.0], amplitudes_um=[5.0], frequencies_Hz=[10.0],
                     controller=hold)
    ref, y, T = np.array(seen).T
    assert len(seen) == 4000  # 4 periods of 10 Hz at 10 kHz
    assert np.all(T == 70.0)
    y_bias = r["points"]["y_bias_um"][0]
    assert np.max(np.abs(y - y_bias)) < 1e-9  # held at the bias: no motion
    assert np.max(ref) - y_bias == pytest.approx(5.0, rel=1e-6)
    # The error of a controller that does nothing is the reference itself: RMS A/sqrt(2).
    assert r["points"]["error_rms_um"][0] == pytest.approx(5.0 / math.sqrt(2.0), rel=1e-3)


def test_a_controllers_faults_are_reported(mdma):
    one = dict(temperatures_C=[20.0], amplitudes_um=[10.0], frequencies_Hz=[10.0])
    with pytest.raises(ValueError, match=r"controller returned nan A at sample 0"):
        gmasim.track(mdma, **one, controller=lambda r, y, T: float("nan"))

    def broken(r, y, T):
        raise ZeroDivisionError("inside the controller")

    with pytest.raises(ZeroDivisionError, match="inside the controller"):
        gmasim.track(mdma, **one, controller=broken)
    with pytest.raises(ValueError, match="not a current in A"):
        gmasim.track(mdma, **one, controller=lambda r, y, T: "one amp")
    with pytest.raises(ValueError, match="must be a callable"):
        gmasim.track(mdma, **one, controller=3.0)
    with pytest.raises(ValueError, match="cannot be combined with feedforward='inverse'"):
        gmasim.track(mdma, **one, controller=PaperPid(), feedforward="inverse")
    # The amplifier clips what the controller asks for.
    r = gmasim.track(mdma, **one, controller=lambda r, y, T: 1e6)
    assert r["points"]["current_max_A"][0] == 10.0 and r["points"]["saturated"][0]


@pytest.mark.parametrize("temperature_C", [20.0, 70.0])
def test_the_c_api_example_runs_the_paper_pid_as_gmasim_track_does(mdma, temperature_C):
    exe = BIN_DIR / "gmasim_user_pid"
    if not exe.exists():
        pytest.fail(f"examples/user_controller/user_pid.c not built at {exe}")
    out = subprocess.run([str(exe), str(temperature_C), "10", "10"], check=True, capture_output=True,
                         text=True).stdout
    c = json.loads(out)
    t = gmasim.track(mdma, temperatures_C=[temperature_C], amplitudes_um=[10.0], frequencies_Hz=[10.0])
    assert c["y_bias_um"] == t["points"]["y_bias_um"][0]
    assert c["error_rms_um"] == t["points"]["error_rms_um"][0]


def test_four_controllers_on_one_reference_in_one_figure(mdma, tmp_path, monkeypatch, capsys):
    """examples/user_controller/compare_controllers.py: PID, PID + temperature schedule, PID +
    inverse feed-forward and a user controller (PID + a static inverse it measures) at
    70 degC, 10 um, 100 Hz. Each feed-forward must beat the plain PID's RMS error, and the figure
    must pass the figure check."""
    import sys

    from conftest import SOURCE_DIR
    from gmasim import figure_check

    sys.path.insert(0, str(SOURCE_DIR / "examples" / "user_controller"))
    import compare_controllers as cc

    res = cc.run(mdma, 70.0, 10.0, 100.0)
    e = {k: r["points"]["error_rms_um"][0] for k, r in res.items()}
    assert e["pid_inverse"] < 0.5 * e["pid"]
    assert e["user"] < e["pid"]
    assert e["pid_temperature"] < e["pid"]
    t = res["pid"]["example"]["t_s"]
    for r in res.values():  # one reference, sampled alike
        np.testing.assert_array_equal(r["example"]["t_s"], t)
        np.testing.assert_array_equal(r["example"]["reference_um"], res["pid"]["example"]["reference_um"])
    figure_check.check(cc.figure(res, 70.0, 10.0, 100.0), "compare_controllers")
    monkeypatch.setenv("GMASIM_FIGURE_CHECK", "1")
    assert cc.main(["--out", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    assert "RMS / PID" in printed and f"{e['pid_inverse']:9.4f}" in printed
    assert (tmp_path / "compare_controllers.png").exists()
