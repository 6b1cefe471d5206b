"""Builds the gmasim Python package with CMake (pyproject.toml holds the metadata).

The extension gmasim._gmasim is the CMake target _gmasim: setup.py configures a build of the
repository (tests and benchmarks off) under build/setuptools, builds that one target, and
copies the module beside python/gmasim/*.py into the wheel. With GMASIM_CMAKE_BUILD_DIR set to
an already configured build directory (build/ci), it only builds _gmasim there (a no-op when it
is up to date) and packages it: what the ctest python_pip_install does.

    /usr/bin/python3 -m venv --system-site-packages /tmp/v
    /tmp/v/bin/python -m pip install -v --no-build-isolation .

pip shows a build backend's output only with -v: then every step below is printed as it runs
("setup.py: ..." lines and CMake's [n/N] build progress); without -v pip prints only "still
running..." for the ~100 s of a fresh build.
"""
import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent
REUSE_DIR = os.environ.get("GMASIM_CMAKE_BUILD_DIR", "")
# setuptools' own build tree, the CMake build and the egg-info live outside the source tree:
# under the reused CMake build, else under $GMASIM_PIP_BUILD_DIR, else the user's cache
# (${XDG_CACHE_HOME:-~/.cache}/gmasim/pip-build), kept so that a second install rebuilds only
# what changed. Nothing is written into the sources.
CACHE = pathlib.Path(os.environ.get("XDG_CACHE_HOME") or pathlib.Path.home() / ".cache")
BUILD_BASE = ((pathlib.Path(REUSE_DIR).resolve() / "setuptools") if REUSE_DIR else
              pathlib.Path(os.environ.get("GMASIM_PIP_BUILD_DIR") or CACHE / "gmasim" / "pip-build").resolve())


def cmake_project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    m = re.search(r"project\(\s*gmasim\s+VERSION\s+([0-9]+\.[0-9]+\.[0-9]+)", text)
    if not m:
        raise RuntimeError("setup.py: no 'project(gmasim VERSION x.y.z' in CMakeLists.txt")
    return m.group(1)


def run(cmd, **kw):
    print("setup.py:", " ".join(str(c) for c in cmd), flush=True)
    sys.stdout.flush()
    subprocess.run([str(c) for c in cmd], check=True, **kw)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        cmake = shutil.which("cmake")
        if not cmake:
            raise RuntimeError("setup.py: cmake not found (apt-get install cmake, or bash scripts/install_deps.sh)")
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        if REUSE_DIR:
            bdir = pathlib.Path(REUSE_DIR).resolve()
            if not (bdir / "CMakeCache.txt").is_file():
                raise RuntimeError(f"setup.py: GMASIM_CMAKE_BUILD_DIR={REUSE_DIR} is not a configured CMake build directory")
        else:
            bdir = pathlib.Path(self.build_temp).resolve() / "cmake"
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            run([cmake, "-S", ROOT, "-B", bdir, *generator, "-DCMAKE_BUILD_TYPE=Release",
                 "-DGMASIM_BUILD_TESTS=OFF", "-DGMASIM_BUILD_BENCH=OFF", "-DGMASIM_BUILD_PYTHON=ON",
                 f"-DGMASIM_PYTHON_EXECUTABLE={sys.executable}"])
        run([cmake, "--build", bdir, "--target", "_gmasim", "-j", jobs])
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = bdir / "python" / "gmasim" / f"_gmasim{suffix}"
        if not built.is_file():
            raise RuntimeError(f"setup.py: the build did not produce {built} (is this Python the one CMake built for?)")
        dest = pathlib.Path(self.get_ext_fullpath(ext.name))
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, dest)


BUILD_BASE.mkdir(parents=True, exist_ok=True)
setup(
    version=cmake_project_version(),
    ext_modules=[Extension("gmasim._gmasim", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(BUILD_BASE)}, "egg_info": {"egg_base": str(BUILD_BASE)}},
)
