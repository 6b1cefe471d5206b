"""gmasim.Stepper: one sample at a time, the same numbers as gmasim.simulate."""
import threading

import numpy as np
import pytest

import gmasim


def _stepped(stepper, currents):
    return np.array([stepper.step(i) for i in currents])


def test_stepping_equals_simulate_bit_for_bit(mdma):
    # simulate() steps t = k dt with the current at the end of each step: feeding the recorded
    # current samples one at a time reproduces every recorded column.
    r = gmasim.simulate(mdma, temperature_C=45, current_pp_A=10, frequency_Hz=50, periods=2, dt_s=1e-5)
    s = r["series"]
    st = gmasim.Stepper(mdma, temperature_C=45, dt_s=r["dt_s"], current_A=s["current_A"][0])
    assert st.y_um == s["y_um"][0]
    y = _stepped(st, s["current_A"][1:])
    np.testing.assert_array_equal(y, s["y_um"][1:])
    assert st.steps == len(s["t_s"]) - 1
    assert st.t_s == s["t_s"][-1]
    out = st.outputs()
    for name, column in s.items():
        assert out[name] == column[-1], name
    assert st.rod_forces_N == [out[f"{r}_F_N"] for r in mdma.rods]
    assert st.rod_strains == pytest.approx([out[f"{r}_lambda_ppm"] * 1e-6 for r in mdma.rods], rel=1e-15)
    assert st.rod_magnetisations_A_per_m == [out[f"{r}_M_A_per_m"] for r in mdma.rods]
    # not a trivial agreement: tens of micrometres of stroke
    assert np.ptp(y) > 10.0


def test_stepping_equals_simulate_for_an_arbitrary_waveform(mdma):
    t = np.linspace(0.0, 0.01, 101)
    i = 1.0 + 3.0 * np.sin(2 * np.pi * 300 * t) * np.exp(-50 * t)
    r = gmasim.simulate(mdma, temperature_C=90, waveform=(t, i), dt_s=2e-5)
    s = r["series"]
    st = gmasim.Stepper(mdma, temperature_C=90, dt_s=r["dt_s"], current_A=s["current_A"][0])
    np.testing.assert_array_equal(st.run(s["current_A"][1:]), s["y_um"][1:])


def test_run_equals_step_and_is_deterministic(mdma):
    currents = 2.0 + 4.0 * np.sin(np.linspace(0, 20, 3000))
    a = gmasim.Stepper(mdma, temperature_C=30, dt_s=1e-5)
    b = gmasim.Stepper(mdma, temperature_C=30, dt_s=1e-5)
    ya = a.run(currents)
    assert isinstance(ya, np.ndarray) and ya.shape == currents.shape
    np.testing.assert_array_equal(ya, _stepped(b, currents))
    # reset: the same bits again
    a.reset()
    assert a.t_s == 0.0 and a.steps == 0
    np.testing.assert_array_equal(a.run(currents), ya)
    # a list and an int array are accepted too
    a.reset(1.0)
    b.reset(1.0)
    np.testing.assert_array_equal(a.run([1, 2, 3]), b.run(np.array([1.0, 2.0, 3.0])))


def test_set_temperature_keeps_the_state_and_reset_uses_it(mdma):
    hot = gmasim.Stepper(mdma, temperature_C=80, dt_s=1e-5, current_A=2.0)
    s = gmasim.Stepper(mdma, temperature_C=20, dt_s=1e-5, current_A=2.0)
    s.run(np.full(100, 2.0))
    y20 = s.y_um
    s.set_temperature(80)
    assert s.temperature_C == 80 and s.steps == 100  # state, time and steps carry on
    s.run(np.full(3000, 2.0))
    assert abs(s.y_um - y20) > 0.1  # the hot actuator settles elsewhere
    s.reset(2.0)
    currents = np.linspace(2.0, 5.0, 500)
    np.testing.assert_array_equal(s.run(currents), hot.run(currents))


def test_bad_numbers_raise_and_leave_the_stepper_untouched(mdma):
    st = gmasim.Stepper(mdma, dt_s=1e-5)
    st.step(1.0)
    before = st.outputs()
    with pytest.raises(gmasim.InputError, match="coil current = nan A: must be a finite number"):
        st.step(float("nan"))
    with pytest.raises(gmasim.InputError, match=r"coil current = 2000 A: must be in \[-1000 A, 1000 A\]"):
        st.step(2000.0)
    with pytest.raises(gmasim.InputError, match=r"currents_A\[2\] = inf A"):
        st.run(np.array([1.0, 1.0, np.inf]))
    with pytest.raises(gmasim.InputError, match="1-D"):
        st.run(np.zeros((2, 2)))
    with pytest.raises(gmasim.InputError, match="Curie"):
        st.set_temperature(380.0)
    assert st.outputs() == before
    with pytest.raises(gmasim.InputError, match="Curie"):
        gmasim.Stepper(mdma, temperature_C=400)
    with pytest.raises(gmasim.InputError, match="time step dt = 0 s: must be > 0"):
        gmasim.Stepper(mdma, dt_s=0.0)
    with pytest.raises(gmasim.InputError, match="time step dt = 0.01 s: must be <= 0.001 s"):
        gmasim.Stepper(mdma, dt_s=1e-2)
    with pytest.raises(gmasim.InputError, match="unknown law 'nonsense' to freeze; known: mu_G, rho_G"):
        gmasim.Stepper(mdma, freeze=["nonsense"])
    # One name set (C++ kFreezeSwitches): the ablation's laws, freeze=[...], metrics.json.
    assert gmasim.FREEZE_LAWS == ("mu_G", "rho_G", "M", "E_G", "E_t", "F_pm", "geometry")
    with pytest.raises(gmasim.InputError, match="no model"):
        gmasim.Stepper(None)


def test_divergence_stops_the_stepper_until_reset(mdma):
    absurd = mdma.with_params({"circuit.branches.phi4.coil_turns": 7.2e9})
    st = gmasim.Stepper(absurd, dt_s=1e-5, current_A=1e-6)
    with pytest.raises(gmasim.DivergenceError, match="diverged at t = "):
        st.run(np.full(200, 1000.0))
    assert st.diverged
    with pytest.raises(gmasim.DivergenceError, match=r"reset\(\) before stepping again"):
        st.step(0.0)
    with pytest.raises(gmasim.DivergenceError, match="earlier divergence"):
        st.run(np.zeros(3))
    st.reset()
    assert not st.diverged
    st.step(0.0)


def test_run_releases_the_gil(mdma):
    # While run() steps in another thread, this thread runs Python and finds the stepper busy.
    st = gmasim.Stepper(mdma, dt_s=1e-5)
    currents = np.sin(np.linspace(0, 100, 300_000))
    done = []
    worker = threading.Thread(target=lambda: done.append(st.run(currents)))
    worker.start()
    busy = 0
    while worker.is_alive():
        try:
            st.t_s
        except RuntimeError as e:
            assert "busy" in str(e)
            busy += 1
    worker.join()
    assert busy > 0
    assert done[0].shape == currents.shape and st.steps == len(currents)


def test_version():
    assert gmasim.__version__ == "0.1.0"
    assert isinstance(gmasim.__git_describe__, str)


def test_the_readmes_replay_line_holds(mdma):
    # README.md, "From your own code": the line it gives, run as written.
    import pathlib
    import re
    readme = (pathlib.Path(__file__).resolve().parents[2] / "README.md").read_text()
    line = re.search(r'`(i = r\["series"\]\["current_A"\]; gmasim\.Stepper\(m, 20, r\["dt_s"\], '
                     r'current_A=i\[0\]\)\.run\(i\[1:\]\))`', readme)
    assert line, "README.md no longer gives the replay line"
    m = mdma
    r = gmasim.simulate(m, temperature_C=20, current_pp_A=8, frequency_Hz=10, periods=1)
    ns = {"gmasim": gmasim, "m": m, "r": r}
    i_line, run_expr = line.group(1).split("; ", 1)
    exec(i_line, ns)
    y = eval(run_expr, ns)
    np.testing.assert_array_equal(y, r["series"]["y_um"][1:])
    # and the plain use the README warns about does differ (the first step from 0 A)
    plain = gmasim.Stepper(m, 20, r["dt_s"]).run(ns["i"])
    assert np.max(np.abs(plain - r["series"]["y_um"])) > 1.0
