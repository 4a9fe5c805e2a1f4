"""The loads of a system must not drive a free rigid-body motion.

A direction φ that no stiffness holds (K̄φ = 0 with the mean stiffness of the connections, meshes and clearances:
a free rotation of a gear train or a planetary set) is a rigid-body motion.  Mean loads with a component along it,
Fᵀφ ≠ 0, accelerate the whole train without bound: there is no steady state, the integration diverges and no
periodic analysis has a solution.  :func:`check_balance` refuses such a system in one line and names the load
that would balance it: a torque (or force) T_j on one DOF j of the motion with Fᵀφ + T_j φ_j = 0 (for r free
motions, r such loads on r DOFs, Φ_Jᵀ T = −Φᵀ F).  The DOF chosen is, among those the loads leave free, the one
that carries the largest share of the motion's kinetic energy M_jj φ_j² (the output shaft of a pair: the heavier
gear; of a planetary driven at the sun: the carrier).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError

__all__ = ["check_balance", "free_motions"]

#: Relative size below which an eigenvalue of the mean stiffness counts as zero (as
#: :func:`geardyn.systems.elements.rigid_modes`).
RTOL = 1e-9
#: Largest net load along a free motion, relative to the sum of the magnitudes of the loads' contributions to it,
#: that counts as balanced: loads written to a few significant digits (the spur example's 20 and −60 N·m on base
#: radii in the ratio 2.9999958) are not refused for their rounding.
LOAD_RTOL = 1e-4
#: A DOF takes part in a free motion when its share of the motion's kinetic energy is above this.
SHARE_TOL = 1e-9


def free_motions(Kt: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the directions a mean stiffness does not hold.

    Parameters
    ----------
    Kt : ndarray (n, n)
        The mean stiffness (non-dimensional).

    Returns
    -------
    ndarray (n, r)
    """
    w, U = np.linalg.eigh(0.5 * (Kt + Kt.T))
    tol = RTOL * max(1.0, float(np.max(np.abs(w))))
    return U[:, np.abs(w) <= tol]


def mean_stiffness(model: Any) -> np.ndarray:
    """K̃_b + Σ k_m V_m V_mᵀ + Σ kc Vc Vcᵀ (+ the rolling bearings' K̃ on their rows): the mean stiffness."""
    Kt = np.array(model.Kb, dtype=float)
    for m, v in zip(model.meshes, model.V):
        Kt += m.k * np.outer(v, v)
    for k, w in zip(model.kc, model.Vc):
        Kt += k * np.outer(w, w)
    for b, br in enumerate(model.bearings):  # a rolling bearing holds its body's x and y
        x, y = model.Vb[2 * b : 2 * b + 2]
        Kt += br.K * (np.outer(x, x) + np.outer(y, y))
    return Kt


def _pick(phi: np.ndarray, share: np.ndarray, loaded: np.ndarray, rotation: np.ndarray) -> list[int]:
    """r DOFs on which r loads can balance the r motions ``phi`` (SI, (n, r)): unloaded rotations first, then
    unloaded translations, then the loaded ones, each group by its ``share`` of the kinetic energy."""
    order = sorted(range(phi.shape[0]), key=lambda j: (bool(loaded[j]), not bool(rotation[j]), -share[j]))
    out: list[int] = []
    for j in order:
        if np.linalg.matrix_rank(phi[out + [j]], tol=1e-9 * float(np.max(np.abs(phi)))) == len(out) + 1:
            out.append(j)
        if len(out) == phi.shape[1]:
            break
    return out


def check_balance(model: Any, desc: Any) -> None:
    """Refuse a system whose mean loads drive a free rigid-body motion (see the module docstring).

    Parameters
    ----------
    model : SystemModel
        The assembled, non-dimensional system (its mean stiffness and loads).
    desc : SystemDescription
        Its physical description (DOF names, mass matrix and SI loads for the message).

    Raises
    ------
    ModelError
        "the loads drive the free rotation of <bodies> (...); a torque of X N·m on <body>.theta would balance
        them".
    """
    R = free_motions(mean_stiffness(model))
    F = np.asarray(model.F)
    if not R.shape[1] or np.linalg.norm(F @ R) <= LOAD_RTOL * np.linalg.norm(np.abs(F) @ np.abs(R)):
        return
    s = np.asarray(model.scaling.dof_scales)
    phi = s[:, None] * R  # the motions in SI coordinates (m, rad)
    F = desc.load_vector()  # SI
    M = desc.mass_matrix()
    labels = list(desc.labels)
    rotation = np.array([d == "theta" for _, d in desc.dof_list])
    share = np.einsum("ij,ij->i", phi, M @ phi)
    moving = share > SHARE_TOL * float(np.max(share))
    J = _pick(phi, share, F != 0, rotation)
    T = np.linalg.lstsq(phi[J].T, -(phi.T @ F), rcond=None)[0]
    bodies = list(dict.fromkeys(labels[i].rsplit(".", 1)[0] for i in np.nonzero(moving)[0]))
    kind = "rotation" if np.any(rotation[moving]) else "motion"
    loads = " and ".join(
        f"a {'torque' if rotation[j] else 'force'} of {t:.6g} {'N·m' if rotation[j] else 'N'} on {labels[j]}"
        for j, t in zip(J, T)
    )
    raise ModelError(
        f"the loads drive the free {kind} of {', '.join(bodies)} (no stiffness holds it, so there is "
        f"no steady state); {loads} would balance them"
    )
