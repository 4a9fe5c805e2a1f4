"""Cylindrical (spur and helical) gear pairs by ISO 6336-1, and the parts ISO 10300-1 shares with it.

ISO 10300-1 rates a bevel or hypoid pair through its *virtual cylindrical gear pair* and then uses
the cylindrical-gear relations of ISO 6336-1 for the contact ratios and for the dynamic factor K_v
by Method B.  This module holds those shared relations and, on top of them, the mesh data of a
cylindrical pair (:func:`cylindrical_mesh`).

Everything is in SI units: metres, radians, newtons; stiffness per unit face width in N/m²
(1 N/(mm·µm) = 1e9 N/m²), pitch deviations in metres.

Relations (ISO 6336-1:2006)

* transverse pressure angle ``tan α_t = tan α_n / cos β``; base helix ``sin β_b = sin β cos α_n``;
* working pressure angle ``inv α_wt = inv α_t + 2 tan α_n (x1 + x2)/(z1 + z2)`` and centre distance
  ``a_w = a cos α_t / cos α_wt``;
* path of contact ``g_α = ½(√(d_a1² − d_b1²) + √(d_a2² − d_b2²)) − a_w sin α_wt``, transverse base
  pitch ``p_bt = π m_n cos α_t / cos β``, ``ε_α = g_α / p_bt``, ``ε_β = b sin β / (π m_n)``;
* single stiffness (Method B, clause 9): ``c′_th = 1/q′`` with
  ``q′ = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1² + C9 x2²``
  (mm·µm/N), ``c′ = c′_th C_M C_R C_B cos β`` with ``C_M = 0.8``, ``C_R = 1`` (solid wheels),
  ``C_B = [1 + 0.5 (1.2 − h_fP/m_n)] [1 − 0.02 (20° − α_n)]``; mesh stiffness
  ``c_γα = c′ (0.75 ε_α + 0.25)``, ``c_γβ = 0.85 c_γα``;
* low load: below ``K_A F_t / b = 100 N/mm`` both stiffnesses are multiplied by
  ``C_F = (K_A F_t / b) / (100 N/mm)``;
* dynamic factor by Method B (clause 6.5): the coefficients ``c_v1 … c_v7`` of the total contact
  ratio (:func:`method_b_coefficients`) and the four speed sectors
  (:func:`dynamic_factor_method_b`).

References
----------
ISO 6336-1:2006, Calculation of load capacity of spur and helical gears — Part 1: Basic
principles, introduction and general influence factors (clauses 6 and 9, Table 8).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from ..errors import ModelError
from ._common import AssumedInput, check_angle, check_positive, defaults, from_fields

__all__ = [
    "C_LOW_LOAD_LINE_LOAD",
    "CylindricalMesh",
    "SECTORS",
    "cylindrical_mesh",
    "dynamic_factor_method_b",
    "involute",
    "low_load_factor",
    "method_b_coefficients",
    "single_stiffness_theoretical",
]

#: Line load K_A F_t / b (N/m) below which ISO 6336-1 / ISO 10300-1 reduce the stiffness (100 N/mm).
C_LOW_LOAD_LINE_LOAD = 100.0e3
#: The speed sectors of Method B, in increasing speed.
SECTORS = ("subcritical", "main resonance", "intermediate", "supercritical")

#: Constants C1 … C9 of the theoretical single stiffness (ISO 6336-1:2006, Table 9), mm·µm/N.
_Q_CONST = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
_TO_SI_STIFFNESS = 1.0e9  # 1 N/(mm·µm) in N/m²


def involute(alpha: float) -> float:
    """Involute function ``inv α = tan α − α`` (α in rad).

    Parameters
    ----------
    alpha : float
        Pressure angle α in rad.

    Returns
    -------
    float
    """
    return math.tan(alpha) - alpha


def _transverse(
    alpha_n: float, beta: float, m_n: float, x1: float, x2: float, z1: float, z2: float
) -> tuple[float, float, float, float]:
    """Transverse pressure angle α_t, base helix angle β_b, transverse module m_t and working pressure angle α_wt
    (inv α_wt = inv α_t + 2 tan α_n (x1 + x2)/(z1 + z2), by Newton iterations from a good start) of a pair."""
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    inv_wt = involute(alpha_t) + 2.0 * math.tan(alpha_n) * (x1 + x2) / (z1 + z2)
    a = (3.0 * inv_wt) ** (1.0 / 3.0) if inv_wt > 0 else 0.0
    for _ in range(50):
        step = (math.tan(a) - a - inv_wt) / (math.tan(a) ** 2)
        a -= step
        if abs(step) < 1e-15:
            break
    return alpha_t, math.asin(math.sin(beta) * math.cos(alpha_n)), m_n / math.cos(beta), a


def low_load_factor(line_load: float | None) -> float:
    """Low-load factor C_F = min(1, (K_A F_t / b) / 100 N/mm).

    Parameters
    ----------
    line_load : float or None
        ``K_A F_t / b`` in N/m; ``None`` (unknown load) gives 1.

    Returns
    -------
    float
        The factor on c′ and c_γ (ISO 6336-1:2006 clause 9; ISO 10300-1:2014 clause 6.3).
    """
    if line_load is None:
        return 1.0
    return min(1.0, line_load / C_LOW_LOAD_LINE_LOAD)


def method_b_coefficients(eps_gamma: float) -> dict[str, float]:
    """Coefficients c_v1 … c_v7 of the dynamic factor by Method B for a total contact ratio ε_γ.

    Parameters
    ----------
    eps_gamma : float
        Total contact ratio ε_γ (> 1).

    Returns
    -------
    dict
        ``{"cv1": …, …, "cv7": …}``.

    Raises
    ------
    ModelError
        If ``eps_gamma`` is not > 1.

    References
    ----------
    ISO 6336-1:2006, Table 8; the same table is used by ISO 10300-1:2014, Table 2.
    """
    e = float(eps_gamma)
    if not (math.isfinite(e) and e > 1.0):
        raise ModelError(f"eps_gamma: Method B needs a total contact ratio > 1, got {eps_gamma!r}")
    if e <= 2.0:
        cv = {"cv1": 0.32, "cv2": 0.34, "cv3": 0.23, "cv4": 0.90, "cv5": 0.47, "cv6": 0.47}
    else:
        cv = {
            "cv1": 0.32,
            "cv2": 0.57 / (e - 0.3),
            "cv3": 0.096 / (e - 1.56),
            "cv4": (0.57 - 0.05 * e) / (e - 1.44),
            "cv5": 0.47,
            "cv6": 0.12 / (e - 1.74),
        }
    if e <= 1.5:
        cv["cv7"] = 0.75
    elif e <= 2.5:
        cv["cv7"] = 0.125 * math.sin(math.pi * (e - 2.0)) + 0.875
    else:
        cv["cv7"] = 1.0
    return cv


def dynamic_factor_method_b(
    N: float, B: float, eps_gamma: float, *, n_sub: float = 0.75, n_main: float = 1.25
) -> tuple[float, str, float]:
    """Dynamic factor K_v by Method B, with f_f,eff = f_p,eff and no tip relief (B_k = 1).

    Parameters
    ----------
    N : float
        Resonance ratio n1 / n_E1 (≥ 0).
    B : float
        Non-dimensional deviation parameter ``c′ f_p,eff / (K_A F_t / b)`` (B_p = B_f).
    eps_gamma : float
        Total contact ratio.
    n_sub, n_main : float
        Upper limits of the subcritical sector and of the main resonance sector: 0.75 and 1.25 for
        bevel gears (ISO 10300-1); ISO 6336-1 uses N_S (0.85 at usual loads) and 1.15.

    Returns
    -------
    K_v : float
        The dynamic factor.
    sector : str
        One of :data:`SECTORS`.
    K : float
        The constant K of the subcritical formula ``K_v = N K + 1`` (always returned).

    References
    ----------
    ISO 6336-1:2006, 6.5.9; ISO 10300-1:2014, 6.3.
    """
    cv = method_b_coefficients(eps_gamma)
    cv12, cv56 = cv["cv1"] + cv["cv2"], cv["cv5"] + cv["cv6"]
    K = cv12 * B + cv["cv3"]
    kv_main = cv12 * B + cv["cv4"] + 1.0
    kv_super = cv56 * B + cv["cv7"]
    if N <= n_sub:
        return N * K + 1.0, SECTORS[0], K
    if N <= n_main:
        return kv_main, SECTORS[1], K
    if N < 1.5:
        return kv_super + (kv_main - kv_super) * (1.5 - N) / (1.5 - n_main), SECTORS[2], K
    return kv_super, SECTORS[3], K


def single_stiffness_theoretical(zn1: float, zn2: float, x1: float = 0.0, x2: float = 0.0) -> float:
    """Theoretical single stiffness c′_th = 1/q′ of ISO 6336-1 Method B, in N/m².

    Parameters
    ----------
    zn1, zn2 : float
        Virtual numbers of teeth in the normal section (z / (cos²β_b cos β)); ``zn2`` of an
        internal gear is negative.
    x1, x2 : float
        Profile shift coefficients.

    Returns
    -------
    float
        c′_th in N/m² (multiply by 1e-9 for N/(mm·µm)).

    References
    ----------
    ISO 6336-1:2006, 9.3.2, Table 9.
    """
    C1, C2, C3, C4, C5, C6, C7, C8, C9 = _Q_CONST
    q = C1 + C2 / zn1 + C3 / zn2 + C4 * x1 + C5 * x1 / zn1 + C6 * x2 + C7 * x2 / zn2 + C8 * x1**2 + C9 * x2**2
    return _TO_SI_STIFFNESS / q


@dataclass(frozen=True)
class CylindricalMesh:
    """Mesh data of a cylindrical gear pair by ISO 6336-1 (SI units).

    Attributes
    ----------
    d1, d2, d_a1, d_a2, d_b1, d_b2 : float
        Reference, tip and base diameters (m).
    a_w : float
        Working centre distance (m).
    alpha_t, alpha_wt, beta_b : float
        Transverse and working transverse pressure angles, base helix angle (rad).
    p_bt, g_alpha : float
        Transverse base pitch and length of path of contact (m).
    eps_alpha, eps_beta, eps_gamma : float
        Transverse, face and total contact ratios.
    C_F : float
        Low-load factor.
    c_prime_th, c_prime, c_gamma_alpha, c_gamma_beta : float
        Theoretical and corrected single stiffness, mesh stiffness (N/m²).
    assumed : tuple of AssumedInput
        The inputs that were defaulted, with their sources.
    """

    d1: float
    d2: float
    d_a1: float
    d_a2: float
    d_b1: float
    d_b2: float
    a_w: float
    alpha_t: float
    alpha_wt: float
    beta_b: float
    p_bt: float
    g_alpha: float
    eps_alpha: float
    eps_beta: float
    eps_gamma: float
    C_F: float
    c_prime_th: float
    c_prime: float
    c_gamma_alpha: float
    c_gamma_beta: float
    assumed: tuple[AssumedInput, ...] = field(default=())

    def to_dict(self) -> dict[str, Any]:
        """All fields as a plain dict (SI units; ``assumed`` as a list of dicts)."""
        out = asdict(self)
        out["assumed"] = [a.to_dict() for a in self.assumed]
        return out


def cylindrical_mesh(
    z1: int,
    z2: int,
    m_n: float,
    alpha_n: float,
    beta: float,
    face_width: float,
    *,
    x1: float | None = None,
    x2: float | None = None,
    h_aP: float | None = None,
    h_fP: float | None = None,
    torque1: float | None = None,
    K_A: float | None = None,
) -> CylindricalMesh:
    """Contact ratios and mesh stiffness of an external cylindrical gear pair (ISO 6336-1).

    Parameters
    ----------
    z1, z2 : int
        Numbers of teeth of pinion and wheel (external gears, z ≥ 5).
    m_n : float
        Normal module (m).
    alpha_n : float
        Normal pressure angle (rad).
    beta : float
        Helix angle at the reference circle (rad), 0 for spur gears.
    face_width : float
        Common face width b (m).
    x1, x2 : float, optional
        Profile shift coefficients (default 0, assumed).
    h_aP, h_fP : float, optional
        Addendum and dedendum of the basic rack in units of m_n (default 1 and 1.25, ISO 53 A).
    torque1 : float, optional
        Pinion torque (N·m) for the low-load factor; without it C_F = 1 (assumed).
    K_A : float, optional
        Application factor (default 1, assumed).

    Returns
    -------
    CylindricalMesh

    Raises
    ------
    ModelError
        For non-physical inputs or a tip that does not reach beyond the base circle.

    References
    ----------
    ISO 6336-1:2006, clauses 6 and 9.
    """
    assumed: list[AssumedInput] = []
    default = defaults(assumed)
    if int(z1) != z1 or int(z2) != z2 or z1 < 5 or z2 < 5:
        raise ModelError(f"z1, z2: must be whole numbers of teeth >= 5, got {z1!r}, {z2!r}")
    m_n = check_positive("m_n", m_n, "m")
    b = check_positive("face_width", face_width, "m")
    alpha_n = check_angle("alpha_n", alpha_n, 10.0, 35.0)
    beta = check_angle("beta", beta, 0.0, 50.0)
    x1 = float(default("x1", 0.0, x1, "", "not given; no profile shift"))
    x2 = float(default("x2", 0.0, x2, "", "not given; no profile shift"))
    h_aP = float(default("h_aP", 1.0, h_aP, "m_n", "not given; basic rack ISO 53 profile A"))
    h_fP = float(default("h_fP", 1.25, h_fP, "m_n", "not given; basic rack ISO 53 profile A"))
    K_A = float(default("K_A", 1.0, K_A, "", "not given; uniform load"))

    alpha_t, beta_b, m_t, alpha_wt = _transverse(alpha_n, beta, m_n, x1, x2, z1, z2)
    d1, d2 = z1 * m_t, z2 * m_t
    d_b1, d_b2 = d1 * math.cos(alpha_t), d2 * math.cos(alpha_t)
    d_a1, d_a2 = d1 + 2.0 * m_n * (h_aP + x1), d2 + 2.0 * m_n * (h_aP + x2)
    a_w = 0.5 * (d1 + d2) * math.cos(alpha_t) / math.cos(alpha_wt)
    if d_a1 <= d_b1 or d_a2 <= d_b2:
        raise ModelError("tip diameters: the tip circle must lie outside the base circle")
    g_alpha = 0.5 * (math.sqrt(d_a1**2 - d_b1**2) + math.sqrt(d_a2**2 - d_b2**2)) - a_w * math.sin(alpha_wt)
    p_bt = math.pi * m_n * math.cos(alpha_t) / math.cos(beta)
    eps_alpha = g_alpha / p_bt
    eps_beta = b * math.sin(beta) / (math.pi * m_n)
    eps_gamma = eps_alpha + eps_beta

    if torque1 is None:
        assumed.append(AssumedInput("torque1", "unknown", "N*m", "not given; C_F = 1 (line load taken >= 100 N/mm)"))
        C_F = 1.0
    else:
        F_t = 2.0 * check_positive("torque1", torque1, "N*m") / d1
        C_F = low_load_factor(K_A * F_t / b)
    zn1 = z1 / (math.cos(beta_b) ** 2 * math.cos(beta))
    zn2 = z2 / (math.cos(beta_b) ** 2 * math.cos(beta))
    c_prime_th = single_stiffness_theoretical(zn1, zn2, x1, x2)
    C_M, C_R = 0.8, 1.0
    C_B = (1.0 + 0.5 * (1.2 - h_fP)) * (1.0 - 0.02 * (20.0 - math.degrees(alpha_n)))
    c_prime = c_prime_th * C_M * C_R * C_B * math.cos(beta) * C_F
    c_gamma_alpha = c_prime * (0.75 * eps_alpha + 0.25)
    c_gamma_beta, assumed = 0.85 * c_gamma_alpha, tuple(assumed)
    return from_fields(CylindricalMesh, locals())
