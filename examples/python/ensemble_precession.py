"""An ensemble: the precession of the Kepler orbit per period under a fourth-order method, for several
eccentricities, run on a local process pool (or pass --dask to use a Dask LocalCluster). The exact orbit
does not precess; the numerical one does, faster at high eccentricity (Chin 2010, Fig. 2).

    python3 examples/python/ensemble_precession.py [--dask]
"""
import argparse
import math

import numpy as np

import nystrom
from nystrom.problems import Kepler

PERIODS = 10


def kepler(e):
    return Kepler(e)


def lrl_angle(q, v):
    """Direction of the Laplace-Runge-Lenz vector v x L - q/|q| in the plane."""
    L = q[0] * v[1] - q[1] * v[0]
    r = math.hypot(q[0], q[1])
    return math.atan2(-v[0] * L - q[1] / r, v[1] * L - q[0] / r)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dask", action="store_true", help="run on a Dask LocalCluster")
    args = ap.parse_args()

    eccs = [0.1, 0.3, 0.5, 0.7, 0.9]
    kw = dict(method="FR", t_span=(0, PERIODS * 2 * math.pi), steps=PERIODS * 1000, t_eval=[PERIODS * 2 * math.pi])
    if args.dask:
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as c, Client(c) as client:
            results = nystrom.ensemble(kepler, eccs, executor=client, **kw)
    else:
        results = nystrom.ensemble(kepler, eccs, max_workers=2, **kw)
    for e, res in zip(eccs, results):
        k = Kepler(e)
        d = lrl_angle(res.q[-1], res.v[-1]) - lrl_angle(k.q0, k.v0)
        d = (d + math.pi) % (2 * math.pi) - math.pi
        print(f"e = {e:.1f}: precession per period {d / PERIODS:+.3e} rad ({res.force_evals} forces)")
    assert np.all([r.success for r in results])


if __name__ == "__main__":
    main()
