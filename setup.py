"""Builds nystrom._core with the project's CMake (option NYSTROM_BUILD_PYTHON) for pip.

Environment: NYSTROM_CMAKE_ARGS (extra configure arguments), NYSTROM_BUILD_JOBS (parallel jobs, default 2),
NYSTROM_CMAKE_BUILD_DIR (an existing CMake build tree with NYSTROM_BUILD_PYTHON=ON to build the module in and
take it from, instead of a fresh one).
"""

import glob
import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target = Path(self.get_ext_fullpath(ext.name)).resolve()
        jobs = os.environ.get("NYSTROM_BUILD_JOBS", "2")
        existing = os.environ.get("NYSTROM_CMAKE_BUILD_DIR")
        if existing:
            build = Path(existing).resolve()
            cache = (build / "CMakeCache.txt").read_text()
            line = [x for x in cache.splitlines() if x.startswith("NYSTROM_PYTHON_PACKAGE_DIR:")]
            if not line:
                raise RuntimeError(f"{build} is not a CMake build tree with NYSTROM_BUILD_PYTHON=ON")
            package = Path(line[0].split("=", 1)[1])
        else:
            build = Path(self.build_temp).resolve() / "cmake"
            package = build / "package" / "nystrom"
            build.mkdir(parents=True, exist_ok=True)
            configure = [
                "cmake", "-S", str(ROOT), "-B", str(build),
                "-DCMAKE_BUILD_TYPE=Release",
                "-DNYSTROM_BUILD_PYTHON=ON",
                "-DNYSTROM_BUILD_TOOL=OFF", "-DNYSTROM_BUILD_TESTS=OFF",
                "-DNYSTROM_BUILD_BENCH=OFF", "-DNYSTROM_BUILD_EXAMPLES=OFF",
                f"-DPython3_EXECUTABLE={sys.executable}",
                f"-DNYSTROM_PYTHON_PACKAGE_DIR={package}",
            ] + os.environ.get("NYSTROM_CMAKE_ARGS", "").split()
            subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "nystrom_python", "-j", jobs], check=True)
        built = glob.glob(str(package / target.name)) or glob.glob(str(package / "_core.*.so"))
        if not built:
            raise RuntimeError(f"the CMake build did not produce the module in {package}")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)


setup(ext_modules=[CMakeExtension("nystrom._core")], cmdclass={"build_ext": CMakeBuild})
