"""First-order systems y' = fun(t, y) in scipy's convention, through nystrom.solve."""
import numpy as np

from . import _core
from ._result import AttrDict
from ._solve import solve


class FirstOrderResult(AttrDict):
    """The result of :func:`solve_ivp`: ``t``, ``y`` (shape ``(n, len(t))`` as scipy's), ``sol`` (``sol(t)`` ->
    y, or None), ``t_events``/``y_events``, ``nfev`` (= ``force_evals``, calls of fun by the method),
    ``output_force_evals``, ``steps``, ``rejected``, ``status``, ``message``, ``success``, ``method``."""

    def __repr__(self):
        keys = ("message", "success", "status", "method", "nfev", "steps")
        return "\n".join(f"{k:>8}: {self[k]!r}" for k in keys if k in self)


class FirstOrderDense:
    """``sol(t) -> y``: the dense output of a first-order run (shape ``(n,)`` for a scalar t, ``(n, len(t))``
    for an array of times, as scipy's OdeSolution)."""

    def __init__(self, second_order):
        self._sol = second_order

    @property
    def t_min(self):
        return self._sol.t_min

    @property
    def t_max(self):
        return self._sol.t_max

    def __call__(self, t):
        _, y = self._sol(t)
        return np.asarray(y).T


def _wrap_event(e):
    def g(t, q, v):
        return e(t, v)

    g.direction = getattr(e, "direction", 0)
    g.terminal = getattr(e, "terminal", False)
    g.__name__ = getattr(e, "__name__", "event")
    return g


def solve_ivp(fun, t_span, y0, method="GBS", t_eval=None, dense_output=False, events=None, rtol=None, atol=None,
              h=None, steps=None, max_steps=10_000_000, progress=False):
    """Integrate the first-order system y' = fun(t, y) from y(t0) = y0 over t_span (scipy's convention).

    It runs as the velocity-dependent second-order problem q'' = fun(t, q') with v = y (q, its integral, is
    carried along and costs no call of fun): any method for velocity-dependent forces can be named (``GBS``,
    the default; ``nystrom.methods()`` entries with ``velocity``); any other is refused with ValueError.

    Parameters
    ----------
    fun : callable
        ``fun(t, y) -> array`` of y's shape (1-D).
    t_span : (t0, t1)
        The span; t1 < t0 integrates backward.
    y0 : array_like, 1-D
    method : str
        ``"GBS"`` (Gragg-Bulirsch-Stoer extrapolation on Gragg's modified midpoint rule, adaptive), ``"DOP853"``,
        ``"Fine5-adaptive"``, ``"mpe-midpoint-adaptive:1,2,3,4"`` (the multi-product expansion of order 2n over
        Gragg's rule, adaptive), or ``"mpe-midpoint:1,2,3"`` (the same with ``h`` or ``steps``).
    t_eval, dense_output, rtol, atol, h, steps, max_steps, progress
        As :func:`nystrom.solve` (rtol = 1e-9 when neither tolerance is given).
    events : callable or list of callables
        ``event(t, y) -> float`` with optional ``terminal`` and ``direction`` attributes.

    Returns
    -------
    FirstOrderResult
    """
    if not callable(fun):
        raise TypeError(f"fun must be a callable fun(t, y), got {type(fun).__name__}")
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    info = _core.solve_method_info(method, rtol is not None or atol is not None)
    if not info["velocity"]:
        raise ValueError(_core.first_order_refusal(info["name"]))
    y0 = np.asarray(y0, dtype=float)
    if y0.ndim != 1:
        raise ValueError(f"y0 must be one-dimensional, got shape {y0.shape}")
    if events is not None:
        events = [_wrap_event(e) for e in ([events] if callable(events) else events)]

    def force(t, q, v):
        return fun(t, v)

    r = solve(force, np.zeros_like(y0), y0, t_span, method=method, rtol=rtol, atol=atol, h=h, steps=steps, t_eval=t_eval,
              events=events, dense_output=dense_output, max_steps=max_steps, progress=progress)
    res = FirstOrderResult()
    res.t = r.t
    res.y = np.asarray(r.v).T
    res.sol = None if r.sol is None else FirstOrderDense(r.sol)
    res.t_events = r.t_events
    res.y_events = None if r.v_events is None else list(r.v_events)
    res.nfev = res.force_evals = r.force_evals
    res.output_force_evals = r.output_force_evals
    res.steps = r.steps
    res.rejected = r.rejected
    res.status = r.status
    res.message = r.message
    res.success = r.success
    res.method = r.method
    return res
