"""Plots with matplotlib: orbits, energy errors, work-precision charts. Each function draws on ``ax``
(a new figure when None) and returns the Axes; save with ``ax.figure.savefig(path)``."""

import numpy as np

__all__ = ["orbit", "energy_error", "work_precision"]


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "ps", "cairo") and not _interactive():
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    return ax


def _interactive():
    import sys

    return hasattr(sys, "ps1") or "IPython" in sys.modules


def orbit(result, ax=None, axes=(0, 1), particles=None, **style):
    """Positions of ``result`` (``nystrom.solve``) in the plane of coordinates ``axes``. For N-body states
    (shape (k, N, 3)) one curve per particle (all, or the indices in ``particles``)."""
    ax = _axes(ax)
    q = np.asarray(result.q)
    i, j = axes
    if q.ndim == 3:
        for p in range(q.shape[1]) if particles is None else particles:
            ax.plot(q[:, p, i], q[:, p, j], lw=0.8, **style)
    else:
        flat = q.reshape(len(q), -1)
        ax.plot(flat[:, i], flat[:, j], lw=0.8, **style)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"q[{i}]")
    ax.set_ylabel(f"q[{j}]")
    ax.set_title(f"{result.method}: orbit")
    return ax


def energy_error(result, energy, ax=None, label=None, **style):
    """Relative energy error |E(t) - E(0)| / |E(0)| against t; ``energy`` is a function energy(q, v) of the
    states (e.g. ``problem.energy``) or a problem with such a method. Times where the error is exactly 0
    have no point on the logarithmic axis: they are left out (gaps in the line), not drawn at some floor."""
    ax = _axes(ax)
    fn = getattr(energy, "energy", energy)
    E = np.array([fn(q, v) for q, v in zip(result.q, result.v)], dtype=float)
    err = np.abs(E - E[0]) / max(abs(E[0]), np.finfo(float).tiny)
    shown = np.ma.masked_less_equal(err[1:], 0.0)
    ax.semilogy(np.asarray(result.t)[1:], shown, label=label or result.method, **style)
    ax.set_xlabel("t")
    ax.set_ylabel("relative energy error")
    if label or result.method:
        ax.legend()
    return ax


# Line styles cycled after the colours: every series of a chart differs from every other one in colour or dash.
_DASHES = ["-", "--", ":", "-."]
_MARKERS = ["o", "s", "^", "v", "D", "P", "X", "*"]


def _series_styles(count):
    """(colour, line style, marker) for each of ``count`` series, all distinct: the 10 colours of matplotlib's
    "tab10" cycle, then again with another line style and marker, and so on."""
    import matplotlib

    colours = list(matplotlib.colormaps["tab10"].colors)
    out = []
    for i in range(count):
        turn = i // len(colours)
        out.append((colours[i % len(colours)], _DASHES[turn % len(_DASHES)], _MARKERS[turn % len(_MARKERS)]))
    return out


def work_precision(rows, ax=None, x="force_evals", y="error"):
    """Work-precision chart: ``rows`` is a list of dicts (or results) with ``x`` and ``y`` keys (default
    ``force_evals`` and ``error``) and optionally ``label``; one line per label, log-log. Without a ``label``
    a row belongs to the series of its ``method`` (as ``nystrom.solve`` results carry it)."""
    ax = _axes(ax)
    series = {}
    for r in rows:
        label = r.get("label") or r.get("method") or "series"
        series.setdefault(str(label), []).append((float(r[x]), float(r[y])))
    for (label, pts), (colour, dash, marker) in zip(series.items(), _series_styles(len(series))):
        pts.sort()
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], color=colour, linestyle=dash, marker=marker, ms=3,
                  label=label)
    ax.set_xlabel(x.replace("_", " "))
    ax.set_ylabel(y.replace("_", " "))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax
