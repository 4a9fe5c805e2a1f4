"""Mesh vectors from gear geometry.

The mesh deflection along the line of action is ``δ = v·q − e`` with, for a pinion (1) driving a gear (2),

    δ = n·x1 + R1 θ1 − n·x2 − R2 θ2,

``n`` the unit flank normal (the direction of the force on the gear), ``x_l`` the body translations in
the global frame, θ_l the rotations about each body's axis j_l, positive in its running direction, and
``R_l = n·(j_l × r_l)`` the directional radii (for a bevel pair exactly the vectors of
:meth:`geardyn.geometry.SpiralBevelGearPair.mesh_vectors`).

Spur and helical pairs (:func:`cylindrical_mesh_vector`) lie in the x–y plane with the axes along z.
The line of centres from pinion to gear makes the angle ψ with +x; with the pinion running
counterclockwise (seen from +z) the transverse line of action is
``n_t = (sin(α_t − ψ), cos(α_t − ψ))`` (clockwise: ``(−sin(α_t + ψ)…)`` mirrored), and a helical pair adds
the axial component: ``n = cos β_b n_t ± sin β_b e_z`` (sign from the hand of the pinion), so
``R_l = r_bl cos β_b``.

References
----------
.. [1] A. Kahraman, R. Singh, "Interactions between time-varying mesh stiffness and clearance
   non-linearities in a geared system", J. Sound Vib. 146 (1991) 135–156 (the bending–torsional
   spur-pair coordinates).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ..geometry import SpiralBevelGearPair

__all__ = ["bevel_mesh_vector", "cylindrical_mesh_vector", "pair_vector"]


def pair_vector(n: np.ndarray, R1: float, R2: float, dofs1, dofs2, body1: str, body2: str):
    """The mesh vector ``[n, R1, −n, −R2]`` restricted to the DOFs the two bodies have.

    Parameters
    ----------
    n : ndarray, shape (3,)
        Unit flank normal (force on the gear).
    R1, R2 : float
        Directional radii (m).
    dofs1, dofs2 : sequence of str
        The DOFs of the pinion and the gear.
    body1, body2 : str
        Their names.

    Returns
    -------
    tuple of ((str, str), float)
    """
    out = []
    for body, dofs, sign, R in ((body1, dofs1, 1.0, R1), (body2, dofs2, -1.0, R2)):
        comp = {"x": n[0], "y": n[1], "z": n[2], "theta": R}
        for d in dofs:
            out.append(((body, d), sign * float(comp[d])))
    return tuple(out)


def cylindrical_mesh_vector(
    body1: str,
    body2: str,
    dofs1,
    dofs2,
    *,
    pressure_angle: float,
    base_radius1: float,
    base_radius2: float,
    helix_angle: float = 0.0,
    center_angle: float = 0.0,
    pinion_rotation: str = "counterclockwise",
    hand: str = "right",
):
    """Mesh vector of an external spur or helical pair (see the module docstring).

    Parameters
    ----------
    body1, body2 : str
        Pinion (driver) and gear.
    dofs1, dofs2 : sequence of str
        Their DOFs.
    pressure_angle : float
        Normal pressure angle α_n (rad); for spur gears the pressure angle.
    base_radius1, base_radius2 : float
        Transverse base radii (m).
    helix_angle : float
        Helix angle β (rad); 0 for spur gears.
    center_angle : float
        Angle ψ of the line of centres (pinion → gear) with +x (rad).
    pinion_rotation : {"counterclockwise", "clockwise"}
        Running sense of the pinion seen from +z.
    hand : {"right", "left"}
        Hand of the pinion's helix (sign of the axial component).

    Returns
    -------
    tuple of ((str, str), float)
    """
    if not 0 < pressure_angle < math.pi / 2:
        raise ModelError(f"pressure_angle: must be in (0°, 90°), got {math.degrees(pressure_angle):g}°")
    if not 0 <= helix_angle < math.pi / 2:
        raise ModelError(f"helix_angle: must be in [0°, 90°), got {math.degrees(helix_angle):g}°")
    for nm, r in (("base_radius1", base_radius1), ("base_radius2", base_radius2)):
        if not r > 0:
            raise ModelError(f"{nm}: must be > 0 m, got {r!r}")
    if pinion_rotation not in ("counterclockwise", "clockwise"):
        raise ModelError(f"pinion_rotation: must be 'counterclockwise' or 'clockwise', got {pinion_rotation!r}")
    if hand not in ("right", "left"):
        raise ModelError(f"hand: must be 'right' or 'left', got {hand!r}")
    alpha_t = math.atan(math.tan(pressure_angle) / math.cos(helix_angle))
    beta_b = math.atan(math.tan(helix_angle) * math.cos(alpha_t))
    if pinion_rotation == "counterclockwise":
        nt = np.array([math.sin(alpha_t - center_angle), math.cos(alpha_t - center_angle)])
    else:  # the mirror image about the line of centres
        nt = np.array([math.sin(alpha_t + center_angle), -math.cos(alpha_t + center_angle)])
    ax = (1.0 if hand == "right" else -1.0) * math.sin(beta_b)
    cb = math.cos(beta_b)
    n = np.array([cb * nt[0], cb * nt[1], ax])
    return pair_vector(n, base_radius1 * cb, base_radius2 * cb, dofs1, dofs2, body1, body2)


def bevel_mesh_vector(pair: SpiralBevelGearPair, body1: str, body2: str, dofs1, dofs2):
    """Mesh vector of a spiral bevel pair from its geometry (frame of :mod:`geardyn.geometry`).

    Parameters
    ----------
    pair : SpiralBevelGearPair
        The pair; its ``mesh_vectors()`` give n, j_l, r_l and R_l = n·(j_l × r_l).
    body1, body2 : str
        Pinion and gear bodies.
    dofs1, dofs2 : sequence of str
        Their DOFs (translations in the pair's frame: origin at the apex, pinion axis y).

    Returns
    -------
    tuple of ((str, str), float)
    """
    mv = pair.mesh_vectors()
    return pair_vector(mv.n1, mv.R1, mv.R2, dofs1, dofs2, body1, body2)
