"""Spiral bevel gear pair geometry and the dimensional → non-dimensional conversion.

:class:`SpiralBevelGearPair` holds the physical description of a spiral bevel pair in SI units
(metres, radians, kilograms, newtons, seconds).  From it follow

* the pitch cone angles ``tan δ1 = sin Σ / (z2/z1 + cos Σ)``, ``δ2 = Σ − δ1``;
* the mesh-point position vectors ``r_l``, the rotation axes ``j_l`` and the common flank normal
  ``n`` at the mesh point, in a frame with its origin at the intersection of the axes
  (:meth:`SpiralBevelGearPair.mesh_vectors`);
* the directional radii ``R_l = n · (j_l × r_l)`` computed from those vectors;
* the equivalent mass ``m_e = I1 I2 / (I2 R1² + I1 R2²)`` and the static mesh force
  ``F_p = (I2 R1 T1 + I1 R2 T2) / (I2 R1² + I1 R2²)``;
* the mean mesh stiffness ``k0`` (given, or face width × c_γ) and ``ω_n = √(k0/m_e)``;
* a non-dimensional :class:`~geardyn.model.GearModel` at an operating point
  (:meth:`SpiralBevelGearPair.gear_model`) and the scales that convert back to physical units
  (:class:`Scales`).

The derivation and every assumption are in ``docs/model.md``.

Coordinate frame
----------------
Origin at the intersection of the shaft axes (the common cone apex).  The pinion axis ``a1`` is
``+y``; the gear axis ``a2 = (sin Σ, cos Σ, 0)`` lies in the x–y plane (``+x`` for Σ = 90°), both
pointing from the apex towards the back of the gear.  The pitch cones touch along the generatrix
``g = (sin δ1, cos δ1, 0)``; the mesh point lies on it.  ``+z`` is normal to the plane of the axes.
The rotation axes ``j_l = ±a_l`` are oriented so that positive ``θ_l`` is the running direction
(both pitch points move the same way at the mesh), so that ``u_n = R1 θ1 − R2 θ2 − e_n`` is the
compression of the mesh.  ``n`` is the common normal of the loaded flanks at the mesh point,
pointing from the pinion flank into the gear flank (the direction of the force on the gear);
``n1 = n2 = n``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import Any

import numpy as np

from .model import GearModel, ModelError

__all__ = [
    "Assumption",
    "DEFAULT_C_GAMMA",
    "DEFAULT_HAND",
    "DEFAULT_DRIVE_SIDE",
    "DEFAULT_XI0",
    "FACE_WIDTH_TO_OUTER_CONE_DISTANCE",
    "MeshHarmonics",
    "MeshVectors",
    "ResolvedInputs",
    "Scales",
    "SpiralBevelGearPair",
    "drive_side_from_rotation",
    "geometry_summary",
    "summary_rows",
]

#: Default mean mesh stiffness per unit face width c_γ, in N/m² (= 20 N/(mm·µm)).  The usual
#: ISO 6336 / ISO 10300 style mean value when nothing better is known.
DEFAULT_C_GAMMA = 20.0e9
#: Face width as a fraction of the outer cone distance used when no face width is given
#: (b = 0.3 R_e, the usual upper limit for bevel gears).
FACE_WIDTH_TO_OUTER_CONE_DISTANCE = 0.3
#: Hand of spiral of the pinion used when none is given (the gear has the opposite hand).
DEFAULT_HAND = "left"
#: Loaded flank of the pinion used when none is given (pinion concave drives gear convex).
DEFAULT_DRIVE_SIDE = "concave"
#: Mean mesh damping ratio ξ0 used when neither ξ0 nor c0 is given (the paper's Table 1 value).
DEFAULT_XI0 = 0.1
#: Relative mismatch between the cone distances implied by r1/sin δ1 and r2/sin δ2 above which a
#: note is added to the summary.
CONE_DISTANCE_NOTE_TOL = 1e-3

HANDS = ("left", "right")
SIDES = ("concave", "convex")
ROTATIONS = ("clockwise", "counterclockwise")

_SOURCE_HAND = (
    "not given in the paper; hand and drive side change only the axial and radial force components, "
    "not the torsional model"
)
_SOURCE_SIDE = _SOURCE_HAND
_SOURCE_C_GAMMA = "typical value: ISO 6336/ISO 10300 style mean mesh stiffness per unit face width, 20 N/(mm·µm)"
_SOURCE_FACE_WIDTH = (
    "not given; b = 0.3·R_e (usual upper limit of the face width of bevel gears, typical value), "
    "with R_e = R_m + b/2 and R_m = r1/sin δ1"
)
_SOURCE_K0 = "not given; k0 = face width × c_γ"
_SOURCE_XI0 = "not given; ξ0 = 0.1 (the paper's Table 1 value, within the range usually assumed for gear meshes)"
_SOURCE_R = "not given; mesh point taken at the mean pitch point, r_l = m_mn z_l / (2 cos β_m)"


def _deg(x: float) -> float:
    return math.degrees(x)


def _finite(name: str, value: Any, unit: str = "") -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected a number{(' in ' + unit) if unit else ''}, got {value!r}") from None
    if not math.isfinite(x):
        raise ModelError(f"{name}: must be a finite number, got {value!r}")
    return x


def _positive(name: str, value: Any, unit: str) -> float:
    x = _finite(name, value, unit)
    if x <= 0:
        raise ModelError(f"{name}: must be > 0 {unit}, got {x:g} {unit}")
    return x


def _angle(name: str, value: Any, lo_deg: float, hi_deg: float, lo_closed: bool = False) -> float:
    """Validate an angle given in radians against an interval given in degrees."""
    x = _finite(name, value, "rad")
    d = math.degrees(x)
    ok_lo = d >= lo_deg if lo_closed else d > lo_deg
    if not (ok_lo and d < hi_deg):
        lb = "[" if lo_closed else "("
        raise ModelError(f"{name}: must be in {lb}{lo_deg:g}, {hi_deg:g}) deg, got {d:.6g} deg")
    return x


def drive_side_from_rotation(hand: str, rotation: str) -> str:
    """Loaded pinion flank for a pinion of the given hand turning the given way.

    Parameters
    ----------
    hand : {"left", "right"}
        Hand of spiral of the pinion (the gear has the opposite hand).
    rotation : {"clockwise", "counterclockwise"}
        Sense of rotation of the driving pinion viewed from its back, looking towards the apex.

    Returns
    -------
    str
        ``"concave"`` or ``"convex"``: the pinion flank that carries the load.  With the
        conventions of this module a left-hand pinion turning clockwise drives on its concave
        flank, a right-hand pinion turning counterclockwise too.
    """
    if hand not in HANDS:
        raise ModelError(f"hand: must be one of {', '.join(HANDS)}, got {hand!r}")
    if rotation not in ROTATIONS:
        raise ModelError(f"pinion_rotation: must be one of {', '.join(ROTATIONS)}, got {rotation!r}")
    # j1 = s·h·a1 with s = -1 (concave) / +1 (convex), h = +1 (left) / -1 (right);
    # j1 = +a1 is counterclockwise seen from the back.
    h = 1 if hand == "left" else -1
    ccw = 1 if rotation == "counterclockwise" else -1
    s = ccw * h
    return "convex" if s > 0 else "concave"


@dataclass(frozen=True)
class Assumption:
    """An input value the paper (or the configuration) does not give, with its source.

    Parameters
    ----------
    name : str
        Parameter name, as in :class:`SpiralBevelGearPair` or in the configuration file.
    value : float or str
        The value used, in ``unit``.
    unit : str
        Unit of ``value`` ("" for words and non-dimensional numbers).
    source : str
        Where the value comes from, or why it was chosen.
    """

    name: str
    value: float | str
    unit: str
    source: str

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "value": self.value, "unit": self.unit, "source": self.source}


@dataclass(frozen=True)
class ResolvedInputs:
    """The optional inputs of a :class:`SpiralBevelGearPair` with every default applied (SI units).

    Attributes
    ----------
    r1, r2 : float
        Distance from the mesh point to the pinion / gear axis (m).
    hand : str
        Hand of spiral of the pinion ("left" or "right").
    drive_side : str
        Loaded flank of the pinion ("concave" or "convex").
    face_width : float
        Face width b (m).
    c_gamma : float
        Mean mesh stiffness per unit face width (N/m²); ``nan`` when k0 was given directly.
    k0 : float
        Mean mesh stiffness (N/m).
    xi0 : float
        Mean mesh damping ratio ξ0 (non-dimensional).
    assumed : tuple of Assumption
        Every value not given by the user (or declared assumed by the user), with its source.
    """

    r1: float
    r2: float
    hand: str
    drive_side: str
    face_width: float
    c_gamma: float
    k0: float
    xi0: float
    assumed: tuple[Assumption, ...]


@dataclass(frozen=True, eq=False)
class MeshVectors:
    """Mesh-point vectors of a spiral bevel pair (frame: origin at the apex, see module docstring).

    Attributes
    ----------
    r1, r2 : ndarray, shape (3,)
        Mesh-point position vectors (m) as seen from each gear: the point on the common pitch
        generatrix at distance r_l from axis l.
    j1, j2 : ndarray, shape (3,)
        Unit rotation axes, oriented in the running direction of each gear.
    n1, n2 : ndarray, shape (3,)
        Unit common flank normal at the mesh point, from the pinion flank into the gear flank
        (``n1 = n2``).
    a1, a2 : ndarray, shape (3,)
        Unit shaft axes pointing from the apex towards the back of each gear.
    g : ndarray, shape (3,)
        Unit pitch-cone generatrix through the mesh point (from the apex outwards).
    t : ndarray, shape (3,)
        Unit running (tangential) direction of the pitch points at the mesh.
    p : ndarray, shape (3,)
        Unit normal of the common pitch plane, from the pinion towards the gear.
    """

    r1: np.ndarray
    r2: np.ndarray
    j1: np.ndarray
    j2: np.ndarray
    n1: np.ndarray
    n2: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    g: np.ndarray
    t: np.ndarray
    p: np.ndarray

    @property
    def R1(self) -> float:
        """Directional radius of the pinion R1 = n1 · (j1 × r1) (m)."""
        return float(self.n1 @ np.cross(self.j1, self.r1))

    @property
    def R2(self) -> float:
        """Directional radius of the gear R2 = n2 · (j2 × r2) (m)."""
        return float(self.n2 @ np.cross(self.j2, self.r2))

    def force_components(self) -> dict[str, dict[str, float]]:
        """Components of the mesh force on each gear per unit normal force (non-dimensional).

        Returns
        -------
        dict
            ``{"pinion": {...}, "gear": {...}}`` with ``tangential`` (along the running direction;
            negative on the pinion, i.e. resisting its rotation, positive on the gear),
            ``axial`` (along the shaft, positive away from the apex, i.e. out of mesh) and
            ``radial`` (positive towards the own axis, i.e. separating).  Multiply by the normal
            force in N to obtain forces in N.
        """
        out = {}
        for name, sign, a, r in (("pinion", -1.0, self.a1, self.r1), ("gear", 1.0, self.a2, self.r2)):
            force = sign * self.n1  # force acting on this gear's flank
            radial_out = r - (r @ a) * a
            radial_out = radial_out / np.linalg.norm(radial_out)
            out[name] = {
                "tangential": float(force @ self.t),
                "axial": float(force @ a),
                "radial": float(-(force @ radial_out)),
            }
        return out

    def to_dict(self) -> dict[str, list[float]]:
        return {f.name: [float(x) for x in getattr(self, f.name)] for f in fields(self)}


@dataclass(frozen=True)
class MeshHarmonics:
    """Fourier harmonics of the mesh damping, stiffness and static transmission error.

    Each series is given either non-dimensionally or dimensionally, not both.  Harmonic ``k``
    (1-based) of each series is element ``k − 1``; phases default to 0 and are in radians.

    Parameters
    ----------
    xi : sequence of float
        Damping harmonics ξ_k = c_k/(2 m_e ω_n) (non-dimensional).
    c : sequence of float
        Damping harmonics c_k (N·s/m).
    phi_c : sequence of float
        Phases φ_ck (rad).
    kappa : sequence of float
        Stiffness harmonics κ_r = k_r/k0 (non-dimensional).
    k : sequence of float
        Stiffness harmonics k_r (N/m).
    phi_k : sequence of float
        Phases φ_kr (rad).
    eps : sequence of float
        STE harmonics ε_l = e_l/b_c (non-dimensional).
    e : sequence of float
        STE harmonics e_l (m).
    phi_e : sequence of float
        Phases φ_el (rad).
    """

    xi: tuple[float, ...] = ()
    c: tuple[float, ...] = ()
    phi_c: tuple[float, ...] = ()
    kappa: tuple[float, ...] = ()
    k: tuple[float, ...] = ()
    phi_k: tuple[float, ...] = ()
    eps: tuple[float, ...] = ()
    e: tuple[float, ...] = ()
    phi_e: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        for f in fields(self):
            vals = getattr(self, f.name)
            if vals is None:
                vals = ()
            if np.isscalar(vals):
                vals = (vals,)
            object.__setattr__(self, f.name, tuple(_finite(f"{f.name}{i + 1}", v) for i, v in enumerate(vals)))
        for nd, dim, unit in (("xi", "c", "N*s/m"), ("kappa", "k", "N/m"), ("eps", "e", "m")):
            if getattr(self, nd) and getattr(self, dim):
                raise ModelError(
                    f"{nd}/{dim}: give the harmonics either non-dimensionally ({nd}) or in {unit} ({dim}), not both"
                )

    def nondimensional(self, m_e: float, omega_n: float, k0: float, b_c: float) -> dict[str, tuple[float, ...]]:
        """Non-dimensional harmonics for :class:`~geardyn.model.GearModel`.

        Parameters
        ----------
        m_e : float
            Equivalent mass (kg).
        omega_n : float
            Natural frequency √(k0/m_e) (rad/s).
        k0 : float
            Mean mesh stiffness (N/m).
        b_c : float
            Characteristic length (m).
        """
        xi = self.xi or tuple(c / (2.0 * m_e * omega_n) for c in self.c)
        kappa = self.kappa or tuple(k / k0 for k in self.k)
        eps = self.eps or tuple(e / b_c for e in self.e)
        return {
            "xi": xi,
            "phi_c": self.phi_c,
            "kappa": kappa,
            "phi_k": self.phi_k,
            "eps": eps,
            "phi_e": self.phi_e,
        }


@dataclass(frozen=True)
class SpiralBevelGearPair:
    """A spiral bevel gear pair (all inputs in SI units: m, rad, kg·m², N/m, N/m²).

    Parameters
    ----------
    z1, z2 : int
        Numbers of teeth of the pinion (driver, 1) and the gear (driven, 2), >= 1.
    m_mn : float
        Mean normal module (m), > 0.
    beta_m : float
        Mean spiral angle β_m (rad), in [0°, 90°).
    alpha_n : float
        Normal pressure angle α_n (rad), in (0°, 90°).
    j_n : float
        Normal backlash (m), >= 0.  The half backlash b_n = j_n/2 is the dead zone of the mesh.
    I1, I2 : float
        Mass moments of inertia of pinion and gear about their axes (kg·m²), > 0.
    Sigma : float
        Shaft angle Σ (rad), in (0°, 180°); default 90°.
    r1, r2 : float, optional
        Distance from the mesh point to the pinion / gear axis (m).  Default: the mean pitch
        radius m_mn z_l/(2 cos β_m) (marked assumed).
    hand : {"left", "right"}, optional
        Hand of spiral of the pinion; the gear has the opposite hand.  Default ``"left"``
        (assumed).  Does not change the torsional model.
    drive_side : {"concave", "convex"}, optional
        Loaded flank of the pinion (the gear's loaded flank is the other one).  Default
        ``"concave"`` (assumed).  Changes the axial and radial force components only.
    face_width : float, optional
        Face width b (m).  Default 0.3 R_e (assumed).  Used only to estimate k0.
    c_gamma : float, optional
        Mean mesh stiffness per unit face width (N/m²; 20 N/(mm·µm) = 2e10 N/m²).  Default
        :data:`DEFAULT_C_GAMMA` (assumed).  Ignored when ``k0`` is given.
    k0 : float, optional
        Mean mesh stiffness along the line of action (N/m).  Default face_width × c_gamma.
    xi0 : float, optional
        Mean mesh damping ratio ξ0 = c0/(2 m_e ω_n) (non-dimensional, >= 0).
    c0 : float, optional
        Mean mesh damping coefficient (N·s/m, >= 0); give ``xi0`` or ``c0``, not both.  Default
        ξ0 = :data:`DEFAULT_XI0` (assumed).
    name : str
        A label for reports.
    assumed : sequence of (str, str)
        ``(parameter name, source)`` pairs for given values that are themselves assumptions
        (e.g. a face width chosen by the user); they appear in :attr:`assumed`.
    """

    z1: int
    z2: int
    m_mn: float
    beta_m: float
    alpha_n: float
    j_n: float
    I1: float
    I2: float
    Sigma: float = math.pi / 2
    r1: float | None = None
    r2: float | None = None
    hand: str | None = None
    drive_side: str | None = None
    face_width: float | None = None
    c_gamma: float | None = None
    k0: float | None = None
    xi0: float | None = None
    c0: float | None = None
    name: str = ""
    assumed: tuple[tuple[str, str], ...] = field(default=())

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        for zname in ("z1", "z2"):
            z = getattr(self, zname)
            if isinstance(z, bool) or not isinstance(z, (int, np.integer, float)) or not float(z).is_integer() or z < 1:
                raise ModelError(f"{zname}: number of teeth must be an integer >= 1, got {z!r}")
            set_(self, zname, int(z))
        set_(self, "m_mn", _positive("m_mn", self.m_mn, "m"))
        set_(self, "beta_m", _angle("beta_m", self.beta_m, 0.0, 90.0, lo_closed=True))
        set_(self, "alpha_n", _angle("alpha_n", self.alpha_n, 0.0, 90.0))
        set_(self, "Sigma", _angle("Sigma", self.Sigma, 0.0, 180.0))
        jn = _finite("j_n", self.j_n, "m")
        if jn < 0:
            raise ModelError(f"j_n: normal backlash must be >= 0 m, got {jn:g} m")
        set_(self, "j_n", jn)
        for name in ("I1", "I2"):
            set_(self, name, _positive(name, getattr(self, name), "kg*m^2"))
        for name, unit in (("r1", "m"), ("r2", "m"), ("face_width", "m"), ("c_gamma", "N/m^2"), ("k0", "N/m")):
            if getattr(self, name) is not None:
                set_(self, name, _positive(name, getattr(self, name), unit))
        for name, unit in (("xi0", ""), ("c0", "N*s/m")):
            v = getattr(self, name)
            if v is not None:
                v = _finite(name, v, unit)
                if v < 0:
                    raise ModelError(f"{name}: mean mesh damping must be >= 0{(' ' + unit) if unit else ''}, got {v:g}")
                set_(self, name, v)
        if self.xi0 is not None and self.c0 is not None:
            raise ModelError("xi0/c0: give the mean mesh damping as a ratio (xi0) or a coefficient (c0), not both")
        if self.hand is not None and self.hand not in HANDS:
            raise ModelError(f"hand: must be one of {', '.join(HANDS)} (pinion hand of spiral), got {self.hand!r}")
        if self.drive_side is not None and self.drive_side not in SIDES:
            raise ModelError(
                f"drive_side: must be one of {', '.join(SIDES)} (loaded pinion flank), got {self.drive_side!r}"
            )
        assumed = tuple((str(n), str(s)) for n, s in (self.assumed or ()))
        known = {f.name for f in fields(self)} - {"name", "assumed"}
        for n, _ in assumed:
            if n not in known:
                raise ModelError(f"assumed: unknown parameter {n!r}; allowed: {', '.join(sorted(known))}")
        set_(self, "assumed", assumed)

    # ------------------------------------------------------------------ pitch cones
    @property
    def ratio(self) -> float:
        """Gear ratio z2/z1 (non-dimensional)."""
        return self.z2 / self.z1

    @property
    def delta1(self) -> float:
        """Pinion pitch cone angle δ1 (rad): tan δ1 = sin Σ / (z2/z1 + cos Σ)."""
        return math.atan2(math.sin(self.Sigma), self.ratio + math.cos(self.Sigma))

    @property
    def delta2(self) -> float:
        """Gear pitch cone angle δ2 = Σ − δ1 (rad)."""
        return self.Sigma - self.delta1

    @property
    def b_n(self) -> float:
        """Half normal backlash b_n = j_n/2 (m)."""
        return 0.5 * self.j_n

    # ------------------------------------------------------------------ defaults applied
    @cached_property
    def resolved(self) -> ResolvedInputs:
        """Every optional input with its default applied, and the list of assumed values."""
        assumed: list[Assumption] = []
        declared = dict(self.assumed)

        def note(name: str, value: float | str, unit: str, default_source: str | None) -> None:
            if name in declared:
                assumed.append(Assumption(name, value, unit, declared[name]))
            elif default_source is not None:
                assumed.append(Assumption(name, value, unit, default_source))

        r_pitch = [self.m_mn * z / (2.0 * math.cos(self.beta_m)) for z in (self.z1, self.z2)]
        r1 = self.r1 if self.r1 is not None else r_pitch[0]
        r2 = self.r2 if self.r2 is not None else r_pitch[1]
        note("r1", r1, "m", None if self.r1 is not None else _SOURCE_R)
        note("r2", r2, "m", None if self.r2 is not None else _SOURCE_R)
        hand = self.hand or DEFAULT_HAND
        note("hand", hand, "", None if self.hand is not None else _SOURCE_HAND)
        side = self.drive_side or DEFAULT_DRIVE_SIDE
        note("drive_side", side, "", None if self.drive_side is not None else _SOURCE_SIDE)
        if self.face_width is not None:
            b = self.face_width
            note("face_width", b, "m", None)
        else:
            r_m = r1 / math.sin(self.delta1)
            f = FACE_WIDTH_TO_OUTER_CONE_DISTANCE
            b = f * r_m / (1.0 - 0.5 * f)
            note("face_width", b, "m", _SOURCE_FACE_WIDTH if self.k0 is None else None)
        if self.k0 is not None:
            k0 = self.k0
            c_gamma = float("nan")
            note("k0", k0, "N/m", None)
            if self.c_gamma is not None:
                note("c_gamma", self.c_gamma, "N/m^2", None)
        else:
            c_gamma = self.c_gamma if self.c_gamma is not None else DEFAULT_C_GAMMA
            note("c_gamma", c_gamma, "N/m^2", None if self.c_gamma is not None else _SOURCE_C_GAMMA)
            k0 = b * c_gamma
            assumed.append(Assumption("k0", k0, "N/m", _SOURCE_K0))
        if self.c0 is not None:
            xi0 = self.c0 / (2.0 * self._m_e_from(r1, r2) * math.sqrt(k0 / self._m_e_from(r1, r2)))
            note("c0", self.c0, "N*s/m", None)
        else:
            xi0 = self.xi0 if self.xi0 is not None else DEFAULT_XI0
            note("xi0", xi0, "", None if self.xi0 is not None else _SOURCE_XI0)
        # values declared assumed that no branch above covered (e.g. z1 or I1)
        covered = {a.name for a in assumed}
        for n, src in self.assumed:
            if n not in covered:
                v = getattr(self, n)
                assumed.append(Assumption(n, v if v is not None else "", _UNITS.get(n, ""), src))
        return ResolvedInputs(r1, r2, hand, side, b, c_gamma, k0, xi0, tuple(assumed))

    @property
    def assumptions(self) -> tuple[Assumption, ...]:
        """Every value not given (defaulted) or declared assumed, with its source."""
        return self.resolved.assumed

    # ------------------------------------------------------------------ vectors
    def mesh_vectors(self) -> MeshVectors:
        """Mesh-point vectors r_l, j_l, n_l built from (α_n, β_m, δ_l, Σ, hand, drive side).

        The common pitch plane at the mesh point is spanned by the generatrix ``g`` and ``z``.
        In it the tooth trace of the pinion makes the angle β_m with ``g``; a left-hand pinion's
        trace leans towards ``+z`` going outwards (seen from the front of the pinion the outer half
        of the tooth is inclined counterclockwise).  The spiral angle grows towards the heel
        (face-milled teeth), so the concave flank of the pinion faces the centre of curvature of
        the trace.  The loaded flank's normal is tilted out of the pitch plane by α_n, towards the
        gear (the separating component).
        """
        rv = self.resolved
        d1, S = self.delta1, self.Sigma
        a1 = np.array([0.0, 1.0, 0.0])
        a2 = np.array([math.sin(S), math.cos(S), 0.0])
        g = np.array([math.sin(d1), math.cos(d1), 0.0])
        ez = np.array([0.0, 0.0, 1.0])
        p = np.array([math.cos(d1), -math.sin(d1), 0.0])  # pinion's outward pitch-cone normal: towards the gear
        h = 1.0 if rv.hand == "left" else -1.0
        c = 1.0 if rv.drive_side == "concave" else -1.0
        cb, sb = math.cos(self.beta_m), math.sin(self.beta_m)
        ca, sa = math.cos(self.alpha_n), math.sin(self.alpha_n)
        trace = cb * g + h * sb * ez  # pinion tooth trace, from toe to heel
        nu = -h * sb * g + cb * ez  # in-plane unit normal of the trace
        bend = h * nu  # direction in which the trace curves (β_m grows towards the heel)
        nu_loaded = c * bend  # in-plane normal of the loaded pinion flank (concave flank faces `bend`)
        assert abs(trace @ nu) < 1e-12
        t = ez * math.copysign(1.0, nu_loaded @ ez)  # running direction: the driver pushes forwards
        n = ca * nu_loaded + sa * p
        n = n / np.linalg.norm(n)
        r1v = (rv.r1 / math.sin(d1)) * g
        r2v = (rv.r2 / math.sin(self.delta2)) * g
        j1 = a1 * math.copysign(1.0, np.cross(a1, r1v) @ t)
        j2 = a2 * math.copysign(1.0, np.cross(a2, r2v) @ t)
        return MeshVectors(r1=r1v, r2=r2v, j1=j1, j2=j2, n1=n, n2=n.copy(), a1=a1, a2=a2, g=g, t=t, p=p)

    def rotation_sense(self) -> tuple[str, str]:
        """Running sense of (pinion, gear), each viewed from its back looking towards the apex."""
        mv = self.mesh_vectors()
        return tuple(  # type: ignore[return-value]
            "counterclockwise" if j @ a > 0 else "clockwise" for j, a in ((mv.j1, mv.a1), (mv.j2, mv.a2))
        )

    # ------------------------------------------------------------------ torsional model
    @cached_property
    def _R(self) -> tuple[float, float]:
        mv = self.mesh_vectors()
        return mv.R1, mv.R2

    @property
    def R1(self) -> float:
        """Directional radius of the pinion R1 = n·(j1 × r1) (m); equals r1 cos α_n cos β_m."""
        return self._R[0]

    @property
    def R2(self) -> float:
        """Directional radius of the gear R2 = n·(j2 × r2) (m); equals r2 cos α_n cos β_m."""
        return self._R[1]

    def _m_e_from(self, r1: float, r2: float) -> float:
        lam = math.cos(self.alpha_n) * math.cos(self.beta_m)
        R1, R2 = lam * r1, lam * r2
        return self.I1 * self.I2 / (self.I2 * R1**2 + self.I1 * R2**2)

    @property
    def m_e(self) -> float:
        """Equivalent mass m_e = I1 I2 / (I2 R1² + I1 R2²) (kg)."""
        R1, R2 = self._R
        return self.I1 * self.I2 / (self.I2 * R1**2 + self.I1 * R2**2)

    @property
    def k0_mean(self) -> float:
        """Mean mesh stiffness k0 along the line of action (N/m), given or face width × c_γ."""
        return self.resolved.k0

    @property
    def omega_n(self) -> float:
        """Natural frequency of the mesh ω_n = √(k0/m_e) (rad/s)."""
        return math.sqrt(self.k0_mean / self.m_e)

    @property
    def c0_mean(self) -> float:
        """Mean mesh damping coefficient c0 = 2 ξ0 m_e ω_n (N·s/m)."""
        return self.c0 if self.c0 is not None else 2.0 * self.resolved.xi0 * self.m_e * self.omega_n

    @property
    def xi0_mean(self) -> float:
        """Mean mesh damping ratio ξ0 (non-dimensional)."""
        return self.resolved.xi0

    def balanced_torque2(self, T1: float) -> float:
        """Gear (output) torque T2 = T1 R2/R1 that balances the pinion torque T1 in steady state (N·m)."""
        return T1 * self.R2 / self.R1

    def static_force(self, T1: float, T2: float | None = None) -> float:
        """Mean mesh force F_p = (I2 R1 T1 + I1 R2 T2)/(I2 R1² + I1 R2²) (N).

        Parameters
        ----------
        T1 : float
            Pinion (input) torque (N·m).
        T2 : float, optional
            Gear (output, load) torque (N·m); default the balanced value T1 R2/R1, for which
            F_p = T1/R1.
        """
        T1 = _finite("torque", T1, "N*m")
        T2 = self.balanced_torque2(T1) if T2 is None else _finite("torque2", T2, "N*m")
        R1, R2 = self._R
        return (self.I2 * R1 * T1 + self.I1 * R2 * T2) / (self.I2 * R1**2 + self.I1 * R2**2)

    def mesh_frequency(self, rpm: float) -> float:
        """Mesh (tooth-passing) angular frequency ω_e = 2π z1 n1/60 (rad/s) for pinion speed n1 (rpm)."""
        return 2.0 * math.pi * self.z1 * _positive("rpm", rpm, "rpm") / 60.0

    def scales(self, b_c: float | None = None) -> "Scales":
        """Scales between physical and non-dimensional quantities.

        Parameters
        ----------
        b_c : float, optional
            Characteristic length (m); default b_n = j_n/2 (then D = 1).  The paper's Table 3
            reading of backlash uses b_c = 1 mm (D = j_n/(2·1 mm)).
        """
        if b_c is None:
            if self.b_n <= 0:
                raise ModelError("b_c: the backlash j_n is 0, so a characteristic length b_c > 0 must be given")
            b_c = self.b_n
        return Scales(self, _positive("b_c", b_c, "m"))

    def gear_model(
        self,
        rpm: float,
        torque: float,
        *,
        torque2: float | None = None,
        mesh: MeshHarmonics | None = None,
        b_c: float | None = None,
    ) -> GearModel:
        """Non-dimensional model at an operating point.

        Parameters
        ----------
        rpm : float
            Pinion speed n1 (rpm), > 0.
        torque : float
            Pinion torque T1 (N·m).
        torque2 : float, optional
            Gear torque T2 (N·m); default balanced, T1 R2/R1.
        mesh : MeshHarmonics, optional
            Harmonics of damping, stiffness and STE; default none (constant coefficients).
        b_c : float, optional
            Characteristic length (m); default b_n.

        Returns
        -------
        GearModel
            With ω = ω_e/ω_n, ξ0, f_p = F_p/(k0 b_c), D = b_n/b_c and the harmonics made
            non-dimensional (ξ_k = c_k/(2 m_e ω_n), κ_r = k_r/k0, ε_l = e_l/b_c).
        """
        sc = self.scales(b_c)
        harmonics = (mesh or MeshHarmonics()).nondimensional(self.m_e, self.omega_n, self.k0_mean, sc.b_c)
        return GearModel(
            omega=sc.omega_from_rpm(rpm),
            xi0=self.xi0_mean,
            fp=sc.fp_from_torque(torque, torque2),
            D=self.b_n / sc.b_c,
            **harmonics,
        )


_UNITS = {
    "m_mn": "m",
    "beta_m": "rad",
    "alpha_n": "rad",
    "Sigma": "rad",
    "j_n": "m",
    "I1": "kg*m^2",
    "I2": "kg*m^2",
    "r1": "m",
    "r2": "m",
    "face_width": "m",
    "c_gamma": "N/m^2",
    "k0": "N/m",
    "c0": "N*s/m",
}


@dataclass(frozen=True)
class Scales:
    """Conversions between physical and non-dimensional quantities of one gear pair.

    The scales are: length b_c (m), time 1/ω_n (s), force k0 b_c (N), frequency ω_n (rad/s).
    Every method accepts floats or NumPy arrays.

    Parameters
    ----------
    pair : SpiralBevelGearPair
        The gear pair (gives m_e, k0, ω_n, z1, R1, R2).
    b_c : float
        Characteristic length (m).
    """

    pair: SpiralBevelGearPair
    b_c: float

    @property
    def omega_n(self) -> float:
        """ω_n = √(k0/m_e) (rad/s)."""
        return self.pair.omega_n

    @property
    def force_scale(self) -> float:
        """Force scale k0 b_c (N)."""
        return self.pair.k0_mean * self.b_c

    @property
    def D(self) -> float:
        """Non-dimensional half backlash b_n/b_c."""
        return self.pair.b_n / self.b_c

    # speed
    def omega_from_rpm(self, rpm: Any) -> Any:
        """ω = ω_e/ω_n (non-dimensional) from pinion speed (rpm)."""
        return 2.0 * np.pi * self.pair.z1 * np.asarray(rpm, dtype=float) / 60.0 / self.omega_n

    def rpm_from_omega(self, omega: Any) -> Any:
        """Pinion speed (rpm) from ω (non-dimensional)."""
        return np.asarray(omega, dtype=float) * self.omega_n * 60.0 / (2.0 * np.pi * self.pair.z1)

    def hz_from_omega(self, omega: Any) -> Any:
        """Mesh frequency (Hz) from ω (non-dimensional); a frequency in orders of the mesh times ω likewise."""
        return np.asarray(omega, dtype=float) * self.omega_n / (2.0 * np.pi)

    # length
    def u_from_m(self, x: Any) -> Any:
        """Non-dimensional displacement from metres."""
        return np.asarray(x, dtype=float) / self.b_c

    def m_from_u(self, u: Any) -> Any:
        """Metres from non-dimensional displacement."""
        return np.asarray(u, dtype=float) * self.b_c

    def u_from_um(self, x: Any) -> Any:
        """Non-dimensional displacement from micrometres."""
        return np.asarray(x, dtype=float) * 1e-6 / self.b_c

    def um_from_u(self, u: Any) -> Any:
        """Micrometres from non-dimensional displacement."""
        return np.asarray(u, dtype=float) * self.b_c * 1e6

    # force
    def force_from_N(self, F: Any) -> Any:
        """Non-dimensional force F/(k0 b_c) from newtons."""
        return np.asarray(F, dtype=float) / self.force_scale

    def N_from_force(self, f: Any) -> Any:
        """Newtons from non-dimensional force (times k0 b_c)."""
        return np.asarray(f, dtype=float) * self.force_scale

    # time
    def tau_from_s(self, t: Any) -> Any:
        """Non-dimensional time τ = ω_n t from seconds."""
        return np.asarray(t, dtype=float) * self.omega_n

    def s_from_tau(self, tau: Any) -> Any:
        """Seconds from non-dimensional time τ."""
        return np.asarray(tau, dtype=float) / self.omega_n

    # load
    def fp_from_torque(self, T1: float, T2: float | None = None) -> float:
        """f_p = F_p/(k0 b_c) (non-dimensional) from pinion torque T1 (N·m), T2 default balanced."""
        return float(self.pair.static_force(T1, T2) / self.force_scale)

    def torque_from_fp(self, fp: Any) -> Any:
        """Pinion torque T1 (N·m) giving f_p with balanced torques: T1 = f_p k0 b_c R1."""
        return np.asarray(fp, dtype=float) * self.force_scale * self.pair.R1

    # mesh coefficients
    def xi_from_c(self, c: Any) -> Any:
        """Damping ratio ξ = c/(2 m_e ω_n) from a damping coefficient (N·s/m)."""
        return np.asarray(c, dtype=float) / (2.0 * self.pair.m_e * self.omega_n)

    def c_from_xi(self, xi: Any) -> Any:
        """Damping coefficient (N·s/m) from a damping ratio."""
        return np.asarray(xi, dtype=float) * 2.0 * self.pair.m_e * self.omega_n

    def kappa_from_k(self, k: Any) -> Any:
        """Stiffness ratio κ = k/k0 from a stiffness (N/m)."""
        return np.asarray(k, dtype=float) / self.pair.k0_mean

    def k_from_kappa(self, kappa: Any) -> Any:
        """Stiffness (N/m) from a stiffness ratio."""
        return np.asarray(kappa, dtype=float) * self.pair.k0_mean


# ---------------------------------------------------------------------------- summaries
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
    out: dict[str, Any] = {
        "name": pair.name,
        "z1": pair.z1,
        "z2": pair.z2,
        "ratio": pair.ratio,
        "delta1_deg": _deg(pair.delta1),
        "delta2_deg": _deg(pair.delta2),
        "Sigma_deg": _deg(pair.Sigma),
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
        "b_c_m": sc.b_c if sc else None,
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
            out["fp"] = Fp / sc.force_scale
        out["mesh_force_components_N"] = {
            g: {k: v * Fp for k, v in comp.items()} for g, comp in mv.force_components().items()
        }
    return out


def summary_rows(summary: dict[str, Any]) -> list[tuple[str, str, str, str]]:
    """Rows (quantity, value, unit, note) of a readable geometry table built from :func:`geometry_summary`.

    Values are converted to the units engineers read (mm, deg, Hz, N/µm); assumed inputs carry
    ``assumed (<name>)`` in the note column (their sources are in ``summary["assumptions"]``).
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
        rows.append(("stiffness per face width c_γ", fmt(summary["c_gamma_N_per_m2"] * 1e-9), "N/(mm·µm)", note("c_gamma")))
    rows += [
        ("mean mesh stiffness k0", fmt(summary["k0_N_per_m"] * 1e-6), "N/µm", note("k0")),
        ("natural frequency ω_n", fmt(summary["omega_n_rad_s"]), "rad/s", ""),
        ("natural frequency f_n", fmt(summary["f_n_Hz"]), "Hz", ""),
        ("mean damping ratio ξ0", fmt(summary["xi0"]), "", note("xi0", "c0")),
        ("mean damping c0", fmt(summary["c0_N_s_per_m"]), "N·s/m", note("c0", "xi0")),
        ("half backlash b_n", fmt(summary["b_n_m"] * 1e3), "mm", note("j_n")),
        ("characteristic length b_c", fmt(None if summary["b_c_m"] is None else summary["b_c_m"] * 1e3), "mm", ""),
        ("non-dimensional backlash D", fmt(summary["D"]), "", ""),
        ("pinion hand / loaded flank", f"{summary['pinion_hand']} / {summary['pinion_drive_flank']}", "", note("hand", "drive_side")),
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
    return rows
