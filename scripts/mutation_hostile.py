"""The hostile classes of issue 19 for scripts/mutation_campaign.py (docs/reliability.md).

Each class builds one case in a fresh directory, runs it, and judges it by the issue's rules:

    crash     killed by a signal we did not send, an abort, exit 4 or a sanitizer report
    hang      still running 5 s after SIGTERM, or past the time limit
    nonsense  (silent wrong) exit 0 while breaking a documented invariant: finite outputs,
              |B| <= mu0 (1.05 M_s + |H|) (consistent state), |strain| <= 3.375 lambda_s, |x| below
              the rod length, inputs unchanged, the two output files of one run belonging
              together, no temporary left behind, y held at constant current, or a stroke or
              hysteresis that moves by more than 1 % when dt is halved
    unclear   a refusal whose message names no file:line, flag or key, or states no rule

Classes: same_file (an output equal to an input), tiny_step (tiny, denormal and halved steps),
absurd_physics (finite but absurd --set values), concurrent (two runs on one --out), signal
(SIGINT/SIGTERM/SIGHUP during a write or identify's first population), rlimit (ulimit -f and
ulimit -v). Standard library only.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import pathlib
import resource
import signal
import subprocess
import time
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent
MU0 = 1.25663706212e-6
KINDS = ["same_file", "tiny_step", "absurd_physics", "concurrent", "signal", "rlimit"]


def _run(cmd, d, timeout, **kw):
    try:
        p = subprocess.run(cmd, cwd=d, capture_output=True, timeout=timeout, **kw)
        return p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        return None, "", ""


def _digest(p: pathlib.Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest() if p.exists() else "absent"


def _fnv(data: bytes) -> str:
    h = 14695981039346656037
    for c in data:
        h = ((h ^ c) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def pair_problem(out: pathlib.Path) -> str:
    """Why out/ is not one run's set (metrics.json names its timeseries.csv), or ''."""
    left = [p.name for p in out.glob("*.tmp.*")] if out.is_dir() else []
    if left:
        return f"temporary left behind: {left[0]}"
    csv, js = out / "timeseries.csv", out / "metrics.json"
    if not (csv.exists() and js.exists()):
        return ""
    try:
        m = json.loads(js.read_text()).get("timeseries_csv")
    except (ValueError, OSError):
        return "metrics.json is not JSON"
    data = csv.read_bytes()
    if m != {"bytes": len(data), "fnv1a64": _fnv(data)}:
        return "metrics.json and timeseries.csv come from different runs"
    return ""


UNIT_WORDS = ("must", "expected", "not ", "only", "cannot", "limit", "refus", "would", "unknown",
              "did you mean", "beyond", "outside", "too many", "exceed", "needs", "no such",
              "malformed", "larger than", "shorter", "longer", "at least", "at most", "duplicate",
              "does not", "give ", "choose", "remove", "lower", "diverged", "no option", "is not",
              "missing", "empty", "write '", "nan", "inf", "non-numeric", "syntax error", "mismatched",
              "out-of-range", "invalid", "error while parsing", "unexpected", "expected", "neither",
              "twice", "damaged")
NAMES = ("--", ".toml", ".csv", ".txt", ".json", " = ", "=")


def clear_message(err: str) -> bool:
    """The issue's test: the message names a file:line, a flag or a key, and states a rule."""
    msg = "\n".join(l for l in err.strip().splitlines() if not l.startswith("Run with --help"))
    msg = msg.replace("gmasim: error: ", "").replace("gmasim: warning: ", "")
    names = any(n in msg for n in NAMES) or any(c.isalpha() and "." in w for w in msg.split() for c in w[:1])
    rule = any(w in msg.lower() for w in UNIT_WORDS)
    return bool(msg) and names and rule and len(msg) < 5000


def refusal_verdict(rc, err):
    if rc is None:
        return "hang", "time limit"
    if rc < 0 or rc >= 128 or rc == 4 or "Sanitizer" in err or "runtime error:" in err:
        return "crash", (err.strip().splitlines() or [f"exit {rc}"])[-1][:200]
    if rc == 3:
        return ("ok", "diverged") if "diverged" in err else ("unclear", err.strip()[:200])
    if rc in (1, 2):
        return ("ok", "refused") if clear_message(err) else ("unclear", err.strip()[:200])
    return "ok", "accepted"


# ---- same_file: an output equal to an input ----------------------------------------------
IDENT = ["identify", "--islands", "1", "--population", "8", "--migrate-every", "1", "--no-refine",
         "--no-plots", "--quiet", "--steps-per-period", "100", "--threads", "1"]


def _same_file_scenarios(d: pathlib.Path):
    """(command, the input files that must stay unchanged)"""
    os.makedirs(d / "o", exist_ok=True)
    os.makedirs(d / "syn", exist_ok=True)
    (d / "o" / "timeseries.csv").write_bytes((d / "w.csv").read_bytes())
    (d / "syn" / "truth.toml").write_bytes((d / "model.toml").read_bytes())
    os.makedirs(d / "hl", exist_ok=True)
    if not (d / "hl" / "timeseries.csv").exists():
        os.link(d / "w.csv", d / "hl" / "timeseries.csv")  # the output, a hard link to the input
    data = ["--data", "manifest.toml", "--fit", "fit.toml", "--generations", "1"]
    refuse = [
        ([*IDENT, *data, "--out", "manifest.toml"], ["manifest.toml"]),
        ([*IDENT, *data, "--out", "meas.csv"], ["meas.csv"]),
        ([*IDENT, *data, "--out", "fit.toml"], ["fit.toml"]),
        ([*IDENT, *data, "--out", "./fit.toml"], ["fit.toml"]),
        ([*IDENT, *data, "--out", "m.toml", "--checkpoint", "meas.csv"], ["meas.csv"]),
        ([*IDENT, *data, "--out", "same.toml", "--checkpoint", "same.toml"], []),
        ([*IDENT, *data, "--model", "model.toml", "--out", "model.toml"], ["model.toml"]),
        ([*IDENT, "--fit", "fit.toml", "--out", "m.toml", "--resume", "ck.txt", "--checkpoint", "fit.toml",
          "--generations", "3"],
         ["fit.toml", "ck.txt"]),
        (["simulate", "--waveform", "o/timeseries.csv", "--out", "o"], ["o/timeseries.csv"]),
        (["simulate", "--waveform", "w.csv", "--out", "hl"], ["w.csv"]),
        (["model", "save", "--model", "model.toml", "--out", "model.toml", "--set", "material.chi_m=20"],
         ["model.toml"]),
        (["model", "save", "--model", "model.toml", "--out", "./model.toml"], ["model.toml"]),
        (["identify", "synthesize", "--model", "syn/truth.toml", "--out", "syn", "--temperatures", "20",
          "--currents", "8", "--frequencies", "10"], ["syn/truth.toml"]),
        (["sweep", "--model", "sweep.toml", "--temperatures", "20", "--currents", "8", "--periods", "1",
          "--out", "."], ["sweep.toml"]),
        (["reproduce", "--quick", "--no-figures", "--doc", "notes.md", "--doc-notes", "notes.md",
          "--out", "rep"], ["notes.md"]),
    ]
    allowed = [  # outputs beside the inputs, none of them equal to one: accepted, inputs unchanged
        ([*IDENT, *data, "--out", "m.toml", "--report", "."], ["manifest.toml", "meas.csv", "fit.toml"]),
        (["simulate", "--model", "model.toml", "--periods", "1", "--out", "."], ["model.toml"]),
        ([*IDENT, "--fit", "fit.toml", "--out", "m2.toml", "--resume", "ck.txt", "--checkpoint", "ck.txt",
          "--generations", "3"], ["fit.toml"]),
    ]
    return [(c, k, True) for c, k in refuse] + [(c, k, False) for c, k in allowed]


def case_same_file(rng, s, bin_, d, timeout):
    for name, key in (("model.toml", "model"), ("w.csv", "waveform"), ("meas.csv", "measurement"),
                      ("manifest.toml", "manifest"), ("fit.toml", "fit"), ("ck.txt", "checkpoint")):
        (d / name).write_text(s[key])
    (d / "sweep.toml").write_text(s["model"])
    (d / "notes.md").write_text("### a claim\nwhy it fails\n")
    cmd, keep, must_refuse = rng.choice(_same_file_scenarios(d))
    before = {k: _digest(d / k) for k in keep}
    rc, out, err = _run([bin_, *cmd], d, timeout)
    changed = [k for k in keep if _digest(d / k) != before[k]]
    if changed:
        return "nonsense", f"input {changed[0]} was overwritten (exit {rc})", cmd
    if rc == 0 and must_refuse:
        return "nonsense", "an output equal to an input was accepted", cmd
    v, why = refusal_verdict(rc, err)
    return v, why, cmd


# ---- tiny_step: tiny, denormal and halved time steps --------------------------------------
TINY = [1e-28, 1e-24, 1e-20, 1e-16, 1e-13, 1.1e-12, 1e-12, 9.9e-13, 1e-10, 1e-9, 4.9e-324, 2.2e-308,
        1e-300, 5e-324, 1e-7]
STEPPER = """
import math, sys, warnings
warnings.simplefilter("ignore")
import gmasim
dt, level, n = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
try:
    st = gmasim.Stepper(gmasim.Model(), dt_s=dt, current_A=level)
except ValueError as e:
    print("refused:", e); sys.exit(2)
y0 = st.y_um
ys = [st.step(level) for _ in range(n)]
drift = max(abs(y - y0) for y in ys)
print("drift_um", drift)
sys.exit(0 if math.isfinite(drift) and drift <= 1e-3 else 5)
"""


def _metrics(d: pathlib.Path, out: str):
    try:
        return json.loads((d / out / "metrics.json").read_text()).get("metrics", {})
    except (OSError, ValueError):
        return {}


def _tiny_cli(rng, bin_, d, timeout):
    dt = rng.choice(TINY)
    level = rng.choice([0.0, 1.0, 5.0, -3.0])
    dur = rng.choice([1e-24, 1e-9, 1e-6, 1e-4, 2e-3])
    cmd = ["simulate", "--waveform-kind", "dc", "--level", repr(level), "--duration", repr(dur),
           "--dt", repr(dt), "--out", "o"]
    rc, out, err = _run([bin_, *cmd], d, timeout)
    if rc == 0:
        m = _metrics(d, "o")
        stroke = m.get("stroke_um", 0.0)
        if not (isinstance(stroke, (int, float)) and math.isfinite(stroke) and stroke <= 1e-3):
            return "nonsense", f"constant current, stroke {stroke} um", cmd
        return "ok", "accepted", cmd
    return (*refusal_verdict(rc, err), cmd)


def _tiny_stepper(rng, bin_, d, timeout, py_env):
    dt = rng.choice(TINY)
    level = rng.choice([0.0, 2.0, 5.0])
    cmd = ["/usr/bin/python3", "-c", STEPPER, repr(dt), repr(level), "200"]
    rc, out, err = _run(cmd, d, timeout, env=py_env)
    if rc == 0 or rc == 2:
        return "ok", out.strip()[:120], cmd
    if rc == 5:
        return "nonsense", f"Stepper(dt_s={dt}) does not hold y at constant current: {out.strip()}", cmd
    return "crash" if rc is None or rc < 0 else "unclear", err.strip()[-200:], cmd


def _halving(rng, bin_, d, timeout):
    f = rng.choice([1.0, 10.0, 100.0, 400.0, 1000.0])
    n = rng.choice([20, 50, 100, 120, 200, 400, 1000])
    dt = 1.0 / (f * n)
    base = ["simulate", "--frequency", repr(f), "--periods", "2"]
    cmd = [*base, "--dt", repr(dt), "--out", "a"]
    rc, out, err = _run([bin_, *cmd], d, timeout)
    if rc != 0:
        return (*refusal_verdict(rc, err), cmd)
    rc2, _, err2 = _run([bin_, *base, "--dt", repr(dt / 2), "--out", "b"], d, timeout)
    if rc2 != 0:
        return "nonsense", f"--dt {dt} accepted, --dt {dt / 2} refused: {err2.strip()[:120]}", cmd
    a, b = _metrics(d, "a"), _metrics(d, "b")
    for k in ("stroke_um", "hysteresis_um"):
        if abs(a[k] - b[k]) > 0.01 * abs(b[k]) + 1e-6:
            return "nonsense", f"{k} moves {a[k]:.6g} -> {b[k]:.6g} when dt is halved", cmd
    return "ok", "converged", cmd


def case_tiny_step(rng, s, bin_, d, timeout, py_env):
    r = rng.random()
    if r < 0.4:
        return _tiny_cli(rng, bin_, d, timeout)
    if r < 0.7:
        return _tiny_stepper(rng, bin_, d, timeout, py_env)
    return _halving(rng, bin_, d, timeout)


# ---- absurd_physics: finite but absurd --set values ------------------------------------------
ABSURD_KEYS = ["material.Ms_A_per_m", "material.lambda_s", "material.sigma_lambda_Pa", "material.Es_Pa",
               "material.Tc_C", "material.rho0_ohm_m", "material.chi_m", "material.x",
               "material.alpha_thermal_per_K", "material.beta_per_K", "preload.force_N", "rod1.length_m",
               "rod2.outer_diameter_m", "rod1.mass_kg", "rod1.k_f", "rod1.k_j", "rod3.damping_N_s_per_m",
               "rod1.ja.a0_A_per_m", "rod2.ja.alpha0", "rod1.ja.c0", "rod3.ja.k0_A_per_m",
               "circuit.branches.phi4.coil_turns", "mechanics.output_stage.stiffness_N_per_m",
               "reference.T_ref_C", "rod1.length", "material.Ms"]


def _base_values() -> dict:
    doc = tomllib.loads((ROOT / "models" / "mdma.toml").read_text())
    flat = {}

    def walk(prefix, node):
        for k, v in node.items():
            if isinstance(v, dict):
                walk(prefix + k + ".", v)
            elif isinstance(v, (int, float)) and not isinstance(v, bool):
                flat[prefix + k] = float(v)
    walk("", doc)
    for b in doc.get("circuit", {}).get("branches", []):
        for k, v in b.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                flat[f"circuit.branches.{b['name']}.{k}"] = float(v)
    return flat


def _rows(csv: pathlib.Path):
    lines = csv.read_text().splitlines()
    names = lines[0].split(",")
    return names, [[float(x) for x in l.split(",")] for l in lines[1:]]


def invariant_problem(d: pathlib.Path, values: dict, T: float) -> str:
    """The first documented invariant the run in d/o breaks, or ''."""
    try:
        names, rows = _rows(d / "o" / "timeseries.csv")
    except (OSError, ValueError, IndexError):
        return ""
    for r in rows:
        if not all(math.isfinite(x) for x in r):
            return "a non-finite value in timeseries.csv"
    lam_s, Ms = values["material.lambda_s"], values["material.Ms_A_per_m"]
    ms_scale = 1.25 if T < values["reference.T_ref_C"] else 1.0
    col = {n: i for i, n in enumerate(names)}
    for rod in ("rod1", "rod2", "rod3"):
        length_um = values[f"{rod}.length_m"] * 1e6 * 1.01
        for r in rows:
            lam = abs(r[col[f"{rod}_lambda_ppm"]]) * 1e-6
            if lam > 3.375 * lam_s * ms_scale ** 2 * 1.001:
                return f"{rod}: |lambda| = {lam:.4g} beyond 3.375 lambda_s"
            if abs(r[col[f"{rod}_x_um"]]) >= length_um:
                return f"{rod}: |x| = {r[col[f'{rod}_x_um']]:.4g} um beyond its length"
            B, H = abs(r[col[f"{rod}_B_T"]]), abs(r[col[f"{rod}_H_A_per_m"]])
            if B > MU0 * (1.05 * Ms * ms_scale + H) * 1.001:
                return f"{rod}: |B| = {B:.4g} T above mu0 (M_s + |H|)"
    return ""


def case_absurd_physics(rng, s, bin_, d, timeout):
    base = _base_values()
    key = rng.choice(ABSURD_KEYS)
    full = key if key in base else key + "_m" if key + "_m" in base else key + "_A_per_m"
    b = base.get(full, 1.0) or 1.0
    value = b * rng.choice([1e-12, 1e-9, 1e-6, 1e-3, 1e3, 1e6, 1e9, 1e12, -1.0, -1e3, 0.5, 2.0, 10.0])
    T = rng.choice([20.0, 70.0, 150.0, -50.0, 250.0, 300.0])
    cmd = ["simulate", "--set", f"{key}={value:.6g}", "--periods", "1", "--frequency", "100",
           "--temperature", repr(T), "--out", "o"]
    rc, out, err = _run([bin_, *cmd], d, timeout)
    if rc == 0 and key != full:
        return "nonsense", f"the unit-less key {key} was accepted", cmd
    if rc == 0:
        values = dict(base)
        values[full] = float(f"{value:.6g}")
        problem = invariant_problem(d, values, T)
        return ("nonsense", problem, cmd) if problem else ("ok", "accepted", cmd)
    return (*refusal_verdict(rc, err), cmd)


# ---- concurrent: two runs on one --out --------------------------------------------------------
def case_concurrent(rng, s, bin_, d, timeout):
    periods = repr(rng.choice([1, 2, 3]))  # equally long runs: their renames coincide
    runs = [["simulate", "--current-pp", repr(pp), "--periods", periods, "--frequency", "100",
             "--out", "o"] for pp in rng.sample([4.0, 6.0, 8.0, 10.0], 2)]
    if rng.random() < 0.3:
        runs[1] = ["sweep", "--temperatures", "20", "--currents", "8", "--frequencies", "100",
                   "--periods", "1", "--out", "o"]
    procs = [subprocess.Popen([bin_, *c], cwd=d, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
             for c in runs]
    rcs = []
    for p in procs:
        try:
            _, err = p.communicate(timeout=timeout)
            rcs.append((p.returncode, err.decode("utf-8", "replace")))
        except subprocess.TimeoutExpired:
            p.kill()
            return "hang", "time limit", runs[0]
    for rc, err in rcs:
        if rc != 0:
            v, why = refusal_verdict(rc, err)
            if v != "ok":
                return v, why, runs[0]
    problem = pair_problem(d / "o")
    return ("nonsense", problem, runs[0]) if problem else ("ok", "one run's set", runs[0])


# ---- signal: SIGINT/SIGTERM/SIGHUP during a write or identify's first population -------------
def _wait_after(p, sig, delay):
    time.sleep(delay)
    if p.poll() is not None:
        return p.returncode, False
    p.send_signal(sig)
    try:
        p.wait(timeout=5.0)
        return p.returncode, True
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
        return None, True


def case_signal(rng, s, bin_, d, timeout):
    sig = rng.choice([signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
    if rng.random() < 0.3:
        (d / "fit.toml").write_text(s["fit"])
        pop = repr(rng.choice([200, 400]))
        cmd = [pop if a == "8" else a for a in IDENT]  # IDENT's --population 8 -> 200 or 400
        cmd = [*cmd, "--fit", "fit.toml", "--generations", "1", "--out", "m.toml",
               "--checkpoint", "ck.txt"]
        delay = rng.uniform(0.3, 2.0)
    else:
        cmd = ["simulate", "--periods", repr(rng.choice([5, 10, 20])), "--frequency", "10",
               "--out", "o"]
        # Time one undisturbed run, then signal the next within its second half: the writing
        # of a 20-80 MB timeseries.csv.
        t0 = time.monotonic()
        _run([bin_, *cmd[:-1], "o_timing"], d, timeout)
        delay = rng.uniform(0.4, 1.0) * (time.monotonic() - t0)
    p = subprocess.Popen([bin_, *cmd], cwd=d, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    rc, sent = _wait_after(p, sig, delay)
    err = p.stderr.read().decode("utf-8", "replace") if p.stderr else ""
    if rc is None:
        return "hang", f"still running 5 s after signal {int(sig)}", cmd
    if rc < 0 and (not sent or -rc != int(sig)):
        return "crash", f"killed by signal {-rc}", cmd
    for where in (d, d / "o"):
        left = [x.name for x in where.glob("*.tmp.*")] if where.is_dir() else []
        if left:
            return "nonsense", f"temporary left behind: {left[0]}", cmd
    problem = pair_problem(d / "o")
    if problem:
        return "nonsense", problem, cmd
    if rc not in (0, 130, 2, 3) and rc > 0 and rc != 128 + int(sig):
        return refusal_verdict(rc, err)[0], err.strip()[-200:], cmd
    return "ok", f"exit {rc} after signal {int(sig) if sent else 'none'}", cmd


# ---- rlimit: ulimit -f and ulimit -v ------------------------------------------------------------
def case_rlimit(rng, s, bin_, d, timeout):
    kind = rng.choice(["fsize", "as"])
    if kind == "fsize":
        limit = rng.choice([1, 10, 100, 1000, 10000]) * 1024
        which = resource.RLIMIT_FSIZE
    else:
        limit = rng.choice([300, 600, 1000, 2000, 4000]) * 1024 * 1024
        which = resource.RLIMIT_AS
    cmds = [
        ["simulate", "--periods", repr(rng.choice([1, 5, 20])), "--frequency", "10", "--out", "o"],
        ["sweep", "--temperatures", "20,70", "--currents", "8", "--frequencies", "100",
         "--periods", "1", "--out", "o"],
    ]
    if kind == "as":  # 100 s at 10 us: 14 GB of record, refused before the run under the limit
        cmds.append(["simulate", "--waveform", "ms.csv", "--out", "o"])
    cmd = rng.choice(cmds)
    (d / "ms.csv").write_text("t_s,current_A\n0,0\n50,1\n100,0\n")  # a waveform given in ms

    def limit_it():
        resource.setrlimit(which, (limit, limit))

    rc, out, err = _run([bin_, *cmd], d, timeout, preexec_fn=limit_it)
    what = f"ulimit -{'f' if kind == 'fsize' else 'v'} {limit // 1024}"
    if rc is None:
        return "hang", f"{what}: time limit", cmd
    if rc < 0 or rc == 4 or rc >= 128:
        return "crash", f"{what}: exit {rc}: {err.strip()[-150:]}", cmd
    if rc == 0:
        problem = pair_problem(d / "o")
        return ("nonsense", f"{what}: {problem}", cmd) if problem else ("ok", "accepted", cmd)
    v, why = refusal_verdict(rc, err)
    return v, f"{what}: {why}", cmd


def run_case(kind, rng, s, bin_, d, timeout, py_env):
    """(verdict, why, command) of one case of a hostile class."""
    if kind == "same_file":
        return case_same_file(rng, s, bin_, d, timeout)
    if kind == "tiny_step":
        return case_tiny_step(rng, s, bin_, d, timeout, py_env)
    if kind == "absurd_physics":
        return case_absurd_physics(rng, s, bin_, d, timeout)
    if kind == "concurrent":
        return case_concurrent(rng, s, bin_, d, timeout)
    if kind == "signal":
        return case_signal(rng, s, bin_, d, timeout)
    return case_rlimit(rng, s, bin_, d, timeout)
