"""Pseudo-arclength continuation of one branch of period-n orbits, with event detection.

A branch is a curve of fixed points of P^n(x; p) in (x, p); it is followed in the scaled space
y = (x, p/ps), ps = |stop − start|, by a tangent predictor and a Newton corrector in the
hyperplane normal to the tangent, so that it passes around folds.  Between consecutive points the
test functions (the tangent's parameter component, det(M − I), det(M + I), det M − 1, u_min/u_max
∓ D) are watched for sign changes, and each change is located by a secant iteration on the branch.

Notes on the discrete map
-------------------------
In the default mode the step is h = T/N with N = ceil(T/Δτ).  When ω is the continuation
parameter N changes by one every ΔT ≈ Δτ, which moves the discrete map by an amount of the order
of the integration error.  The corrector therefore holds N fixed while it iterates and, after
convergence, re-solves with the N that belongs to the converged ω (the point reported is then
exactly what :func:`~geardyn.analysis.periodic.shoot` gives at that ω); parameter derivatives are
taken with N fixed.

References
----------
E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*, SIAM, 2003
(pseudo-arclength continuation, detection of bifurcation points); R. Seydel, *Practical
Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010; Yu. A. Kuznetsov,
*Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004 (numerical analysis of bifurcations).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...model import ModelError, canonical_param
from ..secant import illinois_on_chord
from .branch import STABILITY_LOSSES, Bifurcation, Branch
from .floquet import REAL_MULTIPLIER_TOL, largest_first
from .map import MapEvaluation, PeriodMap
from .orbit import PeriodicOrbit, _minimal_period, _trajectory_extrema, elastic_basis

__all__ = ["continue_branch", "element_extrema", "MAX_BRANCH_POINTS", "DS_MAX", "DS_INIT", "DS_MIN"]

#: Corrector (continuation): ||P^n(x) − x|| <= CORRECTOR_TOL·(1 + ||x||) and a last update below CORRECTOR_STEP_TOL.
CORRECTOR_TOL = 1.0e-9
CORRECTOR_STEP_TOL = 1.0e-7
#: Largest number of corrector iterations per continuation step.
CORRECTOR_MAX_ITER = 8
#: Continuation step sizes: arclength in the space (u, u', p/ps) with the parameter scaled by
#: ps = |stop − start|, so that the whole parameter interval has length 1 (largest, initial, smallest).
DS_MAX = 0.01
DS_INIT = 0.002
DS_MIN = 1.0e-7
#: A step predicted beyond the end of the interval is corrected directly at the end value when the
#: parameter component of the (unit) tangent is at least this (far from a fold).
DIRECT_LANDING_MIN_TP = 0.2
#: Maps kept per branch for repeated evaluations at the same parameter value.
MODEL_CACHE_SIZE = 16
#: Step growth and shrink factors, and the corrector iteration counts that trigger them.
DS_GROW, DS_SHRINK = 1.5, 0.5
FAST_CORRECTOR_ITERS, SLOW_CORRECTOR_ITERS = 2, 5
#: Largest turn of the branch tangent accepted in one step (degrees).
MAX_TANGENT_TURN_DEG = 25.0
#: Largest number of points per branch.
MAX_BRANCH_POINTS = 4000
#: Location of bifurcation points: stop when the bracket along the branch is shorter than LOCATE_TOL
#: (arclength) or after LOCATE_MAX_ITER secant/bisection steps.
LOCATE_TOL = 1.0e-9
LOCATE_MAX_ITER = 60
#: Default mode: successive opposite crossings of one test function closer than this (relative to
#: |stop − start|) are discretisation artefacts and are dropped (see :func:`_drop_discretization_noise`).
NOISE_PARAM_REL = 1.0e-3
#: A sign change of (P^{n/2}x − x)·w within one step counts as the branch meeting the period-n/2
#: branch when |P^{n/2}x − x| at both ends is at most this many times the step's change in x
#: (the separation passes through zero inside the step rather than turning by more than 90°).
MERGE_STEP_FACTOR = 10.0
#: The grazing test functions of every element: key, extreme (0: u_min, 1: u_max), sign s of the test
#: function extreme − s·D, and what the event is.
_GRAZING = (
    ("graze_min_plus", 0, 1.0, "u_min = +D (drive-side contact loss)"),
    ("graze_min_minus", 0, -1.0, "u_min = −D (back-side contact)"),
    ("graze_max_plus", 1, 1.0, "u_max = +D (drive-side contact)"),
    ("graze_max_minus", 1, -1.0, "u_max = −D"),
)


class _Family:
    """The maps P^n(·; p) of one branch in its parameter (the fixed-point problem P^n(x; p) = x)."""

    def __init__(self, pmap: PeriodMap, param: str):
        self.base = pmap
        self.param = canonical_param(param)
        self.n = pmap.n
        self.dim = pmap.dim
        self.accurate = pmap.accurate
        self._maps: dict[float, PeriodMap] = {}
        model = pmap.model
        # the rigid-body gauge: rows Rᵀ q = const fix the free rigid position (empty for the pair)
        R = model.rigid_basis()
        self.gauge = np.hstack([R.T, np.zeros((R.shape[1], self.dim - R.shape[0] + 1))])
        self.elastic_basis = elastic_basis(model)
        self.reference = int(model.reference)
        self.names = tuple(e.name for e in model.elements)

    def elastic(self, M: np.ndarray) -> np.ndarray:
        """The monodromy on the quotient by the rigid-body subspace (M itself without rigid-body modes)."""
        U = self.elastic_basis
        return M if U is None else U.T @ M @ U

    def multipliers(self, M: np.ndarray) -> np.ndarray:
        """The multipliers of the elastic monodromy, largest modulus first."""
        return largest_first(np.linalg.eigvals(self.elastic(M)))

    def gaps_at(self, p: float) -> list[float]:
        """The half gaps of the elements at parameter p."""
        return [e.gap for e in self.map_at(p).model.elements]

    def map_at(self, p: float) -> PeriodMap:
        p = float(p)
        m = self._maps.get(p)
        if m is None:
            if len(self._maps) >= MODEL_CACHE_SIZE:
                self._maps.clear()
            m = self._maps[p] = self.base.with_param(self.param, p)
        return m

    def steps(self, p: float) -> int:
        """ceil(T/Δτ) at parameter p."""
        return self.map_at(p).natural_steps


def element_extrema(pmap: PeriodMap, x: np.ndarray) -> np.ndarray:
    """(elements, 2): every element's extremes of δ over one iteration of ``pmap`` from x (Hermite-refined).

    Parameters
    ----------
    pmap : PeriodMap
    x : ndarray (d,)

    Returns
    -------
    ndarray (elements, 2)
        NaN if the trajectory diverged.
    """
    return _trajectory_extrema(pmap.trajectory(x), len(pmap.model.elements), pmap.step)


@dataclass
class _Point:
    y: np.ndarray  # (x, p/ps): the parameter scaled by the continuation's parameter scale ps
    ev: MapEvaluation
    p: float
    tangent: np.ndarray
    ext: np.ndarray  # (elements, 2): the extremes of every element's δ
    ref: int
    iters: int = 0

    @property
    def u_min(self) -> float:
        return float(self.ext[self.ref, 0])

    @property
    def u_max(self) -> float:
        return float(self.ext[self.ref, 1])

    @property
    def M(self) -> np.ndarray:
        return self.ev.monodromy


class _Continuer:
    """Pseudo-arclength continuation of one branch with event detection."""

    def __init__(
        self,
        prob: _Family,
        lo: float,
        hi: float,
        span: float,
        ds: float | None,
        ds_max: float | None,
        max_points: int,
        locate: bool,
        detect: bool = True,
        stop_on_instability: bool = False,
    ):
        self.prob = prob
        self.lo, self.hi = lo, hi
        self.ps = span  # parameter scale: the continuation works in (u, u', p/ps)
        self.ds_max = ds_max if ds_max is not None else DS_MAX
        self.ds = min(ds if ds is not None else DS_INIT, self.ds_max)
        self.max_points = max_points
        self.locate = locate
        self.detect = detect
        self.stop_on_instability = stop_on_instability
        self.cos_max_turn = math.cos(math.radians(MAX_TANGENT_TURN_DEG))
        self._merge_w: np.ndarray | None = None
        self.on_point: Callable[[float], None] = lambda p: None  # told the parameter of every new branch point

    # -------------------------------------------------------------- building blocks
    def _jacobian(self, ev: MapEvaluation, Gq: np.ndarray, *rows: np.ndarray) -> np.ndarray:
        """[M − I, ∂G/∂q] with ``rows`` below it, then the rigid-body gauge rows (none for the pair)."""
        return np.vstack([np.hstack([ev.monodromy - np.eye(self.prob.dim), Gq[:, None]]), *rows, self.prob.gauge])

    def _finish_point(
        self, ev: MapEvaluation, p: float, Gq: np.ndarray, t_ref: np.ndarray | None, iters: int
    ) -> _Point:
        prob = self.prob
        _, _, vt = np.linalg.svd(self._jacobian(ev, Gq))  # the unit null vector: the last right singular vector
        t = vt[-1] / np.linalg.norm(vt[-1])
        if t_ref is not None and float(t @ t_ref) < 0:
            t = -t
        ext = element_extrema(prob.map_at(p).with_steps(ev.steps), ev.x)
        y = np.append(ev.x, p / self.ps)
        return _Point(y, ev, p, t, ext, prob.reference, iters)

    def correct(
        self, y0: np.ndarray, normal: np.ndarray, t_ref: np.ndarray | None, N: int | None = None
    ) -> _Point | None:
        """Newton on [P^n(x; p) − x; normal·(y − y0)] = 0 from y0 (y = (u, u', p/ps)), with N steps per
        period held fixed.  The parameter column of the Jacobian is taken at the first iterate (chord
        iteration in that column) and recomputed at the converged point for its tangent."""
        prob = self.prob
        ps = self.ps
        y = np.asarray(y0, dtype=float).copy()
        try:
            if N is None:
                N = prob.steps(y[-1] * ps)
            last_dy = math.inf
            Gq = None
            for it in range(CORRECTOR_MAX_ITER + 1):
                p = float(y[-1] * ps)
                pmap = prob.map_at(p).with_steps(N)
                ev = pmap.evaluate(y[:-1])
                if not ev.ok:
                    return None
                G = ev.residual
                done = float(np.linalg.norm(G)) <= CORRECTOR_TOL * (1.0 + float(np.linalg.norm(y[:-1])))
                done = done and last_dy <= CORRECTOR_STEP_TOL
                if not done and it == CORRECTOR_MAX_ITER:
                    return None
                if done or Gq is None:
                    Gp = pmap.param_derivative(y[:-1], prob.param)  # ∂P^n/∂p at fixed x and N
                    if not np.all(np.isfinite(Gp)):
                        return None
                    Gq = Gp * ps
                    if done:
                        return self._finish_point(ev, p, Gq, t_ref, it)
                J = self._jacobian(ev, Gq, normal)
                F = np.concatenate([G, [float(normal @ (y - y0))], prob.gauge @ (y - y0)])
                try:  # rigid-body modes: the gauge rows make the system full rank (least squares)
                    dy = np.linalg.lstsq(J, -F, rcond=None)[0] if prob.gauge.shape[0] else np.linalg.solve(J, -F)
                except np.linalg.LinAlgError:
                    return None
                y = y + dy
                last_dy = float(np.linalg.norm(dy))
                if not np.all(np.isfinite(y)):
                    return None
        except ModelError:
            return None
        return None

    def correct_natural(self, pt: _Point, t_ref: np.ndarray | None) -> _Point:
        """Re-solve at the N that belongs to the converged parameter (only changes anything for ω)."""
        N = self.prob.steps(pt.p)
        if N == pt.ev.steps:
            return pt
        again = self.correct(pt.y, pt.tangent, t_ref, N)
        return again if again is not None else pt

    def land(self, a: _Point, y: np.ndarray, p: float, hi: float) -> _Point | None:
        """The branch point on the bound of the interval (the upper one when p > hi) that the step from a to
        (y, p) crosses, exactly at the bound's parameter (natural step count), from the interpolated guess."""
        bound = self.hi if p > hi else self.lo
        frac = (bound - a.p) / (p - a.p) if p != a.p else 1.0
        y0 = a.y + frac * (y - a.y)
        y0[-1] = bound / self.ps
        return self.correct(y0, np.eye(self.prob.dim + 1)[-1], a.tangent, self.prob.steps(bound))  # normal: p

    # -------------------------------------------------------------- test functions
    def _separation(self, pt: _Point) -> np.ndarray | None:
        """P^{n/2}(x) − x on a branch of even period n (zero where it meets the period-n/2 branch)."""
        n = self.prob.n
        if n % 2:
            return None
        return pt.ev.points[n // 2 - 1] - pt.y[:-1]

    def _tests(self, pt: _Point, gaps: list[float]) -> dict[str, float]:
        M = self.prob.elastic(pt.M)
        out = {"turn": float(pt.tangent[-1])}
        if M.shape == (2, 2):
            tr, det = float(np.trace(M)), float(np.linalg.det(M))
            out.update(det_m_i=1.0 - tr + det, pd=1.0 + tr + det, ns=det - 1.0)
        else:  # det(I − M), det(I + M) and Π_{i<j} (μ_i μ_j − 1): zero at +1, −1 and a pair on the unit circle
            eye = np.eye(M.shape[0])
            mu = np.linalg.eigvals(M)
            prods = (mu[:, None] * mu[None, :])[np.triu_indices(mu.size, 1)]
            out.update(
                det_m_i=float(np.linalg.det(eye - M)),
                pd=float(np.linalg.det(eye + M)),
                ns=float(np.real(np.prod(prods - 1.0))),
            )
        for e, D in enumerate(gaps):  # grazing of every element (the reference element's keys unqualified)
            if D <= 0.0:
                continue
            tag = "" if e == pt.ref else f":{self.prob.names[e]}"
            for key, side, sign, _ in _GRAZING:
                out[key + tag] = float(pt.ext[e, side]) - sign * D
        sep = self._separation(pt)
        if sep is not None and self._merge_w is not None:
            out["merge"] = float(sep @ self._merge_w)
        return out

    def _test_at(self, name: str, pt: _Point, chord: np.ndarray) -> float:
        if name == "turn":
            t = pt.tangent if float(pt.tangent @ chord) >= 0 else -pt.tangent
            return float(t[-1])
        return self._tests(pt, self.prob.gaps_at(pt.p))[name]

    def locate_event(self, a: _Point, b: _Point, name: str) -> tuple[_Point, bool]:
        """Zero of test function ``name`` between branch points a and b (Illinois secant on the chord,
        each trial point corrected onto the branch in the hyperplane normal to the chord)."""
        d = b.y - a.y
        L = float(np.linalg.norm(d))
        e = d / L
        fa, fb = self._test_at(name, a, d), self._test_at(name, b, d)

        def trial(s: float, lo: float, hi: float) -> tuple[float, _Point, float] | None:
            for t in (s, 0.5 * (lo + hi)):  # the secant's point, else bisection
                pt = self.correct(a.y + t * d, e, a.tangent, a.ev.steps)
                if pt is not None:
                    return t, pt, self._test_at(name, pt, d)
            return None

        return illinois_on_chord(fa, fb, trial, a if abs(fa) <= abs(fb) else b, LOCATE_TOL, LOCATE_MAX_ITER, length=L)

    def detect_events(self, a: _Point, b: _Point, branch_index: int) -> list[tuple[float, Bifurcation, _Point]]:
        """Events between consecutive branch points a and b, located; sorted along the branch."""
        D = self.prob.gaps_at(a.p)
        sep_a = self._separation(a)
        norm_a = 0.0 if sep_a is None else float(np.linalg.norm(sep_a))
        self._merge_w = sep_a / norm_a if norm_a > 0.0 else None
        ta, tb = self._tests(a, D), self._tests(b, D)
        d = b.y - a.y
        L = float(np.linalg.norm(d))
        events = []
        chord = d / max(L, 1e-300)

        def sign_change(k: str) -> bool:
            return k in ta and k in tb and np.isfinite(ta[k]) and np.isfinite(tb[k]) and (ta[k] > 0) != (tb[k] > 0)

        # a period-2m branch meeting the period-m branch (the other end of a period doubling): P^m x − x
        # passes through zero and the branch continues onto its mirror image (x ↔ P^m x); stop there.
        # The merge point is a branch point of [M − I, ∂G/∂p] (rank 1), where the corrector is
        # ill-conditioned; it is not located here but interpolated, and :func:`continuation` replaces
        # it by the period doubling of the period-n/2 branch it belongs to.
        s_merge = math.inf
        sep_b = self._separation(b)
        if sign_change("merge") and (  # (both separations exist: the merge test is there)
            norm_a + float(np.linalg.norm(sep_b)) <= MERGE_STEP_FACTOR * float(np.linalg.norm(b.ev.x - a.ev.x))
        ):
            fa, fb = ta["merge"], tb["merge"]
            sig = fa / (fa - fb)
            mu = self.prob.multipliers(a.M + sig * (b.M - a.M))
            s_merge = sig * L
            x_m = a.ev.x + sig * (b.ev.x - a.ev.x)
            events.append(
                (
                    s_merge,
                    Bifurcation(
                        "merge",
                        self.prob.param,
                        a.p + sig * (b.p - a.p),
                        x_m,
                        self.prob.n,
                        branch_index,
                        mu,
                        a.u_min + sig * (b.u_min - a.u_min),
                        a.u_max + sig * (b.u_max - a.u_max),
                        "the branch meets the period-n/2 branch at its period doubling",
                        False,
                        None,
                        None,
                        "merge",
                    ),
                    a,
                )
            )

        turn = float(a.tangent[-1]) * float(b.tangent[-1]) < 0  # both oriented along the travel direction
        checks: list[tuple[str, str, str]] = []
        if math.isfinite(s_merge):
            pass  # the turn at the merge point is the tip of the period-doubling pitchfork, not a fold
        elif turn:
            checks.append(("turn", "fold", "real multiplier through +1 (turning point)"))
        elif sign_change("det_m_i"):
            checks.append(("det_m_i", "branch-point", "real multiplier through +1 without a turn"))
        if sign_change("pd"):
            checks.append(("pd", "period-doubling", "real multiplier through −1"))
        if sign_change("ns"):
            checks.append(("ns", "neimark-sacker", "complex pair through the unit circle"))
        for e, name in enumerate(self.prob.names):
            tag = "" if e == a.ref else f":{name}"
            of = "" if e == a.ref else f" of {name}"
            for k, _, _, lab in _GRAZING:
                if sign_change(k + tag):
                    checks.append((k + tag, "grazing", lab + of))
        for key, typ, detail in checks:
            if self.locate:
                pt, ok = self.locate_event(a, b, key)
            else:
                pt, ok = (a if abs(ta[key]) <= abs(tb[key]) else b), False
            mu = self.prob.multipliers(pt.M)
            if typ == "neimark-sacker" and np.all(np.abs(mu.imag) <= REAL_MULTIPLIER_TOL * np.abs(mu)):
                continue  # a real pair with product 1 (neutral saddle), not a bifurcation
            if typ == "fold" and self.prob.n > 1 and _minimal_period(pt.ev.points, self.prob.n) < self.prob.n:
                typ, detail = "merge", "the branch meets the period-n/2 branch (its period doubling)"
            s = float(chord @ (pt.y - a.y))
            if s >= s_merge:
                continue
            events.append(
                (
                    s,
                    Bifurcation(
                        typ,
                        self.prob.param,
                        pt.p,
                        pt.y[:-1].copy(),
                        self.prob.n,
                        branch_index,
                        mu,
                        pt.u_min,
                        pt.u_max,
                        detail,
                        ok,
                        bool(abs(self.prob.multipliers(a.M)[0]) < 1.0),
                        bool(abs(self.prob.multipliers(b.M)[0]) < 1.0),
                        key,
                    ),
                    pt,
                )
            )
        events.sort(key=lambda e: e[0])
        return events

    # -------------------------------------------------------------- the loop
    def run(self, first: _Point, direction: float, branch_index: int) -> tuple[list[_Point], list[Bifurcation], str]:
        """Continue from ``first`` with the parameter initially moving in ``direction`` (+1/−1)."""
        if first.tangent[-1] * direction < 0:
            first.tangent = -first.tangent
        pts = [first]
        bifs: list[Bifurcation] = []
        ds = self.ds
        lo = self.lo - 1e-12 * self.ps
        hi = self.hi + 1e-12 * self.ps
        while len(pts) < self.max_points:
            a = pts[-1]
            new = None
            outside = False
            while new is None:
                y_pred = a.y + ds * a.tangent
                p_pred = float(y_pred[-1] * self.ps)
                if (p_pred < lo or p_pred > hi) and abs(float(a.tangent[-1])) >= DIRECT_LANDING_MIN_TP:
                    # the step would leave the interval (perhaps where the model is not defined, such as
                    # D < 0) while the branch runs mainly along the parameter: land on the bound directly
                    landed = self.land(a, y_pred, p_pred, hi)
                    if landed is not None and float(landed.tangent @ a.tangent) >= self.cos_max_turn:
                        new, outside = landed, True
                        break
                cand = self.correct(y_pred, a.tangent, a.tangent)
                if cand is not None and (float(cand.tangent @ a.tangent) >= self.cos_max_turn or ds <= 4 * DS_MIN):
                    new = cand
                    break
                ds *= DS_SHRINK
                if ds < DS_MIN:
                    return pts, bifs, "step size underflow (no convergence)"
            if not outside:
                new = self.correct_natural(new, a.tangent)
                if new.p < lo or new.p > hi:  # interpolated to the bound and landed on it exactly
                    new, outside = self.land(a, new.y, new.p, hi) or new, True
            for _s, bif, bpt in self.detect_events(a, new, branch_index) if self.detect else ():
                bifs.append(bif)
                if bif.type == "merge":
                    return pts, bifs, "merged into the period-n/2 branch at its period doubling"
                if self.stop_on_instability and bif.type in STABILITY_LOSSES and bif.stable_before:
                    pts.append(bpt)
                    self.on_point(bpt.p)
                    return pts, bifs, "stopped at the first loss of stability"
            pts.append(new)
            self.on_point(new.p)
            if outside:
                return pts, bifs, "reached the end of the parameter interval"
            if new.iters <= FAST_CORRECTOR_ITERS:
                ds = min(ds * DS_GROW, self.ds_max)
            elif new.iters >= SLOW_CORRECTOR_ITERS:
                ds = max(ds * DS_SHRINK, DS_MIN)
        return pts, bifs, "max points"


def continue_branch(
    orbit: PeriodicOrbit,
    param: str,
    stop: float,
    *,
    start_bound: float | None = None,
    index: int = 0,
    ds: float | None = None,
    ds_max: float | None = None,
    max_points: int = MAX_BRANCH_POINTS,
    locate: bool = True,
    detect: bool = True,
    stop_on_instability: bool = False,
    origin: Bifurcation | None = None,
    direction: float | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> Branch:
    """Continue the branch through a converged orbit in ``param`` towards ``stop``.

    The branch is followed by pseudo-arclength continuation (so it passes around folds) until the
    parameter leaves the interval between ``start_bound`` (default: the orbit's value) and ``stop``,
    the step size underflows, or ``max_points`` is reached.  Events between consecutive points are
    detected by sign changes of test functions and located (see
    :func:`~geardyn.analysis.periodic.continuation`).

    Parameters
    ----------
    orbit : PeriodicOrbit
        A converged orbit; its model, period, Δτ and mode define the branch.
    param : str
        Continuation parameter (any model parameter name).
    stop : float
        Parameter value where the branch ends.
    start_bound : float, optional
        The other end of the interval (default: the orbit's parameter value).
    index : int
        Index given to the branch.
    ds, ds_max : float, optional
        Initial and largest arclength step (defaults :data:`DS_INIT`, :data:`DS_MAX`).
    max_points : int
        Largest number of branch points.
    locate : bool
        Locate events by a secant iteration (otherwise the nearer end of the bracketing step).
    detect : bool
        Watch the test functions at all.
    stop_on_instability : bool
        Stop at the first event where the orbit loses stability.
    origin : Bifurcation, optional
        The event the branch was switched from.
    direction : float, optional
        Initial direction of the parameter (+1 or −1; default towards ``stop``).
    progress : callable, optional
        Called as ``progress(done, total)`` with the parameter distance covered towards ``stop``
        (the farthest point reached so far, never decreasing, also past folds) and ``total`` =
        |stop − p0|: once at the start with ``done`` 0, at every branch point that gets farther,
        and with ``done`` = ``total`` when the branch ends (whatever ended it).

    Returns
    -------
    Branch
        Its points, events and why it ended (``end``).

    Raises
    ------
    ModelError
        If the orbit did not converge or cannot be corrected at its own parameter value.

    References
    ----------
    E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*, SIAM, 2003.
    """
    param = canonical_param(param)
    if not orbit.converged:
        raise ModelError("continuation: the starting orbit did not converge; give a better --guess")
    p0 = orbit.model.get(param)
    lo_b = p0 if start_bound is None else start_bound
    lo, hi = min(lo_b, stop), max(lo_b, stop)
    span = max(hi - lo, abs(stop - p0), 1e-12)
    prob = _Family(PeriodMap(orbit.model, orbit.n, dtau=orbit.dtau, accurate=orbit.accurate), param)
    cont = _Continuer(prob, lo, hi, span, ds, ds_max, max_points, locate, detect, stop_on_instability)
    if direction is None:
        direction = 1.0 if stop >= p0 else -1.0
    first = cont.correct(np.append(orbit.state, p0 / cont.ps), np.eye(prob.dim + 1)[-1], None, prob.steps(p0))
    if first is None:
        raise ModelError("continuation: the starting orbit could not be corrected at the start value")
    total = abs(float(stop) - float(p0))
    cont.on_point = _span_reporter(progress, float(p0), float(stop))
    pts, bifs, end = cont.run(first, direction, index)
    if progress is not None:
        progress(total, total)
    if not prob.accurate:
        bifs = _drop_discretization_noise(bifs, span)
    return Branch(
        index=index,
        param=prob.param,
        n=prob.n,
        values=np.array([q.p for q in pts]),
        states=np.array([q.y[:-1] for q in pts]),
        points=np.array([np.vstack([q.y[None, :-1], q.ev.points[:-1]]) for q in pts]).reshape(
            len(pts), prob.n, prob.dim
        ),
        monodromy=np.array([q.M for q in pts]),
        u_min=np.array([q.u_min for q in pts]),
        u_max=np.array([q.u_max for q in pts]),
        steps=np.array([q.ev.steps for q in pts], dtype=np.int64),
        end=end,
        origin=origin,
        bifurcations=bifs,
        elastic=prob.elastic_basis,
        extrema=np.array([q.ext for q in pts]).reshape(len(pts), len(prob.names), 2),
    )


def _span_reporter(progress: Callable[[float, float], None] | None, p0: float, stop: float) -> Callable[[float], None]:
    """A branch point's parameter → ``progress(farthest distance from p0 towards stop, |stop − p0|)`` when it grows
    (nothing without ``progress``); ``progress(0, |stop − p0|)`` is reported at once."""
    total = abs(stop - p0)
    if progress is None:
        return lambda p: None
    progress(0.0, total)
    sign = 1.0 if stop >= p0 else -1.0
    farthest = [0.0]

    def on_point(p: float) -> None:
        d = min(max(sign * (p - p0), 0.0), total)
        if d > farthest[0]:
            farthest[0] = d
            progress(d, total)

    return on_point


def _drop_discretization_noise(bifs: list[Bifurcation], span: float) -> list[Bifurcation]:
    """Default mode only: drop pairs of successive crossings of the same test function that lie
    closer than NOISE_PARAM_REL·span in the parameter.

    In the default mode the monodromy is the exact Jacobian of a discrete map whose derivative
    jumps (by O(h) relative) each time an RK4 stage crosses u = ±D, so a multiplier close to ±1
    can cross back and forth within a tiny parameter range.  Such back-and-forth pairs are
    artefacts of the discretisation; the accurate mode has no such jumps.
    """
    merges = [b.value for b in bifs if b.type == "merge"]
    kept: list[Bifurcation] = []
    for b in bifs:
        if b.type in ("fold", "branch-point") and any(abs(v - b.value) < NOISE_PARAM_REL * span for v in merges):
            continue  # the turn at a merge point is the tip of the period-doubling pitchfork
        if b.type == "merge" or not b.test:
            kept.append(b)
            continue
        prev = next((k for k in reversed(kept) if k.test == b.test), None)
        if prev is not None and abs(prev.value - b.value) < NOISE_PARAM_REL * span:
            kept.remove(prev)
            continue
        kept.append(b)
    return kept
