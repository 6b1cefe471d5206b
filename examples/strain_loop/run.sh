#!/usr/bin/env bash
# The worked example of docs/data.md: identify the Jiles-Atherton constants and lambda_s of
# one Terfenol-D rod from its strain-vs-field loop (data/, made by make_data.sh), starting
# from the single-rod template, then check the result against the rod's truth (truth.toml):
# fit RMS <= 0.7 % (the data carry 0.5 % noise) and every constant within 2 % of the truth
# or inside its own 95 % confidence interval.
# Usage: examples/strain_loop/run.sh [OUT_DIR]   (GMASIM: the binary; about 10 s)
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
SRC="$(cd "$HERE/../.." && pwd)"
GMASIM="${GMASIM:-$SRC/build/ci/bin/gmasim}"
OUT="${1:-$SRC/out/strain_loop}"
mkdir -p "$OUT"
"$GMASIM" identify --model "$SRC/models/single_rod.toml" --data "$HERE/data/manifest.toml" \
  --fit "$HERE/fit.toml" --out "$OUT/fitted.toml" --islands 2 --population 16 \
  --generations 12 --seed 3 ${NO_PLOTS:+--no-plots}
echo
echo "Check against the truth (truth.toml):"
/usr/bin/python3 "$SRC/tests/cli/check_identify.py" "$OUT/fitted_report/fit_report.json" \
  --gmasim "$GMASIM" --truth-model "$HERE/truth.toml" --max-rms 0.7
echo "Report: $OUT/fitted_report/fit_report.md; figure: $OUT/fitted_report/overlay_T20_I12_qs.png"
