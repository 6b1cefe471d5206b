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
# The machine and the SIMD target the lanes chose on it (run-time dispatch; the sanitizer
# presets compile fewer targets), so that a failure can be tied to a machine (issue 36).
bash scripts/cpu_info.sh
"build/$PRESET/bin/gmasim" --version | sed "s/^/test.sh [$PRESET]: /"

# A fresh build directory has no test timings, so ctest would start the long tests (the CLI
# scripts, pytest, the reproduction check) last and leave one core idle at the end. Seed the
# timings of a clean-clone run (tests/ctest_costs/<preset>.txt, CTest's own format): the long
# tests start first. A test missing from the file just has no cost; a later run's own timings
# (the file ctest rewrites) are kept.
costs="build/$PRESET/Testing/Temporary/CTestCostData.txt"
if [[ -f "tests/ctest_costs/$PRESET.txt" && ! -f "$costs" ]]; then
  mkdir -p "$(dirname "$costs")"
  cp "tests/ctest_costs/$PRESET.txt" "$costs"
fi

t0=$SECONDS
ctest --preset "$PRESET" --output-on-failure -j2
echo "test.sh [$PRESET]: ctest $((SECONDS - t0)) s"
