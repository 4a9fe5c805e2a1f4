"""Figures of the reproduction report that no other result kind has: formula fit, ω search."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from .common import cell_edges, json_list, parameter_text, place_labels, plot_function, set_title, spread, symbol

__all__ = ["CURVE_STYLES", "curve_style", "end_labels", "formula_fit", "readings_map", "response_overlay", "search_map"]


#: Line style and marker of the i-th curve of a figure that compares several (cycled): curves stay
#: distinguishable without colour.
CURVE_STYLES = (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"), ((0, (5, 1, 1, 1, 1, 1)), "v"), ((0, (1, 3)), "P"))


def curve_style(i: int) -> dict:
    """Colour, line style and marker of the i-th of several compared curves (:data:`CURVE_STYLES`, cycled).

    Parameters
    ----------
    i : int
        The curve's index.

    Returns
    -------
    dict
        ``color``, ``ls`` and ``marker``.
    """
    ls, marker = CURVE_STYLES[i % len(CURVE_STYLES)]
    return {"color": f"C{i % 10}", "ls": ls, "marker": marker}


def _formula_groups(ds: xr.Dataset) -> list[tuple[float, float]]:
    return sorted({(float(x), float(y)) for x, y in zip(ds["xi0"].values, ds["b_mm"].values)})


def _formula_grid(ds: xr.Dataset) -> tuple[int, int]:
    n = len(_formula_groups(ds))
    cols = min(3, n)
    return -(-n // cols), cols


@plot_function(
    "formula_fit",
    lambda ds: (1.2 + 3.3 * _formula_grid(ds)[1], 1.4 + 2.6 * _formula_grid(ds)[0]),
    n=lambda ds: len(_formula_groups(ds)),
    subplots=lambda ds: dict(zip(("nrows", "ncols"), _formula_grid(ds)), sharex=True, sharey=True),
    tight=True,
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of Axes, optional
                   Where to draw: one Axes per (ξ0, b) (small multiples), or one Axes for every curve
                   (each in its own colour, line style and marker, labelled at its end); a new figure
                   of small multiples if omitted.""",
)
def formula_fit(ds: xr.Dataset, ax: Any = None) -> None:
    """Computed amplitudes against ω with the fitted A0 + ΔA sin(πω) e^(−ξ0 ω) + β b², one panel per
    (ξ0, b) on shared axes (a result of the reproduction report)."""
    A0, dA, beta = (float(ds.attrs[k]) for k in ("A0", "dA", "beta"))
    w, xi0, b, a = (ds[k].values for k in ("omega", "xi0", "b_mm", "amplitude"))
    axes = ax
    one = not any(axes[1:])  # one Axes for every curve (the other panels not drawn)
    ww = np.linspace(w.min(), w.max(), 300)
    ends = []
    for i, (x0, bb) in enumerate(_formula_groups(ds)):
        target = axes[0 if one else i]
        st = curve_style(i)
        sel = (xi0 == x0) & (b == bb)
        order = np.argsort(w[sel])
        name = f"ξ0 = {x0:g}, b = {bb:g} mm"
        target.plot(
            w[sel][order],
            a[sel][order],
            ls="none",
            marker=st["marker"],
            color=st["color"],
            ms=4,
            label=f"computed, {name}" if one else "computed (up sweep)",
        )
        fit = A0 + dA * np.sin(np.pi * ww) * np.exp(-x0 * ww) + beta * bb**2
        target.plot(ww, fit, ls=st["ls"], color=st["color"], lw=1.2, label=f"fit, {name}" if one else "fitted formula")
        if one:
            ends.append((ww[-1], fit[-1], name, st["color"]))
        else:
            target.set_title(name, fontsize=9, color=st["color"])
            target.grid(alpha=0.3)
    head = f"Amplitude formula fit: R² = {float(ds.attrs['r2']):.3f} (markers: computed, lines: fit)"
    if one:
        place_labels(axes[0], ends)
        axes[0].set_xlabel("mesh frequency ω = ω_e/ω_n")
        axes[0].set_ylabel("amplitude (half peak-to-peak of u) [b_c]")
        set_title(axes[0], head, ds, exclude=["omega", "xi0", "D"])
        return
    axes[0].legend(fontsize=7, loc="upper left")
    cols = axes[0].get_gridspec().ncols if axes[0].get_gridspec() is not None else 1
    for k, x in enumerate(axes):
        if k >= len(axes) - cols:
            x.set_xlabel("ω = ω_e/ω_n")
        if k % cols == 0:
            x.set_ylabel("amplitude (½ p-p of u) [b_c]")
    params = parameter_text(ds, exclude=["omega", "xi0", "D"])
    axes[0].figure.suptitle(f"{head}\n{params}" if params else head, fontsize=10)


@plot_function(
    "search",
    lambda ds: (7, 0.6 + 0.45 * ds["match_fraction"].shape[1] + 1.5),
    ax_doc="""
               ax : matplotlib.axes.Axes, optional
                   Where to draw; a new figure if omitted (the colour bar is added beside it).""",
)
def search_map(ds: xr.Dataset, ax: Axes = None) -> None:
    """Fraction of grid points matching each claim, for each searched ω (a result of the reproduction report)."""
    frac = ds["match_fraction"].values
    im = ax.imshow(
        frac.T,
        aspect="auto",
        origin="lower",
        vmin=0,
        vmax=1,
        cmap="viridis",
        extent=(-0.5, frac.shape[0] - 0.5, -0.5, frac.shape[1] - 0.5),
    )
    ax.set_xticks(range(frac.shape[0]), [f"{w:g}" for w in ds["omega"].values])
    ax.set_xlabel("ω searched")
    for (i, j), f in np.ndenumerate(frac):
        if np.isfinite(f):
            ax.text(i, j, f"{f:.0%}", ha="center", va="center", fontsize=7, color="w" if f < 0.6 else "k")
    param = str(ds.attrs.get("param"))
    _claims(
        ax, ds, im, "grid points matching the claim", f"Where the claims over {symbol(param)} hold", ["omega", param]
    )


def _claims(ax: Axes, ds: xr.Dataset, im: Any, share: str, title: str, exclude: list[str]) -> None:
    """The claims named on the y axis, the colour bar of the fraction of ``share`` and the title of a claims map."""
    ax.set_yticks(range(ds.sizes["claim"]), [str(c) for c in ds["claim"].values])
    ax.figure.colorbar(im, ax=ax, label=f"fraction of {share}")
    set_title(ax, title, ds, exclude=exclude)


@plot_function(
    "readings_map",
    lambda ds: (9, 1.6 + 0.32 * ds["hold_fraction"].shape[0]),
    ax_doc="""
               ax : matplotlib.axes.Axes, optional
                   Where to draw; a new figure if omitted (the colour bar is added beside it).""",
)
def readings_map(ds: xr.Dataset, ax: Axes = None) -> None:
    """Fraction of the readings (phase pairs, backlash readings) under which each claim's screen holds, against ω
    (a result of the reproduction report); the default ω dashed."""
    f = ds["hold_fraction"].values
    w = ds["omega"].values
    im = ax.pcolormesh(cell_edges(w), np.arange(f.shape[0] + 1) - 0.5, f, vmin=0, vmax=1, cmap="viridis")
    ax.axvline(float(ds.attrs.get("default_omega", 1.0)), color="w", ls="--", lw=0.8)
    ax.set_xlabel("mesh frequency ω = ω_e/ω_n (dashed: the default reading)")
    title = "Where each claim holds on the screen of readings"
    _claims(ax, ds, im, "the readings holding", title, ["omega", "xi0", "xi1", "D"])


#: Markers drawn per curve of an overlay (every k-th point; the lines join every point).
MARKERS_PER_CURVE = 15


def _zoom_on_jumps(zoom: Axes, w: np.ndarray, amp: np.ndarray, firsts: list[dict]) -> None:
    """Limits and labels of the inset over the first upward jumps (every jump with a margin of its grid steps)."""
    at = [j["omega"] for j in firsts]
    dw = float(np.median(np.diff(w))) if w.size > 1 else 0.01
    lo, hi = min(at) - 4 * dw, max(at) + 4 * dw
    sel = (w >= lo) & (w <= hi)
    vals = amp[:, :, sel]
    vals = vals[np.isfinite(vals)]
    if vals.size:
        pad = 0.08 * float(np.ptp(vals) or 1.0)
        zoom.set_ylim(float(vals.min()) - pad, float(vals.max()) + pad)
    zoom.set_xlim(lo, hi)
    zoom.set_title("zoom on the first upward jumps (up sweeps)", fontsize=9)
    zoom.set_ylabel("amplitude [b_c]", fontsize=8)
    zoom.grid(alpha=0.3)


def end_labels(ax: Axes, ends: list[tuple[float, float, str, str]]) -> list:
    """Label curves at their right ends, to the right, moved apart vertically so that no two overlap (at least 5 % of
    the height of the axes apart).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw (its y limits should be final).
    ends : list of (x, y, text, colour)
        The end point of each curve and its label.

    Returns
    -------
    list of matplotlib.text.Annotation
    """
    lo, hi = ax.get_ylim()
    d = 0.05 * (hi - lo)
    order = sorted(range(len(ends)), key=lambda k: ends[k][1])
    placed = dict(zip(order, spread([float(ends[k][1]) for k in order], d, np.inf)))
    return [
        ax.annotate(
            text,
            (x, placed[k]),
            xytext=(6, 0),
            textcoords="offset points",
            color=colour,
            fontsize=7,
            ha="left",
            va="center",
        )
        for k, (x, _, text, colour) in enumerate(ends)
    ]


def _case_text(param: str, value: float) -> str:
    text = f"{symbol(param)} = {value:g}"
    return text + f" (b = {2 * value:g} mm)" if param == "D" else text


def _up_jumps(ds: xr.Dataset) -> list[list[dict]]:
    """The upward jumps of each response's up sweep."""
    return [[j for j in js if j["sweep"] == "up" and j["direction"] == "up"] for js in json_list(ds, "jumps")]


def _has_up_jump(ds: xr.Dataset) -> bool:
    return any(_up_jumps(ds))


@plot_function(
    "response_overlay",
    lambda ds: (11, 10.5 if _has_up_jump(ds) else 7.5),
    n=lambda ds: 3 if _has_up_jump(ds) else 2,
    subplots=lambda ds: {"height_ratios": (2.2, 1.3, 1) if _has_up_jump(ds) else (2.2, 1)},
    tight=True,
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of Axes, optional
                   Where to draw: the amplitude panel only (one Axes), or every panel (the amplitude, the
                   zoom on the first upward jumps when there is one, the fluctuation); a new figure if omitted.""",
)
def response_overlay(ds: xr.Dataset, ax: Any = None) -> None:
    """Frequency responses at several values of one parameter on one axes, as the paper's claims compare
    them: amplitude of the up sweep (thick, small filled markers) and the down sweep (thin, large open
    markers) per value, each in its own colour, line style and marker and labelled at its end; the first
    upward jump of each starred (and zoomed on in a panel of its own); the ω the paper names dotted and
    its Table 4 amplitudes as crosses; below, the fluctuation (spread of the Poincaré points of the up
    sweep) on the same ω axis (a result of the reproduction report)."""
    amp_ax, zoom, fl_ax = ax if len(ax) == 3 else (ax[0], None, ax[1])
    both = [t for t in (amp_ax, zoom) if t is not None]
    if fl_ax is not None:
        fl_ax.sharex(amp_ax)
    param = str(ds.attrs["param"])
    w = ds["omega"].values
    values = ds["value"].values
    jumps = _up_jumps(ds)
    marks = json_list(ds, "marks")
    table4 = json_list(ds, "table4")
    ends = []
    step = max(1, w.size // MARKERS_PER_CURVE)
    firsts = []
    for i, v in enumerate(values):
        st = curve_style(i)
        every = (i * step // max(len(values), 1), step)  # markers of the curves staggered, not on top of each other
        up, down = ds["amplitude"].values[i]
        case = _case_text(param, float(v))
        js = jumps[i] if i < len(jumps) else []
        firsts.append(min(js, key=lambda j: j["omega"]) if js else None)
        for target in both:
            full = target is amp_ax
            # the down sweep under the up sweep, its open markers larger: a ring round the up sweep's where they agree
            target.plot(
                w,
                down,
                **st,
                ms=7,
                lw=0.7,
                mfc="none",
                markevery=every if full else None,
                gid="down",
                label="_nolegend_",
            )
            target.plot(
                w,
                up,
                **st,
                ms=3.5,
                lw=1.4,
                markevery=every if full else None,
                gid="up",
                label=case if full else None,
            )
        ends.append((w[-1], up[-1], f"{symbol(param)} = {float(v):g}", st["color"]))
        if fl_ax is not None:
            fl_ax.plot(
                w,
                ds["fluctuation"].values[i],
                **st,
                ms=3.5,
                lw=1.2,
                markevery=every,
                label=case,
            )
    for i, j in enumerate(firsts):
        for target in both if j is not None else ():
            target.plot(
                [j["omega"]],
                [j["amplitude_to"]],
                ls="none",
                marker="*",
                ms=13,
                color=curve_style(i)["color"],
                mec="k",
                mew=0.6,
                zorder=5,
                gid="jump",
                label="_nolegend_",
            )
    for case, omega, A, cid in table4:
        amp_ax.plot(
            [omega],
            [A],
            ls="none",
            marker="X",
            ms=9,
            color=curve_style(int(case))["color"],
            mec="k",
            mew=0.8,
            zorder=6,
            gid="table4",
            label="_nolegend_",
        )
        amp_ax.annotate(cid, (omega, A), xytext=(4, -9), textcoords="offset points", fontsize=6.5)
    for target in both + ([fl_ax] if fl_ax is not None else []):
        for omega, _ in marks:
            target.axvline(omega, color="0.35", ls=":", lw=1.0, gid="mark", zorder=0)
    if zoom is not None and any(firsts):
        _zoom_on_jumps(zoom, w, ds["amplitude"].values, [j for j in firsts if j is not None])
    for k, (omega, _) in enumerate(marks):  # staggered: the names of close ω do not overlap
        amp_ax.annotate(
            f"ω = {omega:g}",
            (omega, 1.0),
            xycoords=amp_ax.get_xaxis_transform(),
            xytext=(2, -3 - 10 * (k % 2)),
            textcoords="offset points",
            ha="left",
            va="top",
            fontsize=7,
            color="0.25",
            gid="mark",
        )
    span = float(w[-1] - w[0]) if w.size > 1 else 1.0
    amp_ax.set_xlim(w[0] - 0.02 * span, w[-1] + 0.14 * span)  # room for the labels at the curves' ends
    from matplotlib.lines import Line2D

    proxies = [
        Line2D([], [], color="0.3", ls="-", marker="o", lw=1.4, label="up sweep (filled markers)"),
        Line2D(
            [],
            [],
            color="0.3",
            ls="-",
            marker="o",
            ms=7,
            mfc="none",
            lw=0.7,
            label="down sweep (open markers, round the up sweep's where they agree)",
        ),
        Line2D([], [], color="0.3", ls="none", marker="*", ms=11, mec="k", label="first upward jump (up sweep)"),
    ]
    proxies += [Line2D([], [], color="0.35", ls=":", label=text) for _, text in marks]
    if table4:
        proxies.append(
            Line2D(
                [],
                [],
                color="0.5",
                ls="none",
                marker="X",
                ms=8,
                mec="k",
                label="paper's Table 4 amplitude (row labelled)",
            )
        )
    handles, _ = amp_ax.get_legend_handles_labels()
    amp_ax.legend(handles=handles + proxies, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    end_labels(amp_ax, ends)
    amp_ax.set_ylabel("amplitude (half peak-to-peak of u) [b_c]")
    amp_ax.grid(alpha=0.3)
    set_title(amp_ax, f"Frequency responses compared over {symbol(param)}", ds, exclude=["omega", param])
    if fl_ax is not None:
        fl_ax.set_ylabel("fluctuation\n(spread of Poincaré points, up sweep)", fontsize=8)
        fl_ax.set_xlabel("mesh frequency ω = ω_e/ω_n")
        fl_ax.grid(alpha=0.3)
        amp_ax.tick_params(labelbottom=False)
    else:
        amp_ax.set_xlabel("mesh frequency ω = ω_e/ω_n")
    if zoom is not None:
        zoom.set_xlabel("mesh frequency ω = ω_e/ω_n", fontsize=8)
