#!/usr/bin/env python3
"""The error floor of nystrom's methods on Kepler (100 periods, final position error against the exact solution) in
double, long double and double-double, through `nystrom run --json`.

Adaptive methods: four tolerances per decade from 1e-6 down to the tightest the tool accepts for the precision;
the floor is the largest and the median error at the four tightest tolerances (what a user gets at any of them,
not a lucky point). Fixed-step methods: steps per period 2^(k/2) from 16 up to a force budget; the floor is the
median of the four smallest errors of the sweep and its minimum.

    python3 bench/error_floor.py BUILD/src/nystrom [--precisions double,long-double,dd] [--ecc 0.5,0.9]
        [--periods 100] [--methods M8,DP12-adaptive,...] [--max-forces 4e7] [--csv out.csv]
"""
import argparse
import json
import math
import statistics
import subprocess
import sys

ADAPTIVE = ["DP12-adaptive", "M10-adaptive", "M12-adaptive", "M14-adaptive", "M16-adaptive"]
FIXED = ["M8", "SS10", "M12", "DP12"]
FORCES_PER_STEP = {"M8": 10, "SS10": 35, "M12": 21, "DP12": 17}


def run(tool, args):
    p = subprocess.run([tool, "run", "--json"] + args, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip()
    return json.loads(p.stdout), ""


def sweep_adaptive(tool, method, prec, ecc, periods):
    pts = []
    for k in range(24, 160):
        tol = 10.0 ** (-k / 4)
        j, err = run(tool, ["--problem", "kepler", "--ecc", str(ecc), "--periods", str(periods), "--method", method,
                            "--precision", prec, "--tol", "%.6g" % tol])
        if j is None:
            if "tolerance" not in err:
                print("  %s %s tol %.3g: %s" % (method, prec, tol, err), file=sys.stderr)
            break
        pts.append((tol, j["position_error"], j["steps"]))
    return pts


def sweep_fixed(tool, method, prec, ecc, periods, max_forces):
    pts = []
    for k in range(8, 60):
        n = int(round(2 ** (k / 2)))
        if n * periods * FORCES_PER_STEP.get(method, 20) > max_forces:
            break
        j, err = run(tool, ["--problem", "kepler", "--ecc", str(ecc), "--periods", str(periods), "--method", method,
                            "--precision", prec, "--steps-per-period", str(n)])
        if j is None:
            print("  %s %s n %d: %s" % (method, prec, n, err), file=sys.stderr)
            break
        pts.append((n, j["position_error"], j["steps"]))
    return pts


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tool")
    ap.add_argument("--precisions", default="double,long-double,dd")
    ap.add_argument("--ecc", default="0.5,0.9")
    ap.add_argument("--periods", type=int, default=100)
    ap.add_argument("--methods", default=",".join(FIXED + ADAPTIVE))
    ap.add_argument("--max-forces", type=float, default=4e7)
    ap.add_argument("--csv", default="")
    a = ap.parse_args()
    rows = []
    print("| method | precision | e | floor: max of 4 tightest tols (adaptive) / median of 4 best (fixed) | median "
          "| min | at |")
    print("|---|---|---|---|---|---|---|")
    for method in a.methods.split(","):
        for prec in a.precisions.split(","):
            for ecc in [float(e) for e in a.ecc.split(",")]:
                adaptive = method.endswith("-adaptive")
                if adaptive:
                    pts = sweep_adaptive(a.tool, method, prec, ecc, a.periods)
                    sel = pts[-4:]
                else:
                    pts = sweep_fixed(a.tool, method, prec, ecc, a.periods, a.max_forces)
                    sel = sorted(pts, key=lambda p: p[1])[:4]
                for p in pts:
                    rows.append((method, prec, ecc, p[0], p[1], p[2]))
                if not sel:
                    continue
                errs = [p[1] for p in sel]
                best = min(pts, key=lambda p: p[1])
                at = ("tol %.3g..%.3g" % (sel[0][0], sel[-1][0])) if adaptive else ("min at %d steps/period" % best[0])
                print("| %s | %s | %g | %.2g | %.2g | %.2g | %s |" % (method, prec, ecc, max(errs),
                                                                    statistics.median(errs), best[1], at))
                sys.stdout.flush()
    if a.csv:
        with open(a.csv, "w") as f:
            f.write("method,precision,ecc,param,error,steps\n")
            for r in rows:
                f.write("%s,%s,%g,%.6g,%.6g,%d\n" % r)


if __name__ == "__main__":
    main()
