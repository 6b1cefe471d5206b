#!/usr/bin/env bash
# Install dependencies, build, and run the full test suite (C++ + Python) via ctest.
#   bash scripts/test.sh             the CI preset (Release, -Werror)
#   bash scripts/test.sh --sanitize  the same suite built with ASan + UBSan (preset sanitize)
#   bash scripts/test.sh --sanitize-native  the C++ and CLI suites under ASan + UBSan, without
#                                    the Python module (preset sanitize-native; the CI job)
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${GMASIM_PRESET:-ci}"
for arg in "$@"; do
  case "$arg" in
    --sanitize) PRESET=sanitize ;;
    --sanitize-native) PRESET=sanitize-native ;;
    *) echo "scripts/test.sh: unknown option $arg (expected --sanitize or --sanitize-native)" >&2; exit 1 ;;
  esac
done

GMASIM_PRESET="$PRESET" bash scripts/build.sh

ctest --preset "$PRESET" --output-on-failure -j2
