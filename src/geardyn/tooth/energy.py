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

with u_f the distance from the root circle to the point where the line of the force crosses the
centre line, S_f = 2 r_f θ_f the root thickness, and each X* = A/θ_f² + B h_f² + C h_f/θ_f + D/θ_f
+ E h_f + F of θ_f (half angle at the root) and h_f = r_f / r_int.

A root crack (after Wu, Zuo & Parey 2008, J. Sound Vib. 317, 608-624, and Chen & Shao 2011, Eng. Fail.
Anal. 18, 2149-2164, with a straight crack): a crack that starts on one flank at the section y_c of half
thickness h_c and reaches the half thickness h_q = (1 − depth) h_c from the centre line makes the band
h_q < x < h_c of every section above y_c carry no load (the crack's shadow along the centre line):
the section keeps the thickness h(y) + h(y) − max(0, min(h(y), h_c) − h_q).  Where h(y) ≤ h_c this is
the published law h + min(h, h_q); in sections thicker than the crack's start the published law would
also drop the material beyond h_c, so that a crack of depth 0 would already soften the tooth.  The
band law is continuous: depth 0 is the healthy tooth.  The fillet foundation term is kept as for the
healthy tooth (as Chen & Shao do).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .geometry import PairGeometry, Section

__all__ = [
    "SAINSOT",
    "ToothCompliance",
    "cantilever_compliance",
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
    """

    bending: np.ndarray
    shear: np.ndarray
    axial: np.ndarray
    fillet: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.bending + self.shear + self.axial + self.fillet


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
        Distance from the root circle to where the force line crosses the centre line (m).
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
    geo: PairGeometry, gear: int, rho: np.ndarray, *, crack_depth: float | None = None
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

    Returns
    -------
    ToothCompliance
    """
    sec = geo.sections[gear]
    blank = geo.gears[gear]
    d, h_l, a1 = load_point(sec, rho)
    w = sec.h + sec.h
    if crack_depth:
        i = sec.crack_start
        h_c = float(sec.h[i])
        lost = np.clip(np.minimum(sec.h[i:], h_c) - (1.0 - crack_depth) * h_c, 0.0, None)
        w = w.copy()
        w[i:] -= lost
    w = np.maximum(w, 1e-3 * float(sec.h.max()))
    kb, ks, ka = cantilever_compliance(sec.y, w, d, h_l, a1, blank.E, blank.nu)
    u_f = d - h_l * np.tan(a1) - sec.r_f
    kf = fillet_compliance(a1, u_f, sec.r_f, sec.theta_f, blank.bore_radius, blank.E)
    return ToothCompliance(bending=kb, shear=ks, axial=ka, fillet=kf)
