"""The report's own figures read as the claims need, checked on the drawn artists: the formula fit in
small multiples, the responses a claim compares on one axes, the gaps of the stability figure named."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from matplotlib.colors import to_rgba

from geardyn.plot.common import new_figure
from geardyn.plot.registry import draw, figures_for

MODEL = json.dumps({"omega": 1.0, "D": 0.25, "xi0": 0.08, "xi": [0.05], "fp": 0.2, "kappa": [0.2], "eps": [0.5]})


def _formula(groups=((0.08, 0.2), (0.08, 0.5), (0.08, 0.7), (0.08, 1.5), (0.1, 0.5), (0.15, 0.5))):
    w = np.linspace(0.3, 1.2, 7)
    rows = [(x, g[0], g[1], 0.5 + 0.1 * k + 0.3 * np.sin(np.pi * x)) for k, g in enumerate(groups) for x in w]
    om, xi0, b, a = (np.array(c) for c in zip(*rows))
    return xr.Dataset(
        {"omega": ("point", om), "xi0": ("point", xi0), "b_mm": ("point", b), "amplitude": ("point", a)},
        attrs={"geardyn_kind": "formula_fit", "model": MODEL, "A0": "0.5", "dA": "0.3", "beta": "0.1", "r2": "0.4"},
    )


def _style(line):
    return (to_rgba(line.get_color()), str(line.get_linestyle()), str(line.get_marker()))


def test_formula_fit_draws_one_panel_per_curve_each_labelled_in_a_style_of_its_own():
    ds = _formula()
    art = draw(ds, "formula_fit")
    axes = art.figure.axes
    assert len(axes) == 6  # small multiples: one panel per (ξ0, b), not nine curves stacked on one axes
    titles = [ax.get_title() for ax in axes]
    assert titles == [
        "ξ0 = 0.08, b = 0.2 mm",
        "ξ0 = 0.08, b = 0.5 mm",
        "ξ0 = 0.08, b = 0.7 mm",
        "ξ0 = 0.08, b = 1.5 mm",
        "ξ0 = 0.1, b = 0.5 mm",
        "ξ0 = 0.15, b = 0.5 mm",
    ]
    styles = []
    for ax in axes:
        dots = [ln for ln in ax.get_lines() if ln.get_linestyle() == "None"]
        fits = [ln for ln in ax.get_lines() if ln.get_linestyle() != "None"]
        assert len(dots) == 1 and len(fits) == 1 and len(dots[0].get_xdata()) == 7
        styles.append((str(fits[0].get_linestyle()), dots[0].get_marker(), to_rgba(fits[0].get_color())))
    assert len({s[0] for s in styles}) == 4 and len({s[1] for s in styles}) == 6 and len({s[2] for s in styles}) == 6
    assert axes[0].get_shared_y_axes().joined(axes[0], axes[5])  # one amplitude scale for every panel
    legend = [t.get_text() for t in axes[0].get_legend().get_texts()]
    assert legend == ["computed (up sweep)", "fitted formula"]
    assert "R² = 0.400" in art.figure.get_suptitle() and "κ1 = 0.2" in art.figure.get_suptitle()


def test_formula_fit_on_one_axes_labels_every_curve_at_its_end_in_distinct_styles():
    ds = _formula()
    fig = new_figure()
    ax = fig.add_subplot()
    draw(ds, "formula_fit", ax=ax)
    fits = [ln for ln in ax.get_lines() if ln.get_linestyle() != "None"]
    assert len(fits) == 6 and len({_style(ln) for ln in fits}) == 6
    labels = sorted(t.get_text() for t in ax.texts)
    assert labels == sorted(
        f"ξ0 = {x:g}, b = {b:g} mm"
        for x, b in {(0.08, 0.2), (0.08, 0.5), (0.08, 0.7), (0.08, 1.5), (0.1, 0.5), (0.15, 0.5)}
    )


def overlay(n=3, param="xi0"):
    """A synthetic ``response_overlay``: n responses, the second with an upward jump at ω = 0.6."""
    w = np.round(np.linspace(0.3, 1.2, 10), 4)
    amp = np.stack(
        [np.stack([np.sin(np.pi * w) * (1 - 0.2 * i), np.sin(np.pi * w) * (1 - 0.2 * i) + 0.05]) for i in range(n)]
    )
    jumps = [[] for _ in range(n)]
    jumps[1] = [
        {"omega": 0.6, "direction": "up", "size": 0.4, "sweep": "up", "amplitude_from": 0.3, "amplitude_to": 0.7},
        {"omega": 0.9, "direction": "down", "size": 0.2, "sweep": "down", "amplitude_from": 0.8, "amplitude_to": 0.6},
    ]
    return xr.Dataset(
        {
            "amplitude": (("case", "sweep", "omega"), amp),
            "fluctuation": (("case", "omega"), np.zeros((n, w.size))),
            "value": ("case", [0.08, 0.1, 0.15, 0.2][:n]),
        },
        coords={"case": np.arange(n), "sweep": ["up", "down"], "omega": w},
        attrs={
            "geardyn_kind": "response_overlay",
            "param": param,
            "model": MODEL,
            "jumps": json.dumps(jumps),
            "hysteresis": json.dumps([[] for _ in range(n)]),
            "marks": json.dumps([[0.5, "ω = 0.5: steady below (paper)"], [0.57, "ω = 0.57: jumps (paper)"]]),
            "table4": json.dumps([[0, 0.6, 0.45, "T4-2"], [2, 0.6, 0.3, "T4-3"]]),
        },
    )


def test_response_overlay_draws_the_compared_responses_on_one_axes():
    ds = overlay()
    (spec,) = figures_for(ds)
    art = spec(ds)
    amp, zoom, fl = art.figure.axes
    assert len(art.axes) == 3 and amp.get_shared_x_axes().joined(amp, fl)
    assert zoom.get_title() == "zoom on the first upward jumps (up sweeps)"
    lo, hi = zoom.get_xlim()
    step = 0.1
    assert lo == pytest.approx(0.6 - 4 * step) and hi == pytest.approx(0.6 + 4 * step)
    assert len([ln for ln in zoom.get_lines() if ln.get_gid() == "up"]) == 3
    assert [ln.get_xdata()[0] for ln in zoom.get_lines() if ln.get_gid() == "jump"] == [0.6]
    ups = [ln for ln in amp.get_lines() if ln.get_gid() == "up"]
    downs = [ln for ln in amp.get_lines() if ln.get_gid() == "down"]
    assert len(ups) == len(downs) == 3  # both sweeps of every response on the one axes
    assert len({_style(ln) for ln in ups}) == 3  # colour, line style and marker of its own per response
    for up, down in zip(ups, downs):
        assert _style(up) == _style(down) and down.get_markerfacecolor() == "none"
        assert up.get_linewidth() > down.get_linewidth()
    legend = [t.get_text() for t in amp.get_legend().get_texts()]
    assert legend[:3] == ["ξ0 = 0.08", "ξ0 = 0.1", "ξ0 = 0.15"]
    assert "ω = 0.5: steady below (paper)" in legend and "ω = 0.57: jumps (paper)" in legend
    assert any("up sweep" in t for t in legend) and any("down sweep" in t for t in legend)
    direct = {t.get_text() for t in amp.texts}  # every curve labelled at its end, the paper's ω named on the axes
    assert {"ξ0 = 0.08", "ξ0 = 0.1", "ξ0 = 0.15", "ω = 0.5", "ω = 0.57", "T4-2", "T4-3"} <= direct
    stars = [ln for ln in amp.get_lines() if ln.get_gid() == "jump"]
    assert len(stars) == 1 and list(stars[0].get_xdata()) == [0.6] and list(stars[0].get_ydata()) == [0.7]
    assert _style(stars[0])[0] == _style(ups[1])[0]  # in the colour of the response that jumps
    crosses = [ln for ln in amp.get_lines() if ln.get_gid() == "table4"]
    assert [(ln.get_xdata()[0], ln.get_ydata()[0]) for ln in crosses] == [(0.6, 0.45), (0.6, 0.3)]
    marks = sorted(ln.get_xdata()[0] for a in (amp, fl) for ln in a.get_lines() if ln.get_gid() == "mark")
    assert marks == [0.5, 0.5, 0.57, 0.57]
    assert len([ln for ln in fl.get_lines() if ln.get_gid() != "mark"]) == 3
    assert "compared over ξ0" in amp.get_title() and "ξ1 = 0.05" in amp.get_title()
    bbox = amp.get_legend().get_window_extent(art.figure.canvas.get_renderer())
    assert bbox.x0 >= amp.get_window_extent(art.figure.canvas.get_renderer()).x1  # the legend beside the data


def test_response_overlay_without_a_jump_has_no_zoom_panel():
    ds = overlay()
    ds.attrs["jumps"] = json.dumps([[] for _ in range(3)])
    art = draw(ds, "response_overlay")
    assert len(art.axes) == 2 and not [ln for ln in art.axes[0].get_lines() if ln.get_gid() == "jump"]
    assert "zoom" not in " ".join(ax.get_title() for ax in art.figure.axes)


def test_response_overlay_over_d_names_the_paper_backlash():
    art = draw(overlay(4, "D"), "response_overlay")
    legend = [t.get_text() for t in art.axes[0].get_legend().get_texts()]
    assert legend[:4] == [
        "D = 0.08 (b = 0.16 mm)",
        "D = 0.1 (b = 0.2 mm)",
        "D = 0.15 (b = 0.3 mm)",
        "D = 0.2 (b = 0.4 mm)",
    ]


def _stability(kinds, crit, linear):
    om = np.round(np.linspace(0.4, 1.4, len(kinds)), 3)
    return xr.Dataset(
        {
            "xi0_critical": ("omega", crit),
            "bifurcation_type": ("omega", kinds),
            "xi0_critical_linear": ("omega", linear),
            "xi0_paper": 0.4899,
        },
        coords={"omega": om},
        attrs={"geardyn_kind": "stability_comparison", "model": MODEL, "xi0_low": "0.001", "xi0_high": "0.6"},
    )


def test_stability_figure_marks_and_names_each_kind_of_gap():
    kinds = ["stable", "period-doubling", "start orbit not found", "fold", "scan incomplete (max_steps)", "stable"]
    crit = [np.nan, 0.1, np.nan, 0.2, np.nan, np.nan]
    ds = _stability(kinds, crit, [0, 0, np.nan, 0.05, 0, 0])
    art = draw(ds, "stability_boundary")
    ax = art.axes[0]
    gaps = {ln.get_label(): list(ln.get_xdata()) for ln in ax.get_lines() if ln.get_gid() == "gap"}
    om = ds["omega"].values
    stable = "gap: full model stays stable down to ξ0 = 0.001 (no boundary above it)"
    undecided = "gap: stability not decided (scan incomplete (max_steps); start orbit not found)"
    linear = "gap in the linear boundary: still unstable at the top of its search, no boundary found"
    assert gaps == {stable: [om[0], om[5]], undecided: [om[2], om[4]], linear: [om[2]]}
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {stable, undecided, linear} <= set(legend)
    markers = {ln.get_label(): ln.get_marker() for ln in ax.get_lines() if ln.get_gid() == "gap"}
    assert len(set(markers.values())) == 3  # each kind of gap in a marker of its own


def test_stability_figure_without_gaps_draws_no_gap_marker():
    ds = _stability(["fold", "period-doubling"], [0.1, 0.2], [0.0, 0.01])
    art = draw(ds, "stability_boundary")
    assert not [ln for ln in art.axes[0].get_lines() if ln.get_gid() == "gap"]


@pytest.mark.parametrize("case", ["stable", "undecided", "none"])
def test_stability_caption_explains_the_gaps(case):
    from geardyn.paper.studies.stability import gaps_text

    if case == "stable":
        ds = _stability(["stable", "fold"], [np.nan, 0.1], [0.0, 0.0])
        text = gaps_text(ds)
        assert "Gaps (▽ on the ω axis) at ω = 0.4: the period-1 response stays stable down to ξ0 = 0.001" in text
        assert "not decided" not in text
    elif case == "undecided":
        ds = _stability(["fold", "start orbit not found"], [0.1, np.nan], [0.0, np.nan])
        text = gaps_text(ds)
        assert "Gaps (× on the ω axis) at ω = 1.4: stability could not be decided (start orbit not found)." in text
        assert "The linear boundary is missing (△ at the top) at ω = 1.4" in text
    else:
        text = gaps_text(_stability(["fold", "fold"], [0.1, 0.2], [0.0, 0.0]))
        assert "no gaps" in text and "Gaps (" not in text
