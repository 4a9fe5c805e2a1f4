"""Datasets of the one-point analyses of multi-DOF systems (``--out`` with ``--system``).

Kinds ``system_simulate`` (time history of every element's δ, δ' and the mesh forces; the
full-state Poincaré points), ``system_lyapunov`` (all 2n exponents and the per-period logs) and
``system_orbit`` (the orbit's section points, monodromy and all multipliers, the elastic ones
marked).  Their figures are registered in :mod:`geardyn.plot.systems`; the command's JSON summary
is kept in the ``summary`` attribute, so ``geardyn plot`` redraws the same figures from the file.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from ..systems.report import mesh_forces
from ..io import system_attrs

__all__ = ["simulate_dataset", "lyapunov_dataset", "orbit_dataset"]


def _states(model: Any) -> list[str]:
    return [f"{lab}" for lab in model.labels] + [f"{lab}'" for lab in model.labels]


def _finish(ds: xr.Dataset, summary: dict[str, Any], units: dict[str, tuple[str, str]]) -> xr.Dataset:
    from ..io import annotate

    del units  # the metadata come from the registry (geardyn.io.SYSTEM_VARIABLES)
    ds.attrs["summary"] = json.dumps(summary, default=lambda o: None)
    return annotate(ds)


def simulate_dataset(res: Any) -> xr.Dataset:
    """The Dataset of a :class:`~geardyn.analysis.steady.SteadyState` of a system.

    Parameters
    ----------
    res : SteadyState

    Returns
    -------
    xarray.Dataset
        Kind ``system_simulate``.
    """
    m, t = res.model, res.traj
    els = [e.name for e in m.elements]
    M = len(m.meshes)
    force = mesh_forces(m, t.tau, t.deltas) if np.all(np.isfinite(t.deltas)) else np.full((t.tau.size, M), np.nan)
    sc = m.scaling
    ds = xr.Dataset({
        "delta": (("tau", "element"), t.deltas[:, :, 0]),
        "delta_rate": (("tau", "element"), t.deltas[:, :, 1]),
        "u": ("tau", t.u), "v": ("tau", t.v),
        "mesh_force": (("tau", "mesh"), force),
        "mesh_force_N": (("tau", "mesh"), force * sc.force_scale),
        "state": (("tau", "coordinate"), t.x),
        "poincare": (("section", "coordinate"), res.poincare),
    }, coords={"tau": t.tau, "element": els, "mesh": els[:M], "coordinate": _states(m),
               "section": np.arange(res.poincare.shape[0])},
        attrs=system_attrs(m, "system_simulate", res.options))
    return _finish(ds, res.to_json(), {
        "delta": ("1", "deflection δ of the element (DTE over b_c for a mesh)"),
        "delta_rate": ("1", "rate dδ/dτ of the element"),
        "mesh_force": ("1", "mesh force over k_ref b_c"), "mesh_force_N": ("N", "dynamic mesh force"),
        "state": ("1", "state (q̃, q̃')"), "poincare": ("1", "Poincaré points of the full state at θ ≡ 0"),
        "u": ("1", "deflection δ of the reference mesh"), "v": ("1", "rate dδ/dτ of the reference mesh")})


def lyapunov_dataset(res: Any) -> xr.Dataset:
    """The Dataset of a :class:`~geardyn.analysis.lyapunov.LyapunovResult` of a system.

    Parameters
    ----------
    res : LyapunovResult

    Returns
    -------
    xarray.Dataset
        Kind ``system_lyapunov``.
    """
    m = res.model
    d = res.exponents.size
    ds = xr.Dataset({"exponents": ("exponent", res.exponents), "uncertainty": ("exponent", res.uncertainty),
                     "log_r": (("section", "exponent"), np.asarray(res.log)[:, :d])},
                    coords={"exponent": np.arange(1, d + 1), "section": np.arange(np.asarray(res.log).shape[0])},
                    attrs=system_attrs(m, "system_lyapunov", res.options))
    return _finish(ds, res.to_json(), {})


def orbit_dataset(orbit: Any) -> xr.Dataset:
    """The Dataset of a :class:`~geardyn.analysis.periodic.PeriodicOrbit` of a system.

    Parameters
    ----------
    orbit : PeriodicOrbit

    Returns
    -------
    xarray.Dataset
        Kind ``system_orbit``.
    """
    m = orbit.model
    mu = np.asarray(orbit.multipliers, complex) if orbit.converged else np.full(m.state_dim, np.nan + 0j)
    el, _ = orbit.elastic if orbit.converged else (np.zeros(0, complex), 0)
    ds = xr.Dataset({
        "points": (("section", "coordinate"), np.asarray(orbit.points, float)),
        "monodromy": (("row", "col"), np.asarray(orbit.monodromy, float)),
        "multiplier_re": ("multiplier", mu.real), "multiplier_im": ("multiplier", mu.imag),
        "elastic_re": ("elastic", el.real), "elastic_im": ("elastic", el.imag),
    }, coords={"section": np.arange(orbit.points.shape[0]), "coordinate": _states(m),
               "multiplier": np.arange(mu.size), "elastic": np.arange(el.size)},
        attrs=system_attrs(m, "system_orbit", None))
    return _finish(ds, orbit.to_json(), {
        "points": ("1", "section points of the orbit (full state)"),
        "elastic_re": ("1", "elastic Floquet multiplier, real part"),
        "elastic_im": ("1", "elastic Floquet multiplier, imaginary part")})
