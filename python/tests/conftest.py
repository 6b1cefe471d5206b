import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("GMASIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BIN_DIR = pathlib.Path(os.environ.get("GMASIM_BIN_DIR", SOURCE_DIR / "build" / "ci" / "bin"))


@pytest.fixture(scope="session")
def gmasim_bin():
    exe = BIN_DIR / "gmasim"
    if not exe.exists():
        pytest.fail(f"gmasim CLI not found at {exe}")
    return str(exe)


@pytest.fixture(scope="session")
def mdma():
    import gmasim

    return gmasim.Model()


@pytest.fixture(scope="session")
def reproduce_quick(gmasim_bin, tmp_path_factory):
    """The output directory of one `gmasim reproduce --quick` (with its figures), shared by the
    tests that read it (test_reproduce, test_figure_check)."""
    import subprocess

    out = tmp_path_factory.mktemp("reproduce") / "rep"
    subprocess.run([gmasim_bin, "reproduce", "--quick", "--out", str(out)], check=True, capture_output=True)
    return out
