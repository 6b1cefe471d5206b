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
