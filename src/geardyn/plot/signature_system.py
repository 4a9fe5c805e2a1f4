"""Figures of a system's vibration signature (``geardyn signature --system``): the pair's figures
(:mod:`.tooth`) with the sensor named."""

from __future__ import annotations

import json
from typing import Any

import xarray as xr

from . import tooth
from .common import PlotArtists

__all__ = ["is_system", "system_signals"]


def is_system(ds: xr.Dataset) -> bool:
    """Whether a ``signature`` result is a system's (its runs name a sensor).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``signature`` result.

    Returns
    -------
    bool
    """
    return "sensor" in json.loads(ds.attrs.get("summary", "{}")).get("runs", [{}])[0]


def system_signals(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Record of the sensor with the tachometer, pinion TSA, residual and difference signals of each run.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``signature`` result of a system.
    ax : Axes or sequence of Axes, optional
        Where to draw (as many Axes as panels); a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    art = tooth.signature_signals(ds, ax=ax)
    r0 = json.loads(ds.attrs["summary"])["runs"][0]
    art.axes[0].set_title(
        f"acceleration of the sensor {r0['sensor']} (mesh {r0['mesh']!r}), sampled with a "
        f"once-per-revolution tachometer on its pinion",
        fontsize=9,
    )
    return art
