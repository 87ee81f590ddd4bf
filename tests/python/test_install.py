"""The install route of docs/python.md on Debian 12 (PEP 668: no pip into the system Python): a virtual
environment that sees the system's packages, then `pip install -v --no-build-isolation`. The module itself is
taken from the CMake build tree these tests run against (NYSTROM_CMAKE_BUILD_DIR), so nothing is recompiled."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import nystrom

REPO = Path(__file__).resolve().parents[2]


def cmake_build_tree():
    """The CMake build tree holding the imported package, or None (an installed package)."""
    d = Path(nystrom.__file__).resolve().parent
    for parent in d.parents:
        if (parent / "CMakeCache.txt").exists():
            return parent
    return None


def cmake_project_version():
    text = Path(REPO, "CMakeLists.txt").read_text()
    return re.search(r"project\(\s*nystrom\s+VERSION\s+([0-9][0-9.]*)", text).group(1)


@pytest.mark.skipif(cmake_build_tree() is None, reason="needs the CMake build tree of the module")
def test_venv_install_with_system_packages(tmp_path):
    src = tmp_path / "src"  # what pip needs of the repository when the module is already built
    src.mkdir()
    for name in ("setup.py", "pyproject.toml", "CMakeLists.txt"):
        shutil.copy2(Path(REPO, name), src / name)
    shutil.copytree(Path(REPO, "python", "nystrom"), src / "python" / "nystrom",
                    ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    (src / "docs").mkdir()
    shutil.copy2(Path(REPO, "docs", "python.md"), src / "docs" / "python.md")
    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable, "-m", "venv",
                    "--system-site-packages", str(venv)], check=True, capture_output=True, timeout=300)
    env = dict(os.environ, NYSTROM_CMAKE_BUILD_DIR=str(cmake_build_tree()), PIP_NO_INDEX="1")
    env.pop("PYTHONPATH", None)
    out = subprocess.run([str(venv / "bin" / "pip"), "install", "-v", "--no-build-isolation", str(src)], env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert "externally-managed-environment" not in out.stderr
    log = out.stdout + out.stderr
    # the build's progress reaches the user with -v: CMake's lines, then the end of the build
    assert "nystrom: compiling the C++ module" in log and "Built target nystrom_python" in log
    assert "nystrom: CMake build: done" in log
    check = subprocess.run([str(venv / "bin" / "python"), "-c",
                            "import nystrom; print(nystrom.__version__); print(nystrom.__file__); "
                            "print(len(nystrom.methods()))"],
                           env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert check.returncode == 0, check.stderr
    version, where, count = check.stdout.split()
    assert version == cmake_project_version()
    assert Path(where).resolve().is_relative_to(venv.resolve())
    assert int(count) > 20
