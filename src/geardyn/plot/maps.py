"""Two-parameter maps: categorical (motion class with period, impact state) and continuous
(amplitude, largest Lyapunov exponent) figures.  Drawn from the Dataset only."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.colors import ListedColormap, TwoSlopeNorm
from matplotlib.patches import Patch

from .bifurcation import IMPACT_COLORS, IMPACT_NAMES
from .common import label, plt, save

#: Categories of the motion map: (name, colour).  Periodic points are split by period.
MOTION_CATEGORIES = [
    ("diverged", "#000000"), ("unresolved", "#bdbdbd"), ("period-1", "#c6dbef"), ("period-2", "#6baed6"),
    ("period-3", "#9e9ac8"), ("period-4", "#2171b5"), ("period-n (n > 4)", "#08306b"),
    ("quasi-periodic", "#3cb371"), ("chaotic", "#e8554c"),
]


def _motion_index(motion: np.ndarray, period: np.ndarray) -> np.ndarray:
    names = [n for n, _ in MOTION_CATEGORIES]
    m, p = motion, period
    out = np.where(m == -1, names.index("diverged"), names.index("unresolved"))
    out = np.where(m == 2, names.index("quasi-periodic"), out)
    out = np.where(m == 3, names.index("chaotic"), out)
    per = np.select([p == 1, p == 2, p == 3, p == 4], [names.index(f"period-{k}") for k in (1, 2, 3, 4)],
                    names.index("period-n (n > 4)"))
    return np.where(m == 1, per, out)


def _axes_names(ds: xr.Dataset) -> tuple[str, str]:
    return str(ds.attrs["x"]), str(ds.attrs["y"])


def _categorical(ds, idx, cats, title):
    xn, yn = _axes_names(ds)
    fig, ax = plt.subplots(figsize=(8, 5))
    cmap = ListedColormap([c for _, c in cats])
    ax.pcolormesh(ds[xn].values, ds[yn].values, idx, cmap=cmap, vmin=-0.5, vmax=len(cats) - 0.5, shading="nearest")
    present = sorted(set(np.unique(idx).tolist()))
    ax.legend(handles=[Patch(color=cats[k][1], label=cats[k][0]) for k in present], loc="center left",
              bbox_to_anchor=(1.01, 0.5), fontsize=8, frameon=False)
    ax.set_xlabel(label(ds[xn], xn))
    ax.set_ylabel(label(ds[yn], yn))
    ax.set_title(title)
    return fig


def motion_map(ds: xr.Dataset):
    """Motion class (periodic split by period) over the grid."""
    return _categorical(ds, _motion_index(ds["motion"].values, ds["period"].values), MOTION_CATEGORIES, "Motion")


def impact_map(ds: xr.Dataset):
    """Impact state over the grid."""
    keys = sorted(IMPACT_COLORS)
    cats = [(IMPACT_NAMES[k], IMPACT_COLORS[k]) for k in keys]
    idx = np.vectorize(lambda c: keys.index(int(c)) if int(c) in keys else 0)(ds["impact"].values)
    return _categorical(ds, idx, cats, "Impact state")


def continuous_map(ds: xr.Dataset, var: str):
    """A continuous variable over the grid (the largest exponent on a scale centred at zero)."""
    xn, yn = _axes_names(ds)
    z = ds[var].values
    fig, ax = plt.subplots(figsize=(7.5, 5))
    if var == "lle":
        finite = z[np.isfinite(z)]
        lim = max(float(np.max(np.abs(finite))) if finite.size else 1.0, 1e-6)
        im = ax.pcolormesh(ds[xn].values, ds[yn].values, z, cmap="RdBu_r",
                           norm=TwoSlopeNorm(vcenter=0.0, vmin=-lim, vmax=lim), shading="nearest")
    else:
        im = ax.pcolormesh(ds[xn].values, ds[yn].values, z, cmap="viridis", shading="nearest")
    fig.colorbar(im, ax=ax, label=label(ds[var], var))
    ax.set_xlabel(label(ds[xn], xn))
    ax.set_ylabel(label(ds[yn], yn))
    ax.set_title(ds[var].attrs.get("long_name", var))
    return fig


def save_all(ds: xr.Dataset, directory: str | Path) -> list[Path]:
    """Write the motion, impact, amplitude and (if computed) largest-exponent maps as PNG."""
    d = Path(directory)
    out = [save(motion_map(ds), d / "map_motion.png"), save(impact_map(ds), d / "map_impact.png"),
           save(continuous_map(ds, "amplitude"), d / "map_amplitude.png")]
    if "lle" in ds and np.any(np.isfinite(ds["lle"].values)):
        out.append(save(continuous_map(ds, "lle"), d / "map_lle.png"))
    return out
