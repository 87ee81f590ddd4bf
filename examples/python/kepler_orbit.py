"""A user force from Python and the same problem built in: Kepler's problem at e = 0.9, five orbits with
the eighth-order multi-product method M8; the orbit and the energy error are saved as PNG files.

    python3 examples/python/kepler_orbit.py [--out DIR]
"""
import argparse
import math
import os

import numpy as np

import nystrom
from nystrom.problems import Kepler


def force(t, q):
    """a = -q / |q|^3, called once per force evaluation with q of shape (2,)."""
    return -q / np.dot(q, q) ** 1.5


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="directory for the PNG files")
    args = ap.parse_args()

    e = 0.9
    prob = Kepler(e)
    t1 = 5 * 2 * math.pi
    mine = nystrom.solve(force, prob.q0, prob.v0, t_span=(0, t1), method="M8", steps=10000)
    builtin = nystrom.solve(prob, t_span=(0, t1), method="M8", steps=10000)
    q_exact, _ = prob.exact(t1)
    print(f"Python force:   {mine.force_evals} force evaluations, final error "
          f"{np.linalg.norm(mine.q[-1] - q_exact):.3e}")
    print(f"built-in force: {builtin.force_evals} force evaluations, final error "
          f"{np.linalg.norm(builtin.q[-1] - q_exact):.3e}")

    import nystrom.plot as nplot

    os.makedirs(args.out, exist_ok=True)
    ax = nplot.orbit(builtin)
    ax.figure.savefig(os.path.join(args.out, "kepler_orbit.png"), dpi=100)
    ax = nplot.energy_error(builtin, prob)
    ax.figure.savefig(os.path.join(args.out, "kepler_energy.png"), dpi=100)
    print("wrote kepler_orbit.png and kepler_energy.png in", args.out)


if __name__ == "__main__":
    main()
