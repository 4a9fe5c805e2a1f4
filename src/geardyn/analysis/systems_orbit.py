"""Periodic orbits of multi-DOF systems by shooting, with all 2n Floquet multipliers.

Newton on ``P^n(x) − x = 0`` for the :class:`~geardyn.analysis.periodic.PeriodMap` of a
:class:`~geardyn.systems.SystemModel` (the map works on any system through the System protocol),
with a least-squares (minimum-norm) step: a free rigid-body mode makes ``M − I`` singular (a
rigid rotation of a whole solution is again a solution), and the minimum-norm step leaves it
where it is.  The multipliers of the rigid-body modes are exactly 1 (one Jordan pair per mode:
position and velocity); :class:`SystemOrbit` reports all 2n multipliers, and separately the
*elastic* ones — the eigenvalues of the monodromy on the quotient by the invariant rigid-body
subspace — which decide stability.  For the paper's torsional pair the elastic multipliers are the
1-DOF model's.

The periodic tools need a periodic forcing: for incommensurate mesh frequencies
(:meth:`SystemModel.period_multiple` is None) :func:`shoot_system` refuses with one line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .._docfill import POINT, SYSTEM, fill
from ..errors import ModelError
from ..integrate_ndof import forcing_period, integrate_batch
from ..model import DEFAULT_DTAU, IntegrationOptions
from ..status import Status
from .periodic.floquet import Floquet, floquet
from .periodic.map import MAP_THREADS, PeriodMap
from .periodic.orbit import _ShotOrbit, _hermite_extrema, _newton as _periodic_newton, GUESS_RECORD_PER_PERIOD, GUESS_TRANSIENT, SHOOT_MAX_ITER, SHOOT_TOL
from .systems_steady import IMPACT_LABELS, mesh_forces, rigid_modes, static_mesh_forces, system_state0

__all__ = ["SystemOrbit", "shoot_system", "require_periodic", "elastic_multipliers"]


@fill(SYSTEM)
def require_periodic(model: Any, what: str = "the periodic tools") -> int:
    """The forcing-period multiple p of a system, refusing incommensurate mesh frequencies.

    Parameters
    ----------
    {{model}}
    what : str
        The tools named in the error message.

    Returns
    -------
    int
        p = :meth:`SystemModel.period_multiple`: the forcing repeats after p reference mesh periods.

    Raises
    ------
    ModelError
        If the mesh-frequency ratios are incommensurate (no common period).
    """
    p = model.period_multiple()
    if p is None:
        ratios = ", ".join(f"{m.name} {m.ratio:.12g}" for m in model.meshes)
        raise ModelError(f"system: {what} need a periodic forcing, but the mesh-frequency ratios ({ratios}) are "
                         f"incommensurate; use simulate or lyapunov")
    return p


@fill(SYSTEM)
def elastic_multipliers(model: Any, monodromy: np.ndarray) -> tuple[np.ndarray, int]:
    """Eigenvalues of the monodromy on the quotient by the rigid-body subspace, and the rigid-mode count r.

    The rigid-body modes (:func:`~geardyn.analysis.systems_steady.rigid_modes`) span, with their
    velocities, an invariant subspace whose 2r multipliers are exactly 1; the remaining 2n − 2r
    decide stability.

    Parameters
    ----------
    {{model}}
    monodromy : ndarray (2n, 2n)
        Monodromy matrix of a periodic orbit.

    Returns
    -------
    multipliers : ndarray of complex (2n − 2r,), largest modulus first
    r : int
    """
    R = rigid_modes(model)
    n, r = model.n, R.shape[1]
    M = np.asarray(monodromy, float)
    if r == 0 or not np.all(np.isfinite(M)):
        mu = np.linalg.eigvals(M) if np.all(np.isfinite(M)) else np.full(M.shape[0], np.nan + 0j)
        return mu[np.argsort(-np.abs(mu), kind="stable")], 0
    S = np.zeros((2 * n, 2 * r))
    S[:n, :r] = R
    S[n:, r:] = R
    Q, _ = np.linalg.qr(np.hstack([S, np.eye(2 * n)]))
    Uc = Q[:, 2 * r:2 * n]
    mu = np.linalg.eigvals(Uc.T @ M @ Uc)
    return mu[np.argsort(-np.abs(mu), kind="stable")], r


@dataclass
@fill(POINT)
class SystemOrbit(_ShotOrbit):
    """A period-n orbit of a system (non-dimensional); see :func:`shoot_system`.

    Attributes
    ----------
    {{model}}
    n : int
        Forcing periods of the orbit.
    state : ndarray (2n,)
        State (q̃, q̃') on the orbit at θ = 0.
    points : ndarray (n, 2n)
        The orbit's Poincaré points.
    monodromy : ndarray (2n, 2n)
        Jacobian of the n-period map at ``state``.
    converged : bool
        Newton met its tolerance.
    status : Status
        ``OK``, ``NOT_CONVERGED`` or ``DIVERGED``.
    iterations : int
        Newton iterations.
    residuals : list of float
        ||P^n(x) − x|| after each iteration.
    meshes : list of dict
        Per-mesh extremes, impact state, DTE, mesh force and dynamic factor on the orbit.
    dtau : float
        Nominal step Δτ (default :data:`~geardyn.model.DEFAULT_DTAU`).
    accurate : bool
        Contact events located exactly.
    steps : int
        RK4 steps per forcing period of the map.

    References
    ----------
    A. H. Nayfeh and D. T. Mook, *Nonlinear Oscillations*, Wiley, 1979 (Floquet theory);
    T. S. Parker and L. O. Chua, *Practical Numerical Algorithms for Chaotic Systems*, Springer,
    1989 (shooting).
    """

    meshes: list[dict[str, Any]]
    dtau: float = DEFAULT_DTAU
    accurate: bool = False
    steps: int = 0

    @property
    def floquet(self) -> Floquet:
        """Floquet analysis of the full monodromy (all 2n multipliers, rigid-body ones included)."""
        return floquet(self.monodromy, self.n, forcing_period(self.model))

    @property
    def elastic(self) -> tuple[np.ndarray, int]:
        """The elastic multipliers and the rigid-mode count (:func:`elastic_multipliers`)."""
        return elastic_multipliers(self.model, self.monodromy)

    @property
    def stable(self) -> bool:
        """Converged and every elastic multiplier inside the unit circle."""
        mu, _ = self.elastic
        return bool(self.converged and np.all(np.abs(mu) < 1.0))

    def to_json(self) -> dict[str, Any]:
        """Keys of ``orbit --json`` (reference mesh) plus ``meshes``, all multipliers and the elastic ones."""
        fl = self.floquet
        mu, r = self.elastic
        num = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731
        ref = next((m for m in self.meshes if m["name"] == self.model.scaling.reference), self.meshes[0])
        ok = self.converged
        p = self.model.period_multiple() or 1

        elastic_fl = floquet(np.diag(mu) if mu.size else np.zeros((0, 0)), self.n, forcing_period(self.model)) \
            if mu.size else None
        instability = elastic_fl.instability if elastic_fl is not None else "none"
        return {
            "omega": self.model.omega,
            "state": [float(s) for s in self.state],
            "points": self.points.tolist(),
            "period": self.n * p if ok else None,
            "requested_period": self.n,
            "multipliers": fl.pairs(),
            "multiplier_moduli": [float(abs(m)) for m in fl.multipliers],
            "floquet_exponents": [num(e) for e in fl.exponents],
            "elastic_multipliers": [[float(m.real), float(m.imag)] for m in mu],
            "rigid_body_modes": r,
            "rigid_body_note": (f"{2 * r} multipliers equal to 1 belong to the {r} rigid-body mode(s) "
                                f"and are left out of the stability test") if r else None,
            "stable": self.stable,
            "instability": instability,
            "converged": bool(ok),
            "status": {Status.OK: "converged", Status.NOT_CONVERGED: "not converged"}.get(self.status, "diverged"),
            "iterations": self.iterations,
            "residual": num(self.residuals[-1]) if self.residuals else None,
            "u_min": ref["u_min"], "u_max": ref["u_max"], "amplitude": ref["amplitude"], "impact": ref["impact"],
            "determinant": num(fl.determinant),
            "accurate": self.accurate,
            "labels": list(self.model.labels),
            "meshes": self.meshes,
        }


def _least_squares_step(A: np.ndarray, G: np.ndarray) -> np.ndarray:
    """The Newton step in least squares: a free rigid-body mode makes monodromy − I singular."""
    return np.linalg.lstsq(A, -G, rcond=1e-10)[0]


def _newton(pmap: PeriodMap, x0: np.ndarray, tol: float, max_iter: int):
    """The damped Newton of :mod:`geardyn.analysis.periodic.orbit` with least-squares steps."""
    return _periodic_newton(pmap, x0, tol, max_iter, step=_least_squares_step)


def _orbit_meshes(model: Any, pmap: PeriodMap, x: np.ndarray) -> list[dict[str, Any]]:
    from ..integrate_ndof import trajectory
    from .classify import impact_state

    tr = trajectory(model, x, IntegrationOptions(dtau=pmap.dtau, transient=0, periods=pmap.n,
                                                 accurate=pmap.accurate),
                    history_periods=pmap.n, steps=pmap.steps, threads=MAP_THREADS)
    force = mesh_forces(model, tr.tau, tr.deltas)
    fs = static_mesh_forces(model)
    sc = model.scaling
    out = []
    for i, m in enumerate(model.meshes):
        d = tr.deltas[:, i, 0]
        ok = bool(np.all(np.isfinite(d)))
        lo, hi = _hermite_extrema(d, tr.deltas[:, i, 1], pmap.step) if ok else (math.nan, math.nan)
        fmax = float(np.max(force[:, i])) if ok else math.nan
        num = lambda v: v if np.isfinite(v) else None  # noqa: E731
        out.append({"name": m.name, "u_min": num(lo), "u_max": num(hi), "amplitude": num(0.5 * (hi - lo)),
                    "impact": IMPACT_LABELS[impact_state(lo, m.D)],
                    "dte_amplitude_um": num(0.5 * (hi - lo) * sc.b_c * 1e6),
                    "mesh_force_max_N": num(fmax * sc.force_scale),
                    "dynamic_factor": num(fmax / fs[i]) if fs[i] > 0 else None})
    return out


def shoot_system(model: Any, n: int = 1, guess: Sequence[float] | None = None, *, dtau: float = DEFAULT_DTAU,
                 accurate: bool = False, tol: float = SHOOT_TOL, max_iter: int = SHOOT_MAX_ITER,
                 state0: Sequence[float] | None = None, transient: int = GUESS_TRANSIENT) -> SystemOrbit:
    """Find a period-n orbit of a system (n forcing periods) by Newton on the n-period map.

    Parameters
    ----------
    model : SystemModel
        The system point (its forcing must be periodic).
    n : int
        Forcing periods of the orbit.
    guess : (2n,) state at θ = 0, optional
        Default: the end of a simulation of ``transient`` periods from ``state0`` (the Poincaré point
        closest to recurring after n periods).
    dtau, accurate, tol, max_iter : as :func:`geardyn.analysis.periodic.shoot`
    state0 : (u0, v0) of the reference mesh or (2n,), optional
        Start of the simulation that provides the default guess.
    transient : int
        Forcing periods of that simulation (default
        :data:`~geardyn.analysis.periodic.orbit.GUESS_TRANSIENT`).

    Returns
    -------
    SystemOrbit

    Raises
    ------
    ModelError
        For incommensurate mesh frequencies, a bad period or guess.

    References
    ----------
    T. S. Parker and L. O. Chua, *Practical Numerical Algorithms for Chaotic Systems*, Springer,
    1989 (shooting); A. H. Nayfeh and D. T. Mook, *Nonlinear Oscillations*, Wiley, 1979 (Floquet
    multipliers).
    """
    require_periodic(model, "shooting and Floquet multipliers")
    n = int(n)
    if n < 1:
        raise ModelError(f"period: must be an integer >= 1, got {n}")
    pmap = PeriodMap(model, n, dtau=dtau, accurate=accurate)
    d = model.state_dim
    if guess is None:
        rec = max(GUESS_RECORD_PER_PERIOD * n, 16)
        res = integrate_batch([model], system_state0(model, state0),
                              IntegrationOptions(dtau=dtau, transient=int(transient), periods=rec, accurate=accurate),
                              threads=MAP_THREADS)
        if not res.ok[0]:
            x0 = None
        else:
            pts = res.poincare[0]
            dist = np.linalg.norm(pts[n:] - pts[:-n], axis=1)
            x0 = pts[len(dist) - 1 - int(np.argmin(dist[::-1]))].copy()
    else:
        x0 = np.asarray(guess, dtype=float)
        if x0.shape != (d,) or not np.all(np.isfinite(x0)):
            raise ModelError(f"guess: expected {d} finite numbers (q̃, q̃'), got {guess!r}")
    if x0 is None:
        nan = np.full((n, d), np.nan)
        return SystemOrbit(model, n, np.zeros(d), nan, np.full((d, d), np.nan), False, Status.DIVERGED, 0,
                           [math.inf], [], dtau, accurate, pmap.steps)
    ev, conv, its, res_, status = _newton(pmap, x0, tol, max_iter)
    if not conv and not accurate:
        acc = PeriodMap(model, n, dtau=dtau, accurate=True, steps=pmap.steps)
        ev_a, conv_a, its_a, res_a, _ = _newton(acc, x0, tol, max_iter)
        if conv_a:
            ev2, conv, its2, res2, status = _newton(pmap, ev_a.x, tol, max_iter)
            if ev2.ok:
                ev, its, res_ = ev2, its + its_a + its2, res_ + res_a + res2
    pts = np.vstack([ev.x[None, :], ev.points[:-1]])
    meshes = _orbit_meshes(model, pmap, ev.x) if ev.ok else []
    return SystemOrbit(model, n, ev.x.copy(), pts, ev.monodromy.copy(), conv, status, its, res_, meshes, dtau,
                       accurate, pmap.steps)
