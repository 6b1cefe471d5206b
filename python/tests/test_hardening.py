"""Issue 19 ("Hardening II") through the Python module: wrong types name the argument and the
type, simulate() and Stepper diverge alike, tiny steps are refused, absurd physics ends the run,
the validity ranges and the warnings."""
import warnings

import numpy as np
import pytest

import gmasim


# ---- item 11: wrongly typed arguments -----------------------------------------------------------
@pytest.mark.parametrize("call, message", [
    (lambda m: gmasim.simulate(m, waveform="abc"),
     r"waveform: expected a pair \(t_s, current_A\) of equally long 1-D arrays of numbers \[s, A\], not str"),
    (lambda m: gmasim.simulate(m, waveform=(np.array(0.0), np.array(1.0))),
     r"waveform\[0\] \(t_s\): expected a 1-D array of numbers, not a 0-D array"),
    (lambda m: gmasim.simulate(m, waveform=([0, 1], ["a", "b"])),
     r"waveform\[1\] \(current_A\): expected a 1-D array of numbers"),
    (lambda m: gmasim.simulate(m, temperature_C="20"),
     r"simulate\(\): temperature_C must be a number \[degC\], not str '20'"),
    (lambda m: gmasim.simulate(m, periods=[1, 2]), r"simulate\(\): periods must be a number, not list"),
    (lambda m: gmasim.simulate(m, ambient_C="hot", self_heating=True),
     r"ambient_C: expected a number or None, not str"),
    (lambda m: gmasim.sweep(m, temperatures_C=np.array(20.0)),
     r"sweep\(\): temperatures_C must be a 1-D sequence of numbers \[degC\], not a 0-d numpy.ndarray"),
    (lambda m: gmasim.sweep(m, temperatures_C="20,30"),
     r"sweep\(\): temperatures_C must be a 1-D sequence of numbers \[degC\], not str"),
    (lambda m: gmasim.frf(m, points=3.5), r"frf\(\): points must be an integer, not float 3.5"),
    (lambda m: m.with_params({"material.Ms_A_per_m": [7e5]}),
     r"with_params: 'material.Ms_A_per_m' = \[700000.0\]: expected a number"),
])
def test_wrong_types_name_the_argument_and_the_type(mdma, call, message):
    with pytest.raises(TypeError, match=message):
        call(mdma)


# ---- item 11: one behaviour on divergence ------------------------------------------------------
def test_simulate_raises_divergence_like_the_stepper(mdma):
    absurd = mdma.with_params({"circuit.branches.phi4.coil_turns": 7.2e9})
    with pytest.raises(gmasim.DivergenceError, match="diverged at t = ") as e:
        gmasim.simulate(absurd, waveform=([0.0, 1e-3, 1.1e-3, 2e-3], [1e-6, 1e-6, 1000.0, 1000.0]))
    partial = e.value.result  # the partial run, as the CLI writes it
    assert partial["diverged"] and "metrics" not in partial
    assert len(partial["series"]["t_s"]) >= 1
    st = gmasim.Stepper(absurd, dt_s=1e-5, current_A=1e-6)
    with pytest.raises(gmasim.DivergenceError, match="diverged at t = "):
        for _ in range(200):
            st.step(1000.0)


# ---- items 2, 3: tiny steps, impossible physics ------------------------------------------------
@pytest.mark.parametrize("dt", [1e-28, 1e-30, 5e-324, 1e-13])
def test_steps_below_the_smallest_are_refused(mdma, dt):
    with pytest.raises(gmasim.InputError, match=r"must be >= 1e-12 s"):
        gmasim.Stepper(mdma, dt_s=dt)


def test_the_smallest_step_holds_the_state(mdma):
    st = gmasim.Stepper(mdma, dt_s=1e-12, current_A=0.0)
    y0 = st.y_um
    assert max(abs(st.step(0.0) - y0) for _ in range(200)) < 1e-9


def test_absurd_modulus_ends_the_run_with_a_warning(mdma):
    with pytest.warns(UserWarning, match=r"material.Es_Pa = 1000 Pa: far outside"):
        absurd = mdma.with_params({"material.Es_Pa": 1e3})
    with pytest.raises(gmasim.DivergenceError, match="beyond the physical bound"):
        gmasim.simulate(absurd, periods=1)


# ---- items 8, 9 ----------------------------------------------------------------------------------
def test_validity_ranges_and_the_warning(mdma):
    r = mdma.temperature_ranges()
    assert r["validated_C"] == (20.0, 150.0)
    lo, hi = r["computable_C"]
    assert lo < -50 and 150 < hi < 300  # above the validated range (observed 202.8 degC)
    with pytest.raises(gmasim.InputError, match=r"outside the range where .* can be computed"):
        gmasim.simulate(mdma, temperature_C=300, periods=1)
    with pytest.warns(UserWarning, match=r"temperature 180 degC: outside the range where .* was validated"):
        gmasim.simulate(mdma, temperature_C=180, periods=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gmasim.simulate(mdma, temperature_C=100, periods=1)


def test_dimensional_keys_need_their_unit(mdma):
    with pytest.raises(gmasim.InputError, match=r"write 'rod1.length_m' \(the value in m\)"):
        mdma.with_params({"rod1.length": 50.0})
    with pytest.raises(gmasim.InputError, match=r"write 'rod1.ja.k0_A_per_m'"):
        mdma.get("rod1.ja.k0")
    assert mdma.get("material.chi_m") == mdma.with_params({"material.chi_m": mdma.get("material.chi_m")}).get("material.chi_m")
