"""Dataset conventions and NetCDF input/output.

Every result is one :class:`xarray.Dataset`: dimensions named after what they index (swept
parameters by their canonical names), variables with ``units`` and ``long_name`` attributes, the
full model and options as JSON attributes (``model``, ``options``), the kind of result in
``geardyn_kind``, and a per-point ``status`` where there are points.  Files are written
atomically: to a temporary file in the same directory, then renamed.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import asdict, is_dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .model import GearModel

#: Units and long names of the variables and coordinates geardyn writes ("1" = non-dimensional).
VARIABLES: dict[str, tuple[str, str]] = {
    "tau": ("1", "non-dimensional time τ = ω_n t"),
    "u": ("1", "dynamic transmission error u (non-dimensional)"),
    "v": ("1", "velocity du/dτ (non-dimensional)"),
    "poincare_u": ("1", "Poincaré section u at θ ≡ 0"),
    "poincare_v": ("1", "Poincaré section du/dτ at θ ≡ 0"),
    "order": ("1", "order of the mesh frequency"),
    "spectrum": ("1", "single-sided amplitude spectrum of u"),
    "amplitude": ("1", "half peak-to-peak displacement"),
    "rms": ("1", "RMS of u about its mean"),
    "mean": ("1", "mean displacement"),
    "u_min": ("1", "smallest displacement"),
    "u_max": ("1", "largest displacement"),
    "period": ("1", "period of the Poincaré sequence (0 not periodic, -1 diverged)"),
    "impact": ("1", "impact state (0 none, 1 single-sided, 2 double-sided, -1 unknown)"),
    "fraction_drive": ("1", "time fraction in drive-side contact"),
    "fraction_separation": ("1", "time fraction in separation"),
    "fraction_back": ("1", "time fraction in back-side contact"),
    "status": ("1", "point status (0 ok, 1 diverged)"),
    "lle": ("1/τ", "largest Lyapunov exponent"),
    "omega": ("1", "mesh frequency ω = ω_e/ω_n"),
    "xi0": ("1", "mean damping ratio ξ0"),
    "fp": ("1", "mean load f_p"),
    "D": ("1", "half backlash D"),
}


def json_attr(obj: Any) -> str:
    """Serialise a model, options dataclass or plain value to a JSON attribute string."""
    if isinstance(obj, GearModel):
        return obj.to_json()
    if is_dataclass(obj):
        return json.dumps(asdict(obj), sort_keys=True, default=_default)
    return json.dumps(obj, sort_keys=True, default=_default)


def _default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def annotate(ds: xr.Dataset) -> xr.Dataset:
    """Fill in ``units`` and ``long_name`` for every known variable and coordinate lacking them."""
    for name in list(ds.variables):
        base = str(name)
        meta = VARIABLES.get(base)
        if meta is None:
            continue
        attrs = ds[name].attrs
        attrs.setdefault("units", meta[0])
        attrs.setdefault("long_name", meta[1])
    return ds


def result_attrs(kind: str, model: GearModel, options: Any = None, **extra: Any) -> dict[str, str]:
    """Standard global attributes: kind, model and options as JSON, and any extra JSON values."""
    from . import __version__

    attrs = {"geardyn_kind": kind, "geardyn_version": __version__, "model": json_attr(model)}
    if options is not None:
        attrs["options"] = json_attr(options)
    for k, v in extra.items():
        attrs[k] = v if isinstance(v, str) else json_attr(v)
    return attrs


def model_from_attrs(ds: xr.Dataset) -> GearModel:
    """The model stored in a Dataset's ``model`` attribute."""
    return GearModel.from_dict(json.loads(ds.attrs["model"]))


def _temp_beside(path: Path) -> str:
    """A new temporary file next to ``path`` with the permissions a plain ``open`` would give."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    return tmp


def _fsync_dir(directory: Path) -> None:
    """Make a rename in ``directory`` durable (POSIX; a no-op where directories cannot be opened)."""
    try:
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write bytes to ``path`` atomically (temporary file in the same directory, fsync, rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temp_beside(path)
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
        _fsync_dir(path.parent)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_netcdf(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to NetCDF (h5netcdf) atomically; returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temp_beside(path)
    try:
        annotate(ds).to_netcdf(tmp, engine="h5netcdf")
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
        _fsync_dir(path.parent)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def read_netcdf(path: str | Path) -> xr.Dataset:
    """Read a geardyn NetCDF file fully into memory."""
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()
