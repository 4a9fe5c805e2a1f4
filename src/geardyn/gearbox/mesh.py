"""A mesh between two gears on shaft nodes: line of action, helical coupling and tooth stiffness.

Geometry (ISO 21771): with α_t = atan(tan α_n/cos β) the transverse pressure angle, the working transverse
pressure angle α_wt of a pair with profile shifts x1, x2 solves
``inv α_wt = inv α_t + 2 tan α_n (x1 + x2)/(z1 + z2)`` (inv α = tan α − α); the working pitch radii are
r_wl = r_bl/cos α_wt and the base helix angle β_b = atan(tan β cos α_t).

The line of action: with e_c the unit vector from the pinion's axis to the gear's (angle ψ, ``center_angle``,
with +x) and σ1 = ±1 the pinion's running sense about +z, the pinion's flank pushes the gear along

    n_t = cos α_wt (σ1 e_z × e_c) + sin α_wt e_c,        n = cos β_b n_t ± sin β_b e_z

(+ for a right-hand pinion, the convention of :func:`geardyn.systems.vectors.cylindrical_mesh_vector`).  A
point of a gear's section at r from its axis moves by ``u + φ × r`` (u the node's translation, φ its small
rotation: rx, ry about x and y and σ θ about z, θ positive in the shaft's running sense), so the mesh
deflection is

    δ = n·u1 + (r1 × n)·φ1 − n·u2 − (r2 × n)·φ2,      r1 = r_w1 e_c,  r2 = −r_w2 e_c

(any point of the line of action gives the same r × n): direction cosines on x, y, z, the tilt arms
(r × n)_x, (r × n)_y on rx, ry — the helical axial force's moment on the shafts — and σ (r × n)_z = r_b cos β_b
on θ.  A spur pair (β = 0) has no axial or tilt entries.

Stiffness and STE from the tooth model (:mod:`geardyn.tooth`, potential-energy method) are along the
transverse line of action (force T1/r_b1); along n they are ``k_n = k_t/cos² β_b`` and ``e_n = e_t cos β_b``
(the same energy ½ k_t δ_t² with δ_t = δ/cos β_b).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ..standards.iso6336 import involute
from .gear import Gear

__all__ = ["working_pressure_angle", "pair_geometry_of", "mesh_vector", "tooth_excitation"]


def working_pressure_angle(g1: Gear, g2: Gear) -> float:
    """α_wt of the pair (the involute function inverted by Newton's method), in rad.

    Parameters
    ----------
    g1, g2 : Gear
        Pinion and gear (their normal pressure angle, helix angle, teeth and profile shifts; ``g1``'s
        pressure and helix angles are used for the pair).
    """
    at = g1.transverse_pressure_angle
    target = involute(at) + 2.0 * math.tan(g1.pressure_angle) * (g1.profile_shift + g2.profile_shift) / (
        g1.teeth + g2.teeth
    )
    a = at
    for _ in range(60):
        step = (involute(a) - target) / math.tan(a) ** 2
        a -= step
        if abs(step) < 1e-16:
            break
    if not 0 < a < math.pi / 2:
        raise ModelError(f"profile shifts {g1.profile_shift:g}, {g2.profile_shift:g}: no working pressure angle")
    return a


def pair_geometry_of(mesh: str, g1: Gear, g2: Gear) -> dict[str, float]:
    """Check that the two gears can mesh and return α_wt, β_b, the base and working pitch radii, a_w.

    Parameters
    ----------
    mesh : str
        Name of the mesh (for error messages).
    g1, g2 : Gear
        Pinion and gear; they need the same module, pressure and helix angles and (helical) opposite hands.

    Returns
    -------
    dict[str, float]
        ``alpha_wt`` and ``beta_b`` (rad), ``rb1``, ``rb2``, ``rw1``, ``rw2`` and ``a_w`` (m).
    """
    who = f"mesh {mesh!r}"
    for key in ("module", "pressure_angle", "helix_angle"):
        a, b = getattr(g1, key), getattr(g2, key)
        if abs(a - b) > 1e-12 * max(abs(a), 1e-300):
            unit, f = ("mm", 1e3) if key == "module" else ("deg", 180 / math.pi)
            raise ModelError(
                f"{who}: {key}: gear {g1.name!r} has {a * f:g} {unit}, gear {g2.name!r} {b * f:g} {unit}; "
                "meshing gears need the same"
            )
    if g1.helix_angle > 0 and g1.hand == g2.hand:
        raise ModelError(
            f"{who}: hand: gears {g1.name!r} and {g2.name!r} are both {g1.hand}-handed; an external helical pair "
            "has opposite hands"
        )
    awt = working_pressure_angle(g1, g2)
    bb = math.atan(math.tan(g1.helix_angle) * math.cos(g1.transverse_pressure_angle))
    rb1, rb2 = g1.base_radius, g2.base_radius
    return {
        "alpha_wt": awt,
        "beta_b": bb,
        "rb1": rb1,
        "rb2": rb2,
        "rw1": rb1 / math.cos(awt),
        "rw2": rb2 / math.cos(awt),
        "a_w": (rb1 + rb2) / math.cos(awt),
    }


def mesh_vector(
    geo: dict[str, float], center_angle: float, sense1: int, sense2: int, hand1: str
) -> tuple[np.ndarray, np.ndarray]:
    """The two nodes' entries of the mesh vector over ``x, y, z, rx, ry, theta`` (pinion, gear).

    Parameters
    ----------
    geo : dict[str, float]
        The pair geometry of :func:`pair_geometry_of` (``alpha_wt``, ``beta_b`` in rad, ``rw1``, ``rw2`` in m).
    center_angle : float
        Angle ψ of the line of centres, pinion to gear, from +x (rad).
    sense1, sense2 : int
        Running senses of the pinion's and the gear's shafts (+1 counterclockwise about +z, −1 clockwise).
    hand1 : str
        Hand of the pinion's helix, ``"right"`` or ``"left"``.
    """
    ec = np.array([math.cos(center_angle), math.sin(center_angle), 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    a, bb = geo["alpha_wt"], geo["beta_b"]
    nt = math.cos(a) * sense1 * np.cross(ez, ec) + math.sin(a) * ec
    n = math.cos(bb) * nt + (1.0 if hand1 == "right" else -1.0) * math.sin(bb) * ez
    out = []
    for sign, r, sense in ((1.0, geo["rw1"] * ec, sense1), (-1.0, -geo["rw2"] * ec, sense2)):
        m = np.cross(r, n)
        out.append(sign * np.array([n[0], n[1], n[2], m[0], m[1], sense * m[2]]))
    return out[0], out[1]


def tooth_excitation(
    g1: Gear, g2: Gear, geo: dict[str, float], torque: float, harmonics: int, E: float, nu: float
) -> dict[str, object]:
    """Mean stiffness (N/m), relative stiffness harmonics and STE harmonics (m) along n, from the tooth model.

    The pair's stiffness and equivalent STE over one mesh cycle (:func:`geardyn.tooth.mesh.mesh_stiffness`,
    the pinion torque ``torque`` in N·m) as Fourier series of the mesh phase, converted to the normal
    direction (module docstring).

    Parameters
    ----------
    g1, g2 : Gear
        Pinion and gear.
    geo : dict[str, float]
        The pair geometry of :func:`pair_geometry_of` (its ``beta_b``, rad, converts to the normal direction).
    torque : float
        Pinion torque (N·m, > 0).
    harmonics : int
        Number of Fourier harmonics kept.
    E : float
        Young's modulus of the gears (Pa).
    nu : float
        Poisson's ratio of the gears.
    """
    from ..tooth.geometry import pair_geometry
    from ..tooth.mesh import mesh_stiffness
    from ..tooth.table import table_of

    if not (math.isfinite(torque) and torque > 0):
        raise ModelError(f"torque: the tooth model needs a pinion torque > 0 N*m, got {torque!r}")
    pg = pair_geometry(
        g1.teeth,
        g2.teeth,
        g1.module,
        alpha_n=g1.pressure_angle,
        beta=g1.helix_angle,
        face_width=min(g1.face_width, g2.face_width),
        x1=g1.profile_shift,
        x2=g2.profile_shift,
        E=E,
        nu=nu,
    )
    ms = mesh_stiffness(pg, torque, cycles=1)
    s = table_of(ms).series(harmonics, 1.0)
    cb = math.cos(geo["beta_b"])
    return {
        "stiffness": float(s["k0"]) / cb**2,
        "kappa": tuple(map(float, s["kappa"])),
        "phi_k": tuple(map(float, s["phi_k"])),
        "e": tuple(float(x) * cb for x in s.get("eps", ())),
        "phi_e": tuple(map(float, s.get("phi_e", ()))),
        "contact_ratio": float(pg.eps_alpha + pg.eps_beta),
    }
