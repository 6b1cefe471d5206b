#!/usr/bin/env bash
# Regenerates docs/reproduction.md into a temporary directory with the command that wrote it
# (the built-in model, the failing-claim notes, the readings compared) and checks it is
# identical to the committed file apart from the wall-time sentence. Exit 0 if identical;
# 1 with the diff otherwise. Used by ctest (reproduction_doc_unchanged) and by refactors
# that must keep every result bit-identical (issue 10).
# Usage: scripts/check_reproduction.sh [--write] [path to gmasim]   (default build/ci/bin/gmasim)
#   --write: rewrite docs/reproduction.md and its figures instead (scripts/regenerate.sh)
set -euo pipefail
SRC="$(cd "$(dirname "$0")/.." && pwd)"
WRITE=0
if [ "${1:-}" = --write ]; then WRITE=1; shift; fi
B="${1:-$SRC/build/ci/bin/gmasim}"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
cd "$SRC"
CMP=(models/mdma_printed.toml)
# The consistent reading (the built-in model) beside its structural readings (issue 37), then
# the printed magnetic state's readings.
for r in consistent consistent__classical_eddy consistent__no_joint_gaps \
         consistent__classical_eddy__no_joint_gaps consistent__mount_on_output consistent__bonded_joints \
         printed__kelvin__compression_negative printed__kelvin__compression_positive \
         printed__room_referenced__compression_negative printed__room_referenced__compression_positive \
         mean_field__room_referenced__compression_negative mean_field__room_referenced__compression_positive; do
  CMP+=("calibration/models/$r.toml")
done
DOC="$T/doc/reproduction.md"
[ "$WRITE" = 1 ] && DOC=docs/reproduction.md
mkdir -p "$T/doc"
"$B" reproduce --out "$T/out" --doc "$DOC" --doc-notes docs/failing_claims.md \
  --compare "${CMP[@]}" >"$T/log" 2>&1 || { cat "$T/log"; exit 1; }
if [ "$WRITE" = 1 ]; then echo "wrote docs/reproduction.md"; exit 0; fi
strip() { sed -E 's/The whole study took [0-9.]+ s/The whole study took N s/' "$1"; }
if diff <(strip docs/reproduction.md) <(strip "$T/doc/reproduction.md"); then
  echo "docs/reproduction.md: identical (apart from the wall time)"
else
  echo "docs/reproduction.md differs from a fresh run (above: < committed, > fresh)"
  exit 1
fi
