"""nystrom.solve: the library's solve() (nystrom/solve.hpp) from Python.

The integration, the output times, the dense output, the events and the step-size control are those of
the C++ driver; this module checks the arguments, passes them on and wraps the result.
"""

import hashlib
import inspect
import math
import numbers
import os
import tempfile

import numpy as np

from . import _core
from ._result import AttrDict
from ._progress import make_progress
from .problems import Problem

__all__ = ["solve", "OdeResult", "DenseSolution"]

_NO_LIMIT = 2**62  # max_steps of a fixed-step run: its number of steps is the caller's choice
# The C++ solve()'s error for a fixed-step method given neither h nor steps (the same words in C++, Python, CLI).
FIXED_STEP_NEEDS = "a fixed-step method needs a positive step size h or a number of steps"


class OdeResult(AttrDict):
    """The result of :func:`nystrom.solve` (a dict whose keys are also attributes).

    Attributes: ``t`` (output times), ``q``, ``v`` (positions and velocities, shape ``(len(t),) +
    q0.shape``), ``force_evals`` (by the method), ``output_force_evals`` (for output times, events and the
    dense output), ``steps``, ``rejected``, ``precise_products`` (adaptive multi-product methods: whether the
    products carried their own rounding, as at tight tolerances or with a compensated force; False for every
    other method), ``status`` (0:
    reached the end of t_span, 1: a terminal event, -1: failure: step size underflow, too many steps or a state
    no longer finite; ``t``, ``q``, ``v`` then hold the states saved before it), ``message``, ``success``,
    ``sol`` (a :class:`DenseSolution` when ``dense_output=True``), ``t_events``, ``q_events``, ``v_events`` (one
    array per event function), ``method``, ``precision``, ``h`` (fixed steps: the step size), ``q_str``/``v_str``
    (the final state in full working precision, as decimal strings), ``solve_seconds`` (wall time of the
    library's solve() call), ``checkpoint_t`` (the time of the checkpoint written, or None).
    """

    def __repr__(self):
        keys = ("message", "success", "status", "method", "force_evals", "steps")
        body = ", ".join(f"{k}={self[k]!r}" for k in keys if k in self)
        return f"OdeResult({body}, t: {len(self.get('t', []))} points)"


class DenseSolution:
    """``sol(t) -> (q, v)``: the state at any t of the integrated span, continued from the step end before t
    by one step of the solution's own method (the library's dense output), so with the method's accuracy;
    each time costs one step's force evaluations. For an array of times the leading axis runs over the
    times.

    It pickles (so that it comes back from an ensemble's worker processes) as the arguments of the run that
    made it: the method's engine and the force it continues with are compiled code, so the unpickled copy
    repeats that run (deterministic, so sol(t) is bitwise the same) at its first use. The force and the
    event functions must then be picklable (module-level functions or built-in problems)."""

    def __init__(self, core, rows, shape, recipe=None):
        self._core = core
        self._rows = rows
        self._shape = tuple(shape)
        self._recipe = recipe

    def _built(self):
        if self._core is None:
            recipe = dict(self._recipe)
            restart_text = recipe.pop("restart_text", None)
            if restart_text is None:
                other = solve(**recipe).sol
            else:  # a restarted run: from the checkpoint as it was read then, not from the file as it is now
                with tempfile.TemporaryDirectory(prefix="nystrom-") as folder:
                    path = os.path.join(folder, "restart.checkpoint")
                    with open(path, "w", encoding="utf-8") as f:
                        f.write(restart_text)
                    recipe["restart"] = path
                    other = solve(**recipe).sol
            self._core, self._rows = other._core, other._rows
        return self._core

    def __reduce__(self):
        if self._recipe is None:
            raise TypeError("this DenseSolution cannot be pickled: its run's arguments were not kept")
        return (_dense_from_recipe, (self._recipe, self._shape))

    @property
    def t_min(self):
        core = self._built()
        return min(core.t_first, core.t_last)

    @property
    def t_max(self):
        core = self._built()
        return max(core.t_first, core.t_last)

    def __call__(self, t):
        ts = np.asarray(t, dtype=float)
        scalar = ts.ndim == 0
        ts = np.ascontiguousarray(ts.reshape(-1))
        if not np.all(np.isfinite(ts)):
            raise ValueError("sol(t): times must be finite")
        q, v = self._built()(ts)
        q, v = self._rows(q), self._rows(v)
        if scalar:
            return q[0], v[0]
        return q, v


def _dense_from_recipe(recipe, shape):
    """An unpickled DenseSolution: the run is repeated at its first use."""
    return DenseSolution(None, None, shape, recipe)


def _positive(name, x):
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a number, got {type(x).__name__}")
    x = float(x)
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"{name} must be positive and finite, got {x!r}")
    return x


def _tolerance(name, x):
    """rtol or atol: a finite number >= 0."""
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a number, got {type(x).__name__}")
    x = float(x)
    if not (math.isfinite(x) and x >= 0):
        raise ValueError(f"{name} must be finite and >= 0, got {x!r}")
    return x


def _state(name, x, shape=None):
    if x is None:
        raise ValueError(f"{name} is required for a force given as a function")
    arr = np.asarray(x)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    arr = np.array(arr, dtype=float)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.size == 0:
        raise ValueError(f"{name} is empty")
    if shape is not None and arr.shape != tuple(shape):
        raise ValueError(f"{name} has shape {arr.shape}, expected {tuple(shape)}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return arr


def _t_span(t_span):
    try:
        t0, t1 = t_span
        t0, t1 = float(t0), float(t1)
    except (TypeError, ValueError):
        raise ValueError("t_span must be a pair of numbers (t0, t1)") from None
    if not (math.isfinite(t0) and math.isfinite(t1)):
        raise ValueError("t_span must be finite")
    return t0, t1


def _t_eval(t_eval, t0, t1):
    te = np.asarray(t_eval, dtype=float).reshape(-1)
    if te.size == 0:
        raise ValueError("t_eval is empty")
    if not np.all(np.isfinite(te)):
        raise ValueError("t_eval contains NaN or infinite values")
    d = 1.0 if t1 >= t0 else -1.0
    if np.any(d * np.diff(te) <= 0):
        raise ValueError("t_eval must be strictly " + ("increasing" if d > 0 else "decreasing") +
                         " (the direction of integration)")
    if d * (te[0] - t0) < 0 or d * (t1 - te[-1]) < 0:
        raise ValueError("t_eval must lie inside t_span")
    return [float(x) for x in te]


def _events(events, from_flat):
    """(g on flat states, direction, terminal, name) for every event function."""
    if events is None:
        return []
    if callable(events):
        events = [events]
    out = []
    for i, e in enumerate(events):
        if not callable(e):
            raise TypeError("events must be callables event(t, q, v) -> float")
        direction = getattr(e, "direction", 0) or 0
        direction = 1 if direction > 0 else (-1 if direction < 0 else 0)
        out.append((lambda t, q, v, e=e: e(t, from_flat(q), from_flat(v)), direction,
                    bool(getattr(e, "terminal", False)), getattr(e, "__name__", f"event {i}")))
    return out


def _precision(precision, bits):
    if not isinstance(precision, str):
        raise TypeError(f"precision must be a string, got {type(precision).__name__}")
    if bits is None:
        return precision
    if precision != "mpfr":
        raise ValueError("bits applies to precision='mpfr' only")
    if isinstance(bits, bool) or not isinstance(bits, numbers.Integral):
        raise TypeError(f"bits must be an integer, got {type(bits).__name__}")
    return f"mpfr:{int(bits)}"


# Bytes per coordinate of a saved state in the C++ Solution, by working precision (MPFR: value and limbs).
_SCALAR_BYTES = {"double": 8, "long-double": 16, "float128": 16, "dd": 16, "qd": 32}


def _memory_bytes():
    """The machine's physical memory in bytes, or None where the platform does not say."""
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def _check_output_memory(n_steps, what, n, precision):
    """Refuses, before anything is allocated, a fixed-step run whose every-step output cannot fit in memory:
    the C++ Solution, its float64 copy and the numpy arrays each hold every state (t, q, v)."""
    mem = _memory_bytes()
    if not mem:
        return
    if precision.startswith("mpfr"):
        bits = int(precision.split(":", 1)[1]) if ":" in precision else 256
        scalar = 32 + bits // 8
    else:
        scalar = _SCALAR_BYTES.get(precision, 8)
    per_state = (1 + 2 * n) * (scalar + 2 * 8) + 2 * 40  # the Solution, two float64 copies; vector headers
    need = (n_steps + 1) * per_state
    if need > mem:
        raise ValueError(f"{what}: saving every step ({n_steps + 1} states of {n} coordinates) needs about "
                         f"{need / 1e9:.3g} GB, more than this machine's {mem / 1e9:.3g} GB of memory; give "
                         "t_eval (the output times) or fewer steps")


def _checkpoint_args(checkpoint, checkpoint_at, restart, t0, t1):
    """(checkpoint time or NaN, checkpoint file or '', restart file or '')."""
    if (checkpoint is None) != (checkpoint_at is None):
        raise ValueError("checkpoint (a file) and checkpoint_at (a time) go together")
    ck_at, ck_file, restart_file = math.nan, "", ""
    if checkpoint is not None:
        ck_file = os.fspath(checkpoint)
        if isinstance(ck_file, bytes) or not ck_file:
            raise ValueError("checkpoint must be a file name")
        if isinstance(checkpoint_at, bool) or not isinstance(checkpoint_at, numbers.Real):
            raise TypeError(f"checkpoint_at must be a number, got {type(checkpoint_at).__name__}")
        ck_at = float(checkpoint_at)
        d = 1.0 if t1 >= t0 else -1.0
        if not (math.isfinite(ck_at) and d * (ck_at - t0) >= 0 and d * (t1 - ck_at) > 0):
            raise ValueError(f"checkpoint_at must lie in the span, before its end, got {checkpoint_at!r}")
    if restart is not None:
        restart_file = os.fspath(restart)
        if isinstance(restart_file, bytes) or not restart_file:
            raise ValueError("restart must be a file name")
        if restart_file == ck_file:
            raise ValueError("checkpoint and restart name the same file")
    return ck_at, ck_file, restart_file


def _takes_velocity(force):
    """Whether a force is written force(t, q, v): three positional parameters without defaults."""
    try:
        params = inspect.signature(force).parameters.values()
    except (TypeError, ValueError):  # a builtin without a signature: force(t, q)
        return False
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return False
    required = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and p.default is p.empty]
    return len(required) == 3


def solve(force, q0=None, v0=None, t_span=None, method="M8", h=None, steps=None, rtol=None, atol=None,
          t_eval=None, events=None, dense_output=False, precision="double", keep_complex=False,
          progress=False, max_steps=10_000_000, bits=None, checkpoint=None, checkpoint_at=None, restart=None):
    """Integrate q'' = a(t, q) or a(t, q, v) from (q0, v0) over t_span with a method of the catalog (the
    library's solve()).

    Parameters
    ----------
    force : callable or nystrom.problems.Problem
        ``force(t, q) -> array`` of exactly ``q``'s shape (called once per force evaluation with the time of
        the stage; exceptions propagate unchanged), or a built-in problem (runs entirely in C++ with the GIL
        released). The time is integrated as one more coordinate (velocity 1), exactly by every method;
        complex-coefficient methods pass complex ``t`` and ``q`` (use numpy functions, not ``math``).
        ``force(t, q, v)`` (three parameters without defaults) is a velocity-dependent force: it runs with
        the methods for y'' = f(t, y, y') only (``GBS``; the others are refused with ValueError).
    q0, v0 : array_like
        Initial positions and velocities (any shape, the same for both). Default for a built-in problem:
        its initial state.
    t_span : (t0, t1)
        The time span; t1 < t0 integrates backward.
    method : str
        A catalog name or specification (``nystrom.methods()``): ``"M8"``, ``"Yoshida6"``,
        ``"DP12-adaptive"``, ``"mpe:1,2,3"``, ``"M10-adaptive"``, ``"GBS"``, ...
    h, steps : float, int
        Fixed steps: the step size (the last step ends on t1) or the number of steps over t_span.
    rtol, atol : float
        Adaptive steps: the relative and absolute tolerances (>= 0, not both 0; one alone sets both;
        rtol = 0 with atol > 0: absolute error control only). Adaptive methods
        (RKN pairs such as ``DP12-adaptive``, ``M<2n>-adaptive``, ``GBS``) take them; a multi-product method
        given a tolerance runs as its adaptive form (``M10`` as ``M10-adaptive``). Without h, steps, rtol
        and atol, adaptive methods use rtol = 1e-9 and a fixed-step method is refused (ValueError: a
        fixed-step method needs a positive step size h or a number of steps).
    t_eval : array_like
        Output times, monotone in the direction of integration, inside t_span (each a partial step of the
        method from the step end before it). Default: every step end (a fixed-step run whose every state
        cannot fit in memory is refused before it starts).
    events : callable or list of callables
        ``event(t, q, v) -> float``; a zero crossed within a step is located on partial steps of the
        method. Optional attributes ``terminal`` (stop at the first zero) and ``direction`` (>0: zeros
        where g rises with t, <0: where it falls, in a backward run too; scipy's is along the integration).
    dense_output : bool
        Keep ``sol(t) -> (q, v)`` (:class:`DenseSolution`; one force evaluation per step end, counted in
        ``output_force_evals``).
    precision : str
        ``"double"``; built-in problems (Kepler, HarmonicOscillator, HenonHeiles) also ``"long-double"``,
        ``"float128"``, ``"dd"``, ``"qd"`` and ``"mpfr"`` (with ``bits``, or ``"mpfr:BITS"``): results in
        float64, the final state in full precision in ``q_str``/``v_str``.
    keep_complex : bool
        Complex-coefficient methods: keep the complexified state between steps.
    progress : bool or callable
        True: a progress bar (tqdm if installed, else a line on stderr); a callable gets ``progress(t)``.
    max_steps : int
        Adaptive steps: the most steps (accepted and rejected) of the run.
    bits : int
        precision="mpfr": the working precision in bits.
    checkpoint, checkpoint_at : path, float
        Write the integrator's whole state (solve/checkpoint.hpp: exact hexadecimal text) to the file
        ``checkpoint`` at the first step boundary at or after ``checkpoint_at``, while the run goes on
        (double and long double; ``res.checkpoint_t`` is the time it was taken).
    restart : path
        Continue from such a file to t_span[1], with the same problem, method and step settings (the method,
        step settings, precision and built-in problem are checked): the result is bitwise that of the run
        that was never interrupted.

    Returns
    -------
    OdeResult
    """
    def kept(x):
        return np.copy(x) if isinstance(x, np.ndarray) else x

    # What repeats this run for an unpickled dense output (output times, progress and the writing of a checkpoint
    # do not change the steps).
    recipe = dict(force=force, q0=kept(q0), v0=kept(v0), t_span=t_span, method=method, h=h, steps=steps,
                  rtol=rtol, atol=atol, events=events, dense_output=True, precision=precision,
                  keep_complex=keep_complex, max_steps=max_steps, bits=bits, restart=restart)
    if t_span is None:
        raise ValueError("t_span is required")
    t0, t1 = _t_span(t_span)
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    precision = _precision(precision, bits)

    # ---- the problem ---------------------------------------------------------------------------
    velocity = False
    if isinstance(force, Problem):
        problem = force
        velocity = bool(getattr(problem, "_velocity", False))
        params = problem._params()
        q0 = _state("q0", problem.q0 if q0 is None else q0, problem.shape)
        v0 = _state("v0", problem.v0 if v0 is None else v0, problem.shape)
        shape = problem.shape
        to_flat, from_flat = problem._to_flat, problem._from_flat
        kind, py_force = problem._kind, None

        rows = problem._rows_from_flat
    elif callable(force):
        q0 = _state("q0", q0)
        v0 = _state("v0", v0, q0.shape)
        shape = q0.shape
        params, kind, py_force = [], "", force
        velocity = _takes_velocity(force)

        def to_flat(x):
            return np.ascontiguousarray(x, dtype=float).reshape(-1)

        def from_flat(x):
            return np.asarray(x).reshape(shape)

        def rows(a):
            return np.asarray(a).reshape((len(a),) + tuple(shape))
    else:
        raise TypeError("force must be a callable force(t, q) or a nystrom.problems problem, "
                        f"got {type(force).__name__}")

    # ---- step mode -----------------------------------------------------------------------------
    if h is not None and steps is not None:
        raise ValueError("give either h or steps, not both")
    fixed = h is not None or steps is not None
    if fixed and (rtol is not None or atol is not None):
        raise ValueError("fixed steps (h, steps) and tolerances (rtol, atol) exclude each other")
    if isinstance(max_steps, bool) or not isinstance(max_steps, numbers.Integral) or max_steps <= 0:
        raise ValueError("max_steps must be a positive integer")
    if max_steps > _NO_LIMIT:
        raise ValueError(f"max_steps must be at most 2**62, got {max_steps!r}")
    rtol = None if rtol is None else _tolerance("rtol", rtol)
    atol = None if atol is None else _tolerance("atol", atol)
    # Without h, steps, rtol and atol the method runs as named: a fixed-step method is refused (the C++
    # solve()'s error), never switched to an adaptive form; a tolerance turns a multi-product method into its
    # adaptive form.
    tolerance = rtol is not None or atol is not None
    info = _core.solve_method_info(method, tolerance)
    if velocity and not info["velocity"]:
        raise ValueError(_core.velocity_refusal(info["name"]))
    h_value, n_steps = 0.0, 0
    if fixed:
        if steps is not None:
            if isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps <= 0:
                raise ValueError(f"steps must be a positive integer, got {steps!r}")
            if steps > _NO_LIMIT:
                raise ValueError(f"steps must be at most 2**62, got {steps!r}")
            n_steps = int(steps)
        else:
            h_value = _positive("h", h)
        rtol = atol = 0.0
    else:
        if not tolerance and not info["adaptive"]:
            raise ValueError(f"method '{info['name']}' runs with fixed steps: {FIXED_STEP_NEEDS}")
        if info["complex"]:
            raise ValueError(f"method '{info['name']}' has complex coefficients: adaptive steps need a method "
                             "with real coefficients (give h or steps)")
        if not info["adaptive"]:
            raise ValueError(f"method '{info['name']}' runs with fixed steps: rtol and atol apply to adaptive "
                             f"methods only; {FIXED_STEP_NEEDS}")
        if rtol is None and atol is None:
            rtol, atol = 1e-9, 0.0
        elif rtol is None:
            rtol = atol
        elif atol is None:
            atol = 0.0
        if rtol == 0 and atol == 0:
            raise ValueError("rtol and atol must not both be 0 for adaptive steps (rtol = 0: absolute control by atol)")
    evs = _events(events, from_flat)
    ck_at, ck_file, restart_file = _checkpoint_args(checkpoint, checkpoint_at, restart, t0, t1)
    # What a checkpoint must match besides the method: the problem (its parameters and initial state) and
    # everything that defines the steps (the end of the span only where it sets the step size).
    start = hashlib.sha256(to_flat(q0).tobytes() + to_flat(v0).tobytes()).hexdigest()[:32]  # the initial state
    ck_problem = " ".join([kind or "python-force", "params=" + ",".join(float(p).hex() for p in params),
                           f"start={start}",
                           "shape=" + "x".join(str(n) for n in shape), f"precision={precision}",
                           f"t0={t0.hex()}", f"h={h_value.hex()}", f"steps={n_steps}"] +
                          ([f"t1={t1.hex()}"] if n_steps else []) +
                          [f"rtol={float(rtol).hex()}", f"atol={float(atol).hex()}",
                           f"keep_complex={int(bool(keep_complex))}"])

    if fixed and t_eval is None:
        _check_output_memory(n_steps if n_steps else math.ceil(abs(t1 - t0) / h_value * (1 - 1e-12)),
                             f"steps={n_steps}" if n_steps else f"h={h_value!r}", int(np.prod(shape)), precision)

    # ---- the run ---------------------------------------------------------------------------------
    bar = make_progress(progress, t0, t1)
    t_end = None  # where the run stopped; unknown when it raised (Ctrl-C): then the last time reported
    try:
        d = _core.solve(kind, params, py_force, list(shape), to_flat(q0), to_flat(v0), t0, t1, method, precision,
                        h_value, n_steps, rtol, atol, None if t_eval is None else _t_eval(t_eval, t0, t1), evs,
                        bool(dense_output), bool(keep_complex), _NO_LIMIT if fixed else int(max_steps),
                        None if bar is None else bar.update, ck_at, ck_problem, ck_file, restart_file, velocity)
        if bar is not None:  # a terminal event ends the output at its time
            t_end = t1 if d["status"] == 0 else float(d["t"][-1]) if d["status"] == 1 else None
    finally:
        if bar is not None:
            bar.close(bar.t if t_end is None else t_end)

    # ---- the result --------------------------------------------------------------------------------
    res = OdeResult()
    res.t = d["t"]
    res.q = rows(d["q"])
    res.v = rows(d["v"])
    res.force_evals = int(d["force_evals"])
    res.output_force_evals = int(d["output_force_evals"])
    res.steps = int(d["steps"])
    res.rejected = int(d["rejected"])
    res.precise_products = bool(d["precise_products"])
    res.status = int(d["status"])
    res.message = d["message"]
    res.success = res.status >= 0
    if restart is not None:
        recipe["restart"], recipe["restart_text"] = None, d["restart_text"]
    res.sol = None if d["sol"] is None else DenseSolution(d["sol"], rows, shape, recipe)
    if evs:
        hits = [[x for x in d["events"] if x[0] == k] for k in range(len(evs))]
        n_flat = int(np.prod(shape))

        def states(hs, j):  # (len(hs),) + shape, also for an event that never fired
            return rows(np.array([x[j][0] for x in hs], dtype=float).reshape(len(hs), n_flat))

        res.t_events = [np.array([x[1] for x in hs], dtype=float) for hs in hits]
        res.q_events = [states(hs, 2) for hs in hits]
        res.v_events = [states(hs, 3) for hs in hits]
    else:
        res.t_events = res.q_events = res.v_events = None
    res.method = info["name"]
    res.precision = precision
    res.h = None if not fixed else (h_value if h_value > 0 else abs(t1 - t0) / n_steps)
    res.solve_seconds = float(d["solve_seconds"])
    res.q_str = list(d["q_str"])
    res.checkpoint_t = d["checkpoint_t"]
    res.v_str = list(d["v_str"])
    return res
