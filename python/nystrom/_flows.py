"""nystrom.flows: built-in problems with velocity-dependent forces whose flows are exact (nystrom/velocity/solve.hpp,
the solver of ``nystrom flows``): a rotating frame (Arenstorf's orbit of the restricted three-body problem), a
charged particle in a uniform magnetic field (the helix with the E x B drift, a Penning trap) and linear friction
(the damped driven oscillator), integrated by any real splitting or multi-product method of the catalog.

Every parameter left as None keeps the library's default, the same as the command line's; the checks of the
input are the library's (ValueError with its one-line message).

>>> import nystrom
>>> res = nystrom.flows("arenstorf", method="KL8", periods=1)
>>> res.return_error < 1e-8, res.force_evals
(True, 340000)

Problems of your own, with forces written in Python (each kick calls them once, with the GIL held):
``rotating_frame(gradient, q0, v0, dt, steps, omega=...)``, ``magnetic(q0, v0, dt, steps, b=..., force=...)`` and
``damped(force, q0, v0, dt, steps, gamma=...)``.

>>> import numpy as np
>>> r = nystrom.damped(lambda t, q: -q, [1.0], [0.0], dt=0.01, steps=100, gamma=0.0, method="FR")
>>> bool(abs(r.q[0] - np.cos(1.0)) < 1e-9)
True
"""

import numbers

from . import _core
from ._result import AttrDict

__all__ = ["flows", "rotating_frame", "magnetic", "damped", "FlowResult"]


class FlowResult(AttrDict):
    """The result of :func:`nystrom.flows` (a dict whose keys are also attributes).

    Attributes: ``q``, ``v`` (the final state, 3 components; the damped oscillator 1), ``time`` (the end time,
    negative for a backward run), ``dt``, ``steps``, ``force_evals`` (kicks), ``flows`` (exact flows applied),
    ``method``, ``order``, ``symplectic``; ``invariant_name`` ("Jacobi integral", "energy" or None) with
    ``invariant0``, ``invariant`` and ``invariant_error`` (the largest change over the samples and the end);
    ``position_error``, ``velocity_error`` (max-norm against the exact solution: helix, penning, damped; else
    NaN); ``return_error`` (|q - q0|) and ``periods`` (Arenstorf); ``sample_times``, ``sample_q``, ``sample_v``,
    ``sample_invariant`` (with ``samples``); ``seconds``, ``problem``, ``precision``.
    """

    def __repr__(self):
        return (f"FlowResult(problem={self.problem!r}, method={self.method!r}, time={self.time!r}, "
                f"force_evals={self.force_evals!r})")


def _opt_real(name, x):
    if x is None:
        return None
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(x).__name__}")
    return float(x)


def _opt_int(name, x):
    if x is None:
        return None
    if isinstance(x, bool) or not isinstance(x, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(x).__name__}")
    x = int(x)
    if not -2**62 <= x < 2**62:
        raise ValueError(f"{name} is out of range, got {x}")
    return x


def _opt_vector(name, x):
    if x is None:
        return None
    if isinstance(x, numbers.Real) and not isinstance(x, bool):
        return [float(x)]
    try:
        values = list(x)
    except TypeError:
        raise TypeError(f"{name} must be a number or a sequence of real numbers") from None
    for v in values:
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise TypeError(f"{name} must be a number or a sequence of real numbers")
    return [float(v) for v in values]


def flows(problem="arenstorf", method=None, periods=None, steps_per_period=None, samples=None, *, mu=None, b=None,
          e=None, kappa=None, gamma=None, omega0=None, drive=None, drive_frequency=None, q0=None, v0=None,
          precision="double"):
    """Integrates a built-in problem with an exact velocity-dependent flow (docs/velocity.md).

    problem: ``"arenstorf"`` (rotating frame, Hairer-Norsett-Wanner's periodic orbit; ``mu``), ``"helix"``
    (uniform ``b`` and ``e``, exact), ``"penning"`` (``b`` along z, quadrupole ``kappa``, exact) or ``"damped"``
    (q'' = -gamma q' - omega0^2 q + drive cos(drive_frequency t), exact). method: a real splitting or
    multi-product method of the catalog (default KL8). periods: the span in periods of the problem (default 1;
    negative: backward in time); steps_per_period (default: arenstorf 20000, helix and penning 32, damped 64);
    samples: record this many evenly spaced states. q0, v0: the initial state (default: the problem's own).
    precision: ``"double"`` or ``"long-double"``. Defaults are those of ``nystrom flows``.
    """
    if not isinstance(problem, str):
        raise TypeError(f"problem must be a string, got {type(problem).__name__}")
    if method is not None and not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    if not isinstance(precision, str):
        raise TypeError(f"precision must be a string, got {type(precision).__name__}")
    d = _core.flows(problem=problem, method=method, periods=_opt_real("periods", periods),
                    steps_per_period=_opt_int("steps_per_period", steps_per_period),
                    samples=_opt_int("samples", samples), mu=_opt_real("mu", mu), b=_opt_vector("b", b),
                    e=_opt_vector("e", e), kappa=_opt_real("kappa", kappa), gamma=_opt_real("gamma", gamma),
                    omega0=_opt_real("omega0", omega0), drive=_opt_real("drive", drive),
                    drive_frequency=_opt_real("drive_frequency", drive_frequency), q0=_opt_vector("q0", q0),
                    v0=_opt_vector("v0", v0), precision=precision)
    return FlowResult(d)


def _steps(dt, steps, samples):
    return _opt_real("dt", dt), _opt_int("steps", steps), 0 if samples is None else _opt_int("samples", samples)


def _callable(name, f, required):
    if f is None:
        if required:
            raise TypeError(f"{name} is required")
        return None
    if not callable(f):
        raise TypeError(f"{name} must be callable")
    return f


def rotating_frame(gradient, q0, v0, dt, steps, *, omega=(0.0, 0.0, 1.0), potential=None, method=None, samples=0):
    """q'' = -2 Omega x v - Omega x (Omega x q) - grad U(q) in a frame rotating with ``omega`` (3 components).

    gradient(q) returns grad U (3 numbers); potential(q), optional, returns U for the Jacobi integral
    (``invariant``). q0, v0: 3 components (v0 is the velocity in the rotating frame). ``dt`` may be negative
    (backward in time). Any real splitting or multi-product method of the catalog (default KL8).
    """
    dt, steps, samples = _steps(dt, steps, samples)
    d = _core.flows_custom(family="rotating", axis=_opt_vector("omega", omega), gamma=0.0,
                           q0=_opt_vector("q0", q0), v0=_opt_vector("v0", v0), t0=0.0,
                           force=_callable("gradient", gradient, True),
                           potential=_callable("potential", potential, False), method=method or "", dt=dt,
                           steps=steps, samples=samples)
    return FlowResult(d)


def magnetic(q0, v0, dt, steps, *, b=(0.0, 0.0, 1.0), force=None, potential=None, method=None, samples=0):
    """q'' = v x b + a(q): a charged particle in the uniform field b = (charge/mass) B (3 components).

    force(q), optional, returns a(q) = (charge/mass) E(q) (3 numbers); potential(q), optional, returns phi with
    a = -grad phi for the energy (``invariant``). ``dt`` may be negative. Default method KL8.
    """
    dt, steps, samples = _steps(dt, steps, samples)
    d = _core.flows_custom(family="magnetic", axis=_opt_vector("b", b), gamma=0.0, q0=_opt_vector("q0", q0),
                           v0=_opt_vector("v0", v0), t0=0.0, force=_callable("force", force, False),
                           potential=_callable("potential", potential, False), method=method or "", dt=dt,
                           steps=steps, samples=samples)
    return FlowResult(d)


def damped(force, q0, v0, dt, steps, *, gamma, t0=0.0, method=None, samples=0):
    """q'' = -gamma v + a(t, q) in d = len(q0) dimensions from the time t0.

    force(t, q) returns a(t, q) (d numbers; None: no force). ``dt`` may be negative. Default method KL8.
    """
    dt, steps, samples = _steps(dt, steps, samples)
    d = _core.flows_custom(family="damped", axis=[], gamma=_opt_real("gamma", gamma), q0=_opt_vector("q0", q0),
                           v0=_opt_vector("v0", v0), t0=_opt_real("t0", t0),
                           force=_callable("force", force, False), potential=None, method=method or "", dt=dt,
                           steps=steps, samples=samples)
    return FlowResult(d)
