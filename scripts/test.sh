#!/usr/bin/env bash
# Install dependencies, build, and run the full test suite (C++ + Python) via ctest.
#   bash scripts/test.sh             the CI preset (Release, -Werror)
#   bash scripts/test.sh --sanitize  the same suite built with ASan + UBSan (preset sanitize)
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${GMASIM_PRESET:-ci}"
for arg in "$@"; do
  case "$arg" in
    --sanitize) PRESET=sanitize ;;
    *) echo "scripts/test.sh: unknown option $arg (expected --sanitize)" >&2; exit 1 ;;
  esac
done

GMASIM_PRESET="$PRESET" bash scripts/build.sh

ctest --preset "$PRESET" --output-on-failure -j2
