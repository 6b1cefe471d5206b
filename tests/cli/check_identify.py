#!/usr/bin/env python3
"""Checks a gmasim identify fit report (fit_report.json) of the synthetic case: the fit RMS,
and every fitted parameter within 2 % of its true value (the start model's value, read with
`gmasim model show`) or within its own 95 % confidence interval."""
import argparse
import json
import subprocess
import sys

ap = argparse.ArgumentParser()
ap.add_argument("report")
ap.add_argument("--gmasim", required=True)
ap.add_argument("--truth-model", default="", help="model file of the truth (default built-in)")
ap.add_argument("--max-rms", type=float, default=1.5)
ap.add_argument("--ranks", type=int, default=0)
ap.add_argument("--not-worse-than", type=float, default=None)
ap.add_argument("--resumed", action="store_true")
ap.add_argument("--interrupted", action="store_true")
ap.add_argument("--skip-params", action="store_true", help="do not check the parameters")
a = ap.parse_args()

rep = json.load(open(a.report))
cmd = [a.gmasim, "model", "show"] + (["--model", a.truth_model] if a.truth_model else [])
truth = {}
for line in subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.splitlines()[2:]:
    f = line.split()
    if len(f) >= 2:
        try:
            truth[f[0]] = float(f[1])
        except ValueError:
            pass

bad = []
print(f'fit RMS {rep["rms_pct"]:.4f} % (start {rep["start_rms_pct"]:.3f} %), '
      f'{rep["algorithm"]["ranks"]} rank(s), {rep["evaluations"]} evaluations, {rep["wall_s"]:.1f} s')
if rep["rms_pct"] > a.max_rms:
    bad.append(f'fit RMS {rep["rms_pct"]} % > {a.max_rms} %')
if a.ranks and rep["algorithm"]["ranks"] != a.ranks:
    bad.append(f'ranks {rep["algorithm"]["ranks"]} != {a.ranks}')
if a.not_worse_than is not None and rep["rms_pct"] > a.not_worse_than * (1 + 1e-12):
    bad.append(f'final RMS {rep["rms_pct"]} % is worse than {a.not_worse_than} %')
if a.resumed and not rep["resumed"]:
    bad.append("the run was not resumed")
if a.interrupted != rep["interrupted"]:
    bad.append(f'interrupted = {rep["interrupted"]}, expected {a.interrupted}')
for p in rep["parameters"]:
    t = truth[p["name"]]
    v = p["value"]
    lo, hi = p["ci95"]
    lo = float("-inf") if lo is None else lo
    hi = float("inf") if hi is None else hi
    ok = abs(v - t) <= 0.02 * abs(t) or lo <= t <= hi
    print(f'  {p["name"]:<26} truth {t:<10.6g} fitted {v:<12.6g} CI [{lo:.6g}, {hi:.6g}]'
          f'{"" if ok else "  <-- outside"}')
    if not (a.interrupted or a.skip_params) and not ok:
        bad.append(f'{p["name"]}: {v} is neither within 2 % of {t} nor in its 95 % CI')
for b in bad:
    print("FAIL:", b)
sys.exit(1 if bad else 0)
