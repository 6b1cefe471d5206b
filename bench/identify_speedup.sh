#!/usr/bin/env bash
# Speed-up of the GA phase of gmasim identify (issue 4, item 8): evaluations per second of the
# 12-condition synthetic case with 1 island on 1 process, 2 islands (2 threads) on 1 process,
# and 1 island on each of 2 MPI ranks. No refinement; the same population and generations.
# Usage: bench/identify_speedup.sh [GMASIM_BINARY]   (default build/ci/bin/gmasim)
set -euo pipefail
SRC="$(cd "$(dirname "$0")/.." && pwd)"
GMASIM="$(realpath "${1:-$SRC/build/ci/bin/gmasim}")"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$GMASIM" identify synthesize --out data --steps-per-period 200 --samples-per-period 100 >/dev/null
ARGS=(identify --data data/manifest.toml --fit "$SRC/examples/identify_synthetic/fit.toml"
      --steps-per-period 200 --population 16 --generations 60 --no-refine --no-profile --no-plots --quiet)
"$GMASIM" "${ARGS[@]}" --islands 1 --out one/model.toml
"$GMASIM" "${ARGS[@]}" --islands 2 --out two/model.toml
mpiexec -np 2 --oversubscribe "$GMASIM" "${ARGS[@]}" --islands 1 --out mpi/model.toml
/usr/bin/python3 - "$(nproc)" <<'PY'
import json, sys
runs = [("1 process,  1 island  ", "one"), ("1 process,  2 islands ", "two"),
        ("2 MPI ranks x 1 island", "mpi")]
base = None
print(f"GA evaluations/s (12-condition objective, 200 steps/period, {sys.argv[1]} cores):")
for label, d in runs:
    r = json.load(open(f"{d}/model_report/fit_report.json"))
    rate = r["ga_evals_per_s"]
    base = base or rate
    print(f"  {label}: {rate:8.1f} evals/s ({r['evaluations']} evaluations)  speed-up {rate / base:.2f}")
PY
