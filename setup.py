"""Builds nystrom._core with the project's CMake (option NYSTROM_BUILD_PYTHON) for pip.

Environment: NYSTROM_CMAKE_ARGS (extra configure arguments), NYSTROM_BUILD_JOBS (parallel jobs, default 2).
"""

import os
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
        build = Path(self.build_temp).resolve() / "cmake"
        build.mkdir(parents=True, exist_ok=True)
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DNYSTROM_BUILD_PYTHON=ON",
            "-DNYSTROM_BUILD_TOOL=OFF", "-DNYSTROM_BUILD_TESTS=OFF",
            "-DNYSTROM_BUILD_BENCH=OFF", "-DNYSTROM_BUILD_EXAMPLES=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DNYSTROM_PYTHON_PACKAGE_DIR={target.parent}",
        ] + os.environ.get("NYSTROM_CMAKE_ARGS", "").split()
        subprocess.run(configure, check=True)
        jobs = os.environ.get("NYSTROM_BUILD_JOBS", "2")
        subprocess.run(["cmake", "--build", str(build), "--target", "nystrom_python", "-j", jobs], check=True)
        if not target.exists():
            raise RuntimeError(f"the CMake build did not produce {target}")


setup(ext_modules=[CMakeExtension("nystrom._core")], cmdclass={"build_ext": CMakeBuild})
