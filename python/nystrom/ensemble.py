"""Ensembles: one integration per parameter, mapped over any concurrent.futures-style executor."""

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor

__all__ = ["ensemble"]


def _run_one(problem_factory, parameter, method, kwargs):
    from ._solve import solve
    from .problems import Problem

    made = problem_factory(parameter)
    kw = dict(kwargs)
    if isinstance(made, Problem):
        return solve(made, method=method, **kw)
    if isinstance(made, dict):
        kw.update(made)
        force = kw.pop("force")
        return solve(force, method=method, **kw)
    raise TypeError("problem_factory(parameter) must return a nystrom.problems problem or a dict of solve() "
                    f"arguments with 'force', got {type(made).__name__}")


def ensemble(problem_factory, parameters, method="M8", executor=None, max_workers=None, **solve_kwargs):
    """Runs ``solve(problem_factory(p), method=method, **solve_kwargs)`` for every p in parameters and
    returns the results in parameter order.

    problem_factory(p) returns a built-in problem (``nystrom.problems``) or a dict of ``solve`` arguments
    with at least ``force`` (and ``q0``, ``v0``, ...). The factory, the parameters and the forces must be
    picklable (module-level functions, not lambdas) for executors in other processes.

    executor: any object with ``submit(fn, *args)`` returning futures with ``result()``:
    ``concurrent.futures.ProcessPoolExecutor``/``ThreadPoolExecutor``, a ``dask.distributed.Client``, an
    ``mpi4py.futures.MPIPoolExecutor``. None: a local process pool of ``max_workers`` processes (default:
    the number of CPUs; started with spawn), closed afterwards. Every run is deterministic, so the results are the same
    whatever executor runs them.
    """
    params = list(parameters)
    if not callable(problem_factory):
        raise TypeError("problem_factory must be callable")
    if executor is not None and not callable(getattr(executor, "submit", None)):
        raise TypeError("executor must have a submit(fn, *args) method (concurrent.futures, Dask, mpi4py)")
    if not params:
        return []
    if executor is None:
        workers = max_workers or min(len(params), os.cpu_count() or 1)
        # spawn, not fork: a forked child inherits the parent's OpenMP runtime (the N-body force), which
        # is not safe to use after fork.
        with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = [pool.submit(_run_one, problem_factory, p, method, solve_kwargs) for p in params]
            return [f.result() for f in futures]
    futures = [executor.submit(_run_one, problem_factory, p, method, solve_kwargs) for p in params]
    return [f.result() for f in futures]
