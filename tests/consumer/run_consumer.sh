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
         share/gmasim/models/mdma.toml share/gmasim/models/mdma_printed.toml; do
  [[ -e "$prefix/$f" ]] || { echo "package_consumer: $prefix/$f was not installed" >&2; exit 1; }
done
libdir="$(dirname "$(find "$prefix" -name gmasimConfig.cmake -print -quit)")"
[[ -f "$libdir/gmasimConfigVersion.cmake" && -f "$libdir/gmasimTargets.cmake" ]]
if grep -rl -e "$build" -e "$src/" "$libdir"; then
  echo "package_consumer: the installed CMake package refers to the build or source tree" >&2
  exit 1
fi
version="$("$prefix/bin/gmasim" --version)"
echo "installed CLI: $version"
[[ "$version" == "gmasim 0.1.0"* ]]

cmake -S "$here" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="$flags" > "$work/configure.log" 2>&1 ||
  { cat "$work/configure.log" >&2; exit 1; }
cmake --build "$work/build" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log" >&2; exit 1; }

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
echo "package_consumer: ok in $((SECONDS - start)) s"
