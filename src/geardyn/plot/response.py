"""Amplitude-frequency response: the up and down sweeps, the jumps marked with arrows and the
hysteresis intervals shaded.  Drawn from the Dataset only (jumps and intervals are attributes)."""

from __future__ import annotations

import json
from pathlib import Path

import xarray as xr

from .bifurcation import diagram
from .common import label, plt, save

#: Marker and colour per sweep.
SWEEP_STYLE = {"up": ("^", "C0"), "down": ("v", "C3")}


def response(ds: xr.Dataset):
    """Amplitude against ω for both sweeps with jumps and hysteresis intervals."""
    name = str(ds.attrs.get("param", "omega"))
    measure = str(ds.attrs.get("measure", "amplitude"))
    x = ds[name].values
    fig, ax = plt.subplots(figsize=(8.5, 4.8))
    for a, b in json.loads(ds.attrs.get("hysteresis", "[]")):
        ax.axvspan(a, b, color="0.88", lw=0, zorder=0)
    for s in [str(v) for v in ds["sweep"].values]:
        mk, c = SWEEP_STYLE.get(s, ("o", "k"))
        ax.plot(x, ds[measure].sel(sweep=s).values, "-", marker=mk, ms=3.5, lw=0.8, color=c, label=f"sweep {s}")
    for j in json.loads(ds.attrs.get("jumps", "[]")):
        c = SWEEP_STYLE.get(j["sweep"], ("o", "k"))[1]
        xj = j[name]
        ax.annotate("", xy=(xj, j["amplitude_to"]), xytext=(xj, j["amplitude_from"]),
                    arrowprops=dict(arrowstyle="->", color=c, lw=1.5))
        ax.text(xj, 0.5 * (j["amplitude_from"] + j["amplitude_to"]), f" {name}={xj:.4g}", color=c, fontsize=7,
                va="center")
    ax.set_xlabel(label(ds[name], name))
    ax.set_ylabel(label(ds[measure], measure))
    hy = json.loads(ds.attrs.get("hysteresis", "[]"))
    ax.set_title("Frequency response (up/down sweeps with continuation)"
                 + ("; grey: hysteresis" if hy else ""))
    ax.legend(fontsize=8)
    return fig


def save_all(ds: xr.Dataset, directory: str | Path) -> list[Path]:
    """Write the response figure and the bifurcation diagram of both sweeps as PNG into ``directory``."""
    d = Path(directory)
    return [save(response(ds), d / "response.png"), save(diagram(ds), d / "response_bifurcation.png")]
