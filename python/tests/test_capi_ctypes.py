"""The C API (libgmasim_c.so) from Python ctypes: the same numbers as gmasim.Stepper, the
status codes and messages of the error paths, and only gmasim_* symbols exported."""
import ctypes
import math
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import gmasim

from conftest import BIN_DIR, SOURCE_DIR

OK, E_INPUT, E_DIVERGED, E_ARGUMENT, E_INTERNAL = range(5)
MAX_RODS = 8


def _library_path():
    candidates = []
    if os.environ.get("GMASIM_LIB_DIR"):
        candidates.append(pathlib.Path(os.environ["GMASIM_LIB_DIR"]))
    candidates += [BIN_DIR.parent / "lib", SOURCE_DIR / "build" / "ci" / "lib"]
    for d in candidates:
        if (d / "libgmasim_c.so").exists():
            return d / "libgmasim_c.so"
    pytest.fail(f"libgmasim_c.so not found in {', '.join(map(str, candidates))}")


class Outputs(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in
                ("t_s", "dt_s", "current_A", "temperature_C", "y_m", "y_um", "y_stack_m", "B_T",
                 "thermal_expansion_m")] + [
        ("steps", ctypes.c_long), ("rod_count", ctypes.c_int), ("diverged", ctypes.c_int)] + [
        (name, ctypes.c_double * MAX_RODS) for name in
        ("rod_F_N", "rod_strain", "rod_M_A_per_m", "rod_H_A_per_m", "rod_B_T", "rod_x_m", "rod_E_Pa",
         "rod_mu_r")]


@pytest.fixture(scope="module")
def lib():
    L = ctypes.CDLL(str(_library_path()))
    P, D, I = ctypes.c_void_p, ctypes.c_double, ctypes.c_int
    sig = {
        "gmasim_version": ([], ctypes.c_char_p),
        "gmasim_last_error": ([], ctypes.c_char_p),
        "gmasim_status_name": ([I], ctypes.c_char_p),
        "gmasim_model_load": ([ctypes.c_char_p, ctypes.POINTER(P)], I),
        "gmasim_model_load_string": ([ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(P)], I),
        "gmasim_model_free": ([P], I),
        "gmasim_sim_create": ([P, D, D, D, ctypes.POINTER(P)], I),
        "gmasim_sim_free": ([P], I),
        "gmasim_sim_last_error": ([P], ctypes.c_char_p),
        "gmasim_sim_step": ([P, D], I),
        "gmasim_sim_reset": ([P, D], I),
        "gmasim_sim_set_temperature": ([P, D], I),
        "gmasim_sim_y_um": ([P, ctypes.POINTER(D)], I),
        "gmasim_sim_B_T": ([P, ctypes.POINTER(D)], I),
        "gmasim_sim_time_s": ([P, ctypes.POINTER(D)], I),
        "gmasim_sim_rod_force_N": ([P, I, ctypes.POINTER(D)], I),
        "gmasim_sim_outputs": ([P, ctypes.POINTER(Outputs)], I),
    }
    for name, (args, res) in sig.items():
        f = getattr(L, name)
        f.argtypes, f.restype = args, res
    return L


class Sim:
    def __init__(self, lib, model, temperature_C, dt_s, current_A):
        self.lib, self.h = lib, ctypes.c_void_p()
        rc = lib.gmasim_sim_create(model, temperature_C, dt_s, current_A, ctypes.byref(self.h))
        assert rc == OK, lib.gmasim_last_error().decode()

    def __del__(self):
        self.lib.gmasim_sim_free(self.h)

    def get(self, fn):
        v = ctypes.c_double()
        assert fn(self.h, ctypes.byref(v)) == OK
        return v.value


@pytest.fixture(scope="module")
def builtin(lib):
    m = ctypes.c_void_p()
    assert lib.gmasim_model_load(None, ctypes.byref(m)) == OK
    yield m
    lib.gmasim_model_free(m)


def test_version(lib):
    assert lib.gmasim_version().decode() == gmasim.__version__


def test_same_numbers_as_the_pybind_stepper(lib, builtin, mdma):
    # 0.1 s of the 10 Hz biased sine (-3 A .. 5 A) at 20 degC.
    dt = 1e-5
    t = np.arange(1, 10001) * dt
    currents = -3.0 + 4.0 * (1.0 - np.cos(2 * np.pi * 10.0 * t))
    sim = Sim(lib, builtin, 20.0, dt, -3.0)
    y = np.empty_like(currents)
    for k, i in enumerate(currents):
        assert lib.gmasim_sim_step(sim.h, i) == OK
        y[k] = sim.get(lib.gmasim_sim_y_um)
    st = gmasim.Stepper(mdma, temperature_C=20.0, dt_s=dt, current_A=-3.0)
    np.testing.assert_array_equal(y, st.run(currents))
    assert 10.0 < np.ptp(y) < 200.0
    o = Outputs()
    assert lib.gmasim_sim_outputs(sim.h, ctypes.byref(o)) == OK
    assert (o.steps, o.rod_count, o.diverged) == (10000, 3, 0)
    assert o.t_s == st.t_s and o.y_um == st.y_um and o.B_T == st.B_T
    assert list(o.rod_F_N[:3]) == st.rod_forces_N and list(o.rod_F_N[3:]) == [0.0] * 5
    assert list(o.rod_strain[:3]) == st.rod_strains
    assert list(o.rod_M_A_per_m[:3]) == st.rod_magnetisations_A_per_m
    f = ctypes.c_double()
    assert lib.gmasim_sim_rod_force_N(sim.h, 2, ctypes.byref(f)) == OK and f.value == st.rod_forces_N[2]


def test_error_codes_and_messages(lib, builtin, tmp_path):
    v = ctypes.c_double()
    assert lib.gmasim_sim_step(None, 1.0) == E_ARGUMENT
    assert b"gmasim_sim_step: sim is NULL" in lib.gmasim_last_error()
    assert lib.gmasim_status_name(E_ARGUMENT) == b"GMASIM_E_ARGUMENT"

    bad = tmp_path / "missing.toml"
    m = ctypes.c_void_p()
    assert lib.gmasim_model_load(str(bad).encode(), ctypes.byref(m)) == E_INPUT
    assert not m.value
    assert str(bad).encode() in lib.gmasim_last_error()
    assert lib.gmasim_model_load_string(b"[stack]\nrods = 1\n", b"inline.toml", ctypes.byref(m)) == E_INPUT
    assert b"inline.toml" in lib.gmasim_last_error()

    s = ctypes.c_void_p()
    assert lib.gmasim_sim_create(builtin, 380.0, 1e-5, 0.0, ctypes.byref(s)) == E_INPUT
    assert b"Curie" in lib.gmasim_last_error()
    assert lib.gmasim_sim_create(builtin, 20.0, 1e-5, math.nan, ctypes.byref(s)) == E_ARGUMENT
    assert lib.gmasim_sim_create(builtin, 20.0, 5e-3, 0.0, ctypes.byref(s)) == E_INPUT

    sim = Sim(lib, builtin, 20.0, 1e-5, 0.0)
    assert lib.gmasim_sim_step(sim.h, math.nan) == E_ARGUMENT
    assert b"coil current = nan A: must be a finite number" in lib.gmasim_sim_last_error(sim.h)
    assert lib.gmasim_sim_step(sim.h, -1e4) == E_INPUT
    assert lib.gmasim_sim_rod_force_N(sim.h, 3, ctypes.byref(v)) == E_ARGUMENT
    assert b"rod index 3: out of range [0, 3)" in lib.gmasim_sim_last_error(sim.h)
    assert lib.gmasim_sim_set_temperature(sim.h, 1e3) == E_INPUT
    assert lib.gmasim_sim_set_temperature(sim.h, 60.0) == OK
    assert sim.get(lib.gmasim_sim_time_s) == 0.0
    assert lib.gmasim_sim_step(sim.h, 1.0) == OK
    assert sim.get(lib.gmasim_sim_time_s) == 1e-5


def test_divergence_is_sticky_until_reset(lib):
    # The built-in model (models/mdma.toml) with an absurd coil, 7.2e9 turns, at 1000 A.
    toml = (SOURCE_DIR / "models" / "mdma.toml").read_text().replace("coil_turns = 720.0", "coil_turns = 7.2e9")
    assert "7.2e9" in toml
    m = ctypes.c_void_p()
    assert lib.gmasim_model_load_string(toml.encode(), b"absurd.toml", ctypes.byref(m)) == OK
    try:
        sim = Sim(lib, m, 20.0, 1e-5, 1e-6)
        codes = [lib.gmasim_sim_step(sim.h, 1000.0) for _ in range(200)]
        first = codes.index(E_DIVERGED)
        assert set(codes[:first]) <= {OK} and set(codes[first:]) == {E_DIVERGED}
        assert b"refused: the sim diverged earlier" in lib.gmasim_sim_last_error(sim.h)
        assert lib.gmasim_sim_reset(sim.h, 0.0) == OK
        assert lib.gmasim_sim_step(sim.h, 0.0) == OK
        del sim
    finally:
        lib.gmasim_model_free(m)


def test_double_free_is_an_error_code(lib):
    # Issue 19, item 12: a freed handle is refused, never undefined behaviour.
    m = ctypes.c_void_p()
    assert lib.gmasim_model_load(None, ctypes.byref(m)) == OK
    sim = ctypes.c_void_p()
    assert lib.gmasim_sim_create(m, 20.0, 1e-5, 0.0, ctypes.byref(sim)) == OK
    assert lib.gmasim_model_free(m) == OK
    assert lib.gmasim_model_free(m) == E_ARGUMENT
    assert b"not a live gmasim_model handle" in lib.gmasim_last_error()
    assert lib.gmasim_sim_step(sim, 1.0) == OK
    assert lib.gmasim_sim_free(sim) == OK
    assert lib.gmasim_sim_step(sim, 1.0) == E_ARGUMENT
    assert lib.gmasim_sim_free(sim) == E_ARGUMENT
    assert lib.gmasim_sim_free(None) == OK


@pytest.mark.skipif(shutil.which("nm") is None, reason="nm (binutils) not installed")
def test_only_the_c_api_is_exported():
    out = subprocess.run(["nm", "-D", "--defined-only", str(_library_path())], check=True,
                         capture_output=True, text=True).stdout
    names = [line.split()[-1] for line in out.splitlines() if line.strip()]
    assert names and all(n.startswith("gmasim_") for n in names), [n for n in names if not n.startswith("gmasim_")][:10]
    assert "gmasim_sim_step" in names
