"""Mesh-point vectors of a spiral bevel pair and the directional radii built from them.

The frame (origin at the apex, pinion axis ``+y``) is described in :mod:`geardyn.geometry`.
:func:`mesh_vectors` builds the position vectors ``r_l``, the rotation axes ``j_l`` and the common
flank normal ``n`` from the pitch cone angles, the spiral and pressure angles, the hand of spiral
and the loaded flank; :class:`MeshVectors` holds them and gives the directional radii
``R_l = n · (j_l × r_l)`` and the components of the mesh force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

__all__ = ["MeshVectors", "mesh_vectors"]


@dataclass(frozen=True, eq=False)
class MeshVectors:
    """Mesh-point vectors of a spiral bevel pair (frame: origin at the apex, see :mod:`geardyn.geometry`).

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

    def rotation_sense(self) -> tuple[str, str]:
        """Running sense of (pinion, gear), each viewed from its back looking towards the apex.

        Returns
        -------
        tuple of str
            ``"clockwise"`` or ``"counterclockwise"`` for the pinion and for the gear.
        """
        return tuple(  # type: ignore[return-value]
            "counterclockwise" if j @ a > 0 else "clockwise" for j, a in ((self.j1, self.a1), (self.j2, self.a2))
        )

    def to_dict(self) -> dict[str, list[float]]:
        """Every vector as a list of three floats, keyed by its name (JSON-ready)."""
        return {f.name: [float(x) for x in getattr(self, f.name)] for f in fields(self)}


def mesh_vectors(
    *,
    alpha_n: float,
    beta_m: float,
    Sigma: float,
    delta1: float,
    delta2: float,
    r1: float,
    r2: float,
    hand: str,
    drive_side: str,
) -> MeshVectors:
    """Mesh-point vectors r_l, j_l, n_l built from (α_n, β_m, δ_l, Σ, hand, drive side).

    The common pitch plane at the mesh point is spanned by the generatrix ``g`` and ``z``.
    In it the tooth trace of the pinion makes the angle β_m with ``g``; a left-hand pinion's
    trace leans towards ``+z`` going outwards (seen from the front of the pinion the outer half
    of the tooth is inclined counterclockwise).  The spiral angle grows towards the heel
    (face-milled teeth), so the concave flank of the pinion faces the centre of curvature of
    the trace.  The loaded flank's normal is tilted out of the pitch plane by α_n, towards the
    gear (the separating component).

    Parameters
    ----------
    alpha_n, beta_m : float
        Normal pressure angle and mean spiral angle (rad).
    Sigma : float
        Shaft angle Σ (rad).
    delta1, delta2 : float
        Pitch cone angles of pinion and gear (rad).
    r1, r2 : float
        Distance from the mesh point to the pinion / gear axis (m).
    hand : {"left", "right"}
        Hand of spiral of the pinion.
    drive_side : {"concave", "convex"}
        Loaded flank of the pinion.

    Returns
    -------
    MeshVectors
    """
    d1, S = delta1, Sigma
    a1 = np.array([0.0, 1.0, 0.0])
    a2 = np.array([math.sin(S), math.cos(S), 0.0])
    g = np.array([math.sin(d1), math.cos(d1), 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    p = np.array([math.cos(d1), -math.sin(d1), 0.0])  # pinion's outward pitch-cone normal: towards the gear
    h = 1.0 if hand == "left" else -1.0
    c = 1.0 if drive_side == "concave" else -1.0
    cb, sb = math.cos(beta_m), math.sin(beta_m)
    ca, sa = math.cos(alpha_n), math.sin(alpha_n)
    trace = cb * g + h * sb * ez  # pinion tooth trace, from toe to heel
    nu = -h * sb * g + cb * ez  # in-plane unit normal of the trace
    bend = h * nu  # direction in which the trace curves (β_m grows towards the heel)
    nu_loaded = c * bend  # in-plane normal of the loaded pinion flank (concave flank faces `bend`)
    assert abs(trace @ nu) < 1e-12
    t = ez * math.copysign(1.0, nu_loaded @ ez)  # running direction: the driver pushes forwards
    n = ca * nu_loaded + sa * p
    n = n / np.linalg.norm(n)
    r1v = (r1 / math.sin(d1)) * g
    r2v = (r2 / math.sin(delta2)) * g
    j1 = a1 * math.copysign(1.0, np.cross(a1, r1v) @ t)
    j2 = a2 * math.copysign(1.0, np.cross(a2, r2v) @ t)
    return MeshVectors(r1=r1v, r2=r2v, j1=j1, j2=j2, n1=n, n2=n.copy(), a1=a1, a2=a2, g=g, t=t, p=p)
