"""The examples in examples/python run and write what they say."""
import os
import subprocess

import pytest


@pytest.mark.parametrize("script,outputs", [
    ("kepler_orbit.py", ["kepler_orbit.png", "kepler_energy.png"]),
    ("work_precision.py", ["work_precision.png"]),
    ("ensemble_precession.py", []),
])
def test_example_runs(script, outputs, repo_root, child_env, python_exe, tmp_path):
    path = os.path.join(repo_root, "examples", "python", script)
    args = [python_exe, path] + (["--out", str(tmp_path)] if outputs else [])
    out = subprocess.run(args, env=child_env, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    for name in outputs:
        assert (tmp_path / name).stat().st_size > 1000
