"""Bevel and hypoid gear pairs by ISO 10300-1: virtual cylindrical gears, contact ratios, c_γ, K_v.

From the mean-point geometry of ISO 23509 (teeth, mean normal module, mean spiral angles, design
pressure angle, shaft angle, face width, mean addenda; for hypoids also the offset angles) this
module builds the virtual cylindrical gear pair of ISO 10300-1 Annex A (Method B1) and derives
from it the contact ratios, the mean mesh stiffness, the resonance speed and the dynamic factor
K_v by Method B, plus the stiffness harmonics of :mod:`geardyn.standards.stiffness`.

Formulas (ISO 10300-1:2014/2023 Annex A and clause 6; SI units, angles in rad)

* pitch cones (no offset): ``tan δ1 = sin Σ / (cos Σ + z2/z1)``, ``δ2 = Σ − δ1``; mean pitch
  diameters ``d_m = z m_mn / cos β_m``;
* pressure angles (ISO 23509, f_αlim = 1): drive ``α_nD = α_d + α_lim``, coast ``α_nC = α_d − α_lim``;
  effective pressure angle ``α_e = α_d`` on both flanks;
* virtual diameters ``d_v = d_m / cos δ``, ``a_v = (d_v1 + d_v2)/2``, tips ``d_va = d_v + 2 h_am``;
* helix ``β_v = (β_m1 + β_m2)/2``, transverse pressure angle ``tan α_vet = tan α_e / cos β_v``,
  base diameters ``d_vb = d_v cos α_vet``, base helix ``sin β_vb = sin β_v cos α_e``,
  transverse module ``m_vt = m_mn / cos β_v``, virtual teeth ``z_v = d_v / m_vt``;
* transverse base pitch ``p_vet = π m_mn cos α_vet / cos β_v``, path of contact
  ``g_vα = ½[(√(d_va1² − d_vb1²) − d_v1 sin α_vet) + (√(d_va2² − d_vb2²) − d_v2 sin α_vet)]``,
  ``ε_vα = g_vα / p_vet``;
* face width (A.19–A.22): ``θ_mp = atan(sin δ2 tan ζ_m)``, ``γ′ = θ_mp − ζ_mp/2``,
  ``b_v,eff = [b2,eff / cos(ζ_mp/2) − g_vα cos α_vet tan(ζ_mp/2)] / [1 − tan γ′ tan(ζ_mp/2)]``,
  ``b_v = b · b_v,eff / b2,eff``; without offset ``b_v,eff = b2,eff`` (default 0.85 b) and ``b_v = b``;
* ``ε_vβ = b_v,eff sin β_v / (π m_mn)``, ``ε_vγ = ε_vα + ε_vβ``;
* forces: ``F_mt1 = 2 T1 / d_m1``, ``F_vmt = F_mt1 cos β_v / cos β_m1``;
* stiffness (clause 6.3): ``c′ = 14 C_F``, ``c_γ = 20 C_F`` N/(mm·µm), with the low-load factor
  ``C_F = min(1, (F_vmt K_A / b_v,eff) / 100 N/mm)``;
* reduced mass per unit face width of the virtual pair
  ``m*_i = (π/8) ρ d_vi² / cos² α_n`` (α_n the mean of α_nD and α_nC), ``m_red = m*_1 m*_2/(m*_1 + m*_2)``;
  resonance speed ``n_E1 = (30/(π z1)) √(c_γ / m_red)`` (rpm with c_γ in N/m², m_red in kg/m),
  ``N = n1 / n_E1``;
* effective pitch deviation ``f_p,eff = f_pt − y_α`` with ``y_α = min(0.075 f_pt, 3 µm)`` (case
  hardened or nitrided steel), ``B = b_v,eff f_p,eff c′ / (F_vmt K_A)``, and K_v from the four
  sectors of :func:`~geardyn.standards.iso6336.dynamic_factor_method_b` (subcritical N ≤ 0.75,
  main resonance 0.75 < N ≤ 1.25, intermediate 1.25 < N < 1.5, supercritical N ≥ 1.5).

The reduced mass uses the diameters of the virtual cylindrical gears: with them the dynamic factors
printed in ISO/TR 10300-30 for sample 1 (K_v = 1.020) and sample 2 (K_v = 1.016) are reproduced;
with the bevel mean diameters d_m they are not (1.018 and 1.014).

References
----------
ISO 10300-1:2014 (and :2023), Calculation of load capacity of bevel gears — Part 1: Introduction
and general influence factors, clause 6 and Annex A.
ISO 23509:2016, Bevel and hypoid gear geometry.
ISO/TR 10300-30:2017 (and :2024), Sample calculations (samples 1 to 3).
ISO 6336-1:2006 (the cylindrical-gear relations and Table 8, see :mod:`geardyn.standards.iso6336`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from ..errors import ModelError
from ._common import AssumedInput, check_angle, check_positive, defaults, from_fields
from .iso6336 import dynamic_factor_method_b, low_load_factor
from .stiffness import StiffnessHarmonics, mesh_stiffness_harmonics

__all__ = [
    "BevelMesh",
    "C_GAMMA_BEVEL",
    "C_PRIME_BEVEL",
    "DEFAULT_DENSITY",
    "DEFAULT_EFFECTIVE_FACE_WIDTH_RATIO",
    "bevel_mesh",
]

#: Mean mesh stiffness per unit face width of bevel gears at line loads >= 100 N/mm (N/m²).
C_GAMMA_BEVEL = 20.0e9
#: Single stiffness of bevel gears at line loads >= 100 N/mm (N/m²).
C_PRIME_BEVEL = 14.0e9
#: Density of steel used when none is given (kg/m³), the value of ISO/TR 10300-30.
DEFAULT_DENSITY = 7860.0
#: Effective face width b2,eff / b used when none is given (ISO 10300-1: 85 % of the face width).
DEFAULT_EFFECTIVE_FACE_WIDTH_RATIO = 0.85
_RUNNING_IN_MAX = 3.0e-6


@dataclass(frozen=True)
class BevelMesh:
    """ISO 10300-1 virtual cylindrical gear pair and mesh data of a bevel or hypoid pair (SI units).

    Lengths in m, angles in rad, forces in N, stiffness per face width in N/m², mass per face width
    in kg/m, speeds in rad/s; ``None`` where the operating point (torque, speed, pitch deviation)
    needed for a value was not given.  :meth:`to_json` gives the engineering units of the CLI.
    The formulas are those of the module docstring.

    Attributes
    ----------
    u : float
        Gear ratio z2/z1.
    delta1, delta2 : float
        Pitch angles of pinion and wheel.
    d_m1, d_m2 : float
        Mean pitch diameters.
    alpha_nD, alpha_nC, alpha_e : float
        Generated pressure angles of the drive and coast flanks, effective pressure angle.
    d_v1, d_v2 : float
        Reference diameters of the virtual cylindrical gears.
    a_v : float
        Centre distance of the virtual pair.
    d_va1, d_va2, d_vb1, d_vb2 : float
        Tip and base diameters of the virtual gears.
    beta_v, beta_vb : float
        Helix angle and base helix angle of the virtual gears.
    alpha_vet : float
        Transverse pressure angle of the virtual gears.
    m_vt : float
        Transverse module of the virtual gears.
    z_v1, z_v2 : float
        Numbers of teeth of the virtual gears.
    p_vet : float
        Transverse base pitch.
    g_valpha : float
        Length of path of contact.
    eps_valpha, eps_vbeta, eps_vgamma : float
        Transverse, face and total contact ratios ε_vα, ε_vβ, ε_vγ.
    b2_eff : float
        Effective face width of the wheel.
    b_v_eff, b_v : float
        Effective and total face widths of the virtual pair.
    C_F : float
        Low-load factor (1 without a torque).
    c_prime, c_gamma : float
        Single stiffness c′ and mesh stiffness c_γ (N/m²).
    m_red : float
        Reduced mass per unit face width of the virtual pair (kg/m).
    omega_E1 : float
        Resonance speed of the pinion (rad/s).
    F_mt1, F_vmt : float or None
        Nominal tangential force at the mean diameter and its virtual-pair value (need ``torque1``).
    N : float or None
        Resonance ratio n1/n_E1 (needs ``speed1``).
    K : float or None
        Constant K of the subcritical formula K_v = N K + 1.
    K_v : float or None
        Dynamic factor by Method B (needs torque, speed and pitch deviation).
    sector : str or None
        Speed sector of Method B (one of :data:`~geardyn.standards.iso6336.SECTORS`).
    kappa : StiffnessHarmonics
        Stiffness harmonics implied by the contact ratios (:mod:`geardyn.standards.stiffness`).
    assumed : tuple of AssumedInput
        The inputs that were defaulted, with their sources.

    References
    ----------
    ISO 10300-1:2014, clause 6 and Annex A; ISO 23509:2016; ISO/TR 10300-30:2017 (sample
    calculations); ISO 6336-1:2006, 6.5.9 (K_v by Method B).
    """

    u: float
    delta1: float
    delta2: float
    d_m1: float
    d_m2: float
    alpha_nD: float
    alpha_nC: float
    alpha_e: float
    d_v1: float
    d_v2: float
    a_v: float
    d_va1: float
    d_va2: float
    d_vb1: float
    d_vb2: float
    beta_v: float
    beta_vb: float
    alpha_vet: float
    m_vt: float
    z_v1: float
    z_v2: float
    p_vet: float
    g_valpha: float
    eps_valpha: float
    b2_eff: float
    b_v_eff: float
    b_v: float
    eps_vbeta: float
    eps_vgamma: float
    C_F: float
    c_prime: float
    c_gamma: float
    m_red: float
    omega_E1: float
    F_mt1: float | None
    F_vmt: float | None
    N: float | None
    K: float | None
    K_v: float | None
    sector: str | None
    kappa: StiffnessHarmonics
    assumed: tuple[AssumedInput, ...] = field(default=())

    @property
    def resonance_speed_rpm(self) -> float:
        """Resonance speed of the pinion n_E1 in rpm."""
        return self.omega_E1 * 30.0 / math.pi

    def to_dict(self) -> dict[str, Any]:
        """All fields in SI units as a plain dict."""
        out = asdict(self)
        out["kappa"] = self.kappa.to_dict()
        out["assumed"] = [a.to_dict() for a in self.assumed]
        return out

    def to_json(self) -> dict[str, Any]:
        """The summary the ``geometry --json`` command reports, in engineering units.

        Returns
        -------
        dict
            Keys ``contact_ratio_alpha``, ``contact_ratio_beta``, ``contact_ratio_total``,
            ``b_v_eff_mm``, ``c_gamma_N_per_mm_um``, ``c_prime_N_per_mm_um``,
            ``resonance_speed_rpm``, ``resonance_ratio``, ``K_v``, ``K_v_sector``,
            ``kappa_from_geometry``, ``phi_k_from_geometry_deg``, the virtual gear data in mm and
            degrees, and ``assumed``.
        """
        mm, deg = 1e3, math.degrees
        return {
            "contact_ratio_alpha": self.eps_valpha,
            "contact_ratio_beta": self.eps_vbeta,
            "contact_ratio_total": self.eps_vgamma,
            "b_v_eff_mm": self.b_v_eff * mm,
            "b_v_mm": self.b_v * mm,
            "c_gamma_N_per_mm_um": self.c_gamma * 1e-9,
            "c_prime_N_per_mm_um": self.c_prime * 1e-9,
            "C_F": self.C_F,
            "m_red_kg_per_mm": self.m_red * 1e-3,
            "resonance_speed_rpm": self.resonance_speed_rpm,
            "resonance_ratio": self.N,
            "K": self.K,
            "K_v": self.K_v,
            "K_v_sector": self.sector,
            "kappa_from_geometry": list(self.kappa.kappa),
            "phi_k_from_geometry_deg": [deg(p) for p in self.kappa.phi],
            "virtual_gears": {
                "d_v_mm": [self.d_v1 * mm, self.d_v2 * mm],
                "d_va_mm": [self.d_va1 * mm, self.d_va2 * mm],
                "d_vb_mm": [self.d_vb1 * mm, self.d_vb2 * mm],
                "a_v_mm": self.a_v * mm,
                "z_v": [self.z_v1, self.z_v2],
                "m_vt_mm": self.m_vt * mm,
                "beta_v_deg": deg(self.beta_v),
                "beta_vb_deg": deg(self.beta_vb),
                "alpha_vet_deg": deg(self.alpha_vet),
                "p_vet_mm": self.p_vet * mm,
                "g_valpha_mm": self.g_valpha * mm,
            },
            "assumed": [a.to_dict() for a in self.assumed],
        }


def bevel_mesh(
    z1: int,
    z2: int,
    m_mn: float,
    beta_m1: float,
    alpha_n: float,
    Sigma: float,
    face_width: float,
    *,
    beta_m2: float | None = None,
    alpha_lim: float | None = None,
    d_m1: float | None = None,
    d_m2: float | None = None,
    delta1: float | None = None,
    delta2: float | None = None,
    h_am1: float | None = None,
    h_am2: float | None = None,
    x_hm1: float | None = None,
    offset: float | None = None,
    zeta_mp: float | None = None,
    zeta_m: float | None = None,
    b2_eff: float | None = None,
    torque1: float | None = None,
    speed1: float | None = None,
    K_A: float | None = None,
    f_pt: float | None = None,
    density: float | None = None,
    n_harmonics: int = 3,
) -> BevelMesh:
    """Virtual cylindrical gears, contact ratios, mesh stiffness and K_v of a bevel or hypoid pair.

    Parameters
    ----------
    z1, z2 : int
        Numbers of teeth of pinion and wheel.
    m_mn : float
        Mean normal module (m).
    beta_m1 : float
        Mean spiral angle of the pinion (rad).
    alpha_n : float
        Design (nominal) normal pressure angle α_d of both flanks (rad); for a spiral bevel pair
        without offset and α_lim = 0 this is the normal pressure angle.
    Sigma : float
        Shaft angle (rad).
    face_width : float
        Face width b (m).
    beta_m2 : float, optional
        Mean spiral angle of the wheel (default β_m1: no offset).
    alpha_lim : float, optional
        Limit pressure angle of ISO 23509 (default 0).
    d_m1, d_m2, delta1, delta2 : float, optional
        Mean pitch diameters (m) and pitch angles (rad) of ISO 23509; computed for pairs without
        offset when not given; required for hypoids.
    h_am1, h_am2 : float, optional
        Mean addenda (m); default ``m_mn (1 ± x_hm1)``.
    x_hm1 : float, optional
        Profile shift coefficient of the pinion (default 0; the wheel has −x_hm1).
    offset : float, optional
        Hypoid offset a (m, default 0).
    zeta_mp, zeta_m : float, optional
        Offset angles in the pitch plane and in the axial plane (rad); required for hypoids.
    b2_eff : float, optional
        Effective face width of the wheel (m, default :data:`DEFAULT_EFFECTIVE_FACE_WIDTH_RATIO` × b).
    torque1 : float, optional
        Pinion torque T1 (N·m); needed for C_F and K_v.
    speed1 : float, optional
        Pinion speed (rad/s); needed for N and K_v.
    K_A : float, optional
        Application factor (default 1).
    f_pt : float, optional
        Single pitch deviation used for K_v (m), the larger of pinion and wheel; needed for K_v.
    density : float, optional
        Density of the gear material (kg/m³, default :data:`DEFAULT_DENSITY`).
    n_harmonics : int, optional
        Number of stiffness harmonics κ_r (default 3).

    Returns
    -------
    BevelMesh

    Raises
    ------
    ModelError
        For invalid inputs, a hypoid without its offset angles or mean-point data, or a
        transverse contact ratio ≤ 1.

    References
    ----------
    ISO 10300-1:2014, clause 6 and Annex A; ISO 23509:2016; ISO/TR 10300-30:2017.
    """
    assumed: list[AssumedInput] = []
    default = defaults(assumed)

    def positive(name: str, value: float, given: float | None, unit: str, source: str) -> float:
        return check_positive(name, default(name, value, given, unit, source), unit)

    if int(z1) != z1 or int(z2) != z2 or z1 < 5 or z2 < z1:
        raise ModelError(f"z1, z2: must be whole numbers of teeth with 5 <= z1 <= z2, got {z1!r}, {z2!r}")
    m_mn = check_positive("m_mn", m_mn, "m")
    b = check_positive("face_width", face_width, "m")
    beta_m1 = check_angle("beta_m1", beta_m1, 0.0, 70.0)
    alpha_d = check_angle("alpha_n", alpha_n, 10.0, 35.0)
    Sigma = check_angle("Sigma", Sigma, 10.0, 170.0)
    a = float(default("offset", 0.0, offset, "m", "not given; no hypoid offset (spiral bevel pair)"))
    hypoid = a != 0.0
    if hypoid:
        given = locals()
        missing = [n for n in ("beta_m2", "d_m1", "d_m2", "delta1", "delta2", "zeta_mp", "zeta_m") if given[n] is None]
        if missing:
            raise ModelError(
                "hypoid pair (offset != 0): give the ISO 23509 mean-point data "
                + ", ".join(missing)
                + " (the hypoid geometry itself is not solved here)"
            )
    src_no_offset = "not given; pair without offset"
    beta_m2 = check_angle(
        "beta_m2", default("beta_m2", beta_m1, beta_m2, "rad", src_no_offset + ": beta_m2 = beta_m1"), 0.0, 70.0
    )
    alpha_lim = float(
        default("alpha_lim", 0.0, alpha_lim, "rad", "not given; no limit pressure angle (ISO 23509, f_alim = 1)")
    )
    zeta_mp = float(default("zeta_mp", 0.0, zeta_mp, "rad", src_no_offset))
    zeta_m = float(default("zeta_m", 0.0, zeta_m, "rad", src_no_offset))
    u = z2 / z1
    d1 = math.atan2(math.sin(Sigma), math.cos(Sigma) + u)
    delta1 = float(default("delta1", d1, delta1, "rad", "not given; tan delta1 = sin Sigma / (cos Sigma + z2/z1)"))
    delta2 = float(default("delta2", Sigma - delta1, delta2, "rad", "not given; delta2 = Sigma - delta1"))
    d_m1 = positive("d_m1", z1 * m_mn / math.cos(beta_m1), d_m1, "m", "not given; d_m1 = z1 m_mn / cos beta_m1")
    d_m2 = positive("d_m2", z2 * m_mn / math.cos(beta_m2), d_m2, "m", "not given; d_m2 = z2 m_mn / cos beta_m2")
    x = (
        float(default("x_hm1", 0.0, x_hm1, "", "not given; no profile shift"))
        if h_am1 is None or h_am2 is None
        else 0.0
    )
    h_am1 = positive("h_am1", m_mn * (1.0 + x), h_am1, "m", "not given; h_am1 = m_mn (1 + x_hm1)")
    h_am2 = positive("h_am2", m_mn * (1.0 - x), h_am2, "m", "not given; h_am2 = m_mn (1 - x_hm1)")
    b2_eff = positive(
        "b2_eff", DEFAULT_EFFECTIVE_FACE_WIDTH_RATIO * b, b2_eff, "m", "not given; b2,eff = 0.85 b (ISO 10300-1)"
    )
    rho = positive("density", DEFAULT_DENSITY, density, "kg/m^3", "not given; steel (ISO/TR 10300-30)")
    K_A = positive("K_A", 1.0, K_A, "", "not given; uniform load")

    alpha_nD, alpha_nC, alpha_e = alpha_d + alpha_lim, alpha_d - alpha_lim, alpha_d
    d_v1, d_v2 = d_m1 / math.cos(delta1), d_m2 / math.cos(delta2)
    if d_v1 <= 0 or d_v2 <= 0:
        raise ModelError("delta1, delta2: pitch angles must be below 90 deg for the virtual gears")
    beta_v = 0.5 * (beta_m1 + beta_m2)
    alpha_vet = math.atan(math.tan(alpha_e) / math.cos(beta_v))
    beta_vb = math.asin(math.sin(beta_v) * math.cos(alpha_e))
    m_vt = m_mn / math.cos(beta_v)
    d_vb1, d_vb2 = d_v1 * math.cos(alpha_vet), d_v2 * math.cos(alpha_vet)
    d_va1, d_va2 = d_v1 + 2.0 * h_am1, d_v2 + 2.0 * h_am2
    p_vet = math.pi * m_mn * math.cos(alpha_vet) / math.cos(beta_v)
    g_valpha = 0.5 * (
        (math.sqrt(d_va1**2 - d_vb1**2) - d_v1 * math.sin(alpha_vet))
        + (math.sqrt(d_va2**2 - d_vb2**2) - d_v2 * math.sin(alpha_vet))
    )
    eps_valpha = g_valpha / p_vet
    if not eps_valpha > 1.0:
        raise ModelError(
            f"transverse contact ratio of the virtual gears eps_va = {eps_valpha:.4g} must be > 1 (ISO 10300-1)"
        )
    th_mp = math.atan(math.sin(delta2) * math.tan(zeta_m))
    gamma_p = th_mp - 0.5 * zeta_mp
    t = math.tan(0.5 * zeta_mp)
    b_v_eff = (b2_eff / math.cos(0.5 * zeta_mp) - g_valpha * math.cos(alpha_vet) * t) / (1.0 - math.tan(gamma_p) * t)
    b_v = b * b_v_eff / b2_eff
    eps_vbeta = b_v_eff * math.sin(beta_v) / (math.pi * m_mn)
    eps_vgamma = eps_valpha + eps_vbeta

    F_mt1 = F_vmt = None
    if torque1 is None:
        assumed.append(
            AssumedInput("torque1", "unknown", "N*m", "not given; C_F = 1 (line load taken >= 100 N/mm); no K_v")
        )
        C_F = 1.0
    else:
        F_mt1 = 2.0 * check_positive("torque1", torque1, "N*m") / d_m1
        F_vmt = F_mt1 * math.cos(beta_v) / math.cos(beta_m1)
        C_F = low_load_factor(F_vmt * K_A / b_v_eff)
    c_prime, c_gamma = C_PRIME_BEVEL * C_F, C_GAMMA_BEVEL * C_F
    alpha_mean = 0.5 * (alpha_nD + alpha_nC)
    m1, m2 = (math.pi / 8.0 * rho * d**2 / math.cos(alpha_mean) ** 2 for d in (d_v1, d_v2))
    m_red = m1 * m2 / (m1 + m2)
    omega_E1 = math.sqrt(c_gamma / m_red) / z1  # pinion speed whose mesh frequency z1 omega1 is sqrt(c/m)

    N = K = K_v = None
    sector = None
    if speed1 is not None:
        N = check_positive("speed1", speed1, "rad/s") / omega_E1
    if N is not None and F_vmt is not None and f_pt is not None:
        fpt = check_positive("f_pt", f_pt, "m")
        y_a = min(0.075 * fpt, _RUNNING_IN_MAX)
        assumed.append(
            AssumedInput(
                "y_alpha", y_a, "m", "running-in allowance of case hardened or nitrided steel: min(0.075 f_pt, 3 um)"
            )
        )
        B = b_v_eff * (fpt - y_a) * c_prime / (F_vmt * K_A)
        K_v, sector, K = dynamic_factor_method_b(N, B, eps_vgamma, n_sub=0.75, n_main=1.25)
    else:
        need = [n for n, v in (("torque1", torque1), ("speed1", speed1), ("f_pt", f_pt)) if v is None]
        assumed.append(AssumedInput("K_v", "not computed", "", "needs " + ", ".join(need)))

    a_v, z_v1, z_v2 = 0.5 * (d_v1 + d_v2), d_v1 / m_vt, d_v2 / m_vt
    kappa, assumed = mesh_stiffness_harmonics(eps_valpha, eps_vbeta, n_harmonics), tuple(assumed)
    return from_fields(BevelMesh, locals())
