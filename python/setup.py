# SPDX-License-Identifier: MIT
"""Build of the rcal package: the pure-Python files, plus librcal_ffi.so
compiled from the repository's C sources by CMake (the rcal_ffi target of
the top-level CMakeLists.txt: core, host library and tools/host/outputs/
rch_ffi*.c, linked with LAPACKE) and copied into the package next to
_lib.py, where the package finds it. The shipped data files (data/irb120.json,
...) go into rcal/data. The version is the CMake project's (rc_version()).

Environment (all optional):
  RCAL_SOURCE_DIR   the repository root (default: the parent of this directory)
  RCAL_CMAKE        the cmake program (default: cmake)
  RCAL_BUILD_JOBS   parallel build jobs (default: 2)
  RCAL_CMAKE_ARGS   extra configure arguments, blank-separated
"""
import os
import re
import shutil
import subprocess
import tempfile

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = ("irb120.json", "kr6.json", "sim_irb120.csv", "sim_irb120_truth.json")


def source_dir():
    root = os.environ.get("RCAL_SOURCE_DIR") or os.path.dirname(HERE)
    if not os.path.isfile(os.path.join(root, "tools", "host", "outputs", "rch_ffi.c")):
        raise SystemExit("rcal: the C sources are not at %s (the package is built from a clone of the repository: "
                         "pip install ./python from its root; or set RCAL_SOURCE_DIR)" % root)
    return root


def version():
    with open(os.path.join(source_dir(), "CMakeLists.txt")) as f:
        m = re.search(r"project\(rcal\s+VERSION\s+([0-9.]+)", f.read())
    if not m:
        raise SystemExit("rcal: no project(rcal VERSION ...) in CMakeLists.txt")
    return m.group(1)


class BuildWithLibrary(build_py):
    """build_py, then cmake --build --target rcal_ffi into a temporary
    directory, the library and the data files copied into the package."""

    def run(self):
        super().run()
        root = source_dir()
        cmake = os.environ.get("RCAL_CMAKE", "cmake")
        if shutil.which(cmake) is None:
            raise SystemExit("rcal: cmake not found (Debian: apt-get install cmake; it builds librcal_ffi.so)")
        build = tempfile.mkdtemp(prefix="rcal-ffi-build-")
        try:
            configure = [cmake, "-S", root, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DRCAL_BUILD_TESTS=OFF",
                         "-DRCAL_STATIC_PROGRAM=OFF"] + os.environ.get("RCAL_CMAKE_ARGS", "").split()
            self.announce("rcal: " + " ".join(configure), level=2)
            subprocess.check_call(configure)
            subprocess.check_call([cmake, "--build", build, "--target", "rcal_ffi", "-j",
                                   os.environ.get("RCAL_BUILD_JOBS", "2")])
            pkg = os.path.join(self.build_lib, "rcal")
            os.makedirs(os.path.join(pkg, "data"), exist_ok=True)
            shutil.copy2(os.path.join(build, "python", "librcal_ffi.so"), os.path.join(pkg, "librcal_ffi.so"))
            for name in DATA:
                shutil.copy2(os.path.join(root, "data", name), os.path.join(pkg, "data", name))
        finally:
            shutil.rmtree(build, ignore_errors=True)


class BinaryDistribution(Distribution):
    """A wheel with a shared library: platform-specific, not pure."""

    def has_ext_modules(self):
        return True


setup(version=version(), cmdclass={"build_py": BuildWithLibrary}, distclass=BinaryDistribution)
