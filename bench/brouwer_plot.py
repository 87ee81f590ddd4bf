"""Charts of the CSVs of bench_brouwer (Kepler), bench_brouwer_planetary (the outer solar system) and
bench/rebound/ias15_brouwer: relative energy error and position error against the number of periods, log-log,
one line per method (the root mean square over the realizations where a CSV has several), with the slopes of
Brouwer's law (t^(1/2) for the energy, t^(3/2) for the position) drawn through the last point of the first method
for comparison. Errors below 1e-18 (an energy kept to the last bit at
the first periods) are left out.

    python3 bench/brouwer_plot.py CSV [CSV ...] OUT_PREFIX

writes OUT_PREFIX_energy.png and OUT_PREFIX_position.png (each written to a temporary file and renamed).
"""
import csv
import os
import sys


def main():
    if len(sys.argv) < 3:
        print("usage: brouwer_plot.py CSV [CSV ...] OUT_PREFIX", file=sys.stderr)
        return 2
    paths, prefix = sys.argv[1:-1], sys.argv[-1]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = {}
    planetary = False
    realizations = 1
    for path in paths:
        try:
            with open(path, newline="") as f:
                for row in csv.DictReader(f):
                    if "steps_per_period" in row:  # Kepler
                        label = row["method"] + (" %s steps/period" % row["steps_per_period"]
                                                 if row["steps_per_period"] != "0" else " tol %s" % row["tol"])
                    else:  # the outer solar system: the label says the step or the tolerance
                        label = row["method"]
                        planetary = True
                        realizations = max(realizations, int(row.get("realizations") or 1))
                    runs.setdefault(label, []).append(
                        (float(row["periods"]), float(row["energy_error"]), float(row["position_error"])))
        except (OSError, KeyError, ValueError, TypeError) as e:
            print("brouwer_plot.py: cannot read %s: %s" % (path, e), file=sys.stderr)
            return 2
    if not runs:
        print("brouwer_plot.py: no runs in %s" % ", ".join(paths), file=sys.stderr)
        return 2
    for col, name, slope in ((1, "energy", 0.5), (2, "position", 1.5)):
        fig, ax = plt.subplots(figsize=(7, 5))
        for label, pts in runs.items():
            xs = [p[0] for p in pts if p[col] > 1e-18]
            ys = [p[col] for p in pts if p[col] > 1e-18]
            ax.loglog(xs, ys, "o-", ms=3, label=label)
        first = next(iter(runs.values()))
        x1, y1 = first[-1][0], max(first[-1][col], 1e-300)
        xs = [x1 / 1e4, x1]
        ax.loglog(xs, [y1 * (x / x1) ** slope for x in xs], "k--", lw=1, label="t^%g (Brouwer)" % slope)
        ax.loglog(xs, [y1 * (x / x1) ** (slope + 0.5) for x in xs], "k:", lw=1, label="t^%g (a bias)" % (slope + 0.5))
        ax.set_xlabel("Jupiter periods" if planetary else "periods")
        if name == "energy":
            ax.set_ylabel("relative energy error")
        else:
            ax.set_ylabel("Jupiter's position error (AU)" if planetary else "position error")
        system = "The outer solar system" if planetary else "Kepler e = 0.5"
        spread = ", rms over %d realizations" % realizations if realizations > 1 else ""
        ax.set_title("%s in double: %s error of long runs%s" % (system, name, spread))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        out = "%s_%s.png" % (prefix, name)
        tmp = out + ".tmp.png"
        fig.savefig(tmp, dpi=110, bbox_inches="tight")
        plt.close(fig)
        os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
