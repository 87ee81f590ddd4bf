"""nystrom.__version__ and `nystrom --version`: the CMake project version."""
import re
import subprocess
from pathlib import Path

import pytest

import nystrom

REPO = Path(__file__).resolve().parents[2]


def cmake_project_version():
    text = Path(REPO, "CMakeLists.txt").read_text()
    return re.search(r"project\(\s*nystrom\s+VERSION\s+([0-9][0-9.]*)", text).group(1)


def test_module_version_is_the_cmake_project_version():
    assert nystrom.__version__ == cmake_project_version()
    assert nystrom._core.__version__ == nystrom.__version__


def the_tool():
    """The build tree's tool beside the package (<build>/python/nystrom -> <build>/src/nystrom), or None."""
    pkg = Path(nystrom.__file__).resolve().parent
    for parent in pkg.parents:
        if (parent / "CMakeCache.txt").exists():
            tool = parent / "src" / "nystrom"
            return tool if tool.exists() else None
    return None


@pytest.mark.skipif(the_tool() is None, reason="the command-line tool is not built beside the module")
def test_cli_version_is_the_same():
    out = subprocess.run([str(the_tool()), "--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == nystrom.__version__
