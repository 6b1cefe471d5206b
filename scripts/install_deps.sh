#!/usr/bin/env bash
# Install the Debian 12 packages needed to build, test and run gmasim.
# Fast no-op when everything is already installed (apt is not touched at all).
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libhwy-dev libtomlplusplus-dev libcli11-dev libfmt-dev libmatio-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  pybind11-dev python3-dev python3-numpy python3-scipy python3-matplotlib python3-pytest python3-pandas
  python3-pip python3-venv python3-setuptools python3-wheel
  libpagmo-dev libboost-serialization-dev libtbb-dev libopenmpi-dev openmpi-bin libceres-dev
  clang-format git ca-certificates valgrind
)

missing=()
for pkg in "${PACKAGES[@]}"; do
  status="$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)"
  if [[ "$status" != "install ok installed" ]]; then
    missing+=("$pkg")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "install_deps: installing missing packages: ${missing[*]}"

SUDO=()
if [[ "$(id -u)" -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
  else
    echo "install_deps: not root and sudo is not available; cannot install: ${missing[*]}" >&2
    exit 1
  fi
fi

export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing[@]}"
