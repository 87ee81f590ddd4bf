"""Work-precision of the Wisdom-Holman maps and the direct methods on Hairer's outer solar system.

Every run is `nystrom run --problem outer-solar-system --method M --h H --years Y --json --no-reference`; Jupiter's
final position is compared with one reference run of the tool (WH-mpe:1,2,3,4,5,6, order 12, in long double at
25 days). For every method the table lists the sweep of steps: force evaluations (interaction kicks for the maps,
N-body forces for the direct methods), wall time, the largest relative energy error over the run (the final one
for direct methods) and Jupiter's position error. The summary compares, at a relative energy error of 1e-12, the
cheapest run of each family (time ratio to the best direct method, measured in the same invocation).

    python3 bench/planetary_work_precision.py --tool build/release/src/nystrom [--years 1e5] [--json FILE]
"""
import argparse
import json
import math
import subprocess
import sys

MAPS = {
    "WH-M8": [400, 300, 200, 150, 100],
    "WH-M10": [400, 300, 200, 150],
    "WH-mpe:1,2,3,4,5,6": [600, 400, 300, 200],
    "SABA4": [100, 50, 25],
    "WH": [50, 20, 10],
}
DIRECT = {
    "M8": [40, 30, 20, 15, 10],
    "M12": [80, 60, 40, 30],
    "M16": [120, 80, 60, 40],
    "KL8": [40, 30, 20, 15],
    "SS10": [60, 40, 30, 20],
}
ADAPTIVE = {"DP12-adaptive": [1e-12, 1e-13, 1e-14, 1e-15]}
TARGET = 1e-12


def run(tool, args):
    out = subprocess.run([tool, "run", "--problem", "outer-solar-system", "--json", *args], check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tool", required=True, help="the nystrom program")
    p.add_argument("--years", type=float, default=1e5)
    p.add_argument("--json", help="write every run to this file")
    a = p.parse_args()
    years = ["--years", repr(a.years)]

    ref = run(a.tool, ["--method", "WH-mpe:1,2,3,4,5,6", "--h", "25", "--precision", "long-double", "--no-reference",
                       *years])
    jref = ref["jupiter_position"]
    print(f"reference: {ref['method']} long double h = 25 days, {ref['cpu_seconds']:.1f} s of CPU, "
          f"energy error {ref['energy_error_max']:.2e}")

    rows = []
    jobs = [(m, ["--h", repr(h)], "map") for m, hs in MAPS.items() for h in hs]
    jobs += [(m, ["--h", repr(h)], "direct") for m, hs in DIRECT.items() for h in hs]
    jobs += [(m, ["--h", "100", "--tol", repr(t)], "direct") for m, ts in ADAPTIVE.items() for t in ts]
    print(f"{'method':22} {'h / tol':>8} {'forces':>11} {'CPU s':>9} {'energy err':>11} {'Jupiter err':>11}")
    for method, extra, kind in jobs:
        r = run(a.tool, ["--method", method, "--no-reference", *extra, *years])
        err = math.dist(r["jupiter_position"], jref)
        row = {"method": method, "kind": kind, "param": extra[-1], "force_evals": r["force_evals"],
               "seconds": r["cpu_seconds"], "energy_error": r["energy_error_max"], "jupiter_error": err}
        rows.append(row)
        print(f"{method:22} {extra[-1]:>8} {r['force_evals']:>11} {r['cpu_seconds']:>9.3f} "
              f"{r['energy_error_max']:>11.2e} {err:>11.2e}")
        sys.stdout.flush()

    def best(kind):
        ok = [r for r in rows if r["kind"] == kind and r["energy_error"] <= TARGET]
        return min(ok, key=lambda r: r["seconds"]) if ok else None

    bm, bd = best("map"), best("direct")
    print(f"\nat energy error <= {TARGET:g}:")
    for name, b in (("map", bm), ("direct", bd)):
        if b:
            print(f"  cheapest {name:6}: {b['method']} ({b['param']}): {b['seconds']:.3f} s, "
                  f"{b['force_evals']} forces, energy {b['energy_error']:.2e}, Jupiter {b['jupiter_error']:.2e} AU")
        else:
            print(f"  no {name} run reached it")
    if bm and bd:
        print(f"  time ratio direct / map: {bd['seconds'] / bm['seconds']:.1f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"years": a.years, "reference": ref, "runs": rows}, f, indent=1)


if __name__ == "__main__":
    main()
