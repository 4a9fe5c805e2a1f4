"""The mesh of a pair as a Dataset and a JSON summary, with the Fourier harmonics it implies and the
ISO 6336-1 single and mesh stiffness beside it."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import xarray as xr

from ..standards.iso6336 import cylindrical_mesh
from .excitation import fourier_series
from .mesh import MeshStiffness, faults_json

__all__ = ["iso_beside", "stiffness_dataset", "stiffness_summary"]


def iso_beside(ms: MeshStiffness, torque1: float | None = None) -> dict[str, float]:
    """ISO 6336-1 Method B c′ and c_γα (C_M = 0.8, C_R = 1, C_B; C_F from the torque) beside the computed
    single-pair maximum and mean mesh stiffness per unit face width, all in N/(mm·µm).

    Parameters
    ----------
    ms : MeshStiffness
        The mesh.
    torque1 : float, optional
        Pinion torque for ISO's C_F (default C_F = 1).

    Returns
    -------
    dict
    """
    geo = ms.geometry
    b = geo.face_width
    mean = float(np.mean(ms.stiffness_unmodified)) / b / 1e9
    c_single = float(np.max(ms.components["pair"])) / b / 1e9
    virtual = any(g.z != g.teeth for g in geo.gears)  # virtual cylindrical gears of a bevel pair: ISO 10300 applies
    c1 = cg = C_F = eps = None
    if not virtual:
        iso = cylindrical_mesh(
            geo.gears[0].teeth,
            geo.gears[1].teeth,
            geo.m_n,
            geo.alpha_n,
            geo.beta,
            geo.face_width,
            x1=geo.gears[0].x,
            x2=geo.gears[1].x,
            h_aP=geo.h_a,
            h_fP=geo.h_f,
            torque1=torque1,
        )
        c1, C_F, eps = iso.c_prime / 1e9, iso.C_F, iso.eps_alpha
        cg = (iso.c_gamma_alpha if geo.beta == 0 else iso.c_gamma_beta) / 1e9
    out = {
        "c_prime_iso": c1,
        "c_gamma_iso": cg,
        "C_F": C_F,
        "single_pair_max": c_single,
        "mesh_mean": mean,
        "mesh_mean_over_c_gamma": None if virtual else mean / cg,
        "single_max_over_c_prime": None if virtual else c_single / c1,
        "eps_alpha_iso": eps,
    }
    if virtual:
        out["note"] = "virtual cylindrical gears: compare with geardyn geometry (ISO 10300-1)"
    return out


def stiffness_summary(ms: MeshStiffness, harmonics: int = 8, torque1: float | None = None) -> dict[str, Any]:
    """Geometry, mean/min/max stiffness, STE, the first harmonics (of the excitation's period) and ISO.

    Parameters
    ----------
    ms : MeshStiffness
        The mesh.
    harmonics : int
        Harmonics listed.
    torque1 : float, optional
        As :func:`iso_beside`.

    Returns
    -------
    dict
    """
    geo = ms.geometry
    k0, ka, kp = fourier_series(ms.stiffness)
    _, ea, ep = fourier_series(ms.ste_equivalent)
    H = min(harmonics, len(ka))
    g1, g2 = geo.gears
    return {
        "z1": g1.teeth,
        "z2": g2.teeth,
        "z_shape": [g1.z, g2.z],
        "m_n_mm": geo.m_n * 1e3,
        "alpha_n_deg": math.degrees(geo.alpha_n),
        "beta_deg": math.degrees(geo.beta),
        "face_width_mm": geo.face_width * 1e3,
        "x1": g1.x,
        "x2": g2.x,
        "eps_alpha": geo.eps_alpha,
        "eps_beta": geo.eps_beta,
        "force_N": ms.force,
        "cycles": ms.cycles,
        "points": int(ms.phase.size),
        "slices": ms.slices,
        "k_mean_N_per_um": k0 / 1e6,
        "k_min_N_per_um": float(ms.stiffness.min()) / 1e6,
        "k_max_N_per_um": float(ms.stiffness.max()) / 1e6,
        "ste_mean_um": float(np.mean(ms.ste)) * 1e6,
        "ste_peak_to_peak_um": float(np.ptp(ms.ste)) * 1e6,
        "harmonic_order_of_mesh": [(j + 1) / ms.cycles for j in range(H)],
        "kappa": (ka[:H] / k0).tolist(),
        "phi_k": kp[:H].tolist(),
        "ste_harmonics_um": (ea[:H] * 1e6).tolist(),
        "phi_e": ep[:H].tolist(),
        "kappa_abs_sum_all": float(np.sum(ka) / k0),
        "iso6336": iso_beside(ms, torque1),
        "faults": faults_json(ms.faults),
    }


def stiffness_dataset(ms: MeshStiffness, summary: dict[str, Any]) -> xr.Dataset:
    """``geardyn_kind = "stiffness"``: stiffness, STE and load shares over the mesh phase, and a healthy
    single pair's compliances by term along the path of contact.

    Parameters
    ----------
    ms : MeshStiffness
        The mesh.
    summary : dict
        Its :func:`stiffness_summary`.

    Returns
    -------
    xarray.Dataset
    """
    c = ms.components
    J = ms.share.shape[1]
    ds = xr.Dataset(
        {
            "mesh_stiffness": ("phase", ms.stiffness / 1e6, {"units": "N/um", "long_name": "mesh stiffness k_m"}),
            "mesh_stiffness_unmodified": ("phase", ms.stiffness_unmodified / 1e6, {"units": "N/um"}),
            "ste": ("phase", ms.ste * 1e6, {"units": "um", "long_name": "loaded static transmission error"}),
            "ste_noload": ("phase", np.where(np.isfinite(ms.ste_noload), ms.ste_noload, np.nan) * 1e6, {"units": "um"}),
            "ste_equivalent": ("phase", ms.ste_equivalent * 1e6, {"units": "um", "long_name": "e_eq = δ − F/k_m"}),
            "load_share": (("phase", "pair"), ms.share, {"units": "1"}),
            "pairs_in_contact": ("phase", ms.pairs_in_contact),
            **{
                f"compliance_{k}": (
                    "path",
                    c[k] * 1e9,
                    {"units": "mm*um/N", "long_name": f"{k} compliance per unit width"},
                )
                for k in ("hertz", "bending", "shear", "axial", "fillet")
            },
            "single_pair_stiffness": ("path", c["pair"] / 1e6, {"units": "N/um"}),
        },
        coords={
            "phase": ("phase", ms.phase, {"units": "mesh cycles"}),
            "pair": np.arange(J),
            "path": (
                "path",
                (c["s"] - ms.geometry.s_A) / ms.geometry.p_bt,
                {"units": "base pitches", "long_name": "position on the path of contact from A"},
            ),
        },
    )
    ds.attrs.update(geardyn_kind="stiffness", summary=json.dumps(summary))
    return ds
