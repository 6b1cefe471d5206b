"""The Python API over the core: numbers, equality with the CLI, errors."""
import json
import subprocess

import numpy as np
import pytest

import gmasim


def test_simulate_returns_numpy_series_and_metrics(mdma):
    r = gmasim.simulate(mdma, temperature_C=70, current_pp_A=8, frequency_Hz=10, periods=2)
    s = r["series"]
    assert isinstance(s["y_um"], np.ndarray)
    assert s["t_s"].shape == s["y_um"].shape
    # stroke = peak-to-peak of y over the last period (of its cubic refinement: between the
    # samples' peak-to-peak and a hair above it, docs/model.md "Time step")
    t = s["t_s"]
    last = (t >= r["metrics"]["window_start_s"] - 1e-12) & (t < r["metrics"]["window_end_s"] - 1e-12)
    sampled = np.ptp(s["y_um"][last])
    assert sampled <= r["metrics"]["stroke_um"] <= sampled * (1 + 1e-6)
    # the stack output is the sum of the rods' displacements (eq. 20); the sensor reads the
    # output stage, which follows it within a micrometre at 10 Hz
    np.testing.assert_allclose(s["y_stack_um"], s["rod1_x_um"] + s["rod2_x_um"] + s["rod3_x_um"], rtol=1e-12, atol=1e-12)
    assert np.max(np.abs(s["y_um"] - s["y_stack_um"])) < 1.0


def test_python_equals_cli_to_1e12(mdma, gmasim_bin, tmp_path):
    r = gmasim.simulate(mdma, temperature_C=45, current_pp_A=10, frequency_Hz=100, periods=3)
    subprocess.run([gmasim_bin, "simulate", "--temperature", "45", "--current-pp", "10", "--frequency", "100",
                    "--periods", "3", "--out", str(tmp_path)], check=True, capture_output=True)
    cli = json.loads((tmp_path / "metrics.json").read_text())["metrics"]
    for key in ("stroke_um", "hysteresis_um", "B_pp_T", "y_mean_um"):
        assert r["metrics"][key] == pytest.approx(cli[key], rel=1e-12, abs=1e-12), key


def test_with_params_changes_the_model(mdma):
    base = gmasim.simulate(mdma, periods=2)["metrics"]["stroke_um"]
    stiff = mdma.with_params({"preload.force_N": 900.0})
    assert stiff.get("preload.force_N") == 900.0
    assert gmasim.simulate(stiff, periods=2)["metrics"]["stroke_um"] != pytest.approx(base, rel=1e-3)
    # prefix resolution of unit-suffixed names
    assert mdma.with_params({"rod1.ja.k0_A_per_m": 2500.0}).get("rod1.ja.k0_A_per_m") == 2500.0


def test_parameter_table_describes_every_parameter(mdma):
    rows = gmasim.parameter_table()
    by_key = {(r["table"], r["key"]): r for r in rows}
    ms = by_key[("material", "Ms_A_per_m")]
    assert ms["unit"] == "A/m" and ms["rule"] == "> 0" and "eq. (4)" in ms["doc"]
    assert ms["lands_in"] == "Material::Ms_A_per_m" and ms["default"] is None
    assert by_key[("thermal_network", "coil_alpha_per_K")]["default"] == pytest.approx(3.93e-3)
    assert by_key[("options", "magnetic_state")]["rule"] == ["printed", "consistent"]
    # every number of the model has a row of its key with its unit
    for name, (value, unit, provenance) in mdma.params().items():
        key = name.rsplit(".", 1)[1]
        if name.startswith("circuit.reluctances_per_H."):
            key = "*"
        assert unit in {r["unit"] for r in rows if r["key"] == key}, name


def test_arbitrary_waveform(mdma):
    t = np.linspace(0, 0.02, 201)
    i = 1.0 + 2.0 * np.sin(2 * np.pi * 100 * t)
    r = gmasim.simulate(mdma, waveform=(t, i))
    np.testing.assert_allclose(np.interp(r["series"]["t_s"], t, i), r["series"]["current_A"], atol=1e-9)


def test_bad_requests_raise_clear_errors(mdma):
    with pytest.raises(gmasim.InputError, match="Curie"):
        gmasim.simulate(mdma, temperature_C=400)
    with pytest.raises(gmasim.InputError, match="frequency"):
        gmasim.simulate(mdma, frequency_Hz=0)
    with pytest.raises(gmasim.InputError, match="increase"):
        gmasim.simulate(mdma, waveform=([0.0, 0.0, 1.0], [0.0, 1.0, 2.0]))
    with pytest.raises(gmasim.InputError, match="unknown parameter"):
        mdma.with_params({"no.such": 1.0})
    with pytest.raises(gmasim.InputError, match="must be > 0"):
        mdma.with_params({"rod1.length_m": -1.0})


@pytest.mark.parametrize("kwargs, message", [
    (dict(periods=1e300), r"periods \(--periods\) = 1e\+300: must be in \[1, 1e\+06\]"),
    (dict(periods=float("nan")), "periods"),
    (dict(frequency_Hz=1e-300), "too many"),
    (dict(frequency_Hz=float("inf")), "frequency"),
    (dict(dt_s=1e-300), r"dt = 1e-300 s \(--dt, dt_s\): must be in \[1e-12, 0.001\] s"),  # issue 19
    (dict(temperature_C=float("nan")), "temperature"),
    (dict(current_pp_A=1e300), "current peak-to-peak = 1e\\+300 A"),
])
def test_every_number_is_checked_before_it_becomes_a_count(mdma, kwargs, message):
    # Issue 8: the library validates before any work, so Python gets the CLI's errors.
    with pytest.raises(gmasim.InputError, match=message):
        gmasim.simulate(mdma, **kwargs)


def test_experiment_requests_are_validated(mdma):
    with pytest.raises(gmasim.InputError, match=r"reference amplitude \(--amplitudes\) = 1e\+300 um"):
        gmasim.track(mdma, temperatures_C=[20], amplitudes_um=[1e300])
    with pytest.raises(gmasim.InputError, match="frequency points"):
        gmasim.frf(mdma, temperatures_C=[20], points=2_000_000_000)
    with pytest.raises(gmasim.InputError, match="too many"):
        gmasim.sweep(mdma, temperatures_C=[20], currents_pp_A=[6], frequencies_Hz=[1e-300])


def test_model_save_round_trip(tmp_path):
    """Model.save writes a file that loads back with the changed values (issue 9, item 6)."""
    m = gmasim.Model().with_params({"material.Ms_A_per_m": 7.1e5, "options.magnetic_state": "printed"})
    path = tmp_path / "changed.toml"
    m.save(str(path))
    back = gmasim.Model(str(path))
    assert back.get("material.Ms_A_per_m") == 7.1e5
    assert "set: Python Model.save; was" in back.params()["material.Ms_A_per_m"][2]
    assert 'magnetic_state = "printed"' in path.read_text()
    # The saved model runs like the changed one.
    a = gmasim.simulate(m, periods=1, current_pp_A=6.0)["metrics"]["stroke_um"]
    b = gmasim.simulate(back, periods=1, current_pp_A=6.0)["metrics"]["stroke_um"]
    assert a == b
    with pytest.raises(ValueError, match="one word"):
        gmasim.Model().with_params({"options.magnetic_state": "a b"})


def test_self_heating_from_python():
    """Issue 9, item 1: a heated run returns the thermal history and a closed energy balance."""
    m = gmasim.Model().with_params({"thermal_network.coil_heat_capacity_J_per_K": 2.0,
                                    "thermal_network.housing_heat_capacity_J_per_K": 4.0})
    r = gmasim.simulate(m, periods=20, dt_s=5e-5, record_every=100, self_heating=True)
    h = r["heating"]
    assert h["coil_C"][-1] > 25.0
    assert r["energy_in_J"] == pytest.approx(r["energy_stored_J"] + r["energy_out_J"], rel=1e-9)
    assert np.all(np.diff(h["coil_C"]) >= 0.0)
