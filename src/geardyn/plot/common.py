"""Shared figure helpers: the non-interactive backend, axis labels from Dataset attributes, saving."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import xarray as xr  # noqa: E402

#: Resolution of saved PNG figures.
DPI = 120


def label(da: xr.DataArray, fallback: str | None = None) -> str:
    """Axis label '<long_name> [units]' from a DataArray's attributes."""
    name = da.attrs.get("long_name", fallback or str(da.name))
    units = da.attrs.get("units")
    return f"{name} [{units}]" if units and units != "1" else name


def save(fig: "plt.Figure", path: str | Path) -> Path:
    """Save a figure as PNG and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    return path
