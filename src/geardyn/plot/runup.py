"""Run-up figure: the order map (order-tracked DTE against speed) above the run-up beside the steady response."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from .common import PlotArtists, panels, result, snapshot

__all__ = ["runup_figure"]


def runup_figure(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Order map of the DTE and the run-up amplitude and dynamic factor against speed, with the steady response.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``runup`` result (``geardyn runup``); its attribute ``quasi_static`` (JSON) holds the steady
        response when it was computed.
    ax : matplotlib.axes.Axes or sequence of 3 Axes, optional
        Where to draw (one Axes: the order map only); a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, axes, _ = panels(ax, 3, (8.5, 9.0), sharex=True)
    before = snapshot(axes)
    phys = "rpm" in ds.coords
    x = ds["rpm"].values if phys else ds["omega"].values
    xlab = "pinion speed n1 [rpm]" if phys else "ω [1]"
    amp_o = ds["order_amplitude_um"].values if "order_amplitude_um" in ds else ds["order_amplitude"].values
    unit = "µm" if "order_amplitude_um" in ds else "1"
    orders = ds["order"].values
    order = np.argsort(x)
    a0 = axes[0]
    mesh = a0.pcolormesh(x[order], orders, amp_o[order].T, shading="nearest", cmap="viridis")
    # the colour bar beside the panel, not taken out of it: the three panels keep one width and one x scale
    fig.colorbar(mesh, cax=a0.inset_axes((1.015, 0.0, 0.025, 1.0)), label=f"order amplitude [{unit}]")
    a0.set_ylabel("mesh order")
    a0.set_yticks(orders)
    rate = float(ds.attrs.get("ramp_rate_rpm_per_s", np.nan))
    what = "run-up" if float(ds.attrs["omega_stop"]) > float(ds.attrs["omega_start"]) else "run-down"
    a0.set_title(f"{what}: order-tracked DTE ({ds.attrs['cycles_per_block']} mesh cycles per speed block"
                 + (f", {rate:.4g} rpm/s" if np.isfinite(rate) else "") + ")", fontsize=10)
    qs = json.loads(ds.attrs.get("quasi_static", "null") or "null")
    a1, a2 = axes[1], axes[2]
    for a, var, ylab in ((a1, "amplitude", f"DTE half peak-to-peak [{unit}]"), (a2, "dynamic_factor",
                                                                                "dynamic factor max F_n/F_p [1]")):
        if a is None:
            continue
        y = ds[f"{var}_um"].values if (var == "amplitude" and unit == "µm") else ds[var].values
        a.plot(x, y, "k-", lw=1.5, label=what)
        if qs is not None:
            for lab, marker, colour in (("up", "^", "C0"), ("down", "v", "C3")):
                if lab in qs:
                    key = var if var in qs[lab] else None
                    if key is not None:
                        a.plot(qs["x"], [np.nan if v is None else v for v in qs[lab][key]], marker=marker, ls="none",
                               color=colour, ms=4, label=f"steady response, sweep {lab}")
        a.set_ylabel(ylab)
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7, loc="upper left")
    (a2 or a1 or a0).set_xlabel(xlab)
    return result(fig, axes, before)
