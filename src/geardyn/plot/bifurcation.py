"""Bifurcation diagram: Poincaré points against the swept parameter, the largest Lyapunov exponent
beneath, and bands of the motion class and impact state.  Drawn from the Dataset only."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from matplotlib.colors import ListedColormap
from matplotlib.patches import Patch

from ..analysis.classify import IMPACT_LABELS, MOTION_LABELS
from .common import cell_edges, contact_lines, equal_steps, label, of_mesh, plot_function, rpm_axis, set_title, symbol

__all__ = ["IMPACT_COLORS", "MOTION_COLORS", "POINT_SIZE", "SWEEP_COLORS", "category_band", "diagram", "diagram_panels"]

#: Colours of the motion classes (codes of :data:`geardyn.analysis.classify.MOTION_LABELS`).
MOTION_COLORS = {-1: "#000000", 0: "#bdbdbd", 1: "#4c9be8", 2: "#3cb371", 3: "#e8554c"}
#: Colours of the impact states (codes of :data:`geardyn.analysis.classify.IMPACT_LABELS`).
IMPACT_COLORS = {-1: "#000000", 0: "#9ecae1", 1: "#fdae6b", 2: "#d94801"}
#: Colours of the sweeps.
SWEEP_COLORS = {"fixed": "k", "up": "C0", "down": "C3"}
#: Marker size of the Poincaré points.
POINT_SIZE = 0.6


#: A sweep of at most this many values, or of unequal steps, is a set of separate settings (Table 3's three
#: backlash values): drawn as separate cells and markers, not joined by bands and lines.
DISCRETE_MAX = 12


def is_discrete(x: np.ndarray) -> bool:
    """Whether the values of a sweep are separate settings rather than a grid (few, or unequally spaced)."""
    x = np.asarray(x, dtype=float)
    return x.size <= DISCRETE_MAX or not equal_steps(x)


def category_band(ax, x: np.ndarray, codes: np.ndarray, colors: dict[int, str], names: dict[int, str], title: str):
    """A one-row categorical strip of ``codes`` against ``x`` with a legend of the codes present.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    x : ndarray
        Grid values (the strip's cells are centred on them).
    codes : ndarray
        Integer code per grid value.
    colors, names : dict
        Colour and legend name of each code.
    title : str
        Label left of the strip.

    Returns
    -------
    list of Artist
        The mesh and the legend.
    """
    keys = sorted(colors)
    cmap = ListedColormap([colors[k] for k in keys])
    idx = np.array([keys.index(int(c)) if int(c) in keys else 0 for c in codes])[None, :]
    if is_discrete(x):  # separate settings: one cell per value, with gaps between them
        half = 0.3 * (float(np.min(np.diff(np.sort(x)))) if x.size > 1 else 1.0)
        mesh = None
        for xi, k in zip(x, idx[0], strict=True):
            mesh = ax.bar(xi, 1.0, width=2 * half, bottom=0.0, color=cmap(int(k)), lw=0)
    else:
        mesh = ax.pcolormesh(cell_edges(x), [0, 1], idx, cmap=cmap, vmin=-0.5, vmax=len(keys) - 0.5, shading="flat")
    ax.set_yticks([])
    ax.set_ylabel(title, rotation=0, ha="right", va="center", fontsize=8)
    present = sorted({int(c) for c in codes})
    handles = [Patch(color=colors[k], label=names[k]) for k in present if k in colors]
    leg = ax.legend(
        handles=handles,
        loc="center left",
        bbox_to_anchor=(1.01, 0.5),
        fontsize=7,
        frameon=False,
        ncol=max(len(handles), 1),
        handlelength=1.0,
        columnspacing=0.8,
        borderpad=0.0,
    )
    return [mesh, leg]


def _has_lle(ds: xr.Dataset) -> bool:
    return "lle" in ds and bool(np.any(np.isfinite(ds["lle"].values)))


def diagram_panels(ds: xr.Dataset) -> int:
    """Number of panels of :func:`diagram` for ``ds``: points, λ1 (if computed), two bands per sweep.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``bifurcation`` or ``response`` result.

    Returns
    -------
    int
        The number of Axes to give :func:`diagram` for the full figure.
    """
    return 1 + int(_has_lle(ds)) + 2 * ds.sizes["sweep"]


@plot_function(
    "bifurcation`` or ``response",
    lambda ds: (9, 5.5 + (1.6 if _has_lle(ds) else 0) + 0.5 * ds.sizes["sweep"]),
    n=diagram_panels,
    subplots=lambda ds: {
        "sharex": True,
        "gridspec_kw": {
            "height_ratios": [5] + ([2] if _has_lle(ds) else []) + [0.35] * (2 * ds.sizes["sweep"]),
            "hspace": 0.08,
        },
    },
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of Axes, optional
                   One Axes: the Poincaré points only; :func:`diagram_panels` Axes: every panel (points, λ1
                   when computed, motion and impact bands of each sweep); omitted: a new figure.""",
)
def diagram(ds: xr.Dataset, ax: Any = None) -> None:
    """The bifurcation figure of a ``bifurcation`` (or ``response``) Dataset, with the contact boundaries
    u = ±D (following D when D is the swept parameter)."""
    name = str(ds.attrs.get("param", [d for d in ds["motion"].dims if d != "sweep"][0]))
    x = ds[name].values
    sweeps = [str(s) for s in ds["sweep"].values]
    axes, ax = ax, ax[0]  # (always several panels: the points and two bands per sweep)
    discrete = is_discrete(x)
    for s in sweeps:
        pu = ds["poincare_u"].sel(sweep=s).values
        xx, pu = np.broadcast_to(x[:, None], pu.shape).ravel(), pu.ravel()
        c = SWEEP_COLORS.get(s, "k")
        ax.plot(xx, pu, ",", color=c, alpha=0.8)
        ax.scatter(
            xx,
            pu,
            s=12 if discrete else POINT_SIZE,
            color=c,
            lw=0,
            label=f"sweep {s}" if len(sweeps) > 1 or s != "fixed" else "Poincaré points",
        )
    if discrete and name in ("D", "backlash", "b"):  # u = ±D at each setting, not a line joining them
        lines = [ax.plot(x, sgn * x, "_", color="0.6", ms=14, mew=1.2, gid="contact")[0] for sgn in (1, -1)]
    else:
        lines = contact_lines(ax, ds, name, x, lw=0.7, ls="--")
    if lines:
        lines[0].set_label(of_mesh("contact u = ±D", ds))
    ax.set_ylabel(of_mesh("Poincaré section u (θ ≡ 0)", ds))
    # where it covers the fewest Poincaré points (their dots enlarged in the legend on a dense grid)
    ax.legend(loc="best", fontsize=8, markerscale=1 if discrete else 8)
    mode = ds.attrs.get("mode", "")
    set_title(ax, f"Bifurcation diagram over {symbol(name)}" + (f" ({mode} mode)" if mode else ""), ds, exclude=[name])
    rpm_axis(ax, ds, name)
    k = 1 + _has_lle(ds)
    ax2 = axes[1] if k == 2 else None
    if ax2 is not None:
        for s in sweeps:
            lle = ds["lle"].sel(sweep=s).values
            err = ds["lle_err"].sel(sweep=s).values if "lle_err" in ds else None
            c = SWEEP_COLORS.get(s, "k")
            if discrete:  # separate settings: markers with their ±3σ bars, nothing joining them
                ax2.errorbar(x, lle, yerr=None if err is None else 3 * err, fmt="o", color=c, ms=4, capsize=3)
                continue
            ax2.plot(x, lle, ".-", color=c, ms=3, lw=0.7)
            if err is not None:
                ax2.fill_between(x, lle - 3 * err, lle + 3 * err, color=c, alpha=0.15, lw=0)
        ax2.axhline(0.0, color="0.3", lw=0.7)
        ax2.set_ylabel("λ1 [1/τ]")
    for s in sweeps:
        if axes[k] is not None:
            for a, var, colors, names in (
                (axes[k], "motion", MOTION_COLORS, MOTION_LABELS),
                (axes[k + 1], "impact", IMPACT_COLORS, IMPACT_LABELS),
            ):
                category_band(
                    a, x, ds[var].sel(sweep=s).values, colors, names, f"{var} ({s})" if len(sweeps) > 1 else var
                )
        k += 2
    [a for a in axes if a is not None][-1].set_xlabel(label(ds[name]))
