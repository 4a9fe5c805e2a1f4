"""Steady response of a multi-DOF system at one point, and the per-mesh outputs every analysis reports.

:func:`simulate_system` integrates one point of a :class:`~geardyn.systems.SystemModel` with its time
history and returns a :class:`SystemSteadyState` whose ``to_json`` has the keys of
``geardyn simulate --json`` (those of the reference mesh, whose δ is the 1-DOF model's u) plus
``meshes``: one entry per mesh with its DTE (non-dimensional and µm), mesh force (N) and dynamic
factor, contact fractions and impact state, and ``clearances`` likewise.

Mesh force ``s_m = C_m(θ) δ_m' + K_m(θ) f(δ_m; D_m)`` (units k_ref b_c); the dynamic factor is its
largest value over the history divided by the static mesh force (the mesh force of the static
equilibrium at mean stiffness in drive contact, ``K̄ q̃ = F̃ + Σ k_m D_m V_m``, least-norm for
rigid-body modes; for the paper's torsional pair exactly f_p).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .._docfill import OPTIONS, POINT, SYSTEM, fill
from ..integrate_ndof import SystemBatchResult, initial_state, trajectory
from ..model import IntegrationOptions
from .classify import IMPACT_LABELS, detect_period, impact_state, period_label
from .steady import SteadyState

__all__ = ["SystemSteadyState", "simulate_system", "static_mesh_forces", "mesh_forces", "rigid_modes"]


def _num(x: Any) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


@fill(SYSTEM)
def rigid_modes(model: Any, rtol: float = 1e-9) -> np.ndarray:
    """Orthonormal basis (n, r) of the rigid-body modes that decouple from the dynamics.

    Directions φ with K̄ φ = 0 (mean stiffness of bearings, meshes and clearances), C̃_b φ = 0 and
    φ·F̃ = 0: along them the system drifts freely and their Floquet multipliers are exactly 1.

    Parameters
    ----------
    {{model}}
    rtol : float
        Eigenvalues of K̄ below ``rtol`` times its largest (at least 1) count as zero.

    Returns
    -------
    ndarray (n, r)
        Orthonormal columns; r = 0 when no zero-stiffness direction is also free of damping and load.
    """
    Kt = np.array(model.Kb, dtype=float)
    for i, m in enumerate(model.meshes):
        Kt += m.k * np.outer(model.V[i], model.V[i])
    for i, k in enumerate(model.kc):
        Kt += k * np.outer(model.Vc[i], model.Vc[i])
    w, U = np.linalg.eigh(Kt)
    tol = rtol * max(1.0, float(np.max(np.abs(w))))
    R = U[:, np.abs(w) <= tol]
    if R.shape[1] and (np.max(np.abs(np.asarray(model.Cb) @ R)) > tol or np.max(np.abs(np.asarray(model.F) @ R)) > 1e-9):
        return np.zeros((model.n, 0))
    return R


@fill(SYSTEM)
def static_mesh_forces(model: Any) -> np.ndarray:
    """Static mesh force of every mesh (units k_ref b_c), see the module docstring.

    Parameters
    ----------
    {{model}}

    Returns
    -------
    ndarray (meshes,)
        k_m (V_m·q̃ − D_m) at the static equilibrium K̄ q̃ = F̃ + Σ k_m D_m V_m (least-norm solution).
    """
    Kt = np.array(model.Kb, dtype=float)
    rhs = np.array(model.F, dtype=float)
    for i, m in enumerate(model.meshes):
        Kt += m.k * np.outer(model.V[i], model.V[i])
        rhs += m.k * m.D * model.V[i]
    q = np.linalg.lstsq(Kt, rhs, rcond=1e-12)[0]
    return np.array([m.k * (model.V[i] @ q - m.D) for i, m in enumerate(model.meshes)])


@fill(SYSTEM)
def mesh_forces(model: Any, tau: np.ndarray, deltas: np.ndarray) -> np.ndarray:
    """Mesh forces s_m = C_m(θ) δ_m' + K_m(θ) f(δ_m; D_m) from the element deflections.

    Parameters
    ----------
    {{model}}
    tau : ndarray (K,)
        Times τ.
    deltas : ndarray (K, elements, 2)
        Deflection δ and its rate δ' of every element (meshes first) at those times.

    Returns
    -------
    ndarray (K, meshes)
        Mesh forces in units k_ref b_c.
    """
    tau = np.asarray(tau, dtype=float)
    th = model.omega * tau
    out = []
    for i, m in enumerate(model.meshes):
        c = m.coefficients()
        C = np.full_like(th, c[0, 0, 0])
        Kk = np.full_like(th, c[1, 0, 0])
        for j in range(1, c.shape[1]):
            ph = j * m.ratio * th
            C = C + c[0, j, 0] * np.cos(ph) + c[0, j, 1] * np.sin(ph)
            Kk = Kk + c[1, j, 0] * np.cos(ph) + c[1, j, 1] * np.sin(ph)
        d = deltas[:, i, 0]
        f = d - np.clip(d, -m.D, m.D)
        out.append(C * deltas[:, i, 1] + Kk * f)
    return np.stack(out, axis=1) if out else np.zeros((tau.size, 0))


def mesh_entries(model: Any, res: SystemBatchResult, point: int = 0, tau: np.ndarray | None = None,
                 deltas: np.ndarray | None = None) -> list[dict[str, Any]]:
    """The ``meshes`` list of a point: name, u_min, u_max, amplitude, rms, mean, impact, contact
    fractions, dynamic_factor, DTE in µm and mesh forces in N (the last from a history, if given)."""
    sc = model.scaling
    um = sc.b_c * 1e6
    ok = bool(res.ok[point])
    fs = static_mesh_forces(model)
    force = mesh_forces(model, tau, deltas) if (tau is not None and deltas is not None and ok) else None
    out = []
    for i, m in enumerate(model.meshes):
        lo, hi = float(res.element_u_min(i)[point]), float(res.element_u_max(i)[point])
        fr = res.element_fractions(i)[point]
        e: dict[str, Any] = {
            "name": m.name,
            "u_min": _num(lo), "u_max": _num(hi), "amplitude": _num(0.5 * (hi - lo)),
            "rms": _num(res.element_rms(i)[point]), "mean": _num(res.element_mean(i)[point]),
            "impact": IMPACT_LABELS[impact_state(lo, m.D)],
            "contact_fractions": {"drive": _num(fr[0]), "separation": _num(fr[1]), "back": _num(fr[2])},
            "dte_min_um": _num(lo * um), "dte_max_um": _num(hi * um), "dte_amplitude_um": _num(0.5 * (hi - lo) * um),
            "static_force_N": _num(fs[i] * sc.force_scale),
            "dynamic_factor": None,
        }
        if force is not None:
            fmax = float(np.max(force[:, i]))
            e["mesh_force_max_N"] = _num(fmax * sc.force_scale)
            e["mesh_force_min_N"] = _num(np.min(force[:, i]) * sc.force_scale)
            e["dynamic_factor"] = _num(fmax / fs[i]) if fs[i] > 0 else None
        out.append(e)
    return out


def clearance_entries(model: Any, res: SystemBatchResult, point: int = 0) -> list[dict[str, Any]]:
    """Per clearance: name, δ extremes, contact fractions and impact state."""
    M = len(model.meshes)
    out = []
    for c, name in enumerate(model.clearance_names):
        e = M + c
        lo, hi = float(res.element_u_min(e)[point]), float(res.element_u_max(e)[point])
        fr = res.element_fractions(e)[point]
        out.append({"name": name, "u_min": _num(lo), "u_max": _num(hi), "amplitude": _num(0.5 * (hi - lo)),
                    "impact": IMPACT_LABELS[impact_state(lo, model.Dc[c])],
                    "contact_fractions": {"drive": _num(fr[0]), "separation": _num(fr[1]), "back": _num(fr[2])}})
    return out


def system_state0(model: Any, state0: Sequence[float] | None) -> np.ndarray:
    """A full initial state: (u0, v0) of the reference mesh (:func:`~geardyn.integrate_ndof.initial_state`),
    a full (2n,) state as given, or the default."""
    if state0 is None:
        return initial_state(model)
    s = np.asarray(state0, dtype=float)
    if s.shape == (2,):
        return initial_state(model, float(s[0]), float(s[1]))
    return s


@dataclass
@fill(POINT, OPTIONS)
class SystemSteadyState(SteadyState):
    """Steady response of one system point (non-dimensional); see :func:`simulate_system`.

    Attributes
    ----------
    {{model, options}}
    state0 : ndarray (2n,)
        The initial state.
    traj : SystemTrajectory
        The integrated trajectory with its time history.
    summary : dict
        The keys of ``simulate --json`` (reference mesh) plus ``meshes``, ``clearances`` and ``labels``.
    """

    def to_json(self) -> dict[str, Any]:
        """Keys of ``simulate --json`` (reference mesh) plus ``meshes``, ``clearances``, ``labels``."""
        return dict(self.summary, poincare=self.poincare.tolist())


@fill(POINT)
def simulate_system(model: Any, options: IntegrationOptions = IntegrationOptions(),
                    state0: Sequence[float] | None = None, *, history_periods: int = 32) -> SystemSteadyState:
    """Integrate one system point and summarise its steady response.

    Parameters
    ----------
    {{model}}
    options : IntegrationOptions
        Transient and recorded periods, step and accuracy.
    state0 : (u0, v0) of the reference mesh, or a full (2n,) state, optional
        Default: the model's default initial state.
    history_periods : int
        Forcing periods of history kept (mesh forces and the dynamic factor are taken over them).

    Returns
    -------
    SystemSteadyState
    """
    s0 = system_state0(model, state0)
    t = trajectory(model, s0, options, history_periods=history_periods)
    res = t.summary
    ok = bool(res.ok[0])
    period = detect_period(res.poincare[0]) if ok else -1
    r = res.reference
    mesh = model.meshes[r]
    lo = float(res.u_min[0])
    fr = res.contact_fractions[0]
    p = model.period_multiple()
    summary = {
        "omega": model.omega,
        "motion": period_label(period) if ok else "diverged",
        "lle": None,
        "period": (period * (p or 1)) if period > 0 else None,
        "impact": IMPACT_LABELS[impact_state(lo, mesh.D)],
        "amplitude": _num(res.amplitude[0]), "rms": _num(res.rms[0]), "mean": _num(res.mean[0]),
        "u_min": _num(lo), "u_max": _num(res.u_max[0]),
        "contact_fractions": {"drive": _num(fr[0]), "separation": _num(fr[1]), "back": _num(fr[2])},
        "status": "ok" if ok else "diverged",
        "reference_mesh": mesh.name,
        "labels": list(model.labels),
        "forcing_period_multiple": p,
        "meshes": mesh_entries(model, res, 0, t.tau, t.deltas),
        "clearances": clearance_entries(model, res, 0),
    }
    return SystemSteadyState(model, options, s0, t, summary)
