#!/usr/bin/env bash
# ctest package_consumer: install a gmasim build into a temporary prefix, then configure, build
# and run the consumer project beside this script against it (find_package(gmasim CONFIG)).
#   run_consumer.sh <gmasim build dir> <work dir>
# GMASIM_CONSUMER_FLAGS: extra compile/link flags (the sanitizer build's -fsanitize=...).
set -euo pipefail
build="$(cd "$1" && pwd)"
work="$2"
here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../.." && pwd)"
flags="${GMASIM_CONSUMER_FLAGS:-}"
start=$SECONDS

rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" > "$work/install.log"

# What the package promises is there, and nothing in it points back at the build or source tree.
for f in bin/gmasim include/gmasim/gmasim_c.h include/gmasim/model.hpp include/gmasim/version.h \
         include/gmasim/capi/gmasim_c.h include/gmasim/model/model.hpp \
         include/gmasim/simulate/run_loop.hpp include/gmasim/mechanics/mechanics.hpp \
         share/gmasim/models/mdma.toml share/gmasim/models/mdma_printed.toml \
         share/gmasim/models/single_rod.toml share/gmasim/models/single_rod_printed.toml; do
  [[ -e "$prefix/$f" ]] || { echo "package_consumer: $prefix/$f was not installed" >&2; exit 1; }
done
libdir="$(dirname "$(find "$prefix" -name gmasimConfig.cmake -print -quit)")"
[[ -f "$libdir/gmasimConfigVersion.cmake" && -f "$libdir/gmasimTargets.cmake" ]]
if grep -rl -e "$build" -e "$src/" "$libdir"; then
  echo "package_consumer: the installed CMake package refers to the build or source tree" >&2
  exit 1
fi
# Issue 41: a relocatable install -- no build- or source-tree path in the installed CLI, the
# Python package in the prefix (the CLI's --plot uses it; PYTHONPATH=it imports gmasim).
if strings "$prefix/bin/gmasim" | grep -e "$build" -e "$src/"; then
  echo "package_consumer: the installed CLI holds a build- or source-tree path (above)" >&2
  exit 1
fi
[[ -f "$prefix/share/gmasim/python/gmasim/__init__.py" ]] ||
  { echo "package_consumer: the Python package was not installed" >&2; exit 1; }
if /usr/bin/python3 -c "import numpy, matplotlib" 2>/dev/null; then
  (cd "$work" && PYTHONPATH="$prefix/share/gmasim/python" /usr/bin/python3 -c \
    "import gmasim; r = gmasim.simulate(gmasim.Model(), periods=1); assert r['metrics']['stroke_um'] > 0") ||
    { echo "package_consumer: the installed Python package does not import" >&2; exit 1; }
  (cd "$work" && "$prefix/bin/gmasim" simulate --periods 1 --plot --out plot_from_prefix > plot.log 2>&1) ||
    { cat "$work/plot.log" >&2; echo "package_consumer: --plot failed from the prefix" >&2; exit 1; }
  [[ -f "$work/plot_from_prefix/simulate.png" ]]
  echo "installed Python package: imports, and the CLI's --plot draws with it"
fi
version="$("$prefix/bin/gmasim" --version)"
echo "installed CLI: $version"
[[ "$version" == "gmasim 0.1.0"* ]]
# Outside the repository, a shipped model's name resolves to the installed copy, and the
# built-in model is labelled as such (not as a file "models/mdma.toml" of the directory).
(
  cd "$work"
  shown="$("$prefix/bin/gmasim" model show --model models/mdma_printed.toml | sed -n 1p)"
  [[ "$shown" == "# $prefix/share/gmasim/models/mdma_printed.toml" ]] ||
    { echo "package_consumer: --model models/mdma_printed.toml gave '$shown'" >&2; exit 1; }
  shown="$("$prefix/bin/gmasim" model show --model single_rod.toml | sed -n 1p)"
  [[ "$shown" == "# $prefix/share/gmasim/models/single_rod.toml" ]] ||
    { echo "package_consumer: --model single_rod.toml gave '$shown'" >&2; exit 1; }
  shown="$("$prefix/bin/gmasim" model show | sed -n 1p)"
  [[ "$shown" == "# the built-in MDMA model"* ]] ||
    { echo "package_consumer: the built-in model is labelled '$shown'" >&2; exit 1; }
  echo "installed CLI: shipped models resolved from $prefix/share/gmasim/models"
)

cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="$flags" > "$work/configure.log" 2>&1 ||
  { cat "$work/configure.log" >&2; exit 1; }
cmake --build "$work/build" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log" >&2; exit 1; }

# Ceres's search must not leak "Could NOT find METIS" into a consumer's configure.
if grep -i metis "$work/configure.log"; then
  echo "package_consumer: find_package(gmasim) printed Ceres's METIS search" >&2
  exit 1
fi
cpp="$("$work/build/consumer_cpp")"
c="$("$work/build/consumer_c")"
echo "$cpp"
echo "$c"
# The C API and the C++ library step the same model to the same bits.
y_cpp="$(sed -n 's/.*y_m //p' <<< "$cpp")"
y_c="$(sed -n 's/.*y_m //p' <<< "$c")"
if [[ -z "$y_cpp" || "$y_cpp" != "$y_c" ]]; then
  echo "package_consumer: C++ y_m '$y_cpp' differs from C y_m '$y_c'" >&2
  exit 1
fi
# The C API alone (find_package(gmasim COMPONENTS c)): configured while CMake may not find any
# of the C++ library's dependencies, with no word of METIS, and libgmasim_c.so needs none of
# their libraries at run time.
barred=""
for p in Ceres Pagmo pagmo Boost MPI Eigen3 tomlplusplus fmt Threads METIS glog gflags; do
  barred="$barred -DCMAKE_DISABLE_FIND_PACKAGE_$p=ON"
done
# shellcheck disable=SC2086
cmake -S "$here/c_only" -B "$work/build_c" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
  $barred > "$work/configure_c.log" 2>&1 || { cat "$work/configure_c.log" >&2; exit 1; }
# (CMake lists the barring variables as "not used by the project": that is the point.)
if grep -v CMAKE_DISABLE_FIND_PACKAGE_ "$work/configure_c.log" | grep -i -e metis -e ceres -e pagmo; then
  echo "package_consumer: the C-only configure looked for the C++ dependencies" >&2
  exit 1
fi
cmake --build "$work/build_c" > "$work/build_c.log" 2>&1 || { cat "$work/build_c.log" >&2; exit 1; }
c_only="$("$work/build_c/consumer_c_only")"
[[ "$(sed -n 's/.*y_m //p' <<< "$c_only")" == "$y_c" ]] ||
  { echo "package_consumer: the C-only consumer differs: $c_only" >&2; exit 1; }
lib="$(find "$prefix" -name 'libgmasim_c.so*' -type f -print -quit)"
needed="$(readelf -d "$lib" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' | tr '\n' ' ')"
echo "libgmasim_c.so needs: $needed"
if grep -i -E 'ceres|pagmo|boost|mpi|glog|metis|tbb' <<< "$needed"; then
  echo "package_consumer: libgmasim_c.so needs an identification-stack library" >&2
  exit 1
fi
echo "C-only consumer (COMPONENTS c, the C++ dependencies barred): $c_only"
echo "package_consumer: ok in $((SECONDS - start)) s"
