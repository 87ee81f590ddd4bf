"""What nystrom.solve costs beyond the C++ solve() call inside it (res.solve_seconds), in one run.

Kepler's problem at e = 0.9 with M8, 100 000 fixed steps over 100 periods: with every-step output (100 001
states returned as arrays) and with one output time; then a Python force's cost per call through nystrom.solve
against the same function called in a bare loop. Best of --repeat runs each.

    PYTHONPATH=<build>/python /usr/bin/python3 bench/python/bench_output.py [--repeat N]
"""
import argparse
import math
import time

import nystrom
from nystrom.problems import Kepler


def best(fn, repeat):
    """(seconds, result) of the fastest of repeat runs; each result is dropped before the next run (as a loop
    rebinding `res` does), so that the runs reuse its memory."""
    best_sec, best_res = math.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        res = fn()
        sec = time.perf_counter() - start
        if sec < best_sec:
            best_sec, best_res = sec, {k: res[k] for k in ("solve_seconds", "force_evals")} | {"n": len(res.t)}
        del res
    return best_sec, best_res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    prob = Kepler(0.9)
    t1 = 100 * 2 * math.pi
    for what, extra in (("every step", {}), ("t_eval=[t1]", dict(t_eval=[t1]))):
        sec, res = best(lambda: nystrom.solve(prob, t_span=(0, t1), method="M8", steps=100_000, **extra),
                        args.repeat)
        print(f"M8, 100 000 steps, {what:11s} ({res['n']:6d} states): nystrom.solve {sec:.4f} s, C++ solve() "
              f"{res['solve_seconds']:.4f} s, ratio {sec / res['solve_seconds']:.3f}")

    def accel(t, q):
        return -q / (q @ q) ** 1.5

    sec, res = best(lambda: nystrom.solve(accel, prob.q0, prob.v0, t_span=(0, t1 / 10), method="M8", steps=2000,
                                          t_eval=[t1 / 10]), max(1, args.repeat // 2))
    q = prob.q0.copy()
    start = time.perf_counter()
    for _ in range(res["force_evals"]):
        accel(0.0, q)
    bare = time.perf_counter() - start
    calls = res["force_evals"]
    print(f"Python force: {sec / calls * 1e6:.2f} us per call through nystrom.solve, "
          f"{bare / calls * 1e6:.2f} us in a bare loop ({calls} calls)")


if __name__ == "__main__":
    main()
