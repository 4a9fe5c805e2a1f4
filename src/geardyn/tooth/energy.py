"""Potential-energy compliances of a loaded tooth, per unit face width (m²/N · m = 1/(N/m²)).

A force F along the line of action, applied at the point (y = d, half thickness h_l) of the tooth's
profile at the angle α1 to the perpendicular of the centre line, bends and shears the tooth with
its component F cos α1 and compresses it with F sin α1.  With I(y) = w(y)³/12 and A(y) = w(y) per
unit face width (w the section's thickness), the stored energies give (Yang & Lin 1987; Tian 2004;
Chen & Shao 2011, eqs. 1-9, written over the centre-line coordinate y as in Ma et al. 2015)::

    1/k_b = ∫_{y_f}^{d} [cos α1 (d − y) − sin α1 h_l]² / (E I(y)) dy          bending
    1/k_s = ∫_{y_f}^{d} 1.2 cos² α1 / (G A(y)) dy,   G = E / (2(1 + ν))        shear
    1/k_a = ∫_{y_f}^{d} sin² α1 / (E A(y)) dy                                   axial compression

The Hertzian contact of two tooth faces of width L (Yang & Sun 1985), independent of the load and of
the contact position::

    1/k_h = (2 / (π L)) [(1 − ν1²)/E1 + (1 − ν2²)/E2]   (= 4(1 − ν²)/(π E L) for one material)

The fillet foundation (Sainsot, Velex & Duverger 2004, J. Mech. Des. 126, 748-752, eq. 9 and
Table 1)::

    1/k_f = cos² α1 / (E L) {L* (u_f/S_f)² + M* (u_f/S_f) + P* (1 + Q* tan² α1)}

with u_f the distance from the root circle to the contact point's height on the centre line (the
convention of Ma et al. 2014-2015; the lever of the root moment, to where the force line crosses the
centre line, gives 4-8 % less tooth compliance and departs further from the finite-element check of
``benchmarks/tooth_fe.py``, docs/excitation.md), S_f = 2 r_f θ_f the root thickness, and each
X* = A/θ_f² + B h_f² + C h_f/θ_f + D/θ_f + E h_f + F of θ_f (half angle at the root) and h_f = r_f / r_int.

A root crack (``crack_model="fracture"``, the default): a straight crack at the section y_c where it starts
(the fillet's 30° point, :attr:`Section.crack_start`), of half thickness h_c, running from the loaded flank
into the tooth to the depth a = depth · h_c, perpendicular to the centre line.  It adds the local
flexibility of a cracked section of fracture mechanics (the energy release of an edge crack, Tada, Paris &
Irwin, *The Stress Analysis of Cracks Handbook*, 3rd ed. 2000, and the local flexibility of Dimarogonas &
Paipetis, *Analytical Methods in Rotor Dynamics*, 1983): with the section's width W = 2 h_c, the moment
M = cos α1 (d − y_c) − sin α1 h_l, the normal force N = −sin α1 and the shear force V = cos α1 per unit
load, K_I = √(πa) (6 M / W² F_M(a/W) + N / W F_N(a/W)) and K_II = √(πa) V / W F_V, and

    1/k_crack = (2 / E) ∫_0^a (K_I² + K_II²) da

(plane stress), with Tada's F_M = 1.122 − 1.40ξ + 7.33ξ² − 13.08ξ³ + 14.0ξ⁴ (bending),
F_N = 1.12 − 0.231ξ + 10.55ξ² − 21.72ξ³ + 30.39ξ⁴ (tension), both within 0.5 % for ξ = a/W ≤ 0.6 (a crack
to 95 % of h_c has ξ ≤ 0.475), and F_V = 1.122 (an edge crack in shear, small ξ).  Depth 0 is the healthy
tooth.

The crack starts in the root fillet, a notch: a crack short against the fillet radius ρ_F sees the fillet's
peak stress, not the strip's nominal one.  Its bending factor is the larger of the strip's F_M and the
short crack at a notch of Lukáš (1987), Eng. Fract. Mech. 26, 471-473,

    F_M,notch = 1.12 Y_S / √(1 + 4.5 a / ρ_F)

with Y_S the stress correction factor of ISO 6336-3 (Method B), the fillet's peak stress over the nominal
6M/s_Fn² at the 30° section: Y_S = (1.2 + 0.13 L) q_s^(1/(1.21 + 2.3/L)), L = s_Fn / h_Fe, q_s = s_Fn / (2ρ_F),
s_Fn = W and h_Fe = M / cos α1 the lever of the load point (to where its force line crosses the centre line),
ρ_F the fillet's radius of curvature at the 30° point (:attr:`Section.rho_F`; both agree with ISO 6336-3's
closed forms to 0.3 %).  The notch's share fades as the crack grows past a few tenths of ρ_F; the radial root
(no fillet) keeps the strip's factors.  The finite-element check of ``benchmarks/tooth_fe.py`` compares it with
a slit in a 2-D model (docs/excitation.md): the strip's factors alone give 0.66-0.69 of the FE's stiffness
reduction at 25 % depth, the FE's energy release rate under a load at the tip running 1.45 times the strip's
over the first eighth of h_c, 1.2 times over the second and equal to it from about 40 %; with the notch,
1.04-1.09 of the FE's at 25 % and 50 %.
Section laws without the fracture term miss the local flexibility at the crack's tip: the one below gives
0.59-0.65 of the FE's reduction at 25 % and 0.76-0.77 at 50 %; a limiting line from the crack's tip to the
loaded flank at the tooth's tip (Mohammed, Rantatalo & Aidanpää 2013) 1.16-1.19 and 0.86-0.87, falling
with depth against the FE's (2.2 at 12.5 %, 0.80 at 75 %).

``crack_model="section"`` is the section law after Wu, Zuo & Parey (2008), J. Sound Vib. 317, 608-624,
and Chen & Shao (2011), Eng. Fail. Anal. 18, 2149-2164: the crack makes the band h_q < x < h_c
(h_q = (1 − depth) h_c) of every section above y_c carry no load, the section keeping the thickness
2 h(y) − max(0, min(h(y), h_c) − h_q) (the published law h + min(h, h_q) wherever h ≤ h_c, continuous at
depth 0), the fillet foundation kept as for the healthy tooth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .geometry import PairGeometry, Section

__all__ = [
    "SAINSOT",
    "TADA_BENDING",
    "TADA_SHEAR",
    "TADA_TENSION",
    "ToothCompliance",
    "cantilever_compliance",
    "crack_compliance",
    "fillet_compliance",
    "hertz_compliance",
    "tooth_compliance",
]

#: Sainsot, Velex & Duverger (2004), Table 1: rows L*, M*, P*, Q*; columns A, B, C, D, E, F.
SAINSOT = np.array(
    [
        [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],
        [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],
        [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],
        [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],
    ]
)


@dataclass(frozen=True)
class ToothCompliance:
    """Compliances per unit face width (m·m/N … as 1/(N/m²)) at each contact point of one tooth.

    Attributes
    ----------
    bending, shear, axial, fillet : ndarray
        The four compliances per unit width at each contact point.
    crack : ndarray or float
        The compliance a root crack adds at each contact point (0 for a healthy tooth).
    """

    bending: np.ndarray
    shear: np.ndarray
    axial: np.ndarray
    fillet: np.ndarray
    crack: np.ndarray | float = 0.0

    @property
    def total(self) -> np.ndarray:
        return self.bending + self.shear + self.axial + self.fillet + self.crack


def _cumtrapz(f: np.ndarray, y: np.ndarray) -> np.ndarray:
    out = np.zeros_like(f)
    out[1:] = np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(y))
    return out


def cantilever_compliance(
    y: np.ndarray, w: np.ndarray, d: np.ndarray, h_l: np.ndarray, alpha1: np.ndarray, E: float, nu: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bending, shear and axial compliances (per unit width) of a cantilever of thickness w(y).

    Parameters
    ----------
    y : ndarray
        Centre-line coordinates of the sections, increasing; the beam is clamped at ``y[0]``.
    w : ndarray
        Section thickness at ``y`` (I = w³/12, A = w per unit width).
    d, h_l, alpha1 : ndarray
        Load points: centre-line coordinate, lever of the axial component (distance of the point from
        the centre line), angle of the force to the perpendicular of the centre line.
    E, nu : float
        Young's modulus and Poisson's ratio.

    Returns
    -------
    (bending, shear, axial) : tuple of ndarray
        The integrals of the module docstring, evaluated with the trapezoidal rule on ``y`` (the load
        point's segment included by linear interpolation of the running integrals).
    """
    yy = y - y[0]
    dd = np.asarray(d, dtype=float) - y[0]
    inv_i = 12.0 / w**3
    J0, J1, J2 = (_cumtrapz(inv_i * yy**k, yy) for k in range(3))
    A0 = _cumtrapz(1.0 / w, yy)
    j0, j1, j2, a0 = (np.interp(dd, yy, J) for J in (J0, J1, J2, A0))
    c, s = np.cos(alpha1), np.sin(alpha1)
    G = E / (2.0 * (1.0 + nu))
    bending = (
        c * c * (dd * dd * j0 - 2.0 * dd * j1 + j2) - 2.0 * c * s * h_l * (dd * j0 - j1) + s * s * h_l * h_l * j0
    ) / E
    return bending, 1.2 * c * c * a0 / G, s * s * a0 / E


def hertz_compliance(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """Hertzian compliance per unit width, 1/k_h = (2/π)[(1 − ν1²)/E1 + (1 − ν2²)/E2] (Yang & Sun 1985).

    Parameters
    ----------
    E1, nu1 : float
        Young's modulus and Poisson's ratio of the pinion.
    E2, nu2 : float
        Those of the wheel.

    Returns
    -------
    float
        Compliance per unit width (m²/N).
    """
    return 2.0 / math.pi * ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def fillet_compliance(
    alpha1: np.ndarray, u_f: np.ndarray, r_f: float, theta_f: float, r_int: float, E: float
) -> np.ndarray:
    """Fillet-foundation compliance per unit width (Sainsot, Velex & Duverger 2004, eq. 9).

    Parameters
    ----------
    alpha1 : ndarray
        Angle of the force to the perpendicular of the centre line (rad).
    u_f : ndarray
        Distance from the root circle to the load point's height on the centre line (m).
    r_f : float
        Root radius (m).
    theta_f : float
        Half angle of the tooth at the root circle (rad).
    r_int : float
        Bore radius (m).
    E : float
        Young's modulus (Pa).

    Returns
    -------
    ndarray
        Compliance per unit width (m²/N).
    """
    h = r_f / r_int
    terms = np.array([1.0 / theta_f**2, h * h, h / theta_f, 1.0 / theta_f, h, 1.0])
    L, M, P, Q = SAINSOT @ terms
    S_f = 2.0 * r_f * theta_f
    x = u_f / S_f
    return np.cos(alpha1) ** 2 / E * (L * x * x + M * x + P * (1.0 + Q * np.tan(alpha1) ** 2))


def load_point(sec: Section, rho: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(d, h_l, α1) of the contact point at radius ρ on the tooth (α1 = α_ρ − ψ(ρ))."""
    rho = np.asarray(rho, dtype=float)
    psi = sec.half_angle(rho)
    a_rho = np.arccos(np.clip(sec.r_b / rho, -1.0, 1.0))
    return rho * np.cos(psi), rho * np.sin(psi), a_rho - psi


def tooth_compliance(
    geo: PairGeometry, gear: int, rho: np.ndarray, *, crack_depth: float | None = None, crack_model: str = "fracture"
) -> ToothCompliance:
    """Compliances (per unit face width) of a tooth of ``gear`` loaded at the radii ``rho``.

    Parameters
    ----------
    geo : PairGeometry
        The pair.
    gear : int
        0 pinion, 1 wheel.
    rho : ndarray
        Contact radii.
    crack_depth : float, optional
        Depth of a root crack as a fraction of the half thickness h_c of the section where it starts
        (:attr:`Section.crack_start`); None (or 0) for a healthy tooth.
    crack_model : str
        ``"fracture"`` (the cracked section's local flexibility) or ``"section"`` (the band law).

    Returns
    -------
    ToothCompliance
    """
    sec = geo.sections[gear]
    blank = geo.gears[gear]
    d, h_l, a1 = load_point(sec, rho)
    w = sec.h + sec.h
    i = sec.crack_start
    if crack_model not in ("fracture", "section"):
        raise ValueError(f"crack_model: 'fracture' or 'section', got {crack_model!r}")
    if crack_depth and crack_model == "section":
        h_c = float(sec.h[i])
        lost = np.clip(np.minimum(sec.h[i:], h_c) - (1.0 - crack_depth) * h_c, 0.0, None)
        w = w.copy()
        w[i:] -= lost
    w = np.maximum(w, 1e-3 * float(sec.h.max()))
    kb, ks, ka = cantilever_compliance(sec.y, w, d, h_l, a1, blank.E, blank.nu)
    u_f = d - sec.r_f
    kf = fillet_compliance(a1, u_f, sec.r_f, sec.theta_f, blank.bore_radius, blank.E)
    kc = 0.0
    if crack_depth and crack_model == "fracture":
        kc = crack_compliance(crack_depth, float(sec.y[i]), float(sec.h[i]), d, h_l, a1, blank.E, sec.rho_F)
    return ToothCompliance(bending=kb, shear=ks, axial=ka, fillet=kf, crack=kc)


#: Tada, Paris & Irwin (2000): geometry factors of an edge crack in a strip, ξ = a/W, in increasing powers.
TADA_BENDING = np.array([1.122, -1.40, 7.33, -13.08, 14.0])
TADA_TENSION = np.array([1.12, -0.231, 10.55, -21.72, 30.39])
TADA_SHEAR = np.array([1.122])


def _xi_integral(f: np.ndarray, g: np.ndarray, xi: float) -> float:
    """∫_0^ξ t f(t) g(t) dt of two polynomials (coefficients in increasing powers)."""
    p = np.polynomial.polynomial.polymul(np.polynomial.polynomial.polymul(f, g), [0.0, 1.0])
    return float(np.polynomial.polynomial.polyval(xi, np.polynomial.polynomial.polyint(p)))


def stress_correction(s_Fn: float, h_Fe: np.ndarray, rho_F: float) -> np.ndarray:
    """ISO 6336-3 (Method B) stress correction factor Y_S of a tooth's root fillet.

    Y_S = (1.2 + 0.13 L) q_s^(1 / (1.21 + 2.3 / L)), L = s_Fn / h_Fe, q_s = s_Fn / (2 ρ_F) (held in ISO's range
    1 … 8): the fillet's peak stress over the nominal bending stress 6 M / s_Fn² at the 30° section.

    Parameters
    ----------
    s_Fn : float
        Chord of the 30° section (m).
    h_Fe : ndarray
        Lever of the bending moment at that section: the distance along the centre line from it to where the
        force line crosses the centre line (m, > 0).
    rho_F : float
        Fillet radius at the 30° point (m).

    Returns
    -------
    ndarray
    """
    L = s_Fn / np.asarray(h_Fe, dtype=float)
    q_s = min(max(s_Fn / (2.0 * rho_F), 1.0), 8.0)
    return (1.2 + 0.13 * L) * q_s ** (1.0 / (1.21 + 2.3 / L))


#: Composite Gauss-Legendre rule over the crack depth (panels × points) for the notch's short-crack term.
_PANELS, _GAUSS = 48, np.polynomial.legendre.leggauss(4)
#: Load points per block of that quadrature.
_CHUNK = 4096


def crack_compliance(
    depth: float,
    y_c: float,
    h_c: float,
    d: np.ndarray,
    h_l: np.ndarray,
    alpha1: np.ndarray,
    E: float,
    rho_F: float = 0.0,
) -> np.ndarray:
    """Local flexibility (per unit width) of an edge crack of depth ``depth`` · h_c at the section y_c.

    Parameters
    ----------
    depth : float
        Crack depth as a share of the half thickness h_c of its section (0 … 0.95).
    y_c, h_c : float
        Centre-line coordinate and half thickness of the cracked section (m).
    d, h_l, alpha1 : ndarray
        Load points as :func:`load_point`.
    E : float
        Young's modulus.
    rho_F : float
        Radius of the root fillet where the crack starts (m); 0: no notch (the strip's factors alone).

    Returns
    -------
    ndarray
        1/k_crack of the module docstring (m²/N).
    """
    W = 2.0 * h_c
    xi = depth * h_c / W
    M = np.cos(alpha1) * (d - y_c) - np.sin(alpha1) * h_l
    N, V = -np.sin(alpha1), np.cos(alpha1)
    bm, tn = 6.0 * M / W**2, N / W
    if rho_F > 0 and xi > 0:
        # the bending factor of the crack at the fillet: the larger of the strip's F_M and the short crack at
        # the notch, 1.12 Y_S / sqrt(1 + 4.5 a / rho_F) (Lukas 1987)
        # Y_S's lever h_Fe = M / cos α1: to where the force line crosses the centre line
        shape = np.shape(M)
        h_Fe = np.maximum(np.ravel(M / np.cos(alpha1)), 1e-6 * W)
        K_t = stress_correction(W, h_Fe, rho_F)
        x, w = _GAUSS
        edges = np.linspace(0.0, xi, _PANELS + 1)
        half = 0.5 * (edges[1] - edges[0])
        t = (0.5 * (edges[:-1] + edges[1:])[:, None] + half * x[None, :]).ravel()
        wt = np.tile(half * w, _PANELS) * t  # ∫_0^ξ t g(t) dt = wt @ g
        P = np.polynomial.polynomial.polyval
        f_m, f_n, notch = (
            P(t, TADA_BENDING)[None, :],
            P(t, TADA_TENSION)[None, :],
            1.12 / np.sqrt(1.0 + 4.5 * W * t / rho_F),
        )
        I_mm, I_mn = np.empty(K_t.size), np.empty(K_t.size)
        for i in range(0, K_t.size, _CHUNK):  # in blocks: (points × quadrature nodes) stays small
            F_b = np.maximum(f_m, K_t[i : i + _CHUNK, None] * notch[None, :])
            I_mm[i : i + _CHUNK] = (F_b * F_b) @ wt
            I_mn[i : i + _CHUNK] = (F_b * f_n) @ wt
        I_mm, I_mn = I_mm.reshape(shape), I_mn.reshape(shape)
    else:
        I_mm = _xi_integral(TADA_BENDING, TADA_BENDING, xi)
        I_mn = _xi_integral(TADA_BENDING, TADA_TENSION, xi)
    I_nn = _xi_integral(TADA_TENSION, TADA_TENSION, xi)
    I_vv = _xi_integral(TADA_SHEAR, TADA_SHEAR, xi)
    # ∫_0^a π a (…)² da = π W² ∫_0^ξ t (…)² dt
    return 2.0 * math.pi * W**2 / E * (bm * bm * I_mm + 2 * bm * tn * I_mn + tn * tn * I_nn + (V / W) ** 2 * I_vv)
