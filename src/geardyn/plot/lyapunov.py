"""Convergence of the Lyapunov exponents: running estimates against the number of periods, with
the final values and their uncertainty.  Drawn from the Dataset only."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr

from .common import plt, save


def convergence(ds: xr.Dataset):
    """Running λ1, λ2 estimates; the dashed line is −2ξ0 − λ1 for comparison with λ2."""
    run = ds["running"].values
    k = np.arange(1, run.shape[0] + 1)
    lam = ds["exponents"].values
    err = ds["uncertainty"].values
    fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    for i, ax in enumerate(axes):
        ax.plot(k, run[:, i], lw=0.9, color=f"C{i}")
        if np.isfinite(lam[i]):
            ax.axhline(lam[i], color="k", lw=0.7)
            e = err[i] if np.isfinite(err[i]) else 0.0
            ax.axhspan(lam[i] - 3 * e, lam[i] + 3 * e, color="0.85", lw=0)
        ax.set_ylabel(f"λ{i + 1} [1/τ]")
        ax.set_xscale("log")
    xi0 = json.loads(ds.attrs["model"])["xi0"]
    if np.isfinite(lam[0]):
        axes[1].axhline(-2 * xi0 - lam[0], color="C3", lw=0.7, ls="--", label="−2ξ0 − λ1")
        axes[1].legend(fontsize=8)
    axes[-1].set_xlabel("recorded forcing periods")
    omega = json.loads(ds.attrs["model"])["omega"]
    axes[0].set_title(f"Lyapunov exponents at ω = {omega:g}: λ1 = {lam[0]:.5g} ± {err[0]:.2g}, "
                      f"λ2 = {lam[1]:.5g} ± {err[1]:.2g}  (band: ±3σ)")
    return fig


def save_all(ds: xr.Dataset, directory: str | Path) -> list[Path]:
    """Write the convergence figure as PNG into ``directory``."""
    return [save(convergence(ds), Path(directory) / "lyapunov.png")]
