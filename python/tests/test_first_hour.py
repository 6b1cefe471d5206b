"""Issue 20 from Python: a sampled current (current_A=, current_dt_s=) and the (t_s, current_A)
pair, a short repr of results, the quantities a run reports, the prestress key."""
import numpy as np
import pytest

import gmasim
from conftest import SOURCE_DIR


def _sampled(dt=1e-4, n=401):
    t = np.arange(n) * dt
    return t, 2.0 + 2.0 * np.sin(2 * np.pi * 25.0 * t)


def test_sampled_current_equals_the_pair(mdma):
    t, i = _sampled()
    a = gmasim.simulate(mdma, current_A=i, current_dt_s=1e-4)
    b = gmasim.simulate(mdma, waveform=(t, i))
    assert a["steps"] == b["steps"] > 0
    np.testing.assert_array_equal(a["series"]["y_um"], b["series"]["y_um"])
    # the run lasts to the last sample, and the drive is the samples at their times
    assert a["series"]["t_s"][-1] == pytest.approx(t[-1], rel=1e-12)
    np.testing.assert_allclose(np.interp(t, a["series"]["t_s"], a["series"]["current_A"]), i,
                               rtol=0, atol=1e-9)


def test_docstring_names_both_forms():
    doc = gmasim.simulate.__doc__
    assert "current_A=ndarray, current_dt_s=" in doc
    assert "waveform=(t_s, current_A)" in doc


def test_sampled_current_errors(mdma):
    t, i = _sampled()
    with pytest.raises(gmasim.InputError, match="current_A= needs current_dt_s="):
        gmasim.simulate(mdma, current_A=i)
    with pytest.raises(gmasim.InputError, match="current_dt_s = -1 s: must be > 0"):
        gmasim.simulate(mdma, current_A=i, current_dt_s=-1.0)
    with pytest.raises(gmasim.InputError, match="not both"):
        gmasim.simulate(mdma, current_A=i, current_dt_s=1e-4, waveform=(t, i))
    # the mistake of the issue: a bare array as waveform names the keyword to use
    with pytest.raises(TypeError, match="current_A=array, current_dt_s="):
        gmasim.simulate(mdma, waveform=i)


def test_repr_is_short_and_has_the_numbers(mdma):
    r = gmasim.simulate(mdma, periods=1)
    text = repr(r)
    assert text.startswith("SimulationResult(") and len(text) < 400, text
    assert f"stroke_um={r['metrics']['stroke_um']:.4g}" in text
    assert "array(" not in text and "\n" not in text
    assert str(r) == text
    assert isinstance(r, dict) and r["series"]["y_um"].size > 1000  # still the dict


def test_quantities_default_to_drive_output_and_flux(mdma):
    r = gmasim.simulate(mdma, periods=1)
    q = r["quantities"]
    assert set(q) == {"current_A", "y_um", "B_T"}
    # the current is the biased sine -3 .. 5 A: p-p 8 A, mean 1 A over the run's samples
    assert q["current_A"]["pp"] == pytest.approx(8.0, rel=1e-6)
    assert q["y_um"]["pp"] > 0 and q["B_T"]["rms"] > 0
    named = gmasim.simulate(mdma, periods=1, quantities=["rod2_F_N"])
    assert set(named["quantities"]) == {"rod2_F_N"}


def test_prestress_key_from_python():
    m = gmasim.Model(str(SOURCE_DIR / "models" / "single_rod.toml"))
    assert m.get("preload.prestress_MPa") == 6.4
    m12 = m.with_params({"preload.prestress_MPa": 12.0})
    assert "prestress_MPa = 12.0  # set: Python Model.toml; was 6.4" in m12.toml()
    a = gmasim.simulate(m, current_pp_A=6, current_min_A=0, periods=1)
    b = gmasim.simulate(m12, current_pp_A=6, current_min_A=0, periods=1)
    assert b["metrics"]["stroke_um"] != a["metrics"]["stroke_um"]  # the preload is used
