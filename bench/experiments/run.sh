#!/usr/bin/env bash
# The lanes' speed experiments of docs/performance.md ("Session of 2026-11-28, evening (stop
# 33)"): each patch here is a change to the lanes' kernel that was measured and not kept, or
# (unaligned) the revert of one that was kept. For each NAME given (default: every
# bench/experiments/*.patch) the current commit is checked out in a scratch git worktree, the
# patch applied, gmasim_bench built there (CMake preset ci, ccache when installed); the
# unpatched commit is built the same way first. Then ROUNDS rounds (default 5) run every build's
# batched sweep and identify objective (and the unpatched build's scalar ones), the builds in a
# rotated order each round, so that the machine's drifting load reaches each build alike.
# Prints, per benchmark, the median and range of the rounds, the ratio of the median to the
# unpatched build's, and the batched benchmark's speed-up over the unpatched scalar one.
# Usage: bash bench/experiments/run.sh [NAME ...]
#   NAME: a patch's name without .patch (letters, digits, _), or several joined by + (applied
#   together), e.g. fma_contract+reciprocal+carried_anchors
# Needs the build dependencies (scripts/install_deps.sh); about 6 min per build on 2 cores
# without ccache. The source tree is not touched: the worktrees and builds live in a mktemp
# directory removed at exit; the rounds' raw timings and the build logs of a failed build are
# printed. GMASIM_BENCH_SIMD is unset (every build runs on the CPU's best target). Exit status:
# 0 when every build and run succeeded, 1 otherwise (the others are still reported), 2 for a bad
# NAME.
set -euo pipefail
SRC="$(cd "$(dirname "$0")/../.." && pwd)"
HERE="$SRC/bench/experiments"
cd "$SRC"
unset GMASIM_BENCH_SIMD
names=()
for n in "$@"; do  # each NAME once
  if ! [[ "$n" =~ ^[A-Za-z0-9_]+(\+[A-Za-z0-9_]+)*$ ]]; then
    echo "run.sh: NAME '$n': patch names (letters, digits, _) joined by +" >&2
    exit 2
  fi
  case " ${names[*]-} " in *" $n "*) ;; *) names+=("$n") ;; esac
done
if [ $# -eq 0 ]; then
  for p in "$HERE"/*.patch; do names+=("$(basename "$p" .patch)"); done
fi
for n in "${names[@]}"; do
  IFS=+ read -r -a parts <<<"$n"
  for p in "${parts[@]}"; do
    [ -f "$HERE/$p.patch" ] || { echo "run.sh: no patch $HERE/$p.patch" >&2; exit 2; }
  done
done
ROUNDS="${ROUNDS:-5}"
if ! [[ "$ROUNDS" =~ ^[1-9][0-9]?$ ]]; then
  echo "run.sh: ROUNDS=$ROUNDS: must be a whole number in [1, 99]" >&2
  exit 2
fi
git rev-parse --git-dir >/dev/null || { echo "run.sh: $SRC is not a git checkout" >&2; exit 2; }
WORK="$(mktemp -d)"
cleanup() {
  for d in "$WORK"/w*/; do
    if [ -d "$d" ]; then git -C "$SRC" worktree remove --force "$d" 2>/dev/null || true; fi
  done
  git -C "$SRC" worktree prune 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
BATCHED='SweepDefaultGrid_batched/1/|ObjectiveBatch16_batched'
SCALAR='SweepDefaultGrid_scalar/1/|ObjectiveBatch16_scalar'
failures=()
build() {  # $1: label, $2: tree; the build's output in $2.log, its tail printed on failure
  if ! (cd "$2" && CCACHE_BASEDIR="$2" cmake --preset ci "${launcher[@]}" &&
    CCACHE_BASEDIR="$2" cmake --build build/ci -j2 --target gmasim_bench) >"$2.log" 2>&1; then
    echo "run.sh: $1 did not build; the end of its log:" >&2
    tail -n 40 "$2.log" >&2
    failures+=("$1: build")
    return 1
  fi
}
labels=() bins=() ntree=0
add_tree() {  # $1: label, $2: patches joined by +, or empty
  local tree="$WORK/w$ntree"
  ntree=$((ntree + 1))
  git worktree add --detach "$tree" HEAD >/dev/null
  local ok=1 p
  if [ -n "$2" ]; then
    IFS=+ read -r -a parts <<<"$2"
    for p in "${parts[@]}"; do
      if ! git -C "$tree" apply "$HERE/$p.patch"; then
        echo "run.sh: $p.patch does not apply to $(git rev-parse --short HEAD) (in $1)" >&2
        failures+=("$1: $p.patch does not apply")
        ok=0
      fi
    done
  fi
  if [ "$ok" = 1 ] && build "$1" "$tree"; then
    labels+=("$1")
    bins+=("$tree/build/ci/bin/gmasim_bench")
  elif [ "$1" = baseline ]; then
    echo "run.sh: the unpatched build failed" >&2
    exit 1
  fi
}
add_tree baseline ""
for n in "${names[@]}"; do add_tree "$n" "$n"; done
results="$WORK/results.txt"
: >"$results"
count=${#labels[@]}
for ((r = 0; r < ROUNDS; ++r)); do
  for ((i = 0; i < count; ++i)); do
    k=$(((i + r) % count))
    l="${labels[$k]}" bin="${bins[$k]}"
    filter="$BATCHED"
    if [ "$l" = baseline ]; then filter="$SCALAR|$BATCHED"; fi
    if ! out="$("$bin" --benchmark_filter="$filter" 2>"$WORK/bench.err")"; then
      echo "run.sh: $l's gmasim_bench failed in round $((r + 1)):" >&2
      tail -n 20 "$WORK/bench.err" >&2
      failures+=("$l: round $((r + 1))")
      continue
    fi
    awk -v l="$l" '/^BM_/ {print l, $1, $2, $3}' <<<"$out" >>"$results"
  done
done
echo "raw timings (label, benchmark, time, unit), round by round:"
cat "$results"
/usr/bin/python3 - "$results" <<'PY'
import statistics
import sys
runs = {}
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) < 4 or f[3] != "ms":
        continue  # a benchmark that reported an error, or another unit
    try:
        runs.setdefault((f[0], f[1]), []).append(float(f[2]))
    except ValueError:
        continue
if not runs:
    sys.exit("run.sh: no timings")
rows = [(label, name, statistics.median(v), min(v), max(v), len(v))
        for (label, name), v in runs.items()]
base = {name: ms for label, name, ms, *_ in rows if label == "baseline"}
print(f"\n{'experiment':40s} {'benchmark':40s} {'median ms':>10s} {'range':>15s} "
      f"{'/ baseline':>10s} {'x scalar':>9s}")
for label, name, ms, lo, hi, n in rows:
    short = name.replace("/iterations:3", "").replace("/real_time", "")
    ratio = f"{ms / base[name]:10.3f}" if name in base else f"{'n/a':>10s}"
    scalar = base.get(name.replace("_batched", "_scalar"))
    speedup = f"{scalar / ms:8.2f}x" if "_batched" in name and scalar else ""
    rng = f"{lo:.1f}-{hi:.1f} ({n})"
    print(f"{label:40s} {short:40s} {ms:10.2f} {rng:>15s} {ratio} {speedup:>9s}")
PY
if [ ${#failures[@]} -gt 0 ]; then
  printf 'run.sh: failed: %s\n' "${failures[@]}" >&2
  exit 1
fi
