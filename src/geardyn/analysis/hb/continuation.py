"""Pseudo-arclength continuation of harmonic-balance solutions, with bifurcation detection.

The branch is traced in y = (a, p/p_s): the 2H + 1 real coefficients and the parameter scaled by
p_s = |stop − start| (so that the interval has length 1).  Predictor: a step ds along the unit
tangent (null vector of [∂R/∂a, ∂R/∂p], oriented by the previous one); corrector: Newton on
R(a, p) = 0 in the hyperplane normal to the tangent through the predicted point.  The step grows
after fast corrections and shrinks after slow or failed ones and after large turns of the tangent.

Events between consecutive points are detected by sign changes of test functions and located by a
safeguarded secant along the chord (each trial corrected onto the branch):

* ``fold`` — the parameter component of the tangent changes sign (a Hill exponent through 0,
  μ through +1; the Jacobian is singular there);
* ``period-doubling`` — (μ₁ + 1)(μ₂ + 1) from Hill's multipliers changes sign (μ through −1);
* ``neimark-sacker`` — |μ₁μ₂| − 1 changes sign while the pair is complex (impossible for ξ0 > 0
  by Liouville, |μ₁μ₂| = exp(−2ξ0 nT), but reported when the damping is continued through zero);
* ``grazing`` — u_min or u_max of the reconstructed time signal crosses +D or −D.

Points where Hill's multipliers are unresolved carry ``Status.UNRESOLVED`` and take no part in
the multiplier tests.

References
----------
R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010;
Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
(pseudo-arclength continuation, test functions of folds, period doublings and Neimark–Sacker points).
T. M. Cameron and J. H. Griffin, "An alternating frequency/time domain method for calculating the
steady-state response of nonlinear dynamic systems", J. Appl. Mech. 56 (1989) 149–154.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...model import GearModel, ModelError, canonical_param
from ...status import Status, flag_attrs
from ..secant import illinois_on_chord
from ._blas import single_thread_blas, solve
from .aft import signal_extrema
from .damping import require_damping
from .hill import HillResult
from .solve import HBSystem, hb_solve

__all__ = [
    "KIND",
    "HBBifurcation",
    "HBContinuation",
    "hb_continuation",
    "max_points_end",
    "span_reporter",
    "trace_branch",
]

#: ``geardyn_kind`` of a continued HB branch (its figures: :mod:`geardyn.plot.hb`).
KIND = "hb"

#: Arclength steps in (a, p/p_s): initial, largest, smallest.
DS_INIT, DS_MAX, DS_MIN = 0.005, 0.02, 1e-7
CORRECTOR_TOL = 1e-10
CORRECTOR_MAX_ITER = 10
MAX_TURN_DEG = 20.0
MAX_POINTS = 3000
#: Event location: stop when the chord bracket is below this (relative to the chord) or after LOCATE_MAX_ITER.
LOCATE_REL_TOL = 1e-9
LOCATE_MAX_ITER = 40
#: While a real multiplier is within NEAR_CRITICAL of −1 (or a complex pair of the unit circle), the
#: step is at most NEAR_CRITICAL_DS·ds_max, so that two events close together (a period-doubling
#: interval a few thousandths wide) are not stepped over with no net sign change of their test.
NEAR_CRITICAL = 0.1
NEAR_CRITICAL_DS = 0.1
#: A step is refused (and halved) when a resolved multiplier moves farther than this in the complex plane.
MAX_MULTIPLIER_STEP = 0.1
#: The next step is at most the last one times MULTIPLIER_STEP_TARGET / (its largest multiplier move), so that
#: steps are seldom refused for a multiplier move above MAX_MULTIPLIER_STEP.
MULTIPLIER_STEP_TARGET = 0.09


class _Pt:
    """A corrected branch point; its Hill stability is computed when first asked for (a point whose
    step is refused by the turn of the tangent, or a trial of a fold or grazing location, needs none)."""

    __slots__ = ("y", "t", "u_min", "u_max", "iters", "_stability", "_hill")

    def __init__(
        self,
        y: np.ndarray,
        t: np.ndarray,
        u_min: float,
        u_max: float,
        stability: Callable[[], HillResult],
        iters: int = 0,
    ):
        self.y, self.t, self.u_min, self.u_max, self.iters = y, t, u_min, u_max, iters
        self._stability = stability
        self._hill: HillResult | None = None

    @property
    def hill(self) -> HillResult:
        if self._hill is None:
            self._hill = self._stability()
        return self._hill


@dataclass
class HBBifurcation:
    """A located event on an HB branch.

    Attributes
    ----------
    type : str
        ``fold``, ``period-doubling``, ``neimark-sacker`` or ``grazing``.
    value : float
        Parameter value.
    u_min, u_max : float
        Extremes of u there.
    multipliers : complex ndarray (2,)
    detail : str
    located : bool
        The location iteration met its tolerance.
    coefficients : ndarray
        Harmonic coefficients of the solution at the event (empty when not recorded).
    """

    type: str
    value: float
    u_min: float
    u_max: float
    multipliers: np.ndarray
    detail: str
    located: bool
    coefficients: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))

    def to_json(self) -> dict[str, Any]:
        return {
            "type": self.type,
            "value": self.value,
            "u_min": self.u_min,
            "u_max": self.u_max,
            "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "detail": self.detail,
            "located": self.located,
        }


@dataclass
class HBContinuation:
    """A continued harmonic-balance branch.

    Attributes
    ----------
    model : GearModel
        Base model (``param`` varies along the branch).
    param : str
    harmonics, period, samples : int
        H, n and the time samples N per response period.
    values : ndarray (P,)
        Parameter values along the branch.
    coefficients : ndarray (P, 2H + 1)
    u_min, u_max : ndarray (P,)
    multipliers : complex ndarray (P, 2)
    status : ndarray of int (P,)
        :class:`~geardyn.status.Status` per point (``OK`` or ``UNRESOLVED`` for points whose
        multipliers Hill's method could not resolve; a start that failed is one ``NOT_CONVERGED``/
        ``DIVERGED`` point with NaN values).
    bifurcations : list of HBBifurcation
    end : str
        Why the continuation stopped.
    """

    model: GearModel
    param: str
    harmonics: int
    period: int
    samples: int
    values: np.ndarray
    coefficients: np.ndarray
    u_min: np.ndarray
    u_max: np.ndarray
    multipliers: np.ndarray
    status: np.ndarray
    bifurcations: list[HBBifurcation]
    end: str

    @property
    def amplitude(self) -> np.ndarray:
        return 0.5 * (self.u_max - self.u_min)

    @property
    def stable(self) -> np.ndarray:
        """True where the point is resolved and all |μ| < 1."""
        return (self.status == int(Status.OK)) & np.all(np.abs(self.multipliers) < 1.0, axis=1)

    @property
    def converged(self) -> bool:
        return bool(self.values.size) and bool(
            np.all(self.status != int(Status.NOT_CONVERGED)) and np.all(self.status != int(Status.DIVERGED))
        )

    def of_type(self, typ: str) -> list[HBBifurcation]:
        return [b for b in self.bifurcations if b.type == typ]

    def to_json(self) -> dict[str, Any]:
        """Plain-dict summary: ``branch`` points, ``bifurcations``, ``harmonics``, ``converged``."""

        def num(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        pts = [
            {
                self.param: float(v),
                "amplitude": num(0.5 * (hi - lo)),
                "u_min": num(lo),
                "u_max": num(hi),
                "stable": bool(st) if int(s) == int(Status.OK) else None,
                "status": Status(int(s)).label,
                "multipliers": [[num(m.real), num(m.imag)] for m in mu],
            }
            for v, lo, hi, st, s, mu in zip(
                self.values, self.u_min, self.u_max, self.stable, self.status, self.multipliers
            )
        ]
        bifs = [
            {"type": b.type, self.param: float(b.value), **{k: v for k, v in b.to_json().items() if k != "type"}}
            for b in self.bifurcations
        ]
        return {
            "param": self.param,
            "branch": pts,
            "bifurcations": bifs,
            "harmonics": self.harmonics,
            "period": self.period,
            "samples": self.samples,
            "converged": self.converged,
            "end": self.end,
        }

    def to_dataset(self):
        """The branch as an :class:`xarray.Dataset` over ``point`` (kind ``hb``; the bifurcations as the JSON
        attribute ``bifurcations``, keyed like ``to_json()``)."""
        import json

        import xarray as xr

        from ...io import annotate, result_attrs

        ds = xr.Dataset(
            {
                self.param: ("point", self.values),
                "u_min": ("point", self.u_min),
                "u_max": ("point", self.u_max),
                "amplitude": ("point", self.amplitude),
                "stable": ("point", self.stable.astype(np.int8)),
                "multiplier_re": (("point", "multiplier"), self.multipliers.real),
                "multiplier_im": (("point", "multiplier"), self.multipliers.imag),
                "coefficients": (("point", "coefficient"), self.coefficients),
                "status": ("point", self.status.astype(np.int64)),
            },
            coords={
                "point": np.arange(self.values.size),
                "multiplier": [0, 1],
                "coefficient": np.arange(2 * self.harmonics + 1),
            },
            attrs=result_attrs(
                KIND,
                self.model,
                param=self.param,
                harmonics=self.harmonics,
                period=self.period,
                samples=self.samples,
                end=self.end,
                coefficient_layout="[a0, a1..aH, b1..bH] of u(φ) = a0 + Σ a_k cos kφ + b_k sin kφ, φ = ωτ/n",
                bifurcations=json.dumps(self.to_json()["bifurcations"]),
            ),
        )
        ds["status"].attrs.update(flag_attrs())
        return annotate(ds)


class _Tracer:
    #: Test function → (event type, detail) of :meth:`events`.
    labels = {
        "turn": ("fold", "turning point: a Hill exponent through 0 (μ through +1)"),
        "pd": ("period-doubling", "real multiplier through −1"),
        "ns": ("neimark-sacker", "complex pair through the unit circle"),
        "graze_min_plus": ("grazing", "u_min = +D (drive-side contact loss)"),
        "graze_min_minus": ("grazing", "u_min = −D (back-side contact)"),
        "graze_max_plus": ("grazing", "u_max = +D (drive-side contact)"),
        "graze_max_minus": ("grazing", "u_max = −D"),
    }

    def __init__(self, sysm: HBSystem, lo: float, hi: float, ps: float):
        self.s, self.lo, self.hi, self.ps = sysm, lo, hi, ps
        self.M = sysm.basis.size

    def p(self, y: np.ndarray) -> float:
        return float(y[-1] * self.ps)

    def _aug(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R and [[∂R/∂a, ∂R/∂(p/p_s)], [0]] at ``y``."""
        return self.s.bordered(y[:-1], self.p(y), self.ps)

    def tangent(self, y: np.ndarray, ref: np.ndarray, aug: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """Unit null vector of [∂R/∂a, ∂R/∂p] at ``y`` oriented like ``ref`` (``aug``: :meth:`_aug` at ``y``,
        if already evaluated; its matrix is overwritten)."""
        _R, A = self._aug(y) if aug is None else aug
        A[-1] = ref
        rhs = np.zeros(self.M + 1)
        rhs[-1] = 1.0
        t = np.linalg.lstsq(A, rhs, rcond=None)[0] if not np.all(np.isfinite(A)) else solve(A, rhs)
        t /= np.linalg.norm(t)
        return t if t @ ref >= 0 else -t

    def correct(self, y0: np.ndarray, normal: np.ndarray, ref_t: np.ndarray) -> _Pt | None:
        y = y0.copy()
        F = np.empty(self.M + 1)
        for it in range(CORRECTOR_MAX_ITER):
            try:
                self.s.check(self.p(y))
            except ModelError:
                return None
            aug = R, A = self._aug(y)
            g = float(normal @ (y - y0))
            if math.sqrt(R @ R) <= CORRECTOR_TOL * (1 + math.sqrt(y @ y)) and abs(g) <= 1e-12:
                return self._finish(y, ref_t, it, aug)
            F[:-1] = R
            F[-1] = g
            A[-1] = normal
            try:
                dy = solve(A, -F)
            except np.linalg.LinAlgError:
                return None
            y = y + dy
            if not np.all(np.isfinite(y)):
                return None
            if math.sqrt(dy @ dy) <= 1e-13 * (1 + math.sqrt(y @ y)):
                return self._finish(y, ref_t, it + 1)
        return None

    def _finish(
        self, y: np.ndarray, ref_t: np.ndarray, iters: int, aug: tuple[np.ndarray, np.ndarray] | None = None
    ) -> _Pt:
        t = self.tangent(y, ref_t, aug)
        a, p = y[:-1], self.p(y)
        umin, umax = self.extremes(a, p)
        return _Pt(y, t, umin, umax, lambda: self.s.stability(a, p), iters)

    def extremes(self, a: np.ndarray, p: float) -> tuple[float, float]:
        """(u_min, u_max) of the solution ``a`` at parameter ``p``."""
        umin, umax, _, _ = signal_extrema(self.s.basis, a)
        return umin, umax

    def multiplier_step(self, a: HillResult, b: HillResult) -> float:
        """How far the multipliers moved between two points (:func:`_multiplier_step`)."""
        return _multiplier_step(a, b)

    def near_critical(self, h: HillResult) -> bool:
        """Whether the step is to be capped near a critical multiplier (:func:`_near_critical`)."""
        return _near_critical(h)

    # ---------------------------------------------------------------- tests and events
    def tests(self, pt: _Pt, chord: np.ndarray | None = None, key: str | None = None) -> dict[str, float]:
        """Test functions at ``pt`` (the tangent oriented along ``chord``): all of them, or only ``key``'s
        kind (then Hill's multipliers are computed only for the multiplier tests)."""
        D = self.s._at(self.p(pt.y))[1]
        t = pt.t if chord is None or pt.t @ chord >= 0 else -pt.t
        out = {"turn": float(t[-1])}
        if key is None or key in ("pd", "ns"):
            h = pt.hill
            if h.status is Status.OK:
                mu = h.multipliers
                out["pd"] = float(np.real((mu[0] + 1) * (mu[1] + 1)))
                if np.any(np.abs(mu.imag) > 1e-9 * np.abs(mu)):
                    out["ns"] = float(abs(mu[0] * mu[1]) - 1.0)
        if D > 0 and (key is None or key.startswith("graze")):
            out.update(
                graze_min_plus=pt.u_min - D,
                graze_min_minus=pt.u_min + D,
                graze_max_plus=pt.u_max - D,
                graze_max_minus=pt.u_max + D,
            )
        return out

    def locate(self, a: _Pt, b: _Pt, key: str) -> tuple[_Pt, bool]:
        d = b.y - a.y
        L = float(np.linalg.norm(d))
        e = d / L
        fa, fb = self.tests(a, d)[key], self.tests(b, d)[key]

        def trial(s: float, lo: float, hi: float) -> tuple[float, _Pt, float] | None:
            pt = self.correct(a.y + s * d, e, a.t)
            if pt is None:
                return None
            f = self.tests(pt, d, key).get(key, math.nan)
            return (s, pt, f) if math.isfinite(f) else None

        return illinois_on_chord(fa, fb, trial, a if abs(fa) <= abs(fb) else b, LOCATE_REL_TOL, LOCATE_MAX_ITER)

    def events(self, a: _Pt, b: _Pt) -> list[HBBifurcation]:
        d = b.y - a.y
        ta, tb = self.tests(a, d), self.tests(b, d)
        out = []
        for key, (typ, detail) in self.labels.items():
            if key in ta and key in tb and (ta[key] > 0) != (tb[key] > 0):
                pt, ok = self.locate(a, b, key)
                out.append(
                    (
                        float((pt.y - a.y) @ d),
                        HBBifurcation(
                            typ,
                            self.p(pt.y),
                            pt.u_min,
                            pt.u_max,
                            pt.hill.multipliers.copy(),
                            detail,
                            ok,
                            pt.y[:-1].copy(),
                        ),
                    )
                )
        out.sort(key=lambda e: e[0])
        return [b for _s, b in out]


def _multiplier_step(a: HillResult, b: HillResult) -> float:
    """Largest move of a multiplier between two resolved points (the pairing that moves least; 0 if either
    point is unresolved)."""
    if a.status is not Status.OK or b.status is not Status.OK:
        return 0.0
    ma, mb = a.multipliers, b.multipliers
    return float(min(np.max(np.abs(ma - mb)), np.max(np.abs(ma - mb[::-1]))))


def _near_critical(h: HillResult) -> bool:
    """A resolved real multiplier close to −1, or a complex pair close to the unit circle (folds, where a
    multiplier passes +1, are found from the tangent, whose turn limits the step already)."""
    if h.status is not Status.OK:
        return False
    mu = h.multipliers
    if np.any(np.abs(mu.imag) > 1e-9 * np.abs(mu)):
        return bool(abs(abs(mu[0]) - 1.0) < NEAR_CRITICAL)
    return bool(np.any(np.abs(mu.real + 1.0) < NEAR_CRITICAL))


def hb_continuation(
    model: GearModel,
    param: str,
    start: float,
    stop: float,
    *,
    harmonics: int | None = None,
    period: int = 1,
    guess: Any = None,
    samples: int | None = None,
    ds: float = DS_INIT,
    ds_max: float = DS_MAX,
    max_points: int = MAX_POINTS,
    floquet: str = "monodromy",
    progress: Callable[[float, float], None] | None = None,
) -> HBContinuation:
    """Continue the period-n harmonic-balance solution of ``model`` in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    model : GearModel
        Base model (its value of ``param`` is replaced).
    param : str
        Any model parameter name (``omega``, ``xi0``, ``kappa1``, ``fp``, ``D``, ``eps1`` …).
    start, stop : float
        The branch starts at ``start`` and is followed (through folds) until the parameter leaves the
        interval between ``start`` and ``stop``.
    harmonics : int
        H, harmonics of ν = ω/(P n) (default :func:`~geardyn.analysis.hb.solve.default_harmonics`: 16 for a
        one-cycle model).
    period : int
        n, the response period in forcing periods.
    guess : coefficients, "simulate" or "linear", optional
        Start guess at ``start`` (default: the attractor reached by simulation from rest).
    samples : int, optional
        Time samples per response period (default from H, see :mod:`.aft`).
    ds, ds_max : float
        Initial and largest arclength step in (a, p/|stop − start|).
    max_points : int
        Largest number of branch points (the branch then ends with ``end`` saying so).
    floquet : str
        How the multipliers are computed: ``"monodromy"`` (default, :mod:`.monodromy`) or ``"hill"``
        (Hill's method, :mod:`.hill`).
    progress : callable, optional
        Called as ``progress(done, total)`` with the parameter distance covered towards ``stop`` (the farthest
        point so far) and |stop − start|.

    Returns
    -------
    HBContinuation
        The branch with per-point status and the located bifurcations.

    Raises
    ------
    ModelError
        Unknown parameter, start/stop outside the parameter's valid range, or a model without damping
        (:func:`~geardyn.analysis.hb.damping.require_damping`: no stability can be decided).

    References
    ----------
    R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010;
    Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
    (pseudo-arclength continuation, test functions of folds, period doublings and Neimark–Sacker points).

    Examples
    --------
    >>> from geardyn import GearModel, hb_continuation
    >>> res = hb_continuation(GearModel(), "omega", 0.5, 0.6, harmonics=8)
    >>> res.converged, float(res.values[0]), res.end
    (True, 0.5, 'reached the end of the interval')
    """
    param = canonical_param(param)
    start, stop = float(start), float(stop)
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ModelError("start, stop: must be finite and different")
    m0 = model.with_param(param, start)
    model.with_param(param, stop)
    require_damping(model, param, start, stop)
    report = span_reporter(progress, start, stop)
    sysm = HBSystem(model, harmonics, period, param=param, samples=samples, floquet=floquet)
    H = sysm.H
    sol = hb_solve(m0, H, period, guess, samples=sysm.basis.N, stability=False)  # Hill: at the first point
    nanmu = np.full((1, 2), complex(math.nan, math.nan))
    if not sol.converged:
        return HBContinuation(
            model,
            param,
            H,
            sysm.n,
            sysm.basis.N,
            np.array([start]),
            sol.coefficients[None, :],
            np.array([math.nan]),
            np.array([math.nan]),
            nanmu,
            np.array([int(sol.status)]),
            [],
            f"start: {sol.status.label}",
        )
    ps = abs(stop - start)
    direction = 1.0 if stop > start else -1.0
    lo, hi = min(start, stop), max(start, stop)
    tr = _Tracer(sysm, lo, hi, ps)
    y = np.concatenate([sol.coefficients, [start / ps]])
    ref = np.zeros(sysm.basis.size + 1)
    ref[-1] = direction
    pts, bifs, end = trace_branch(tr, y, ref, ds, ds_max, max_points, report)
    vals = np.array([tr.p(q.y) for q in pts])
    return HBContinuation(
        model,
        param,
        H,
        sysm.n,
        sysm.basis.N,
        vals,
        np.array([q.y[:-1] for q in pts]),
        np.array([q.u_min for q in pts]),
        np.array([q.u_max for q in pts]),
        np.array([q.hill.multipliers for q in pts]),
        np.array([int(q.hill.status) for q in pts]),
        bifs,
        end,
    )


def span_reporter(
    progress: Callable[[float, float], None] | None, start: float, stop: float
) -> Callable[[float], None] | None:
    """A branch point's parameter → ``progress(farthest distance from start towards stop, |stop − start|)``.

    Parameters
    ----------
    progress : callable or None
        ``progress(done, total)``; called once with 0 now, then whenever the distance grows.
    start, stop : float
        The continuation's interval.

    Returns
    -------
    callable or None
        The callback of each branch point's parameter; None without ``progress``.
    """
    if progress is None:
        return None
    total = abs(stop - start)
    sign = 1.0 if stop >= start else -1.0
    farthest = [0.0]
    progress(0.0, total)

    def on_point(p: float) -> None:
        d = min(max(sign * (p - start), 0.0), total)
        if d > farthest[0]:
            farthest[0] = d
            progress(d, total)

    return on_point


def max_points_end(max_points: int) -> str:
    """The ``end`` of a branch stopped by the point limit.

    Parameters
    ----------
    max_points : int
        The limit.

    Returns
    -------
    str
    """
    return (
        f"max points: stopped at {max_points} points before the end of the interval (allow more points, or "
        f"a larger ds_max)"
    )


def trace_branch(
    tr: _Tracer,
    y: np.ndarray,
    ref: np.ndarray,
    ds: float,
    ds_max: float,
    max_points: int,
    on_point: Callable[[float], None] | None = None,
) -> tuple[list[_Pt], list[HBBifurcation], str]:
    """The pseudo-arclength loop of :func:`hb_continuation` on any tracer (the 1-DOF one or a subclass).

    Parameters
    ----------
    tr : _Tracer
        The equations with their tests; its ``lo``, ``hi`` bound the parameter.
    y : ndarray
        The first solution (unknowns, then p/p_s).
    ref : ndarray
        Direction the first tangent is oriented by.
    ds, ds_max : float
        Initial and largest arclength step.
    max_points : int
        Largest number of points.
    on_point : callable, optional
        Called with the parameter of each point added (the progress, :func:`span_reporter`).

    Returns
    -------
    (points, bifurcations, end)
    """
    lo, hi = tr.lo, tr.hi
    with single_thread_blas():
        first = tr._finish(y, ref, 0)
        pts = [first]
        bifs: list[HBBifurcation] = []
        h = float(ds)
        end = max_points_end(max_points)
        while len(pts) < max_points:
            cur = pts[-1]
            nxt = None
            dmu = 0.0
            while h >= DS_MIN:
                yp = cur.y + h * cur.t
                nxt = tr.correct(yp, cur.t, cur.t)
                if nxt is not None:
                    cosang = float(np.clip(nxt.t @ cur.t, -1, 1))
                    if math.degrees(math.acos(cosang)) <= MAX_TURN_DEG:
                        dmu = tr.multiplier_step(cur.hill, nxt.hill)
                        if dmu <= MAX_MULTIPLIER_STEP and (
                            h <= NEAR_CRITICAL_DS * ds_max or not tr.near_critical(nxt.hill)
                        ):
                            break
                nxt = None
                h *= 0.5
            if nxt is None:
                end = "corrector failed (step below DS_MIN)"
                break
            bifs.extend(tr.events(cur, nxt))
            pts.append(nxt)
            if on_point is not None:
                on_point(tr.p(nxt.y))
            h_next = min(ds_max, h * (1.5 if nxt.iters <= 3 else 1.0 if nxt.iters <= 6 else 0.5))
            if dmu > 0.0:  # the multipliers move about linearly in the step: aim below the refusal limit
                h_next = min(h_next, h * MULTIPLIER_STEP_TARGET / dmu)
            h = h_next
            if tr.near_critical(nxt.hill):
                h = min(h, NEAR_CRITICAL_DS * ds_max)
            p = tr.p(nxt.y)
            if p > hi or p < lo:
                end = "reached the end of the interval"
                bifs = [b for b in bifs if lo <= b.value <= hi]
                break
    return pts, bifs, end
