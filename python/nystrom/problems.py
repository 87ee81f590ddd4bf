"""Built-in problems: their forces run entirely in C++ (the GIL released), so an integration costs what
the C++ library costs. Pass one to :func:`nystrom.solve` in place of a force function::

    import nystrom
    res = nystrom.solve(nystrom.problems.Kepler(0.9), t_span=(0, 20 * 3.141592653589793), method="M8", steps=20000)

Each problem carries its initial state (``q0``, ``v0``), its ``energy(q, v)`` and, where known, its
``exact(t)`` solution, computed in numpy independently of the integrators.
"""

import math
import numbers

import numpy as np

from . import _core

__all__ = ["Problem", "Kepler", "HarmonicOscillator", "HenonHeiles", "NBody", "Plummer"]


def _real(name, x):
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(x).__name__}")
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x!r}")
    return x


class Problem:
    """Base of the built-in problems (not meant to be instantiated directly)."""

    _kind = None
    q0 = None
    v0 = None

    @property
    def shape(self):
        return np.shape(self.q0)

    def _params(self):
        return []

    # The flat state the C++ side integrates, and back (identity layout unless overridden).
    def _to_flat(self, x):
        return np.ascontiguousarray(x, dtype=float).reshape(-1)

    def _from_flat(self, x):
        return np.asarray(x, dtype=float).reshape(self.shape)

    def _rows_from_flat(self, a):
        """States saved as rows of flat states, shape (k, size), as one array of shape (k,) + shape."""
        a = np.asarray(a, dtype=float)
        return a.reshape((a.shape[0],) + tuple(self.shape))

    def energy(self, q, v):
        raise NotImplementedError

    def __reduce__(self):
        return (_rebuild, (type(self), self.__dict__.copy()))


def _rebuild(cls, state):
    obj = cls.__new__(cls)
    obj.__dict__.update(state)
    return obj


class Kepler(Problem):
    """The planar Kepler problem a = -q/|q|^3 of Chin (2010), eqs (35)-(36): q0 = (1+e, 0),
    v0 = (0, sqrt((1-e)/(1+e))), energy -1/2, period 2 pi, started at apocentre.

    compensated=True: the force in double-word arithmetic (CompensatedKeplerForce), which the fixed-step splitting,
    composition and multi-product methods (SS10, KL8, M8, ...), the adaptive RKN pairs (DP12-adaptive,
    DOP853-adaptive) and the adaptive multi-product expansions of one order (M12-adaptive, ...; tolerances then
    down to eps/2) in double use to go below the plain force's rounding; other methods and precisions are refused,
    as by `nystrom run --force compensated`."""

    def __init__(self, e=0.9, compensated=False):
        e = _real("e", e)
        if not 0 <= e < 1:
            raise ValueError(f"eccentricity must satisfy 0 <= e < 1, got {e!r}")
        if not isinstance(compensated, bool):
            raise TypeError(f"compensated must be True or False, got {compensated!r}")
        self._kind = "kepler_compensated" if compensated else "kepler"
        self.compensated = compensated
        self.e = e
        self.q0 = np.array([1 + e, 0.0])
        self.v0 = np.array([0.0, math.sqrt((1 - e) / (1 + e))])

    period = 2 * math.pi

    def energy(self, q, v):
        q, v = np.asarray(q), np.asarray(v)
        return 0.5 * np.sum(v * v, axis=-1) - 1 / np.sqrt(np.sum(q * q, axis=-1))

    def exact(self, t):
        """The analytic solution (q, v) at time(s) t: Kepler's equation solved by Newton's method."""
        t = np.asarray(t, dtype=float)
        e = self.e
        m = np.mod(math.pi + t + math.pi, 2 * math.pi) - math.pi  # mean anomaly pi + t, reduced to [-pi, pi)
        E = np.where(e > 0.8, np.where(m >= 0, math.pi, -math.pi), m + e * np.sin(m)).astype(float)
        for _ in range(100):
            d = (E - e * np.sin(E) - m) / (1 - e * np.cos(E))
            E = E - d
            if np.all(np.abs(d) <= 4e-16 * (1 + np.abs(E))):
                break
        s = math.sqrt(1 - e * e)
        cE, sE = np.cos(E), np.sin(E)
        Edot = 1 / (1 - e * cE)
        q = np.stack([e - cE, -s * sE], axis=-1)
        v = np.stack([sE * Edot, -s * cE * Edot], axis=-1)
        return q, v


class HarmonicOscillator(Problem):
    """q'' = -omega^2 q for any number of coordinates (default: one, q0 = 1, v0 = 0)."""

    _kind = "harmonic"

    def __init__(self, omega=1.0, q0=1.0, v0=0.0):
        self.omega = _real("omega", omega)
        if not self.omega > 0:
            raise ValueError(f"omega must be positive, got {self.omega!r}")
        self.q0 = np.atleast_1d(np.array(q0, dtype=float))
        self.v0 = np.atleast_1d(np.array(v0, dtype=float))
        if self.q0.shape != self.v0.shape:
            raise ValueError(f"q0 has shape {self.q0.shape} but v0 has shape {self.v0.shape}")

    def _params(self):
        return [self.omega * self.omega]

    @property
    def period(self):
        return 2 * math.pi / self.omega

    def energy(self, q, v):
        q, v = np.asarray(q), np.asarray(v)
        return 0.5 * np.sum(v * v + self.omega**2 * q * q, axis=-1)

    def exact(self, t):
        t = np.asarray(t, dtype=float)[..., None]
        w = self.omega
        q = self.q0 * np.cos(w * t) + self.v0 / w * np.sin(w * t)
        v = -self.q0 * w * np.sin(w * t) + self.v0 * np.cos(w * t)
        return q.reshape(np.shape(t)[:-1] + self.q0.shape), v.reshape(np.shape(t)[:-1] + self.q0.shape)


class HenonHeiles(Problem):
    """The Hénon-Heiles system, V = (x^2 + y^2)/2 + x^2 y - y^3/3 (Hénon & Heiles, Astron. J. 69 (1964) 73).
    Default start: (x, y) = (0, 0.1), (vx, vy) = (0.35, 0), energy about 0.066 (bounded, below 1/6)."""

    _kind = "henon_heiles"

    def __init__(self, q0=(0.0, 0.1), v0=(0.35, 0.0)):
        self.q0 = np.array(q0, dtype=float).reshape(2)
        self.v0 = np.array(v0, dtype=float).reshape(2)

    def energy(self, q, v):
        q, v = np.asarray(q), np.asarray(v)
        x, y = q[..., 0], q[..., 1]
        return 0.5 * np.sum(v * v, axis=-1) + 0.5 * (x * x + y * y) + x * x * y - y**3 / 3


class NBody(Problem):
    """Gravitational N-body problem with Plummer softening, built REBOUND-style::

        sim = nystrom.problems.NBody(G=1.0)
        sim.add(m=1.0)
        sim.add(m=1e-3, x=1.0, vy=1.0)

    State arrays have shape (N, 3). ``eps`` is the softening length.

    compensated=True: the force in double-word arithmetic (CompensatedNBodyForce), which the fixed-step splitting,
    composition and multi-product methods, the adaptive RKN pairs and the adaptive multi-product expansions of one
    order in double use to go below the plain force's rounding; other methods and precisions are refused, as by
    `nystrom run --force compensated`.
    """

    def __init__(self, masses=None, G=1.0, eps=0.0, compensated=False):
        if not isinstance(compensated, bool):
            raise TypeError(f"compensated must be True or False, got {compensated!r}")
        self._kind = "nbody_compensated" if compensated else "nbody"
        self.compensated = compensated
        self.G = _real("G", G)
        if not self.G > 0:
            raise ValueError(f"G must be positive, got {self.G!r}")
        self.eps = _real("eps", eps)
        if self.eps < 0:
            raise ValueError(f"eps must be >= 0, got {self.eps!r}")
        self.masses = []
        self._q, self._v = [], []
        if masses is not None:
            for m in masses:
                self.add(m)

    def add(self, m, x=0.0, y=0.0, z=0.0, vx=0.0, vy=0.0, vz=0.0):
        """Adds a particle of mass m at (x, y, z) with velocity (vx, vy, vz)."""
        m = _real("m", m)
        if not m > 0:
            raise ValueError(f"particle mass must be positive, got {m!r}")
        self.masses.append(m)
        self._q.append([_real("x", x), _real("y", y), _real("z", z)])
        self._v.append([_real("vx", vx), _real("vy", vy), _real("vz", vz)])
        return self

    @property
    def N(self):
        return len(self.masses)

    @property
    def q0(self):
        return np.array(self._q, dtype=float).reshape(self.N, 3)

    @property
    def v0(self):
        return np.array(self._v, dtype=float).reshape(self.N, 3)

    def _params(self):
        if self.N == 0:
            raise ValueError("N-body system has no particles: add some with add(m, x, y, z, vx, vy, vz)")
        return [self.eps**2] + [self.G * m for m in self.masses]

    # The library's N-body state is a structure of arrays: x_0..x_{N-1}, y_0.., z_0...
    def _to_flat(self, x):
        return np.ascontiguousarray(np.asarray(x, dtype=float).reshape(self.N, 3).T).reshape(-1)

    def _from_flat(self, x):
        return np.asarray(x, dtype=float).reshape(3, self.N).T.copy()

    def _rows_from_flat(self, a):
        a = np.asarray(a, dtype=float)
        return np.ascontiguousarray(a.reshape(a.shape[0], 3, self.N).transpose(0, 2, 1))

    def energy(self, q, v):
        """Kinetic plus (softened) potential energy; q, v of shape (N, 3) or (k, N, 3)."""
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        m = np.asarray(self.masses)
        kin = 0.5 * np.sum(m[:, None] * v * v, axis=(-2, -1))
        d = q[..., :, None, :] - q[..., None, :, :]
        r = np.sqrt(np.sum(d * d, axis=-1) + self.eps**2)
        iu = np.triu_indices(self.N, 1)
        pot = -self.G * np.sum((m[:, None] * m[None, :])[iu] / r[..., iu[0], iu[1]], axis=-1)
        return kin + pot


class Plummer(NBody):
    """A Plummer sphere of n equal-mass particles in standard units (total mass 1, G = 1, E = -1/4),
    sampled with seed (Aarseth, Hénon & Wielen, Astron. Astrophys. 37 (1974) 183); softening
    eps = 1/n unless given; compensated as for NBody."""

    def __init__(self, n, seed=42, eps=None, compensated=False):
        if isinstance(n, bool) or not isinstance(n, numbers.Integral):
            raise TypeError(f"n must be an integer, got {type(n).__name__}")
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        super().__init__(G=1.0, eps=1.0 / n if eps is None and n > 0 else (0.0 if eps is None else eps),
                         compensated=compensated)
        m, q, v = _core.plummer(int(n), int(seed))
        self.masses = [float(x) for x in m]
        self._q = q.tolist()
        self._v = v.tolist()
