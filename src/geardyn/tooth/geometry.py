"""Involute-and-fillet geometry of a cylindrical gear pair for the potential-energy stiffness.

Everything is in SI units (m, rad, Pa).  The tooth is described in the transverse plane of each gear
as a cantilever along its centre line (coordinate ``y`` measured from the gear centre) with the half
thickness ``h(y)`` of its profile:

* the involute, at the half angle ``ψ(ρ) = π/(2z) + 2 x tan α_t / z + inv α_t − inv α_ρ`` with
  ``cos α_ρ = r_b/ρ``, so ``y = ρ cos ψ``, ``h = ρ sin ψ`` (e.g. Litvin & Fuentes, *Gear Geometry and
  Applied Theory*, 2004), from the radius r_L where the straight flank of the generating rack stops
  cutting it;
* below r_L, down to the root circle r_f, the root fillet as it is cut (``root="trochoid"``, the
  default): the envelope of the rack's tip rounding of radius ρ_fP (ISO 53 basic rack profiles A–D)
  rolling on the generating pitch line at the profile shift x m.  The rack point at the centre of the
  rounding, (X_c, Y_c) = ((π/4 − h_fP tan α − ρ_fP tan(π/4 − α/2)) m, r + x m − (h_fP − ρ_fP) m), moves
  to X_c + r φ while the gear turns by φ; the point it cuts lies on the rounding along the line from
  the pitch point (0, r) through the centre (the normal of an enveloping surface passes through the
  instantaneous centre of the relative motion), turned back by φ into the gear.  When the straight
  flank would generate the involute below the base circle (t_L = r sin α − u_T / sin α < 0, u_T the
  depth of the rounding's tangent point below the pitch line) the tooth is undercut: the trochoid cuts
  into the involute above r_b and the profile is the thinner of the two.  The root half angle θ_f is
  that of the fillet on the root circle;
* or (``root="radial"``) below the base circle a radial straight line at the base-circle half angle
  ψ_b (the model of Liang, Zuo & Pandey 2014 and Ma et al. 2015 for z < 42 at α = 20°), the earlier
  model, kept for comparison;
* the body under the root circle is the fillet foundation of Sainsot, Velex & Duverger (2004).

A helical pair's fillet is that of its transverse section, with the rack's tip radius taken as ρ_fP
m_n in the transverse plane (the transverse section of the rounding is an ellipse of that height).

The pair (:class:`PairGeometry`) adds the working centre distance and pressure angle (ISO 21771 /
ISO 6336-1, from the profile shifts), the line of action T1T2, the start A and end E of the active
contact and the transverse base pitch.  A helical pair uses its transverse profile (m_t, α_t) in
every slice of the face width.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..model import _whole_number
from ..standards.iso6336 import _transverse, involute

__all__ = ["ISO53_RACKS", "GearBlank", "PairGeometry", "Section", "pair_geometry", "trochoid"]

#: Points of the tabulated tooth section (from the root circle to the tip).
SECTION_POINTS = 801


@dataclass(frozen=True)
class GearBlank:
    """The data of one gear of the pair.

    Attributes
    ----------
    z : float
        Number of teeth of the tooth shape (the virtual number z_v of a bevel gear's virtual cylindrical gear).
    x : float
        Profile shift coefficient.
    bore_radius : float
        Radius of the bore (m), for the fillet foundation (h_f = r_f / r_int of Sainsot et al.).
    E, nu : float
        Young's modulus (Pa) and Poisson's ratio.
    teeth : int
        Number of teeth of the gear itself (tooth indices, shaft orders); ``round(z)`` when not given.
    """

    z: float
    x: float = 0.0
    bore_radius: float | None = None
    E: float = 206.0e9
    nu: float = 0.3
    #: Number of teeth of the gear itself (tooth indices, shaft orders); ``z`` unless a virtual gear.
    teeth: int = 0

    def __post_init__(self) -> None:
        if not self.teeth:
            object.__setattr__(self, "teeth", int(round(self.z)))


@dataclass(frozen=True)
class Section:
    """The tooth of one gear as a cantilever: centre-line coordinate ``y`` and half thickness ``h``.

    Attributes
    ----------
    y, h : ndarray
        Centre-line coordinate (m) and half thickness (m), root to tip.
    r_f, r_b, r_a : float
        Root, base and tip radii (m).
    theta_f : float
        Half angle at the root circle (rad).
    psi0 : float
        π/(2z) + 2 x tan α_t / z + inv α_t.
    crack_start : int
        Index of the section where a root crack starts: the point of the fillet whose tangent makes
        30° with the centre line (the critical section of ISO 6336-3); the root circle for the
        radial model.
    r_L : float
        Radius where the involute starts (the form radius of the generated flank).
    rho_F : float
        Radius of curvature of the root fillet at the crack's start (m); 0 for the radial model.
    """

    #: Centre-line coordinate from the gear centre (m), increasing from the root to the tip.
    y: np.ndarray
    #: Half thickness (m).
    h: np.ndarray
    #: Root radius r_f, base radius r_b, tip radius r_a (m).
    r_f: float
    r_b: float
    r_a: float
    #: Half angle of the tooth at the root circle (rad), θ_f of Sainsot et al.
    theta_f: float
    #: Half angle at the reference circle parameters: π/(2z) + 2 x tan α_t / z + inv α_t.
    psi0: float
    #: Index of the section where a root crack starts.
    crack_start: int = 0
    #: Radius where the involute starts.
    r_L: float = 0.0
    #: Radius of curvature of the root fillet at the crack's start (m); 0 for the radial model (no fillet).
    rho_F: float = 0.0

    def half_angle(self, rho: np.ndarray) -> np.ndarray:
        """Half angle ψ(ρ) of the tooth at radius ρ (≥ r_b: involute; below: constant ψ_b)."""
        return _half_angle(self.psi0, self.r_b, rho)


def _half_angle(psi0: float, r_b: float, rho: np.ndarray) -> np.ndarray:
    a = np.arccos(np.clip(r_b / np.maximum(np.asarray(rho, dtype=float), r_b), -1.0, 1.0))
    return psi0 - (np.tan(a) - a)


@dataclass(frozen=True)
class PairGeometry:
    """A spur or helical pair in the transverse plane (SI units).

    Attributes
    ----------
    gears : tuple of GearBlank
        Pinion and wheel.
    m_n, alpha_n, beta, face_width : float
        Normal module, normal pressure angle, helix angle, face width.
    h_a, h_f : float
        Addendum and dedendum coefficients of the basic rack (in m_n).
    m_t, alpha_t, alpha_wt, beta_b, a_w : float
        Transverse module, transverse and working pressure angles, base helix angle, centre distance.
    r, r_b, r_a, r_f : tuple of float
        Reference, base, tip and root radii of pinion and wheel.
    p_bt : float
        Transverse base pitch.
    T1T2, s_A, s_E : float
        Length of the line of action between the tangent points, and the start A and end E of the
        active contact as distances from T1 (pinion's tangent point).
    eps_alpha, eps_beta : float
        Transverse and overlap contact ratios.
    sections : tuple of Section
        The tooth of each gear.
    """

    gears: tuple[GearBlank, GearBlank]
    m_n: float
    alpha_n: float
    beta: float
    face_width: float
    h_a: float
    h_f: float
    m_t: float
    alpha_t: float
    alpha_wt: float
    beta_b: float
    a_w: float
    r: tuple[float, float]
    r_b: tuple[float, float]
    r_a: tuple[float, float]
    r_f: tuple[float, float]
    p_bt: float
    T1T2: float
    s_A: float
    s_E: float
    eps_alpha: float
    eps_beta: float
    sections: tuple[Section, Section] = field(repr=False)

    def contact_radius(self, gear: int, s: np.ndarray) -> np.ndarray:
        """Radius of the contact point on ``gear`` (0 pinion, 1 wheel) at the distance ``s`` from T1."""
        s = np.asarray(s, dtype=float)
        t = s if gear == 0 else self.T1T2 - s
        return np.sqrt(self.r_b[gear] ** 2 + t * t)

    @property
    def s_pitch(self) -> float:
        """Distance of the pitch point C from T1 (pure rolling there)."""
        return self.r_b[0] * math.tan(self.alpha_wt)


#: ISO 53:1998 basic rack profiles: (dedendum h_fP / m, root fillet radius ρ_fP / m); α_P = 20°, h_aP = 1 m.
ISO53_RACKS = {"A": (1.25, 0.38), "B": (1.25, 0.30), "C": (1.25, 0.25), "D": (1.40, 0.39)}

#: Points of the tabulated fillet (from the root circle to where the involute starts).
FILLET_POINTS = 401


def trochoid(
    z: float, x: float, m_t: float, alpha_t: float, h_fP: float, rho_fP: float, n: int = FILLET_POINTS
) -> tuple[np.ndarray, np.ndarray]:
    """The root fillet cut by a rack's tip rounding: radius ρ and half angle ψ of the tooth, root circle first.

    Parameters
    ----------
    z, x : float
        Teeth and profile shift coefficient.
    m_t, alpha_t : float
        Transverse module (m) and pressure angle (rad) of the rack.
    h_fP, rho_fP : float
        The rack's addendum (the gear's dedendum) and tip radius, in modules.
    n : int
        Points.

    Returns
    -------
    (rho, psi) : ndarray
        From the root circle (ψ = θ_f) to the tangent point of the rounding with the rack's straight flank.
    """
    r = 0.5 * z * m_t
    rho = rho_fP * m_t
    Yc = r + (x - h_fP + rho_fP) * m_t
    Xc = (0.25 * math.pi - h_fP * math.tan(alpha_t) - rho_fP * math.tan(0.25 * math.pi - 0.5 * alpha_t)) * m_t
    phi = np.linspace(-Xc / r, ((r - Yc) / math.tan(alpha_t) - Xc) / r, n)
    dx, dy = Xc + r * phi, np.full_like(phi, Yc - r)
    L = np.hypot(dx, dy)
    qx, qy = Xc + r * phi + rho * dx / L, Yc + rho * dy / L
    gx = qx * np.cos(phi) - qy * np.sin(phi)
    gy = qx * np.sin(phi) + qy * np.cos(phi)
    return np.hypot(gx, gy), math.pi / z - np.arctan2(gx, gy)


def _section(
    z: float,
    x: float,
    m_t: float,
    alpha_t: float,
    r_f: float,
    r_a: float,
    *,
    h_fP: float = 1.25,
    rho_fP: float = 0.38,
    root: str = "trochoid",
    m_n: float | None = None,
) -> Section:
    r = 0.5 * z * m_t
    r_b = r * math.cos(alpha_t)
    psi0 = math.pi / (2 * z) + 2.0 * x * math.tan(alpha_t) / z + involute(alpha_t)
    start, rho_F = 0, 0.0
    if root == "radial":
        rho = np.linspace(r_f, r_a, SECTION_POINTS)
        psi = _half_angle(psi0, r_b, rho)
        r_L = max(r_f, r_b)
    else:
        m_n = m_t if m_n is None else m_n
        # the rack in the transverse plane: heights in m_n, the tooth thickness in m_t
        rho_t, psi_t = trochoid(z, x, m_t, alpha_t, h_fP * m_n / m_t, rho_fP * m_n / m_t)
        u_T = (h_fP - rho_fP * (1.0 - math.sin(alpha_t)) - x) * m_n
        t_L = r * math.sin(alpha_t) - u_T / math.sin(alpha_t)
        if t_L >= 0:  # the involute from r_L, the fillet below
            r_L = math.hypot(r_b, t_L)
        else:  # undercut: the fillet cuts into the involute above the base circle
            r_L = r_b
            over = rho_t > r_b
            psi_t = np.where(over, np.minimum(psi_t, _half_angle(psi0, r_b, rho_t)), psi_t)
        top = float(rho_t[-1])
        rho_i = np.linspace(max(top, r_L), r_a, SECTION_POINTS)
        rho_i = rho_i[1:] if rho_i[0] <= top else rho_i
        rho = np.concatenate([rho_t, rho_i])
        psi = np.concatenate([psi_t, _half_angle(psi0, r_b, rho_i)])
    if psi[-1] <= 0:
        raise ModelError(f"tooth of z = {z:g}: pointed (zero thickness below the tip circle); reduce x or h_a")
    y, h = rho * np.cos(psi), rho * np.sin(psi)
    if np.any(np.diff(y) <= 0):
        raise ModelError(f"tooth of z = {z:g}: the root fillet folds back on itself (rack tip radius too large)")
    if root != "radial":
        slope = -np.diff(h) / np.diff(y)  # the fillet's tangent against the centre line: tan of its angle
        crit = np.flatnonzero(slope <= math.tan(math.radians(30.0)))
        start = int(crit[0]) if crit.size else 0
        rho_F = _curvature_radius(y[: rho_t.size], h[: rho_t.size], min(start, rho_t.size - 2))
    return Section(y, h, r_f, r_b, r_a, float(psi[0]), psi0, start, float(r_L), rho_F)


def _curvature_radius(x: np.ndarray, y: np.ndarray, i: int) -> float:
    """Radius of curvature of the tabulated curve (x, y) at its point i (central differences in the index)."""
    x1, y1 = np.gradient(x), np.gradient(y)
    x2, y2 = np.gradient(x1), np.gradient(y1)
    k = abs(x1[i] * y2[i] - y1[i] * x2[i]) / (x1[i] ** 2 + y1[i] ** 2) ** 1.5
    return float(1.0 / k) if k > 0 else math.inf


def pair_geometry(
    z1: int,
    z2: int,
    m_n: float,
    *,
    alpha_n: float = math.radians(20.0),
    beta: float = 0.0,
    face_width: float = 0.02,
    x1: float = 0.0,
    x2: float = 0.0,
    h_a: float = 1.0,
    h_f: float | None = None,
    bore1: float | None = None,
    bore2: float | None = None,
    E: float = 206.0e9,
    nu: float = 0.3,
    teeth: tuple[int, int] | None = None,
    rack: str = "A",
    rho_f: float | None = None,
    root: str = "trochoid",
    rim1: float | None = None,
    rim2: float | None = None,
) -> PairGeometry:
    """The geometry of an external spur (β = 0) or helical pair.

    Parameters
    ----------
    z1, z2 : int
        Numbers of teeth (≥ 8).
    m_n : float
        Normal module (m).
    alpha_n, beta : float
        Normal pressure angle and helix angle (rad).
    face_width : float
        Face width b (m).
    x1, x2 : float
        Profile shift coefficients.
    h_a, h_f : float
        Addendum and dedendum coefficients (h_f: the rack's h_fP, default that of ``rack``).
    bore1, bore2 : float, optional
        Bore radii (m); default 0.5 r_f (h_f = 2, inside the range Sainsot et al. fitted).
    rack : str
        ISO 53 basic rack profile ``"A"`` … ``"D"`` (h_fP, ρ_fP): A (1.25, 0.38), B (1.25, 0.30),
        C (1.25, 0.25), D (1.40, 0.39).
    rho_f : float, optional
        The rack's tip radius ρ_fP in modules (default that of ``rack``).
    root : str
        ``"trochoid"`` (the fillet as cut, default) or ``"radial"`` (a radial flank below the base circle).
    rim1, rim2 : float, optional
        Rim thickness s_R under the root circle (m): the bore radius r_f − s_R (instead of bore1, bore2).
    E, nu : float
        Young's modulus and Poisson's ratio of both gears.
    teeth : (int, int), optional
        The gears' own numbers of teeth when z1, z2 are the virtual numbers z_v = d_v/m_vt of a bevel pair's
        virtual cylindrical gears (ISO 10300-1 Annex A, :mod:`geardyn.standards.iso10300`): the tooth shape and
        the path of contact come from the virtual gears, the tooth indices and shaft orders from ``teeth``.

    Returns
    -------
    PairGeometry

    Raises
    ------
    ModelError
        For non-physical inputs, a pointed tooth or a transverse contact ratio below 1.
    """
    if teeth is None and not (_whole_number(z1) and _whole_number(z2)):
        raise ModelError(f"z1, z2: whole numbers of teeth, got {z1!r}, {z2!r} (virtual numbers need teeth=)")
    if z1 < 8 or z2 < 8:
        raise ModelError(f"z1, z2: at least 8 teeth, got {z1!r}, {z2!r}")
    if teeth is not None and (len(teeth) != 2 or not all(_whole_number(n, 5) for n in teeth)):
        raise ModelError(f"teeth: two whole numbers >= 5, got {teeth!r}")
    for name, v in (("m_n", m_n), ("face_width", face_width), ("E", E)):
        if not (math.isfinite(v) and v > 0):
            raise ModelError(f"{name}: must be > 0, got {v!r}")
    if not 0.05e-3 <= m_n <= 0.1:
        raise ModelError(f"m_n: module from 0.05 to 100 mm, got {m_n * 1e3:g} mm")
    if face_width > 100.0 * m_n:
        raise ModelError(f"face_width: at most 100 m_n = {100 * m_n * 1e3:g} mm, got {face_width * 1e3:g} mm")
    if not 0.0 <= nu < 0.5:
        raise ModelError(f"nu: Poisson's ratio in [0, 0.5), got {nu!r}")
    if not math.radians(10.0) <= alpha_n <= math.radians(35.0):
        raise ModelError(f"alpha_n: between 10 and 35 deg, got {math.degrees(alpha_n):g} deg")
    if not 0.0 <= beta < math.radians(45.0):
        raise ModelError(f"beta: between 0 and 45 deg, got {math.degrees(beta):g} deg")
    if rack not in ISO53_RACKS:
        raise ModelError(f"rack: an ISO 53 basic rack profile A, B, C or D, got {rack!r}")
    if root not in ("trochoid", "radial"):
        raise ModelError(f"root: 'trochoid' or 'radial', got {root!r}")
    h_f = ISO53_RACKS[rack][0] if h_f is None else h_f
    rho_f = ISO53_RACKS[rack][1] if rho_f is None else rho_f
    if not (math.isfinite(h_a) and 0.5 <= h_a <= 1.5):
        raise ModelError(f"h_a: addendum coefficient in [0.5, 1.5], got {h_a!r}")
    if not (math.isfinite(h_f) and h_a < h_f <= 2.0):
        raise ModelError(f"h_f: dedendum coefficient in (h_a = {h_a:g}, 2], got {h_f!r}")
    for name, x in (("x1", x1), ("x2", x2)):
        if not (math.isfinite(x) and -1.0 <= x <= 1.5):
            raise ModelError(f"{name}: profile shift coefficient in [-1, 1.5], got {x!r}")
    rho_max = (0.25 * math.pi - h_f * math.tan(alpha_n)) / math.tan(0.25 * math.pi - 0.5 * alpha_n)
    if not (math.isfinite(rho_f) and 0.0 <= rho_f <= rho_max):
        raise ModelError(
            f"rho_f: rack tip radius in [0, {rho_max:.4g}] modules (the rounding within the rack's tooth tip), "
            f"got {rho_f!r}"
        )
    z1, z2 = float(z1), float(z2)
    n1, n2 = (int(round(z1)), int(round(z2))) if teeth is None else (int(teeth[0]), int(teeth[1]))
    alpha_t, beta_b, m_t, alpha_wt = _transverse(alpha_n, beta, m_n, x1, x2, z1, z2)
    r = (0.5 * z1 * m_t, 0.5 * z2 * m_t)
    r_b = (r[0] * math.cos(alpha_t), r[1] * math.cos(alpha_t))
    r_a = (r[0] + m_n * (h_a + x1), r[1] + m_n * (h_a + x2))
    r_f = (r[0] - m_n * (h_f - x1), r[1] - m_n * (h_f - x2))
    a_w = (r[0] + r[1]) * math.cos(alpha_t) / math.cos(alpha_wt)
    T1T2 = a_w * math.sin(alpha_wt)
    s_E = math.sqrt(r_a[0] ** 2 - r_b[0] ** 2)
    s_A = T1T2 - math.sqrt(r_a[1] ** 2 - r_b[1] ** 2)
    p_bt = math.pi * m_t * math.cos(alpha_t)
    bores = []
    for g, (rf, rim, bore) in enumerate(zip(r_f, (rim1, rim2), (bore1, bore2))):
        if rim is not None:
            if bore is not None:
                raise ModelError(f"rim{g + 1}: give a rim thickness or a bore radius, not both")
            if not (math.isfinite(rim) and 0.0 < rim < rf):
                raise ModelError(f"rim{g + 1}: rim thickness in (0, r_f = {rf:g} m), got {rim!r}")
            bore = rf - rim
        bores.append(0.5 * rf if bore is None else bore)
    if s_A < 0:
        raise ModelError("geometry: the wheel's tip reaches past the pinion's base circle (interference)")
    eps_alpha = (s_E - s_A) / p_bt
    if eps_alpha < 1.0:
        raise ModelError(f"geometry: transverse contact ratio {eps_alpha:.3f} < 1")
    eps_beta = face_width * math.sin(beta) / (math.pi * m_n)
    gears = tuple(GearBlank(z, x, b, E, nu, n) for z, x, b, n in zip((z1, z2), (x1, x2), bores, (n1, n2)))
    for g, rf in zip(gears, r_f):
        if not 0 < g.bore_radius < rf:
            raise ModelError(f"bore radius of z = {g.z:g}: must lie between 0 and the root radius {rf:g} m")
    sections = tuple(
        _section(z, x, m_t, alpha_t, rf, ra, h_fP=h_f, rho_fP=rho_f, root=root, m_n=m_n)
        for z, x, rf, ra in zip((z1, z2), (x1, x2), r_f, r_a)
    )
    for g, sec in enumerate(sections):
        s_low = s_A if g == 0 else T1T2 - s_E
        if math.hypot(r_b[g], s_low) < sec.r_L * (1.0 - 1e-9):
            raise ModelError(
                f"geometry: contact reaches below the involute of gear {g + 1} (radius "
                f"{math.hypot(r_b[g], s_low) * 1e3:.4g} mm < form radius {sec.r_L * 1e3:.4g} mm: undercut or "
                f"root interference); use a profile shift"
            )
    return PairGeometry(
        gears,
        m_n,
        alpha_n,
        beta,
        face_width,
        h_a,
        h_f,
        m_t,
        alpha_t,
        alpha_wt,
        beta_b,
        a_w,
        r,
        r_b,
        r_a,
        r_f,
        p_bt,
        T1T2,
        s_A,
        s_E,
        eps_alpha,
        eps_beta,
        sections,
    )
