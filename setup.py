"""Builds nystrom._core with the project's CMake (option NYSTROM_BUILD_PYTHON) for pip.

The version is the CMake project's (CMakeLists.txt). The build prints CMake's progress lines as they come (one per
compiled file; `pip install -v` shows them) and a line at least every minute while a file compiles.

Environment: NYSTROM_CMAKE_ARGS (extra configure arguments), NYSTROM_BUILD_JOBS (parallel jobs, default 2),
NYSTROM_CMAKE_BUILD_DIR (an existing CMake build tree with NYSTROM_BUILD_PYTHON=ON to build the module in and
take it from, instead of a fresh one).
"""

import glob
import os
import re
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
HEARTBEAT_SECONDS = 60


def project_version():
    """The VERSION of CMakeLists.txt's project(nystrom VERSION ...)."""
    text = (ROOT / "CMakeLists.txt").read_text()
    m = re.search(r"project\(\s*nystrom\s+VERSION\s+([0-9][0-9.]*)", text)
    if not m:
        raise RuntimeError("CMakeLists.txt has no project(nystrom VERSION ...)")
    return m.group(1)


def say(line):
    print(line, flush=True)


def run_with_progress(cmd, what):
    """Runs cmd, echoing its output line by line as it comes, and a line every HEARTBEAT_SECONDS of silence (a
    long compilation) with the time spent so far."""
    say(f"nystrom: {what}: {' '.join(cmd)}")
    start = time.monotonic()
    last = [start]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1)
    finished = threading.Event()

    def heartbeat():
        while not finished.wait(5):
            now = time.monotonic()
            if now - last[0] >= HEARTBEAT_SECONDS:
                last[0] = now
                say(f"nystrom: {what}: still running after {int(now - start)} s")

    ticker = threading.Thread(target=heartbeat, daemon=True)
    ticker.start()
    try:
        for line in proc.stdout:
            last[0] = time.monotonic()
            say(line.rstrip("\n"))
        code = proc.wait()
    finally:
        finished.set()
        if proc.poll() is None:
            proc.kill()
    if code != 0:
        raise RuntimeError(f"{what} failed (exit status {code}); its output is above (pip install -v shows it)")
    say(f"nystrom: {what}: done in {int(time.monotonic() - start)} s")


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
            run_with_progress(configure, "CMake configure")
        say("nystrom: compiling the C++ module (several minutes; one line per compiled file)")
        run_with_progress(["cmake", "--build", str(build), "--target", "nystrom_python", "-j", jobs], "CMake build")
        built = glob.glob(str(package / target.name)) or glob.glob(str(package / "_core.*.so"))
        if not built:
            raise RuntimeError(f"the CMake build did not produce the module in {package}")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)


setup(version=project_version(), ext_modules=[CMakeExtension("nystrom._core")], cmdclass={"build_ext": CMakeBuild})
