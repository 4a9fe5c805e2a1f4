"""ISO 10300-1 mesh data of a configured bevel or hypoid pair: contact ratios, c_γ, k0 by ISO, K_v, κ_r.

The torsional model (:class:`~geardyn.geometry.SpiralBevelGearPair`) needs only the mean mesh
stiffness k0; ISO 10300-1 gives it from the geometry as ``k0 = c_γ · b_v,eff`` (mesh stiffness per
unit face width of the virtual cylindrical gears times their effective face width), and gives
further the contact ratios, the stiffness harmonics they imply
(:func:`~geardyn.standards.mesh_stiffness_harmonics`), the resonance speed and the dynamic factor
K_v by Method B.  This module feeds a pair and the extra ``[gear_pair]`` keys of a configuration
(:data:`ISO_KEYS`) to :func:`~geardyn.standards.bevel_mesh` and turns the result into rows of the
geometry report.

k0 methods (``[gear_pair] k0_method``):

* ``"iso"``: ``k0 = c_γ b_v,eff`` with c_γ = 20 N/(mm·µm) · C_F (ISO 10300-1 clause 6.3, C_F the
  low-load factor at the configured torque; C_F = 1 without a torque), or the given ``c_gamma``
  times b_v,eff;
* ``"face_width"``: ``k0 = c_γ · b`` (the estimate geardyn used before; b the face width).

The default is ``"iso"`` when the configuration gives any ISO-only input (:data:`ISO_ONLY_KEYS`)
and ``"face_width"`` otherwise, so that the configurations written before keep their k0.

References
----------
ISO 10300-1:2014, clause 6 and Annex A; ISO 23509:2016; ISO/TR 10300-30:2017.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..model import ModelError
from ..standards import BevelMesh, bevel_mesh

__all__ = [
    "ISO_KEYS",
    "ISO_ONLY_KEYS",
    "K0_METHODS",
    "SIMULATED_KV",
    "iso_k0",
    "iso_kv_block",
    "iso_rows",
    "iso_summary",
    "pair_iso_mesh",
]

#: The extra ``[gear_pair]`` keys read by :func:`pair_iso_mesh` (names of :func:`bevel_mesh` arguments).
ISO_KEYS = (
    "beta_m2",
    "alpha_lim",
    "d_m1",
    "d_m2",
    "delta1",
    "delta2",
    "h_am1",
    "h_am2",
    "x_hm1",
    "offset",
    "zeta_mp",
    "zeta_m",
    "b2_eff",
    "K_A",
    "f_pt",
    "density",
)
#: Inputs that only the ISO chain uses: giving any of them selects ``k0_method = "iso"`` by default.
ISO_ONLY_KEYS = ISO_KEYS
#: The ways to obtain k0 from the geometry.
K0_METHODS = ("iso", "face_width")
#: Number of stiffness harmonics κ_r derived from the contact ratios.
N_KAPPA = 3


def pair_iso_mesh(
    pair: Any,
    inputs: Mapping[str, float] | None = None,
    *,
    rpm: float | None = None,
    torque: float | None = None,
    n_harmonics: int = N_KAPPA,
) -> BevelMesh:
    """The ISO 10300-1 mesh data of a pair with the extra inputs of its configuration.

    Parameters
    ----------
    pair : SpiralBevelGearPair
        The pair (teeth, m_mn, β_m, α_n, Σ and the resolved face width are used).
    inputs : mapping, optional
        The extra inputs by their :data:`ISO_KEYS` names, in SI units.
    rpm : float, optional
        Pinion speed (rpm): gives the resonance ratio N and, with ``torque`` and ``f_pt``, K_v.
    torque : float, optional
        Pinion torque T1 (N·m): gives the low-load factor C_F.
    n_harmonics : int, optional
        Number of stiffness harmonics κ_r.

    Returns
    -------
    BevelMesh
        The result of :func:`~geardyn.standards.bevel_mesh` for the pair and these inputs.

    Raises
    ------
    ModelError
        When the ISO chain does not apply (see :func:`~geardyn.standards.bevel_mesh`).
    """
    kw = dict(inputs or {})
    unknown = set(kw) - set(ISO_KEYS)
    if unknown:
        raise ModelError(f"iso inputs: unknown {sorted(unknown)}; allowed: {', '.join(ISO_KEYS)}")
    speed = None if rpm is None else float(rpm) * math.pi / 30.0
    return bevel_mesh(
        pair.z1,
        pair.z2,
        pair.m_mn,
        pair.beta_m,
        pair.alpha_n,
        pair.Sigma,
        pair.resolved.face_width,
        torque1=torque,
        speed1=speed,
        n_harmonics=n_harmonics,
        **kw,
    )


def iso_k0(mesh: BevelMesh, c_gamma: float | None = None) -> float:
    """k0 by ISO 10300-1: ``c_γ · b_v,eff`` (N/m), with the given ``c_gamma`` (N/m²) instead of ISO's when given.

    Parameters
    ----------
    mesh : BevelMesh
        The virtual cylindrical gears of the pair (:class:`geardyn.standards.iso10300.BevelMesh`).
    c_gamma : float, optional
        Mesh stiffness c_γ in N/m² (per unit face width); default the ISO value ``mesh.c_gamma``.

    Returns
    -------
    float
        Mesh stiffness k0 in N/m.

    References
    ----------
    ISO 10300-1:2014, *Calculation of load capacity of bevel gears — Part 1: Introduction and
    general influence factors*.
    """
    return (mesh.c_gamma if c_gamma is None else float(c_gamma)) * mesh.b_v_eff


def iso_summary(
    mesh: BevelMesh, *, k0_method: str, k0_used: float, c_gamma_given: float | None, hypoid: bool
) -> dict[str, Any]:
    """The ISO block of the geometry summary: :meth:`BevelMesh.to_json` plus k0 by ISO and the method used.

    Parameters
    ----------
    mesh : BevelMesh
        The ISO mesh data.
    k0_method : str
        ``"iso"``, ``"face_width"`` or ``"given"``: how the model's k0 was obtained.
    k0_used : float
        The model's k0 (N/m).
    c_gamma_given : float or None
        A c_γ given in the configuration (N/m²).
    hypoid : bool
        Whether the pair has an offset (the torsional model is then its zero-offset equivalent).

    Returns
    -------
    dict
        Every key of :meth:`BevelMesh.to_json` except ``assumed`` (which becomes ``iso_assumed``),
        ``k0_iso_N_per_m``, ``k0_method``, ``k0_N_per_m_used`` and ``iso_notes``.
    """
    out = mesh.to_json()
    assumed = out.pop("assumed")
    kap = ", ".join(f"{k:.4g}" for k in mesh.kappa.kappa)
    notes = [
        f"ISO 10300-1: k0 = c_γ b_v,eff = {mesh.c_gamma * 1e-9:.4g} N/(mm·µm) × {mesh.b_v_eff * 1e3:.5g} mm"
        f" = {iso_k0(mesh) * 1e-6:.5g} N/µm; the model uses k0 = {k0_used * 1e-6:.5g} N/µm ({k0_method})",
        f"contact ratios ε_vα = {mesh.eps_valpha:.4g}, ε_vβ = {mesh.eps_vbeta:.4g} imply κ_r = {kap} "
        '(geardyn.standards.stiffness; [mesh] kappa = "geometry" uses them)',
    ]
    if hypoid:
        notes.append(
            "hypoid pair: the ISO data include the offset; the torsional model is its zero-offset "
            "equivalent (pitch cones from the ratio, directional radii from r1, r2)"
        )
    return out | {
        "k0_iso_N_per_m": iso_k0(mesh, c_gamma_given if k0_method == "iso" else None),
        "k0_method": k0_method,
        "iso_assumed": assumed,
        "iso_notes": notes,
    }


def iso_rows(s: Mapping[str, Any]) -> list[tuple[str, str, str, str]]:
    """Rows (quantity, value, unit, note) of the ISO block of a geometry summary (:func:`iso_summary`).

    Parameters
    ----------
    s : mapping
        A geometry summary holding the :func:`iso_summary` keys.

    Returns
    -------
    list of (str, str, str, str)
        The table rows, values formatted (``—`` for a missing one).
    """

    def f(x: Any, spec: str = ".5g") -> str:
        return "—" if x is None else format(x, spec)

    k0_note = {"iso": "used as k0", "face_width": "k0 above is c_γ × face width", "given": "k0 above is given"}
    kv_need = next((a["source"] for a in s.get("iso_assumed", []) if a["name"] == "K_v"), "not computed")
    rows = [
        ("contact ratio ε_vα (ISO 10300-1)", f(s["contact_ratio_alpha"], ".4f"), "", "virtual cylindrical gears"),
        ("face contact ratio ε_vβ", f(s["contact_ratio_beta"], ".4f"), "", ""),
        ("total contact ratio ε_vγ", f(s["contact_ratio_total"], ".4f"), "", ""),
        ("effective face width b_v,eff", f(s["b_v_eff_mm"], ".4f"), "mm", ""),
        ("mesh stiffness c_γ (ISO)", f(s["c_gamma_N_per_mm_um"], ".4g"), "N/(mm·µm)", f"C_F = {s['C_F']:.4g}"),
        ("k0 by ISO, c_γ b_v,eff", f(s["k0_iso_N_per_m"] * 1e-6), "N/µm", k0_note.get(s["k0_method"], "")),
    ]
    rows += [
        (f"κ{r} from the contact ratios", f(k, ".4g"), "", f"φ_k{r} = {p:.4g} deg")
        for r, (k, p) in enumerate(zip(s["kappa_from_geometry"], s["phi_k_from_geometry_deg"]), start=1)
    ]
    return rows + [
        ("resonance speed n_E1 (ISO)", f(s["resonance_speed_rpm"], ".6g"), "rpm", ""),
        ("resonance ratio N = n1/n_E1", f(s["resonance_ratio"], ".4f"), "", ""),
        ("dynamic factor K_v (Method B)", f(s["K_v"], ".4f"), "", s["K_v_sector"] or kv_need),
    ]


#: What the simulated dynamic factor of :func:`iso_kv_block` is.
SIMULATED_KV = (
    "(u_max − D)/f_p: the mesh force at the largest compression with the mean stiffness, over the "
    "static force (the simulated counterpart of K_v = F_max/F_static)"
)


def iso_kv_block(
    pair: Any,
    inputs: Mapping[str, float],
    *,
    torque: float,
    rpm: Any,
    u_max: Mapping[str, Any],
    D: float,
    fp: float,
    model_resonance_rpm: float,
) -> dict[str, Any]:
    """The ISO K_v-B curve over a speed grid next to the simulated dynamic factor (JSON-ready).

    Parameters
    ----------
    pair : SpiralBevelGearPair
        The pair.
    inputs : mapping
        Its ISO inputs (:data:`ISO_KEYS`); ``f_pt`` is needed for K_v.
    torque : float
        Pinion torque T1 (N·m) of the sweep.
    rpm : array_like
        Pinion speeds of the sweep (rpm).
    u_max : mapping of str to array_like
        Largest non-dimensional displacement per sweep direction (``"up"``, ``"down"``).
    D, fp : float
        The model's backlash and static load.
    model_resonance_rpm : float
        The speed at which the model's mesh frequency equals its natural frequency (ω = 1).

    Returns
    -------
    dict
        ``rpm``, ``K_v``, ``N``, ``sector`` (per speed), ``resonance_speed_rpm`` (n_E1),
        ``sector_bounds_rpm`` (N = 0.75, 1.25, 1.5), ``model_resonance_rpm``, ``simulated`` (per
        sweep, :data:`SIMULATED_KV`), ``simulated_definition``, ``torque_N_m``, ``standard``.
    """
    rows = [pair_iso_mesh(pair, inputs, rpm=float(r), torque=torque) for r in rpm]
    n_e1 = rows[0].resonance_speed_rpm if rows else float("nan")
    sim = {
        k: [None if not math.isfinite(float(u)) else max(float(u) - D, 0.0) / fp for u in v] for k, v in u_max.items()
    }
    return {
        "standard": "ISO 10300-1:2014 clause 6.3 (ISO 6336-1 Method B sectors)",
        "torque_N_m": float(torque),
        "rpm": [float(r) for r in rpm],
        "K_v": [m.K_v for m in rows],
        "N": [m.N for m in rows],
        "sector": [m.sector for m in rows],
        "resonance_speed_rpm": n_e1,
        "sector_bounds_rpm": {
            "subcritical_end": 0.75 * n_e1,
            "main_resonance_end": 1.25 * n_e1,
            "supercritical_start": 1.5 * n_e1,
        },
        "model_resonance_rpm": float(model_resonance_rpm),
        "simulated": sim,
        "simulated_definition": SIMULATED_KV,
    }
