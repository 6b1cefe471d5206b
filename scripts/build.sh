#!/usr/bin/env bash
# Configure and build gmasim with a CMake preset (default: ci; override with GMASIM_PRESET).
# Prints each step's wall time (the CI's stages, docs/reliability.md).
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${GMASIM_PRESET:-ci}"

t0=$SECONDS
bash scripts/install_deps.sh
t1=$SECONDS
cmake --preset "$PRESET"
t2=$SECONDS
cmake --build --preset "$PRESET" -j2
t3=$SECONDS
echo "build.sh [$PRESET]: deps $((t1 - t0)) s, configure $((t2 - t1)) s, build $((t3 - t2)) s"
