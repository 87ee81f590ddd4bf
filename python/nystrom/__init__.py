"""nystrom: high-order splitting, Runge-Kutta-Nyström and multi-product integrators for q'' = a(q); GBS
extrapolation for velocity-dependent forces q'' = a(t, q, v) and first-order systems y' = f(t, y)
(``solve_ivp``).

    import numpy as np, nystrom
    res = nystrom.solve(lambda t, q: -q / np.linalg.norm(q) ** 3, [1.9, 0.0], [0.0, 0.2294157338705618],
                        t_span=(0, 20 * np.pi), method="M8", steps=20000)
    res.q[-1], res.force_evals

Built-in problems (``nystrom.problems``), the exact velocity-dependent flows (``nystrom.flows``: a rotating
frame, a magnetic field, friction), the split-operator Schrödinger solver (``nystrom.quantum``), diffusion
(``nystrom.smoluchowski``, ``nystrom.thermal``), Langevin path ensembles (``nystrom.langevin``) and the exact
stationary law of a Langevin splitting (``nystrom.stationary_law``) run in C++
with the GIL released; ``nystrom.ensemble`` maps runs over a process pool, a Dask client or an MPI pool;
``nystrom.plot`` draws orbits, energy errors and work-precision charts.
"""

import json
import numbers

from . import _core
from ._solve import DenseSolution, OdeResult, solve
from ._first_order import FirstOrderResult, solve_ivp
from ._flows import FlowResult, damped, flows, magnetic, rotating_frame
from ._quantum import QuantumResult, quantum
from ._diffusion import SmoluchowskiResult, ThermalResult, smoluchowski, thermal
from ._langevin import LangevinResult, StationaryLawResult, langevin, stationary_law
from .ensemble import ensemble
from . import problems

__version__ = _core.__version__  # the CMake project version, as `nystrom --version` prints it

__all__ = ["methods", "method_info", "coeffs", "bch", "solve", "solve_ivp", "OdeResult", "FirstOrderResult",
           "DenseSolution", "quantum", "QuantumResult", "smoluchowski", "SmoluchowskiResult", "thermal", "ThermalResult",
           "flows", "rotating_frame", "magnetic", "damped", "FlowResult",
           "langevin", "LangevinResult", "stationary_law", "StationaryLawResult", "problems", "ensemble", "plot"]


def methods():
    """The catalog: one dict per method with name, family, order, stages, forces_per_step, fsal,
    symmetric, symplectic, complex, adaptive, order_control (an adaptive multi-product expansion choosing its order
    per step), velocity (integrates velocity-dependent forces), published_digits,
    tolerance_exponent, tolerance_anchor, aliases, source, description; force_evals_per_step and
    velocity_dependent repeat forces_per_step and velocity under the names of ``nystrom methods --json``, so that
    both records are the same."""
    return _core.methods()


def method_info(spec):
    """The catalog record of a method specification: a name or alias, ``M<2n>``, ``mpe:1,2,3``,
    ``mpe-vv:1,2,3``, ``M<2n>-adaptive``, ``adjoint:NAME``, ``triplejump:P``, ``suzuki:P``, ..."""
    if not isinstance(spec, str):
        raise TypeError(f"method must be a string, got {type(spec).__name__}")
    return _core.method_info(spec)


def coeffs(what, seq=None, order=None, n=None, sum=None, digits=20):
    """Coefficients, as ``nystrom coeffs`` prints them with --json.

    ``coeffs("Yoshida6")``: any method's table (splitting sub-steps, RKN tableau or MPE sequence), decimals
    with ``digits`` digits; ``coeffs("mpe", seq=[1, 2, 3])``, ``coeffs("mpe", order=8)`` or
    ``coeffs("mpe", n=4, sum=12)``: exact multi-product coefficients (Chin eqs 14-15) as rational strings.
    """
    if not isinstance(what, str):
        raise TypeError(f"what must be a string, got {type(what).__name__}")
    if what != "mpe":
        if seq is not None or order is not None or n is not None or sum is not None:
            raise ValueError("seq, order, n and sum apply to coeffs('mpe', ...) only")
        return _core.method_coeffs(what, _integer("digits", digits, 1, 1000))
    given = (seq is not None) + (order is not None) + (n is not None or sum is not None)
    if given != 1:
        raise ValueError("coeffs('mpe') needs exactly one of seq, order, or n with sum")
    if seq is not None:
        if isinstance(seq, (str, bytes)) or not hasattr(seq, "__iter__"):
            raise TypeError(f"seq must be a sequence of integers, got {type(seq).__name__}")
        k = []
        for x in seq:
            if isinstance(x, bool) or not isinstance(x, numbers.Integral):
                raise TypeError(f"seq must be a sequence of integers, got a member of type {type(x).__name__}")
            if x <= 0:
                raise ValueError(f"MPE sequence members must be positive integers, got {int(x)}")
            if x > 1_000_000:
                raise ValueError(f"MPE sequence member too large: {int(x)}")
            k.append(int(x))
    elif order is not None:
        if int(order) != order or order < 2 or order % 2:
            raise ValueError("order must be a positive even number")
        if order > 400:
            raise ValueError("order must be at most 400")
        k = list(range(1, order // 2 + 1))
    else:
        if n is None or sum is None:
            raise ValueError("n and sum must both be positive")
        n = _integer("n", n, 1, 200)  # an MPE sequence has at most 200 members
        k = _core.optimal_mpe_sequence(n, _integer("sum", sum, n * (n + 1) // 2, 200 * 1_000_000))
    return _core.mpe_coeffs(k)


def bch(method, degree=7, basis="hall", algebra="rkn", bits=192, tolerance=0.0):
    """The BCH series of a splitting method, as ``nystrom bch --json``: the coefficients of H - Z (the
    method's modified Hamiltonian minus the exact one) in a Lie basis for every degree up to ``degree``,
    the algebraic order and the leading error terms (Gürkan, sec. 4); every term with re, im, abs and, when
    computed exactly, the rational ``exact``. basis: "hall" or "lyndon"; algebra:
    "rkn" (q'' = a(q): [V,[V,[T,V]]] = 0) or "free"."""
    if not isinstance(method, str):
        raise TypeError(f"method must be a string, got {type(method).__name__}")
    degree = _integer("degree", degree, 1, _core.max_lie_degree)
    bits = _integer("bits", bits, 64, 4096)
    return json.loads(_core.bch_json(method, degree, str(basis), str(algebra), bits, float(tolerance)))


def _integer(name, x, lo, hi):
    """x as an int in [lo, hi], or a one-line TypeError/ValueError (the C++ library's words for the range)."""
    if isinstance(x, bool) or not isinstance(x, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(x).__name__}")
    if not lo <= x <= hi:
        raise ValueError(f"{name} must be between {lo} and {hi}, got {int(x)}")
    return int(x)


def __getattr__(name):
    # matplotlib is imported only when plotting is asked for.
    if name == "plot":
        import importlib

        return importlib.import_module(".plot", __name__)
    raise AttributeError(f"module 'nystrom' has no attribute {name!r}")
