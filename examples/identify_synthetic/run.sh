#!/usr/bin/env bash
# The synthetic validation of gmasim identify (issue 4, item 6; docs/identify.md):
#   1. measurements from the built-in model at 12 conditions (20/45/70 degC x 6/8 A x
#      10/100 Hz), 2 periods of 200 samples, 1 % Gaussian noise (of each condition's p-p);
#   2. 8 parameters started 8-30 % off (fit.toml), identified by the multi-island GA and
#      Levenberg-Marquardt, with checkpoints;
#   3. checked: fit RMS <= 1.5 % and every parameter within 2 % of the truth or within its
#      own 95 % confidence interval; the fit report shows which the data determine.
# Usage: examples/identify_synthetic/run.sh [OUT_DIR]
# Environment: GMASIM (binary), NP (MPI ranks, default 1), SEED (noise seed, default 2),
#   STEPS (time steps per period, default 500), ISLANDS, POPULATION, GENERATIONS.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
SRC="$(cd "$HERE/../.." && pwd)"
GMASIM="${GMASIM:-$SRC/build/ci/bin/gmasim}"
OUT="${1:-$SRC/out/identify_synthetic}"
NP="${NP:-1}"
SEED="${SEED:-2}"
STEPS="${STEPS:-500}"
mkdir -p "$OUT"

"$GMASIM" identify synthesize --out "$OUT/data" --steps-per-period "$STEPS" \
  --samples-per-period 200 --periods 2 --noise 1 --flux-noise 1 --seed "$SEED"

ARGS=(identify --data "$OUT/data/manifest.toml" --fit "$HERE/fit.toml"
      --out "$OUT/fitted.toml" --steps-per-period "$STEPS"
      --islands "${ISLANDS:-4}" --population "${POPULATION:-24}"
      --generations "${GENERATIONS:-40}" --migrate-every 5
      --checkpoint "$OUT/checkpoint.txt" --checkpoint-every 10)
if [[ "$NP" -gt 1 ]]; then
  export OMPI_MCA_btl_vader_single_copy_mechanism=none
  mpiexec -np "$NP" --oversubscribe "$GMASIM" "${ARGS[@]}"
else
  "$GMASIM" "${ARGS[@]}"
fi

echo
echo "Check against the truth (the built-in model):"
/usr/bin/python3 "$SRC/tests/cli/check_identify.py" "$OUT/fitted_report/fit_report.json" \
  --gmasim "$GMASIM" --max-rms 1.5
echo "Report: $OUT/fitted_report/fit_report.md; plots: $OUT/fitted_report/*.png"
