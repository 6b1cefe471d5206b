"""gmasim.linearize (issue 40 item 1): the plant as a scipy.signal.StateSpace, equal to the FRF's
small-signal curve, and the CLI's MATLAB v5 file read back by scipy.io.loadmat (an independent
reader of what matio wrote)."""
import subprocess

import numpy as np
import pytest
import scipy.io
from scipy import signal

import gmasim


def test_statespace_is_the_frf_small_signal_curve(mdma):
    for T in (20.0, 70.0):
        sys = gmasim.linearize(mdma, temperature_C=T, bias_A=1.0)
        assert isinstance(sys, signal.StateSpace)
        assert sys.A.shape == (11, 11) and sys.B.shape == (11, 1) and sys.C.shape == (1, 11)
        assert sys.states[:3] == ["rod1_H", "rod2_H", "rod3_H"] and sys.state_units[3] == "m"
        assert sys.outputs == ["y"] and sys.output_units == ["m"]
        f = np.array([1.0, 100.0, 900.0, 1270.0, 1500.0, 3000.0])
        r = gmasim.frf(mdma, temperatures_C=[T], f_min_Hz=1.0, f_max_Hz=3000.0, points=2,
                       stepped_sine=False, peak_refinements=0)
        fr = r["response"]["frequency_Hz"]
        # The transfer function by hand, C (jwI - A)^-1 B, against the FRF's small-signal curve
        # (observed ~1e-15), and scipy's freqresp, which goes through a transfer function's
        # polynomials (s^11 against poles of 1e5 1/s: it warns BadCoefficients; observed 1.5e-9).
        def by_hand(fk):
            return (sys.C @ np.linalg.solve(2j * np.pi * fk * np.eye(11) - sys.A, sys.B))[0, 0]
        mag = np.abs([by_hand(fk) for fk in fr]) * 1e6
        assert mag == pytest.approx(r["response"]["linear_mag_um_per_A"], rel=1e-12)
        with pytest.warns(signal.BadCoefficients):
            _, hs = signal.freqresp(sys, w=2 * np.pi * f)
        assert np.abs(hs) == pytest.approx(np.abs([by_hand(fk) for fk in f]), rel=1e-7)
        assert sys.dc_gain[0] == pytest.approx(-(sys.C @ np.linalg.solve(sys.A, sys.B))[0, 0], rel=1e-12)


def test_flux_density_output_and_bad_output(mdma):
    both = gmasim.linearize(mdma, output="all")
    assert both.outputs == ["y", "B"] and both.output_units == ["m", "T"]
    B = gmasim.linearize(mdma, output="B")
    assert B.C.shape == (1, 11)
    assert B.dc_gain[0] == pytest.approx(both.dc_gain[1], rel=0)
    with pytest.raises(gmasim.InputError, match="output must be one of"):
        gmasim.linearize(mdma, output="z")


def test_cli_mat_file_is_the_python_statespace(mdma, gmasim_bin, tmp_path):
    subprocess.run([gmasim_bin, "linearize", "--temperature", "70", "--bias", "1", "--out",
                    str(tmp_path)], check=True, capture_output=True)
    d = scipy.io.loadmat(tmp_path / "linearize.mat")
    sys = gmasim.linearize(mdma, temperature_C=70, bias_A=1, output="all")
    for k in "ABCD":
        assert d[k] == pytest.approx(getattr(sys, k), rel=0, abs=0), k
    assert d["temperature_C"][0, 0] == 70 and d["bias_A"][0, 0] == 1
    for k in "ABCD":  # the blocks, bit for bit
        assert d[k + "_stack"] == pytest.approx(getattr(sys.stack, k), rel=0, abs=0), k
        assert d[k + "_mount"] == pytest.approx(getattr(sys.mount, k), rel=0, abs=0), k
    assert (tmp_path / "linearize_A.csv").read_text().splitlines()[0].startswith("row,unit,rod1_H")


def test_describing_function_beside_the_state_space(mdma, gmasim_bin, tmp_path):
    """gmasim.linearize(amplitude_A=1): the large-signal gain at +-1 A about the bias (the FRF's
    stepped sine) beside the small-signal one, the numbers of `gmasim linearize --amplitude 1`."""
    import json
    import subprocess

    sys_ = gmasim.linearize(mdma, temperature_C=20.0, amplitude_A=1.0, frequencies_Hz=[10.0, 100.0])
    df = sys_.describing_function
    assert list(df["frequency_Hz"]) == [10.0, 100.0]
    assert np.all(df["gain_um_per_A"] > 2.0 * df["small_signal_gain_um_per_A"])
    assert df["small_signal_gain_um_per_A"][0] == pytest.approx(1e6 * sys_.dc_gain[0], rel=1e-3)
    subprocess.run([gmasim_bin, "linearize", "--amplitude", "1", "--frequencies", "10,100",
                    "--out", str(tmp_path / "l")], check=True, capture_output=True)
    rows = json.loads((tmp_path / "l" / "linearize.json").read_text())["tables"]["describing_function"]["rows"]
    np.testing.assert_allclose(df["gain_um_per_A"], [r["gain_um_per_A"] for r in rows], rtol=1e-12)
    np.testing.assert_allclose(df["phase_deg"], [r["phase_deg"] for r in rows], atol=1e-9)
    assert not hasattr(gmasim.linearize(mdma), "describing_function")


def test_the_mount_is_a_separable_block(mdma):
    """sys.stack (current -> y_stack, q) and sys.mount (q -> dy) put together as
    sys.interconnection says give the plant; another sensor model can take the mount's place."""
    sys = gmasim.linearize(mdma, temperature_C=70)
    assert sys.interconnection == "y = y_stack + dy"
    assert sys.stack.outputs[:2] == ["y_stack", "q"] and sys.stack.input == "current"
    assert sys.mount.input == "q" and sys.mount.outputs == ["dy"] and sys.mount.A.shape == (2, 2)

    def resp(s, f, row=0):
        n = s.A.shape[0]
        return (s.C[row] @ np.linalg.solve(2j * np.pi * f * np.eye(n) - s.A, s.B))[0] + s.D[row, 0]

    for f in (1.0, 100.0, 1270.0, 5000.0):
        whole = resp(sys, f)
        parts = resp(sys.stack, f, 0) + resp(sys.mount, f) * resp(sys.stack, f, 1)
        assert parts == pytest.approx(whole, rel=1e-12), f
