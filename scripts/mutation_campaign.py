#!/usr/bin/python3
"""A mutation campaign against the gmasim CLI (issue 8, docs/reliability.md).

    /usr/bin/python3 scripts/mutation_campaign.py --runs 5000 --out out/mutation
    /usr/bin/python3 scripts/mutation_campaign.py --bin build/sanitize/bin/gmasim --runs 500

Each run mutates one input (the model file, a waveform CSV, a measurement CSV, a manifest, a
fit spec, a checkpoint, or the command-line flags) from a valid seed, runs gmasim on it
with a time limit, and classifies the outcome:

    crash     killed by a signal, exit >= 128, exit 4 (internal error), or a sanitizer report
    hang      the time limit was reached
    nonsense  exit 0, but an output file or the summary holds NaN or Inf
    unclear   exit 1 or 2 whose message names no file:line, flag or key, or states no rule
    ok        exit 0 with finite outputs, or a clear refusal (1, 2), or a diagnosed divergence (3)

Issue 19 added six hostile classes (scripts/mutation_hostile.py, judged by the issue's rules:
outputs equal to inputs, tiny and denormal steps, absurd but finite physics, concurrent runs on
one output, signals during writes, resource limits); `--classes issue19` runs only those.

It writes OUT/campaign.csv (one row per run), OUT/summary.json, and keeps the inputs of every
finding under OUT/findings/. Exit 0 if there are no crashes, hangs or nonsense. Standard
library only; deterministic for a given --seed.
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import csv
import json
import os
import pathlib
import random
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import mutation_hostile as hostile  # noqa: E402

HOSTILE_NUMBERS = ["nan", "NaN", "inf", "-inf", "1e300", "-1e300", "1e-300", "1e-320", "0", "-0",
                   "-1", "2e9", "9223372036854775808", "1e18", "+-1", "0x10", "1e", "", "  ",
                   "abc", "1,5", "3.4e38", "-3.4e38", "4.9e-324", "1" * 400]
HOSTILE_TEXT = ["\x00", "\xce\xa0", "[[[1]]]", "[&", "[[=", "\"", "'''", "#", "=", "\n\n",
                "\r", "\ufeff", "[", "]", "{", "}", "\t", "\\"]


def seeds(work: pathlib.Path, bin_: str) -> dict[str, str]:
    """Valid seed inputs, created once."""
    s = {"model": (ROOT / "models" / "mdma.toml").read_text()}
    s["waveform"] = "t_s,current_A\n0,-3\n0.005,5\n0.01,-3\n0.015,5\n0.02,-3\n"
    lines = ["# temperature_C = 20", "# frequency_Hz = 100", "# current_pp_A = 8",
             "t_s,current_A,displacement_um"]
    for k in range(41):
        t = k * 0.0005
        lines.append(f"{t:.4f},{-3 + 4 * (1 - __import__('math').cos(6.283185307 * 100 * t)):.6f},"
                     f"{20 + 10 * __import__('math').sin(6.283185307 * 100 * t):.6f}")
    s["measurement"] = "\n".join(lines) + "\n"
    s["manifest"] = '[[measurement]]\nfile = "meas.csv"\nweight = 1.0\n'
    s["fit"] = ('[[parameter]]\nname = "material.lambda_s"\nlower = 0.8e-3\nupper = 1.2e-3\n\n'
                '[[target]]\nkind = "stroke_change_pct"\ntemperature_C = 70.0\ncurrent_pp_A = 8.0\n'
                'frequency_Hz = 10.0\nvalue = -12.6\n\n'
                '[[target]]\nkind = "hysteresis_change_pct"\ntemperature_C = 70.0\n'
                'current_pp_A = 8.0\nfrequency_Hz = 10.0\nvalue = -27.6\n')
    (work / "fit.toml").write_text(s["fit"])
    subprocess.run([bin_, *IDENTIFY, "--fit", "fit.toml", "--out", "m.toml", "--generations", "2",
                    "--checkpoint", "ck.txt", "--checkpoint-every", "1"],
                   cwd=work, capture_output=True, timeout=300, check=True)
    s["checkpoint"] = (work / "ck.txt").read_text()
    return s


IDENTIFY = ["identify", "--islands", "1", "--population", "8", "--migrate-every", "1", "--no-refine",
            "--no-plots", "--quiet", "--steps-per-period", "100", "--threads", "1"]

NUM = re.compile(r"(?<![A-Za-z_])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def mutate_text(text: str, rng: random.Random) -> str:
    """One to three mutations: a number replaced by a hostile one, a line deleted, duplicated or
    swapped, hostile text inserted, bytes flipped, or the text truncated."""
    for _ in range(rng.randint(1, 3)):
        op = rng.random()
        lines = text.split("\n")
        if op < 0.45:
            nums = list(NUM.finditer(text))
            if nums:
                m = rng.choice(nums)
                text = text[:m.start()] + rng.choice(HOSTILE_NUMBERS) + text[m.end():]
        elif op < 0.55 and lines:
            del lines[rng.randrange(len(lines))]
            text = "\n".join(lines)
        elif op < 0.63 and lines:
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
            text = "\n".join(lines)
        elif op < 0.70 and len(lines) > 1:
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            text = "\n".join(lines)
        elif op < 0.85:
            i = rng.randrange(len(text) + 1)
            text = text[:i] + rng.choice(HOSTILE_TEXT) + text[i:]
        elif op < 0.95 and text:
            b = bytearray(text.encode("utf-8", "surrogateescape"))
            for _ in range(rng.randint(1, 4)):
                b[rng.randrange(len(b))] = rng.randrange(256)
            text = b.decode("utf-8", "surrogateescape")
        elif text:
            text = text[:rng.randrange(len(text))]
    return text


CLI_CASES = [
    ("simulate", ["--temperature", "--current-pp", "--current-min", "--frequency", "--periods", "--dt",
                  "--record-every", "--level", "--step-to", "--step-time", "--f0", "--f1", "--amplitude",
                  "--offset", "--duration"], ["--periods", "1", "--frequency", "100"]),
    ("sweep", ["--temperatures", "--currents", "--frequencies", "--periods", "--dt", "--current-min"],
     ["--temperatures", "20", "--currents", "6", "--frequencies", "100", "--periods", "1"]),
    ("frf", ["--temperatures", "--points", "--f-min", "--f-max", "--bias", "--amplitude",
             "--settle-periods", "--measure-periods", "--threads"], ["--temperatures", "20", "--points", "3",
                                                        "--method", "linear"]),
    ("track", ["--temperatures", "--amplitudes", "--frequencies", "--sample-rate", "--current-limit",
               "--bias", "--periods", "--sensor-noise", "--kp", "--ki", "--kd", "--gain-rate"], ["--temperatures", "20", "--amplitudes", "10",
                                                   "--frequencies", "10", "--periods", "1"]),
    # issue 9: self-heating, compensation and --set take the same hostile values.
    ("simulate", ["--thermal-step", "--ambient", "--periods", "--frequency", "--dt", "--set"],
     ["--periods", "2", "--frequency", "100", "--self-heating"]),
    ("compensate", ["--temperatures", "--reference-temperature", "--reference-current-pp", "--current-min",
                    "--target-stroke", "--frequency", "--periods", "--max-current", "--tolerance", "--dt",
                    "--set"], ["--temperatures", "20,70", "--periods", "1", "--frequency", "100", "--no-track"]),
]


def case(kind: str, rng: random.Random, s: dict, d: pathlib.Path) -> tuple[list[str], str]:
    """The command of one run in directory d, and the mutated file's name ('' for flags)."""
    if kind == "model":
        (d / "model.toml").write_text(mutate_text(s["model"], rng), errors="surrogateescape")
        if rng.random() < 0.3:
            return ["model", "check", "model.toml"], "model.toml"
        return ["simulate", "--model", "model.toml", "--periods", "1", "--frequency", "100",
                "--out", "o"], "model.toml"
    if kind == "waveform":
        (d / "w.csv").write_text(mutate_text(s["waveform"], rng), errors="surrogateescape")
        return ["simulate", "--waveform", "w.csv", "--out", "o"], "w.csv"
    if kind == "measurement":
        (d / "meas.csv").write_text(mutate_text(s["measurement"], rng), errors="surrogateescape")
        (d / "manifest.toml").write_text(s["manifest"])
        return [*IDENTIFY, "--data", "manifest.toml", "--fit", "material.lambda_s:0.8e-3:1.2e-3",
                "--generations", "1", "--out", "m.toml"], "meas.csv"
    if kind == "manifest":
        (d / "meas.csv").write_text(s["measurement"])
        (d / "manifest.toml").write_text(mutate_text(s["manifest"], rng), errors="surrogateescape")
        return [*IDENTIFY, "--data", "manifest.toml", "--fit", "material.lambda_s:0.8e-3:1.2e-3",
                "--generations", "1", "--out", "m.toml"], "manifest.toml"
    if kind == "fit":
        (d / "fit.toml").write_text(mutate_text(s["fit"], rng), errors="surrogateescape")
        return [*IDENTIFY, "--fit", "fit.toml", "--generations", "1", "--out", "m.toml"], "fit.toml"
    if kind == "checkpoint":
        (d / "fit.toml").write_text(s["fit"])
        (d / "ck.txt").write_text(mutate_text(s["checkpoint"], rng), errors="surrogateescape")
        return [*IDENTIFY, "--fit", "fit.toml", "--generations", "3", "--out", "m.toml",
                "--resume", "ck.txt"], "ck.txt"
    # flags
    sub, flags, base = rng.choice(CLI_CASES)
    args = list(base)
    flag = rng.choice(flags)
    value = rng.choice(HOSTILE_NUMBERS)
    if flag == "--set":  # a hostile value for a real parameter (or option)
        value = rng.choice(["material.Ms_A_per_m", "rod1.length_m", "rod2.ja.k0_A_per_m", "preload.force_N",
                            "thermal_network.coil_heat_capacity_J_per_K", "thermal_network.coil_resistance_ohm",
                            "options.magnetic_state"]) + "=" + value
    if flag in args:
        args[args.index(flag) + 1] = value
    else:
        args += [flag, value]
    if sub == "simulate" and flag in ("--level", "--step-to", "--step-time", "--f0", "--f1",
                                      "--amplitude", "--offset"):
        # A sine's flags would contradict the step or chirp (a usage error since issue 19).
        kind = "step" if flag in ("--level", "--step-to", "--step-time") else "chirp"
        args = [flag, value, "--waveform-kind", kind, "--duration", "0.01"]
        if kind == "step" and flag != "--step-time":  # a step inside the run (0 never steps)
            args += ["--step-time", "0.002"]
    return [sub, *args, "--out", "o"], ""


NONFINITE = re.compile(rb"(?<![A-Za-z_])[-+]?(?:nan|inf)(?![A-Za-z_])", re.IGNORECASE)


def classify(rc: int | None, out: str, err: str, d: pathlib.Path, mutated: str,
             cmd: list[str]) -> tuple[str, str]:
    if rc is None:
        return "hang", "time limit"
    text = out + err
    if rc < 0 or rc >= 128 or rc == 4 or "AddressSanitizer" in text or "runtime error:" in text \
            or "LeakSanitizer" in text:
        return "crash", (err.strip().splitlines() or [f"exit {rc}"])[-1][:200]
    if rc == 0:
        for p in d.rglob("*"):
            if p.is_file() and p.suffix in (".csv", ".json") and p.name not in (mutated, "meas.csv"):
                data = p.read_bytes()
                # JSON "null" is the writer's non-finite marker; the literal tokens are not.
                if NONFINITE.search(data):
                    return "nonsense", f"non-finite value in {p.relative_to(d)}"
        if NONFINITE.search(out.encode()) and "simulate" in cmd:
            return "nonsense", "non-finite value in the summary"
        return "ok", "accepted"
    if rc == 3:  # a divergence must name its time (and rod, quantity) on stderr
        return ("ok", "diverged") if "diverged at t =" in err else ("unclear", err.strip()[:200])
    if rc in (1, 2):  # the issue-19 test: names a file:line, flag or key, and states a rule
        msg = err.strip()
        clear = hostile.clear_message(err)
        return ("ok", "refused") if clear else ("unclear", msg[:200])
    return "unclear", f"exit {rc}: {err.strip()[:200]}"


def one(i: int, kind: str, seed: int, s: dict, bin_: str, timeout: float, keep: pathlib.Path,
        py_env: dict):
    rng = random.Random(seed * 1_000_003 + i)
    with tempfile.TemporaryDirectory(prefix="gmasim_mut_") as tmp:
        d = pathlib.Path(tmp)
        rc, err = "", ""
        if kind in hostile.KINDS:
            verdict, why, cmd = hostile.run_case(kind, rng, s, bin_, d, timeout, py_env)
        else:
            cmd, mutated = case(kind, rng, s, d)
            try:
                p = subprocess.run([bin_, *cmd], cwd=d, capture_output=True, timeout=timeout)
                rc, out, err = p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
            except subprocess.TimeoutExpired:
                rc, out, err = None, "", ""
            verdict, why = classify(rc, out, err, d, mutated, cmd)
        if verdict != "ok":
            dest = keep / f"{i:05d}_{kind}_{verdict}"
            shutil.copytree(d, dest, dirs_exist_ok=True)
            (dest / "command.txt").write_text(" ".join(cmd) + f"\nexit {rc}\n{err[-4000:]}")
        return {"run": i, "kind": kind, "verdict": verdict, "exit": "" if rc is None else rc,
                "why": why.replace("\n", " "), "command": " ".join(cmd)[:300]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "build/ci/bin/gmasim"))
    ap.add_argument("--runs", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per run")
    ap.add_argument("--out", default=str(ROOT / "out/mutation"))
    ap.add_argument("--classes", choices=["all", "mutation", "issue19"], default="all",
                    help="the mutation classes of issue 8, the hostile classes of issue 19, or both")
    a = ap.parse_args(argv)
    if not 1 <= a.runs <= 10_000_000 or not 1 <= a.jobs <= 256 or not 0 < a.timeout <= 3600:
        print("mutation_campaign.py: --runs 1..1e7, --jobs 1..256, --timeout (0, 3600] s", file=sys.stderr)
        return 1
    out = pathlib.Path(a.out).resolve()
    if out.exists():
        shutil.rmtree(out)
    keep = out / "findings"
    keep.mkdir(parents=True)
    # A private copy: a rebuild during the campaign must not change (or lock) the binary.
    bin_ = str(out / "gmasim")
    shutil.copy2(pathlib.Path(a.bin).resolve(), bin_)
    with tempfile.TemporaryDirectory(prefix="gmasim_seed_") as tmp:
        s = seeds(pathlib.Path(tmp), bin_)
    kinds = []
    if a.classes != "issue19":
        kinds += ["model"] * 30 + ["waveform"] * 15 + ["measurement"] * 10 + ["manifest"] * 8 + \
            ["fit"] * 10 + ["checkpoint"] * 10 + ["flags"] * 17
    if a.classes != "mutation":
        kinds += ["same_file"] * 10 + ["tiny_step"] * 10 + ["absurd_physics"] * 10 + \
            ["concurrent"] * 5 + ["signal"] * 5 + ["rlimit"] * 5
    py_env = dict(os.environ, PYTHONPATH=str(pathlib.Path(a.bin).resolve().parent.parent / "python"))
    plan = [(i, random.Random(a.seed * 7919 + i).choice(kinds)) for i in range(a.runs)]
    rows = []
    with cf.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futs = [ex.submit(one, i, k, a.seed, s, bin_, a.timeout, keep, py_env) for i, k in plan]
        for n, f in enumerate(cf.as_completed(futs), 1):
            rows.append(f.result())
            if n % 250 == 0:
                print(f"{n}/{a.runs}", file=sys.stderr, flush=True)
    rows.sort(key=lambda r: r["run"])
    with open(out / "campaign.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    summary = {"runs": len(rows), "binary": bin_, "seed": a.seed}
    for v in ("ok", "crash", "hang", "nonsense", "unclear"):
        summary[v] = sum(r["verdict"] == v for r in rows)
    summary["by_kind"] = {k: {v: sum(r["verdict"] == v for r in rows if r["kind"] == k)
                              for v in ("ok", "crash", "hang", "nonsense", "unclear")}
                          for k in sorted({k for _, k in plan})}
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps({k: summary[k] for k in ("runs", "ok", "crash", "hang", "nonsense", "unclear")}))
    return 0 if summary["crash"] == summary["hang"] == summary["nonsense"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
