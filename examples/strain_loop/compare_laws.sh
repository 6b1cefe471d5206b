#!/usr/bin/env bash
# Issue 21, item 2: Jiles-Atherton and Preisach fitted to the worked example's loop (data/,
# a synthetic loop of a JA rod: truth.toml; no public measured Terfenol-D loop was found, see
# docs/data.md), then both judged on minor loops held out of the fit (made from the truth
# like data/), with the loops' shape (width vs strain, knee) beside the data's.
# Usage: examples/strain_loop/compare_laws.sh [OUT_DIR]   (GMASIM: the binary; REUSE_FITS=1
# keeps the fitted models already in OUT_DIR)
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
SRC="$(cd "$HERE/../.." && pwd)"
GMASIM="${GMASIM:-$SRC/build/ci/bin/gmasim}"
OUT="${1:-$SRC/out/compare_laws}"
PY=/usr/bin/python3
mkdir -p "$OUT"
# Held-out minor loops: 0..6 A and -6..0 A of the same rod, quasi-static, 0.5 % noise.
for spec in "6 0 heldout_up" "6 -6 heldout_down"; do
  set -- $spec
  "$GMASIM" identify synthesize --model "$HERE/truth.toml" --out "$OUT/$3" \
    --temperatures 20 --currents "$1" --current-min "$2" --quasi-static --drive field \
    --response strain --offset first_sample --precycles 2 --periods 1 \
    --samples-per-period 120 --no-flux --noise 0.5 --seed 11 >/dev/null
done
fit() {  # law model fitspec
  # REUSE_FITS=1: keep a fitted model already in OUT (to rerun the judging alone).
  if [[ -n "${REUSE_FITS:-}" && -f "$OUT/$1.toml" ]]; then echo "$1: fit reused"; return; fi
  # CPU time beside the wall time: on a shared machine the wall time measures the load.
  local TIMEFORMAT="$1: fit %R s wall, %U s user + %S s sys CPU"
  time "$GMASIM" identify --model "$2" --data "$HERE/data/manifest.toml" --fit "$3" \
    --out "$OUT/$1.toml" --islands 2 --population 16 --generations 12 --seed 3 --no-plots \
    --quiet 2>&1
}
fit ja "$SRC/models/single_rod.toml" "$HERE/fit.toml"
fit preisach "$SRC/models/single_rod_preisach.toml" "$HERE/fit_preisach.toml"
# A fit spec that moves nothing (lambda_s within 1e-9 of itself): its start RMS is the fitted
# model's RMS on the held-out loops.
for law in ja preisach; do
  lam=$($PY -c "import tomllib; print(repr(tomllib.load(open('$OUT/$law.toml', 'rb'))['material']['lambda_s']))")
  printf '[[parameter]]\nname = "material.lambda_s"\nlower = %s\nupper = %s\n' \
    "$($PY -c "print($lam * (1 - 1e-9))")" "$($PY -c "print($lam * (1 + 1e-9))")" \
    >"$OUT/hold_$law.toml"
  for h in heldout_up heldout_down; do
    "$GMASIM" identify --model "$OUT/$law.toml" --data "$OUT/$h/manifest.toml" \
      --fit "$OUT/hold_$law.toml" --out "$OUT/${law}_$h.toml" --islands 1 --population 8 \
      --generations 1 --no-refine --no-profile --no-plots --quiet
    $PY -c "import json; r = json.load(open('$OUT/${law}_${h}_report/fit_report.json')); \
print('$law on $h: RMS %.3f %%' % r['start_rms_pct'])"
  done
  # The fitted model's own loops (noise-free), for their shape.
  for spec in "12 -6 major" "6 0 heldout_up" "6 -6 heldout_down"; do
    set -- $spec
    "$GMASIM" identify synthesize --model "$OUT/$law.toml" --out "$OUT/shape_${law}_$3" \
      --temperatures 20 --currents "$1" --current-min "$2" --quasi-static --drive field \
      --response strain --offset first_sample --precycles 2 --periods 1 \
      --samples-per-period 120 --no-flux --noise 0 --seed 1 >/dev/null
  done
done
for law in ja preisach; do
  $PY -c "import json; r = json.load(open('$OUT/${law}_report/fit_report.json')); \
print('$law fit: RMS %.3f %% (start %.3f %%), %d evaluations' % (r['rms_pct'], \
r['start_rms_pct'], r['evaluations']))"
done
$PY "$HERE/loop_shape.py" "$HERE/data/"*.csv "$OUT"/heldout_*/*.csv "$OUT"/shape_*/*.csv
