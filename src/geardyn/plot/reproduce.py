"""Figures of the reproduction report that no other result kind has: formula fit, ω search."""

from __future__ import annotations


import numpy as np
import xarray as xr

from matplotlib.axes import Axes

from .common import plot_function, set_title, symbol

__all__ = ["formula_fit", "readings_map", "search_map"]


@plot_function("formula_fit", (8.5, 4.8))
def formula_fit(ds: xr.Dataset, ax: Axes = None) -> None:
    """Computed amplitudes against ω with the fitted A0 + ΔA sin(πω) e^(−ξ0 ω) + β b², per (ξ0, b)
    (a result of the reproduction report)."""
    A0, dA, beta = (float(ds.attrs[k]) for k in ("A0", "dA", "beta"))
    w, xi0, b, a = (ds[k].values for k in ("omega", "xi0", "b_mm", "amplitude"))
    groups = sorted({(x, y) for x, y in zip(xi0, b)})
    for i, (x0, bb) in enumerate(groups):
        sel = (xi0 == x0) & (b == bb)
        order = np.argsort(w[sel])
        c = f"C{i % 10}"
        ax.plot(w[sel][order], a[sel][order], ".", color=c, ms=4, label=f"ξ0 = {x0:g}, b = {bb:g} mm")
        ww = np.linspace(w.min(), w.max(), 300)
        ax.plot(ww, A0 + dA * np.sin(np.pi * ww) * np.exp(-x0 * ww) + beta * bb**2, "-", color=c, lw=1)
    ax.set_xlabel("mesh frequency ω = ω_e/ω_n")
    ax.set_ylabel("amplitude (half peak-to-peak of u)")
    set_title(ax, f"Amplitude formula fit: R² = {float(ds.attrs['r2']):.3f} (dots: computed, lines: fit)", ds,
              exclude=["omega", "xi0", "D"])
    ax.legend(fontsize=7, ncol=2)


def _search_size(ds: xr.Dataset) -> tuple[float, float]:
    return 7, 0.6 + 0.45 * ds["match_fraction"].shape[1] + 1.5


@plot_function("search", _search_size, ax_doc="""
               ax : matplotlib.axes.Axes, optional
                   Where to draw; a new figure if omitted (the colour bar is added beside it).""")
def search_map(ds: xr.Dataset, ax: Axes = None) -> None:
    """Fraction of grid points matching each claim, for each searched ω (a result of the reproduction report)."""
    frac = ds["match_fraction"].values
    im = ax.imshow(frac.T, aspect="auto", origin="lower", vmin=0, vmax=1, cmap="viridis",
                   extent=(-0.5, frac.shape[0] - 0.5, -0.5, frac.shape[1] - 0.5))
    ax.set_xticks(range(frac.shape[0]), [f"{w:g}" for w in ds["omega"].values])
    ax.set_yticks(range(frac.shape[1]), [str(c) for c in ds["claim"].values])
    ax.set_xlabel("ω searched")
    for i in range(frac.shape[0]):
        for j in range(frac.shape[1]):
            if np.isfinite(frac[i, j]):
                ax.text(i, j, f"{frac[i, j]:.0%}", ha="center", va="center", fontsize=7,
                        color="w" if frac[i, j] < 0.6 else "k")
    ax.figure.colorbar(im, ax=ax, label="fraction of grid points matching the claim")
    param = str(ds.attrs.get("param"))
    set_title(ax, f"Where the claims over {symbol(param)} hold", ds, exclude=["omega", param])


def _readings_size(ds: xr.Dataset) -> tuple[float, float]:
    return 9, 1.6 + 0.32 * ds["hold_fraction"].shape[0]


@plot_function("readings_map", _readings_size, ax_doc="""
               ax : matplotlib.axes.Axes, optional
                   Where to draw; a new figure if omitted (the colour bar is added beside it).""")
def readings_map(ds: xr.Dataset, ax: Axes = None) -> None:
    """Fraction of the readings (phase pairs, backlash readings) under which each claim's screen holds, against ω
    (a result of the reproduction report); the default ω dashed."""
    f = ds["hold_fraction"].values
    w = ds["omega"].values
    mid = 0.5 * (w[1:] + w[:-1])
    half = float(w[1] - w[0]) / 2 if w.size > 1 else 0.005
    edges = np.concatenate([[w[0] - half], mid, [w[-1] + (float(w[-1] - w[-2]) / 2 if w.size > 1 else half)]])
    im = ax.pcolormesh(edges, np.arange(f.shape[0] + 1) - 0.5, f, vmin=0, vmax=1, cmap="viridis")
    ax.set_yticks(range(f.shape[0]), [str(c) for c in ds["claim"].values])
    ax.axvline(float(ds.attrs.get("default_omega", 1.0)), color="w", ls="--", lw=0.8)
    ax.set_xlabel("mesh frequency ω = ω_e/ω_n (dashed: the default reading)")
    ax.figure.colorbar(im, ax=ax, label="fraction of the readings holding")
    set_title(ax, "Where each claim holds on the screen of readings", ds, exclude=["omega", "xi0", "xi1", "D"])
