"""gmasim.sensitivity from Python: shapes and units of the arrays, eq. 21's analytic
derivative, the fit spec's parameters, the heatmap."""
import numpy as np
import pytest

import gmasim
from conftest import SOURCE_DIR


def test_thermal_claim_derivatives_are_eq21(mdma):
    s = gmasim.sensitivity(mdma, params=["thermal_expansion.sleeve_length_m", "material.Ms_A_per_m",
                                         ("rod3.inner_diameter_m", 1e-3)],
                           claims=["thermal_model"], threads=2)
    assert s["quantities"] == ["thermal_model"]
    assert s["derivative"].shape == (1, 3)
    assert s["steps"] == ["absolute", "log", "absolute"]
    # d x_T' / d l_sleeve = -1e6 alpha_sleeve [um/degC per m]; M_s does not enter eq. 21.
    a_s = mdma.get("thermal_expansion.sleeve_alpha_per_K")
    assert s["derivative"][0, 0] == pytest.approx(-1e6 * a_s, rel=1e-9)
    assert s["derivative_small"][0, 0] == pytest.approx(-1e6 * a_s, rel=1e-9)
    assert s["derivative"][0, 1] == 0.0
    assert list(s["flags"][0]) == ["ok", "ok", "step_refused"]  # 0 - h s < 0: rule >= 0
    assert np.isnan(s["derivative"][0, 2])
    # per tolerance: the claim's 1 % of 0.662 um/degC
    assert s["quantity_scales"][0] == pytest.approx(0.00662)
    assert s["per_tolerance"][0, 0] == pytest.approx(s["scaled"][0, 0] / 0.00662)
    assert s["evaluations"] == 13


def test_metric_quantity_and_identifiability(mdma):
    s = gmasim.sensitivity(mdma, params=["material.Ms_A_per_m", "material.lambda_s"],
                           claims=["stroke_um@20C_8A_10Hz", "B_pp_T@20C_8A_10Hz"], threads=2)
    assert s["quantity_kinds"] == ["metric", "metric"]
    stroke = gmasim.simulate(mdma, temperature_C=20, current_pp_A=8, frequency_Hz=10)
    assert s["quantity_values"][0] == pytest.approx(stroke["metrics"]["stroke_um"], rel=1e-12)
    assert (s["flags"] == "ok").all()
    assert np.all(s["disagreement"] < 3e-3)
    ident = s["identifiability"]
    assert ident["jacobian"].shape == (2, 2)
    assert ident["correlation"].shape == (2, 2)
    assert ident["correlation"][0, 0] == pytest.approx(1.0)
    assert ident["directions"].shape == (2, 2)


def test_fit_parameters_and_errors(mdma, tmp_path):
    ps = gmasim.fit_parameters(mdma, SOURCE_DIR / "calibration" / "consistent.toml")
    assert len(ps) == 11
    assert ("material.Ms_A_per_m", 0.0) in ps
    fit0 = tmp_path / "fit0.toml"
    fit0.write_text('[[parameter]]\nname = "magnet.alpha_pm1_per_K"\nlower = -3e-4\nupper = 0.0\n')
    ps0 = gmasim.fit_parameters(mdma, fit0)
    assert ("magnet.alpha_pm1_per_K", pytest.approx(3e-4)) in ps0  # 0 in the model: the bounds' width
    with pytest.raises(gmasim.InputError, match="unknown quantity 'nope'"):
        gmasim.sensitivity(mdma, params=["material.Ms_A_per_m"], claims=["nope"])
    with pytest.raises(gmasim.InputError, match="no parameter"):
        gmasim.sensitivity(mdma)


def test_heatmap_figure(mdma):
    s = gmasim.sensitivity(mdma, params=["thermal_expansion.sleeve_length_m",
                                         "thermal_expansion.sleeve_alpha_per_K"],
                           claims=["thermal_model", "thermal_measured"], threads=1)
    fig = gmasim.plots.sensitivity_heatmap(s["quantities"], s["parameters"], s["per_tolerance"],
                                           flags=s["flags"],
                                           correlation=s["identifiability"]["correlation"])
    assert len(fig.axes) == 4  # two panels, two colour bars
    # The sleeve's length and coefficient enter eq. 21 as a product: correlation -1.
    assert s["identifiability"]["correlation"][0, 1] == pytest.approx(-1.0, abs=1e-6)
    assert s["identifiability"]["near_null"][-1]
