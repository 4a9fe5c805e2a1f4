"""Bifurcation diagram: Poincaré points against the swept parameter, the largest Lyapunov exponent
beneath, and bands of the motion class and impact state.  Drawn from the Dataset only."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

from .common import label, plt, save

#: Colours of the motion classes (codes −1 … 3 of ``geardyn.analysis.classify``).
MOTION_COLORS = {-1: "#000000", 0: "#bdbdbd", 1: "#4c9be8", 2: "#3cb371", 3: "#e8554c"}
MOTION_NAMES = {-1: "diverged", 0: "unresolved", 1: "periodic", 2: "quasi-periodic", 3: "chaotic"}
#: Colours of the impact states (codes −1 … 2).
IMPACT_COLORS = {-1: "#000000", 0: "#9ecae1", 1: "#fdae6b", 2: "#d94801"}
IMPACT_NAMES = {-1: "unknown", 0: "no impact", 1: "single-sided impact", 2: "double-sided impact"}
#: Colours of the sweeps.
SWEEP_COLORS = {"fixed": "k", "up": "C0", "down": "C3"}
#: Marker size of the Poincaré points.
POINT_SIZE = 0.6


def _param(ds: xr.Dataset) -> str:
    return str(ds.attrs.get("param", [d for d in ds["motion"].dims if d != "sweep"][0]))


def category_band(ax, x: np.ndarray, codes: np.ndarray, colors: dict[int, str], names: dict[int, str], title: str):
    """A one-row categorical strip of ``codes`` against ``x`` with a legend of the codes present."""
    keys = sorted(colors)
    cmap = ListedColormap([colors[k] for k in keys])
    idx = np.array([keys.index(int(c)) if int(c) in keys else 0 for c in codes])[None, :]
    if x.size > 1:
        edges = np.concatenate([[x[0] - 0.5 * (x[1] - x[0])], 0.5 * (x[1:] + x[:-1]), [x[-1] + 0.5 * (x[-1] - x[-2])]])
    else:
        edges = np.array([x[0] - 0.5, x[0] + 0.5])
    ax.pcolormesh(edges, [0, 1], idx, cmap=cmap, vmin=-0.5, vmax=len(keys) - 0.5, shading="flat")
    ax.set_yticks([])
    ax.set_ylabel(title, rotation=0, ha="right", va="center", fontsize=8)
    present = sorted({int(c) for c in codes})
    handles = [Patch(color=colors[k], label=names[k]) for k in present if k in colors]
    ax.legend(handles=handles, loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=7, frameon=False,
              ncol=max(len(handles), 1), handlelength=1.0, columnspacing=0.8, borderpad=0.0)


def diagram(ds: xr.Dataset):
    """The bifurcation figure of a ``bifurcation`` (or ``response``) Dataset."""
    name = _param(ds)
    x = ds[name].values
    sweeps = [str(s) for s in ds["sweep"].values]
    has_lle = "lle" in ds and bool(np.any(np.isfinite(ds["lle"].values)))
    nb = 2 * len(sweeps)
    ratios = [5] + ([2] if has_lle else []) + [0.35] * nb
    fig, axes = plt.subplots(len(ratios), 1, figsize=(9, 5.5 + (1.6 if has_lle else 0) + 0.25 * nb), sharex=True,
                             gridspec_kw={"height_ratios": ratios, "hspace": 0.08})
    ax = axes[0]
    for s in sweeps:
        pu = ds["poincare_u"].sel(sweep=s).values
        xx = np.broadcast_to(x[:, None], pu.shape)
        ax.plot(xx.ravel(), pu.ravel(), ",", color=SWEEP_COLORS.get(s, "k"), alpha=0.8)
        ax.scatter(xx.ravel(), pu.ravel(), s=POINT_SIZE, color=SWEEP_COLORS.get(s, "k"), lw=0,
                   label=f"sweep {s}" if len(sweeps) > 1 or s != "fixed" else "Poincaré points")
    D = _backlash(ds)
    if D is not None and D > 0:
        ax.axhline(D, color="0.6", lw=0.7, ls="--")
        ax.axhline(-D, color="0.6", lw=0.7, ls="--")
    ax.set_ylabel("Poincaré section u (θ ≡ 0)")
    ax.legend(loc="upper left", fontsize=8, markerscale=8)
    mode = ds.attrs.get("mode", "")
    ax.set_title(f"Bifurcation diagram over {name}" + (f" ({mode} mode)" if mode else ""))
    k = 1
    if has_lle:
        ax2 = axes[1]
        for s in sweeps:
            lle = ds["lle"].sel(sweep=s).values
            err = ds["lle_err"].sel(sweep=s).values if "lle_err" in ds else None
            c = SWEEP_COLORS.get(s, "k")
            ax2.plot(x, lle, ".-", color=c, ms=3, lw=0.7)
            if err is not None:
                ax2.fill_between(x, lle - 3 * err, lle + 3 * err, color=c, alpha=0.15, lw=0)
        ax2.axhline(0.0, color="0.3", lw=0.7)
        ax2.set_ylabel("λ1 [1/τ]")
        k = 2
    for s in sweeps:
        category_band(axes[k], x, ds["motion"].sel(sweep=s).values, MOTION_COLORS, MOTION_NAMES,
                      f"motion ({s})" if len(sweeps) > 1 else "motion")
        category_band(axes[k + 1], x, ds["impact"].sel(sweep=s).values, IMPACT_COLORS, IMPACT_NAMES,
                      f"impact ({s})" if len(sweeps) > 1 else "impact")
        k += 2
    axes[-1].set_xlabel(label(ds[name], name))
    return fig


def _backlash(ds: xr.Dataset) -> float | None:
    import json

    try:
        return float(json.loads(ds.attrs["model"])["D"])
    except (KeyError, ValueError, TypeError):
        return None


def save_all(ds: xr.Dataset, directory: str | Path) -> list[Path]:
    """Write the bifurcation figure as PNG into ``directory``."""
    return [save(diagram(ds), Path(directory) / "bifurcation.png")]
