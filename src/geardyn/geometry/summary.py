"""The geometry report of a gear pair: a JSON-ready summary and the rows of a readable table."""

from __future__ import annotations

import math
from typing import Any

from .bevel import SpiralBevelGearPair
from .inputs import CONE_DISTANCE_NOTE_TOL
from .iso import iso_rows

__all__ = ["geometry_summary", "summary_rows"]


def geometry_summary(
    pair: SpiralBevelGearPair,
    rpm: float | None = None,
    torque: float | None = None,
    torque2: float | None = None,
    b_c: float | None = None,
) -> dict[str, Any]:
    """The geometry report (JSON-serialisable), keys as in DESIGN §5 plus more.

    Parameters
    ----------
    pair : SpiralBevelGearPair
        The gear pair.
    rpm : float, optional
        Pinion speed (rpm); adds the mesh frequency and ω.
    torque : float, optional
        Pinion torque T1 (N·m); gives ``F_p_N`` (``None`` without it) and f_p.
    torque2 : float, optional
        Gear torque T2 (N·m); default balanced.
    b_c : float, optional
        Characteristic length (m); default b_n.

    Returns
    -------
    dict
        ``delta1_deg``, ``delta2_deg``, ``R1_m``, ``R2_m``, ``m_e_kg``, ``F_p_N``,
        ``omega_n_rad_s``, ``assumed`` (names of assumed inputs), ``assumptions`` (name, value,
        unit, source), and further keys (k0, c0, ξ0, b_n, b_c, radii, hands, rotation, vectors,
        force components; the operating point when given).
    """
    rv = pair.resolved
    mv = pair.mesh_vectors()
    sc = pair.scales(b_c) if (b_c is not None or pair.b_n > 0) else None
    rot1, rot2 = pair.rotation_sense()
    lam = math.cos(pair.alpha_n) * math.cos(pair.beta_m)
    cone1, cone2 = rv.r1 / math.sin(pair.delta1), rv.r2 / math.sin(pair.delta2)
    notes = []
    mismatch = abs(cone1 - cone2) / max(cone1, cone2)
    if mismatch > CONE_DISTANCE_NOTE_TOL:
        notes.append(
            f"r1/sin δ1 = {cone1 * 1e3:.4g} mm and r2/sin δ2 = {cone2 * 1e3:.4g} mm differ by {100 * mismatch:.2g} %: "
            "each gear's mesh-point vector is placed on the common pitch generatrix at its own cone distance"
        )
    from ..plausible import undercut_note

    undercut = undercut_note(pair.z1, pair.delta1, pair.beta_m, pair.alpha_n)
    if undercut:
        notes.append(undercut)
    out: dict[str, Any] = {
        "name": pair.name,
        "z1": pair.z1,
        "z2": pair.z2,
        "ratio": pair.ratio,
        "delta1_deg": math.degrees(pair.delta1),
        "delta2_deg": math.degrees(pair.delta2),
        "Sigma_deg": math.degrees(pair.Sigma),
        "r1_m": rv.r1,
        "r2_m": rv.r2,
        "R1_m": pair.R1,
        "R2_m": pair.R2,
        "projection_cos_alpha_cos_beta": lam,
        "cone_distance_m": [cone1, cone2],
        "m_e_kg": pair.m_e,
        "k0_N_per_m": pair.k0_mean,
        "face_width_m": rv.face_width,
        "c_gamma_N_per_m2": None if math.isnan(rv.c_gamma) else rv.c_gamma,
        "omega_n_rad_s": pair.omega_n,
        "f_n_Hz": pair.omega_n / (2.0 * math.pi),
        "xi0": pair.xi0_mean,
        "c0_N_s_per_m": pair.c0_mean,
        "j_n_m": pair.j_n,
        "b_n_m": pair.b_n,
        "b_c_m": sc.b_c_m if sc else None,
        "D": sc.D if sc else None,
        "pinion_hand": rv.hand,
        "gear_hand": "right" if rv.hand == "left" else "left",
        "pinion_drive_flank": rv.drive_side,
        "gear_drive_flank": "convex" if rv.drive_side == "concave" else "concave",
        "pinion_rotation_from_back": rot1,
        "gear_rotation_from_back": rot2,
        "vectors": mv.to_dict(),
        "force_components_per_unit_normal_force": mv.force_components(),
        "F_p_N": None,
        "assumed": [a.name for a in rv.assumed],
        "assumptions": [a.to_dict() for a in rv.assumed],
        "notes": notes,
    }
    if rpm is not None:
        we = pair.mesh_frequency(rpm)
        out["rpm"] = float(rpm)
        out["mesh_frequency_Hz"] = we / (2.0 * math.pi)
        out["omega"] = we / pair.omega_n
    if torque is not None:
        Fp = pair.static_force(torque, torque2)
        out["T1_N_m"] = float(torque)
        out["T2_N_m"] = float(pair.balanced_torque2(torque) if torque2 is None else torque2)
        out["F_p_N"] = Fp
        if sc is not None:
            out["fp"] = float(sc.force_from_N(Fp))
        out["mesh_force_components_N"] = {
            g: {k: v * Fp for k, v in comp.items()} for g, comp in mv.force_components().items()
        }
    return out


def summary_rows(summary: dict[str, Any]) -> list[tuple[str, str, str, str]]:
    """Rows (quantity, value, unit, note) of a readable geometry table built from :func:`geometry_summary`.

    Values are converted to the units engineers read (mm, deg, Hz, N/µm); assumed inputs carry
    ``assumed (<name>)`` in the note column (their sources are in ``summary["assumptions"]``).

    Parameters
    ----------
    summary : dict
        A summary from :func:`geometry_summary` (or :meth:`LoadedConfig.geometry_summary
        <geardyn.config.LoadedConfig.geometry_summary>`).

    Returns
    -------
    list of tuple of str
        ``(quantity, value, unit, note)`` rows, in the order of a report.
    """
    src = {a["name"] for a in summary.get("assumptions", [])}

    def note(*names: str) -> str:
        hits = [n for n in names if n in src]
        return f"assumed ({', '.join(hits)})" if hits else ""

    def fmt(x: Any, spec: str = ".6g") -> str:
        return "—" if x is None else format(x, spec)

    rows = [
        ("teeth z1 / z2", f"{summary['z1']} / {summary['z2']}", "", ""),
        ("pitch cone angle δ1", fmt(summary["delta1_deg"], ".4f"), "deg", ""),
        ("pitch cone angle δ2", fmt(summary["delta2_deg"], ".4f"), "deg", ""),
        ("mesh point to pinion axis r1", fmt(summary["r1_m"] * 1e3), "mm", note("r1")),
        ("mesh point to gear axis r2", fmt(summary["r2_m"] * 1e3), "mm", note("r2")),
        ("directional radius R1", fmt(summary["R1_m"] * 1e3), "mm", "n·(j1 × r1)"),
        ("directional radius R2", fmt(summary["R2_m"] * 1e3), "mm", "n·(j2 × r2)"),
        ("equivalent mass m_e", fmt(summary["m_e_kg"]), "kg", ""),
        ("face width b", fmt(summary["face_width_m"] * 1e3), "mm", note("face_width")),
    ]
    if summary.get("c_gamma_N_per_m2") is not None:
        rows.append(
            ("stiffness per face width c_γ", fmt(summary["c_gamma_N_per_m2"] * 1e-9), "N/(mm·µm)", note("c_gamma"))
        )
    rows += [
        ("mean mesh stiffness k0", fmt(summary["k0_N_per_m"] * 1e-6), "N/µm", note("k0")),
        ("natural frequency ω_n", fmt(summary["omega_n_rad_s"]), "rad/s", ""),
        ("natural frequency f_n", fmt(summary["f_n_Hz"]), "Hz", ""),
        ("mean damping ratio ξ0", fmt(summary["xi0"]), "", note("xi0", "c0")),
        ("mean damping c0", fmt(summary["c0_N_s_per_m"]), "N·s/m", note("c0", "xi0")),
        ("half backlash b_n", fmt(summary["b_n_m"] * 1e3), "mm", note("j_n")),
        ("characteristic length b_c", fmt(None if summary["b_c_m"] is None else summary["b_c_m"] * 1e3), "mm", ""),
        ("non-dimensional backlash D", fmt(summary["D"]), "", ""),
        (
            "pinion hand / loaded flank",
            f"{summary['pinion_hand']} / {summary['pinion_drive_flank']}",
            "",
            note("hand", "drive_side"),
        ),
        ("pinion rotation (viewed from back)", summary["pinion_rotation_from_back"], "", "from hand and flank"),
    ]
    if "rpm" in summary:
        rows += [
            ("pinion speed n1", fmt(summary["rpm"]), "rpm", note("rpm")),
            ("mesh frequency", fmt(summary["mesh_frequency_Hz"]), "Hz", ""),
            ("frequency ratio ω", fmt(summary["omega"]), "", ""),
        ]
    if summary.get("F_p_N") is not None:
        rows += [
            ("pinion torque T1", fmt(summary["T1_N_m"]), "N·m", note("torque")),
            ("gear torque T2", fmt(summary["T2_N_m"]), "N·m", note("torque2")),
            ("static mesh force F_p", fmt(summary["F_p_N"]), "N", ""),
        ]
        if "fp" in summary:
            rows.append(("non-dimensional load f_p", fmt(summary["fp"]), "", ""))
        comp = summary["mesh_force_components_N"]
        for g in ("pinion", "gear"):
            rows.append(
                (
                    f"{g} force axial / radial",
                    f"{comp[g]['axial']:.5g} / {comp[g]['radial']:.5g}",
                    "N",
                    "> 0: away from apex / towards axis",
                )
            )
    if summary.get("contact_ratio_alpha") is not None:
        rows += iso_rows(summary)
    return rows
