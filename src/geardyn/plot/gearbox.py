"""Mode shapes of a gearbox along its shafts (a ``modes`` result of a file with ``[[shaft]]``).

One panel per mode (the lowest elastic modes): for each shaft, the lateral deflection √(x² + y²) of its nodes
against their position along the shaft (solid), the torsional one r θ (dashed; r the largest gear reference
radius on the shaft: the motion of its largest pitch circle) and the axial one z (dotted), all in metres and
normalised by the largest of them in the mode, so that lateral, torsional and axial motion compare.  The
title of a panel names the mode, its frequency and the elements holding most of its strain energy.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from .common import json_list, plot_function

__all__ = ["has_shafts", "mode_shapes", "SHAPE_PANELS"]

#: Modes drawn (the lowest elastic ones).
SHAPE_PANELS = 6


def has_shafts(ds: xr.Dataset) -> bool:
    """Whether a ``modes`` result is a gearbox's (it has shaft nodes).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``modes`` result.
    """
    return "node_position" in ds and ds.sizes.get("node", 0) > 0


@plot_function(
    "modes",
    (12, 7.5),
    n=SHAPE_PANELS,
    subplots={"nrows": 2, "ncols": 3, "sharex": True},
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of six Axes, optional
                   One Axes: the lowest elastic mode only; six: one mode each; omitted: a new figure.""",
)
def mode_shapes(ds: xr.Dataset, ax: Axes = None) -> None:
    """Deflection along each shaft of the lowest elastic modes: lateral (solid), torsional (dashed), axial (dotted)."""
    dofs = [str(d) for d in ds["dof"].values]
    index = {d: k for k, d in enumerate(dofs)}
    nodes = json_list(ds, "nodes")
    names = json_list(ds, "shafts")
    shaft_of = np.asarray(ds["node_shaft"].values, dtype=int)
    pos = ds["node_position"].values * 1e3
    shape = ds["shape"].values
    elements = [str(e) for e in ds["element"].values]
    energy = ds["energy_fraction"].values
    r = ds["node_radius"].values
    radius = np.array([float(np.max(r[shaft_of == k])) for k in shaft_of])
    for a, i in zip(ax, [i for i, rigid in enumerate(ds["rigid"].values) if not rigid][:SHAPE_PANELS]):
        if a is None:
            continue
        x, y, theta, z = (shape[[index[f"{n}.{c}"] for n in nodes], i] for c in ("x", "y", "theta", "z"))
        curves = np.array([np.hypot(x, y), theta * radius, z])
        curves = curves / max(float(np.max(np.abs(curves))), 1e-300)
        for j, s in enumerate(names):
            sel = shaft_of == j
            for y, fmt, lw, what in zip(
                curves, ("-o", "--", ":"), (1.3, 1.0, 1.2), ("lateral", "torsion r θ", "axial")
            ):
                a.plot(pos[sel], y[sel], fmt, ms=3, color=f"C{j}", lw=lw, label=f"{s}: {what}")
        a.axhline(0.0, color="0.7", lw=0.6)
        top = np.argsort(energy[i])[::-1][:2]
        held = ", ".join(f"{elements[k]} {energy[i, k]:.0%}" for k in top)
        a.set_title(f"mode {i + 1}: {float(ds['frequency_Hz'].values[i]):.5g} Hz\n{held}", fontsize=9)
        a.set_ylim(-1.1, 1.1)
    for a in ax:
        if a is not None and a.get_subplotspec() is not None and a.get_subplotspec().is_last_row():
            a.set_xlabel("position along the shaft [mm]")
    first = next(a for a in ax if a is not None)
    first.set_ylabel("normalised deflection")
    first.legend(fontsize=6, loc="lower left", ncol=1, framealpha=0.8)
