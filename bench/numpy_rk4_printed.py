#!/usr/bin/python3
"""A plain numpy RK4 of the single-rod model in its printed reading, against gmasim (issue 22).

    /usr/bin/python3 bench/numpy_rk4_printed.py [--bin build/ci/bin/gmasim] [--reps 3] [--json]
    /usr/bin/python3 bench/numpy_rk4_printed.py --check [--bin ...]   # ctest numpy_rk4_reference

The reference a user without gmasim would write: the ODE of models/single_rod.toml with
options.magnetic_state = "printed" (docs/model.md; the same laws as src/model/rk4_reference.cpp:
eq. 3 permeability, eq. 2 reluctance and the one-node magnetic circuit, eq. 7 eddy lag, eq. 9-10
Jiles-Atherton with M_irr integrated, eq. 11-14 magnetostriction, Delta-E modulus and force,
eq. 15-18 the rod's oscillator and its load chain), integrated by classical RK4 at a fixed step,
numpy scalars, one Python call per stage. Its constants are computed here from the model file
(tomllib), not taken from gmasim.

Both run the same waveform (biased sine, 8 A peak-to-peak from -3 A, 50 Hz, 3 periods, 20 degC);
the stroke of the last period is compared (the two integrators and starts differ: gmasim starts
at rest after a quasi-static ramp and steps with its exact update at T/2000; the reference starts
demagnetised at 0 A and steps RK4 at 2 us), and both are timed in this one run, interleaved, the
median of --reps, as CPU time (user + system; the machines are shared). The ratio is numpy's
time over gmasim's, gmasim's process start included.
Observed: the strokes agree to 2.4e-6 (relative).

--check (the ctest numpy_rk4_reference, numbers not timing): a shorter run (2 periods at 100 Hz,
RK4 at 4 us) whose strokes must agree within CHECK_REL_TOL; exit 1 otherwise.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
MU0 = 1.25663706212e-6
MODEL = ROOT / "models" / "single_rod.toml"
PP_A, MIN_A, FREQ_HZ, PERIODS, T_C = 8.0, -3.0, 50.0, 3, 20.0
RK4_DT_S = 2e-6
CHECK = {"freq": 100.0, "periods": 2, "dt": 4e-6}
CHECK_REL_TOL = 1.5e-5  # 10 x the observed 1.44e-6 (2 periods from the two starts, RK4 at 4 us)


def langevin(x: float) -> tuple[float, float]:
    """L(x) = coth x - 1/x and L'(x), with the series near 0 (jiles_atherton.hpp)."""
    ax = abs(x)
    if ax < 0.1:
        x2 = x * x
        return (x * (1 / 3 - x2 * (1 / 45 - x2 * (2 / 945 - x2 * (1 / 4725 - x2 * (2 / 93555))))),
                1 / 3 - x2 * (1 / 15 - x2 * (2 / 189 - x2 * (1 / 675 - x2 * (2 / 10395)))))
    e = np.exp(-2.0 * ax)
    coth = (1 + e) / (1 - e)
    return (coth if x > 0 else -coth) - 1 / x, 1 / (x * x) - 4 * e / (1 - e) ** 2


class SingleRodPrinted:
    """The constants of the single-rod template at T_C in the printed reading."""

    def __init__(self, path: pathlib.Path, T_C: float):
        with open(path, "rb") as f:
            d = tomllib.load(f)
        opt, mat, rod, ja = d["options"], d["material"], d["rod"], d["rod"]["ja"]
        Tr = d["reference"]["T_ref_C"]
        dT = T_C - Tr
        dTg = dT if opt.get("geometry_thermal_expansion", True) else 0.0
        g = 1 + mat["alpha_thermal_per_K"] * dTg
        self.l = rod["length_m"] * g
        ro, ri = 0.5 * rod["outer_diameter_m"] * g, 0.5 * rod["inner_diameter_m"] * g
        self.A = math.pi * (ro * ro - ri * ri)
        A_ref = math.pi * (rod["outer_diameter_m"] ** 2 - rod["inner_diameter_m"] ** 2) / 4
        preload = d["preload"]["prestress_MPa"] * 1e6 * A_ref
        self.sigma_p = preload / self.A
        sigma = (-1 if opt["stress_sign"] == "compression_negative" else 1) * self.sigma_p
        self.kf = rod["k_f"]
        Ms, x, Tc = mat["Ms_A_per_m"], mat["x"], mat["Tc_C"]
        self.MsT = Ms * (1 - dT / (Tc - Tr)) ** x  # eq. 4
        self.Ms_strain = self.MsT if opt["eq11_saturation"] == "temperature" else Ms
        ls, sl, beta, self.chi_m = mat["lambda_s"], mat["sigma_lambda_Pa"], mat["beta_per_K"], mat["chi_m"]
        self.ls = ls
        s0 = sl * math.atanh(1 / 3)
        s = (sigma - s0) / sl
        ln_cosh = abs(s) + math.log1p(math.exp(-2 * abs(s))) - math.log(2)
        L0 = 0.25 * ls * sigma + 0.75 * ls * sl * (math.log(2 * math.sqrt(2) / 3) + ln_cosh)  # eq. 6
        self.S = 2 * (ls * sigma - L0) + 2 * beta * dT * sigma  # eq. 3's stress term
        u = (sigma - s0) / sl  # eq. 13's terms
        self.inv_Es = 1 / mat["Es_Pa"]
        self.rot = 3 * ls / (4 * sl) / math.cosh(u) ** 2
        self.coup = 1.5 * ls * (1 - math.tanh(u)) + 2 * beta * dT
        self.mu0Ms2_chi = MU0 * self.MsT ** 2 / self.chi_m
        # eq. 10 (room-referenced scale in kelvin; mean-field or printed a^T)
        TK, TcK, TrK = T_C + 273.15, Tc + 273.15, Tr + 273.15
        t, tr = (T_C / Tc, Tr / Tc) if opt["eq10_temperature_scale"] == "celsius" else (TK / TcK, TrK / TcK)
        room = opt["eq10_temperature_scale"] == "room_referenced"

        def law(p0, f):
            return p0 * f(t) / f(tr) if room else p0 * f(t)

        fa = lambda tt: math.exp(-2 / ja["beta1"] * tt) * (1 - tt) ** -ja["beta1"]  # noqa: E731
        self.alpha = law(ja["alpha0"], fa)
        self.c = law(ja["c0"], fa)
        self.k = law(ja["k0_A_per_m"], lambda tt: math.exp(-tt / ja["beta2"]))
        self.a = (ja["a0_A_per_m"] * TK / TrK if opt["eq10_shape_law"] == "mean_field"
                  else law(ja["a0_A_per_m"], lambda tt: math.exp(-tt / ja["beta3"])))
        rho = mat["rho0_ohm_m"] + mat["drho_dT_ohm_m_per_K"] * dT  # eq. 8
        self.eddy = (ro * ro - ri * ri) / (4 * rod["k_j"] * rho)  # eq. 7, per unit permeability
        c = d["circuit"]
        R = c["reluctances_per_H"]
        coil = next(b for b in c["branches"] if "coil_turns" in b)
        self.N = coil["coil_turns"]
        self.R_coil = sum(R[k] for k in coil["series"])
        self.R_par = [sum(R[k] for k in b["series"]) for b in c["branches"]
                      if "rod" not in b and "coil_turns" not in b]
        el = d["mechanics"]["elements"]
        chain = d["mechanics"]["chains"]["rod"]
        m_load = sum(el[e]["mass_kg"] for e in chain)
        # The rod's mass: the file's, else derived from the cold geometry (gmasim/model/derived.hpp).
        r0o, r0i = 0.5 * rod["outer_diameter_m"], 0.5 * rod["inner_diameter_m"]
        m_rod = rod.get("mass_kg", mat.get("density_kg_per_m3", 9250.0) * math.pi
                        * (r0o * r0o - r0i * r0i) * rod["length_m"])
        self.m = m_rod / 3 + m_load  # eq. 15
        self.cd = rod["damping_N_s_per_m"] + 1 / sum(1 / el[e]["damping_N_s_per_m"] for e in chain)
        self.k_load = 1 / sum(1 / el[e]["stiffness_N_per_m"] for e in chain)  # eq. 18

    def magnetisation(self, H: float, Mirr: float, M: float) -> float:
        """Eq. 9: M = M_irr + c (M_an(H + alpha M) - M_irr), Newton from M."""
        for _ in range(8):
            L, dL = langevin((H + self.alpha * M) / self.a)
            gfun = M - (1 - self.c) * Mirr - self.c * self.MsT * L
            dM = gfun / (1 - self.c * self.MsT / self.a * dL * self.alpha)
            M -= dM
            if abs(dM) <= 1e-13 * (abs(M) + self.MsT * 1e-6):
                break
        return M

    def mechanics(self, M: float) -> tuple[float, float]:
        """Force and stiffness of the rod (eq. 11-14, 17) at M."""
        mm = M / self.MsT
        cc = math.cos(0.5 * math.pi * mm) ** 2
        E = 1 / (self.inv_Es + self.rot * (1 - mm * mm)
                 + self.coup ** 2 * mm * mm * cc / (self.mu0Ms2_chi - cc * self.S))  # eq. 13
        ss, smax = 0.5 * self.ls * E, 1.5 * self.ls * E
        f = 1 + 0.5 * math.tanh(2 * self.sigma_p / ss)
        if self.sigma_p > ss:
            f *= 1 - (self.sigma_p - ss) / smax
        lam = f * self.ls * (M / self.Ms_strain) ** 2  # eq. 11-12
        return lam * E * self.A, E * self.A / self.l

    def rhs(self, y: np.ndarray, I: float, M_guess: float) -> tuple[np.ndarray, float]:
        H, Mirr, x, v = y
        M = self.magnetisation(H, Mirr, M_guess)
        c2 = math.cos(0.5 * math.pi * M / self.MsT) ** 2
        mu = MU0 * (1 + 1 / (1 / (self.chi_m * c2) - self.S / (MU0 * self.MsT ** 2)))  # eq. 3
        R_rod = self.l / (mu * self.A)  # eq. 2
        G = 1 / self.R_coil + 1 / R_rod + sum(1 / r for r in self.R_par)
        u = self.N * I / self.R_coil / G  # the one node's magnetic potential
        Hc = (u / R_rod) / (self.kf * mu * self.A)  # eq. 7, static field
        dH = (Hc - H) / (mu * self.eddy)  # eq. 7, eddy lag
        He = H + self.alpha * M
        L, dL = langevin(He / self.a)
        diff = self.MsT * L - Mirr
        delta = 1.0 if dH >= 0 else -1.0
        dirr = diff / (self.k * delta) if diff * delta > 0 else 0.0
        chi_e = (1 - self.c) * dirr + self.c * self.MsT / self.a * dL
        dMirr = dirr / (1 - self.alpha * chi_e) * dH  # eq. 9
        F, k_rod = self.mechanics(M)
        dv = (F - self.cd * v - (k_rod + self.k_load) * x) / self.m  # eq. 15
        return np.array([dH, dMirr, v, dv]), M


def run_numpy(model: SingleRodPrinted, freq: float, periods: int, dt: float) -> tuple[float, int]:
    """Stroke [um] of the last period and the number of steps."""
    per = 1 / freq
    n_per = int(round(per / dt))
    h = per / n_per
    cur = lambda t: MIN_A + 0.5 * PP_A * (1 - math.cos(2 * math.pi * freq * t))  # noqa: E731
    y = np.zeros(4)
    M = 0.0
    ys = []
    for k in range(periods * n_per):
        t = k * h
        k1, M = model.rhs(y, cur(t), M)
        k2, M = model.rhs(y + 0.5 * h * k1, cur(t + 0.5 * h), M)
        k3, M = model.rhs(y + 0.5 * h * k2, cur(t + 0.5 * h), M)
        k4, M = model.rhs(y + h * k3, cur(t + h), M)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if k >= (periods - 1) * n_per:
            ys.append(y[2])
    return (max(ys) - min(ys)) * 1e6, periods * n_per


def run_gmasim(binary: str, out: pathlib.Path, freq: float, periods: int) -> tuple[float, int]:
    subprocess.run([binary, "simulate", "--model", str(MODEL), "--set", "options.magnetic_state=printed",
                    "--temperature", str(T_C), "--current-pp", str(PP_A), "--current-min", str(MIN_A),
                    "--frequency", str(freq), "--periods", str(periods), "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    m = json.loads((out / "metrics.json").read_text())
    return m["metrics"]["stroke_um"], int(m["steps"])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "build/ci/bin/gmasim"), help="the gmasim executable")
    ap.add_argument("--reps", type=int, default=3, help="timed repetitions (median), 1-20")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--check", action="store_true",
                    help=f"the short run only: the strokes agree within {CHECK_REL_TOL:g} or exit 1")
    a = ap.parse_args()
    if not 1 <= a.reps <= 20:
        sys.exit(f"numpy_rk4_printed.py: --reps {a.reps}: must be in [1, 20]")
    model = SingleRodPrinted(MODEL, T_C)
    if a.check:
        s_np, _ = run_numpy(model, CHECK["freq"], CHECK["periods"], CHECK["dt"])
        with tempfile.TemporaryDirectory() as tmp:
            s_gm, _ = run_gmasim(a.bin, pathlib.Path(tmp) / "c", CHECK["freq"], CHECK["periods"])
        rel = abs(s_np - s_gm) / s_gm
        ok = rel <= CHECK_REL_TOL
        print(f"numpy RK4 stroke {s_np:.9g} um, gmasim {s_gm:.9g} um: relative difference {rel:.3g} "
              f"({'within' if ok else 'OUTSIDE'} {CHECK_REL_TOL:g})")
        return 0 if ok else 1
    tn, tg = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(a.reps):  # CPU time (user + system): what the machine's load changes least
            t0 = time.process_time()
            s_np, n_np = run_numpy(model, FREQ_HZ, PERIODS, RK4_DT_S)
            tn.append(time.process_time() - t0)
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            s_gm, n_gm = run_gmasim(a.bin, pathlib.Path(tmp) / f"r{r}", FREQ_HZ, PERIODS)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            tg.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    res = {"waveform": f"biased sine {PP_A:g} A p-p from {MIN_A:g} A, {FREQ_HZ:g} Hz, {PERIODS} periods, "
                       f"{T_C:g} degC, models/single_rod.toml printed",
           "steps": f"numpy {n_np} (RK4 {RK4_DT_S * 1e6:g} us), gmasim {n_gm}",
           "numpy_s": statistics.median(tn), "gmasim_s": statistics.median(tg),
           "numpy_s_per_step": statistics.median(tn) / n_np, "gmasim_s_per_step": statistics.median(tg) / n_gm,
           "ratio": statistics.median(tn) / statistics.median(tg),
           "stroke_numpy_um": s_np, "stroke_gmasim_um": s_gm, "stroke_rel_diff": abs(s_np - s_gm) / s_gm}
    if a.json:
        print(json.dumps(res))
    else:
        for k, v in res.items():
            print(f"{k}: {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
