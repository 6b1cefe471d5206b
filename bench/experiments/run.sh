#!/usr/bin/env bash
# The lanes' speed experiments of docs/performance.md ("Why the lanes stop short of 4x"), each a
# patch on the kernel that was measured and not kept. For each NAME given (default: all of
# bench/experiments/*.patch) the current commit is checked out in a scratch worktree, the patch
# applied, gmasim_bench built there (CMake preset ci, ccache when installed) and the batched
# sweep and identify objective run; the unpatched commit is built and run the same way first.
# Prints each benchmark's time, its ratio to the unpatched build and the batched benchmark's
# speed-up over the scalar step() benchmark of the unpatched build, all from the same run.
# Usage: bash bench/experiments/run.sh [NAME ...]
#   NAME: a patch's name without .patch, or several joined by + (applied together), e.g.
#   fma_contract+reciprocal+carried_anchors
# Needs the build dependencies (scripts/install_deps.sh); about 6 min per build on 2 cores
# without ccache. Nothing in the source tree is changed; the worktrees are removed at the end.
set -euo pipefail
SRC="$(cd "$(dirname "$0")/../.." && pwd)"
HERE="$SRC/bench/experiments"
cd "$SRC"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for p in "$HERE"/*.patch; do names+=("$(basename "$p" .patch)"); done
fi
for n in "${names[@]}"; do
  IFS=+ read -r -a parts <<<"$n"
  for p in "${parts[@]}"; do
    [ -f "$HERE/$p.patch" ] || { echo "run.sh: no patch $HERE/$p.patch" >&2; exit 2; }
  done
done
WORK="$(mktemp -d)"
cleanup() {
  for d in "$WORK"/*/; do
    if [ -d "$d" ]; then git -C "$SRC" worktree remove --force "$d" 2>/dev/null || true; fi
  done
  rm -rf "$WORK"
}
trap cleanup EXIT
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
BATCHED='SweepDefaultGrid_batched/1/|ObjectiveBatch16_batched'
SCALAR='SweepDefaultGrid_scalar/1/|ObjectiveBatch16_scalar'
build() {  # $1: label, $2: tree
  (cd "$2" && CCACHE_BASEDIR="$2" cmake --preset ci "${launcher[@]}" >/dev/null &&
    CCACHE_BASEDIR="$2" cmake --build build/ci -j2 --target gmasim_bench >/dev/null) ||
    { echo "run.sh: $1 did not build" >&2; return 1; }
}
# The builds first, then ROUNDS rounds that run every build's benchmarks in turn (the machine's
# load drifts over minutes: interleaved, each build sees the same drift); the median of the
# rounds is reported.
ROUNDS="${ROUNDS:-5}"
labels=(baseline)
git worktree add --detach "$WORK/baseline" HEAD >/dev/null 2>&1
build baseline "$WORK/baseline"
for n in "${names[@]}"; do
  git worktree add --detach "$WORK/$n" HEAD >/dev/null 2>&1
  IFS=+ read -r -a parts <<<"$n"
  applied=1
  for p in "${parts[@]}"; do
    if ! git -C "$WORK/$n" apply "$HERE/$p.patch"; then
      echo "run.sh: $p.patch does not apply to $(git rev-parse --short HEAD) (in $n)" >&2
      applied=0
    fi
  done
  if [ "$applied" = 1 ] && build "$n" "$WORK/$n"; then labels+=("$n"); fi
done
: >"$WORK/results.txt"
for ((r = 1; r <= ROUNDS; ++r)); do
  for l in "${labels[@]}"; do
    filter="$BATCHED"
    if [ "$l" = baseline ]; then filter="$SCALAR|$BATCHED"; fi
    "$WORK/$l/build/ci/bin/gmasim_bench" --benchmark_filter="$filter" 2>/dev/null |
      awk -v l="$l" '/^BM_/ {print l, $1, $2}' >>"$WORK/results.txt"
  done
done
/usr/bin/python3 - "$WORK/results.txt" <<'PY'
import sys
import statistics
runs = {}
for line in open(sys.argv[1]):
    label, name, ms = line.split()
    runs.setdefault((label, name), []).append(float(ms))
rows = [(label, name, statistics.median(v)) for (label, name), v in runs.items()]
base = {name: ms for label, name, ms in rows if label == "baseline"}
def scalar_of(name):
    return name.replace("_batched", "_scalar")
print(f"\nmedians of {len(next(iter(runs.values())))} interleaved rounds")
print(f"{'experiment':40s} {'benchmark':44s} {'ms':>8s} {'/ baseline':>11s} {'x scalar':>9s}")
for label, name, ms in rows:
    short = name.replace("/iterations:3", "").replace("/real_time", "")
    speedup = f"{base[scalar_of(name)] / ms:8.2f}x" if "_batched" in name else ""
    print(f"{label:40s} {short:44s} {ms:8.2f} {ms / base[name]:11.3f} {speedup:>9s}")
PY
