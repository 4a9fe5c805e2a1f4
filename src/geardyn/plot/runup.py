"""Run-up figure: the order map (order-tracked DTE against speed) above the run-up beside the steady response.

With an excitation of P mesh cycles the order map is the spectrum of every order j/P (log colour scale), so the
shaft-order sidebands around the mesh orders show.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from matplotlib.colors import LogNorm

from .common import json_attr, plot_function
from .response import SWEEP_STYLE

__all__ = ["runup_figure"]


@plot_function(
    "runup",
    (8.5, 9.0),
    n=3,
    subplots={"sharex": True},
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of 3 Axes, optional
                   Where to draw (one Axes: the order map only); a new figure if omitted.""",
)
def runup_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """Order map of the DTE and the run-up amplitude and dynamic factor against speed, with the steady response
    (of ``geardyn runup``; its attribute ``quasi_static`` (JSON) holds the steady response when it was computed)."""
    a0, a1, a2 = ax
    phys = "rpm" in ds.coords
    x = ds["rpm" if phys else "omega"].values
    xlab = "pinion speed n1 [rpm]" if phys else "ω [1]"
    unit = "µm" if "order_amplitude_um" in ds else "1"
    orders = ds["order"].values
    order = np.argsort(x)
    if "spectrum" in ds:  # an excitation of P mesh cycles: every order j/P, the shaft-order sidebands too
        scale = 1.0e6 * float(json_attr(ds, "physical_scales").get("b_c_m", np.nan))
        spec = ds["spectrum"].values * (scale if unit == "µm" and np.isfinite(scale) else 1.0)
        unit = unit if unit != "µm" or np.isfinite(scale) else "1"
        positive = spec[np.isfinite(spec) & (spec > 0)]
        top = float(positive.max()) if positive.size else 1.0
        # a log scale over four decades: the sidebands sit orders of magnitude below the mesh orders
        mesh = a0.pcolormesh(
            x[order],
            ds["spectrum_order"].values,
            np.clip(spec[order].T, top * 1e-4, None),
            shading="nearest",
            cmap="viridis",
            norm=LogNorm(vmin=top * 1e-4, vmax=top),
        )
        a0.set_ylabel(f"order (mesh orders; sidebands at j/{int(ds.attrs.get('excitation_cycles', 1))})")
        a0.set_yticks(np.arange(1, int(np.ceil(ds["spectrum_order"].values.max())) + 1))
    else:
        amp_o = ds["order_amplitude_um" if unit == "µm" else "order_amplitude"].values
        mesh = a0.pcolormesh(x[order], orders, amp_o[order].T, shading="nearest", cmap="viridis")
        a0.set_ylabel("mesh order")
        a0.set_yticks(orders)
    # the colour bar beside the panel, not taken out of it: the three panels keep one width and one x scale
    a0.figure.colorbar(mesh, cax=a0.inset_axes((1.015, 0.0, 0.025, 1.0)), label=f"order amplitude [{unit}]")
    rate = float(ds.attrs.get("ramp_rate_rpm_per_s", np.nan))
    what = "run-up" if float(ds.attrs["omega_stop"]) > float(ds.attrs["omega_start"]) else "run-down"
    a0.set_title(
        f"{what}: order-tracked DTE ({ds.attrs['cycles_per_block']} mesh cycles per speed block"
        + (f", {rate:.4g} rpm/s" if np.isfinite(rate) else "")
        + ")",
        fontsize=10,
    )
    qs = json_attr(ds, "quasi_static")
    for a, var, ylab in (
        (a1, "amplitude", f"DTE half peak-to-peak [{unit}]"),
        (a2, "dynamic_factor", "dynamic factor max F_n/F_p [1]"),
    ):
        if a is None:
            continue
        y = ds[f"{var}_um" if var == "amplitude" and unit == "µm" else var].values
        a.plot(x, y, "k-", lw=1.5, label=what)
        for lab, (marker, colour) in SWEEP_STYLE.items():
            if var in qs.get(lab, ()):
                a.plot(
                    qs["x"],
                    np.array(qs[lab][var], dtype=float),  # None: nan
                    marker=marker,
                    ls="none",
                    color=colour,
                    ms=4,
                    label=f"steady response, sweep {lab}",
                )
        a.set_ylabel(ylab)
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7, loc="upper left")
    (a2 or a1 or a0).set_xlabel(xlab)
