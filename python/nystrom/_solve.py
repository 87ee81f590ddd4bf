"""nystrom.solve: one driver for Python forces and built-in problems.

The integration itself runs in the library's engines (nystrom._core); this module chooses the step
mode, cuts the time span at the requested output times, records the steps, locates events and builds
the dense-output interpolant.
"""

import math
import numbers

import numpy as np

from . import _core
from ._progress import make_progress
from .problems import Problem

__all__ = ["solve", "OdeResult", "DenseSolution"]

# Steps per advance when events are watched: terminal events stop the integration at most this many
# steps after the event.
_EVENT_CHUNK = 512


class OdeResult(dict):
    """The result of :func:`nystrom.solve` (a dict whose keys are also attributes).

    Attributes: ``t`` (output times), ``q``, ``v`` (positions and velocities, shape ``(len(t),) +
    q0.shape``), ``force_evals``, ``steps``, ``rejected``, ``status`` (0: reached the end of t_span,
    1: a terminal event, -1: failure), ``message``, ``success``, ``sol`` (a :class:`DenseSolution` when
    ``dense_output=True``), ``t_events``, ``q_events``, ``v_events`` (one array per event function),
    ``method``, ``precision``, ``h`` (fixed steps: the step size), ``q_str``/``v_str`` (the final state
    in full working precision, as decimal strings).
    """

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    __setattr__ = dict.__setitem__

    def __repr__(self):
        keys = ("message", "success", "status", "method", "force_evals", "steps")
        body = ", ".join(f"{k}={self[k]!r}" for k in keys if k in self)
        return f"OdeResult({body}, t: {len(self.get('t', []))} points)"

    def __reduce__(self):
        return (OdeResult, (dict(self),))


class DenseSolution:
    """Continuous solution between the steps: a quintic Hermite interpolant through the positions,
    velocities and accelerations at every step (local error O(h^6)).

    ``sol(t)`` returns ``(q, v)``; for an array of times the leading axis runs over the times.
    """

    def __init__(self, t, q, v, a, shape):
        self.t = np.asarray(t, dtype=float)
        self._q = np.asarray(q, dtype=float).reshape(len(self.t), -1)
        self._v = np.asarray(v, dtype=float).reshape(len(self.t), -1)
        self._a = np.asarray(a, dtype=float).reshape(len(self.t), -1)
        self._shape = tuple(shape)

    @property
    def t_min(self):
        return float(self.t[0])

    @property
    def t_max(self):
        return float(self.t[-1])

    def __call__(self, t):
        ts = np.asarray(t, dtype=float)
        scalar = ts.ndim == 0
        ts = np.atleast_1d(ts)
        if not np.all(np.isfinite(ts)):
            raise ValueError("sol(t): times must be finite")
        lo, hi = self.t[0], self.t[-1]
        span = hi - lo
        if np.any(ts < lo - 1e-12 * abs(span)) or np.any(ts > hi + 1e-12 * abs(span)):
            raise ValueError(f"sol(t): times must lie in [{lo!r}, {hi!r}]")
        i = np.clip(np.searchsorted(self.t, ts, side="right") - 1, 0, len(self.t) - 2)
        t0, t1 = self.t[i], self.t[i + 1]
        h = (t1 - t0)[:, None]
        s = ((ts - t0) / (t1 - t0))[:, None]
        q0, q1 = self._q[i], self._q[i + 1]
        v0, v1 = self._v[i] * h, self._v[i + 1] * h
        a0, a1 = self._a[i] * h * h, self._a[i + 1] * h * h
        # Quintic Hermite basis on [0, 1] for value, first and second derivative at both ends.
        s2, s3 = s * s, s * s * s
        s4, s5 = s3 * s, s3 * s2
        h00 = 1 - 10 * s3 + 15 * s4 - 6 * s5
        h01 = 10 * s3 - 15 * s4 + 6 * s5
        h10 = s - 6 * s3 + 8 * s4 - 3 * s5
        h11 = -4 * s3 + 7 * s4 - 3 * s5
        h20 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5
        h21 = 0.5 * s3 - s4 + 0.5 * s5
        q = h00 * q0 + h01 * q1 + h10 * v0 + h11 * v1 + h20 * a0 + h21 * a1
        d00 = -30 * s2 + 60 * s3 - 30 * s4
        d10 = 1 - 18 * s2 + 32 * s3 - 15 * s4
        d11 = -12 * s2 + 28 * s3 - 15 * s4
        d20 = s - 4.5 * s2 + 6 * s3 - 2.5 * s4
        d21 = 1.5 * s2 - 4 * s3 + 2.5 * s4
        v = (d00 * q0 - d00 * q1 + d10 * v0 + d11 * v1 + d20 * a0 + d21 * a1) / h
        q = q.reshape((len(ts),) + self._shape)
        v = v.reshape((len(ts),) + self._shape)
        if scalar:
            return q[0], v[0]
        return q, v


def _positive(name, x):
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a number, got {type(x).__name__}")
    x = float(x)
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"{name} must be positive and finite, got {x!r}")
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
    if not t1 > t0:
        raise ValueError(f"t_span must be increasing: got ({t0!r}, {t1!r})")
    return t0, t1


def _events(events):
    if events is None:
        return []
    if callable(events):
        events = [events]
    events = list(events)
    for e in events:
        if not callable(e):
            raise TypeError("events must be callables event(t, q, v) -> float")
    return events


def _find_root(fn, a, b, fa, fb):
    """Root of fn in [a, b] with fa, fb of opposite signs (Illinois variant of regula falsi)."""
    side = 0
    for _ in range(200):
        c = (a * fb - b * fa) / (fb - fa)
        if not (min(a, b) <= c <= max(a, b)):
            c = 0.5 * (a + b)
        fc = fn(c)
        if fc == 0 or abs(b - a) <= 4e-16 * max(1.0, abs(a), abs(b)):
            return c
        if (fc > 0) == (fb > 0):
            b, fb = c, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = c, fc
            if side == 1:
                fb *= 0.5
            side = 1
    return c


def _force_row(force, t, q_row, from_flat):
    """force(t, q) at a recorded state, as a row of the stepper's state (zero for the time coordinate)."""
    q = from_flat(q_row)
    r = np.asarray(force(float(t), q), dtype=float).reshape(-1)
    if r.size != q.size:
        raise ValueError(f"force(t, q) returned {r.size} values for a state of {q.size} coordinates")
    out = np.zeros(len(q_row))
    out[: r.size] = r
    return out


def _accelerations(stepper, force, t, q_flat, from_flat):
    """Accelerations at the recorded steps for the interpolant, and the force calls they took."""
    a = np.empty_like(q_flat)
    if force is None:
        for i in range(len(t)):
            a[i] = stepper.acceleration(q_flat[i])
        return a, 0
    for i in range(len(t)):
        a[i] = _force_row(force, t[i], q_flat[i], from_flat)
    return a, len(t)


def solve(force, q0=None, v0=None, t_span=None, method="M8", h=None, steps=None, rtol=None, atol=None,
          t_eval=None, events=None, dense_output=False, precision="double", keep_complex=False,
          progress=False, max_steps=10_000_000):
    """Integrate q'' = a(q) from (q0, v0) over t_span with a method of the catalog.

    Parameters
    ----------
    force : callable or nystrom.problems.Problem
        ``force(t, q) -> array`` shaped like ``q`` (called once per force evaluation with the time of the
        stage; exceptions propagate unchanged), or a built-in problem (runs entirely in C++ with the GIL
        released). The time is integrated as one more coordinate (velocity 1), exactly by every method.
    q0, v0 : array_like
        Initial positions and velocities (any shape, the same for both). Default for a built-in problem:
        its initial state.
    t_span : (t0, t1)
        Increasing time span.
    method : str
        A catalog name or specification (``nystrom.methods()``): ``"M8"``, ``"Yoshida6"``,
        ``"DP12-adaptive"``, ``"mpe:1,2,3"``, ``"M10-adaptive"``, ...
    h, steps : float, int
        Fixed steps: the step size (rounded so that a whole number of steps fits each output interval)
        or the number of steps over t_span.
    rtol, atol : float
        Adaptive steps with tolerance ``min(rtol, atol)`` (the library's mixed absolute/relative norm).
        Multi-product methods and RKN pairs with an embedded formula (``DP12-adaptive``) adapt.
        Without h, steps, rtol and atol, adaptive methods use rtol = 1e-9.
    t_eval : array_like
        Output times (increasing, inside t_span); the integration lands on each. Default: every step.
    events : callable or list of callables
        ``event(t, q, v) -> float``; roots are located on the dense interpolant. Optional attributes
        ``terminal`` (stop at the first root) and ``direction`` (>0 rising only, <0 falling only).
    dense_output : bool
        Build ``sol(t) -> (q, v)`` (quintic Hermite; with a Python force it calls the force once per step
        more, counted in ``interpolant_force_evals``).
    precision : str
        ``"double"``; built-in problems also ``"long-double"``, ``"float128"``, ``"dd"``, ``"qd"``
        (results in float64, the final state in full precision in ``q_str``/``v_str``).
    keep_complex : bool
        Complex-coefficient methods: keep the complexified state between steps.
    progress : bool or callable
        True: a progress bar (tqdm if installed, else a line on stderr); a callable gets ``progress(t)``.
    max_steps : int
        Adaptive steps: the most steps per output interval.

    Returns
    -------
    OdeResult
    """
    if t_span is None:
        raise ValueError("t_span is required")
    t0, t1 = _t_span(t_span)
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    if not isinstance(precision, str):
        raise TypeError(f"precision must be a string, got {type(precision).__name__}")
    info = _core.method_info(method)
    events = _events(events)

    # ---- the problem ---------------------------------------------------------------------------
    if isinstance(force, Problem):
        problem = force
        params = problem._params()
        q0 = _state("q0", problem.q0 if q0 is None else q0, problem.shape)
        v0 = _state("v0", problem.v0 if v0 is None else v0, problem.shape)
        user_shape = problem.shape
        to_flat, from_flat = problem._to_flat, problem._from_flat
        py_force = None
    elif callable(force):
        problem = None
        q0 = _state("q0", q0)
        v0 = _state("v0", v0, q0.shape)
        user_shape = q0.shape
        n_user = q0.size
        to_flat = lambda x: np.ascontiguousarray(x, dtype=float).reshape(-1)  # noqa: E731
        # The stepper's state carries the time as one more coordinate (the last), stripped here.
        from_flat = lambda x: np.asarray(x)[:n_user].reshape(user_shape)  # noqa: E731
        py_force = force
        if precision != "double":
            raise ValueError(f"precision '{precision}' is available for built-in problems only; "
                             "Python forces run in double")
    else:
        raise TypeError("force must be a callable force(t, q) or a nystrom.problems problem, "
                        f"got {type(force).__name__}")

    # ---- step mode -----------------------------------------------------------------------------
    if h is not None and steps is not None:
        raise ValueError("give either h or steps, not both")
    fixed = h is not None or steps is not None
    if fixed and (rtol is not None or atol is not None):
        raise ValueError("fixed steps (h, steps) and tolerances (rtol, atol) exclude each other")
    if not isinstance(max_steps, numbers.Integral) or max_steps <= 0:
        raise ValueError("max_steps must be a positive integer")
    tol = 0.0
    if not fixed:
        tols = [_positive(n, x) for n, x in (("rtol", rtol), ("atol", atol)) if x is not None]
        if not tols:
            if info["family"] != "mpe" and not info["adaptive"]:
                raise ValueError(f"method '{info['name']}' takes fixed steps: give h or steps "
                                 "(or choose an adaptive method and rtol)")
            tols = [1e-9]
        tol = min(tols)
    if steps is not None:
        if isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps <= 0:
            raise ValueError(f"steps must be a positive integer, got {steps!r}")
        h_nominal = (t1 - t0) / int(steps)
    elif h is not None:
        h_nominal = _positive("h", h)
    # Output times.
    if t_eval is not None:
        te = np.asarray(t_eval, dtype=float).reshape(-1)
        if te.size == 0:
            raise ValueError("t_eval is empty")
        if not np.all(np.isfinite(te)):
            raise ValueError("t_eval contains NaN or infinite values")
        if np.any(np.diff(te) <= 0):
            raise ValueError("t_eval must be strictly increasing")
        if te[0] < t0 or te[-1] > t1:
            raise ValueError("t_eval must lie inside t_span")

    # ---- the stepper ---------------------------------------------------------------------------
    common = dict(tol=tol, max_steps=int(max_steps), keep_complex=bool(keep_complex))
    if problem is not None:
        stepper = _core.builtin_stepper(problem._kind, params, int(q0.size), method,
                                        precision=precision, **common)
    else:
        stepper = _core.python_stepper(py_force, list(user_shape), method, **common)
    if py_force is None:
        def state_row(x, t_value, is_velocity):
            return to_flat(x)
    else:
        def state_row(x, t_value, is_velocity):
            return np.append(to_flat(x), 1.0 if is_velocity else t_value)
    stepper.set_state(state_row(q0, t0, False), state_row(v0, t0, True))

    bar = make_progress(progress, t0, t1)
    beat = None if bar is None else bar.update
    need_steps = t_eval is None or dense_output or bool(events)
    # Segments: the output times cut the span (the integration lands on each of them).
    cuts = [t0] + ([] if t_eval is None else [float(x) for x in te if x > t0]) + ([t1] if t_eval is None or
                                                                                  te[-1] < t1 else [])
    cuts = sorted(set(cuts))
    out_t = [t0] if (t_eval is None or te[0] == t0) else []
    q_start, v_start = stepper.state()
    out_q = [q_start.copy()] if out_t else []
    out_v = [v_start.copy()] if out_t else []
    step_t, step_q, step_v = [t0], [q_start.copy()], [v_start.copy()]
    total_steps = total_rejected = 0
    status, message = 0, "The solver successfully reached the end of the integration interval."
    h_used = None
    stop_at = None  # (t, event index) of a terminal event
    ev_t = [[] for _ in events]
    ev_q = [[] for _ in events]
    ev_v = [[] for _ in events]

    def record_block(d):
        if len(d["t"]):
            step_t.extend(d["t"].tolist())
            step_q.extend(list(d["q"]))
            step_v.extend(list(d["v"]))

    try:
        for a, b in zip(cuts[:-1], cuts[1:]):
            if fixed:
                n = max(1, int(math.ceil((b - a) / h_nominal - 1e-9)))
                h_used = (b - a) / n if h_used is None else h_used
                done = 0
                chunk = _EVENT_CHUNK if events else n
                while done < n:
                    m = min(chunk, n - done)
                    ta = a + (b - a) * done / n
                    tb = b if done + m == n else a + (b - a) * (done + m) / n
                    d = stepper.advance_fixed(ta, tb, m, 1 if need_steps else 0, beat)
                    done += m
                    total_steps += d["steps"]
                    if need_steps:
                        first_new = len(step_t)
                        record_block(d)
                        if events:
                            stop_at = _scan_events(events, step_t, step_q, step_v, first_new - 1, stepper,
                                                   py_force, from_flat, ev_t, ev_q, ev_v)
                    if d["failed"]:
                        status, message = -1, d["message"]
                        break
                    if stop_at is not None:
                        break
                    if beat is not None:
                        beat(tb)
            else:
                d = stepper.advance_adaptive(a, b, need_steps, beat)
                total_steps += d["steps"]
                total_rejected += d["rejected"]
                if need_steps:
                    first_new = len(step_t)
                    record_block(d)
                    if events:
                        stop_at = _scan_events(events, step_t, step_q, step_v, first_new - 1, stepper, py_force,
                                               from_flat, ev_t, ev_q, ev_v)
                if d["failed"]:
                    status, message = -1, d["message"]
                if beat is not None:
                    beat(b)
            if status != 0 or stop_at is not None:
                break
            if t_eval is not None and b in set(te.tolist()):
                q_b, v_b = stepper.state()
                out_t.append(b)
                out_q.append(q_b)
                out_v.append(v_b)
    finally:
        if bar is not None:
            bar.close()

    if stop_at is not None:
        status, message = 1, "A termination event occurred."

    # ---- assemble the result --------------------------------------------------------------------
    st = np.asarray(step_t, dtype=float)
    sq = np.asarray(step_q, dtype=float).reshape(len(st), -1)
    sv = np.asarray(step_v, dtype=float).reshape(len(st), -1)
    sol = None
    interp_evals = 0
    if dense_output:
        acc, interp_evals = _accelerations(stepper, py_force, st, sq, from_flat)
        sol = DenseSolution(st, [from_flat(x) for x in sq], [from_flat(x) for x in sv],
                            [from_flat(x) for x in acc], user_shape)
    if t_eval is None:
        ot, oq, ov = st, sq, sv
    else:
        ot = np.asarray(out_t, dtype=float)
        oq = np.asarray(out_q, dtype=float).reshape(len(ot), -1)
        ov = np.asarray(out_v, dtype=float).reshape(len(ot), -1)
    if stop_at is not None:
        keep = ot <= stop_at[0]
        ot, oq, ov = ot[keep], oq[keep], ov[keep]
        ev_i = stop_at[1]
        ot = np.append(ot, ev_t[ev_i][-1])
        oq = np.vstack([oq, state_row(ev_q[ev_i][-1], ot[-1], False)[None, :]])
        ov = np.vstack([ov, state_row(ev_v[ev_i][-1], ot[-1], True)[None, :]])
    res = OdeResult()
    res.t = ot
    res.q = np.stack([from_flat(x) for x in oq]) if len(ot) else np.empty((0,) + tuple(user_shape))
    res.v = np.stack([from_flat(x) for x in ov]) if len(ot) else np.empty((0,) + tuple(user_shape))
    res.force_evals = int(stepper.force_evals)
    res.interpolant_force_evals = int(interp_evals)
    res.steps = int(total_steps)
    res.rejected = int(total_rejected)
    res.status = status
    res.message = message
    res.success = status >= 0
    res.sol = sol
    res.t_events = [np.asarray(x, dtype=float) for x in ev_t] if events else None
    res.q_events = [np.asarray(x, dtype=float).reshape((len(x),) + tuple(user_shape)) for x in ev_q] if events else None
    res.v_events = [np.asarray(x, dtype=float).reshape((len(x),) + tuple(user_shape)) for x in ev_v] if events else None
    res.method = info["name"]
    res.precision = precision
    res.h = h_used
    strs = stepper.state_strings()
    half, n_coords = len(strs) // 2, int(np.prod(user_shape))
    res.q_str = strs[:n_coords]
    res.v_str = strs[half:half + n_coords]
    return res


def _scan_events(events, step_t, step_q, step_v, start, stepper, py_force, from_flat, ev_t, ev_q, ev_v):
    """Looks for roots of the event functions between recorded steps start .. end. Returns (t, index) of
    the first terminal event found, else None. Roots are located on the quintic Hermite interpolant of
    each step."""
    start = max(start, 0)
    terminal_hit = None
    accel_cache = {}

    def acc(i):
        if i not in accel_cache:
            if py_force is None:
                accel_cache[i] = stepper.acceleration(step_q[i])
            else:
                accel_cache[i] = _force_row(py_force, step_t[i], step_q[i], from_flat)
        return accel_cache[i]

    g_prev = [float(e(step_t[start], from_flat(step_q[start]), from_flat(step_v[start]))) for e in events]
    for i in range(start + 1, len(step_t)):
        g_now = [float(e(step_t[i], from_flat(step_q[i]), from_flat(step_v[i]))) for e in events]
        found = []
        for k, e in enumerate(events):
            ga, gb = g_prev[k], g_now[k]
            direction = getattr(e, "direction", 0) or 0
            crossed = (ga < 0 <= gb) or (ga > 0 >= gb)
            if ga == 0:
                crossed = False
            if not crossed:
                continue
            if (direction > 0 and gb < ga) or (direction < 0 and gb > ga):
                continue
            seg = DenseSolution([step_t[i - 1], step_t[i]], [step_q[i - 1], step_q[i]], [step_v[i - 1], step_v[i]],
                                [acc(i - 1), acc(i)], (len(step_q[i]),))

            def g(t, e=e, seg=seg):
                q, v = seg(t)
                return float(e(t, from_flat(q), from_flat(v)))

            tr = step_t[i] if gb == 0 else _find_root(g, step_t[i - 1], step_t[i], ga, gb)
            qr, vr = seg(tr)
            found.append((tr, k, qr, vr))
        for tr, k, qr, vr in sorted(found, key=lambda x: x[0]):
            ev_t[k].append(tr)
            ev_q[k].append(from_flat(qr))
            ev_v[k].append(from_flat(vr))
            if getattr(events[k], "terminal", False):
                terminal_hit = (tr, k)
                break
        if terminal_hit is not None:
            return terminal_hit
        g_prev = g_now
    return None
