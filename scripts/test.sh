#!/usr/bin/env bash
# Install dependencies, build, and run the full test suite (C++ + Python) via ctest.
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${GMASIM_PRESET:-ci}"

bash scripts/build.sh

ctest --preset "$PRESET" --output-on-failure -j2
