"""nystrom from Python against scipy.integrate.solve_ivp (DOP853, RK45) in the same run.

Kepler's problem at e = 0.9 over 100 periods; error = |q(t1) - q_exact(t1)| (Kepler's equation). For every
integrator a sweep of tolerances; the cheapest run (wall time) reaching 1e-6 and 1e-9 is reported, with the
ratios to DOP853. scipy integrates the first-order system y = (q, v), f = (v, a(q)); nystrom integrates
q'' = a(q) with the same Python force a(q), and with the built-in (C++) force. The module's overhead is the
time of nystrom.solve on the built-in force against the C++ library's own fixed-step loop
(experiments/kepler.hpp) on the same steps, and against the library's solve() call inside it (res.solve_seconds).

    PYTHONPATH=<build>/python python3 bench/python/bench_scipy.py [--quick] [--json FILE] [--plot FILE.png]

--plot draws the work-precision chart (final error against wall time, one line per integrator) with matplotlib.
"""
import argparse
import json
import math
import os
import sys
import tempfile
import time

import numpy as np
from scipy.integrate import solve_ivp

import nystrom
from nystrom import _core
from nystrom.problems import Kepler

E = 0.9
PERIODS = 100
T1 = PERIODS * 2 * math.pi
TARGETS = (1e-6, 1e-9, 1e-12)


def accel(t, q):
    return -q / np.dot(q, q) ** 1.5


def rhs(t, y):
    q = y[:2]
    return np.concatenate([y[2:], -q / np.dot(q, q) ** 1.5])


def timed(fn, repeat):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def write_atomically(path, write):
    """Writes through write(temporary_path) and renames onto path, so that path is never left half written."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".bench_scipy-", suffix=os.path.splitext(path)[1])
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's file is private; a result file gets the usual permissions
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def plot_work_precision(runs, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5))
    for who in dict.fromkeys(r["integrator"] for r in runs):
        pts = [(r["seconds"], r["error"]) for r in runs if r["integrator"] == who and r["error"] > 0]  # by tolerance
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if who.startswith("nystrom") else "s--",
                      label=who, ms=4)
    for target in TARGETS:
        ax.axhline(target, color="0.8", lw=0.8, zorder=0)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("final position error")
    ax.set_title(f"Kepler e = {E}, {PERIODS} periods: nystrom from Python against scipy's solve_ivp")
    ax.legend(fontsize=7)
    fig.tight_layout()
    write_atomically(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer tolerances, one repetition")
    ap.add_argument("--json", help="write all runs to this file")
    ap.add_argument("--plot", help="write the work-precision chart (PNG) to this file")
    args = ap.parse_args()
    repeat = 1 if args.quick else 3
    prob = Kepler(E)
    q_exact, _ = prob.exact(T1)
    y0 = np.concatenate([prob.q0, prob.v0])
    runs = []

    def record(who, setting, sec, evals, q):
        err = float(np.linalg.norm(np.asarray(q) - q_exact))
        runs.append(dict(integrator=who, setting=setting, seconds=sec, force_evals=int(evals), error=err))
        print(f"{who:28s} {setting:>12s}  {sec:9.4f} s  {evals:9d} forces  error {err:.2e}", flush=True)

    sci_tols = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] if args.quick else [10.0 ** -k for k in range(4, 14)]
    for name in ("DOP853", "RK45"):
        for tol in sci_tols:
            if name == "RK45" and tol < 1e-10:
                continue  # RK45 needs millions of steps there
            sec, sol = timed(lambda: solve_ivp(rhs, (0, T1), y0, method=name, rtol=tol, atol=tol,
                                               t_eval=[T1]), repeat)
            record(f"scipy {name}", f"tol {tol:.0e}", sec, sol.nfev, sol.y[:2, -1])

    ny_tols = [1e-5, 1e-7, 1e-9, 1e-11, 1e-13] if args.quick else [10.0 ** -k for k in range(5, 15)]
    for method in ("DP12-adaptive", "M10"):
        for tol in ny_tols:
            sec, res = timed(lambda: nystrom.solve(accel, prob.q0, prob.v0, t_span=(0, T1), method=method,
                                                   rtol=tol, t_eval=[T1]), repeat)
            record(f"nystrom {method} (Python)", f"tol {tol:.0e}", sec, res.force_evals, res.q[-1])
            sec, res = timed(lambda: nystrom.solve(prob, t_span=(0, T1), method=method, rtol=tol, t_eval=[T1]),
                             max(repeat, 3))
            record(f"nystrom {method} (built-in)", f"tol {tol:.0e}", sec, res.force_evals, res.q[-1])

    # Below double's rounding: the built-in force in double-double, and fixed steps in double (compensated).
    for tol in ([1e-14, 1e-16] if args.quick else [1e-14, 1e-15, 1e-16, 1e-17]):
        sec, res = timed(lambda: nystrom.solve(prob, t_span=(0, T1), method="DP12-adaptive", rtol=tol, t_eval=[T1],
                                               precision="dd"), repeat)
        record("nystrom DP12-adaptive (built-in, dd)", f"tol {tol:.0e}", sec, res.force_evals, res.q[-1])
    for spp in ([4000, 16000] if args.quick else [2000, 4000, 8000, 16000, 32000]):
        sec, res = timed(lambda: nystrom.solve(prob, t_span=(0, T1), method="M8", steps=spp * PERIODS, t_eval=[T1]),
                         repeat)
        record("nystrom M8 fixed (built-in)", f"{spp}/period", sec, res.force_evals, res.q[-1])

    # Module overhead on the built-in force: the same fixed-step M8 run through nystrom.solve and through the
    # library's own loop (run_kepler), best of several.
    spp = 4000
    lib = min(_core.library_kepler_seconds("M8", E, spp, PERIODS)[0] for _ in range(5))
    mod, res = timed(lambda: nystrom.solve(prob, t_span=(0, T1), method="M8", steps=spp * PERIODS, t_eval=[T1]), 5)
    overhead = mod / lib
    # ... and against the library's solve() inside that call (the driver's own per-step cost excluded).
    in_solve = min(nystrom.solve(prob, t_span=(0, T1), method="M8", steps=spp * PERIODS,
                                 t_eval=[T1]).solve_seconds for _ in range(5))

    # Cost of one Python force call through nystrom.solve against a bare loop calling the same force.
    n_calls = 20000
    q_probe = np.array(prob.q0)
    bare, _ = timed(lambda: [accel(0.0, q_probe) for _ in range(n_calls)], max(repeat, 3))
    through, res = timed(lambda: nystrom.solve(accel, prob.q0, prob.v0, t_span=(0, T1), method="M8",
                                               steps=n_calls // 10, t_eval=[T1]), max(repeat, 3))
    per_call_bare = bare / n_calls
    per_call = through / res.force_evals

    print("\ncheapest run reaching each error (wall time; ratio = DOP853 time / this time):")
    summary = {}
    for target in TARGETS:
        best = {}
        for r in runs:
            if r["error"] <= target:
                k = ("nystrom (Python force)" if "(Python)" in r["integrator"] else
                     "nystrom (built-in force)" if "(built-in" in r["integrator"] else r["integrator"])
                if k not in best or r["seconds"] < best[k]["seconds"]:
                    best[k] = r
        summary[f"{target:.0e}"] = best
        print(f"  error <= {target:.0e}:")
        ref = best.get("scipy DOP853")
        for k, r in best.items():
            ratio = f"  x{ref['seconds'] / r['seconds']:.1f}" if ref else ""
            print(f"    {k:26s} {r['seconds']:9.4f} s  {r['force_evals']:9d} forces  ({r['integrator']}, "
                  f"{r['setting']}){ratio}")
        if ref is None:
            print("    scipy DOP853 does not reach it")
    print(f"\nmodule overhead on the built-in force (M8, {spp} steps/period, {PERIODS} periods): "
          f"nystrom.solve {mod:.4f} s / library loop {lib:.4f} s = {overhead:.3f}x; / the C++ solve() it calls "
          f"{in_solve:.4f} s = {mod / in_solve:.3f}x")
    print(f"a Python force call through nystrom.solve (M8, fixed steps): {1e6 * per_call:.2f} us, the bare call "
          f"{1e6 * per_call_bare:.2f} us")
    if args.json:
        doc = dict(runs=runs, summary=summary, overhead=overhead, library_seconds=lib, module_seconds=mod,
                   solve_seconds=in_solve, python_call_seconds=per_call, bare_call_seconds=per_call_bare)

        def dump(tmp):
            with open(tmp, "w") as f:
                json.dump(doc, f, indent=1)
        write_atomically(args.json, dump)
    if args.plot:
        plot_work_precision(runs, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
