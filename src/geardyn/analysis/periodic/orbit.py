"""Periodic orbits by shooting: Newton on P^n(x) − x = 0 for the n-period map.

:func:`shoot` finds a period-n orbit (damped Newton, with a guess from simulation when none is
given) and returns a :class:`PeriodicOrbit`: its section points, monodromy matrix, Floquet
analysis, extremes and status.  :func:`orbit_extrema` gives the extremes of u over an orbit,
refined between the RK4 steps.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from ...integrate import integrate_batch, start_state
from ...io import json_number
from ...labels import IMPACT_LABELS, impact_state
from ...model import DEFAULT_DTAU, GearModel, IntegrationOptions, ModelError
from ...status import Status
from ...system import require_periodic
from .floquet import Floquet, floquet, largest_first, pairs
from .map import MAP_THREADS, MapEvaluation, PeriodMap

__all__ = [
    "PeriodicOrbit",
    "shoot",
    "elastic_basis",
    "elastic_multipliers",
    "guess_from_simulation",
    "orbit_extrema",
    "orbit_status_label",
    "SHOOT_TOL",
    "SHOOT_MAX_ITER",
    "NEWTON_MIN_DAMPING",
    "GUESS_TRANSIENT",
    "GUESS_RECORD_PER_PERIOD",
    "SAME_POINT_TOL",
]

#: Newton (shooting) converges when ||P^n(x) − x|| <= SHOOT_TOL·(1 + ||x||).
SHOOT_TOL = 1.0e-10
#: Largest number of Newton iterations in :func:`shoot`.
SHOOT_MAX_ITER = 40
#: Smallest damping factor of a backtracking Newton step before the iteration gives up.
NEWTON_MIN_DAMPING = 2.0**-16
#: Forcing periods simulated (and discarded) to build a shooting guess when none is given.
GUESS_TRANSIENT = 400
#: Poincaré points recorded after the transient from which the guess is picked (times n, at least 16).
GUESS_RECORD_PER_PERIOD = 8
#: Two section points of an orbit count as the same point when closer than this (relative to 1 + |x|);
#: used for the minimal period of an orbit and to detect a period-2n branch merging into the period-n one.
SAME_POINT_TOL = 1.0e-5


def orbit_status_label(status: Status) -> str:
    """The word an orbit's status is written as in JSON and NetCDF (``converged`` for OK).

    Parameters
    ----------
    status : Status
        ``OK``, ``NOT_CONVERGED`` or ``DIVERGED``.

    Returns
    -------
    str
        ``converged``, ``not converged`` or ``diverged`` (the contract of ``geardyn orbit --json``).
    """
    status = Status.parse(status)
    return "converged" if status is Status.OK else status.label


def _hermite_extrema(u: np.ndarray, v: np.ndarray, h: float) -> tuple[float, float]:
    """Min and max of the piecewise cubic Hermite interpolant through (u_k, u'_k) sampled every h."""
    idx = np.nonzero(v[:-1] * v[1:] <= 0.0)[0]
    a0, a1, b0, b1 = u[idx], u[idx + 1], h * v[idx], h * v[idx + 1]
    # u(x) = (2x³−3x²+1)a0 + (x³−2x²+x)b0 + (−2x³+3x²)a1 + (x³−x²)b1; u'(x) = A x² + B x + C
    A = 6 * a0 + 3 * b0 - 6 * a1 + 3 * b1
    B = -6 * a0 - 4 * b0 + 6 * a1 - 2 * b1
    C = b0
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = np.sqrt(np.maximum(B * B - 4 * A * C, 0.0))
        quad = np.abs(A) > 1e-14 * (np.abs(B) + np.abs(C) + 1e-300)
        r = np.where(quad, np.stack([-B + disc, -B - disc]) / (2 * A), -C / B)  # both roots of every step
    ok = np.isfinite(r) & (r >= 0.0) & (r <= 1.0)
    x = r[ok]
    a0, b0, a1, b1 = (np.broadcast_to(c, r.shape)[ok] for c in (a0, b0, a1, b1))
    x2, x3 = x * x, x * x * x
    val = (2 * x3 - 3 * x2 + 1) * a0 + (x3 - 2 * x2 + x) * b0 + (-2 * x3 + 3 * x2) * a1 + (x3 - x2) * b1
    return float(np.min(val, initial=np.min(u))), float(np.max(val, initial=np.max(u)))


def orbit_extrema(
    model: GearModel,
    state: Sequence[float],
    n: int = 1,
    *,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = False,
    steps: int | None = None,
) -> tuple[float, float]:
    """Smallest and largest u over n periods from ``state`` (non-dimensional).

    The step-end samples are refined by the cubic Hermite interpolant of (u, u') (error O(h⁴)
    instead of O(h²)).

    Parameters
    ----------
    model : GearModel
        The model.
    state : (u, u')
        State at θ = 0.
    n : int
        Forcing periods.
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    accurate : bool
        Split the steps at the contact boundaries u = ±D (``IntegrationOptions.accurate``); default False.
    steps : int, optional
        RK4 steps per period (default ceil(T/Δτ)).

    Returns
    -------
    (u_min, u_max) : tuple of float
        NaN if the trajectory diverged.
    """
    pmap = PeriodMap(model, n, dtau=dtau, accurate=accurate, steps=steps)
    lo, hi = _trajectory_extrema(pmap.trajectory(state), len(model.elements), pmap.step)[model.reference]
    return float(lo), float(hi)


def _trajectory_extrema(tr: Any, elements: int, h: float) -> np.ndarray:
    """(elements, 2): every element's extremes of δ along a trajectory of step h (Hermite-refined; NaN if it
    diverged)."""
    out = np.full((elements, 2), np.nan)
    if np.all(np.isfinite(tr.x)):
        for e in range(elements):
            out[e] = _hermite_extrema(tr.deltas[:, e, 0], tr.deltas[:, e, 1], h)
    return out


def elastic_basis(model: Any) -> np.ndarray | None:
    """Orthonormal columns (d, d − 2r) spanning the complement of the rigid-body subspace, or None (r = 0).

    The rigid-body modes R (``model.rigid_basis()``) and their velocities span an invariant subspace of
    every monodromy of the system, whose 2r multipliers are exactly 1; the monodromy restricted to the
    quotient, ``Ucᵀ M Uc``, has the elastic multipliers.

    Parameters
    ----------
    model : System

    Returns
    -------
    ndarray (d, d − 2r) or None
    """
    R = model.rigid_basis()
    n, r = R.shape
    if r == 0:
        return None
    S = np.zeros((2 * n, 2 * r))
    S[:n, :r] = R
    S[n:, r:] = R
    Q, _ = np.linalg.qr(np.hstack([S, np.eye(2 * n)]))
    return Q[:, 2 * r : 2 * n]


def elastic_multipliers(model: Any, monodromy: np.ndarray) -> tuple[np.ndarray, int]:
    """Eigenvalues of the monodromy on the quotient by the rigid-body subspace, and the rigid-mode count r.

    The rigid-body modes (``model.rigid_basis()``) span, with their velocities, an invariant subspace
    whose 2r multipliers are exactly 1; the remaining d − 2r decide stability (:func:`elastic_basis`).
    For a system without rigid-body modes (the pair) these are all the multipliers.

    Parameters
    ----------
    model : System
    monodromy : ndarray (d, d)
        Monodromy matrix of a periodic orbit.

    Returns
    -------
    multipliers : ndarray of complex (d − 2r,), largest modulus first
    r : int
    """
    Uc = elastic_basis(model)
    M = np.asarray(monodromy, float)
    r = 0
    if not np.all(np.isfinite(M)):
        mu = np.full(M.shape[0], np.nan + 0j)
    elif Uc is None:
        mu = np.linalg.eigvals(M)
    else:
        mu, r = np.linalg.eigvals(Uc.T @ M @ Uc), (M.shape[0] - Uc.shape[1]) // 2
    return largest_first(mu), r


def _minimal_period(points: np.ndarray, n: int) -> int:
    """Smallest d dividing n with P^d(x) = x within SAME_POINT_TOL (points[k] = P^{k+1}(x))."""
    x = points[-1]
    scale = 1.0 + float(np.linalg.norm(x))
    for d in range(1, n):
        if n % d == 0 and float(np.linalg.norm(points[d - 1] - x)) <= SAME_POINT_TOL * scale:
            return d
    return n


@dataclass
class PeriodicOrbit:
    """A period-n orbit of any System found by shooting (all quantities non-dimensional).

    Attributes
    ----------
    model : System
        The model the orbit belongs to.
    n : int
        Forcing periods of the map P^n that was solved (``--period``).
    state : ndarray (2,)
        (u, u') at θ = 0 on the orbit.
    points : ndarray (n, 2)
        The n section points x, P(x), ..., P^{n−1}(x) (first is ``state``).
    monodromy : ndarray (2, 2)
        Jacobian of P^n at ``state``.
    converged : bool
        Newton met the tolerance.
    status : Status
        ``Status.OK`` (converged), ``Status.NOT_CONVERGED`` or ``Status.DIVERGED``; written as
        :attr:`status_label` (``converged``, ``not converged``, ``diverged``) in JSON and NetCDF.
    iterations : int
        Newton iterations taken.
    residuals : list of float
        ||P^n(x) − x|| at each Newton iterate (quadratic decrease in the default mode; when the
        default-mode iteration stalls far from the orbit, the accurate-mode iterates that brought it
        close follow, then the final default-mode ones).
    u_min, u_max : float
        Extremes of the reference element's u over the orbit (Hermite-refined between steps).
    dtau, accurate, steps : float, bool, int
        The integration settings: target step, mode and RK4 steps per period (0: ceil(T/Δτ)).
    extra : dict
        What the system adds to the summary (``System.report``: per-mesh entries; empty for the pair).

    References
    ----------
    A. H. Nayfeh and D. T. Mook, *Nonlinear Oscillations*, Wiley, 1979 (Floquet theory).
    """

    model: Any
    n: int
    state: np.ndarray
    points: np.ndarray
    monodromy: np.ndarray
    converged: bool
    status: Status
    iterations: int
    residuals: list[float]
    u_min: float
    u_max: float
    dtau: float = DEFAULT_DTAU
    accurate: bool = False
    steps: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def multipliers(self) -> np.ndarray:
        """Floquet multipliers of :attr:`floquet` (all d of them, rigid-body ones included), largest modulus first."""
        return self.floquet.multipliers

    @property
    def elastic(self) -> tuple[np.ndarray, int]:
        """The elastic multipliers and the rigid-mode count (:func:`elastic_multipliers`)."""
        return elastic_multipliers(self.model, self.monodromy)

    @property
    def status_label(self) -> str:
        """``converged``, ``not converged`` or ``diverged`` (see :func:`orbit_status_label`)."""
        return orbit_status_label(self.status)

    @property
    def period_map(self) -> PeriodMap:
        """The map P^n whose fixed point this orbit is (same step count and mode)."""
        return PeriodMap(self.model, self.n, dtau=self.dtau, accurate=self.accurate, steps=self.steps or None)

    @property
    def residual(self) -> float:
        """||P^n(x) − x|| at the last iterate."""
        return self.residuals[-1] if self.residuals else math.nan

    @property
    def floquet(self) -> Floquet:
        """Floquet analysis of the monodromy matrix."""
        return floquet(self.monodromy, self.n, self.model.sampling_period)

    @property
    def stable(self) -> bool:
        """Converged and all elastic multipliers inside the unit circle (the rigid-body ones are exactly 1)."""
        mu, r = self.elastic
        if r == 0:
            return self.converged and self.floquet.stable
        return bool(self.converged and np.all(np.abs(mu) < 1.0))

    def _instability(self) -> str:
        mu, r = self.elastic
        if r == 0:
            return self.floquet.instability
        return floquet(np.diag(mu), self.n, self.model.sampling_period).instability if mu.size else "none"

    @property
    def minimal_period(self) -> int:
        """Smallest number of forcing periods after which the orbit repeats (divides n)."""
        if not self.converged:
            return 0
        cyc = np.vstack([self.points[1:], self.points[:1]])  # P^1(x), ..., P^n(x) = x
        return _minimal_period(cyc, self.n)

    @property
    def amplitude(self) -> float:
        """Half peak-to-peak displacement (u_max − u_min)/2."""
        return 0.5 * (self.u_max - self.u_min)

    @property
    def impact(self) -> str:
        """Impact state from u_min (``no impact``, ``single-sided``, ``double-sided``, ...)."""
        m = self.model
        return IMPACT_LABELS[impact_state(self.u_min, m.elements[m.reference].gap)]

    def history(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(τ, u, u') at every step over the n periods of the orbit, starting at ``state``."""
        return self.period_map.history(self.state)

    def to_json(self) -> dict[str, Any]:
        """The ``orbit --json`` summary (DESIGN §5 keys plus a few more)."""
        fl = self.floquet
        mu, r = self.elastic

        return {
            "omega": self.model.omega,
            "state": self.state.tolist(),
            "points": self.points.tolist(),
            "period": self.minimal_period * (self.model.period_multiple() or 1) if self.converged else None,
            "requested_period": self.n,
            "multipliers": fl.pairs(),
            "multiplier_moduli": [float(abs(m)) for m in fl.multipliers],
            "floquet_exponents": [json_number(e) for e in fl.exponents],
            "elastic_multipliers": pairs(mu),
            "rigid_body_modes": r,
            "rigid_body_note": (
                f"{2 * r} multipliers equal to 1 belong to the {r} rigid-body mode(s) "
                f"and are left out of the stability test"
            )
            if r
            else None,
            "stable": bool(self.stable),
            "instability": self._instability(),
            "converged": bool(self.converged),
            "status": self.status_label,
            "iterations": self.iterations,
            "residual": json_number(self.residual),
            "u_min": json_number(self.u_min),
            "u_max": json_number(self.u_max),
            "amplitude": json_number(self.amplitude),
            "impact": self.impact,
            "determinant": json_number(fl.determinant),
            "accurate": self.accurate,
            **self.extra,
        }

    def to_dataset(self) -> xr.Dataset:
        """Section points, multipliers, monodromy and the time history over the orbit's n periods."""
        from ...io import annotate, result_attrs

        tau, u, v = self.history() if self.converged else (np.zeros(0),) * 3
        fl = self.floquet
        d = len(self.state)
        m = self.model
        sec = m.element_series(self.points, 0.0)[:, m.reference, :]  # the reference element's (δ, δ')
        ds = xr.Dataset(
            {
                "poincare_u": ("section", sec[:, 0]),
                "poincare_v": ("section", sec[:, 1]),
                "multiplier_re": ("multiplier", fl.multipliers.real),
                "multiplier_im": ("multiplier", fl.multipliers.imag),
                "floquet_exponent": ("multiplier", fl.exponents),
                "monodromy": (("row", "col"), self.monodromy),
                "u": ("tau", u),
                "v": ("tau", v),
            },
            coords={
                "tau": tau,
                "section": np.arange(self.n),
                "multiplier": np.arange(d),
                "row": list(range(d)),
                "col": list(range(d)),
            },
            attrs=result_attrs(
                "orbit",
                self.model,
                {"dtau": self.dtau, "accurate": self.accurate, "steps_per_period": self.steps},
                summary=self.to_json(),
            ),
        )
        names = [
            "multiplier_re",
            "multiplier_im",
            "floquet_exponent",
            "monodromy",
            "section",
            "multiplier",
            "row",
            "col",
        ]
        if d != 2:  # a system: the full section states
            from ...system import state_names

            ds["points"] = (("section", "state"), np.asarray(self.points, float))
            ds = ds.assign_coords(state=state_names(m, d))
            names += ["points", "state"]
        annotate(ds, names=names)
        ds.attrs["status"] = self.status_label
        return ds


def guess_from_simulation(
    model: GearModel,
    n: int = 1,
    state0: Sequence[float] | None = None,
    *,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = False,
    transient: int = GUESS_TRANSIENT,
    progress: Callable[[int, int], None] | None = None,
) -> np.ndarray | None:
    """A shooting guess from a simulation.

    Simulate ``transient`` periods, then pick among the next Poincaré points the one closest to
    recurring after n periods.

    Parameters
    ----------
    model : GearModel
        The model.
    n : int
        Period of the orbit sought.
    state0 : (u, u'), optional
        Initial state (default zeros).
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    accurate : bool
        Split the steps at the contact boundaries u = ±D (``IntegrationOptions.accurate``); default False.
    transient : int
        Forcing periods discarded first.
    progress : callable, optional
        Called as ``progress(done, total)`` in forcing periods while the simulation runs
        (:func:`~geardyn.integrate.integrate_batch`); the guess is that of a call without it, bit for bit.

    Returns
    -------
    ndarray (2,) or None
        The guess; None if the simulation diverged.
    """
    rec = max(GUESS_RECORD_PER_PERIOD * n, 16)
    s0 = start_state(model, state0)
    opts = IntegrationOptions(dtau=dtau, transient=int(transient), periods=rec, accurate=accurate)
    res = integrate_batch([model], s0, opts, threads=MAP_THREADS, progress=progress)
    if not res.ok[0]:
        return None
    pts = res.poincare[0]
    d = np.linalg.norm(pts[n:] - pts[:-n], axis=1)
    k = int(np.argmin(d[::-1]))  # latest among the closest
    return pts[len(d) - 1 - k].copy()


def newton_step(A: np.ndarray, G: np.ndarray, rigid: bool = False) -> np.ndarray:
    """The Newton step dx of A dx = −G (least squares where A is singular).

    Parameters
    ----------
    A : ndarray (d, d)
    G : ndarray (d,)
    rigid : bool
        The system has rigid-body modes (``model.rigid_basis()`` not empty): the minimum-norm step.  A free
        rigid-body mode makes monodromy − I singular (a rigid rotation of a whole solution is again a
        solution), and the minimum-norm step leaves it where it is.

    Returns
    -------
    ndarray (d,)
    """
    if rigid:
        return np.linalg.lstsq(A, -G, rcond=1e-10)[0]
    try:
        return np.linalg.solve(A, -G)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(A, -G, rcond=None)[0]


def _newton(
    pmap: PeriodMap, x0: np.ndarray, tol: float, max_iter: int, rigid: bool = False
) -> tuple[MapEvaluation, bool, int, list[float], Status]:
    """Damped Newton on P^n(x) − x = 0 for one map (fixed parameters and steps per period).

    The step is :func:`newton_step` (the minimum-norm one with ``rigid``: the system has rigid-body modes).
    Returns (last evaluation, converged, iterations, residuals, status)."""
    ev = pmap.evaluate(x0)
    if not ev.ok:
        return ev, False, 0, [math.inf], Status.DIVERGED
    eye = np.eye(ev.x.size)
    res = [float(np.linalg.norm(ev.residual))]
    for it in range(max_iter + 1):
        r = res[-1]
        if r <= tol * (1.0 + float(np.linalg.norm(ev.x))):
            return ev, True, it, res, Status.OK
        if it == max_iter:
            break
        dx = newton_step(ev.monodromy - eye, ev.residual, rigid)
        lam = 1.0
        new = None
        while lam >= NEWTON_MIN_DAMPING:
            trial = pmap.evaluate(ev.x + lam * dx)
            if trial.ok and float(np.linalg.norm(trial.residual)) < (1.0 - 1e-4 * lam) * r:
                new = trial
                break
            lam *= 0.5
        if new is None:
            return ev, False, it + 1, res, Status.NOT_CONVERGED
        ev = new
        res.append(float(np.linalg.norm(ev.residual)))
    return ev, False, max_iter, res, Status.NOT_CONVERGED


def shoot(
    model: GearModel,
    n: int = 1,
    guess: Sequence[float] | None = None,
    *,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = False,
    tol: float = SHOOT_TOL,
    max_iter: int = SHOOT_MAX_ITER,
    state0: Sequence[float] | None = None,
    transient: int = GUESS_TRANSIENT,
    progress: Callable[[int, int], None] | None = None,
) -> PeriodicOrbit:
    """Find a period-n orbit by Newton's method on the n-period stroboscopic map.

    Parameters
    ----------
    model : GearModel
        Non-dimensional model.
    n : int
        Number of forcing periods of the orbit (the map solved is P^n).
    guess : (u, u') at θ = 0, optional
        Newton's starting point.  If omitted the guess comes from a simulation of ``transient``
        periods from ``state0`` (default (0, 0), as for ``geardyn simulate``), so the orbit
        found is the attractor reached from there when it is stable.
    dtau : float
        Target step Δτ (the step is T/ceil(T/Δτ)).
    accurate : bool
        Integrate in the accurate mode (steps split at u = ±D).
    tol : float
        Convergence: ||P^n(x) − x|| <= tol·(1 + ||x||).
    max_iter : int
        Newton iterations allowed.
    state0 : (u, u'), optional
        Start of the simulation that gives the guess when ``guess`` is None.
    transient : int
        Forcing periods of that simulation.
    progress : callable, optional
        Called as ``progress(done, total)`` in forcing periods while that simulation runs (the Newton
        iterations after it report nothing); the orbit is that of a call without it, bit for bit.

    Returns
    -------
    PeriodicOrbit
        Check ``converged``/``status``; its Floquet analysis is ``orbit.floquet``.

    Raises
    ------
    ModelError
        For a period below 1, a step not below the forcing period or a malformed guess.

    References
    ----------
    T. S. Parker and L. O. Chua, *Practical Numerical Algorithms for Chaotic Systems*, Springer,
    1989 (shooting for periodic solutions of forced systems).

    Examples
    --------
    >>> from geardyn import GearModel, shoot
    >>> orb = shoot(GearModel(omega=0.8), 2)  # Newton on the 2-period map
    >>> orb.converged, orb.stable, [round(float(abs(m)), 3) for m in orb.multipliers]
    (True, True, [0.72, 0.06])
    """
    require_periodic(model, "shooting and Floquet multipliers")
    n = int(n)
    if n < 1:
        raise ModelError(f"period: must be an integer >= 1, got {n}")
    IntegrationOptions(dtau=dtau).check_for(model.omega)
    pmap = PeriodMap(model, n, dtau=dtau, accurate=accurate)
    N = pmap.steps
    rigid = bool(model.rigid_basis().shape[1])  # rigid-body modes: the minimum-norm Newton step
    if guess is None:
        x0 = guess_from_simulation(
            model, n, state0, dtau=dtau, accurate=accurate, transient=transient, progress=progress
        )
        if x0 is None:
            return _failed_orbit(pmap, start_state(model, state0))
    else:
        x0 = np.asarray(guess, dtype=float)
        if x0.shape != (pmap.dim,) or not np.all(np.isfinite(x0)):
            what = "two finite numbers u,v" if pmap.dim == 2 else f"{pmap.dim} finite numbers (the full state)"
            raise ModelError(f"guess: expected {what}, got {guess!r}")
    ev, conv, its, res, status = _newton(pmap, x0, tol, max_iter, rigid)
    if not conv and not accurate:
        # The default-mode map has a kink wherever an RK4 stage crosses ±D, which can stall the
        # damped iteration far from the orbit.  The accurate-mode map is smooth there and its orbit
        # lies within the discretisation error of the default-mode one: get close with it, then
        # finish in the default mode (quadratic convergence).
        acc = PeriodMap(model, n, dtau=dtau, accurate=True, steps=N)
        ev_a, conv_a, its_a, res_a, _st = _newton(acc, x0, tol, max_iter, rigid)
        if conv_a:
            ev2, conv, its2, res2, status = _newton(pmap, ev_a.x, tol, max_iter, rigid)
            if ev2.ok:
                ev, its, res = ev2, its + its_a + its2, res + res_a + res2
    if not ev.ok:
        return _failed_orbit(pmap, x0)
    return _orbit_from_eval(pmap, ev, conv, status, its, res)


def _orbit_from_eval(
    pmap: PeriodMap, ev: MapEvaluation, conv: bool, status: Status, its: int, res: list[float]
) -> PeriodicOrbit:
    """The orbit through a converged evaluation of ``pmap`` (which has the evaluation's steps)."""
    pts = np.vstack([ev.x[None, :], ev.points[:-1]])
    m = pmap.model
    tr = pmap.trajectory(ev.x)
    ext = _trajectory_extrema(tr, len(m.elements), pmap.step)
    umin, umax = map(float, ext[m.reference])
    extra = m.report(tau=tr.tau, deltas=tr.deltas, extrema=ext)
    return PeriodicOrbit(
        m,
        pmap.n,
        ev.x.copy(),
        pts,
        ev.monodromy.copy(),
        conv,
        status,
        its,
        res,
        umin,
        umax,
        pmap.dtau,
        pmap.accurate,
        ev.steps,
        extra,
    )


def _failed_orbit(pmap: PeriodMap, x: np.ndarray) -> PeriodicOrbit:
    """The orbit of a shooting with ``pmap`` whose simulation or Newton iteration diverged."""
    x = np.asarray(x, float)
    d = x.size
    return PeriodicOrbit(
        pmap.model,
        pmap.n,
        x,
        np.full((pmap.n, d), np.nan),
        np.full((d, d), np.nan),
        False,
        Status.DIVERGED,
        0,
        [math.inf],
        math.nan,
        math.nan,
        pmap.dtau,
        pmap.accurate,
        pmap.steps,
    )
