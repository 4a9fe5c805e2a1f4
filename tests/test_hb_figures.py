"""Figures: an HB response figure spans the requested ω range even where no point has a value (hatched there),
and amplitude spectra are stems with dots from a floor near the data for a line spectrum and one line for a
dense one (dense stems from 1e-12 filled the axis like bars)."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402

from geardyn.analysis.hb import hb_continuation  # noqa: E402
from geardyn.analysis.hb.response import response_from_branch  # noqa: E402
from geardyn.model import GearModel  # noqa: E402
from geardyn.plot import common  # noqa: E402
from geardyn.plot.response import response  # noqa: E402


def _axes():
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    return fig, ax


def _xspan(p):
    """The x extent (data) of an axvspan, a Rectangle or (older Matplotlib) a Polygon."""
    if isinstance(p, Rectangle):
        return p.get_x(), p.get_x() + p.get_width()
    xy = np.asarray(p.get_xy())
    return float(xy[:, 0].min()), float(xy[:, 0].max())


def test_line_spectrum_is_stems_with_dots_from_a_floor_near_the_data():
    x = np.arange(41) * 0.5
    amp = np.full(41, 1e-17)  # rounding between the harmonics of a periodic response
    amp[2::2] = 10.0 ** -np.arange(20) * 0.9  # 20 harmonics from 0.9 down to 9e-20 (the smallest below 1e-6 of it)
    fig, ax = _axes()
    common.log_stems(ax, x, amp)
    lo, hi = ax.get_ylim()
    assert ax.get_yscale() == "log"
    assert lo == pytest.approx(1e-7) and hi == pytest.approx(1.8)  # a decade under 9e-7, the last within 1e-6
    (stems,) = [c for c in ax.collections if isinstance(c, LineCollection)]
    segs = stems.get_segments()
    assert len(segs) == 7  # the harmonics within six decades of the peak; none of the rounding
    assert all(s[0][1] == pytest.approx(lo) for s in segs)  # from the floor of the axis, not from 1e-12
    tops = sorted(s[1][1] for s in segs)
    np.testing.assert_allclose(tops, sorted(0.9 * 10.0 ** -np.arange(7)))
    (dots,) = [ln for ln in ax.lines if ln.get_gid() == "spectrum-peaks"]
    assert dots.get_marker() == "o" and len(dots.get_xdata()) == 7
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_dense_spectrum_is_one_line():
    rng = np.random.default_rng(1)
    x = np.linspace(0.0, 10.0, 401)
    amp = 1e-3 * (1.0 + rng.random(401))
    amp[20] = 0.7
    fig, ax = _axes()
    common.log_stems(ax, x, amp)
    assert not [c for c in ax.collections if isinstance(c, LineCollection)]  # no stems filling the axis
    (line,) = [ln for ln in ax.lines if ln.get_gid() == "spectrum"]
    np.testing.assert_array_equal(line.get_xdata(), x[1:])
    np.testing.assert_array_equal(line.get_ydata(), amp[1:])
    assert ax.get_ylim()[0] == pytest.approx(1e-4) and len(x) - 1 > common.STEM_MAX
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_hb_response_axis_covers_the_requested_range_with_the_gap_hatched():
    grid = np.linspace(0.5, 0.65, 16)
    ds = response_from_branch(hb_continuation(GearModel(), "omega", 0.5, 0.65, harmonics=8), grid)
    for v in ("amplitude", "rms", "mean", "u_min", "u_max"):
        ds[v][:, -5:] = math.nan  # no stable period-n solution on the last five points of both sweeps
    art = response(ds)
    ax = art.axes[0]
    lo, hi = ax.get_xlim()
    assert lo < 0.5 and hi > 0.65  # it ended at the last point with a value
    hatched = [p for p in ax.patches if isinstance(p, (Polygon, Rectangle)) and p.get_hatch() == "///"]
    assert len(hatched) == 5
    spans = sorted(_xspan(p) for p in hatched)
    assert spans[0][0] == pytest.approx(0.5 * (grid[10] + grid[11])) and spans[-1][1] == pytest.approx(0.65)
    assert "no stable period-n solution" in [t.get_text() for t in ax.get_legend().get_texts()]
    import matplotlib.pyplot as plt

    plt.close(art.figure)
