#!/usr/bin/env bash
# Configure and build gmasim with a CMake preset (default: ci; override with GMASIM_PRESET).
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${GMASIM_PRESET:-ci}"

bash scripts/install_deps.sh

cmake --preset "$PRESET"
cmake --build --preset "$PRESET" -j2
