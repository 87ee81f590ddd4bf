"""nystrom.plot: charts without surprises (default labels, no invented values, distinguishable series)."""
import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import nystrom  # noqa: E402
import nystrom.plot  # noqa: E402
from nystrom.problems import HarmonicOscillator, Kepler  # noqa: E402


def test_work_precision_without_labels_uses_the_method():
    rows = []
    for method in ("M4", "M6"):
        for steps in (100, 200, 400):
            res = nystrom.solve(Kepler(0.5), t_span=(0, 6.0), method=method, steps=steps)
            rows.append(dict(method=res.method, force_evals=res.force_evals,
                             error=float(np.abs(res.q[-1] - Kepler(0.5).exact(6.0)[0]).max())))
    ax = nystrom.plot.work_precision(rows)
    assert [line.get_label() for line in ax.get_lines()] == ["M4", "M6"]
    assert all(len(line.get_xdata()) == 3 for line in ax.get_lines())
    rows2 = [dict(r, label=f"{r['method']} run") for r in rows]
    ax = nystrom.plot.work_precision(rows2)
    assert [line.get_label() for line in ax.get_lines()] == ["M4 run", "M6 run"]


def test_work_precision_series_never_share_a_style():
    rows = [dict(label=f"s{i}", force_evals=10.0 * (j + 1), error=10.0 ** -(i + j)) for i in range(25)
            for j in range(2)]
    ax = nystrom.plot.work_precision(rows)
    lines = ax.get_lines()
    assert len(lines) == 25
    styles = {(matplotlib.colors.to_hex(line.get_color()), line.get_linestyle(), line.get_marker())
              for line in lines}
    assert len(styles) == 25


def test_energy_error_leaves_zeros_out_instead_of_clamping_them():
    # Verlet on the oscillator conserves no energy exactly, but a state equal to the first has error 0
    prob = HarmonicOscillator()
    res = nystrom.solve(prob, t_span=(0, 1.0), method="VV", steps=10)
    res.q[3] = res.q[0]
    res.v[3] = res.v[0]
    ax = nystrom.plot.energy_error(res, prob)
    y = ax.get_lines()[0].get_ydata()
    assert np.ma.is_masked(y) and np.ma.getmaskarray(y)[2]  # the state at index 3 (index 2 of t[1:])
    shown = np.ma.compressed(y)
    assert len(shown) == 9 and shown.min() > 1e-17  # no point drawn at an invented floor
