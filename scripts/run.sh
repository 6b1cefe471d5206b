#!/usr/bin/env bash
# Install dependencies, build, and run the gmasim CLI with default settings.
# Extra arguments are forwarded to the gmasim subcommand.
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${GMASIM_PRESET:-ci}"

bash scripts/build.sh

BIN="build/${PRESET}/bin/gmasim"
if [[ ! -x "$BIN" ]]; then
  echo "run.sh: executable $BIN not found (did the build produce the CLI?)" >&2
  exit 1
fi

# Capture help first: piping straight into 'grep -q' can SIGPIPE under pipefail.
help_text="$("$BIN" --help 2>&1 || true)"
if grep -q reproduce <<<"$help_text"; then
  mkdir -p out/reproduce
  exec "$BIN" reproduce --out out/reproduce "$@"
else
  mkdir -p out/simulate
  exec "$BIN" simulate --out out/simulate "$@"
fi
