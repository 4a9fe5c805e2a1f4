"""Amplitude-frequency response: the up and down sweeps, the jumps marked with arrows and the
hysteresis intervals shaded.  Drawn from the Dataset only (jumps and intervals are attributes)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from .common import json_list, label, place_labels, plot_function, rpm_axis, set_title, symbol, system_info

__all__ = ["SWEEP_STYLE", "draw_response", "response"]

#: Marker and colour per sweep.
SWEEP_STYLE = {"up": ("^", "C0"), "down": ("v", "C3")}


def draw_response(
    ax: Axes,
    x: np.ndarray,
    da: xr.DataArray,
    hysteresis: Sequence[Sequence[float]],
    jumps: Sequence[tuple[float, float, float, str, str]],
    min_width: float = 0.0,
    coexistence: Sequence[Sequence[float]] = (),
) -> None:
    """The sweeps of ``da`` (dimension ``sweep``) against ``x`` with shaded hysteresis intervals and jump arrows,
    each jump labelled beside its arrow where the label covers no other label or arrow.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    x : ndarray
        The abscissa of the sweeps.
    da : xarray.DataArray
        The response measure over (``sweep``, x).
    hysteresis : sequence of (float, float)
        Intervals of ``x`` shaded grey (at least ``min_width`` wide).
    jumps : sequence of (x, from, to, sweep, text)
        Where each jump is, the measure before and after it, its sweep and its label.
    min_width : float
        Smallest width drawn of a hysteresis interval.
    coexistence : sequence of (float, float)
        Intervals where the sweeps end on different attractors with no jump at a bound, shaded hatched.
    """
    for a, b in hysteresis:
        ax.axvspan(a, max(b, a + min_width), color="0.88", lw=0, zorder=0)
    for k, (a, b) in enumerate(coexistence):
        ax.axvspan(
            a,
            max(b, a + min_width),
            facecolor="none",
            edgecolor="0.6",
            hatch="//",
            lw=0,
            zorder=0,
            label="coexisting attractors" if k == 0 else None,
        )
    for s in [str(v) for v in da["sweep"].values]:
        mk, c = SWEEP_STYLE.get(s, ("o", "k"))
        ax.plot(x, da.sel(sweep=s).values, "-", marker=mk, ms=3.5, lw=0.8, color=c, label=f"sweep {s}")
    arrows = [
        ax.annotate(
            "",
            xy=(xj, a1),
            xytext=(xj, a0),
            arrowprops=dict(arrowstyle="->", color=SWEEP_STYLE.get(s, ("o", "k"))[1], lw=1.5),
        )
        for xj, a0, a1, s, _ in jumps
    ]
    place_labels(
        ax,
        [(xj, 0.5 * (a0 + a1), text, SWEEP_STYLE.get(s, ("o", "k"))[1]) for xj, a0, a1, s, text in jumps],
        avoid=arrows,
    )
    ax.legend(fontsize=8, loc="best")


def _no_solution(ax: Axes, x: np.ndarray, da: xr.DataArray) -> None:
    """Hatch the grid intervals where neither sweep has a stable period-n solution (an HB response: a period-2n,
    quasi-periodic or chaotic response there, which harmonic balance of period n cannot tell apart)."""
    none = np.all(~np.isfinite(da.values), axis=0)
    half = 0.5 * np.diff(x)
    edges = np.concatenate([[x[0]], x[:-1] + half, [x[-1]]]) if x.size > 1 else np.array([x[0], x[0]])
    at = np.nonzero(none)[0]
    for k, i in enumerate(at):
        ax.axvspan(
            edges[i],
            edges[i + 1],
            facecolor="none",
            edgecolor="0.7",
            hatch="///",
            lw=0,
            zorder=0,
            label="no stable period-n solution" if k == 0 else None,
        )
    if at.size:
        ax.legend(fontsize=8, loc="best")


@plot_function("response", (8.5, 4.8))
def response(ds: xr.Dataset, ax: Axes = None) -> None:
    """The response measure against the swept parameter for both sweeps, with jumps and hysteresis intervals."""
    name = str(ds.attrs.get("param", "omega"))
    measure = str(ds.attrs.get("measure", "amplitude"))
    hy = json_list(ds, "hysteresis")
    co = json_list(ds, "coexistence")
    jumps = [
        (j[name], j["amplitude_from"], j["amplitude_to"], j["sweep"], f"{symbol(name)} = {j[name]:.4g}")
        for j in json_list(ds, "jumps")
    ]
    x = ds[name].values
    draw_response(ax, x, ds[measure], hy, jumps, coexistence=co)
    if ds.attrs.get("method") == "hb":
        _no_solution(ax, x, ds[measure])
    if x.size > 1:  # the requested range, also where no point has a value
        pad = 0.02 * float(x[-1] - x[0])
        ax.set_xlim(float(x[0]) - pad, float(x[-1]) + pad)
    ax.set_xlabel(label(ds[name]))
    ax.set_ylabel(label(ds[measure]))
    if system_info(ds):  # a system: its pinion speed on a top axis (the pair draws a figure against rpm)
        rpm_axis(ax, ds, name)
    shading = ("; grey: hysteresis" if hy else "") + ("; hatched: coexisting attractors" if co else "")
    set_title(ax, "Frequency response (up/down sweeps with continuation)" + shading, ds, exclude=[name])
