#!/usr/bin/env bash
# Regenerates data/ of the worked example (docs/data.md, "Worked example"): the rod of
# truth.toml (models/single_rod.toml with four changed constants, `gmasim model save --set`)
# measured as a lab measures a material loop: quasi-static (no time axis), the field read
# by a Hall probe (field_A_per_m), the strain by a gauge zeroed at the first sample
# (strain_ppm, offset = first_sample), after two pre-cycles, with 0.5 % Gaussian noise.
# Usage: examples/strain_loop/make_data.sh   (GMASIM: the binary)
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
SRC="$(cd "$HERE/../.." && pwd)"
GMASIM="${GMASIM:-$SRC/build/ci/bin/gmasim}"
"$GMASIM" identify synthesize --model "$HERE/truth.toml" --out "$HERE/data" \
  --temperatures 20 --currents 12 --current-min -6 --quasi-static --drive field \
  --response strain --offset first_sample --precycles 2 --periods 1 \
  --samples-per-period 120 --no-flux --noise 0.5 --seed 7
