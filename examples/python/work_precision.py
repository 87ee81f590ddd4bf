"""Work-precision chart: final position error against force evaluations on Kepler's problem (e = 0.5,
ten orbits) for a splitting method, a composition, an RKN method and two multi-product methods.

    python3 examples/python/work_precision.py [--out DIR]
"""
import argparse
import math
import os

import numpy as np

import nystrom
from nystrom.problems import Kepler


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="directory for the PNG file")
    args = ap.parse_args()

    prob = Kepler(0.5)
    t1 = 10 * 2 * math.pi + 1.0
    q_exact, _ = prob.exact(t1)
    rows = []
    for method in ("FR", "Y6", "DP10", "M8", "M12"):
        for n in (250, 500, 1000, 2000, 4000):
            res = nystrom.solve(prob, t_span=(0, t1), method=method, steps=n, t_eval=[t1])
            err = float(np.linalg.norm(res.q[-1] - q_exact))
            rows.append(dict(label=method, force_evals=res.force_evals, error=max(err, 1e-16)))
            print(f"{method:5s} steps {n:5d}  forces {res.force_evals:7d}  error {err:.3e}")

    import nystrom.plot as nplot

    os.makedirs(args.out, exist_ok=True)
    ax = nplot.work_precision(rows)
    ax.set_title("Kepler e = 0.5, ten orbits")
    ax.figure.savefig(os.path.join(args.out, "work_precision.png"), dpi=100)
    print("wrote work_precision.png in", args.out)


if __name__ == "__main__":
    main()
