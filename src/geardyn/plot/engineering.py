"""The simulated dynamic factor against pinion speed with the ISO K_v-B curve and its speed sectors overlaid."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .common import json_attr, plot_function
from .response import SWEEP_STYLE

__all__ = ["has_iso_kv", "kv_overlay"]


def has_iso_kv(ds: xr.Dataset) -> bool:
    """Whether a response carries the ISO K_v curve (attribute ``iso_kv``).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``response`` result.

    Returns
    -------
    bool
    """
    return bool(ds.attrs.get("iso_kv"))


@plot_function("response", (8.5, 4.8))
def kv_overlay(ds: xr.Dataset, ax: Any = None) -> None:
    """Simulated dynamic factor per sweep and ISO K_v (Method B) against pinion speed, sectors shaded (a response
    with the ``iso_kv`` attribute: ``geardyn response`` of a pair with ISO inputs)."""
    b = json_attr(ds, "iso_kv")
    rpm = np.asarray(b["rpm"], dtype=float)
    n_e1 = b["resonance_speed_rpm"]
    bounds = b["sector_bounds_rpm"]
    for lo, hi, c, what in (
        ("subcritical_end", "main_resonance_end", "0.85", "main resonance sector (0.75 < N ≤ 1.25)"),
        ("main_resonance_end", "supercritical_start", "0.93", "intermediate sector (1.25 < N < 1.5)"),
    ):
        ax.axvspan(bounds[lo], bounds[hi], color=c, zorder=0, label=f"ISO {what}")
    ax.axvline(n_e1, color="0.4", ls=":", lw=1.0, label=f"ISO resonance n_E1 = {n_e1:.0f} rpm")
    ax.axvline(
        b["model_resonance_rpm"],
        color="C2",
        ls="--",
        lw=1.0,
        label=f"model resonance ω = 1 at {b['model_resonance_rpm']:.0f} rpm",
    )
    ax.plot(rpm, np.array(b["K_v"], dtype=float), "k-", lw=2.0, label="ISO K_v (Method B)")  # None: nan
    for lab, vals in b["simulated"].items():
        marker, colour = SWEEP_STYLE.get(lab, ("o", "C1"))
        ax.plot(
            rpm, np.array(vals, dtype=float), marker=marker, color=colour, ms=4, lw=1.0, label=f"simulated, sweep {lab}"
        )
    ax.set_xlim(rpm.min(), rpm.max())
    ax.set_xlabel("pinion speed n1 [rpm]")
    ax.set_ylabel("dynamic factor [1]")
    ax.set_title(f"Dynamic factor: simulation vs ISO 10300-1 K_v-B (T1 = {b['torque_N_m']:.4g} N·m)", fontsize=10)
    ax.legend(fontsize=7, loc="upper left", framealpha=0.85)
    ax.grid(True, alpha=0.3)
