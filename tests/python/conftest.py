# The tests import the package built by CMake (PYTHONPATH=<build>/python) or installed by pip.
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))

try:
    import nystrom  # noqa: F401
except ImportError as exc:  # pragma: no cover - a configuration error, reported once
    raise ImportError("the nystrom package is not importable: build the CMake target nystrom_python and set "
                      "PYTHONPATH=<build>/python, or pip install the repository") from exc


@pytest.fixture(scope="session")
def repo_root():
    return REPO


@pytest.fixture(scope="session")
def child_env():
    """Environment for child interpreters: the same nystrom package, no GUI backend."""
    env = dict(os.environ)
    import nystrom

    pkg_parent = os.path.dirname(os.path.dirname(os.path.abspath(nystrom.__file__)))
    env["PYTHONPATH"] = pkg_parent + os.pathsep + env.get("PYTHONPATH", "")
    env["MPLBACKEND"] = "Agg"
    return env


@pytest.fixture(scope="session")
def python_exe():
    return sys.executable
