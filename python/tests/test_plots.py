"""Figures are readable without explanation: units on axes, legends, titles; PNG and SVG."""
import numpy as np

import gmasim
from gmasim import plots


def _check_axes(fig):
    for ax in fig.axes:
        if ax.get_label() == "<colorbar>":
            continue
        xlabel = ax.get_xlabel() or next((o.get_xlabel() for o in ax.get_shared_x_axes().get_siblings(ax)
                                           if o.get_xlabel()), "")
        categorical = any(t.get_text() and not t.get_text().replace("−", "-").replace(".", "").lstrip("-").isdigit()
                          for t in ax.get_xticklabels() if "$" not in t.get_text())
        assert xlabel, "missing x label"
        assert categorical or ("(" in xlabel and ")" in xlabel), xlabel
        assert "(" in ax.get_ylabel() and ")" in ax.get_ylabel(), ax.get_ylabel()
    assert any(ax.get_title() for ax in fig.axes) or fig._suptitle is not None


def test_hysteresis_loops_from_the_model(mdma, tmp_path):
    cols = {"temperature_C": [], "current_A": [], "y_um": []}
    for T in (20.0, 70.0):
        r = gmasim.simulate(mdma, temperature_C=T, periods=2, record_every=10)
        s, m = r["series"], r["metrics"]
        last = s["t_s"] >= m["window_start_s"] - 1e-12
        cols["temperature_C"] += [T] * int(last.sum())
        cols["current_A"] += list(s["current_A"][last])
        cols["y_um"] += list(s["y_um"][last])
    fig = plots.hysteresis_loops({k: np.asarray(v) for k, v in cols.items()})
    _check_axes(fig)
    assert fig.axes[0].get_legend() is not None
    files = plots.save(fig, tmp_path, "loops")
    assert [f.suffix for f in files] == [".png", ".svg"]
    assert all(f.stat().st_size > 1000 for f in files)


def test_sweep_bode_tracking_retention_params_ablation_figures(tmp_path):
    T = np.repeat([20.0, 45.0, 70.0], 2)
    I = np.tile([6.0, 8.0], 3)
    sweep = {"temperature_C": T, "current_pp_A": I, "frequency_Hz": np.full(6, 10.0),
             "stroke_um": 10 + I - T / 10, "hysteresis_um": 5 - T / 50, "B_pp_T": 1.0 - T / 1000}
    _check_axes(plots.sweep_vs_temperature(sweep))
    f = np.logspace(0, 3.7, 10)
    frf = {"temperature_C": np.repeat([20.0, 70.0], 10), "frequency_Hz": np.tile(f, 2),
           "stepped_mag_um_per_A": np.tile(5 / np.sqrt(1 + (f / 300) ** 2), 2),
           "stepped_phase_deg": np.tile(-np.degrees(np.arctan(f / 300)), 2),
           "linear_mag_um_per_A": np.tile(5 / np.sqrt(1 + (f / 300) ** 2), 2),
           "linear_phase_deg": np.tile(-np.degrees(np.arctan(f / 300)), 2)}
    _check_axes(plots.bode(frf))
    track = {"temperature_C": T, "amplitude_um": np.tile([10.0, 20.0], 3), "frequency_Hz": np.full(6, 10.0),
             "error_rms_um": 0.1 + T / 1000}
    _check_axes(plots.tracking_error(track))
    ret = {"current_pp_A": I, "temperature_C": T, "stroke_retention_pct": 100 - (T - 20) / 2}
    _check_axes(plots.retention(ret))
    params = {"temperature_C": np.repeat([20.0, 70.0], 3), "rod": np.tile(["rod1", "rod2", "rod3"], 2),
              "mu_r_mean": np.ones(6), "rho_ohm_m": np.ones(6), "M_peak_A_per_m": np.ones(6),
              "E_G_mean_GPa": np.ones(6), "E_t_GPa": np.ones(6)}
    _check_axes(plots.params_vs_temperature(params))
    ab = {"law": np.array(["M", "E_G", "M", "E_G"]), "frequency_Hz": np.array([10.0, 10.0, 200.0, 200.0]),
          "error_rms_um": np.array([0.5, 0.2, 0.1, 0.4])}
    fig = plots.ablation(ab)
    _check_axes(fig)
    plots.save(fig, tmp_path, "ablate")
    assert (tmp_path / "ablate.svg").read_text().startswith("<?xml")
