"""Figures of the reproduction report that no other result kind has: formula fit, ω search."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .common import PlotArtists, one_axes, result, snapshot

__all__ = ["formula_fit", "search_map"]


def formula_fit(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Computed amplitudes against ω with the fitted A0 + ΔA sin(πω) e^(−ξ0 ω) + β b², per (ξ0, b).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``formula_fit`` result of the reproduction report.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (8.5, 4.8))
    before = snapshot([ax])
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
    ax.set_title(f"Amplitude formula fit: R² = {float(ds.attrs['r2']):.3f} (dots: computed, lines: fit)")
    ax.legend(fontsize=7, ncol=2)
    return result(fig, [ax], before)


def search_map(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Fraction of grid points matching each claim, for each searched ω.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``search`` result of the reproduction report.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted (the colour bar is added beside it).

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    frac = ds["match_fraction"].values
    fig, ax, _ = one_axes(ax, (7, 0.6 + 0.45 * frac.shape[1] + 1.5))
    before = snapshot([ax])
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
    fig.colorbar(im, ax=ax, label="fraction of grid points matching the claim")
    ax.set_title(f"Where the claims over {ds.attrs.get('param')} hold")
    return result(fig, [ax], before)
