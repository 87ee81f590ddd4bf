"""nystrom.quantum: the library's split-operator solver for the Schrödinger and Gross-Pitaevskii equations
(nystrom/quantum/solve.hpp, the solver of ``nystrom quantum``) from Python.

The propagation runs in C++ with the GIL released; the checks of the input are the library's (ValueError
with its one-line message), this module converts the arguments and wraps the result.

>>> import nystrom
>>> res = nystrom.quantum("harmonic", imaginary_time=True, dt=0.1, steps=1000, converge=1e-10)
>>> res.method, res.converged, round(res.energy, 8)
('M8', True, 0.5)
"""

import numbers

import numpy as np

from . import _core
from ._progress import counted_progress
from ._result import AttrDict

__all__ = ["quantum", "QuantumResult"]


class QuantumResult(AttrDict):
    """The result of :func:`nystrom.quantum` (a dict whose keys are also attributes).

    Attributes: ``norm``, ``norm_drift`` (final norm minus initial), ``energy`` (<H>, with g|psi|^2/2 for
    Gross-Pitaevskii), ``chemical_potential``, ``mean_position``, ``mean_momentum`` (one value per dimension),
    ``energies`` (imaginary time: the energies of the ``states`` lowest states, ground state first),
    ``psi`` (the final wave function, complex128 of shape ``(grid,) * dims`` at x_i = -box/2 + i box/grid),
    ``times`` with ``sample_norms``, ``sample_energies``, ``sample_mean_position`` (the observables at the
    recorded times) and ``autocorrelation`` (C(t) = <psi(0)|psi(t)> at ``times``, when asked for),
    ``exact_error`` (L2 distance to the exact solution where one is known, else NaN) and ``exact_solution``
    (its name), ``time`` (of the steps taken), ``dt``, ``steps`` (asked for), ``steps_taken``, ``converged``
    (with ``converge``: whether the criterion was met; else None), ``fft_count``, ``seconds`` (wall time of
    the propagation), ``method``, ``order``, ``precision``.
    """

    def __repr__(self):
        return (f"QuantumResult(method={self.method!r}, energy={self.energy!r}, norm={self.norm!r}, "
                f"time={self.time!r}, fft_count={self.fft_count!r})")


def _integer(name, x):
    if isinstance(x, bool) or not isinstance(x, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(x).__name__}")
    x = int(x)
    if not -2**31 <= x < 2**31:
        raise ValueError(f"{name} is out of range, got {x}")
    return x


def _real(name, x):
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(x).__name__}")
    return float(x)


def _vector(name, x):
    """x0 or p0: one number (the first axis) or one per axis."""
    arr = np.asarray(x)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise TypeError(f"{name} must be a number or a sequence of real numbers")
    if arr.ndim > 1:
        raise ValueError(f"{name} must be a number or a sequence of numbers, got shape {arr.shape}")
    return [float(v) for v in arr.reshape(-1)]


def quantum(potential="harmonic", dims=1, grid=256, box=20.0, method=None, dt=0.05, steps=200,
            imaginary_time=False, x0=None, p0=None, width=None, g=0.0, states=1, precision="double",
            autocorrelation=False, samples=None, potential_values=None, threads=1, progress=False, psi0=None,
            converge=None, allow_negative_coefficients=False):
    """Propagate a wave function (a Gaussian packet, or ``psi0``) by i psi_t = (-nabla^2/2 + V + g|psi|^2) psi
    (units hbar = m = 1) on the periodic grid [-box/2, box/2)^dims with ``grid`` points per axis, by ``steps``
    steps of ``dt`` of a splitting or multi-product method (the library's split-operator solver, as
    ``nystrom quantum``).

    Parameters
    ----------
    potential : str
        ``"harmonic"`` (|x|^2/2), ``"anisotropic"``, ``"morse"``, ``"double-well"``, ``"soft-coulomb"``,
        ``"free"`` (docs/quantum.md).
    potential_values : array_like, optional
        The potential's values on the grid, shape ``(grid,) * dims`` (index i of an axis at
        x_i = -box/2 + i box/grid); replaces ``potential``.
    dims, grid, box : int, int, float
        Dimensions (1 to 3), points per axis, box length.
    method : str, optional
        A splitting or multi-product method of the catalog (``"KL8"``, ``"M8"``, ``"PV"`` (Strang splitting,
        position Verlet), ``"Y6"``, ``"BC1"``, ``"mpe4:1,2,3"``, ``"4A"``, ...; ``nystrom.methods()``); RKN
        tableaux and adaptive methods do not apply. Default: ``"KL8"`` in real time (real coefficients: unitary,
        the norm is kept), ``"M8"`` in imaginary time (every flow runs forward). A multi-product or
        complex-coefficient method is not unitary in real time.
    dt, steps : float, int
        The step (in real or imaginary time) and the number of steps (with ``converge``: the most steps).
    imaginary_time : bool
        Propagate in imaginary time, renormalising after every step (relaxes to the ground state). A method
        with a backward sub-step (a coefficient whose real part is not positive: Forest-Ruth, Yoshida,
        Kahan-Li, ...) is refused there with ValueError naming the forward methods, since it amplifies the
        highest wave numbers and gives a wrong ground state.
    allow_negative_coefficients : bool
        Run such a method in imaginary time anyway.
    converge : float, optional
        Imaginary time: stop once the energy changes by less than this per unit imaginary time over one step
        (|E_n - E_(n-1)| / dt < converge; the energy is evaluated after every step). ``converged`` and
        ``steps_taken`` say what happened.
    x0, p0, width : float or sequence, float
        The initial Gaussian: centre and momentum (one number: the first axis; or one per axis; default 1
        and 0), width (default 1: the harmonic coherent state).
    psi0 : array_like, optional
        The initial wave function instead of the Gaussian: complex (or real) values of shape
        ``(grid,) * dims`` at the grid points (as ``potential_values``), finite and not all zero; it is
        normalised on input (sum |psi0|^2 (box/grid)^dims = 1). Not with ``x0``, ``p0`` or ``width``.
    g : float
        Gross-Pitaevskii coupling (with |psi|^2 normalised to 1).
    states : int
        Imaginary time, g = 0: the ``states`` lowest states by orthogonalisation (``energies``).
    precision : str
        ``"double"`` or ``"long-double"`` (results in float64 and complex128).
    autocorrelation : bool
        Record C(t) = <psi(0)|psi(t)> after every step (``times``, ``autocorrelation``).
    samples : int, optional
        Record the observables at this many evenly spaced times besides t = 0 (default: none, or every
        step with ``autocorrelation``).
    threads : int
        FFTW threads per transform.
    progress : bool or callable
        True: a progress bar (tqdm if installed, else a line on stderr); a callable gets
        ``progress(steps_done, steps_total)``. Ctrl-C interrupts the run (KeyboardInterrupt) either way.

    Returns
    -------
    QuantumResult

    Examples
    --------
    The coherent state of the oscillator from x0 = 1 follows the classical orbit <x>(t) = cos t; the
    default real-time method KL8 keeps the norm to rounding:

    >>> import math, nystrom
    >>> res = nystrom.quantum("harmonic", x0=1.0, dt=0.05, steps=200)
    >>> res.method, abs(res.mean_position[0] - math.cos(10.0)) < 1e-8, abs(res.norm - 1) < 1e-12
    ('KL8', True, True)

    Imaginary time relaxes to the ground state, E0 = d/2, and ``converge`` stops the run once it is there:

    >>> res = nystrom.quantum("harmonic", dims=2, grid=64, box=16.0, imaginary_time=True, dt=0.1,
    ...                       steps=2000, x0=[1.0, 0.5], converge=1e-9)
    >>> res.converged, res.steps_taken < 2000, round(res.energy, 7)
    (True, True, 1.0)

    A method with negative coefficients is refused in imaginary time:

    >>> nystrom.quantum("double-well", method="KL8", imaginary_time=True)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: 'KL8' has a coefficient with a real part that is not positive ...

    A wave function of one's own, normalised on input (here the ground state times 3):

    >>> import numpy as np
    >>> x = -10.0 + np.arange(256) * 20.0 / 256
    >>> res = nystrom.quantum(psi0=3 * np.exp(-x**2 / 2), steps=10)
    >>> round(res.energy, 10), round(res.norm, 10)
    (0.5, 1.0)
    """
    if not hasattr(_core, "quantum"):
        raise RuntimeError("this nystrom module was built without FFTW: the quantum solver is not available")
    if method is None:
        method = ""  # the library's default_method(): KL8 in real time, M8 in imaginary time
    for name, value in (("potential", potential), ("method", method), ("precision", precision)):
        if not isinstance(value, str):
            raise TypeError(f"{name} must be a string, got {type(value).__name__}")
    dims, grid, steps, states = (_integer(n, v) for n, v in (("dims", dims), ("grid", grid), ("steps", steps),
                                                            ("states", states)))
    threads = _integer("threads", threads)
    initial = None
    if psi0 is not None:
        if x0 is not None or p0 is not None or width is not None:
            raise ValueError("psi0 replaces the Gaussian: give no x0, p0 or width with it")
        initial = np.asarray(psi0)
        if not (np.issubdtype(initial.dtype, np.number) and not np.issubdtype(initial.dtype, np.timedelta64)):
            raise TypeError(f"psi0 must be an array of complex numbers, got dtype {initial.dtype}")
        expected = (grid,) * dims if 1 <= dims <= 3 and grid > 0 else None
        if expected is not None and initial.shape != expected:
            raise ValueError(f"psi0 has shape {initial.shape}, expected {expected} (grid points per axis)")
        initial = np.ascontiguousarray(initial, dtype=complex).reshape(-1)
        x0, p0, width = [], [], 1.0
    else:
        x0 = _vector("x0", 1.0 if x0 is None else x0)
        p0 = _vector("p0", 0.0 if p0 is None else p0)
        width = 1.0 if width is None else width
    box, dt, width, g = (_real(n, v) for n, v in (("box", box), ("dt", dt), ("width", width), ("g", g)))
    converge_tol = 0.0
    if converge is not None:
        converge_tol = _real("converge", converge)
        if not (converge_tol > 0 and np.isfinite(converge_tol)):
            raise ValueError(f"converge must be positive and finite, got {converge}")
    if samples is None:
        samples = steps if autocorrelation else 0
    samples = _integer("samples", samples)
    values = None
    if potential_values is not None:
        values = np.asarray(potential_values)
        if not (np.issubdtype(values.dtype, np.floating) or np.issubdtype(values.dtype, np.integer)):
            raise TypeError(f"potential_values must be an array of real numbers, got dtype {values.dtype}")
        expected = (grid,) * dims if 1 <= dims <= 3 and grid > 0 else None
        if expected is not None and values.shape != expected:
            raise ValueError(f"potential_values has shape {values.shape}, expected {expected} (grid points per axis)")
        values = np.ascontiguousarray(values, dtype=float).reshape(-1)
    update, close = counted_progress(progress)
    done = None  # the steps taken, once the run has returned
    try:
        d = _core.quantum(potential, values, initial, dims, grid, box, method, dt, steps, bool(imaginary_time),
                          x0, p0, width, g, states, precision, bool(autocorrelation), samples, threads, converge_tol,
                          bool(allow_negative_coefficients), update)
        done = int(d["steps_taken"])
    finally:
        if close is not None:
            close(done)

    res = QuantumResult()
    for key in ("method", "order", "dt", "time", "steps", "steps_taken", "norm", "norm_drift", "energy",
                "chemical_potential", "mean_position", "mean_momentum", "energies", "exact_error", "exact_solution",
                "fft_count", "seconds", "psi"):
        res[key] = d[key]
    res.time = float(res.time)
    res.times = d["sample_times"]
    res.sample_norms = d["sample_norms"]
    res.sample_energies = d["sample_energies"]
    res.sample_mean_position = d["sample_mean_position"]
    res.autocorrelation = d["sample_autocorrelation"] if autocorrelation else None
    res.final_autocorrelation = complex(d["final_autocorrelation"]) if autocorrelation else None
    res.converged = bool(d["converged"]) if converge is not None else None
    res.precision = precision
    return res
