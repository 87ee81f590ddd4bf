"""nystrom.smoluchowski and nystrom.thermal: the Smoluchowski equation on a periodic grid
(nystrom/quantum/smoluchowski.hpp, the solver of ``nystrom smoluchowski``) and the partition function from
extrapolated path-integral propagators (nystrom/quantum/thermal.hpp, ``nystrom thermal``).

Both run in C++ with the GIL released; the checks of the input are the library's (ValueError with its one-line
message), this module converts the arguments and wraps the result.

>>> import nystrom
>>> res = nystrom.smoluchowski("harmonic", beta=2.0, box=12.0, grid=128, x0=1.0, dt=0.05, steps=20)
>>> res.exact_solution, res.exact_error < 1e-8
('Ornstein-Uhlenbeck', True)
"""

import numpy as np

from . import _core
from ._quantum import _integer, _real, _vector
from ._result import AttrDict

__all__ = ["smoluchowski", "SmoluchowskiResult", "thermal", "ThermalResult"]


class SmoluchowskiResult(AttrDict):
    """The result of :func:`nystrom.smoluchowski` (a dict whose keys are also attributes).

    Attributes: ``density`` (rho at the end, float64 of shape ``(grid,) * dims`` at x_i = -box/2 + i box/grid),
    ``boltzmann`` (the normalised Boltzmann density e^{-beta U}/Z on the grid), ``mass`` (1 at the start),
    ``mass_drift``, ``min_density`` and ``negative_mass`` (positivity), ``imaginary_part`` (complex methods:
    max |Im rho| / max |rho|), ``mean`` and ``variance`` (per axis), ``boltzmann_distance`` (L1 distance to the
    Boltzmann density), ``exact_error`` (L1 distance to the exact density where one is known, else NaN) and
    ``exact_solution`` (its name), ``rates`` (the lowest nonzero relaxation rates) with ``rate_residuals``,
    ``kramers_rate`` (double well: Kramers' high-barrier estimate of the first rate, else NaN), ``time``, ``dt``,
    ``steps``, ``fft_count``, ``seconds``, ``method``, ``order``.
    """

    def __repr__(self):
        return (f"SmoluchowskiResult(method={self.method!r}, time={self.time!r}, mass={self.mass!r}, "
                f"boltzmann_distance={self.boltzmann_distance!r}, rates={list(self.rates)!r})")


class ThermalResult(AttrDict):
    """The result of :func:`nystrom.thermal` (a dict whose keys are also attributes).

    Attributes: ``beads`` (the numbers N of beads), ``z_primitive``, ``energy_primitive`` (Tr K(beta/N)^N and its
    energy -d ln Z/d beta, one per N), ``z_extrapolated``, ``energy_extrapolated`` (the multi-product extrapolated
    propagator), ``z_exact``, ``energy_exact`` and ``levels`` (the grid Hamiltonian's), ``order`` (of the
    extrapolated propagator), ``extrapolate``, ``beta``, ``seconds``.
    """

    def __repr__(self):
        return (f"ThermalResult(beta={self.beta!r}, order={self.order!r}, z_exact={self.z_exact!r}, "
                f"z_extrapolated={list(self.z_extrapolated)!r})")


def _grid_array(name, x, shape):
    arr = np.asarray(x)
    if not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    if shape is not None and arr.shape != shape:
        raise ValueError(f"{name} has shape {arr.shape}, expected {shape} (grid points per axis)")
    return np.ascontiguousarray(arr, dtype=float).reshape(-1)


def _sequence(name, x):
    if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
        x = [x]
    try:
        return [_integer(name, v) for v in x]
    except TypeError:
        raise TypeError(f"{name} must be an integer or a sequence of integers") from None


def smoluchowski(potential="double-well", dims=1, grid=64, box=6.0, beta=1.0, diffusion=1.0, method=None, dt=0.01,
                 steps=100, x0=None, width=None, rho0=None, potential_values=None, rates=0, threads=1):
    """Propagates a density by the Smoluchowski equation rho_t = D div(grad rho + beta rho grad U) on the periodic
    grid [-box/2, box/2)^dims (the library's solver, the same defaults as ``nystrom smoluchowski``).

    potential: ``"harmonic"`` (|x|^2/2, the Ornstein-Uhlenbeck process), ``"double-well"`` ((x_1^2 - 1)^2 + the
    other axes harmonic) or ``"free"``; ``potential_values``: U on the grid (shape ``(grid,) * dims``) instead.
    The initial density is a Gaussian of standard deviation ``width`` (default 0.25) at ``x0`` (default 0), or
    ``rho0`` (an array of the grid's shape, not negative; normalised to mass 1). ``method``: a forward method
    (default M8; ``M4``..``M16``, ``mpe:1,2,3``, ``4A``, ``AC1``, ``BC1``, ...); a method with a negative
    coefficient is refused (ValueError), since it diverges on a diffusion. ``rates``: the number of lowest nonzero
    relaxation rates to compute. See docs/diffusion.md.

    >>> import nystrom
    >>> res = nystrom.smoluchowski(beta=3.0, box=5.0, grid=96, dt=0.01, steps=400, rates=1)
    >>> f"{res.rates[0]:.6f}", res.rate_residuals[0] < 1e-4
    ('0.241860', True)
    """
    if not hasattr(_core, "smoluchowski"):
        raise RuntimeError("this nystrom module was built without FFTW: the Smoluchowski solver is not available")
    if method is None:
        method = ""  # the library's default, M8
    for name, value in (("potential", potential), ("method", method)):
        if not isinstance(value, str):
            raise TypeError(f"{name} must be a string, got {type(value).__name__}")
    dims, grid, steps, rates, threads = (_integer(n, v) for n, v in (("dims", dims), ("grid", grid), ("steps", steps),
                                                                     ("rates", rates), ("threads", threads)))
    shape = (grid,) * dims if 1 <= dims <= 3 and grid > 0 else None
    initial = None
    if rho0 is not None:
        if x0 is not None or width is not None:
            raise ValueError("rho0 replaces the Gaussian: give no x0 or width with it")
        initial = _grid_array("rho0", rho0, shape)
        x0, width = [], 0.25
    else:
        x0 = [] if x0 is None else _vector("x0", x0)
        width = 0.25 if width is None else width
    box, beta, diffusion, dt, width = (_real(n, v) for n, v in (("box", box), ("beta", beta), ("diffusion", diffusion),
                                                                ("dt", dt), ("width", width)))
    values = None if potential_values is None else _grid_array("potential_values", potential_values, shape)
    d = _core.smoluchowski(potential, values, initial, dims, grid, box, diffusion, beta, x0, width, method, dt, steps,
                           rates, threads)
    res = SmoluchowskiResult()
    for key, value in d.items():
        res[key] = value
    return res


def thermal(potential="harmonic", grid=64, box=20.0, beta=1.0, beads=(4, 8, 16), extrapolate=(1, 2, 3),
            potential_values=None):
    """The partition function Z = Tr e^{-beta H} and the energy -d ln Z / d beta of H = -d^2/dx^2 / 2 + V on a
    periodic grid of one dimension, from N-bead products of the primitive propagator
    e^{-eps V/2} e^{-eps T} e^{-eps V/2} (eps = beta/N) and of its multi-product extrapolation over ``extrapolate``
    (Zillich, Mayrhofer & Chin, J. Chem. Phys. 132 (2010) 044103), evaluated exactly (traces of grid matrices), with
    the grid Hamiltonian's own Z and energy for reference (the same defaults as ``nystrom thermal``).

    >>> import nystrom, math
    >>> res = nystrom.thermal("harmonic", beta=2.0, beads=[8, 16])
    >>> abs(res.z_extrapolated[-1] * 2 * math.sinh(1.0) - 1) < 1e-8
    True
    """
    if not hasattr(_core, "thermal"):
        raise RuntimeError("this nystrom module was built without FFTW: the thermal solver is not available")
    if not isinstance(potential, str):
        raise TypeError(f"potential must be a string, got {type(potential).__name__}")
    grid = _integer("grid", grid)
    box, beta = _real("box", box), _real("beta", beta)
    beads, extrapolate = _sequence("beads", beads), _sequence("extrapolate", extrapolate)
    values = None
    if potential_values is not None:
        values = _grid_array("potential_values", potential_values, (grid,) if grid > 0 else None)
    d = _core.thermal(potential, values, grid, box, beta, beads, extrapolate)
    res = ThermalResult()
    for key, value in d.items():
        res[key] = value
    return res
