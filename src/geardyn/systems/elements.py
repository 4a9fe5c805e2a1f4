"""What a :class:`~geardyn.systems.SystemModel` gives the System contract beyond its arrays: the elements'
deflections, the default initial state, the rigid-body modes and the mean trace of the Jacobian.

Element e is mesh e for e < meshes, then the clearances; its deflection is ``δ_m = V[m]·q̃ − E_m(θ)``
(the dynamic transmission error over b_c) or ``δ_c = Vc[c]·q̃``.  The reference mesh's δ is the 1-DOF
model's u.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..series import series_values
from .balance import mean_stiffness

__all__ = ["element_series", "initial_state", "rigid_modes", "mean_trace"]


def element_series(model: Any, x: np.ndarray, tau: np.ndarray | float) -> np.ndarray:
    """δ and δ' of every element for states x at times τ.

    A mesh's δ is V_m·q̃ minus its transmission error e_m(θ); a clearance's is Vc·q̃.

    Parameters
    ----------
    model : SystemModel
    x : ndarray (..., 2n)
        States (q̃, q̃').
    tau : ndarray or float
        Times τ, broadcast against the leading axes of ``x``.

    Returns
    -------
    ndarray (..., elements, 2)
        δ and δ' of the meshes, then the clearances, then each rolling bearing's x and y.
    """
    x = np.asarray(x, dtype=float)
    n = model.n
    q, v = x[..., :n], x[..., n:]
    theta = model.omega * np.asarray(tau, dtype=float)
    out = []
    for m, w in zip(model.meshes, model.V):
        E, Ed = series_values(m.coefficients(), theta, (2,), ratio=m.ratio, derivative=True)
        out.append(np.stack([q @ w - E, v @ w - model.omega * Ed], axis=-1))
    for w in (*model.Vc, *model.Vb):  # the clearances, the rolling bearings' x and y relative displacements
        out.append(np.stack([q @ w, v @ w], axis=-1))
    return np.stack(out, axis=-2)


def initial_state(model: Any, u0: float = 0.0, v0: float = 0.0) -> np.ndarray:
    """The state (2n,) at θ = 0 with the reference mesh's (δ, δ') = (u0, v0) and every other mesh's (0, 0).

    The least-norm q̃, q̃' solving ``V q̃ = E(0) + target``, ``V q̃' = ω E'(0) + target'`` (for the
    paper's torsional pair, exactly the 1-DOF start (u0, v0) with the rigid-body coordinate at rest).

    Parameters
    ----------
    model : SystemModel
    u0, v0 : float
        The reference mesh's deflection and its rate at θ = 0.

    Returns
    -------
    ndarray (2n,)
    """
    n = model.n
    M = len(model.meshes)
    zero = np.zeros(2 * n)
    ev = element_series(model, zero, 0.0)[:M]  # (M, 2) = (−E, −ωE')
    tq = -ev[:, 0]
    tv = -ev[:, 1]
    r = model.reference
    tq[r] += u0
    tv[r] += v0
    pinv = np.linalg.pinv(np.asarray(model.V))
    return np.concatenate([pinv @ tq, pinv @ tv])


def rigid_modes(model: Any, rtol: float = 1e-9) -> np.ndarray:
    """Orthonormal basis (n, r) of the rigid-body modes that decouple from the dynamics.

    Directions φ with K̄ φ = 0 (mean stiffness of bearings, meshes and clearances), C̃_b φ = 0 and
    φ·F̃ = 0: along them the system drifts freely and their Floquet multipliers are exactly 1.  Eigenvalues
    of K̄ below ``rtol`` times its largest (at least 1) count as zero.

    Parameters
    ----------
    model : SystemModel
    rtol : float
        Relative threshold of a zero eigenvalue.

    Returns
    -------
    ndarray (n, r)
        Orthonormal columns; r = 0 when no zero-stiffness direction is also free of damping and load.
    """
    w, U = np.linalg.eigh(mean_stiffness(model))
    tol = rtol * max(1.0, float(np.max(np.abs(w))))
    R = U[:, np.abs(w) <= tol]
    if R.shape[1] and (
        np.max(np.abs(np.asarray(model.Cb) @ R)) > tol or np.max(np.abs(np.asarray(model.F) @ R)) > 1e-9
    ):
        return np.zeros((model.n, 0))
    return R


def mean_trace(model: Any) -> float:
    """−mean over a forcing period of trace(M̃⁻¹C̃(θ)): the mean trace of the Jacobian, the sum of the
    Lyapunov exponents.

    C̃ = C̃_b + Σ C_m(θ) V_m V_mᵀ + Σ cc Vc Vcᵀ (+ the rolling bearings' dampers); the mesh-damping harmonics
    average to zero, so only their mean 2ξ0 enters.  For the paper's 1-DOF pair this is −2ξ0.

    Parameters
    ----------
    model : SystemModel

    Returns
    -------
    float
        The mean trace per unit τ.
    """
    Mi = np.asarray(model.Mi)
    tr = float(np.trace(Mi @ model.Cb))
    for m, v in zip(model.meshes, model.V):
        tr += 2.0 * m.xi0 * float(v @ Mi @ v)  # harmonics average to 0
    for c, w in zip(model.cc, model.Vc):
        tr += c * float(w @ Mi @ w)
    for b, br in enumerate(model.bearings):
        x, y = model.Vb[2 * b : 2 * b + 2]
        tr += br.cx * float(x @ Mi @ x) + br.cy * float(y @ Mi @ y)
    return -tr
