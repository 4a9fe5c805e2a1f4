"""Two-parameter maps: categorical (motion class with period, impact state) and continuous
(amplitude, largest Lyapunov exponent) figures.  Drawn from the Dataset only."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
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
from .common import NAN_COLOR, NAN_HATCH, cells, label, plot_function, set_title

__all__ = ["MOTION_CATEGORIES", "continuous_map", "impact_map", "motion_map"]

#: Largest period drawn in a colour of its own; longer periods share one category.
SHOWN_PERIODS = 4
#: Categories of the motion map: (name, colour).  Periodic points are split by period.
MOTION_CATEGORIES = [
    (MOTION_LABELS[MOTION_DIVERGED], "#000000"),
    (MOTION_LABELS[MOTION_UNRESOLVED], "#bdbdbd"),
    *zip(
        (motion_label(MOTION_PERIODIC, n) for n in range(1, SHOWN_PERIODS + 1)),
        ("#c6dbef", "#6baed6", "#9e9ac8", "#2171b5"),
    ),
    (f"period-n (n > {SHOWN_PERIODS})", "#08306b"),
    (MOTION_LABELS[MOTION_QUASIPERIODIC], "#3cb371"),
    (MOTION_LABELS[MOTION_CHAOTIC], "#e8554c"),
]


def _motion_index(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    names = [n for n, _ in MOTION_CATEGORIES]
    out = names.index(MOTION_LABELS[MOTION_UNRESOLVED])
    for code in (MOTION_DIVERGED, MOTION_QUASIPERIODIC, MOTION_CHAOTIC):
        out = np.where(m == code, names.index(MOTION_LABELS[code]), out)
    shown = range(1, SHOWN_PERIODS + 1)
    per = np.select(
        [p == k for k in shown],
        [names.index(motion_label(MOTION_PERIODIC, k)) for k in shown],
        names.index(f"period-n (n > {SHOWN_PERIODS})"),
    )
    return np.where(m == MOTION_PERIODIC, per, out)


def _axes_names(ds: xr.Dataset) -> tuple[str, str]:
    return str(ds.attrs["x"]), str(ds.attrs["y"])


def _labels(ax: Axes, ds: xr.Dataset, title: str) -> None:
    xn, yn = _axes_names(ds)
    ax.set_xlabel(label(ds[xn]))
    ax.set_ylabel(label(ds[yn]))
    set_title(ax, title, ds, exclude=[xn, yn])


def _categorical(ds: xr.Dataset, idx: np.ndarray, cats: list, title: str, ax: Axes) -> None:
    xn, yn = _axes_names(ds)
    cmap = ListedColormap([c for _, c in cats])
    cells(ax, ds[xn].values, ds[yn].values, idx, cmap=cmap, vmin=-0.5, vmax=len(cats) - 0.5)
    present = sorted(set(np.unique(idx).tolist()))
    ax.legend(
        handles=[Patch(color=cats[k][1], label=cats[k][0]) for k in present],
        loc="center left",
        bbox_to_anchor=(1.01, 0.5),
        fontsize=8,
        frameon=False,
    )
    _labels(ax, ds, title)


@plot_function("map", (8, 5))
def motion_map(ds: xr.Dataset, ax: Axes = None) -> None:
    """Motion class over the grid, periodic points split by period (:data:`MOTION_CATEGORIES`)."""
    _categorical(ds, _motion_index(ds["motion"].values, ds["period"].values), MOTION_CATEGORIES, "Motion", ax)


@plot_function("map", (8, 5))
def impact_map(ds: xr.Dataset, ax: Axes = None) -> None:
    """Impact state over the grid."""
    keys = sorted(IMPACT_COLORS)
    cats = [(IMPACT_LABELS[k], IMPACT_COLORS[k]) for k in keys]
    codes = ds["impact"].values
    idx = np.select([codes == k for k in keys], list(range(len(keys))), 0)
    _categorical(ds, idx, cats, "Impact state", ax)


@plot_function(
    "map",
    (7.5, 5.5),
    params="""
               var : str
                   The variable drawn (``amplitude``, ``lle``, ``rms``, …).""",
    ax_doc="""
               ax : matplotlib.axes.Axes, optional
                   Where to draw; a new figure if omitted (the colour bar is added beside it).""",
)
def continuous_map(ds: xr.Dataset, var: str = "amplitude", ax: Axes = None) -> None:
    """A continuous variable over the grid (the largest exponent on a scale centred at zero); points
    without a value (NaN) are drawn hatched in :data:`~geardyn.plot.common.NAN_COLOR`, named in a legend."""
    xn, yn = _axes_names(ds)
    x, y, z = ds[xn].values, ds[yn].values, ds[var].values
    missing = ~np.isfinite(z)
    if var == "lle":
        finite = z[~missing]
        lim = max(float(np.max(np.abs(finite))) if finite.size else 1.0, 1e-6)
        im = cells(ax, x, y, z, cmap="RdBu_r", norm=TwoSlopeNorm(vcenter=0.0, vmin=-lim, vmax=lim))
    else:
        im = cells(ax, x, y, z, cmap="viridis")
    if missing.any():
        ax.pcolor(
            x,
            y,
            np.ma.masked_array(np.zeros(z.shape), ~missing),
            cmap=ListedColormap([NAN_COLOR]),
            shading="nearest",
            hatch=NAN_HATCH,
            edgecolor="0.35",
            lw=0,
            gid="nan",
        )
        what = "no exponent" if var == "lle" else "no value"
        ax.legend(
            handles=[Patch(facecolor=NAN_COLOR, edgecolor="0.35", hatch=NAN_HATCH, label=f"{what} (NaN)")],
            loc="upper left",
            bbox_to_anchor=(0.0, -0.13),
            fontsize=8,
            frameon=False,
        )
    ax.figure.colorbar(im, ax=ax, label=label(ds[var]))
    _labels(ax, ds, ds[var].attrs.get("long_name", var))
