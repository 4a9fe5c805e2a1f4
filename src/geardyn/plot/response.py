"""Amplitude-frequency response: the up and down sweeps, the jumps marked with arrows and the
hysteresis intervals shaded.  Drawn from the Dataset only (jumps and intervals are attributes)."""

from __future__ import annotations

import json
from typing import Any

import xarray as xr

from .common import PlotArtists, label, one_axes, result, snapshot

__all__ = ["SWEEP_STYLE", "response"]

#: Marker and colour per sweep.
SWEEP_STYLE = {"up": ("^", "C0"), "down": ("v", "C3")}


def response(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """The response measure against the swept parameter for both sweeps, with jumps and hysteresis intervals.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``response`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (8.5, 4.8))
    before = snapshot([ax])
    name = str(ds.attrs.get("param", "omega"))
    measure = str(ds.attrs.get("measure", "amplitude"))
    x = ds[name].values
    hy = json.loads(ds.attrs.get("hysteresis", "[]"))
    for a, b in hy:
        ax.axvspan(a, b, color="0.88", lw=0, zorder=0)
    for s in [str(v) for v in ds["sweep"].values]:
        mk, c = SWEEP_STYLE.get(s, ("o", "k"))
        ax.plot(x, ds[measure].sel(sweep=s).values, "-", marker=mk, ms=3.5, lw=0.8, color=c, label=f"sweep {s}")
    for j in json.loads(ds.attrs.get("jumps", "[]")):
        c = SWEEP_STYLE.get(j["sweep"], ("o", "k"))[1]
        xj = j[name]
        ax.annotate("", xy=(xj, j["amplitude_to"]), xytext=(xj, j["amplitude_from"]),
                    arrowprops=dict(arrowstyle="->", color=c, lw=1.5))
        ax.text(xj, 0.5 * (j["amplitude_from"] + j["amplitude_to"]), f" {name}={xj:.4g}", color=c, fontsize=7,
                va="center")
    ax.set_xlabel(label(ds[name], name))
    ax.set_ylabel(label(ds[measure], measure))
    ax.set_title("Frequency response (up/down sweeps with continuation)" + ("; grey: hysteresis" if hy else ""))
    ax.legend(fontsize=8)
    return result(fig, [ax], before)
