"""nystrom.langevin: Langevin dynamics dq = v dt, dv = a(q) dt - gamma v dt + sqrt(2 gamma kT) dW of one particle
of unit mass in a built-in potential, by a splitting over the drift A, the kick B and the exact
Ornstein-Uhlenbeck flow O, with averages over many paths extrapolated by the multi-product expansion
(nystrom/stochastic/langevin.hpp, the solver of ``nystrom langevin``; docs/stochastic.md).

The paths run in C++ on threads with the GIL released; the checks of the input are the library's (ValueError
with its one-line message), this module converts the arguments and wraps the result.

>>> import nystrom
>>> res = nystrom.langevin("harmonic", kT=0.5, h=0.1, t_end=20.0, paths=2000, extrapolate=[1, 2])
>>> abs(res.averages["q2"]["value"] - 0.5) < 5 * res.averages["q2"]["stderr"]
True
"""

import numbers
import os

from . import _core
from ._progress import counted_progress
from ._result import AttrDict

__all__ = ["langevin", "LangevinResult", "stationary_law", "StationaryLawResult"]


class LangevinResult(AttrDict):
    """The result of :func:`nystrom.langevin` (a dict whose keys are also attributes).

    Attributes: ``averages`` and ``final`` (dicts mapping the observables ``q``, ``q2``, ``q4``, ``v2``,
    ``energy`` to ``{"value", "stderr"}``: the time average over ``window`` and the value at ``t_end``, means
    over the paths, extrapolated), ``members`` (one dict per k_i: ``k``, ``h`` = h / k_i, and its own
    ``averages`` and ``final``), ``coefficients`` (c_i), ``order`` (the weak order of the combination),
    ``window`` ((n0 h, t_end), n0 = floor(steps / 2)), ``method``, ``h``, ``t_end``, ``steps``, ``paths``,
    ``seed``, ``extrapolate``, ``force_evaluations``.
    """

    def __repr__(self):
        q2 = self.averages["q2"]
        return (f"LangevinResult(method={self.method!r}, extrapolate={self.extrapolate!r}, "
                f"q2={q2['value']!r} +- {q2['stderr']!r}, paths={self.paths!r})")


def _real(name, x):
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(x).__name__}")
    return float(x)


def _integer(name, x, lo, hi):
    if isinstance(x, bool) or not isinstance(x, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(x).__name__}")
    x = int(x)
    if not lo <= x <= hi:
        raise ValueError(f"{name} must be between {lo} and {hi}, got {x}")
    return x


def _sequence(extrapolate):
    if isinstance(extrapolate, str):
        items = extrapolate.split(",")
        if any(not s.strip().isdigit() for s in items):
            raise ValueError(f"extrapolate must be positive integers such as '1,2,3', got {extrapolate!r}")
        return [int(s) for s in items]
    if isinstance(extrapolate, numbers.Integral) and not isinstance(extrapolate, bool):
        return [int(extrapolate)]
    try:
        seq = list(extrapolate)
    except TypeError:
        raise TypeError("extrapolate must be a sequence of positive integers such as [1, 2, 3]") from None
    return [_integer("extrapolate", k, 1, 1000000) for k in seq]


_CHUNK = 64  # paths per chunk of the library's deterministic reduction (nystrom/stochastic/langevin.hpp)


def _partial(args, first, count):
    """One executor task: the statistics of paths first .. first + count - 1 (plain, picklable data)."""
    from . import _core as core

    return core.langevin_partial(core.LangevinRequest(*args), first, count)


def langevin(potential="harmonic", gamma=1.0, kT=1.0, method="BAOAB", h=0.05, t_end=10.0, paths=1000,
             extrapolate=(1,), seed=1, q0=1.0, v0=0.0, omega=1.0, threads=0, progress=False, executor=None,
             tasks=None):
    """Averages over ``paths`` independent Langevin paths from (q0, v0), with standard errors (as
    ``nystrom langevin``, with the same defaults).

    Parameters
    ----------
    potential : str
        ``"harmonic"`` (U = omega^2 q^2 / 2) or ``"double-well"`` (U = (q^2 - 1)^2); unit mass.
    gamma, kT : float
        Friction and temperature (not negative).
    method : str
        A splitting string over A (drift), B (kick), O (exact Ornstein-Uhlenbeck flow), each letter's
        occurrences sharing the step equally (Leimkuhler & Matthews 2013): ``"BAOAB"``, ``"OBABO"``,
        ``"ABOBA"``, ``"BAO"``, ...; OpenMM's ``"VRORV"`` (V = B, R = A) also reads.
    h, t_end : float
        The step and the end time, a whole number of steps.
    paths : int
        Independent paths.
    extrapolate : sequence of int or str
        The multi-product sequence k_1..k_n (``[1, 2, 3]`` or ``"1,2,3"``): every path runs at h / k_i with
        one Brownian path, and the averages are combined with Chin's coefficients c_i: weak order 2n for a
        symmetric splitting (BAOAB); a non-symmetric one is refused with n > 1. ``[1]``: the scheme alone.
    seed : int
        The seed of the counter-based generator (Philox): the noise of path p is a pure function of
        (seed, p, step), so the result does not depend on ``threads``.
    q0, v0, omega : float
        The initial state; the harmonic angular frequency.
    threads : int
        Threads (0: all cores).
    progress : bool or callable
        True: a progress bar; a callable gets ``progress(paths_done, paths)``. Ctrl-C interrupts the run
        (KeyboardInterrupt) either way.
    executor : optional
        Any object with ``submit(fn, *args)`` returning futures (``concurrent.futures`` pools, a
        ``dask.distributed.Client``, ``mpi4py.futures.MPIPoolExecutor``): the paths are split into ``tasks``
        ranges (default: up to 32, whole chunks of 64 paths), each run there with ``threads`` threads (0: one),
        and the statistics merged here in path order: the result is bitwise that of the run without it.

    Returns
    -------
    LangevinResult

    Examples
    --------
    BAOAB samples the harmonic oscillator's position exactly at any stable step, <q^2> = kT / omega^2, while
    <v^2> = kT (1 - h^2 omega^2 / 4); the two-term extrapolation removes that h^2 error:

    >>> import nystrom
    >>> r = nystrom.langevin("harmonic", h=0.5, t_end=100.0, paths=1000, extrapolate=[1, 2])
    >>> v2 = r.members[0]["averages"]["v2"]
    >>> abs(v2["value"] - 0.9375) < 5 * v2["stderr"], abs(r.averages["v2"]["value"] - 1) < 5 * r.averages["v2"]["stderr"]
    (True, True)

    Bad splitting strings are refused:

    >>> nystrom.langevin(method="BAXAB")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Langevin splitting 'BAXAB': 'X' is not A (drift), B (kick) or O ...
    """
    for name, value in (("potential", potential), ("method", method)):
        if not isinstance(value, str):
            raise TypeError(f"{name} must be a string, got {type(value).__name__}")
    gamma, kT, h, t_end, q0, v0, omega = (_real(n, v) for n, v in (("gamma", gamma), ("kT", kT), ("h", h),
                                                                   ("t_end", t_end), ("q0", q0), ("v0", v0),
                                                                   ("omega", omega)))
    paths = _integer("paths", paths, 1, 2**62)
    seed = _integer("seed", seed, 0, 2**64 - 1)
    threads = _integer("threads", threads, 0, 1024)
    seq = _sequence(extrapolate)
    if executor is not None:
        if not callable(getattr(executor, "submit", None)):
            raise TypeError("executor must have a submit(fn, *args) method (concurrent.futures, Dask, mpi4py)")
        chunks = -(-paths // _CHUNK)
        tasks = min(chunks, 32) if tasks is None else _integer("tasks", tasks, 1, 1 << 20)
        per = -(-chunks // tasks) * _CHUNK
        args = (potential, omega, gamma, kT, q0, v0, method, h, t_end, paths, seed, seq, threads or 1)
        request = _core.LangevinRequest(*args)
        _core.langevin_check(request)  # the library's checks, here, before anything is submitted
        futures = [executor.submit(_partial, args, first, min(per, paths - first)) for first in range(0, paths, per)]
        return LangevinResult(_core.langevin_finish(request, [f.result() for f in futures]))
    if threads == 0:
        threads = min(os.cpu_count() or 1, 64)
    request = _core.LangevinRequest(potential, omega, gamma, kT, q0, v0, method, h, t_end, paths, seed, seq, threads)
    update, close = counted_progress(progress)
    done = None  # the paths run, once the run has returned
    try:
        d = _core.langevin(request, update)
        done = paths
    finally:
        if close is not None:
            close(done)
    return LangevinResult(d)


class StationaryLawResult(AttrDict):
    """The result of :func:`nystrom.stationary_law` (a dict whose keys are also attributes).

    Attributes: ``stationary`` (a dict mapping the observables ``q``, ``q2``, ``q4``, ``v2``, ``energy`` to the
    combination's stationary average), ``boltzmann`` (the exact Boltzmann averages by the same quadrature),
    ``members`` (one dict per k_i: ``k``, ``h`` = h / k_i, ``steps`` to the fixed point, its own ``stationary``),
    ``coefficients`` (c_i), ``order``, ``method``, ``h``, ``extrapolate``, ``grid`` (``points``, ``q`` range,
    ``v_max``), ``resolution`` (fraction of the densities' spectrum in the outer quarter of the wave numbers) and
    ``edge`` (largest density on the grid's edges relative to its maximum).
    """

    def __repr__(self):
        q2 = self.stationary["q2"]
        return (f"StationaryLawResult(method={self.method!r}, h={self.h!r}, extrapolate={self.extrapolate!r}, "
                f"q2={q2!r}, bias={q2 - self.boltzmann['q2']!r})")


def stationary_law(potential="harmonic", gamma=1.0, kT=1.0, method="BAOAB", h=0.05, extrapolate=(1,), q0=1.0,
                   omega=1.0, grid_points=65):
    """The exact stationary averages of a Langevin splitting at the steps h / k_i and of their multi-product
    combination, from the scheme's law on a phase-space grid: no paths, no statistical error (as ``nystrom
    langevin --stationary-law``, with the same defaults; docs/stochastic.md).

    The density of (q, v) is carried by the splitting's own flows, each exact on the grid's trigonometric
    polynomials (drift and kick: band-limited shifts; O: the Ornstein-Uhlenbeck transition kernel), and iterated
    from the Boltzmann density to the scheme's fixed point. ``potential``, ``gamma``, ``kT``, ``method``, ``h``,
    ``extrapolate``, ``omega`` are those of :func:`nystrom.langevin` (gamma and kT must be positive); ``q0`` is
    where the search for the grid's q range starts (where the Boltzmann density exceeds e^-40 of its maximum);
    ``grid_points`` (odd, 9..257) per axis. A density that reaches the grid's edges or is not resolved by it (a
    step near the scheme's stability bound) is refused with RuntimeError.

    >>> import nystrom
    >>> r = nystrom.stationary_law("harmonic", h=1.0)  # BAOAB: <q^2> exact, <v^2> = kT (1 - h^2 / 4)
    >>> round(r.stationary["q2"], 10), round(r.stationary["v2"], 10)
    (1.0, 0.75)
    """
    for name, value in (("potential", potential), ("method", method)):
        if not isinstance(value, str):
            raise TypeError(f"{name} must be a string, got {type(value).__name__}")
    gamma, kT, h, q0, omega = (_real(n, v) for n, v in (("gamma", gamma), ("kT", kT), ("h", h), ("q0", q0),
                                                         ("omega", omega)))
    grid_points = _integer("grid_points", grid_points, 9, 257)
    seq = _sequence(extrapolate)
    return StationaryLawResult(_core.stationary_law(potential, omega, gamma, kT, q0, method, h, seq, grid_points))
