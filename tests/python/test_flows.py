"""nystrom.flows: the velocity-dependent forces with exact flows from Python, against the Arenstorf orbit's period,
the exact solutions of the magnetic and damped problems, and the command line's defaults."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import nystrom


def test_arenstorf_returns_after_one_period_with_the_default_steps():
    res = nystrom.flows("arenstorf", method="KL8", periods=1)
    assert res.method == "KL8" and res.order == 8 and res.symplectic
    assert res.steps == 20000 and res.force_evals == 17 * 20000
    assert abs(res.time - 17.0652165601579625588917206249) < 1e-12
    assert res.return_error < 1e-8
    assert res.invariant_name == "Jacobi integral"
    back = nystrom.flows("arenstorf", periods=-1)
    assert back.time < 0 and back.return_error < 1e-8


@pytest.mark.parametrize("problem", ["helix", "penning", "damped"])
def test_exact_problems_converge_with_the_method_order(problem):
    a = nystrom.flows(problem, method="FR", periods=3.3, steps_per_period=16)
    b = nystrom.flows(problem, method="FR", periods=3.3, steps_per_period=32)
    ea = max(a.position_error, a.velocity_error)
    eb = max(b.position_error, b.velocity_error)
    assert 3.6 < math.log2(ea / eb) < 5
    m8 = nystrom.flows(problem, method="M8", periods=-3.3, steps_per_period=64, precision="long-double")
    assert m8.time < 0 and m8.position_error < 1e-9 and m8.velocity_error < 1e-9


def test_samples_have_the_shape_of_the_state():
    res = nystrom.flows("penning", method="KL8", periods=2, samples=10)
    assert res.sample_q.shape == (11, 3) and res.sample_v.shape == (11, 3)
    assert res.sample_times[0] == 0 and abs(res.sample_times[-1] - res.time) < 1e-12
    assert np.max(np.abs(res.sample_invariant - res.invariant0)) == pytest.approx(res.invariant_error)
    assert res.invariant_error < 1e-10


@pytest.mark.parametrize("kwargs", [dict(problem="nowhere"), dict(method="N4"), dict(method="AC1"), dict(periods=0),
                                    dict(problem="helix", b=[0, 0, 0]), dict(problem="damped", q0=[1, 2]),
                                    dict(precision="float"), dict(mu=2.0)])
def test_bad_input_is_a_one_line_value_error(kwargs):
    with pytest.raises(ValueError) as e:
        nystrom.flows(**kwargs)
    assert "\n" not in str(e.value)


def test_type_errors():
    with pytest.raises(TypeError):
        nystrom.flows("arenstorf", periods="1")
    with pytest.raises(TypeError):
        nystrom.flows("arenstorf", steps_per_period=1.5)


def test_defaults_are_the_command_lines(child_env):
    tool = os.environ.get("NYSTROM_BIN")
    if not tool:
        pytest.skip("NYSTROM_BIN (the command-line tool) not set")
    for problem in ["arenstorf", "helix", "penning", "damped"]:
        out = subprocess.run([tool, "flows", "--problem", problem, "--json"], capture_output=True, text=True,
                             check=True).stdout
        j = json.loads(out)
        res = nystrom.flows(problem)
        assert j["method"] == res.method and j["steps"] == res.steps and j["dt"] == res.dt
        assert j["q"] == list(res.q) and j["v"] == list(res.v)


def test_docstring_examples_run():
    import doctest

    import nystrom._flows as module

    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 2
    assert result.failed == 0


def test_a_rotating_frame_from_python_is_the_built_in_arenstorf():
    mu = 0.012277471
    built = nystrom.flows("arenstorf", method="M8", periods=0.1, steps_per_period=20000)

    def gradient(q):
        r1 = np.array([q[0] + mu, q[1], q[2]])
        r2 = np.array([q[0] - (1 - mu), q[1], q[2]])
        return (1 - mu) * r1 / np.linalg.norm(r1) ** 3 + mu * r2 / np.linalg.norm(r2) ** 3

    def potential(q):
        return -(1 - mu) / math.hypot(q[0] + mu, q[1], q[2]) - mu / math.hypot(q[0] - 1 + mu, q[1], q[2])

    own = nystrom.rotating_frame(gradient, [0.994, 0, 0], [0, -2.00158510637908252240537862224, 0], dt=built.dt,
                                 steps=built.steps, omega=[0, 0, 1], potential=potential, method="M8")
    assert own.force_evals == built.force_evals
    assert np.max(np.abs(own.q - built.q)) < 1e-10 and np.max(np.abs(own.v - built.v)) < 1e-9
    assert abs(own.invariant0 - built.invariant0) < 1e-14 and own.invariant_error < 1e-9


def test_a_magnetic_field_from_python_gives_the_exact_helix_backward():
    built = nystrom.flows("helix", method="KL8", periods=-2.5, steps_per_period=32)
    e = np.array([0.1, 0.0, 0.05])
    own = nystrom.magnetic([1, 0, 0], [0, 1, 0.1], dt=built.dt, steps=built.steps, b=[0, 0, 1],
                           force=lambda q: e, potential=lambda q: -float(e @ q), method="KL8")
    assert own.time < 0
    assert np.max(np.abs(own.q - built.q)) < 1e-12 and np.max(np.abs(own.v - built.v)) < 1e-12
    assert built.position_error < 1e-12


def test_python_forces_are_checked_and_their_errors_propagate():
    with pytest.raises(ValueError, match="must return 1 numbers"):
        nystrom.damped(lambda t, q: [1.0, 2.0], [1.0], [0.0], dt=0.1, steps=3, gamma=0.1)
    with pytest.raises(ZeroDivisionError):
        nystrom.damped(lambda t, q: 1 / 0, [1.0], [0.0], dt=0.1, steps=3, gamma=0.1)
    with pytest.raises(TypeError):
        nystrom.rotating_frame(None, [1, 0, 0], [0, 1, 0], dt=0.1, steps=3)
    with pytest.raises(ValueError, match="3 components"):
        nystrom.magnetic([1, 0], [0, 1, 0], dt=0.1, steps=3)
