# Shared by the identify CLI tests: strict mode, the synthetic data (12 conditions,
# 20/45/70 degC x 6/8 A x 10/100 Hz, 1 % noise) and the CI-sized search settings.
set -euo pipefail
GMASIM="$1"
WORK="$2"
SRC="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
PY=/usr/bin/python3
rm -rf "$WORK"
mkdir -p "$WORK"
cd "$WORK"
TRUTH="$SRC/tests/data/identify_fixture.toml"  # the calibrated printed reading (tests/identify_fixture.hpp)
"$GMASIM" identify synthesize --model "$TRUTH" --out data --steps-per-period 200 --samples-per-period 100 \
  --noise 1 --seed 2 >/dev/null
FIT="$SRC/examples/identify_synthetic/fit.toml"
COMMON=(identify --model "$TRUTH" --data data/manifest.toml --fit "$FIT" --steps-per-period 200 --islands 2
        --population 12 --no-plots)
