"""Figures of a ``simulate`` result: time history, phase portrait with Poincaré points, spectrum."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from .common import PlotArtists, label, one_axes, result, snapshot

__all__ = ["TIME_PERIODS_SHOWN", "phase_portrait", "spectrum", "time_history"]

#: Periods of the time history drawn (the Dataset may hold more, for the spectrum).
TIME_PERIODS_SHOWN = 8


def _D(ds: xr.Dataset) -> float:
    return float(json.loads(ds.attrs["model"])["D"])


def _omega(ds: xr.Dataset) -> float:
    return float(json.loads(ds.attrs["model"])["omega"])


def time_history(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """u(τ) over the last :data:`TIME_PERIODS_SHOWN` periods with the backlash band |u| <= D shaded.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (8, 3.2))
    before = snapshot([ax])
    T = 2 * np.pi / _omega(ds)
    tau = ds["tau"].values
    keep = tau >= tau[-1] - TIME_PERIODS_SHOWN * T - 1e-12
    D = _D(ds)
    if D > 0:
        ax.axhspan(-D, D, color="0.9", label="separation |u| ≤ D")
        ax.axhline(D, color="0.6", lw=0.8)
        ax.axhline(-D, color="0.6", lw=0.8)
    ax.plot(tau[keep], ds["u"].values[keep], lw=1.0, color="C0", label="u")
    for k in range(TIME_PERIODS_SHOWN + 1):  # period boundaries: where the Poincaré section is taken
        ax.axvline(tau[-1] - k * T, color="C3", lw=0.4, alpha=0.5)
    ax.set_xlabel(label(ds["tau"]))
    ax.set_ylabel(label(ds["u"]))
    ax.set_title(f"Time history, ω = {_omega(ds):g}  (red lines: Poincaré section θ ≡ 0)")
    ax.legend(loc="upper right", fontsize=8)
    return result(fig, [ax], before)


def phase_portrait(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Phase portrait (u, u') with the Poincaré points.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (5.5, 4.5))
    before = snapshot([ax])
    D = _D(ds)
    if D > 0:
        ax.axvspan(-D, D, color="0.92", label="separation")
    ax.plot(ds["u"].values, ds["v"].values, lw=0.6, color="C0", label="trajectory")
    ax.plot(ds["poincare_u"].values, ds["poincare_v"].values, ".", color="C3", ms=5, label="Poincaré points")
    ax.set_xlabel(label(ds["u"]))
    ax.set_ylabel(label(ds["v"]))
    ax.set_title(f"Phase portrait, ω = {_omega(ds):g}")
    ax.legend(fontsize=8)
    return result(fig, [ax], before)


def spectrum(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Amplitude spectrum of u in orders of the mesh frequency (log scale).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (7, 3.2))
    before = snapshot([ax])
    order = ds["order"].values
    amp = ds["spectrum"].values
    ax.vlines(order[1:], 1e-12, np.maximum(amp[1:], 1e-12), color="C0", lw=1.0)
    ax.set_yscale("log")
    top = max(float(np.max(amp[1:])) if amp.size > 1 else 1.0, 1e-12)
    ax.set_ylim(max(top * 1e-6, 1e-12), top * 2)
    ax.set_xlabel("order of the mesh frequency")
    ax.set_ylabel(label(ds["spectrum"]))
    ax.set_title("Amplitude spectrum of u")
    return result(fig, [ax], before)
