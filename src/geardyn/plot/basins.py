"""Basins of attraction: the grid of initial states coloured by the attractor reached, with the
attractors' Poincaré points on top.  Drawn from the Dataset only."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

from ..analysis.classify import motion_label
from .common import label, plot_function, set_title, speed_text

__all__ = ["BASIN_COLORS", "POINT_COLORS", "basin_figure"]

#: Basin colours (attractor 0, 1, …; cycled), diverged in black.
BASIN_COLORS = "#9ecae1 #fdae6b #a1d99b #bcbddc #fc9272 #fdd0a2 #c7e9c0 #dadaeb".split()
#: Marker colours of the attractors' Poincaré points.
POINT_COLORS = "#08519c #a63603 #006d2c #54278f #a50f15 #7f2704 #00441b #3f007d".split()


@plot_function("basins", (7, 6))
def basin_figure(ds: xr.Dataset, ax: Axes = None) -> None:
    """Basins over (u0, v0) with the attractors' Poincaré points and a legend of motion and basin share."""
    lab = ds["attractor"].values
    A = ds.sizes["attractor_index"]
    colors = ["#000000"] + [BASIN_COLORS[k % len(BASIN_COLORS)] for k in range(A)]
    ax.pcolormesh(
        ds["u0"].values,
        ds["v0"].values,
        lab + 1,
        cmap=ListedColormap(colors),
        vmin=-0.5,
        vmax=A + 0.5,
        shading="nearest",
    )
    handles = []
    for k in range(A):
        ax.plot(
            ds["attractor_u"].values[k],
            ds["attractor_v"].values[k],
            "o",
            ms=6,
            mfc=POINT_COLORS[k % len(POINT_COLORS)],
            mec="w",
            mew=1.0,
        )
        per = int(ds["attractor_period"].values[k])
        name = motion_label(int(ds["attractor_motion"].values[k]), per)
        frac = float(ds["attractor_fraction"].values[k])
        amp = float(ds["attractor_amplitude"].values[k])
        handles.append(
            Patch(
                color=colors[k + 1],
                label=f"{k}: {name}, amplitude {amp:.3g}, basin {100 * frac:.1f} %",
            )
        )
    if np.any(lab < 0):
        handles.append(Patch(color="#000000", label=f"diverged {100 * np.mean(lab < 0):.1f} %"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize=8, frameon=False)
    ax.set_xlabel(label(ds["u0"]))
    ax.set_ylabel(label(ds["v0"]))
    set_title(ax, f"Basins of attraction{speed_text(ds)} (dots: attractors' Poincaré points)", ds)
