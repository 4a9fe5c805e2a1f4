"""Gear rattle figures: the history of one point with its impacts, and the rattle map over speed × amplitude.
Drawn from the Datasets of :mod:`geardyn.analysis.rattle` only."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from .common import cells, json_attr, model_of, plot_function

__all__ = ["rattle_history", "rattle_map_figure"]

_DRIVE, _BACK = "#d62728", "#1f77b4"


@plot_function("rattle", (9, 4.5), tight=True)
def rattle_history(ds: xr.Dataset, ax: Axes = None) -> None:
    """u over the recorded cycles, the backlash ±D shaded, the impacts on the drive (+D) and back (−D) flanks
    marked."""

    D = float(model_of(ds)["D"])
    tau, u = ds["tau"].values, ds["u"].values
    ax.axhspan(-D, D, color="0.92", lw=0, label="backlash |u| ≤ D")
    ax.plot(tau, u, color="0.2", lw=0.8, label="u")
    t, f = ds["impact_time"].values, ds["impact_flank"].values
    for flank, color, name in ((1, _DRIVE, "drive-flank impact"), (-1, _BACK, "back-flank impact")):
        sel = f == flank
        if np.any(sel):
            ax.plot(
                t[sel], np.full(int(sel.sum()), flank * D), "v" if flank > 0 else "^", color=color, ms=5, label=name
            )
    ax.set_xlabel("non-dimensional time τ")
    ax.set_ylabel("relative displacement u (b_c)")
    s = json_attr(ds, "summary")
    per = s.get("flanks", {})
    ax.set_title(
        "Rattle: "
        + f"{per.get('drive', {}).get('impacts_per_cycle', 0):g} drive, "
        + f"{per.get('back', {}).get('impacts_per_cycle', 0):g} back impacts per cycle",
        fontsize=10,
    )
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=4, fontsize=8, frameon=False)


@plot_function("rattle_map", (13, 4.2), n=3, subplots={"nrows": 1, "ncols": 3}, tight=True)
def rattle_map_figure(ds: xr.Dataset, ax: list = None) -> None:
    """The rattle map: the rattle index (impact kinetic-energy loss per cycle), the drive- and back-flank impacts
    per cycle over the speed (rpm when known, else ω) and the scale of the torque orders' amplitude."""
    xname = "rpm" if "rpm" in ds.coords else "omega"
    x = ds[xname].values
    y = ds["amplitude_scale"].values
    panels = (
        ("rattle_index_J", "rattle index (J per cycle)")
        if "rattle_index_J" in ds
        else ("rattle_index", "rattle index"),
        ("impacts_drive", "drive-flank impacts per cycle"),
        ("impacts_back", "back-flank impacts per cycle"),
    )
    for a, (var, title) in zip(ax, panels):
        if a is None:
            continue
        z = ds[var].values.T  # rows: amplitude scale, columns: speed
        im = cells(a, x, y, z, cmap="magma" if var.startswith("rattle") else "viridis")
        a.figure.colorbar(im, ax=a, shrink=0.85)
        a.set_xlabel("pinion speed (rpm)" if xname == "rpm" else "mesh frequency ω")
        a.set_ylabel("torque-order amplitude scale")
        a.set_title(title, fontsize=10)
