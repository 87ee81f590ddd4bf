"""GIL release, Ctrl-C, progress, and ensembles over a process pool, threads, Dask and MPI."""
import json
import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import nystrom
from nystrom.problems import Kepler


def run_kepler(e):
    return nystrom.solve(Kepler(e), t_span=(0, 50.0), method="M8", steps=20000, t_eval=[25.0, 50.0])


def test_threads_integrating_built_in_problems_match_sequential_runs():
    es = [0.1, 0.5, 0.8, 0.9]
    seq = [run_kepler(e) for e in es]
    with ThreadPoolExecutor(max_workers=2) as pool:
        par = list(pool.map(run_kepler, es))
    for a, b in zip(seq, par):
        assert np.array_equal(a.q, b.q) and np.array_equal(a.v, b.v)
        assert a.force_evals == b.force_evals


@pytest.mark.skipif(os.name != "posix", reason="needs POSIX signals")
@pytest.mark.parametrize("python_force", [False, True])
def test_ctrl_c_interrupts_a_long_integration(python_force):
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    prob = Kepler(0.5)
    try:
        with pytest.raises(KeyboardInterrupt):
            if python_force:
                nystrom.solve(lambda t, q: -q / np.dot(q, q) ** 1.5, prob.q0, prob.v0, t_span=(0, 1e6),
                              method="M8", h=0.01, t_eval=[1e6])
            else:
                nystrom.solve(prob, t_span=(0, 1e8), method="M8", h=1e-3, t_eval=[1e8])
    finally:
        timer.cancel()


def test_progress_callback_sees_increasing_times():
    seen = []
    nystrom.solve(Kepler(0.5), t_span=(0, 2000.0), method="M4", h=1e-3, t_eval=[1000.0, 2000.0],
                  progress=seen.append)
    assert len(seen) >= 2
    assert all(b >= a for a, b in zip(seen, seen[1:]))
    assert 0 < seen[0] and seen[-1] <= 2000.0


def test_progress_line_on_stderr(capsys):
    nystrom.solve(Kepler(0.5), t_span=(0, 10.0), method="M4", steps=100, t_eval=[10.0], progress=True)
    err = capsys.readouterr().err
    assert "100.0%" in err


def last_progress(err):
    """(t, t1, percent) of the last progress line written on stderr."""
    m = re.fullmatch(r"nystrom: t = (\S+) of (\S+) \(\s*([0-9.]+)%\)", err.strip().split("\r")[-1])
    assert m, err[-300:]
    return float(m.group(1)), float(m.group(2)), float(m.group(3))


@pytest.mark.skipif(os.name != "posix", reason="needs POSIX signals")
def test_progress_line_after_ctrl_c_shows_where_the_run_stopped(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # the built-in line, whether tqdm is installed or not
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            nystrom.solve(Kepler(0.5), t_span=(0, 1e8), method="M8", h=1e-3, t_eval=[1e8], progress=True)
    finally:
        timer.cancel()
    t, t1, percent = last_progress(capsys.readouterr().err)
    assert t1 == 1e8 and 0 < t < 1e6 and percent < 1


def test_progress_line_after_a_terminal_event_shows_its_time(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)

    def at_five(t, q, v):
        return t - 5.0
    at_five.terminal = True
    res = nystrom.solve(Kepler(0.5), t_span=(0, 20.0), method="M4", steps=2000, events=[at_five], progress=True)
    assert res.status == 1
    t, t1, percent = last_progress(capsys.readouterr().err)
    assert t == pytest.approx(5.0) and t1 == 20.0 and percent == pytest.approx(25.0)


# ---- ensembles ---------------------------------------------------------------------------------

def make_kepler(e):
    return Kepler(e)


ENSEMBLE_ARGS = dict(t_span=(0, 20.0), steps=2000, t_eval=[10.0, 20.0])
ECCS = [0.0, 0.3, 0.6, 0.9]


def assert_same(results, reference):
    assert len(results) == len(reference)
    for a, b in zip(results, reference):
        assert np.array_equal(a.t, b.t) and np.array_equal(a.q, b.q) and np.array_equal(a.v, b.v)
        assert a.force_evals == b.force_evals


@pytest.fixture(scope="module")
def reference():
    return [nystrom.solve(Kepler(e), method="M8", **ENSEMBLE_ARGS) for e in ECCS]


def test_ensemble_on_a_local_process_pool(reference):
    res = nystrom.ensemble(make_kepler, ECCS, method="M8", max_workers=2, **ENSEMBLE_ARGS)
    assert_same(res, reference)
    # Results in parameter order: each is the orbit of its own eccentricity.
    assert np.allclose([r.q[-1, 0] for r in res], [Kepler(e).exact(20.0)[0][0] for e in ECCS], atol=1e-6)


def test_ensemble_on_threads_and_with_dict_factories(reference):
    def factory(e):
        k = Kepler(e)
        return dict(force=lambda t, q: -q / np.dot(q, q) ** 1.5, q0=k.q0, v0=k.v0)

    with ThreadPoolExecutor(max_workers=2) as pool:
        res = nystrom.ensemble(factory, ECCS, method="M8", executor=pool, **ENSEMBLE_ARGS)
    for a, b in zip(res, reference):
        assert np.allclose(a.q, b.q, atol=1e-10)
    with pytest.raises(TypeError, match="submit"):
        nystrom.ensemble(make_kepler, ECCS, executor=object())


def test_ensemble_on_a_dask_local_cluster(reference):
    distributed = pytest.importorskip("distributed")
    # In-process scheduler and worker (processes=False: no network beyond the process).
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        res = nystrom.ensemble(make_kepler, ECCS, method="M8", executor=client, **ENSEMBLE_ARGS)
    assert_same(res, reference)


MPI_SCRIPT = r"""
import json, sys
from mpi4py.futures import MPIPoolExecutor
import nystrom
sys.path.insert(0, {here!r})
from test_parallel import make_kepler, ENSEMBLE_ARGS, ECCS
with MPIPoolExecutor() as pool:
    res = nystrom.ensemble(make_kepler, ECCS, method="M8", executor=pool, **ENSEMBLE_ARGS)
print("RESULT", json.dumps([[r.q.tolist(), r.v.tolist(), r.force_evals] for r in res]))
"""


def test_ensemble_over_mpi(reference, tmp_path, child_env):
    pytest.importorskip("mpi4py")
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("mpirun not found")
    script = tmp_path / "mpi_ensemble.py"
    script.write_text(MPI_SCRIPT.format(here=os.path.dirname(os.path.abspath(__file__))))
    env = dict(child_env)
    # Localhost only, more ranks than cores allowed, as root in containers.
    env.update(OMPI_MCA_rmaps_base_oversubscribe="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_btl="self,tcp", OMPI_MCA_btl_tcp_if_include="lo", OMPI_MCA_oob_tcp_if_include="lo",
               OMPI_MCA_btl_vader_single_copy_mechanism="none")
    cmd = [mpirun, "-np", "2", sys.executable, "-m", "mpi4py.futures", str(script)]
    try:
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail("mpirun did not finish within 120 s")
    assert out.returncode == 0, out.stderr[-2000:]
    line = [x for x in out.stdout.splitlines() if x.startswith("RESULT ")][-1]
    got = json.loads(line[len("RESULT "):])
    for (q, v, evals), ref in zip(got, reference):
        assert np.array_equal(np.array(q), ref.q) and np.array_equal(np.array(v), ref.v)
        assert evals == ref.force_evals


# ---- dense output through pickle and ensembles -------------------------------------------------------

def kepler_force(t, q):
    return -q / np.dot(q, q) ** 1.5


DENSE_TIMES = np.linspace(0.0, 20.0, 37) + 0.01 * np.sin(np.arange(37))  # between the step ends


@pytest.mark.parametrize("python_force", [False, True])
def test_dense_output_pickles_and_evaluates_bitwise(python_force):
    prob = Kepler(0.6)
    if python_force:
        res = nystrom.solve(kepler_force, prob.q0, prob.v0, t_span=(0, 20.5), method="DP12-adaptive", rtol=1e-10,
                            dense_output=True)
    else:
        res = nystrom.solve(prob, t_span=(0, 20.5), method="M8", steps=3000, dense_output=True)
    back = pickle.loads(pickle.dumps(res))
    q, v = res.sol(DENSE_TIMES)
    q2, v2 = back.sol(DENSE_TIMES)
    assert np.array_equal(q, q2) and np.array_equal(v, v2)
    assert back.sol.t_min == res.sol.t_min and back.sol.t_max == res.sol.t_max
    assert np.allclose(q, prob.exact(DENSE_TIMES)[0], rtol=0, atol=1e-6)


def test_pickled_dense_output_of_a_restarted_run_does_not_reread_the_checkpoint(tmp_path):
    # The unpickled copy repeats the run from the checkpoint as it was read, even when the file has since
    # been replaced by another run's checkpoint or removed.
    prob = Kepler(0.6)
    path = tmp_path / "run.checkpoint"
    nystrom.solve(prob, t_span=(0, 20.5), method="M8", steps=3000, checkpoint=path, checkpoint_at=7.0)
    res = nystrom.solve(prob, t_span=(0, 20.5), method="M8", steps=3000, restart=path, dense_output=True)
    blob = pickle.dumps(res)
    nystrom.solve(prob, t_span=(0, 20.5), method="M8", steps=3000, checkpoint=path, checkpoint_at=12.0)
    times = DENSE_TIMES[DENSE_TIMES >= res.sol.t_min]
    q, v = res.sol(times)
    back = pickle.loads(blob)
    q2, v2 = back.sol(times)
    assert np.array_equal(q, q2) and np.array_equal(v, v2)
    assert back.sol.t_min == res.sol.t_min
    path.unlink()
    q3, v3 = pickle.loads(blob).sol(times)
    assert np.array_equal(q, q3) and np.array_equal(v, v3)


def test_dense_output_of_an_unpicklable_force_refuses_to_pickle():
    prob = Kepler(0.6)
    res = nystrom.solve(lambda t, q: -q / np.dot(q, q) ** 1.5, prob.q0, prob.v0, t_span=(0, 1.0), steps=10,
                        dense_output=True)
    with pytest.raises((pickle.PicklingError, AttributeError, TypeError)):
        pickle.dumps(res)


def test_ensemble_with_dense_output_matches_a_serial_run():
    args = dict(t_span=(0, 20.0), steps=2000, dense_output=True)
    serial = [nystrom.solve(Kepler(e), method="M8", **args) for e in ECCS]
    pooled = nystrom.ensemble(make_kepler, ECCS, method="M8", max_workers=2, **args)
    for a, b in zip(serial, pooled):
        assert np.array_equal(a.q, b.q)
        qa, va = a.sol(DENSE_TIMES)
        qb, vb = b.sol(DENSE_TIMES)
        assert np.array_equal(qa, qb) and np.array_equal(va, vb)
