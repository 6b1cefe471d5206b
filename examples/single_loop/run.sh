#!/usr/bin/env bash
# One measured loop, 8 free parameters (docs/identify.md, "One measured loop: budget and
# degeneracies"): a strain-vs-field butterfly of one rod, as a lab publishes it (quasi-static,
# field in kA/m, the gauge's zero unknown, started at the negative remanence the previous
# cycle left), made from the single-rod template (the truth) with 0.5 % noise, then
# identified with gmasim identify's default search from starts 10-40 % off.
# Usage: examples/single_loop/run.sh [OUT_DIR]   (GMASIM: the binary; SEED, NOISE_SEED and
# any extra identify flags in IDENTIFY_FLAGS)
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
SRC="$(cd "$HERE/../.." && pwd)"
GMASIM="${GMASIM:-$SRC/build/ci/bin/gmasim}"
OUT="${1:-$SRC/out/single_loop}"
mkdir -p "$OUT"
"$GMASIM" identify synthesize --model "$SRC/models/single_rod.toml" --out "$OUT/data" \
  --temperatures 20 --currents 12 --current-min -6 --quasi-static --drive field \
  --response strain --offset fitted --response-offset 40 --initial-state negative_remanence \
  --periods 1 --samples-per-period 100 --no-flux --noise 0.5 --seed "${NOISE_SEED:-5}" > /dev/null
# The field as a lab gives it: in kA/m (the column says so).
for f in "$OUT"/data/*.csv; do
  awk -F, 'BEGIN{OFS=","} /^#/ {print; next} $1=="field_A_per_m" {$1="field_kA_per_m"; print; next}
           {$1=sprintf("%.12g", $1/1000); print}' "$f" > "$f.tmp" && mv "$f.tmp" "$f"
done
# shellcheck disable=SC2086
"$GMASIM" identify --model "$SRC/models/single_rod.toml" --data "$OUT/data/manifest.toml" \
  --fit "$HERE/fit8.toml" --out "$OUT/fitted.toml" --seed "${SEED:-1}" --no-plots \
  ${IDENTIFY_FLAGS:-}
