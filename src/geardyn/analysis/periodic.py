"""Periodic orbits: shooting, Floquet analysis, pseudo-arclength continuation, bifurcations.

A period-n orbit of the forced gear pair is a fixed point of the n-period stroboscopic map
P^n (section θ ≡ 0 mod 2π).  Everything here works on that map as computed by the one kernel
(:func:`geardyn.integrate.period_map`), which also returns its Jacobian, the monodromy matrix M,
by tangent propagation.  In the default integration mode M is the exact Jacobian of the discrete
map, so Newton's method converges quadratically; in the accurate mode (steps split at u = ±D) it
is the Jacobian of the split steps with the crossing times frozen, which is accurate to the
integration error (the vector field is continuous, so the flow needs no saltation correction).

Contents
--------
:func:`shoot`
    Newton on P^n(x) − x = 0 (damped by backtracking), with a guess from simulation when none
    is given.  Returns a :class:`PeriodicOrbit`.
:func:`floquet`
    Multipliers μ (eigenvalues of M), Floquet exponents ln|μ|/(nT) per unit τ, stability, and
    the type of instability.
:func:`continuation`
    Pseudo-arclength continuation of a branch of period-n orbits in any model parameter
    (``omega``, ``xi0``, ``kappa1``, ``fp``, ``D``, ...), around folds, with detection and location
    of folds (a multiplier through +1), period doublings (through −1), Neimark–Sacker points (a
    complex pair through the unit circle) and grazing (min or max of u over the orbit touching
    ±D); branch switching at period doublings onto the period-2n branch.
:func:`paper_stability_damping`, :func:`stability_boundary`, :func:`mathieu_boundary`, :func:`compare_stability_condition`
    The paper's stability condition ξ0 = ½√(1 − κ1²) and the stability boundaries Floquet
    analysis gives, for comparison.

All quantities are non-dimensional (displacements in units of the characteristic length b_c,
time τ in units of 1/ω_n).

Notes on the discrete map
-------------------------
In the default mode the step is h = T/N with N = ceil(T/Δτ).  When ω is the continuation
parameter N changes by one every ΔT ≈ Δτ, which moves the discrete map by an amount of the order
of the integration error.  The corrector therefore holds N fixed while it iterates and, after
convergence, re-solves with the N that belongs to the converged ω (the point reported is then
exactly what :func:`shoot` gives at that ω); parameter derivatives are taken with N fixed.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Iterable, Iterator, Sequence

import numpy as np
import xarray as xr

from ..integrate import integrate_batch, period_map, trajectory
from ..model import DEFAULT_DTAU, GearModel, IntegrationOptions, ModelError, canonical_param, steps_per_period

__all__ = [
    "PeriodicOrbit",
    "Floquet",
    "Bifurcation",
    "Branch",
    "ContinuationResult",
    "shoot",
    "floquet",
    "continuation",
    "continue_branch",
    "switch_at_period_doubling",
    "orbit_extrema",
    "paper_stability_damping",
    "paper_stability_condition",
    "stability_boundary",
    "mathieu_boundary",
    "compare_stability_condition",
    "BIFURCATION_TYPES",
]

# ---------------------------------------------------------------------------------------------
# Named constants (tolerances and defaults)
# ---------------------------------------------------------------------------------------------
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
#: A multiplier with |Im μ| below this (relative to |μ|) counts as real.
REAL_MULTIPLIER_TOL = 1.0e-9

#: Corrector (continuation): ||P^n(x) − x|| <= CORRECTOR_TOL·(1 + ||x||) and a last update below CORRECTOR_STEP_TOL.
CORRECTOR_TOL = 1.0e-9
CORRECTOR_STEP_TOL = 1.0e-7
#: Largest number of corrector iterations per continuation step.
CORRECTOR_MAX_ITER = 8
#: Relative step of the central finite difference for ∂P^n/∂p: δ = FD_REL_STEP·max(1, |p|).
FD_REL_STEP = 1.0e-6
#: Continuation step sizes: arclength in the space (u, u', p/ps) with the parameter scaled by
#: ps = |stop − start|, so that the whole parameter interval has length 1 (largest, initial, smallest).
DS_MAX = 0.01
DS_INIT = 0.002
DS_MIN = 1.0e-7
#: A step predicted beyond the end of the interval is corrected directly at the end value when the
#: parameter component of the (unit) tangent is at least this (far from a fold).
DIRECT_LANDING_MIN_TP = 0.2
#: Models kept per branch for repeated evaluations at the same parameter value.
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
#: Branch switching at a period doubling: parameter offset (relative to |stop − start|) at which the
#: period-2n orbit is sought, and the trial offsets along the critical eigenvector (times 1 + |x|).
SWITCH_PARAM_REL = 2.0e-3
SWITCH_AMPLITUDES = (3e-3, 1e-2, 3e-2, 1e-1, 3e-1)
#: Largest period reached by branch switching by default.
DEFAULT_MAX_PERIOD = 4

#: Default mode: successive opposite crossings of one test function closer than this (relative to
#: |stop − start|) are discretisation artefacts and are dropped (see :func:`_drop_discretization_noise`).
NOISE_PARAM_REL = 1.0e-3
#: A period doubling counts as the end of an already traced period-2n branch when its parameter and
#: state lie this close (relative to |stop − start| and to 1 + |x|) to that branch's merge point.
SAME_EVENT_PARAM_REL = 1.0e-3
SAME_EVENT_STATE_REL = 1.0e-2
#: A sign change of (P^{n/2}x − x)·w within one step counts as the branch meeting the period-n/2
#: branch when |P^{n/2}x − x| at both ends is at most this many times the step's change in x
#: (the separation passes through zero inside the step rather than turning by more than 90°).
MERGE_STEP_FACTOR = 10.0

#: Stability boundary scans in ξ0 start at XI0_SCAN_HIGH (a heavily damped, stable response) and
#: stop at XI0_SCAN_LOW (at ξ0 = 0 the mean damping vanishes, det M = 1, and every orbit is neutral).
XI0_SCAN_HIGH = 0.6
XI0_SCAN_LOW = 1.0e-3

#: Bifurcation (event) types reported by :func:`continuation`.
BIFURCATION_TYPES = ("fold", "period-doubling", "neimark-sacker", "grazing", "branch-point")

#: Instability types of a periodic orbit (see :class:`Floquet`).
INSTABILITY_TYPES = {
    "none": "stable: all multipliers inside the unit circle",
    "saddle": "one real multiplier > 1 (the kind of instability a fold creates)",
    "flip-saddle": "one real multiplier < −1 (the kind a period doubling creates)",
    "unstable-focus": "a complex pair outside the unit circle (the kind a Neimark–Sacker bifurcation creates)",
    "repeller": "both real multipliers outside the unit circle",
}


# ---------------------------------------------------------------------------------------------
# Kernel access
# ---------------------------------------------------------------------------------------------
@contextmanager
def _single_thread() -> Iterator[None]:
    """Run the kernel on one thread: shooting and continuation call it thousands of times on one
    point each, where starting a thread team costs far more than the integration itself."""
    import numba

    old = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(old)


def _dtau_for_steps(model: GearModel, N: int) -> float:
    """A Δτ for which the kernel uses exactly N steps per period of ``model`` (ceil(T/Δτ) = N)."""
    return model.period / (N - 0.5)


def _natural_steps(model: GearModel, dtau: float) -> int:
    return int(steps_per_period(model.omega, dtau))


@dataclass
class _Eval:
    """One evaluation of P^n at (x, p) with N steps per period."""

    x: np.ndarray
    p: float
    N: int
    points: np.ndarray
    M: np.ndarray
    ok: bool

    @property
    def G(self) -> np.ndarray:
        return self.points[-1] - self.x


class _Problem:
    """The fixed-point problem P^n(x; p) = x of one branch."""

    def __init__(self, model: GearModel, param: str | None, n: int, dtau: float, accurate: bool):
        self.base = model
        self.param = canonical_param(param) if param is not None else None
        self.n = int(n)
        self.dtau = float(dtau)
        self.accurate = bool(accurate)
        self._models: dict[float, GearModel] = {}

    def model_at(self, p: float | None) -> GearModel:
        if self.param is None or p is None:
            return self.base
        p = float(p)
        m = self._models.get(p)
        if m is None:
            if len(self._models) >= MODEL_CACHE_SIZE:
                self._models.clear()
            m = self._models[p] = self.base.with_param(self.param, p)
        return m

    def steps(self, p: float | None) -> int:
        return _natural_steps(self.model_at(p), self.dtau)

    def evaluate(self, x: np.ndarray, p: float | None, N: int | None = None) -> _Eval:
        m = self.model_at(p)
        if N is None:
            N = _natural_steps(m, self.dtau)
        x = np.asarray(x, dtype=float)
        if not np.all(np.isfinite(x)):
            return _Eval(x, p, N, np.full((self.n, 2), np.nan), np.full((2, 2), np.nan), False)
        pts, M, _st, ok = period_map(m, x, self.n, dtau=_dtau_for_steps(m, N), accurate=self.accurate)
        ok = ok and bool(np.all(np.isfinite(M)))
        return _Eval(x.copy(), p, N, pts, M, ok)

    def dG_dp(self, x: np.ndarray, p: float, N: int) -> np.ndarray | None:
        """∂P^n/∂p at fixed x and fixed N (central difference in one kernel batch; one-sided at a
        domain edge such as D = 0)."""
        d = FD_REL_STEP * max(1.0, abs(p))
        x = np.asarray(x, dtype=float)
        pts, steps = [], []
        for q in (p + d, p - d, p):
            try:
                pts.append(self.model_at(q))
                steps.append(q)
            except ModelError:
                continue
        if len(steps) < 2:
            return None
        if steps[0] == p + d and steps[1] == p - d:
            pts, steps = pts[:2], steps[:2]
        # Δτ giving exactly N steps per period at p gives N at p ± d too (|d/p| << 1/N)
        opts = IntegrationOptions(dtau=_dtau_for_steps(self.model_at(p), N), transient=0, periods=self.n,
                                  accurate=self.accurate)
        res = integrate_batch(pts, x, opts)
        if not np.all(res.ok) or not np.all(res.nsteps == N):
            return None
        ends = res.poincare[:, -1, :]
        return (ends[0] - ends[1]) / (steps[0] - steps[1])


# ---------------------------------------------------------------------------------------------
# Orbit extrema (dense refinement)
# ---------------------------------------------------------------------------------------------
def _hermite_extrema(u: np.ndarray, v: np.ndarray, h: float) -> tuple[float, float]:
    """Min and max of the piecewise cubic Hermite interpolant through (u_k, u'_k) sampled every h."""
    u0, u1, v0, v1 = u[:-1], u[1:], v[:-1], v[1:]
    cand_min = [float(np.min(u))]
    cand_max = [float(np.max(u))]
    idx = np.nonzero(v0 * v1 <= 0.0)[0]
    if idx.size:
        a0, a1, b0, b1 = u0[idx], u1[idx], h * v0[idx], h * v1[idx]
        # u(x) = (2x³−3x²+1)a0 + (x³−2x²+x)b0 + (−2x³+3x²)a1 + (x³−x²)b1; u'(x) = A x² + B x + C
        A = 6 * a0 + 3 * b0 - 6 * a1 + 3 * b1
        B = -6 * a0 - 4 * b0 + 6 * a1 - 2 * b1
        C = b0
        xs = []
        with np.errstate(divide="ignore", invalid="ignore"):
            disc = np.sqrt(np.maximum(B * B - 4 * A * C, 0.0))
            quad = np.abs(A) > 1e-14 * (np.abs(B) + np.abs(C) + 1e-300)
            r1 = np.where(quad, (-B + disc) / (2 * A), -C / B)
            r2 = np.where(quad, (-B - disc) / (2 * A), -C / B)
        for r in (r1, r2):
            xs.append(r)
        for r in xs:
            ok = np.isfinite(r) & (r >= 0.0) & (r <= 1.0)
            if not np.any(ok):
                continue
            x = r[ok]
            x2, x3 = x * x, x * x * x
            val = ((2 * x3 - 3 * x2 + 1) * a0[ok] + (x3 - 2 * x2 + x) * b0[ok] + (-2 * x3 + 3 * x2) * a1[ok]
                   + (x3 - x2) * b1[ok])
            cand_min.append(float(np.min(val)))
            cand_max.append(float(np.max(val)))
    return min(cand_min), max(cand_max)


def orbit_extrema(model: GearModel, state: Sequence[float], n: int = 1, *, dtau: float = DEFAULT_DTAU,
                  accurate: bool = False, steps: int | None = None) -> tuple[float, float]:
    """Smallest and largest u over n periods from ``state`` (non-dimensional), refined between the
    step ends by the cubic Hermite interpolant of (u, u') (error O(h⁴) instead of O(h²) for the
    step-end samples).  ``steps`` fixes the number of RK4 steps per period (default ceil(T/Δτ))."""
    N = _natural_steps(model, dtau) if steps is None else int(steps)
    opts = IntegrationOptions(dtau=_dtau_for_steps(model, N), transient=0, periods=int(n), accurate=accurate)
    with _single_thread():
        tr = trajectory(model, state, opts, history_periods=int(n))
    if not np.all(np.isfinite(tr.u)):
        return math.nan, math.nan
    return _hermite_extrema(tr.u, tr.v, model.period / N)


# ---------------------------------------------------------------------------------------------
# Floquet analysis
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Floquet:
    """Floquet analysis of a period-n orbit from its monodromy matrix (non-dimensional).

    Attributes
    ----------
    multipliers : ndarray of complex (2,)
        Eigenvalues μ of the monodromy matrix, largest modulus first.
    exponents : ndarray (2,)
        Floquet (Lyapunov) exponents ln|μ|/(nT) per unit τ; for a stable orbit the first equals the
        largest Lyapunov exponent.
    stable : bool
        All |μ| < 1 (asymptotically stable).
    instability : str
        One of :data:`INSTABILITY_TYPES`: ``none``, ``saddle`` (a real μ > 1), ``flip-saddle``
        (a real μ < −1), ``unstable-focus`` (a complex pair with |μ| > 1), ``repeller``.
    determinant, trace : float
        det M and tr M; for this model det M = exp(−2 ξ0 n T).
    """

    multipliers: np.ndarray
    exponents: np.ndarray
    stable: bool
    instability: str
    determinant: float
    trace: float

    @property
    def max_modulus(self) -> float:
        return float(np.max(np.abs(self.multipliers)))

    @property
    def crossing(self) -> str | None:
        """The bifurcation through which this kind of instability arises (None if stable)."""
        return {"saddle": "fold", "flip-saddle": "period-doubling", "unstable-focus": "neimark-sacker",
                "repeller": None, "none": None}[self.instability]

    def pairs(self) -> list[list[float]]:
        """Multipliers as [[re, im], ...] (the JSON form)."""
        return [[float(m.real), float(m.imag)] for m in self.multipliers]


def floquet(monodromy: np.ndarray, n: int, period: float) -> Floquet:
    """Floquet multipliers, exponents, stability and instability type of a period-n orbit.

    Parameters
    ----------
    monodromy : (2, 2) array
        Jacobian of P^n at a point of the orbit (from :func:`geardyn.integrate.period_map`).
    n : int
        Number of forcing periods of the orbit.
    period : float
        Forcing period T = 2π/ω (non-dimensional time).
    """
    M = np.asarray(monodromy, dtype=float)
    if not np.all(np.isfinite(M)):
        nan = np.array([complex(math.nan, 0.0)] * 2)
        return Floquet(nan, np.full(2, math.nan), False, "repeller", math.nan, math.nan)
    mu = np.linalg.eigvals(M).astype(complex)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    with np.errstate(divide="ignore"):
        expo = np.log(np.abs(mu)) / (n * period)
    mod = np.abs(mu)
    out = mod > 1.0
    stable = bool(not np.any(out))
    is_real = np.abs(mu.imag) <= REAL_MULTIPLIER_TOL * np.maximum(mod, 1e-300)
    if stable:
        kind = "none"
    elif not np.all(is_real):
        kind = "unstable-focus"
    elif np.all(out):
        kind = "repeller"
    else:
        kind = "saddle" if mu[0].real > 0 else "flip-saddle"
    return Floquet(mu, expo, stable, kind, float(np.linalg.det(M)), float(np.trace(M)))


# ---------------------------------------------------------------------------------------------
# Shooting
# ---------------------------------------------------------------------------------------------
def _impact_label(u_min: float, D: float) -> str:
    from .classify import IMPACT_LABELS, impact_state

    return IMPACT_LABELS[impact_state(u_min, D)]


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
    """A period-n orbit found by shooting (all quantities non-dimensional).

    Attributes
    ----------
    model : GearModel
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
    status : str
        ``converged``, ``not converged`` or ``diverged``.
    iterations : int
    residuals : list of float
        ||P^n(x) − x|| at each Newton iterate (quadratic decrease in the default mode; when the
        default-mode iteration stalls far from the orbit, the accurate-mode iterates that brought it
        close follow, then the final default-mode ones).
    u_min, u_max : float
        Extremes of u over the orbit (Hermite-refined between steps).
    """

    model: GearModel
    n: int
    state: np.ndarray
    points: np.ndarray
    monodromy: np.ndarray
    converged: bool
    status: str
    iterations: int
    residuals: list[float]
    u_min: float
    u_max: float
    dtau: float = DEFAULT_DTAU
    accurate: bool = False
    steps: int = 0

    @property
    def residual(self) -> float:
        return self.residuals[-1] if self.residuals else math.nan

    @property
    def floquet(self) -> Floquet:
        return floquet(self.monodromy, self.n, self.model.period)

    @property
    def multipliers(self) -> np.ndarray:
        return self.floquet.multipliers

    @property
    def stable(self) -> bool:
        return self.converged and self.floquet.stable

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
        return _impact_label(self.u_min, self.model.D)

    def history(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(τ, u, u') at every step over the n periods of the orbit, starting at ``state``."""
        N = self.steps or _natural_steps(self.model, self.dtau)
        opts = IntegrationOptions(dtau=_dtau_for_steps(self.model, N), transient=0, periods=self.n,
                                  accurate=self.accurate)
        with _single_thread():
            tr = trajectory(self.model, self.state, opts, history_periods=self.n)
        return tr.tau, tr.u, tr.v

    def to_json(self) -> dict[str, Any]:
        """The ``orbit --json`` summary (DESIGN §5 keys plus a few more)."""
        fl = self.floquet

        def num(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        return {
            "omega": self.model.omega,
            "state": [float(self.state[0]), float(self.state[1])],
            "points": self.points.tolist(),
            "period": self.minimal_period if self.converged else None,
            "requested_period": self.n,
            "multipliers": fl.pairs(),
            "multiplier_moduli": [float(abs(m)) for m in fl.multipliers],
            "floquet_exponents": [num(e) for e in fl.exponents],
            "stable": bool(self.stable),
            "instability": fl.instability,
            "converged": bool(self.converged),
            "status": self.status,
            "iterations": self.iterations,
            "residual": num(self.residual),
            "u_min": num(self.u_min),
            "u_max": num(self.u_max),
            "amplitude": num(self.amplitude),
            "impact": self.impact,
            "determinant": num(fl.determinant),
            "accurate": self.accurate,
        }

    def to_dataset(self) -> xr.Dataset:
        """Section points, multipliers, monodromy and the time history over the orbit's n periods."""
        from ..io import result_attrs

        tau, u, v = self.history() if self.converged else (np.zeros(0), np.zeros(0), np.zeros(0))
        fl = self.floquet
        ds = xr.Dataset(
            {
                "poincare_u": ("section", self.points[:, 0]),
                "poincare_v": ("section", self.points[:, 1]),
                "multiplier_re": ("multiplier", fl.multipliers.real),
                "multiplier_im": ("multiplier", fl.multipliers.imag),
                "floquet_exponent": ("multiplier", fl.exponents),
                "monodromy": (("row", "col"), self.monodromy),
                "u": ("tau", u),
                "v": ("tau", v),
            },
            coords={"tau": tau, "section": np.arange(self.n), "multiplier": np.arange(2), "row": [0, 1],
                    "col": [0, 1]},
            attrs=result_attrs(
                "orbit", self.model,
                {"dtau": self.dtau, "accurate": self.accurate, "steps_per_period": self.steps},
                summary=self.to_json(),
            ),
        )
        for name, (units, long) in {
            "multiplier_re": ("1", "Floquet multiplier, real part"),
            "multiplier_im": ("1", "Floquet multiplier, imaginary part"),
            "floquet_exponent": ("1/τ", "Floquet exponent ln|μ|/(nT)"),
            "monodromy": ("1", "monodromy matrix (Jacobian of the n-period map)"),
            "section": ("1", "index of the section point along the orbit"),
            "multiplier": ("1", "multiplier index (largest modulus first)"),
            "row": ("1", "row of the monodromy matrix"),
            "col": ("1", "column of the monodromy matrix"),
        }.items():
            ds[name].attrs.update(units=units, long_name=long)
        ds.attrs["status"] = self.status
        return ds


def guess_from_simulation(model: GearModel, n: int = 1, state0: Sequence[float] | None = None, *,
                          dtau: float = DEFAULT_DTAU, accurate: bool = False,
                          transient: int = GUESS_TRANSIENT) -> np.ndarray | None:
    """A shooting guess: simulate ``transient`` periods, then pick among the next Poincaré points the
    one closest to recurring after n periods.  None if the simulation diverged."""
    rec = max(GUESS_RECORD_PER_PERIOD * n, 16)
    s0 = np.zeros(2) if state0 is None else np.asarray(state0, dtype=float)
    opts = IntegrationOptions(dtau=dtau, transient=int(transient), periods=rec, accurate=accurate)
    with _single_thread():
        res = integrate_batch([model], s0, opts)
    if not res.ok[0]:
        return None
    pts = res.poincare[0]
    d = np.linalg.norm(pts[n:] - pts[:-n], axis=1)
    k = int(np.argmin(d[::-1]))  # latest among the closest
    return pts[len(d) - 1 - k].copy()


def _newton(prob: _Problem, x0: np.ndarray, p: float | None, N: int, tol: float, max_iter: int
            ) -> tuple[_Eval | None, bool, int, list[float], str]:
    """Damped Newton on P^n(x) − x = 0 at fixed parameter; returns (last eval, converged, iterations, residuals, status)."""
    ev = prob.evaluate(x0, p, N)
    if not ev.ok:
        return ev, False, 0, [math.inf], "diverged"
    res = [float(np.linalg.norm(ev.G))]
    for it in range(max_iter + 1):
        r = res[-1]
        if r <= tol * (1.0 + float(np.linalg.norm(ev.x))):
            return ev, True, it, res, "converged"
        if it == max_iter:
            break
        A = ev.M - np.eye(2)
        try:
            dx = np.linalg.solve(A, -ev.G)
        except np.linalg.LinAlgError:
            dx = np.linalg.lstsq(A, -ev.G, rcond=None)[0]
        lam = 1.0
        new = None
        while lam >= NEWTON_MIN_DAMPING:
            trial = prob.evaluate(ev.x + lam * dx, p, N)
            if trial.ok and float(np.linalg.norm(trial.G)) < (1.0 - 1e-4 * lam) * r:
                new = trial
                break
            lam *= 0.5
        if new is None:
            return ev, False, it + 1, res, "not converged"
        ev = new
        res.append(float(np.linalg.norm(ev.G)))
    return ev, False, max_iter, res, "not converged"


def shoot(model: GearModel, n: int = 1, guess: Sequence[float] | None = None, *, dtau: float = DEFAULT_DTAU,
          accurate: bool = False, tol: float = SHOOT_TOL, max_iter: int = SHOOT_MAX_ITER,
          state0: Sequence[float] | None = None, transient: int = GUESS_TRANSIENT) -> PeriodicOrbit:
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

    Returns
    -------
    PeriodicOrbit
        Check ``converged``/``status``; its Floquet analysis is ``orbit.floquet``.
    """
    n = int(n)
    if n < 1:
        raise ModelError(f"period: must be an integer >= 1, got {n}")
    IntegrationOptions(dtau=dtau).check_for(model.omega)
    prob = _Problem(model, None, n, dtau, accurate)
    N = prob.steps(None)
    with _single_thread():
        if guess is None:
            x0 = guess_from_simulation(model, n, state0, dtau=dtau, accurate=accurate, transient=transient)
            if x0 is None:
                return _failed_orbit(model, n, np.zeros(2) if state0 is None else np.asarray(state0, float),
                                     "diverged", dtau, accurate, N)
        else:
            x0 = np.asarray(guess, dtype=float)
            if x0.shape != (2,) or not np.all(np.isfinite(x0)):
                raise ModelError(f"guess: expected two finite numbers u,v, got {guess!r}")
        ev, conv, its, res, status = _newton(prob, x0, None, N, tol, max_iter)
        if not conv and not accurate:
            # The default-mode map has a kink wherever an RK4 stage crosses ±D, which can stall the
            # damped iteration far from the orbit.  The accurate-mode map is smooth there and its orbit
            # lies within the discretisation error of the default-mode one: get close with it, then
            # finish in the default mode (quadratic convergence).
            acc = _Problem(model, None, n, dtau, True)
            ev_a, conv_a, its_a, res_a, _st = _newton(acc, x0, None, N, tol, max_iter)
            if conv_a:
                ev2, conv, its2, res2, status = _newton(prob, ev_a.x, None, N, tol, max_iter)
                if ev2 is not None and ev2.ok:
                    ev, its, res = ev2, its + its_a + its2, res + res_a + res2
    if ev is None or not ev.ok:
        return _failed_orbit(model, n, x0, "diverged", dtau, accurate, N)
    return _orbit_from_eval(model, prob, ev, conv, status, its, res)


def _orbit_from_eval(model: GearModel, prob: _Problem, ev: _Eval, conv: bool, status: str, its: int,
                     res: list[float]) -> PeriodicOrbit:
    pts = np.vstack([ev.x[None, :], ev.points[:-1]])
    umin, umax = orbit_extrema(model, ev.x, prob.n, dtau=prob.dtau, accurate=prob.accurate, steps=ev.N)
    return PeriodicOrbit(model, prob.n, ev.x.copy(), pts, ev.M.copy(), conv, status, its, res, umin, umax,
                         prob.dtau, prob.accurate, ev.N)


def _failed_orbit(model: GearModel, n: int, x: np.ndarray, status: str, dtau: float, accurate: bool,
                  N: int) -> PeriodicOrbit:
    nanpts = np.full((n, 2), np.nan)
    return PeriodicOrbit(model, n, np.asarray(x, float), nanpts, np.full((2, 2), np.nan), False, status, 0,
                         [math.inf], math.nan, math.nan, dtau, accurate, N)


# ---------------------------------------------------------------------------------------------
# Continuation
# ---------------------------------------------------------------------------------------------
@dataclass
class Bifurcation:
    """A located event on a branch (non-dimensional).

    ``type`` is one of :data:`BIFURCATION_TYPES`; ``value`` the parameter value; ``state`` the orbit's
    (u, u') at θ = 0; ``n`` the period of the branch it lies on; ``detail`` says which multiplier or
    which boundary (e.g. ``u_min = +D``); ``located`` is False when the location did not converge
    (the value is then the better end of the bracketing step).
    """

    type: str
    param: str
    value: float
    state: np.ndarray
    n: int
    branch: int
    multipliers: np.ndarray
    u_min: float
    u_max: float
    detail: str = ""
    located: bool = True
    stable_before: bool | None = None
    stable_after: bool | None = None
    test: str = ""

    @property
    def amplitude(self) -> float:
        return 0.5 * (self.u_max - self.u_min)

    def to_json(self) -> dict[str, Any]:
        return {
            "type": self.type,
            self.param: float(self.value),
            "period": int(self.n),
            "branch": int(self.branch),
            "state": [float(self.state[0]), float(self.state[1])],
            "amplitude": float(self.amplitude),
            "u_min": float(self.u_min),
            "u_max": float(self.u_max),
            "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "detail": self.detail,
            "located": bool(self.located),
        }


@dataclass
class _Point:
    y: np.ndarray  # (u, u', p/ps): the parameter scaled by the continuation's parameter scale ps
    ev: _Eval
    Gq: np.ndarray  # ∂P^n/∂(p/ps)
    tangent: np.ndarray
    u_min: float
    u_max: float
    iters: int = 0

    @property
    def p(self) -> float:
        return float(self.ev.p)

    @property
    def M(self) -> np.ndarray:
        return self.ev.M


@dataclass
class Branch:
    """A continued branch of period-n orbits (arrays over its K points, non-dimensional).

    ``values`` the parameter, ``states`` (K, 2) the orbit at θ = 0, ``points`` (K, n, 2) all section
    points, ``multipliers`` (K, 2) complex, ``u_min``/``u_max`` (K,), ``stable`` (K,).  ``origin`` is
    the bifurcation it was switched from (None for a primary branch); ``end`` says why it stopped.
    """

    index: int
    param: str
    n: int
    values: np.ndarray
    states: np.ndarray
    points: np.ndarray
    monodromy: np.ndarray
    u_min: np.ndarray
    u_max: np.ndarray
    steps: np.ndarray
    end: str
    origin: Bifurcation | None = None
    bifurcations: list[Bifurcation] = field(default_factory=list)

    @property
    def multipliers(self) -> np.ndarray:
        mu = np.linalg.eigvals(self.monodromy)
        order = np.argsort(-np.abs(mu), axis=1, kind="stable")
        return np.take_along_axis(mu, order, axis=1)

    @property
    def stable(self) -> np.ndarray:
        return np.max(np.abs(self.multipliers), axis=1) < 1.0

    @property
    def amplitude(self) -> np.ndarray:
        return 0.5 * (self.u_max - self.u_min)

    def __len__(self) -> int:
        return len(self.values)


def _null_vector(Ja: np.ndarray) -> np.ndarray:
    """Unit null vector of a 2x3 matrix (last right singular vector)."""
    _, _, vt = np.linalg.svd(Ja)
    t = vt[-1]
    return t / np.linalg.norm(t)


class _Continuer:
    """Pseudo-arclength continuation of one branch with event detection."""

    def __init__(self, prob: _Problem, lo: float, hi: float, span: float, ds: float | None, ds_max: float | None,
                 max_points: int, locate: bool, detect: bool = True, stop_on_instability: bool = False):
        self.prob = prob
        self.lo, self.hi = lo, hi
        self.span = span
        self.ps = span  # parameter scale: the continuation works in (u, u', p/ps)
        self.ds_max = ds_max if ds_max is not None else DS_MAX
        self.ds = min(ds if ds is not None else DS_INIT, self.ds_max)
        self.ds_min = DS_MIN
        self.max_points = max_points
        self.locate = locate
        self.detect = detect
        self.stop_on_instability = stop_on_instability
        self.cos_max_turn = math.cos(math.radians(MAX_TANGENT_TURN_DEG))
        self._merge_w: np.ndarray | None = None

    # -------------------------------------------------------------- building blocks
    def _finish_point(self, ev: _Eval, Gq: np.ndarray, t_ref: np.ndarray | None, iters: int) -> _Point:
        prob = self.prob
        J = np.hstack([ev.M - np.eye(2), Gq[:, None]])
        t = _null_vector(J)
        if t_ref is not None and float(t @ t_ref) < 0:
            t = -t
        m = prob.model_at(ev.p)
        umin, umax = orbit_extrema(m, ev.x, prob.n, dtau=prob.dtau, accurate=prob.accurate, steps=ev.N)
        y = np.array([ev.x[0], ev.x[1], ev.p / self.ps])
        return _Point(y, ev, Gq, t, umin, umax, iters)

    def correct(self, y0: np.ndarray, normal: np.ndarray, t_ref: np.ndarray | None, N: int | None = None
                ) -> _Point | None:
        """Newton on [P^n(x; p) − x; normal·(y − y0)] = 0 from y0 (y = (u, u', p/ps)), with N steps per
        period held fixed.  The parameter column of the Jacobian is taken at the first iterate (chord
        iteration in that column) and recomputed at the converged point for its tangent."""
        prob = self.prob
        ps = self.ps
        y = np.asarray(y0, dtype=float).copy()
        try:
            if N is None:
                N = prob.steps(y[2] * ps)
            last_dy = math.inf
            Gq = None
            for it in range(CORRECTOR_MAX_ITER + 1):
                p = float(y[2] * ps)
                ev = prob.evaluate(y[:2], p, N)
                if not ev.ok:
                    return None
                G = ev.G
                r = float(np.linalg.norm(G))
                if r <= CORRECTOR_TOL * (1.0 + float(np.linalg.norm(y[:2]))) and last_dy <= CORRECTOR_STEP_TOL:
                    Gp = prob.dG_dp(y[:2], p, N)
                    if Gp is None:
                        return None
                    return self._finish_point(ev, Gp * ps, t_ref, it)
                if it == CORRECTOR_MAX_ITER:
                    return None
                if Gq is None:
                    Gp = prob.dG_dp(y[:2], p, N)
                    if Gp is None:
                        return None
                    Gq = Gp * ps
                J = np.zeros((3, 3))
                J[:2, :2] = ev.M - np.eye(2)
                J[:2, 2] = Gq
                J[2, :] = normal
                F = np.concatenate([G, [float(normal @ (y - y0))]])
                try:
                    dy = np.linalg.solve(J, -F)
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
        if N == pt.ev.N:
            return pt
        again = self.correct(pt.y, pt.tangent, t_ref, N)
        return again if again is not None else pt

    def at_parameter(self, y_guess: np.ndarray, p: float, t_ref: np.ndarray | None) -> _Point | None:
        """The branch point with the parameter exactly p (natural step count), from a nearby guess."""
        y0 = np.array([y_guess[0], y_guess[1], p / self.ps])
        return self.correct(y0, np.array([0.0, 0.0, 1.0]), t_ref, self.prob.steps(p))

    # -------------------------------------------------------------- test functions
    def _separation(self, pt: _Point) -> np.ndarray | None:
        """P^{n/2}(x) − x on a branch of even period n (zero where it meets the period-n/2 branch)."""
        n = self.prob.n
        if n % 2:
            return None
        return pt.ev.points[n // 2 - 1] - pt.y[:2]

    def _tests(self, pt: _Point, D: float) -> dict[str, float]:
        M = pt.M
        tr, det = float(np.trace(M)), float(np.linalg.det(M))
        out = {
            "turn": float(pt.tangent[2]),
            "det_m_i": 1.0 - tr + det,
            "pd": 1.0 + tr + det,
            "ns": det - 1.0,
        }
        if D > 0.0:
            out["graze_min_plus"] = pt.u_min - D
            out["graze_min_minus"] = pt.u_min + D
            out["graze_max_plus"] = pt.u_max - D
            out["graze_max_minus"] = pt.u_max + D
        sep = self._separation(pt)
        if sep is not None and self._merge_w is not None:
            out["merge"] = float(sep @ self._merge_w)
        return out

    def _test_at(self, name: str, pt: _Point, chord: np.ndarray) -> float:
        if name == "turn":
            t = pt.tangent if float(pt.tangent @ chord) >= 0 else -pt.tangent
            return float(t[2])
        if name == "merge":
            sep = self._separation(pt)
            return float(sep @ self._merge_w) if sep is not None and self._merge_w is not None else math.nan
        return self._tests(pt, self.prob.model_at(pt.p).D)[name]

    def locate_event(self, a: _Point, b: _Point, name: str) -> tuple[_Point, bool]:
        """Zero of test function ``name`` between branch points a and b (Illinois secant on the chord,
        each trial point corrected onto the branch in the hyperplane normal to the chord)."""
        d = b.y - a.y
        L = float(np.linalg.norm(d))
        e = d / L
        fa, fb = self._test_at(name, a, d), self._test_at(name, b, d)
        lo, hi, flo, fhi = 0.0, 1.0, fa, fb
        best = a if abs(fa) <= abs(fb) else b
        side = 0
        for _ in range(LOCATE_MAX_ITER):
            if (hi - lo) * L <= LOCATE_TOL:
                return best, True
            s = (lo * fhi - hi * flo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
            if not (lo < s < hi):
                s = 0.5 * (lo + hi)
            pt = self.correct(a.y + s * d, e, a.tangent, a.ev.N)
            if pt is None:  # fall back to bisection
                s = 0.5 * (lo + hi)
                pt = self.correct(a.y + s * d, e, a.tangent, a.ev.N)
                if pt is None:
                    return best, False
            f = self._test_at(name, pt, d)
            best = pt
            if f == 0.0:
                return pt, True
            if (f > 0) == (flo > 0):
                lo, flo = s, f
                if side == -1:
                    fhi *= 0.5
                side = -1
            else:
                hi, fhi = s, f
                if side == 1:
                    flo *= 0.5
                side = 1
        return best, (hi - lo) * L <= 1e3 * LOCATE_TOL

    def detect_events(self, a: _Point, b: _Point, branch_index: int) -> list[tuple[float, Bifurcation, _Point]]:
        """Events between consecutive branch points a and b, located; sorted along the branch."""
        D = self.prob.model_at(a.p).D
        sep_a = self._separation(a)
        self._merge_w = None
        if sep_a is not None and float(np.linalg.norm(sep_a)) > 0.0:
            self._merge_w = sep_a / float(np.linalg.norm(sep_a))
        ta, tb = self._tests(a, D), self._tests(b, D)
        d = b.y - a.y
        events = []
        chord = d / max(float(np.linalg.norm(d)), 1e-300)

        def sign_change(k: str) -> bool:
            return k in ta and k in tb and np.isfinite(ta[k]) and np.isfinite(tb[k]) and (ta[k] > 0) != (tb[k] > 0)

        # a period-2m branch meeting the period-m branch (the other end of a period doubling): P^m x − x
        # passes through zero and the branch continues onto its mirror image (x ↔ P^m x); stop there.
        # The merge point is a branch point of [M − I, ∂G/∂p] (rank 1), where the corrector is
        # ill-conditioned; it is not located here but interpolated, and :func:`continuation` replaces
        # it by the period doubling of the period-n/2 branch it belongs to.
        s_merge = math.inf
        sep_b = self._separation(b)
        if sign_change("merge") and sep_a is not None and sep_b is not None and (
                float(np.linalg.norm(sep_a)) + float(np.linalg.norm(sep_b))
                <= MERGE_STEP_FACTOR * float(np.linalg.norm(b.ev.x - a.ev.x))):
            fa, fb = ta["merge"], tb["merge"]
            sig = fa / (fa - fb)
            mu = np.linalg.eigvals(a.M + sig * (b.M - a.M))
            mu = mu[np.argsort(-np.abs(mu), kind="stable")]
            s_merge = sig * float(np.linalg.norm(d))
            x_m = a.ev.x + sig * (b.ev.x - a.ev.x)
            events.append((s_merge, Bifurcation(
                "merge", self.prob.param, a.p + sig * (b.p - a.p), x_m, self.prob.n, branch_index, mu,
                a.u_min + sig * (b.u_min - a.u_min), a.u_max + sig * (b.u_max - a.u_max),
                "the branch meets the period-n/2 branch at its period doubling", False, None, None, "merge"), a))

        turn = float(a.tangent[2]) * float(b.tangent[2]) < 0  # both oriented along the travel direction
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
        for k, lab in (("graze_min_plus", "u_min = +D (drive-side contact loss)"),
                       ("graze_min_minus", "u_min = −D (back-side contact)"),
                       ("graze_max_plus", "u_max = +D (drive-side contact)"),
                       ("graze_max_minus", "u_max = −D")):
            if sign_change(k):
                checks.append((k, "grazing", lab))
        for key, typ, detail in checks:
            if self.locate:
                pt, ok = self.locate_event(a, b, key)
            else:
                pt, ok = (a if abs(ta[key]) <= abs(tb[key]) else b), False
            mu = np.linalg.eigvals(pt.M)
            mu = mu[np.argsort(-np.abs(mu), kind="stable")]
            if typ == "neimark-sacker" and np.all(np.abs(mu.imag) <= REAL_MULTIPLIER_TOL * np.abs(mu)):
                continue  # a real pair with product 1 (neutral saddle), not a bifurcation
            if typ == "fold":
                pts = np.vstack([pt.ev.points])
                if self.prob.n > 1 and _minimal_period(pts, self.prob.n) < self.prob.n:
                    typ, detail = "merge", "the branch meets the period-n/2 branch (its period doubling)"
            s = float(chord @ (pt.y - a.y))
            if s >= s_merge:
                continue
            events.append((s, Bifurcation(
                typ, self.prob.param, pt.p, pt.y[:2].copy(), self.prob.n, branch_index, mu, pt.u_min, pt.u_max,
                detail, ok, bool(np.max(np.abs(np.linalg.eigvals(a.M))) < 1.0),
                bool(np.max(np.abs(np.linalg.eigvals(b.M))) < 1.0), key), pt))
        events.sort(key=lambda e: e[0])
        return events

    # -------------------------------------------------------------- the loop
    def run(self, first: _Point, direction: float, branch_index: int, prefix: list[_Point] | None = None
            ) -> tuple[list[_Point], list[Bifurcation], str]:
        """Continue from ``first`` with the parameter initially moving in ``direction`` (+1/−1)."""
        t = first.tangent if first.tangent[2] * direction >= 0 else -first.tangent
        first.tangent = t
        pts = list(prefix or []) + [first]
        bifs: list[Bifurcation] = []
        ds = self.ds
        end = "max points"
        lo = self.lo - 1e-12 * self.span
        hi = self.hi + 1e-12 * self.span
        while len(pts) < self.max_points:
            a = pts[-1]
            new = None
            at_bound = False
            while new is None:
                y_pred = a.y + ds * a.tangent
                p_pred = float(y_pred[2] * self.ps)
                if (p_pred < lo or p_pred > hi) and abs(float(a.tangent[2])) >= DIRECT_LANDING_MIN_TP:
                    # the step would leave the interval (perhaps where the model is not defined, such as
                    # D < 0) while the branch runs mainly along the parameter: land on the bound directly
                    bound = self.hi if p_pred > hi else self.lo
                    frac = (bound - a.p) / (p_pred - a.p) if p_pred != a.p else 1.0
                    landed = self.at_parameter(a.y + frac * (y_pred - a.y), bound, a.tangent)
                    if landed is not None and float(landed.tangent @ a.tangent) >= self.cos_max_turn:
                        new = landed
                        at_bound = True
                        break
                cand = self.correct(y_pred, a.tangent, a.tangent)
                if cand is not None and float(cand.tangent @ a.tangent) >= self.cos_max_turn:
                    new = cand
                    break
                if cand is not None and ds <= 4 * self.ds_min:
                    new = cand
                    break
                ds *= DS_SHRINK
                if ds < self.ds_min:
                    return pts, bifs, "step size underflow (no convergence)"
            if not at_bound:
                new = self.correct_natural(new, a.tangent)
            p = new.p
            outside = at_bound or p < lo or p > hi
            if outside and not at_bound:
                bound = self.hi if p > hi else self.lo
                # interpolate to the bound along the step and land on it exactly
                frac = (bound - a.p) / (p - a.p) if p != a.p else 1.0
                guess = a.y + frac * (new.y - a.y)
                landed = self.at_parameter(guess, bound, a.tangent)
                if landed is not None:
                    new = landed
            if outside:
                end = "reached the end of the parameter interval"
            if self.detect:
                evs = self.detect_events(a, new, branch_index)
                stop_here = None
                for s, bif, bpt in evs:
                    if bif.type == "merge":
                        bifs.append(bif)
                        return pts, bifs, "merged into the period-n/2 branch at its period doubling"
                    bifs.append(bif)
                    if self.stop_on_instability and bif.type in ("fold", "period-doubling", "neimark-sacker",
                                                                 "branch-point") and bif.stable_before:
                        stop_here = bpt
                        break
                if stop_here is not None:
                    pts.append(stop_here)
                    return pts, bifs, "stopped at the first loss of stability"
            pts.append(new)
            if outside:
                return pts, bifs, end
            if new.iters <= FAST_CORRECTOR_ITERS:
                ds = min(ds * DS_GROW, self.ds_max)
            elif new.iters >= SLOW_CORRECTOR_ITERS:
                ds = max(ds * DS_SHRINK, self.ds_min)
        return pts, bifs, end


def _make_branch(index: int, prob: _Problem, pts: list[_Point], end: str, origin: Bifurcation | None,
                 bifs: list[Bifurcation]) -> Branch:
    n = prob.n
    return Branch(
        index=index, param=prob.param, n=n,
        values=np.array([q.p for q in pts]),
        states=np.array([q.y[:2] for q in pts]),
        points=np.array([np.vstack([q.y[None, :2], q.ev.points[:-1]]) for q in pts]).reshape(len(pts), n, 2),
        monodromy=np.array([q.M for q in pts]),
        u_min=np.array([q.u_min for q in pts]),
        u_max=np.array([q.u_max for q in pts]),
        steps=np.array([q.ev.N for q in pts], dtype=np.int64),
        end=end, origin=origin, bifurcations=bifs,
    )


def continue_branch(orbit: PeriodicOrbit, param: str, stop: float, *, start_bound: float | None = None,
                    index: int = 0, ds: float | None = None, ds_max: float | None = None,
                    max_points: int = MAX_BRANCH_POINTS, locate: bool = True, detect: bool = True,
                    stop_on_instability: bool = False, origin: Bifurcation | None = None,
                    direction: float | None = None) -> Branch:
    """Continue the branch through a converged orbit in ``param`` towards ``stop``.

    The branch is followed by pseudo-arclength continuation (so it passes around folds) until the
    parameter leaves the interval between ``start_bound`` (default: the orbit's value) and ``stop``,
    the step size underflows, or ``max_points`` is reached.  Events between consecutive points are
    detected by sign changes of test functions and located (see :func:`continuation`).
    """
    param = canonical_param(param)
    if not orbit.converged:
        raise ModelError("continuation: the starting orbit did not converge; give a better --guess")
    p0 = orbit.model.get(param)
    lo_b = p0 if start_bound is None else start_bound
    lo, hi = min(lo_b, stop), max(lo_b, stop)
    span = max(hi - lo, abs(stop - p0), 1e-12)
    prob = _Problem(orbit.model, param, orbit.n, orbit.dtau, orbit.accurate)
    cont = _Continuer(prob, lo, hi, span, ds, ds_max, max_points, locate, detect, stop_on_instability)
    if direction is None:
        direction = 1.0 if stop >= p0 else -1.0
    with _single_thread():
        N = prob.steps(p0)
        first = cont.correct(np.array([orbit.state[0], orbit.state[1], p0 / cont.ps]), np.array([0.0, 0.0, 1.0]),
                             None, N)
        if first is None:
            raise ModelError("continuation: the starting orbit could not be corrected at the start value")
        pts, bifs, end = cont.run(first, direction, index)
    if not prob.accurate:
        bifs = _drop_discretization_noise(bifs, span)
    return _make_branch(index, prob, pts, end, origin, bifs)


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


def switch_at_period_doubling(branch: Branch, bif: Bifurcation, model: GearModel, *, stop: float,
                              start: float, dtau: float, accurate: bool) -> PeriodicOrbit | None:
    """A period-2n orbit next to a period doubling of a period-n branch (branch switching).

    At the flip point x* the eigenvector e of the multiplier −1 gives the direction in which the
    period-2n orbit emanates (a pitchfork of P^{2n}).  Period-2n orbits are sought by shooting at
    the parameter p* ± δ from x* + a·e for a few offsets a, first on the side where the period-n
    orbit is unstable (supercritical case), then on the other; the first solution whose minimal
    period is 2n is returned (None if there is none).
    """
    param = branch.param
    n2 = 2 * branch.n
    m_star = model.with_param(param, bif.value)
    with _single_thread():
        _pts, M, _st, ok = period_map(m_star, bif.state, branch.n, dtau=dtau, accurate=accurate)
    if not ok:
        return None
    w, V = np.linalg.eig(M)
    k = int(np.argmin(np.abs(w + 1.0)))
    e = np.real(V[:, k])
    e = e / np.linalg.norm(e)
    delta = SWITCH_PARAM_REL * abs(stop - start)
    lo, hi = min(start, stop), max(start, stop)
    sides = []
    if bif.stable_before is not None and bif.stable_after is not None and bif.stable_before != bif.stable_after:
        # the side where the period-n orbit is unstable first
        direction = 1.0 if stop >= start else -1.0
        unstable_dir = direction if bif.stable_before else -direction
        sides = [unstable_dir, -unstable_dir]
    else:
        sides = [1.0, -1.0]
    prob2 = _Problem(model, param, n2, dtau, accurate)
    scale = 1.0 + float(np.linalg.norm(bif.state))
    with _single_thread():
        for sgn in sides:
            p = bif.value + sgn * delta
            if not (lo - 1e-12 <= p <= hi + 1e-12):
                continue
            try:
                m = model.with_param(param, p)
            except ModelError:
                continue
            for a in SWITCH_AMPLITUDES:
                for s_e in (1.0, -1.0):
                    x0 = bif.state + s_e * a * scale * e
                    ev, conv, its, res, status = _newton(prob2, x0, p, prob2.steps(p), SHOOT_TOL, SHOOT_MAX_ITER)
                    if not conv or ev is None:
                        continue
                    cyc = ev.points
                    if _minimal_period(cyc, n2) == n2:
                        return _orbit_from_eval(m, prob2, ev, True, "converged", its, res)
    return None


@dataclass
class ContinuationResult:
    """Branches and bifurcations of a continuation run (see :func:`continuation`)."""

    model: GearModel
    param: str
    start: float
    stop: float
    branches: list[Branch]
    dtau: float
    accurate: bool
    notes: list[str] = field(default_factory=list)

    @property
    def bifurcations(self) -> list[Bifurcation]:
        """All events, excluding a period-2n branch's return to the period-n branch (already listed as
        that branch's period doubling), sorted by branch then parameter."""
        out = []
        for b in self.branches:
            out.extend(x for x in b.bifurcations if x.type != "merge")
        return out

    def of_type(self, typ: str, n: int | None = None) -> list[Bifurcation]:
        return [b for b in self.bifurcations if b.type == typ and (n is None or b.n == n)]

    def to_json(self) -> dict[str, Any]:
        """The ``continuation --json`` summary (DESIGN §5): ``branch`` points and ``bifurcations``."""
        pts = []
        for br in self.branches:
            mu = br.multipliers
            st = br.stable
            for i in range(len(br)):
                pts.append({
                    self.param: float(br.values[i]),
                    "amplitude": float(br.amplitude[i]),
                    "stable": bool(st[i]),
                    "multipliers": [[float(m.real), float(m.imag)] for m in mu[i]],
                    "period": int(br.n),
                    "branch": int(br.index),
                    "state": [float(br.states[i, 0]), float(br.states[i, 1])],
                    "u_min": float(br.u_min[i]),
                    "u_max": float(br.u_max[i]),
                })
        return {
            "param": self.param,
            "start": self.start,
            "stop": self.stop,
            "branch": pts,
            "bifurcations": [b.to_json() for b in self.bifurcations],
            "branches": [
                {"branch": b.index, "period": b.n, "points": len(b), "end": b.end,
                 "from": None if b.origin is None else {"type": b.origin.type, self.param: b.origin.value,
                                                        "branch": b.origin.branch}}
                for b in self.branches
            ],
            "notes": self.notes,
        }

    def to_dataset(self) -> xr.Dataset:
        """One Dataset: dimension ``point`` (all branches concatenated, ``branch`` says which),
        ``section`` (section points, NaN-padded to the longest period), ``bifurcation``."""
        from ..io import annotate, result_attrs

        nmax = max([b.n for b in self.branches] + [1])
        rows = []
        for b in self.branches:
            K = len(b)
            pu = np.full((K, nmax), np.nan)
            pv = np.full((K, nmax), np.nan)
            pu[:, : b.n] = b.points[:, :, 0]
            pv[:, : b.n] = b.points[:, :, 1]
            mu = b.multipliers
            rows.append(dict(
                value=b.values, branch=np.full(K, b.index), period=np.full(K, b.n), u0=b.states[:, 0],
                v0=b.states[:, 1], amplitude=b.amplitude, u_min=b.u_min, u_max=b.u_max,
                stable=b.stable.astype(np.int8), mre=mu.real, mim=mu.imag, pu=pu, pv=pv,
            ))

        def cat(k: str) -> np.ndarray:
            return np.concatenate([r[k] for r in rows]) if rows else np.zeros(0)

        P = self.param
        bifs = self.bifurcations
        ds = xr.Dataset(
            {
                P: ("point", cat("value")),
                "branch": ("point", cat("branch").astype(np.int64)),
                "period": ("point", cat("period").astype(np.int64)),
                "u": ("point", cat("u0")),
                "v": ("point", cat("v0")),
                "amplitude": ("point", cat("amplitude")),
                "u_min": ("point", cat("u_min")),
                "u_max": ("point", cat("u_max")),
                "stable": ("point", cat("stable").astype(np.int8)),
                "multiplier_re": (("point", "multiplier"), cat("mre").reshape(-1, 2)),
                "multiplier_im": (("point", "multiplier"), cat("mim").reshape(-1, 2)),
                "poincare_u": (("point", "section"), cat("pu").reshape(-1, nmax)),
                "poincare_v": (("point", "section"), cat("pv").reshape(-1, nmax)),
                "status": ("point", np.zeros(sum(len(b) for b in self.branches), dtype=np.int64)),
                "bifurcation_type": ("bifurcation", np.array([b.type for b in bifs], dtype=object)),
                f"bifurcation_{P}": ("bifurcation", np.array([b.value for b in bifs], dtype=float)),
                "bifurcation_period": ("bifurcation", np.array([b.n for b in bifs], dtype=np.int64)),
                "bifurcation_branch": ("bifurcation", np.array([b.branch for b in bifs], dtype=np.int64)),
                "bifurcation_u": ("bifurcation", np.array([b.state[0] for b in bifs], dtype=float)),
                "bifurcation_v": ("bifurcation", np.array([b.state[1] for b in bifs], dtype=float)),
                "bifurcation_amplitude": ("bifurcation", np.array([b.amplitude for b in bifs], dtype=float)),
                "bifurcation_detail": ("bifurcation", np.array([b.detail for b in bifs], dtype=object)),
            },
            coords={"point": np.arange(sum(len(b) for b in self.branches)), "multiplier": np.arange(2),
                    "section": np.arange(nmax), "bifurcation": np.arange(len(bifs))},
            attrs=result_attrs(
                "continuation", self.model, {"dtau": self.dtau, "accurate": self.accurate},
                param=P, start=str(self.start), stop=str(self.stop),
                branches=[{"branch": b.index, "period": b.n, "end": b.end} for b in self.branches],
                notes=self.notes,
            ),
        )
        meta = {
            "branch": ("1", "branch index"),
            "period": ("1", "period of the orbit (forcing periods)"),
            "u": ("1", "orbit displacement u at θ = 0"),
            "v": ("1", "orbit velocity du/dτ at θ = 0"),
            "amplitude": ("1", "half peak-to-peak displacement of the orbit"),
            "stable": ("1", "orbit stable (1) or unstable (0)"),
            "multiplier_re": ("1", "Floquet multiplier, real part"),
            "multiplier_im": ("1", "Floquet multiplier, imaginary part"),
            "poincare_u": ("1", "section points u of the orbit (θ ≡ 0)"),
            "poincare_v": ("1", "section points du/dτ of the orbit (θ ≡ 0)"),
            "status": ("1", "point status (0 ok)"),
            "point": ("1", "index of the branch point"),
            "multiplier": ("1", "multiplier index (largest modulus first)"),
            "section": ("1", "index of the section point along the orbit"),
            "bifurcation": ("1", "index of the bifurcation"),
            "bifurcation_type": ("1", "bifurcation type"),
            f"bifurcation_{P}": ("1", f"parameter {P} at the bifurcation"),
            "bifurcation_period": ("1", "period of the branch the bifurcation lies on"),
            "bifurcation_branch": ("1", "branch index of the bifurcation"),
            "bifurcation_u": ("1", "orbit u at θ = 0 at the bifurcation"),
            "bifurcation_v": ("1", "orbit du/dτ at θ = 0 at the bifurcation"),
            "bifurcation_amplitude": ("1", "orbit amplitude at the bifurcation"),
            "bifurcation_detail": ("1", "which multiplier or boundary"),
        }
        for k, (u, lname) in meta.items():
            ds[k].attrs.update(units=u, long_name=lname)
        annotate(ds)
        if "long_name" not in ds[P].attrs:
            ds[P].attrs.update(units="1", long_name=f"continuation parameter {P}")
        return ds


def continuation(model: GearModel, param: str, start: float, stop: float, n: int = 1,
                 guess: Sequence[float] | None = None, *, dtau: float = DEFAULT_DTAU, accurate: bool = True,
                 switch: bool = True, max_period: int = DEFAULT_MAX_PERIOD, ds: float | None = None,
                 ds_max: float | None = None, max_points: int = MAX_BRANCH_POINTS, locate: bool = True,
                 state0: Sequence[float] | None = None) -> ContinuationResult:
    """Pseudo-arclength continuation of period-n orbits in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    model : GearModel
        The model; ``param`` is set to ``start`` for the first orbit.
    param : str
        Any model parameter name (``omega``, ``xi0``, ``xi1``, ``kappa1``, ``fp``, ``eps1``/``fe``,
        ``D``/``backlash``, phases ``phi_c1``…).
    start, stop : float
        The interval; ``stop`` may lie below ``start``.
    n : int
        Period of the first branch (forcing periods).
    guess : (u, u'), optional
        Shooting guess at ``start``; by default the attractor reached by simulation from
        ``state0`` (default (0, 0)).
    switch : bool
        Switch at every period doubling onto the period-2n branch (up to ``max_period``) and
        continue it too.
    ds, ds_max : float, optional
        Initial and largest arclength step in (u, u', p/|stop − start|), i.e. with the parameter
        interval scaled to length 1 (defaults DS_INIT and DS_MAX).  Smaller steps resolve closely
        spaced events better.
    locate : bool
        Locate events precisely (secant on test functions); otherwise report the nearer end of the
        step that brackets them.

    Returns
    -------
    ContinuationResult
        Branches (stable and unstable parts; ``Branch.stable``) and bifurcations: ``fold`` (a
        real multiplier through +1 at a turning point of the branch; the jump points of a
        hysteresis loop), ``period-doubling`` (a real multiplier through −1), ``neimark-sacker``
        (a complex pair through the unit circle; impossible here for ξ0 > 0 since
        |μ1 μ2| = det M = exp(−2ξ0 nT) < 1), ``grazing`` (u_min or u_max of the orbit crossing ±D:
        contact loss or back-side contact begins, the map changes form) and ``branch-point``
        (a multiplier through +1 without a turn; not generic here).
    """
    param = canonical_param(param)
    for name, val in (("start", start), ("stop", stop)):
        if not math.isfinite(float(val)):
            raise ModelError(f"{name}: must be a finite number, got {val!r}")
    if start == stop:
        raise ModelError("stop: must differ from start")
    if max_period < n:
        max_period = n
    m0 = model.with_param(param, start)
    model.with_param(param, stop)  # validates the far end too
    IntegrationOptions(dtau=dtau).check_for(m0.omega)
    if param == "omega":
        IntegrationOptions(dtau=dtau).check_for(max(start, stop))
    orbit = shoot(m0, n, guess, dtau=dtau, accurate=accurate, state0=state0)
    notes: list[str] = []
    if not orbit.converged:
        raise ModelError(f"guess: shooting for the period-{n} orbit at {param} = {start:g} did not converge "
                         f"(status {orbit.status}); give a better --guess u,v")
    if orbit.minimal_period < n:
        notes.append(f"the starting orbit has minimal period {orbit.minimal_period} < {n}")
    branches = [continue_branch(orbit, param, stop, start_bound=start, index=0, ds=ds, ds_max=ds_max,
                                max_points=max_points, locate=locate)]
    span = abs(stop - start)
    if switch:
        queue = [0]
        seen: list[tuple[int, float, np.ndarray]] = []  # (period, value, state) of merge points / sources
        while queue:
            bi = queue.pop(0)
            br = branches[bi]
            if 2 * br.n > max_period:
                continue
            for b in br.bifurcations:
                if b.type != "period-doubling":
                    continue
                if any(nn == 2 * br.n and abs(v - b.value) <= SAME_EVENT_PARAM_REL * span
                       and np.linalg.norm(s - b.state) <= SAME_EVENT_STATE_REL * (1 + np.linalg.norm(s))
                       for nn, v, s in seen):
                    continue  # the period-2n branch through this point is already traced
                new = switch_at_period_doubling(br, b, model, stop=stop, start=start, dtau=dtau,
                                                accurate=accurate)
                if new is None:
                    notes.append(f"no period-{2 * br.n} orbit found next to the period doubling at "
                                 f"{param} = {b.value:.6g}")
                    continue
                p_new = new.model.get(param)
                away = 1.0 if p_new >= b.value else -1.0
                far, near = (max(start, stop), min(start, stop)) if away > 0 else (min(start, stop), max(start, stop))
                nb = continue_branch(new, param, far, start_bound=near, index=len(branches), ds=ds,
                                     ds_max=ds_max, max_points=max_points, locate=locate, origin=b,
                                     direction=away)
                nb = _prepend_source(nb, b, model, dtau, accurate)
                nb = _append_merge(nb, br, model, dtau, accurate, span)
                branches.append(nb)
                seen.append((2 * br.n, b.value, b.state.copy()))
                for mb in nb.bifurcations:
                    if mb.type == "merge":
                        seen.append((nb.n, mb.value, mb.state.copy()))
                queue.append(nb.index)
    return ContinuationResult(model, param, float(start), float(stop), branches, dtau, accurate, notes)


def _append_merge(br: Branch, parent: Branch, model: GearModel, dtau: float, accurate: bool, span: float) -> Branch:
    """A switched branch that ended by meeting its parent branch: replace the interpolated merge point
    by the parent's period doubling there (located precisely on the parent) and end the branch on it."""
    merges = [b for b in br.bifurcations if b.type == "merge"]
    if not merges:
        return br
    mb = merges[-1]
    pds = [b for b in parent.bifurcations if b.type == "period-doubling"]
    if not pds:
        return br
    pd = min(pds, key=lambda b: abs(b.value - mb.value))
    if abs(pd.value - mb.value) > SAME_EVENT_PARAM_REL * span + 1e-12:
        return br
    mb.value, mb.state, mb.u_min, mb.u_max, mb.located = pd.value, pd.state.copy(), pd.u_min, pd.u_max, pd.located
    m = model.with_param(br.param, pd.value)
    with _single_thread():
        pts, M, _st, ok = period_map(m, pd.state, br.n, dtau=dtau, accurate=accurate)
    if not ok:
        return br
    mb.multipliers = np.sort_complex(np.linalg.eigvals(M))[::-1]
    sec = np.vstack([pd.state[None, :], pts[:-1]])
    br.values = np.concatenate([br.values, [pd.value]])
    br.states = np.vstack([br.states, pd.state[None, :]])
    br.points = np.concatenate([br.points, sec[None]])
    br.monodromy = np.concatenate([br.monodromy, M[None]])
    br.u_min = np.concatenate([br.u_min, [pd.u_min]])
    br.u_max = np.concatenate([br.u_max, [pd.u_max]])
    br.steps = np.concatenate([br.steps, [_natural_steps(m, dtau)]])
    return br


def _prepend_source(br: Branch, src: Bifurcation, model: GearModel, dtau: float, accurate: bool) -> Branch:
    """Put the period-doubling point (the period-n orbit traversed twice) at the head of a switched branch,
    so that the period-2n branch is drawn from where it is born."""
    m = model.with_param(br.param, src.value)
    with _single_thread():
        pts, M, _st, ok = period_map(m, src.state, br.n, dtau=dtau, accurate=accurate)
    if not ok:
        return br
    sec = np.vstack([src.state[None, :], pts[:-1]])
    br.values = np.concatenate([[src.value], br.values])
    br.states = np.vstack([src.state[None, :], br.states])
    br.points = np.concatenate([sec[None], br.points])
    br.monodromy = np.concatenate([M[None], br.monodromy])
    br.u_min = np.concatenate([[src.u_min], br.u_min])
    br.u_max = np.concatenate([[src.u_max], br.u_max])
    br.steps = np.concatenate([[_natural_steps(m, dtau)], br.steps])
    return br


# ---------------------------------------------------------------------------------------------
# The paper's stability condition and the Floquet stability boundaries
# ---------------------------------------------------------------------------------------------
def paper_stability_damping(kappa1: float) -> float:
    """The paper's "Hopf" stability condition ξ0 = ½√(1 − κ1²) (non-dimensional damping ratio)."""
    k = float(kappa1)
    if not (abs(k) <= 1.0):
        raise ModelError(f"kappa1: the condition ½√(1 − κ1²) needs |κ1| <= 1, got {kappa1!r}")
    return 0.5 * math.sqrt(1.0 - k * k)


def paper_stability_condition(model: GearModel) -> dict[str, Any]:
    """Evaluate the paper's condition for a model: the critical ξ0 and whether ξ0 exceeds it."""
    crit = paper_stability_damping(model.get("kappa1"))
    return {"kappa1": model.get("kappa1"), "xi0_paper": crit, "xi0": model.xi0,
            "above_paper_condition": bool(model.xi0 > crit)}


def stability_boundary(model: GearModel, omegas: Iterable[float], *, xi0_high: float = XI0_SCAN_HIGH,
                       xi0_low: float = XI0_SCAN_LOW, n: int = 1, dtau: float = DEFAULT_DTAU,
                       accurate: bool = False) -> xr.Dataset:
    """Floquet stability boundary of the period-n response in ξ0, for each ω.

    At each ω the period-n orbit reached by simulation at ``xi0_high`` (heavily damped, stable) is
    continued in ξ0 down to ``xi0_low``; the first bifurcation at which it loses stability (fold,
    period doubling or Neimark–Sacker) gives the critical ξ0_c(ω): below it the orbit that is
    stable at high damping is no longer stable.  NaN when it stays stable down to ``xi0_low``.

    Returns a Dataset over ``omega`` with ``xi0_critical``, ``bifurcation_type`` and ``status``
    (0 found, or stable throughout; 1 the start orbit was not found or the scan stopped early).
    """
    om = np.asarray(list(omegas), dtype=float)
    crit = np.full(om.size, np.nan)
    kinds = np.array([""] * om.size, dtype=object)
    status = np.zeros(om.size, dtype=np.int64)
    for i, w in enumerate(om):
        m = model.replace(omega=float(w), xi0=xi0_high)
        orb = shoot(m, n, dtau=dtau, accurate=accurate)
        if not orb.converged or not orb.stable:
            status[i] = 1
            kinds[i] = "start orbit not found" if not orb.converged else "start orbit unstable"
            continue
        br = continue_branch(orb, "xi0", xi0_low, start_bound=xi0_high, stop_on_instability=True)
        lost = [b for b in br.bifurcations if b.type in ("fold", "period-doubling", "neimark-sacker", "branch-point")
                and b.stable_before]
        if lost:
            crit[i] = lost[0].value
            kinds[i] = lost[0].type
        elif br.values.min() > xi0_low + 1e-9 * (xi0_high - xi0_low):
            status[i] = 1
            kinds[i] = f"scan incomplete ({br.end})"
        else:
            kinds[i] = "stable"
    from ..io import result_attrs

    ds = xr.Dataset(
        {"xi0_critical": ("omega", crit), "bifurcation_type": ("omega", kinds), "status": ("omega", status)},
        coords={"omega": om},
        attrs=result_attrs("stability_boundary", model, {"dtau": dtau, "accurate": accurate, "n": n},
                           xi0_high=str(xi0_high), xi0_low=str(xi0_low)),
    )
    ds["xi0_critical"].attrs.update(units="1", long_name="ξ0 below which the period-n response loses stability")
    ds["bifurcation_type"].attrs.update(units="1", long_name="bifurcation at the stability boundary")
    return ds


def mathieu_boundary(model: GearModel, omegas: Iterable[float], *, dtau: float = DEFAULT_DTAU,
                     xi0_max: float = 1.0, tol: float = 1e-8) -> xr.Dataset:
    """Floquet stability boundary of the linear contact model (D = 0, no load, no STE; the damped
    Mathieu–Hill equation u'' + 2ξ(θ)u' + k(θ)u = 0 with the model's ξ_k, κ_r): for each ω the
    smallest ξ0 above which u = 0 is stable (bisection on max|μ| = 1; 0 where it is stable already at
    ξ0 = XI0_SCAN_LOW, i.e. outside the parametric instability tongues)."""
    om = np.asarray(list(omegas), dtype=float)
    crit = np.zeros(om.size)
    lin = model.replace(D=0.0, fp=0.0, eps=(), phi_e=())
    with _single_thread():
        for i, w in enumerate(om):
            def rho(xi0: float) -> float:
                m = lin.replace(omega=float(w), xi0=xi0)
                _pts, M, _st, ok = period_map(m, (0.0, 0.0), 1, dtau=dtau)
                return float(np.max(np.abs(np.linalg.eigvals(M)))) if ok else math.inf
            if rho(XI0_SCAN_LOW) < 1.0:
                crit[i] = 0.0  # stable for every positive damping in the scan (outside the instability tongues)
                continue
            lo, hi = 0.0, xi0_max
            if rho(hi) >= 1.0:
                crit[i] = math.nan
                continue
            while hi - lo > tol:
                mid = 0.5 * (lo + hi)
                if rho(mid) >= 1.0:
                    lo = mid
                else:
                    hi = mid
            crit[i] = 0.5 * (lo + hi)
    from ..io import result_attrs

    ds = xr.Dataset({"xi0_critical": ("omega", crit)}, coords={"omega": om},
                    attrs=result_attrs("mathieu_boundary", lin, {"dtau": dtau}))
    ds["xi0_critical"].attrs.update(units="1", long_name="ξ0 above which the linear contact model is stable")
    return ds


def compare_stability_condition(model: GearModel, omegas: Iterable[float], *, dtau: float = DEFAULT_DTAU,
                                xi0_high: float = XI0_SCAN_HIGH, xi0_low: float = XI0_SCAN_LOW) -> xr.Dataset:
    """The paper's condition ξ0 = ½√(1 − κ1²) against the Floquet stability boundaries.

    Returns one Dataset over ``omega`` with ``xi0_critical`` (period-1 response of the full model,
    :func:`stability_boundary`), ``xi0_critical_linear`` (linear contact model, :func:`mathieu_boundary`)
    and, in the attributes, ``xi0_paper`` and the largest critical values over the ω grid with
    where they occur, so a report can say whether the paper's value is a stability boundary.
    """
    om = np.asarray(list(omegas), dtype=float)
    nl = stability_boundary(model, om, xi0_high=xi0_high, xi0_low=xi0_low, dtau=dtau)
    lin = mathieu_boundary(model, om, dtau=dtau)
    paper = paper_stability_damping(model.get("kappa1"))
    ds = nl.rename({"xi0_critical": "xi0_critical", "bifurcation_type": "bifurcation_type"})
    ds["xi0_critical_linear"] = lin["xi0_critical"]
    ds["xi0_critical_linear"].attrs.update(units="1", long_name="ξ0 above which the linear contact model "
                                                                 "(D = 0, unforced) is stable")
    ds["xi0_paper"] = xr.DataArray(paper, attrs={"units": "1", "long_name": "paper's condition ½√(1 − κ1²)"})

    def argmax(a: np.ndarray) -> tuple[float | None, float | None]:
        if not np.any(np.isfinite(a)):
            return None, None
        i = int(np.nanargmax(a))
        return float(a[i]), float(om[i])

    mx, wmx = argmax(nl["xi0_critical"].values)
    ml, wml = argmax(lin["xi0_critical"].values)
    ds.attrs["xi0_paper"] = str(paper)
    ds.attrs["max_xi0_critical"] = "null" if mx is None else str(mx)
    ds.attrs["max_xi0_critical_at_omega"] = "null" if wmx is None else str(wmx)
    ds.attrs["max_xi0_critical_linear"] = "null" if ml is None else str(ml)
    ds.attrs["max_xi0_critical_linear_at_omega"] = "null" if wml is None else str(wml)
    ds.attrs["geardyn_kind"] = "stability_comparison"
    return ds
