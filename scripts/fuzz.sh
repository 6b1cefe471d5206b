#!/usr/bin/env bash
# Build the libFuzzer harnesses of fuzz/ (preset fuzz: clang, ASan + UBSan) and run each for
# a given time (docs/reliability.md). Findings (crash-*, timeout-*, oom-*) go to
# build/fuzz/artifacts/<harness>/ and make the script exit non-zero.
#   bash scripts/fuzz.sh                 every harness, 600 s each
#   bash scripts/fuzz.sh 60              every harness, 60 s each
#   bash scripts/fuzz.sh 120 model checkpoint
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_EACH="${1:-600}"
shift || true
case "$SECONDS_EACH" in
  ''|*[!0-9]*) echo "scripts/fuzz.sh: the time per harness must be whole seconds, got '$SECONDS_EACH'" >&2; exit 1 ;;
esac
if (( SECONDS_EACH < 1 || SECONDS_EACH > 86400 )); then
  echo "scripts/fuzz.sh: the time per harness must be 1..86400 s, got $SECONDS_EACH" >&2
  exit 1
fi

bash scripts/install_deps.sh
if ! command -v clang++ >/dev/null 2>&1; then
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get install -y --no-install-recommends clang
fi

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j2

HARNESSES=("$@")
if [[ ${#HARNESSES[@]} -eq 0 ]]; then
  for f in fuzz/fuzz_*.cpp; do n="$(basename "$f" .cpp)"; HARNESSES+=("${n#fuzz_}"); done
fi

status=0
for h in "${HARNESSES[@]}"; do
  exe="build/fuzz/bin/fuzz_$h"
  [[ -x "$exe" ]] || { echo "scripts/fuzz.sh: no harness '$h' (fuzz/fuzz_$h.cpp)" >&2; exit 1; }
  work="build/fuzz/corpus/$h"
  art="build/fuzz/artifacts/$h"
  mkdir -p "$work" "$art"
  echo "== fuzz_$h for ${SECONDS_EACH} s (seeds: fuzz/corpus/$h)"
  # -timeout: an input that takes > 10 s is a hang; -rss_limit_mb: > 2 GiB is a finding.
  if ! ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
      "$exe" -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
        -print_final_stats=1 -artifact_prefix="$art/" "$work" "fuzz/corpus/$h" \
        2>"build/fuzz/$h.log"; then
    echo "   FINDING: see build/fuzz/$h.log and $art/"
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "build/fuzz/$h.log" | sed 's/^/   /' || true
done
exit $status
