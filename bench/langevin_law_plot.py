"""Chart of the CSV of bench_langevin_law: the exact stationary bias of <q^2> and <q^4> in the double well against
force evaluations per unit of simulated time, log-log, for BAOAB and its two- and three-term multi-product
extrapolations (|bias|; the largest of the two observables per point, and each observable as a thin line).

    python3 bench/langevin_law_plot.py CSV OUT.png

writes OUT.png (to a temporary file, then renamed).
"""
import csv
import os
import sys


def main():
    if len(sys.argv) != 3:
        print("usage: langevin_law_plot.py CSV OUT.png", file=sys.stderr)
        return 2
    path, out = sys.argv[1], sys.argv[2]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = {}
    try:
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                rows.setdefault(r["method"], []).append(
                    (float(r["forces_per_time"]), abs(float(r["bias_q2"])), abs(float(r["bias_q4"]))))
    except (OSError, KeyError, ValueError) as e:
        print(f"langevin_law_plot.py: cannot read {path}: {e}", file=sys.stderr)
        return 2
    if not rows:
        print(f"langevin_law_plot.py: no rows in {path}", file=sys.stderr)
        return 2
    fig, ax = plt.subplots(figsize=(7, 5))
    for method, pts in rows.items():
        pts.sort()
        x = [p[0] for p in pts]
        line, = ax.loglog(x, [max(p[1], p[2]) for p in pts], "o-", ms=3, label=method)
        ax.loglog(x, [p[1] for p in pts], "--", lw=0.7, color=line.get_color())
        ax.loglog(x, [p[2] for p in pts], ":", lw=0.7, color=line.get_color())
    ax.axhline(1e-4, color="gray", lw=0.5)
    ax.set_xlabel("force evaluations per unit time")
    ax.set_ylabel("|stationary bias| (max; dashed <q^2>, dotted <q^4>)")
    ax.set_title("double well, kT = 0.5, gamma = 1: exact bias of BAOAB and its extrapolations", fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
