"""nystrom.langevin: Langevin path ensembles from Python, against closed forms of the harmonic oscillator (BAOAB
samples q exactly, <q^2> = kT / omega^2, and <v^2> = kT (1 - h^2 omega^2 / 4) at the end of a step), with the
refusals and the thread-independence of the tool."""
import doctest
import inspect
import multiprocessing
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import pytest

import nystrom
import nystrom._langevin


def within(estimate, expected, z=5.0):
    return abs(estimate["value"] - expected) <= z * estimate["stderr"]


def test_docstring_examples_run():
    assert doctest.testmod(nystrom._langevin, optionflags=doctest.ELLIPSIS).failed == 0


def test_baoab_stationary_variances_and_their_extrapolation():
    kT, omega, h = 0.5, 2.0, 0.25  # h omega = 1/2: <v^2> = kT (1 - 1/16)
    r = nystrom.langevin("harmonic", kT=kT, omega=omega, h=h, t_end=100.0, paths=600, extrapolate=[1, 2])
    plain = r.members[0]["averages"]
    assert within(plain["q2"], kT / omega**2)
    assert within(plain["v2"], kT * (1 - h * h * omega * omega / 4))
    assert abs(plain["v2"]["value"] - kT) > 8 * plain["v2"]["stderr"]  # the bias is seen
    assert within(r.averages["v2"], kT)  # the h^2 term is all of it: the two-term combination is exact
    assert r.coefficients == pytest.approx([-1 / 3, 4 / 3], rel=1e-15)
    assert r.order == 4
    assert r.window == (50.0, 100.0)
    assert r.force_evaluations == 600 * (400 + 1 + 800 + 1)  # BAOAB: one force per step and the first


def test_the_result_does_not_depend_on_the_thread_count():
    args = dict(potential="double-well", kT=0.5, h=0.05, t_end=5.0, paths=300, extrapolate="1,2,3", seed=7)
    runs = [nystrom.langevin(**args, threads=t) for t in (1, 2, 4)]
    for r in runs[1:]:
        assert r.averages == runs[0].averages and r.final == runs[0].final  # exact equality of the floats


def test_an_executor_gives_the_same_result_bitwise():
    args = dict(potential="double-well", kT=0.5, h=0.1, t_end=4.0, paths=500, extrapolate=[1, 2], seed=3)
    plain = nystrom.langevin(**args, threads=2)
    with ThreadPoolExecutor(3) as pool:
        threaded = nystrom.langevin(**args, executor=pool, tasks=5)
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        processes = nystrom.langevin(**args, executor=pool)
    for r in (threaded, processes):
        assert r.averages == plain.averages and r.final == plain.final and r.members == plain.members
        assert r.force_evaluations == plain.force_evaluations
    with ThreadPoolExecutor(1) as pool, pytest.raises(ValueError, match="'X' is not A"):
        nystrom.langevin(method="BAXAB", executor=pool)


def test_defaults_are_the_tools():
    sig = inspect.signature(nystrom.langevin)
    defaults = {k: v.default for k, v in sig.parameters.items()}
    # `nystrom langevin --help`: harmonic, gamma 1, kT 1, BAOAB, h 0.05, t-end 10, paths 1000, extrapolate 1,
    # seed 1, q0 1, v0 0, omega 1, threads 0
    assert defaults == dict(potential="harmonic", gamma=1.0, kT=1.0, method="BAOAB", h=0.05, t_end=10.0, paths=1000,
                            extrapolate=(1,), seed=1, q0=1.0, v0=0.0, omega=1.0, threads=0, progress=False,
                            executor=None, tasks=None)


@pytest.mark.parametrize("kwargs,message", [
    (dict(method="BAXAB"), "'X' is not A (drift)"),
    (dict(method="BAAB"), "has no O"),
    (dict(method="BAO", extrapolate=[1, 2]), "symmetric splitting"),
    (dict(h=0.3, t_end=1.0), "whole number of steps"),
    (dict(potential="quartic"), "unknown Langevin potential"),
    (dict(gamma=-1.0), "friction"),
    (dict(extrapolate=[1, 1]), "duplicate"),
    (dict(paths=0), "paths"),
])
def test_bad_input_is_refused_with_one_line(kwargs, message):
    with pytest.raises(ValueError) as e:
        nystrom.langevin(**kwargs)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_wrong_types_are_refused():
    with pytest.raises(TypeError):
        nystrom.langevin(paths=1.5)
    with pytest.raises(TypeError):
        nystrom.langevin(method=3)
    with pytest.raises(TypeError):
        nystrom.langevin(progress="yes")


def test_progress_reports_the_paths():
    seen = []
    nystrom.langevin(paths=200, t_end=1.0, progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1] == (200, 200)


def test_stationary_law_is_the_tools_and_exact_for_the_harmonic_oscillator():
    kT, omega, h = 0.5, 2.0, 0.5  # h omega = 1: BAOAB's <q^2> = kT / omega^2, <v^2> = kT (1 - 1/4)
    r = nystrom.stationary_law("harmonic", kT=kT, omega=omega, h=h, extrapolate=[1, 2])
    assert r.members[0]["stationary"]["q2"] == pytest.approx(kT / omega**2, abs=1e-11)
    assert r.members[0]["stationary"]["v2"] == pytest.approx(kT * 0.75, abs=1e-11)
    assert r.stationary["v2"] == pytest.approx(kT, abs=1e-11)  # the h^2 term is all of <v^2>'s bias
    assert r.boltzmann["q2"] == pytest.approx(kT / omega**2, abs=1e-12)
    assert r.order == 4 and r.grid["points"] == (65, 65)
    assert r.resolution < 1e-6 and r.edge < 1e-6
    # the tool's --stationary-law gives the same numbers (shortest round-trip JSON of the same doubles)
    import json
    import os
    import subprocess
    tool = os.environ.get("NYSTROM_BIN")
    if tool:
        out = subprocess.run([tool, "langevin", "--stationary-law", "--potential", "harmonic", "--kT", "0.5",
                              "--omega", "2", "--h", "0.5", "--extrapolate", "1,2", "--json"],
                             check=True, capture_output=True, text=True).stdout
        assert json.loads(out)["stationary"] == r.stationary


def test_stationary_law_refusals():
    with pytest.raises(ValueError, match="symmetric"):
        nystrom.stationary_law(method="BAO", extrapolate=[1, 2])
    with pytest.raises(ValueError, match="friction"):
        nystrom.stationary_law(gamma=0.0)
    with pytest.raises(ValueError, match="grid_points"):
        nystrom.stationary_law(grid_points=64)
    with pytest.raises(ValueError, match="between 9 and 257"):
        nystrom.stationary_law(grid_points=1001)
    with pytest.raises(TypeError):
        nystrom.stationary_law(h="0.1")
    with pytest.raises(RuntimeError, match="grid"):
        nystrom.stationary_law("double-well", kT=0.5, h=0.4)
