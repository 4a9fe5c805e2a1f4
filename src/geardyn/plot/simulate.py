"""Figures of a ``simulate`` result: time history, phase portrait with Poincaré points, spectrum."""

from __future__ import annotations

import textwrap

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from ..errors import ModelError
from .common import OUTSIDE_RIGHT, contact_lines, label, log_stems, model_of, of_mesh, plot_function, set_title

__all__ = ["TIME_PERIODS_SHOWN", "last_periods", "phase_portrait", "spectrum", "time_history"]

#: Mesh periods of the time history drawn (the Dataset may hold more, for the spectrum).
TIME_PERIODS_SHOWN = 8


def last_periods(ds: xr.Dataset) -> tuple[np.ndarray, float]:
    """(mask of the samples in the last :data:`TIME_PERIODS_SHOWN` mesh periods, the mesh period T).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result (its ``tau`` coordinate and model).

    Returns
    -------
    keep : ndarray of bool
        The samples shown.
    T : float
        The mesh period 2π/ω (the forcing period when the forcing repeats every mesh cycle).
    """
    T = 2 * np.pi / float(model_of(ds)["omega"])
    tau = ds["tau"].values
    return tau >= tau[-1] - TIME_PERIODS_SHOWN * T - 1e-12, T


@plot_function("simulate", (8, 3.2))
def time_history(ds: xr.Dataset, ax: Axes = None) -> None:
    """u(τ) over the last :data:`TIME_PERIODS_SHOWN` periods with the backlash band |u| <= D shaded."""
    keep, T = last_periods(ds)
    tau = ds["tau"].values
    D = float(model_of(ds)["D"])
    if D > 0:
        ax.axhspan(-D, D, color="0.9", label="separation |u| ≤ D")
        contact_lines(ax, ds)
    ax.plot(tau[keep], ds["u"].values[keep], lw=1.0, color="C0", label=of_mesh("u", ds))
    # the Poincaré section is taken once a forcing period: P mesh periods of a system whose forcing repeats
    # after P mesh cycles (ratios, torque orders, bearings), so a window of a few mesh periods may hold one line
    try:
        Tf = float(ds.geardyn.model.sampling_period)
    except ModelError:  # a system result of an earlier geardyn stores no system: its mesh period, as it was drawn
        Tf = T
    for k in range(int(TIME_PERIODS_SHOWN * T / Tf + 1e-9) + 1):
        ax.axvline(tau[-1] - k * Tf, color="C3", lw=0.4, alpha=0.5)
    ax.set_xlabel(label(ds["tau"]))
    ax.set_ylabel("\n".join(textwrap.wrap(label(ds["u"]), 36)))  # a low panel: the label on two lines if long
    set_title(ax, "Time history (red lines: Poincaré section θ ≡ 0)", ds)
    ax.legend(**OUTSIDE_RIGHT)


@plot_function("simulate", (5.5, 4.5))
def phase_portrait(ds: xr.Dataset, ax: Axes = None) -> None:
    """Phase portrait (u, u') with the Poincaré points."""
    D = float(model_of(ds)["D"])
    if D > 0:
        ax.axvspan(-D, D, color="0.92", label="separation")
    ax.plot(ds["u"].values, ds["v"].values, lw=0.6, color="C0", label="trajectory")
    ax.plot(ds["poincare_u"].values, ds["poincare_v"].values, ".", color="C3", ms=5, label="Poincaré points")
    ax.set_xlabel(label(ds["u"]))
    ax.set_ylabel(label(ds["v"]))
    set_title(ax, "Phase portrait", ds, fontsize=9)
    ax.legend(fontsize=8)


@plot_function("simulate", (7, 4))
def spectrum(ds: xr.Dataset, ax: Axes = None) -> None:
    """Amplitude spectrum of u in orders of the mesh frequency (log scale)."""
    log_stems(ax, ds["order"].values, ds["spectrum"].values)
    ax.set_xlabel("order of the mesh frequency")
    ax.set_ylabel(of_mesh("amplitude of u", ds))
    set_title(ax, ds["spectrum"].attrs.get("long_name", "Amplitude spectrum of u"), ds)
