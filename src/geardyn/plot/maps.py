"""Two-parameter maps: categorical (motion class with period, impact state) and continuous
(amplitude, largest Lyapunov exponent) figures.  Drawn from the Dataset only."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from matplotlib.colors import ListedColormap, TwoSlopeNorm
from matplotlib.patches import Patch

from ..analysis.classify import (
    IMPACT_LABELS,
    MOTION_CHAOTIC,
    MOTION_DIVERGED,
    MOTION_LABELS,
    MOTION_PERIODIC,
    MOTION_QUASIPERIODIC,
    MOTION_UNRESOLVED,
    motion_label,
)
from .bifurcation import IMPACT_COLORS
from .common import PlotArtists, label, one_axes, result, snapshot

__all__ = ["MOTION_CATEGORIES", "continuous_map", "impact_map", "motion_map"]

#: Largest period drawn in a colour of its own; longer periods share one category.
SHOWN_PERIODS = 4
#: Categories of the motion map: (name, colour).  Periodic points are split by period.
MOTION_CATEGORIES = [
    (MOTION_LABELS[MOTION_DIVERGED], "#000000"), (MOTION_LABELS[MOTION_UNRESOLVED], "#bdbdbd"),
    *zip((motion_label(MOTION_PERIODIC, n) for n in range(1, SHOWN_PERIODS + 1)),
         ("#c6dbef", "#6baed6", "#9e9ac8", "#2171b5")),
    (f"period-n (n > {SHOWN_PERIODS})", "#08306b"),
    (MOTION_LABELS[MOTION_QUASIPERIODIC], "#3cb371"), (MOTION_LABELS[MOTION_CHAOTIC], "#e8554c"),
]


def _motion_index(motion: np.ndarray, period: np.ndarray) -> np.ndarray:
    names = [n for n, _ in MOTION_CATEGORIES]
    m, p = motion, period
    out = np.where(m == MOTION_DIVERGED, names.index(MOTION_LABELS[MOTION_DIVERGED]),
                   names.index(MOTION_LABELS[MOTION_UNRESOLVED]))
    out = np.where(m == MOTION_QUASIPERIODIC, names.index(MOTION_LABELS[MOTION_QUASIPERIODIC]), out)
    out = np.where(m == MOTION_CHAOTIC, names.index(MOTION_LABELS[MOTION_CHAOTIC]), out)
    shown = range(1, SHOWN_PERIODS + 1)
    per = np.select([p == k for k in shown], [names.index(motion_label(MOTION_PERIODIC, k)) for k in shown],
                    names.index(f"period-n (n > {SHOWN_PERIODS})"))
    return np.where(m == MOTION_PERIODIC, per, out)


def _axes_names(ds: xr.Dataset) -> tuple[str, str]:
    return str(ds.attrs["x"]), str(ds.attrs["y"])


def _categorical(ds, idx, cats, title, ax) -> PlotArtists:
    fig, ax, _ = one_axes(ax, (8, 5))
    before = snapshot([ax])
    xn, yn = _axes_names(ds)
    cmap = ListedColormap([c for _, c in cats])
    ax.pcolormesh(ds[xn].values, ds[yn].values, idx, cmap=cmap, vmin=-0.5, vmax=len(cats) - 0.5, shading="nearest")
    present = sorted(set(np.unique(idx).tolist()))
    ax.legend(handles=[Patch(color=cats[k][1], label=cats[k][0]) for k in present], loc="center left",
              bbox_to_anchor=(1.01, 0.5), fontsize=8, frameon=False)
    ax.set_xlabel(label(ds[xn], xn))
    ax.set_ylabel(label(ds[yn], yn))
    ax.set_title(title)
    return result(fig, [ax], before)


def motion_map(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Motion class over the grid, periodic points split by period (:data:`MOTION_CATEGORIES`).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``map`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    return _categorical(ds, _motion_index(ds["motion"].values, ds["period"].values), MOTION_CATEGORIES, "Motion", ax)


def impact_map(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Impact state over the grid.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``map`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    keys = sorted(IMPACT_COLORS)
    cats = [(IMPACT_LABELS[k], IMPACT_COLORS[k]) for k in keys]
    idx = np.vectorize(lambda c: keys.index(int(c)) if int(c) in keys else 0)(ds["impact"].values)
    return _categorical(ds, idx, cats, "Impact state", ax)


def continuous_map(ds: xr.Dataset, var: str = "amplitude", ax: Any = None) -> PlotArtists:
    """A continuous variable over the grid (the largest exponent on a scale centred at zero).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``map`` result.
    var : str
        The variable drawn (``amplitude``, ``lle``, ``rms``, …).
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted (the colour bar is added beside it).

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (7.5, 5))
    before = snapshot([ax])
    xn, yn = _axes_names(ds)
    z = ds[var].values
    if var == "lle":
        finite = z[np.isfinite(z)]
        lim = max(float(np.max(np.abs(finite))) if finite.size else 1.0, 1e-6)
        im = ax.pcolormesh(ds[xn].values, ds[yn].values, z, cmap="RdBu_r",
                           norm=TwoSlopeNorm(vcenter=0.0, vmin=-lim, vmax=lim), shading="nearest")
    else:
        im = ax.pcolormesh(ds[xn].values, ds[yn].values, z, cmap="viridis", shading="nearest")
    fig.colorbar(im, ax=ax, label=label(ds[var], var))
    ax.set_xlabel(label(ds[xn], xn))
    ax.set_ylabel(label(ds[yn], yn))
    ax.set_title(ds[var].attrs.get("long_name", var))
    return result(fig, [ax], before)
