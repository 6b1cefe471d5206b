#!/usr/bin/env bash
# ctest python_pip_install: pip-install the repository (pyproject.toml + setup.py) into a fresh
# venv that sees Debian's packages, then import gmasim and simulate from outside the repository
# with no PYTHONPATH.
#   pip_install.sh <work dir>
# GMASIM_CMAKE_BUILD_DIR: reuse this configured CMake build (the ctest sets it to its own build,
# so only the packaging runs); unset, setup.py configures and builds from scratch under
# build/setuptools (docs/c_api.md records how long that takes).
# GMASIM_PYTHON: the interpreter (default /usr/bin/python3).
set -euo pipefail
work="$1"
py="${GMASIM_PYTHON:-/usr/bin/python3}"
src="$(cd "$(dirname "$0")/../.." && pwd)"
start=$SECONDS

rm -rf "$work"
mkdir -p "$work/elsewhere"
# --without-pip: Debian's pip (python3-pip) is visible through --system-site-packages, and the
# venv is not "externally managed" (PEP 668), so no --break-system-packages is needed.
"$py" -m venv --system-site-packages --without-pip "$work/venv"
vpy="$work/venv/bin/python"
unset PYTHONPATH
# -v: pip shows the build backend's output (docs/c_api.md): every step of setup.py as it runs.
had_setuptools_dir=0
[[ -d "$src/build/setuptools" ]] && had_setuptools_dir=1
"$vpy" -m pip install -v --no-build-isolation --no-index --no-cache-dir "$src" >"$work/pip.log" 2>&1 ||
  { tail -50 "$work/pip.log" >&2; exit 1; }
echo "pip install: $((SECONDS - start)) s"
grep -q '^ *setup.py: .*cmake --build' "$work/pip.log" ||
  { echo "pip_install: the build's progress is not shown with -v" >&2; exit 1; }
# No build tree in the source: no egg-info beside the sources, no build/setuptools there.
if compgen -G "$src/*.egg-info" >/dev/null || compgen -G "$src/python/*.egg-info" >/dev/null ||
  [[ $had_setuptools_dir -eq 0 && -d "$src/build/setuptools" ]]; then
  echo "pip_install: pip left a build tree in the source directory $src" >&2
  exit 1
fi

cd "$work/elsewhere"
"$vpy" - "$work/venv" <<'PY'
import pathlib
import sys

import numpy as np

import gmasim

venv = pathlib.Path(sys.argv[1]).resolve()
where = pathlib.Path(gmasim.__file__).resolve()
assert venv in where.parents, f"gmasim imported from {where}, not from the venv {venv}"
assert gmasim.__version__ == "0.1.0", gmasim.__version__
m = gmasim.Model()
r = gmasim.simulate(m, temperature_C=20, current_pp_A=8, frequency_Hz=10, periods=1)
stroke = r["metrics"]["stroke_um"]
assert 10.0 < stroke < 200.0, stroke
st = gmasim.Stepper(m, temperature_C=20, dt_s=r["dt_s"], current_A=r["series"]["current_A"][0])
y = st.run(r["series"]["current_A"][1:])
assert np.array_equal(y, r["series"]["y_um"][1:])
import gmasim.plots  # noqa: F401  (matplotlib from the system)
print(f"gmasim {gmasim.__version__} ({gmasim.__git_describe__ or 'no git'}) from {where.parent}: "
      f"stroke {stroke:.3f} um at 20 degC, 8 A pp, 10 Hz; Stepper agrees")
PY
echo "python_pip_install: ok in $((SECONDS - start)) s"
