"""Work-precision of the Wisdom-Holman maps and the direct methods on Hairer's outer solar system.

Every run is `nystrom run --problem outer-solar-system --method M --h H --years Y --json --no-reference`; Jupiter's
final position is compared with one reference run per horizon (WH-mpe:1,2,3,4,5,6, order 12, in long double),
computed once and cached in a JSON file (--cache) so that later invocations reuse it. The reference runs in a
separate process while the sweep goes on; each run reports the CPU time of its own integrating thread.

For every method the table lists its sweep of steps: interaction kicks (maps) or force evaluations (direct
methods), Kepler drifts (one drift = every planet advanced once), CPU seconds, the relative energy error (for the
maps the largest of about a thousand samples over the run, for the direct methods the final one: their error
grows with time) and Jupiter's position error. For each method the CPU time and the force count that reach a
relative energy error of 1e-12 are interpolated log-log between the two runs of its sweep that bracket it; the
summary gives the cheapest Wisdom-Holman method, the cheapest direct method and their ratio, and the smallest
energy error any method reached.

    python3 bench/planetary_work_precision.py --tool build/release/src/nystrom [--years 1e5] [--json FILE]
        [--markdown FILE] [--cache FILE] [--only M1,M2] [--only 'SABA(10,6,4)']
"""
import argparse
import json
import math
import os
import subprocess
import sys

# steps in days: each sweep brackets a relative energy error of 1e-12 over 1e4-1e6 years where it can
MAPS = {
    "WH": [20, 5],
    "WHC7": [100, 50, 25],
    "SABA4": [100, 50, 25],
    # Blanes, Casas, Farres, Laskar, Makazaga & Murua (2013): no eps^2 h^2 term; eps^3 h^4 (or eps^2 h^4) instead
    "SABA(10,6,4)": [500, 450, 400, 350, 300, 200],
    "SABAH(10,6,4)": [450, 400, 350, 300, 200],
    "SABA(8,6,4)": [300, 250, 200, 150],
    "SABAH(8,6,4)": [300, 250, 200, 150],
    "SABA(10,4)": [200, 150, 100],
    "SABAH(8,4,4)": [200, 150, 100],
    "WH-KL8": [300, 200, 100],
    "WH-SS10": [400, 300, 200],
    "WH-M6": [200, 100, 50],
    "WH-M8": [300, 200, 150, 100, 75],
    "WH-M10": [400, 300, 200, 150],
    # the expansion over the kick-drift-kick map: 10 Kepler drifts and 14 kicks per step instead of 14 and 10
    "WH-mpe-vv:1,2,3,4": [300, 200, 150, 100],
    "WHD-M8": [300, 200, 100],
}
DIRECT = {
    "M8": [40, 30, 20, 15, 10],
    "M10": [60, 40, 30, 20],
    "M12": [80, 60, 40],
    "M16": [120, 80, 60],
    "KL8": [20, 10, 5],
    "SS10": [40, 20, 10],
    "RKNa14": [10, 5, 2.5],
    "DP12": [60, 40, 20],
}
ADAPTIVE = {"DP12-adaptive": [1e-12, 1e-13, 1e-14]}
TARGET = 1e-12
REFERENCE = {"method": "WH-mpe:1,2,3,4,5,6", "h": 25.0, "precision": "long-double"}


def command(tool, years, method, extra):
    return [tool, "run", "--problem", "outer-solar-system", "--json", "--no-reference", "--method", method,
            "--years", repr(years), *extra]


def run(tool, years, method, extra):
    out = subprocess.run(command(tool, years, method, extra), check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def reference_key(years):
    return f"{REFERENCE['method']}|{REFERENCE['precision']}|h={REFERENCE['h']!r}|years={years!r}"


def crossing(points, target):
    """Cost at which error = target, log-log between the bracketing runs (points: (cost, error), any order).
    Returns (cost, how): how is 'interpolated', 'at most' (every run below target: the cheapest run's cost bounds
    it from above) or None when no run reached the target."""
    pts = sorted((c, e) for c, e in points if c > 0 and e > 0)
    if not pts:
        return None, None
    below = [p for p in pts if p[1] <= target]
    if not below:
        return None, None
    first = below[0]
    i = pts.index(first)
    if i == 0:
        return first[0], "at most"
    (c0, e0), (c1, e1) = pts[i - 1], first
    t = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
    return math.exp(math.log(c0) + t * (math.log(c1) - math.log(c0))), "interpolated"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tool", required=True, help="the nystrom program (Release build)")
    p.add_argument("--years", type=float, default=1e5)
    p.add_argument("--cache", default="planetary_reference.json", help="reference cache (JSON, keyed by horizon)")
    p.add_argument("--only", action="append",
                   help="methods to run, comma-separated or repeated; a value that names a method of the sweep "
                        "whole (SABA(10,6,4), WH-mpe-vv:1,2,3,4) is not split (default: all)")
    p.add_argument("--json", help="write every run to this file")
    p.add_argument("--markdown", help="write the tables as markdown to this file")
    a = p.parse_args()

    cache = {}
    if os.path.exists(a.cache):
        with open(a.cache) as f:
            cache = json.load(f)
    key = reference_key(a.years)
    ref_proc = None
    if key not in cache:
        ref_proc = subprocess.Popen(command(a.tool, a.years, REFERENCE["method"],
                                            ["--h", repr(REFERENCE["h"]), "--precision", REFERENCE["precision"]]),
                                    stdout=subprocess.PIPE, text=True)

    jobs = [(m, ["--h", repr(h)], "map") for m, hs in MAPS.items() for h in hs]
    jobs += [(m, ["--h", repr(h)], "direct") for m, hs in DIRECT.items() for h in hs]
    jobs += [(m, ["--h", "100", "--tol", repr(t)], "direct") for m, ts in ADAPTIVE.items() for t in ts]
    only = None
    if a.only:
        known = {j[0] for j in jobs}
        only = set()
        for v in a.only:
            only.update([v] if v in known else v.split(","))
    jobs = [j for j in jobs if only is None or j[0] in only]

    rows = []
    print(f"{a.years:g} years; {'method':14} {'h / tol':>8} {'forces':>11} {'drifts':>10} {'CPU s':>8} "
          f"{'energy err':>10}")
    for method, extra, kind in jobs:
        r = run(a.tool, a.years, method, extra)
        row = {"method": method, "kind": kind, "param": extra[-1],
               "force_evals": r["force_evals"], "kepler_drifts": r["kepler_drifts"], "seconds": r["cpu_seconds"],
               "energy_error": r["energy_error_max"], "jupiter": r["jupiter_position"], "jupiter_error": None}
        rows.append(row)
        print(f"{'':14}{method:14} {row['param']:>8} {r['force_evals']:>11} {r['kepler_drifts']:>10} "
              f"{r['cpu_seconds']:>8.3f} {r['energy_error_max']:>10.2e}")
        sys.stdout.flush()

    if ref_proc is not None:
        out, _ = ref_proc.communicate()
        if ref_proc.returncode != 0:
            sys.exit("the reference run failed")
        cache[key] = json.loads(out)
        with open(a.cache, "w") as f:
            json.dump(cache, f, indent=1)
    ref = cache[key]
    jref = ref["jupiter_position"]
    for row in rows:
        row["jupiter_error"] = math.dist(row["jupiter"], jref)

    def cost_at_target(method):
        rs = [r for r in rows if r["method"] == method]
        t, how = crossing([(r["seconds"], r["energy_error"]) for r in rs], TARGET)
        f, _ = crossing([(r["force_evals"], r["energy_error"]) for r in rs], TARGET)
        return t, f, how

    summary = []
    for method in dict.fromkeys(r["method"] for r in rows):
        kind = next(r["kind"] for r in rows if r["method"] == method)
        t, f, how = cost_at_target(method)
        floor = min(r["energy_error"] for r in rows if r["method"] == method)
        summary.append({"method": method, "kind": kind, "seconds": t, "forces": f, "how": how, "floor": floor})

    lines = [f"Outer solar system, {a.years:g} years; reference {ref['method']} in long double at "
             f"h = {REFERENCE['h']:g} days (its own energy error {ref['energy_error_max']:.1e}, "
             f"{ref['cpu_seconds']:.0f} s of CPU).", "",
             "| method | h (days) or tol | kicks / forces | Kepler drifts | CPU s | energy error "
             "| Jupiter error (AU) |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        lines.append(f"| `{r['method']}` | {r['param']} | {r['force_evals']} | {r['kepler_drifts']} | "
                     f"{r['seconds']:.3f} | {r['energy_error']:.1e} | {r['jupiter_error']:.1e} |")
    lines += ["", f"Cost at a relative energy error of {TARGET:g} (log-log interpolation in the sweep):", "",
              "| method | kind | CPU s | kicks / forces | smallest energy error |",
              "| --- | --- | ---: | ---: | ---: |"]
    for s in sorted(summary, key=lambda s: s["seconds"] if s["seconds"] else math.inf):
        if s["seconds"]:
            c = f"{'<= ' if s['how'] == 'at most' else ''}{s['seconds']:.3f}"
            fo = f"{'<= ' if s['how'] == 'at most' else ''}{s['forces']:.3g}"
        else:
            c = fo = "not reached"
        lines.append(f"| `{s['method']}` | {s['kind']} | {c} | {fo} | {s['floor']:.1e} |")
    reached = [s for s in summary if s["seconds"]]
    bm = min((s for s in reached if s["kind"] == "map"), key=lambda s: s["seconds"], default=None)
    bd = min((s for s in reached if s["kind"] == "direct"), key=lambda s: s["seconds"], default=None)
    lines.append("")
    if bm and bd:
        lines.append(f"Cheapest at {TARGET:g}: map `{bm['method']}` {bm['seconds']:.3f} s, direct `{bd['method']}` "
                     f"{bd['seconds']:.3f} s: direct / map time ratio {bd['seconds'] / bm['seconds']:.2f}, force "
                     f"ratio {bd['forces'] / bm['forces']:.2f}.")
    best = min(summary, key=lambda s: s["floor"])
    lines.append(f"Smallest relative energy error reached: {best['floor']:.1e} (`{best['method']}`).")
    text = "\n".join(lines)
    print()
    print(text)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text + "\n")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"years": a.years, "reference": ref, "runs": rows, "summary": summary}, f, indent=1)


if __name__ == "__main__":
    main()
