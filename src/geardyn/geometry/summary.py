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

    def rows_of(*specs: tuple) -> list[tuple[str, str, str, str]]:
        """Rows of (quantity, key, scale, unit, assumed names...): the value times the scale (``—`` when missing),
        angles to 4 decimals, the note naming the assumed inputs among the names."""
        return [
            (label, "—" if (x := summary[key]) is None else format(x * scale, ".4f" if key[-4:] == "_deg" else ".6g"))
            + (unit, note(*names))
            for label, key, scale, unit, *names in specs
        ]

    rows = [("teeth z1 / z2", f"{summary['z1']} / {summary['z2']}", "", "")] + rows_of(
        ("pitch cone angle δ1", "delta1_deg", 1, "deg"),
        ("pitch cone angle δ2", "delta2_deg", 1, "deg"),
        ("mesh point to pinion axis r1", "r1_m", 1e3, "mm", "r1"),
        ("mesh point to gear axis r2", "r2_m", 1e3, "mm", "r2"),
    )
    rows += [
        (f"directional radius R{i}", format(summary[f"R{i}_m"] * 1e3, ".6g"), "mm", f"n·(j{i} × r{i})") for i in "12"
    ]
    rows += rows_of(
        ("equivalent mass m_e", "m_e_kg", 1, "kg"),
        ("face width b", "face_width_m", 1e3, "mm", "face_width"),
    )
    if summary.get("c_gamma_N_per_m2") is not None:
        rows += rows_of(("stiffness per face width c_γ", "c_gamma_N_per_m2", 1e-9, "N/(mm·µm)", "c_gamma"))
    rows += rows_of(
        ("mean mesh stiffness k0", "k0_N_per_m", 1e-6, "N/µm", "k0"),
        ("natural frequency ω_n", "omega_n_rad_s", 1, "rad/s"),
        ("natural frequency f_n", "f_n_Hz", 1, "Hz"),
        ("mean damping ratio ξ0", "xi0", 1, "", "xi0", "c0"),
        ("mean damping c0", "c0_N_s_per_m", 1, "N·s/m", "c0", "xi0"),
        ("half backlash b_n", "b_n_m", 1e3, "mm", "j_n"),
        ("characteristic length b_c", "b_c_m", 1e3, "mm"),
        ("non-dimensional backlash D", "D", 1, ""),
    )
    rows += [
        (
            "pinion hand / loaded flank",
            f"{summary['pinion_hand']} / {summary['pinion_drive_flank']}",
            "",
            note("hand", "drive_side"),
        ),
        ("pinion rotation (viewed from back)", summary["pinion_rotation_from_back"], "", "from hand and flank"),
    ]
    if "rpm" in summary:
        rows += rows_of(
            ("pinion speed n1", "rpm", 1, "rpm", "rpm"),
            ("mesh frequency", "mesh_frequency_Hz", 1, "Hz"),
            ("frequency ratio ω", "omega", 1, ""),
        )
    if summary.get("F_p_N") is not None:
        rows += rows_of(
            ("pinion torque T1", "T1_N_m", 1, "N·m", "torque"),
            ("gear torque T2", "T2_N_m", 1, "N·m", "torque2"),
            ("static mesh force F_p", "F_p_N", 1, "N"),
            *([("non-dimensional load f_p", "fp", 1, "")] if "fp" in summary else []),
        )
        comp = summary["mesh_force_components_N"]
        rows += [
            (
                f"{g} force axial / radial",
                f"{comp[g]['axial']:.5g} / {comp[g]['radial']:.5g}",
                "N",
                "> 0: away from apex / towards axis",
            )
            for g in ("pinion", "gear")
        ]
    if summary.get("contact_ratio_alpha") is not None:
        rows += iso_rows(summary)
    return rows
