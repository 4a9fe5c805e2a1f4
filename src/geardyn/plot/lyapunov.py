"""Convergence of the Lyapunov exponents: running estimates against the number of periods, with
the final values and their uncertainty.  Drawn from the Dataset only."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .common import model_of, plot_function, set_title

__all__ = ["convergence"]


@plot_function(
    "lyapunov",
    (8, 5.5),
    n=2,
    subplots={"sharex": True},
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of two Axes, optional
                   One Axes: λ1 only; two: λ1 and λ2; omitted: a new figure.""",
)
def convergence(ds: xr.Dataset, ax: Any = None) -> None:
    """Running λ1, λ2 estimates with the final values ±3σ; the dashed line is −2ξ0 − λ1 for comparison with λ2."""
    run = ds["running"].values
    k = np.arange(1, run.shape[0] + 1)
    lam = ds["exponents"].values
    err = ds["uncertainty"].values
    for i, a in enumerate(ax):
        if a is None:
            continue
        a.plot(k, run[:, i], lw=0.9, color=f"C{i}")
        if np.isfinite(lam[i]):
            a.axhline(lam[i], color="k", lw=0.7)
            e = err[i] if np.isfinite(err[i]) else 0.0
            a.axhspan(lam[i] - 3 * e, lam[i] + 3 * e, color="0.85", lw=0)
        a.set_ylabel(f"λ{i + 1} [1/τ]")
        a.set_xscale("log")
    m = model_of(ds)
    if np.isfinite(lam[0]) and ax[1] is not None and "xi0" in m:  # the pair's λ1 + λ2 = −2ξ0
        ax[1].axhline(-2 * m["xi0"] - lam[0], color="C3", lw=0.7, ls="--", label="−2ξ0 − λ1")
        ax[1].legend(fontsize=8)
    [a for a in ax if a is not None][-1].set_xlabel("recorded forcing periods")
    set_title(
        ax[0],
        f"Lyapunov exponents: λ1 = {lam[0]:.5g} ± {err[0]:.2g}, λ2 = {lam[1]:.5g} ± {err[1]:.2g}  (band: ±3σ)",
        ds,
    )
