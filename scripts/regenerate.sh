#!/usr/bin/env bash
# Regenerates everything that is written from the calibrated model, in the order the files
# depend on each other, after a change that moves the step's results (even in their last
# digits: calibration_smoke compares the start model's RMS with the committed fit report, and
# calibration_reproduces reruns every reading at the committed budget and compares its outputs).
#
#   bash scripts/regenerate.sh            # the built-in reading (consistent) and what follows
#   bash scripts/regenerate.sh --all      # every reading of calibration/readings.toml
#   bash scripts/regenerate.sh --docs     # skip the calibration: only what follows the model
#
# Steps (each prints its wall time):
#   1. build (ci preset: Release, as CI builds it)
#   2. calibration/calibrate.py consistent (or every reading with --all): writes
#      calibration/models/*, calibration/scores.csv and installs models/mdma.toml
#   3. rebuild: the built-in model is embedded in the binary at build time
#   4. calibrate.py --smoke --write-reference (calibration/reference/consistent.json)
#   5. docs/reproduction.md and docs/figures/ (the command of scripts/check_reproduction.sh)
#   6. docs/parameters.md (gmasim model params --markdown), docs/claims.md (gmasim reproduce
#      --claim-kinds)
#   7. docs/model.md's time-step table (gmasim model check --dt-table, between its markers)
#   8. the quoted numbers of docs/*.md (scripts/check_quoted_numbers.py): reported, not
#      rewritten -- a prose number is edited by hand, with the sentence around it.
# Nothing is committed; `git diff --stat` afterwards shows what moved.
set -euo pipefail
SRC="$(cd "$(dirname "$0")/.." && pwd)"
cd "$SRC"
MODE=consistent
case "${1:-}" in
  "") ;;
  --all) MODE=all ;;
  --docs) MODE=docs ;;
  *) echo "usage: bash scripts/regenerate.sh [--all | --docs]" >&2; exit 2 ;;
esac
PY=/usr/bin/python3
B="$SRC/build/ci/bin/gmasim"
stage() { echo "== $1 ($(date +%T))"; }
build() {
  local launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake --preset ci "${launcher[@]}" >/dev/null
  cmake --build build/ci -j"$(nproc)"  # every target: the C library and the tests embed the model too
}

stage "1. build"
build
if [ "$MODE" != docs ]; then
  stage "2. calibrate ($MODE)"
  if [ "$MODE" = all ]; then "$PY" calibration/calibrate.py --bin "$B"
  else "$PY" calibration/calibrate.py --bin "$B" consistent; fi
  stage "3. rebuild (the embedded built-in model)"
  build
  stage "4. smoke reference"
  "$PY" calibration/calibrate.py --bin "$B" --smoke --write-reference
fi

stage "5. docs/reproduction.md and figures"
bash scripts/check_reproduction.sh --write "$B"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT

stage "6. docs/parameters.md"
"$B" model params --markdown >docs/parameters.md.tmp
mv docs/parameters.md.tmp docs/parameters.md
"$B" reproduce --claim-kinds >docs/claims.md.tmp
mv docs/claims.md.tmp docs/claims.md

stage "7. docs/model.md time-step table"
"$B" model check --dt-table >"$T/dt.txt"
"$PY" - "$T/dt.txt" <<'EOF'
import pathlib, sys
doc = pathlib.Path("docs/model.md")
text = doc.read_text()
a, b = "<!-- dt-table: gmasim model check --dt-table -->\n", "<!-- end dt-table -->"
i, j = text.index(a) + len(a), text.index(b)
table = pathlib.Path(sys.argv[1]).read_text()
if not table.endswith("\n"):
    table += "\n"
tmp = doc.with_name(doc.name + ".tmp")
tmp.write_text(text[:i] + table + text[j:])
tmp.replace(doc)
EOF

stage "8. quoted numbers in docs/ (edit the ones listed by hand)"
"$PY" scripts/check_quoted_numbers.py --gmasim "$B" docs || true
stage "done"
git status --short
