"""The Arenstorf orbit (velocity-dependent force) from Python: nystrom's GBS, DOP853 (its Nystrom form) and the
adaptive multi-product expansion of order 8 over the midpoint rule against scipy's solve_ivp (DOP853) in the same run.

The restricted three-body problem in the rotating frame, with the initial state and period of Hairer, Nørsett
& Wanner I, sec. II.0; error = |q(T) - q0| after one period (the orbit closes to about 1e-15 with the printed
digits). Over ten periods the return error of every run, of either integrator at any tolerance, is of order 1: the
orbit amplifies the rounding of its double initial state and of every step beyond any tolerance (--periods 10
shows it), so that span needs a reference in a wider precision, not the return to q0. Both integrators call the same kind of Python function once per force
evaluation: nystrom.solve the force(t, q, v) of q'' = a(t, q, v), scipy the right-hand side of the first-order
system y = (q, v). For each integrator a sweep of tolerances; for each target error the cheapest run (wall time,
best of --repeat) that reaches it, and the ratio of the times (scipy / nystrom) and of the force evaluations.

    PYTHONPATH=<build>/python python3 bench/python/bench_arenstorf.py [--quick] [--json FILE]
"""
import argparse
import json
import math
import os
import tempfile
import time

import numpy as np
from scipy.integrate import solve_ivp

import nystrom

MU = 0.012277471
MUP = 1 - MU
Q0 = np.array([0.994, 0.0])
V0 = np.array([0.0, -2.00158510637908252240537862224])
T = 17.0652165601579625588917206249
TARGETS = (1e-6, 1e-9, 1e-12)


def accel(q, v):
    d1 = ((q[0] + MU) ** 2 + q[1] ** 2) ** 1.5
    d2 = ((q[0] - MUP) ** 2 + q[1] ** 2) ** 1.5
    return np.array([q[0] + 2 * v[1] - MUP * (q[0] + MU) / d1 - MU * (q[0] - MUP) / d2,
                     q[1] - 2 * v[0] - MUP * q[1] / d1 - MU * q[1] / d2])


def force(t, q, v):
    return accel(q, v)


def rhs(t, y):
    return np.concatenate([y[2:], accel(y[:2], y[2:])])


def timed(fn, repeat):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def run_nystrom(method):
    def run(tol, periods):
        res = nystrom.solve(force, Q0, V0, t_span=(0, periods * T), method=method, rtol=tol, atol=tol,
                            max_steps=10**7)
        return float(np.linalg.norm(res.q[-1] - Q0)), res.force_evals
    return run


def run_scipy(tol, periods):
    res = solve_ivp(rhs, (0, periods * T), np.concatenate([Q0, V0]), method="DOP853", rtol=tol, atol=tol)
    return float(np.linalg.norm(res.y[:2, -1] - Q0)), int(res.nfev)


def sweep(name, fn, tols, periods, repeat):
    rows = []
    for tol in tols:
        seconds, (err, evals) = timed(lambda: fn(tol, periods), repeat)
        rows.append({"integrator": name, "periods": periods, "tol": tol, "error": err, "force_evals": evals,
                     "seconds": seconds})
        print(f"  {name:<14} periods {periods:>2}  tol {tol:8.1e}  error {err:9.2e}  forces {evals:>7}  "
              f"{seconds * 1e3:9.2f} ms", flush=True)
    return rows


def cheapest(rows, target):
    ok = [r for r in rows if r["error"] <= target]
    return min(ok, key=lambda r: r["seconds"]) if ok else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer tolerances, one repetition")
    ap.add_argument("--periods", type=int, default=1, help="periods integrated (default 1)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="write the rows and ratios to this file")
    args = ap.parse_args()
    repeat = 1 if args.quick else args.repeat
    tols = [10.0 ** -k for k in (range(4, 14, 3) if args.quick else range(4, 15))]
    out = {"rows": [], "ratios": []}
    for periods in (args.periods,):
        sci = sweep("scipy DOP853", run_scipy, tols, periods, repeat)
        out["rows"] += sci
        print(f"  smallest error  scipy DOP853 {min(r['error'] for r in sci):.2e}")
        for method in ("DOP853", "GBS", "mpe-midpoint-adaptive:1,2,3,4"):
            nys = sweep("nystrom " + method, run_nystrom(method), tols, periods, repeat)
            out["rows"] += nys
            print(f"\nperiods {periods}: smallest error  nystrom {method} {min(r['error'] for r in nys):.2e}")
            for target in TARGETS:
                a, b = cheapest(nys, target), cheapest(sci, target)
                if a and b:
                    ratio = {"periods": periods, "method": method, "target": target,
                             "time_ratio": b["seconds"] / a["seconds"],
                             "force_ratio": b["force_evals"] / a["force_evals"]}
                    out["ratios"].append(ratio)
                    print(f"  error <= {target:.0e}: scipy DOP853 / nystrom {method}  time "
                          f"{ratio['time_ratio']:.2f}x  forces {ratio['force_ratio']:.2f}x")
                else:
                    print(f"  error <= {target:.0e}: " + (f"nystrom {method}" if not a else "scipy DOP853") +
                          " does not reach it")
        print()
    if args.json:  # written whole or not at all: a temporary file in the same folder, renamed into place
        folder = os.path.dirname(os.path.abspath(args.json))
        with tempfile.NamedTemporaryFile("w", dir=folder, delete=False, suffix=".tmp") as f:
            json.dump(out, f, indent=1)
        os.replace(f.name, args.json)


if __name__ == "__main__":
    main()
