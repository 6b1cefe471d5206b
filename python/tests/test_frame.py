"""gmasim.frame (issue 41): a result's table as a pandas DataFrame, its numbers unchanged."""
import numpy as np
import pytest

import gmasim

pd = pytest.importorskip("pandas", reason="python3-pandas (scripts/install_deps.sh installs it)")


@pytest.fixture(scope="module")
def model():
    return gmasim.Model()


def test_the_series_is_a_frame_indexed_by_time(model):
    r = gmasim.simulate(model, temperature_C=70, current_pp_A=8, frequency_Hz=100, periods=2)
    df = r.to_frame()
    assert df.index.name == "t_s"
    np.testing.assert_array_equal(df.index.to_numpy(), r["series"]["t_s"])
    assert set(df.columns) == set(r["series"]) - {"t_s"}
    for name in df.columns:  # every column, bit for bit
        np.testing.assert_array_equal(df[name].to_numpy(), r["series"][name])
    assert gmasim.frame(r).equals(df)


def test_a_sweep_gives_its_points_and_meta(model):
    s = gmasim.sweep(model, temperatures_C=[20, 70], currents_pp_A=[8], periods=2)
    df = gmasim.frame(s, "points")
    assert len(df) == 2
    np.testing.assert_array_equal(df["stroke_um"].to_numpy(), s["points"]["stroke_um"])
    assert df.attrs["meta"] == s["meta"]
    assert gmasim.frame(s).equals(df)  # its one table


def test_bad_tables_are_named():
    with pytest.raises(KeyError, match="no table 'nope'"):
        gmasim.frame({"points": {"a": np.zeros(2)}}, "nope")
    with pytest.raises(ValueError, match="not one table"):
        gmasim.frame({"a": np.zeros(2), "b": np.zeros(3)})
    with pytest.raises(ValueError, match="give table= one of a, b"):
        gmasim.frame({"a": {"x": np.zeros(2)}, "b": {"y": np.zeros(2)}})
