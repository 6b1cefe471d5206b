#!/usr/bin/python3
"""The tables of docs/performance.md, measured in one run on this machine (issue 22, item 5).

    /usr/bin/python3 scripts/performance.py [--bin build/ci/bin] [--reps 3] [--sections bench,numpy,scaling,growth,callgrind]

Every figure is a ratio of two timings taken in the same run, interleaved (A B A B ...) and
reduced to the median of --reps repetitions, because the machines are shared and noisy: the
absolute times are printed for reference only. Sections:

  1. gmasim_bench (one run, its own repetitions): each benchmark against the printed reading's
     step (BM_FullModelStep/1).
  2. gmasim against a plain numpy RK4 of the same model in its printed reading
     (bench/numpy_rk4_printed.py), the same waveform, stroke compared.
  3. threads: `gmasim sweep` and `gmasim identify` with --threads 1 and 2.
  4. MPI: `gmasim identify` on one process against 2 ranks (mpirun -np 2), the same islands.
  5. growth: rods (models/single_rod.toml, 1 rod, against models/mdma.toml, 3 rods), periods
     of a simulation, conditions (grid points) of a sweep.
  6. callgrind (not in the default --sections): the instructions of step() per step, consistent
     state (the run of BM_FullModelStep/0) against the printed reading (/1), counted by valgrind's
     callgrind over a fixed 2000 steps (gmasim_step_count, the same steps without Google
     Benchmark and without libhwy's load-time timer probe, issue 36), and their ratio; beside it the ns per step of
     BM_FullModelStep/0 and /1 from one run, interleaved (issue 22, item 1: /0 <= 500 ns and
     /0 <= /1; the count decides where the shared machine's timings cannot).

--step-budget N (the ctest step_instruction_budget): only the callgrind counts, no timing;
exits 1 unless the consistent step costs at most N instructions per step and no more than the
printed reading's (/0 <= /1), and 77 (ctest's skip) with the reason printed when valgrind cannot
run the counter on this CPU (an instruction its decoder does not know). Instruction counts do not swing with the shared machine's load,
so a stray allocation or a slower law shows here where a timing would not.

Standard library only (numpy for section 2, as bench/numpy_rk4_printed.py needs it).
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


def timed(cmd: list[str], cwd: pathlib.Path, env: dict | None = None) -> tuple[float, float]:
    """(wall, CPU) time [s] of one command (CPU: user + system of the process and its children);
    its output is discarded, a failure stops the script."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         env={**os.environ, **(env or {})})
    t = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        sys.exit(f"performance.py: {' '.join(cmd)} failed:\n{res.stderr}")
    return t, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def interleaved(variants: dict[str, list[str]], reps: int, cwd: pathlib.Path,
                env: dict | None = None, cpu: bool = False) -> dict[str, float]:
    """Median wall (cpu: CPU) time of each variant over reps rounds, the variants alternating."""
    times: dict[str, list[float]] = {k: [] for k in variants}
    for _ in range(reps):
        for k, cmd in variants.items():
            times[k].append(timed(cmd, cwd, env)[1 if cpu else 0])
    return {k: statistics.median(v) for k, v in times.items()}


def table(header: list[str], rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


BENCH_FILTER = ("BM_FullModelStep|BM_LawSingleRodStep/0|BM_PeriodExact|BM_PeriodRk4At2us|"
                "BM_RunLoopNoRecorder|BM_MakeConditions|BM_CompileBuiltIn|BM_SweepDefaultGrid|"
                "BM_Objective12Conditions/200")
BENCH_WHAT = {
    "BM_FullModelStep/0": "one step, built-in model (consistent state, 3 rods), 70 degC, 400 Hz",
    "BM_FullModelStep/1": "one step, printed reading (3 rods)",
    "BM_FullModelStepWithLedger": "one step of /0 with the energy ledgers",
    "BM_LawSingleRodStep/0": "one step, single-rod template (JA), 50 Hz",
    "BM_PeriodExact/10": "one 10 Hz period, production step at the automatic dt",
    "BM_PeriodExact/400": "one 400 Hz period, production step",
    "BM_PeriodRk4At2us/10": "one 10 Hz period, explicit RK4 at 2 us (C++ reference)",
    "BM_PeriodRk4At2us/400": "one 400 Hz period, explicit RK4 at 2 us",
    "BM_RunLoopNoRecorder": "run_loop over a period, no recorder",
    "BM_MakeConditions": "temperature-dependent constants at one temperature",
    "BM_CompileBuiltIn": "model file -> compiled Model",
}


def bench_section(bindir: pathlib.Path, reps: int) -> str:
    exe = bindir / "gmasim_bench"
    if not exe.is_file():
        return f"(no {exe}: build the gmasim_bench target of a Release preset)"
    run = subprocess.run([str(exe), f"--benchmark_filter={BENCH_FILTER}", "--benchmark_format=json",
                          f"--benchmark_repetitions={reps}", "--benchmark_report_aggregates_only=true"],
                         cwd=ROOT, capture_output=True, text=True)
    if run.returncode != 0:
        return f"(gmasim_bench failed: {run.stderr.strip()[-400:]})"
    res = {b["run_name"]: b for b in json.loads(run.stdout)["benchmarks"]
           if b.get("aggregate_name") == "median"}
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    # CPU time of the benchmark's thread (what the load changes least); wall time for the
    # benchmarks that run worker threads (real_time in their name).
    t = {k: b["real_time" if "real_time" in k else "cpu_time"] * scale[b["time_unit"]]
         for k, b in res.items()}
    ref = t.get("BM_FullModelStep/1")
    rows = []
    for k, v in t.items():
        extra = ""
        b = res[k]
        for c in ("points_per_s", "items_per_second", "evals_per_s"):
            if c in b:
                extra = f"{c} {b[c]:.4g}"
        what = BENCH_WHAT.get(k, "")
        if k.startswith("BM_SweepDefaultGrid"):
            what = "the default sweep grid (24 points), threads in the name"
        if k.startswith("BM_Objective12Conditions"):
            what = "one evaluation of a 12-condition identify objective (200 steps/period)"
        rows.append([k, what, f"{v * 1e6:.4g} us", f"{v / ref:.3g}" if ref else "-", extra])
    return table(["benchmark", "measures", "median CPU time (wall: real_time)", "x printed step", "counter"],
                 rows)


def numpy_section(bindir: pathlib.Path, reps: int) -> str:
    script = ROOT / "bench" / "numpy_rk4_printed.py"
    if not script.is_file():
        return "(bench/numpy_rk4_printed.py is missing)"
    res = subprocess.run(["/usr/bin/python3", str(script), "--bin", str(bindir / "gmasim"),
                          "--reps", str(reps), "--json"], cwd=ROOT, capture_output=True, text=True)
    if res.returncode != 0:
        return f"(bench/numpy_rk4_printed.py failed: {res.stderr.strip()[-400:]})"
    d = json.loads(res.stdout)
    rows = [[d["waveform"], f"{d['steps']}", f"{d['numpy_s_per_step'] * 1e6:.4g} us",
             f"{d['gmasim_s_per_step'] * 1e6:.4g} us", f"{d['ratio']:.3g}",
             f"{d['stroke_numpy_um']:.5g} / {d['stroke_gmasim_um']:.5g} um ({d['stroke_rel_diff']:.2e})"]]
    return table(["waveform", "steps", "numpy RK4 per step", "gmasim per step", "numpy / gmasim",
                  "stroke numpy / gmasim (rel. diff.)"], rows)


STEP_SYMBOL = "gmasim::step(*"  # callgrind collects inside step() only (--toggle-collect)
STEP_COUNTER = "gmasim_step_count"  # bench/count/step_count.cpp: BM_FullModelStep's run, 2000 steps
SKIP = 77  # the ctest step_instruction_budget's SKIP_RETURN_CODE
# What valgrind prints when it cannot run a program on the CPU at hand (an instruction its
# decoder does not know, e.g. valgrind 3.19 and RDTSCP on AMD Zen 5, or AVX-512 anywhere): the
# tool cannot count here, which is not a failure of the step.
VALGRIND_CANNOT_RUN = ("unrecognised instruction", "unhandled instruction bytes",
                       "your program just tried to execute an instruction that valgrind")


class CannotCount(Exception):
    """valgrind cannot run the counter on this CPU; the message says why."""


def cpu_model() -> str:
    """The machine as scripts/cpu_info.sh names it (model, vendor, SIMD flags, libm path)."""
    res = subprocess.run(["bash", str(ROOT / "scripts/cpu_info.sh")], capture_output=True, text=True)
    return res.stdout.strip().removeprefix("cpu: ") if res.returncode == 0 else "unknown CPU"


def callgrind_step_instructions(exe: pathlib.Path, arg: int, work: pathlib.Path) -> tuple[float, int]:
    """(instructions per step, steps) inside step() for gmasim_step_count <arg> (the steps of
    BM_FullModelStep/<arg>): the instructions callgrind collected while in step(), over
    the calls of step() it recorded. Raises CannotCount when valgrind cannot run the program on
    this CPU."""
    out = work / f"callgrind.{arg}.out"
    res = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                          f"--toggle-collect={STEP_SYMBOL}", str(exe), str(arg)],
                         cwd=ROOT, capture_output=True, text=True)
    cannot = next((s for s in VALGRIND_CANNOT_RUN if s in res.stderr.lower()), None)
    if cannot is not None:
        where = next((ln.split("== ", 1)[-1].strip() for ln in res.stderr.splitlines()
                      if "at 0x" in ln), "")
        raise CannotCount(f"valgrind cannot run {exe.name} on this CPU ({cpu_model()}): "
                          f"'{cannot}'" + (f" {where}" if where else ""))
    if res.returncode != 0 or not out.is_file():
        sys.exit(f"performance.py: callgrind of {exe.name} {arg} failed (exit {res.returncode}):\n"
                 f"{res.stderr[-600:]}")
    # Function names are compressed: "(id) name" the first time an id appears, "(id)" after it.
    total, calls, names, lines = None, 0, {}, out.read_text().splitlines()
    for i, line in enumerate(lines):
        if line.startswith("summary:") or line.startswith("totals:"):
            total = int(line.split()[1])
        if line.startswith(("fn=(", "cfn=(")):
            fid, _, name = line.split("=", 1)[1].partition(" ")
            name = names.setdefault(fid, name)
            if (line.startswith("cfn=") and name.startswith("gmasim::step(") and i + 1 < len(lines)
                    and lines[i + 1].startswith("calls=")):
                calls += int(lines[i + 1].split()[0].removeprefix("calls="))
    if not total or calls <= 0:
        sys.exit(f"performance.py: no calls of step() in {out}")
    return total / calls, calls


def callgrind_section(bindir: pathlib.Path, reps: int, work: pathlib.Path) -> str:
    exe, bench = bindir / STEP_COUNTER, bindir / "gmasim_bench"
    if not exe.is_file() or not bench.is_file():
        return f"(no {exe} or {bench}: build the gmasim_bench and {STEP_COUNTER} targets of a Release preset)"
    if not shutil.which("valgrind"):
        return "(no valgrind on PATH: apt-get install valgrind)"
    try:
        ir = {arg: callgrind_step_instructions(exe, arg, work) for arg in (0, 1)}
    except CannotCount as e:
        return f"(not counted: {e})"
    run = subprocess.run([str(bench), "--benchmark_filter=^BM_FullModelStep/[01]$",
                          "--benchmark_format=json", f"--benchmark_repetitions={max(reps, 2)}",
                          "--benchmark_enable_random_interleaving=true"],
                         cwd=ROOT, capture_output=True, text=True)
    if run.returncode != 0:
        return f"(gmasim_bench failed: {run.stderr.strip()[-400:]})"
    ns: dict[str, list[float]] = {"0": [], "1": []}
    for b in json.loads(run.stdout)["benchmarks"]:
        if b.get("run_type") == "iteration" and b["time_unit"] == "ns":
            ns[b["run_name"].rsplit("/", 1)[1]].append(b["cpu_time"])
    med = {k: statistics.median(v) for k, v in ns.items() if v}
    rows = [[f"/{a}", "consistent state (built-in)" if a == 0 else "printed reading",
             f"{ir[a][0]:.0f}", f"{ir[a][1]}", f"{med.get(str(a), float('nan')):.0f}",
             f"{min(ns[str(a)]):.0f}-{max(ns[str(a)]):.0f}" if ns[str(a)] else "-"] for a in (0, 1)]
    rows.append(["/0 / /1", "", f"{ir[0][0] / ir[1][0]:.3f}", "",
                 f"{med['0'] / med['1']:.3f}" if len(med) == 2 else "-", ""])
    return table(["BM_FullModelStep", "step", "instructions per step (callgrind)", "steps counted",
                  "median CPU ns per step (interleaved)", "range ns"], rows)


def step_budget_check(bindir: pathlib.Path, budget: int, work: pathlib.Path,
                      counter: pathlib.Path | None = None) -> int:
    """--step-budget: /0 <= budget instructions per step and /0 <= /1 (callgrind), 0 if both;
    SKIP (77, with the reason) when valgrind cannot run the counter on this CPU. `counter`
    replaces gmasim_step_count (the test of the skip runs a program valgrind cannot decode)."""
    exe = counter or bindir / STEP_COUNTER
    if not exe.is_file():
        sys.exit(f"performance.py: --step-budget: no {exe}" + ("" if counter else f" (build {STEP_COUNTER}, a Release preset)"))
    exe = exe.resolve()
    if not shutil.which("valgrind"):
        sys.exit("performance.py: --step-budget: no valgrind on PATH (scripts/install_deps.sh)")
    try:
        ir = {arg: callgrind_step_instructions(exe, arg, work)[0] for arg in (0, 1)}
    except CannotCount as e:
        print(f"performance.py: SKIP: {e}; the step's instruction budget is not checked on this "
              "machine (docs/reliability.md, 'Tests that depend on the CPU')")
        return SKIP
    print(f"step() instructions per step (callgrind, {cpu_model()}): /0 consistent state "
          f"{ir[0]:.0f}, /1 printed reading {ir[1]:.0f}, ratio {ir[0] / ir[1]:.3f}; "
          f"budget /0 <= {budget}")
    ok = ir[0] <= budget and ir[0] <= ir[1]
    if not ok:
        print("performance.py: FAIL: the consistent step exceeds its budget or the printed "
              "reading's step (issue 22, item 1; docs/performance.md)")
    return 0 if ok else 1


def identify_cmd(gm: str, out: pathlib.Path, islands: int, threads: int) -> list[str]:
    return [gm, "identify", "--model", str(ROOT / "calibration/start/consistent.toml"),
            "--fit", str(ROOT / "calibration/consistent.toml"), "--out", str(out / "m.toml"),
            "--algorithm", "sade", "--islands", str(islands), "--population", "8",
            "--generations", "4", "--seed", "3", "--threads", str(threads), "--no-refine",
            "--no-profile", "--no-plots", "--quiet", "--mpi", "auto"]


def scaling_section(bindir: pathlib.Path, reps: int, work: pathlib.Path) -> str:
    gm = str(bindir / "gmasim")
    sweep = [gm, "sweep", "--temperatures", "20:10:70", "--currents", "6,8,10,12", "--periods", "2"]
    t = interleaved({f"sweep{n}": sweep + ["--threads", str(n), "--out", str(work / f"s{n}")]
                     for n in (1, 2)}, reps, work)
    ti = interleaved({f"id{n}": identify_cmd(gm, work / f"i{n}", 2, n) for n in (1, 2)}, reps, work)
    rows = [["`gmasim sweep`, 28 points, 2 periods", f"{t['sweep1']:.3g} s", f"{t['sweep2']:.3g} s",
             f"{t['sweep1'] / t['sweep2']:.2f}"],
            ["`gmasim identify`, consistent fit, 2 islands x 8 x 4 generations",
             f"{ti['id1']:.3g} s", f"{ti['id2']:.3g} s", f"{ti['id1'] / ti['id2']:.2f}"]]
    out = table(["command", "1 thread", "2 threads", "speed-up"], rows)
    mpirun = shutil.which("mpirun")
    if mpirun:
        tm = interleaved({"one": identify_cmd(gm, work / "m1", 2, 1),
                          "mpi": [mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "2"]
                          + identify_cmd(gm, work / "m2", 1, 1)}, reps, work, MPI_ENV)
        out += "\n\n" + table(
            ["`gmasim identify` (the same 2 islands)", "1 process, 1 thread", "2 MPI ranks x 1 thread",
             "speed-up"],
            [["consistent fit, 8 x 4 generations per island", f"{tm['one']:.3g} s", f"{tm['mpi']:.3g} s",
              f"{tm['one'] / tm['mpi']:.2f}"]])
    return out


def growth_section(bindir: pathlib.Path, reps: int, work: pathlib.Path) -> str:
    gm = str(bindir / "gmasim")

    def sim(model: str, periods: int, tag: str, printed: bool = False) -> list[str]:
        cmd = [gm, "simulate", "--model", str(ROOT / model), "--current-pp", "8", "--frequency", "50",
               "--periods", str(periods), "--out", str(work / tag)]
        return cmd + (["--set", "options.magnetic_state=printed"] if printed else [])

    rods = interleaved({"1": sim("models/single_rod.toml", 40, "r1"), "3": sim("models/mdma.toml", 40, "r3"),
                        "1p": sim("models/single_rod.toml", 40, "r1p", True),
                        "3p": sim("models/mdma_printed.toml", 40, "r3p")}, reps, work, cpu=True)
    per = interleaved({str(p): sim("models/mdma.toml", p, f"p{p}") for p in (10, 40, 160)}, reps, work,
                      cpu=True)
    sweep = [gm, "sweep", "--currents", "8", "--periods", "2", "--threads", "1"]
    temps = {1: "20", 4: "20:10:50", 16: "20:2:50"}
    cond = interleaved({str(n): sweep + ["--temperatures", temps[n], "--out", str(work / f"c{n}")]
                        for n in temps}, reps, work, cpu=True)
    rows = [["rods: 3 (mdma.toml) / 1 (single_rod.toml), consistent state, 40 periods at 50 Hz",
             f"{rods['1']:.3g} s", f"{rods['3']:.3g} s", f"{rods['3'] / rods['1']:.2f}"],
            ["rods: 3 (mdma_printed.toml) / 1 (single_rod.toml printed), printed reading",
             f"{rods['1p']:.3g} s", f"{rods['3p']:.3g} s", f"{rods['3p'] / rods['1p']:.2f}"],
            ["periods: 40 / 10 (mdma.toml, 50 Hz, one process each)", f"{per['10']:.3g} s",
             f"{per['40']:.3g} s", f"{per['40'] / per['10']:.2f}"],
            ["periods: 160 / 10", f"{per['10']:.3g} s", f"{per['160']:.3g} s",
             f"{per['160'] / per['10']:.2f}"],
            ["conditions: 4 / 1 sweep points (1 thread)", f"{cond['1']:.3g} s", f"{cond['4']:.3g} s",
             f"{cond['4'] / cond['1']:.2f}"],
            ["conditions: 16 / 1 sweep points", f"{cond['1']:.3g} s", f"{cond['16']:.3g} s",
             f"{cond['16'] / cond['1']:.2f}"]]
    return table(["growth (CPU time of the process)", "base (this run)", "larger (this run)", "ratio"],
                 rows)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "build/ci/bin"), help="directory of gmasim and gmasim_bench")
    ap.add_argument("--reps", type=int, default=3, help="repetitions per timing (median), >= 1")
    ap.add_argument("--sections", default="bench,numpy,scaling,growth",
                    help="comma-separated subset of bench, numpy, scaling, growth, callgrind")
    ap.add_argument("--step-budget", type=int, default=None, metavar="N",
                    help="only check: /0 <= N instructions per step and /0 <= /1 (callgrind)")
    ap.add_argument("--counter", default=None, metavar="EXE",
                    help=f"with --step-budget: count EXE 0 and EXE 1 instead of {STEP_COUNTER} (tests)")
    a = ap.parse_args()
    if a.counter is not None and a.step_budget is None:
        sys.exit("performance.py: --counter needs --step-budget")
    if a.step_budget is not None:
        if not 1000 <= a.step_budget <= 10**7:
            sys.exit(f"performance.py: --step-budget {a.step_budget}: must be in [1000, 1e7]")
        with tempfile.TemporaryDirectory(prefix="gmasim_step_budget_") as tmp:
            return step_budget_check(pathlib.Path(a.bin).resolve(), a.step_budget, pathlib.Path(tmp),
                                     pathlib.Path(a.counter) if a.counter else None)
    if not 1 <= a.reps <= 50:
        sys.exit(f"performance.py: --reps {a.reps}: must be in [1, 50]")
    bindir = pathlib.Path(a.bin).resolve()
    wanted = a.sections.split(",")
    unknown = set(wanted) - {"bench", "numpy", "scaling", "growth", "callgrind"}
    if unknown:
        sys.exit(f"performance.py: --sections: unknown {sorted(unknown)}")
    if set(wanted) & {"numpy", "scaling", "growth"} and not (bindir / "gmasim").is_file():
        sys.exit(f"performance.py: no gmasim in {bindir} (--bin)")
    print(f"# performance.py: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start, "
          f"--reps {a.reps}\n")
    with tempfile.TemporaryDirectory(prefix="gmasim_performance_") as tmp:
        work = pathlib.Path(tmp)
        for name, fn in (("bench", lambda: bench_section(bindir, a.reps)),
                         ("numpy", lambda: numpy_section(bindir, a.reps)),
                         ("scaling", lambda: scaling_section(bindir, a.reps, work)),
                         ("growth", lambda: growth_section(bindir, a.reps, work)),
                         ("callgrind", lambda: callgrind_section(bindir, a.reps, work))):
            if name in wanted:
                print(f"## {name}\n\n{fn()}\n", flush=True)
    print(f"# load average {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
