"""Builds the compiled half of the Python package `plate` (plate._plate) with the project's CMake build,
for `pip install --no-build-isolation .` (pyproject.toml declares the package; this file only drives
CMake). The build tree is setuptools' temporary folder, or PLATE_BUILD_DIR if set (an existing,
configured build tree -- e.g. `build`, after scripts/build.sh -- is then reused and only the module's
target is brought up to date). PLATE_BUILD_JOBS sets the parallel jobs (default: the machine's cores).
"""
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


def cmake_version():
    """The project's version: `project(plate ... VERSION X.Y.Z)` in CMakeLists.txt."""
    with open(os.path.join(HERE, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(plate\b[^)]*\bVERSION\s+([0-9][0-9.]*)", f.read())
    if not m:
        raise RuntimeError("CMakeLists.txt: no 'project(plate ... VERSION X.Y.Z)' line")
    return m.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = os.environ.get("PLATE_BUILD_DIR") or os.path.join(os.path.abspath(self.build_temp), "cmake")
        if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
            os.makedirs(build_dir, exist_ok=True)
            subprocess.check_call(["cmake", "-S", HERE, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DPLATE_TESTS=OFF", "-DPLATE_PEERS=OFF", "-DPLATE_SICONOS=OFF",
                                   "-DPython3_EXECUTABLE=" + sys.executable])
        jobs = os.environ.get("PLATE_BUILD_JOBS") or str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", build_dir, "--target", "plate_python", "-j", jobs])
        built = os.path.join(build_dir, "python", "plate")
        names = [n for n in os.listdir(built) if n.startswith("_plate") and n.endswith(".so")]
        if len(names) != 1:
            raise RuntimeError(f"{built}: expected one compiled module _plate*.so, found {names or 'none'}"
                               " (is pybind11 installed? scripts/install-deps.sh installs it)")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(built, names[0]), target)


setup(version=cmake_version(),
      ext_modules=[Extension("plate._plate", sources=[])],
      cmdclass={"build_ext": CMakeBuild})
