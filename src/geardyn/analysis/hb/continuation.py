"""Pseudo-arclength continuation of harmonic-balance solutions of any system, with bifurcation detection.

The branch is traced in y = (x, p/p_s): the unknowns of :class:`~geardyn.analysis.hb.equations.HBEquations` (every
coordinate's coefficients, then the gauge multipliers) and the parameter scaled by p_s = |stop − start|.
Predictor: a step ds along the unit tangent (null vector of [∂R/∂x, ∂R/∂p], oriented by the previous one);
corrector: Newton on R = 0 in the hyperplane normal to the tangent through the predicted point.  The step grows
after fast corrections and shrinks after slow or failed ones, large turns of the tangent and large moves of the
multipliers (:class:`_StepRules`, ``docs/hb.md`` "Continuation and events").

Events between consecutive points are detected by sign changes of test functions and located by a
safeguarded secant along the chord (each trial corrected onto the branch):

* ``fold`` — the parameter component of the tangent changes sign (a multiplier through +1: det(I − M) = 0,
  the Jacobian is singular there);
* ``period-doubling`` — det(I + M) = Π(μ_i + 1) over the elastic multipliers changes sign (μ through −1);
* ``neimark-sacker`` — |μ_i μ_j| − 1 of the k-th complex pair changes sign (``ns``, ``ns2``, …); left out for a
  system without damping, whose multipliers multiply to 1 (Liouville) so that a pair on the unit circle has
  |μ μ̄| − 1 = 0 up to rounding: there det(I ± M), which work on the circle, are the tests;
* ``grazing`` — δ_min or δ_max of an element with a gap crosses ±D (the reference element's u_min, u_max).

Points whose multipliers are unresolved carry ``Status.UNRESOLVED`` and take no part in the multiplier tests.

References
----------
R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010;
Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
(pseudo-arclength continuation, test functions of folds, period doublings and Neimark–Sacker points).
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ModelError
from ...grid import param_name
from ...status import Status, flag_attrs
from ..periodic.arclength import _span_reporter
from ..periodic.floquet import pairs
from ..secant import illinois_on_chord
from .damping import require_decidable
from .equations import HBEquations, single_thread_blas, solve
from .form import mean
from .hill import HillResult
from .solve import hb_solve

__all__ = ["KIND", "HBBifurcation", "HBContinuation", "hb_continuation"]

#: ``geardyn_kind`` of a continued HB branch (its figures: :mod:`geardyn.plot.hb`).
KIND = "hb"

#: Arclength steps in (x, p/p_s): initial, smallest.
DS_INIT, DS_MIN = 0.005, 1e-7
CORRECTOR_TOL = 1e-10
CORRECTOR_MAX_ITER = 10
MAX_TURN_DEG = 20.0
MAX_POINTS = 3000
#: Event location: stop when the chord bracket is below this (relative to the chord) or after LOCATE_MAX_ITER, or
#: when the test function is below ROOT_REL_TOL times its change over the chord (a root to rounding).  An event
#: whose test function is below SHARED_REL_TOL times its change over the chord at a point located already in the
#: step (meshes of the same loads grazing together) is that point.
LOCATE_REL_TOL = 1e-9
LOCATE_MAX_ITER = 40
ROOT_REL_TOL = 1e-12
SHARED_REL_TOL = LOCATE_REL_TOL
#: The multipliers' tests (period doubling, Neimark–Sacker) are located to this relative bracket: the multipliers
#: carry RK4's error and move with the switch instants of the monodromy's period (about 1e-7 here, and their test
#: functions are no smoother), so a narrower bracket only adds trials, each with its monodromy matrix.
MULTIPLIER_LOCATE_TOL = 1e-6
#: While a real multiplier is within NEAR_CRITICAL of −1 (or a complex pair within the rules' band of the unit
#: circle) the step is at most NEAR_CRITICAL_DS·ds_max, so that two events close together (a period-doubling
#: interval a few thousandths wide) are not stepped over with no net sign change of their test.
NEAR_CRITICAL = 0.1
NEAR_CRITICAL_DS = 0.1
#: A step is refused (and halved) when a resolved multiplier moves farther than this.
MAX_MULTIPLIER_STEP = 0.1
#: The next step is at most the last one times MULTIPLIER_STEP_TARGET / (its largest multiplier move).
MULTIPLIER_STEP_TARGET = 0.09
#: The corrector of a sparse Jacobian (forms of more than ``SPARSE_DOFS`` coordinates) solves with the factors of an
#: earlier iteration (a chord step, refined once with the current matrix) while the residual falls at least by this
#: factor an iteration; else it factorises the current matrix.  (Dense Jacobians: Newton, factorised every time.)
CHORD_RATE = 0.25
#: A system without damping: a multiplier counts as on the unit circle (neutrally stable) within this.
NEUTRAL_TOL = 1e-6


@dataclass(frozen=True)
class _StepRules:
    """How the step follows the multipliers: ``radial`` measures their motion by the moduli (the Hausdorff distance
    of the sets: a lightly damped mode's pair turns by ω_d ΔT when the period changes, which no test sees) instead of
    the positions; a complex pair within ``band`` of the unit circle caps the step; ``ds_max`` is the default."""

    radial: bool
    band: float
    ds_max: float


#: The pair's rules (two multipliers) and those of every other form (the arclength then runs over every
#: coordinate's 2H + 1 coefficients, so the default largest step is larger; near a critical multiplier it is
#: NEAR_CRITICAL_DS·0.2 = 0.02, shooting's largest step; events are located, not bracketed, so their values do not
#: depend on it: on the bevel pair ds_max = 0.02 and 0.2 agree to 1e-9).
PAIR_RULES = _StepRules(False, NEAR_CRITICAL, 0.02)
SYSTEM_RULES = _StepRules(True, 0.01, 0.2)
#: The largest steps by default (``geardyn hb --ds-max``).
DS_MAX, SYSTEM_DS_MAX = PAIR_RULES.ds_max, SYSTEM_RULES.ds_max


@dataclass(eq=False)
class _Pt:
    """A corrected branch point; its tangent and stability are computed when first asked for (a point whose step is
    refused by the turn of the tangent, or a trial of a fold or grazing location, needs no stability; a trial of a
    grazing or a multiplier test no tangent)."""

    y: np.ndarray
    tangent: Callable[[], np.ndarray]
    ext: np.ndarray  # (elements, 2): every element's δ_min, δ_max
    stability: Callable[[], HillResult]
    iters: int = 0

    @functools.cached_property
    def t(self) -> np.ndarray:
        return self.tangent()

    @functools.cached_property
    def hill(self) -> HillResult:
        return self.stability()


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
        The reference element's extremes there.
    multipliers : complex ndarray
    detail : str
    located : bool
        The location met its tolerance.
    coefficients : ndarray
        The unknowns of the solution at the event (empty when not recorded).
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
        out = {"type": self.type, "value": self.value, "u_min": self.u_min, "u_max": self.u_max}
        out["multipliers"] = pairs(self.multipliers)
        return {**out, "detail": self.detail, "located": self.located}


@dataclass
class HBContinuation:
    """A continued harmonic-balance branch of a system.

    Attributes
    ----------
    model : System
        Base model (``param`` varies along the branch).
    param : str
    harmonics, period, samples : int
        H per coordinate, n and the time samples N per response period.
    values : ndarray (P,)
        Parameter values along the branch.
    coefficients : ndarray (P, dofs(2H + 1))
        Every coordinate's coefficients, coordinate by coordinate (the pair: u's 2H + 1).
    u_min, u_max : ndarray (P,)
        Extremes of the reference element's deflection (the pair's u).
    multipliers : complex ndarray (P, 2(dofs − rigid))
        The elastic Floquet multipliers.
    status : ndarray of int (P,)
        :class:`~geardyn.status.Status` per point (``OK`` or ``UNRESOLVED`` for points whose multipliers could
        not be resolved; a start that failed is one ``NOT_CONVERGED``/``DIVERGED`` point with NaN values).
    bifurcations : list of HBBifurcation
    end : str
        Why the continuation stopped.
    elements, kinds : tuple of str
        Element names and kinds (``mesh``, ``clearance``).
    gaps : tuple of float
        Every element's half gap D.
    element_u_min, element_u_max : ndarray (P, elements)
        Every element's δ extremes.
    equations : HBEquations
        The equations of the branch (for :attr:`dynamic_factor`).
    rigid : int
        Rigid-body modes (their multipliers, exactly 1, left out).
    reference : int
        Index of the reference element.
    labels : tuple of str
        Coordinate names.
    conservative : bool
        No damping: the multipliers multiply to 1, a point is stable when every |μ| <= 1 + :data:`NEUTRAL_TOL`
        (neutrally, not asymptotically).
    """

    model: Any
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
    elements: tuple[str, ...] = ("mesh",)
    kinds: tuple[str, ...] = ("mesh",)
    gaps: tuple[float, ...] = (0.0,)
    element_u_min: np.ndarray = field(default_factory=lambda: np.zeros((0, 1)))
    element_u_max: np.ndarray = field(default_factory=lambda: np.zeros((0, 1)))
    equations: Any = field(default=None, repr=False, compare=False)
    rigid: int = 0
    reference: int = 0
    labels: tuple[str, ...] = ("u",)
    conservative: bool = False

    @property
    def amplitude(self) -> np.ndarray:
        return 0.5 * (self.u_max - self.u_min)

    @functools.cached_property
    def dynamic_factor(self) -> np.ndarray:
        """(P, meshes): largest mesh force over the period / static mesh force (NaN where the static force is 0 or
        the point did not converge), computed when first asked for."""
        eq, P = self.equations, self.values.size
        out = np.full((P, sum(k == "mesh" for k in self.kinds)), math.nan)
        for i, (c, v, s) in enumerate(zip(self.coefficients, self.values, self.status)):
            if eq is not None and int(s) in (int(Status.OK), int(Status.UNRESOLVED)):
                out[i] = eq.dynamic_factors(c, float(v))  # (the coefficients alone: no gauge multipliers needed)
        return out

    @property
    def stable(self) -> np.ndarray:
        """True where the point is resolved and all |μ| < 1 (<= 1 + NEUTRAL_TOL without damping)."""
        mu = np.abs(self.multipliers)
        inside = mu <= 1.0 + NEUTRAL_TOL if self.conservative else mu < 1.0
        return (self.status == int(Status.OK)) & np.all(inside, axis=1)

    @property
    def converged(self) -> bool:
        return bool(self.values.size) and not np.isin(self.status, (Status.NOT_CONVERGED, Status.DIVERGED)).any()

    def of_type(self, typ: str) -> list[HBBifurcation]:
        return [b for b in self.bifurcations if b.type == typ]

    def bifurcations_json(self) -> list[dict[str, Any]]:
        """The bifurcations as :meth:`to_json` gives them (the parameter under its own name)."""
        return [{"type": b.type, self.param: float(b.value), **b.to_json()} for b in self.bifurcations]

    def attrs(self, kind: str, options: Any = None, **extra: Any) -> dict[str, str]:
        """The global attributes of a result of this branch (:func:`~geardyn.io.result_attrs`), ``model`` with the
        reference element's D and ξ0 (a system's has only its ω) for the figures."""
        from ...io import result_attrs

        attrs = result_attrs(kind, self.model, options, **extra)
        ref = json.loads(attrs["model"])
        ref.setdefault("D", self.gaps[self.reference])
        ref.setdefault("xi0", 0.5 * mean(self.model.hb_form().elements[self.reference].C))
        attrs["model"] = json.dumps(ref)
        return attrs

    def to_json(self) -> dict[str, Any]:
        """Plain-dict summary: ``branch`` points (the reference element's ``amplitude``, ``u_min``, ``u_max``,
        ``stable``, ``status``, ``multipliers``), ``bifurcations``, ``harmonics``, ``converged``, ``end``, and
        per element (``meshes``, ``clearances``, a rolling bearing's x and y rows in ``bearings``: ``name`` and per
        point ``u_min``, ``u_max``, ``amplitude``, ``impact``, a mesh's ``dynamic_factor``), ``labels``,
        ``reference_mesh``, ``rigid_body_modes``, ``conservative`` and ``notes``."""
        from ...io import json_number
        from ..classify import IMPACT_LABELS, impact_state

        pts, cols = [], (self.values, self.u_min, self.u_max, self.stable, self.status, self.multipliers)
        for v, lo, hi, st, s, mu in zip(*cols):
            pt = {
                self.param: float(v),
                "amplitude": json_number(0.5 * (hi - lo)),
                "u_min": json_number(lo),
                "u_max": json_number(hi),
            }
            pt.update(stable=bool(st) if int(s) == int(Status.OK) else None, status=Status(int(s)).label)
            pts.append({**pt, "multipliers": [[json_number(m.real), json_number(m.imag)] for m in mu]})
        rows: dict[str, list[dict[str, Any]]] = {"mesh": [], "clearance": []}
        for e, (nm, kind) in enumerate(zip(self.elements, self.kinds)):
            lo, hi = self.element_u_min[:, e], self.element_u_max[:, e]
            row = {"name": nm, "u_min": list(map(json_number, lo)), "u_max": list(map(json_number, hi))}
            row["amplitude"] = list(map(json_number, 0.5 * (hi - lo)))
            row["impact"] = [IMPACT_LABELS[impact_state(v, self.gaps[e])] if np.isfinite(v) else None for v in lo]
            if kind == "mesh":  # (the mesh's column: the meshes before it)
                row["dynamic_factor"] = list(map(json_number, self.dynamic_factor[:, self.kinds[:e].count("mesh")]))
            rows.setdefault(kind, []).append(row)
        notes = [
            f"{2 * self.rigid} Floquet multipliers equal to 1 belong to the {self.rigid} rigid-body mode(s) and are "
            f"left out; the multipliers listed are the elastic ones"
        ] * bool(self.rigid)
        if self.conservative:
            notes.append(
                "no damping: the multipliers multiply to 1 and lie on or off the unit circle; stable means every "
                f"|μ| <= 1 + {NEUTRAL_TOL:g} (neutrally stable); folds and period doublings are located by det(I − M) "
                "and det(I + M), no Neimark–Sacker test is made"
            )
        out = dict(param=self.param, branch=pts, bifurcations=self.bifurcations_json(), harmonics=self.harmonics)
        out.update(period=self.period, samples=self.samples, converged=self.converged, end=self.end)
        out.update(meshes=rows["mesh"], clearances=rows["clearance"])
        out.update({"bearings": rows["bearing"]} if "bearing" in rows else {})
        out.update(labels=list(self.labels), reference_mesh=self.elements[self.reference], rigid_body_modes=self.rigid)
        return {**out, "conservative": self.conservative, "notes": notes}

    def to_dataset(self):
        """The branch as an :class:`xarray.Dataset` over ``point`` (kind ``hb``): the reference element's values,
        every coordinate's coefficients, every element's extremes; the bifurcations as the JSON attribute
        ``bifurcations`` and the whole :meth:`to_json` as ``summary``."""
        import xarray as xr

        from ...io import annotate

        P, nd = self.values.size, len(self.labels)
        summary = self.to_json()
        attrs = self.attrs(
            KIND,
            **{k: summary[k] for k in ("param", "harmonics", "period", "samples", "end", "rigid_body_modes")},
            coefficient_layout="[a0, a1..aH, b1..bH] per coordinate of q(φ) = a0 + Σ a_k cos kφ + b_k sin kφ, "
            "φ = ωτ/(n p)",
            bifurcations=json.dumps(summary["bifurcations"]),
            summary=json.dumps(summary),
        )
        pm, el = ("point", "multiplier"), ("point", "element")
        ds = xr.Dataset(
            {
                self.param: ("point", self.values),
                **{k: ("point", getattr(self, k)) for k in ("u_min", "u_max", "amplitude")},
                "stable": ("point", self.stable.astype(np.int8)),
                "multiplier_re": (pm, self.multipliers.real),
                "multiplier_im": (pm, self.multipliers.imag),
                "coefficients": (("point", "dof", "coefficient"), self.coefficients.reshape(P, nd, -1)),
                **{k: (el, getattr(self, k)) for k in ("element_u_min", "element_u_max")},
                "status": ("point", self.status.astype(np.int64)),
            },
            coords={
                "point": np.arange(P),
                "multiplier": np.arange(self.multipliers.shape[1]),
                "dof": list(self.labels),
                "coefficient": np.arange(2 * self.harmonics + 1),
                "element": list(self.elements),
            },
            attrs=attrs,
        )
        ds["status"].attrs.update(flag_attrs())
        return annotate(ds)


def _pairs(mu: np.ndarray) -> np.ndarray:
    """Products μ_i μ_j of the complex-conjugate pairs: μ_i with Im > 0 whose nearest other multiplier is
    closer to conj(μ_i) than Im μ_i (Hill's real multipliers carry small spurious imaginary parts)."""
    out = []
    for i in np.nonzero(mu.imag > 1e-9 * np.abs(mu))[0]:
        d = np.abs(mu - np.conj(mu[i]))
        d[i] = np.inf
        j = int(np.argmin(d))
        if d[j] < mu[i].imag:
            out.append(mu[i] * mu[j])
    return np.array(out)


#: Side of a grazing test → its description.
_SIDES = {
    "min_plus": "δ_min = +D (drive-side contact loss)",
    "min_minus": "δ_min = −D (back-side contact)",
    "max_plus": "δ_max = +D (drive-side contact)",
    "max_minus": "δ_max = −D",
}


class _Tracer:
    """The equations with their test functions and step rules."""

    def __init__(self, eq: HBEquations, lo: float, hi: float, ps: float, conservative: bool):
        self.s, self.lo, self.hi, self.ps, self.conservative, self.M = eq, lo, hi, ps, conservative, eq.basis.size
        self.rules = PAIR_RULES if eq.form.scalar else SYSTEM_RULES  # (a scalar form: the pair's)
        # test function → (event type, detail) of :meth:`events`; the reference element's grazing is ``graze_*``
        ns = ("neimark-sacker", "complex pair through the unit circle")
        self.labels = {"turn": ("fold", "turning point: a multiplier through +1 (det(I − M) = 0)")}
        self.labels.update(pd=("period-doubling", "real multiplier through −1"), ns=ns)
        self.labels.update({f"ns{k}": ns for k in range(2, eq.basis.dofs - eq.basis.rigid + 1)})
        self.graze = ["graze" if e == eq.reference else f"graze{e}" for e in range(len(eq.elements))]
        for pre, nm in zip(self.graze, eq.elements):
            who = "" if pre == "graze" else f"{nm}: "
            self.labels.update({f"{pre}_{k}": ("grazing", f"{who}{v}") for k, v in _SIDES.items()})

    def p(self, y: np.ndarray) -> float:
        return float(y[-1] * self.ps)

    def _aug(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """R and [[∂R/∂x, ∂R/∂(p/p_s)], [0]] at ``y``."""
        return self.s.bordered(y[:-1], self.p(y), self.ps)

    def tangent(self, y: np.ndarray, ref: np.ndarray, aug: tuple | None = None, lu: Any = None) -> np.ndarray:
        """Unit null vector of [∂R/∂x, ∂R/∂p] at ``y`` oriented like ``ref`` (``aug``: :meth:`_aug` at ``y``,
        if already evaluated; its matrix is overwritten; ``lu``: a sparse Jacobian's factors at a nearby point
        bordered by ``ref`` itself, the corrector's last, used as in a chord step)."""
        _R, A = self._aug(y) if aug is None else aug
        A[-1] = ref
        rhs = np.zeros(self.M + 1)
        rhs[-1] = 1.0
        t = solve(A, rhs, robust=True, lu=lu)
        t /= np.linalg.norm(t)
        return t if t @ ref >= 0 else -t

    def correct(self, y0: np.ndarray, normal: np.ndarray, ref_t: np.ndarray) -> _Pt | None:
        """The point of the branch in the hyperplane through ``y0`` normal to ``normal`` (Newton; a sparse Jacobian's
        factors are kept while the residual falls by CHORD_RATE an iteration), or None."""
        y, F, lu, r_last = y0.copy(), np.empty(self.M + 1), None, math.inf
        for it in range(CORRECTOR_MAX_ITER):
            try:
                self.s._entry(self.p(y))  # (a ModelError: not a valid value of the parameter)
            except ModelError:
                return None
            aug = R, A = self._aug(y)
            g = float(normal @ (y - y0))
            r = math.sqrt(R @ R)
            if r <= CORRECTOR_TOL * (1 + math.sqrt(y @ y)) and abs(g) <= 1e-12:
                return self._finish(y, ref_t, it, aug, lu if normal is ref_t else None)
            F[:-1], F[-1] = R, g
            A[-1] = normal
            try:
                dy = solve(A, -F, lu=lu if r <= CHORD_RATE * r_last else None)
            except np.linalg.LinAlgError:
                return None
            lu, r_last = getattr(A, "lu", None), r
            y = y + dy
            if not np.all(np.isfinite(y)):
                return None
            if math.sqrt(dy @ dy) <= 1e-13 * (1 + math.sqrt(y @ y)):
                return self._finish(y, ref_t, it + 1, None, lu if normal is ref_t else None)
        return None

    def _finish(self, y: np.ndarray, ref_t: np.ndarray, iters: int, aug: tuple | None = None, lu: Any = None) -> _Pt:
        a, p = y[:-1], self.p(y)
        ext = self.s.element_extremes(a, p)
        return _Pt(y, lambda: self.tangent(y, ref_t, aug, lu), ext, lambda: self.s.stability(a, p), iters)

    def multiplier_step(self, a: HillResult, b: HillResult) -> float:
        """How far the multipliers moved between two resolved points (0 if either is not): their positions (the
        pairing that moves least), or the Hausdorff distance of their moduli (:attr:`_StepRules.radial`)."""
        if a.status is not Status.OK or b.status is not Status.OK or not a.multipliers.size:
            return 0.0
        ma, mb = a.multipliers, b.multipliers
        if not self.rules.radial:
            return float(min(np.max(np.abs(ma - mb)), np.max(np.abs(ma - mb[::-1]))))
        d = np.abs(np.abs(ma)[:, None] - np.abs(mb)[None, :])
        return float(max(d.min(axis=1).max(), d.min(axis=0).max()))

    def near_critical(self, h: HillResult) -> bool:
        """A resolved real multiplier close to −1, or a complex pair close to the unit circle (folds, where a
        multiplier passes +1, are found from the tangent, whose turn limits the step already; without damping
        every pair is on the circle and only −1 counts)."""
        if h.status is not Status.OK or not h.multipliers.size:
            return False
        mu = h.multipliers
        if not self.rules.radial and not self.conservative and np.any(np.abs(mu.imag) > 1e-9 * np.abs(mu)):
            return bool(abs(abs(mu[0]) - 1.0) < self.rules.band)
        near_pair = not self.conservative and np.any(np.abs(np.sqrt(np.abs(_pairs(mu))) - 1.0) < self.rules.band)
        return bool(near_pair or np.any(np.abs(mu + 1.0) < NEAR_CRITICAL))

    def tests(self, pt: _Pt, chord: np.ndarray | None = None, key: str | None = None) -> dict[str, float]:
        """Test functions at ``pt`` (the tangent oriented along ``chord``): all of them, or only ``key``'s kind
        (then the multipliers are computed only for the multiplier tests)."""
        out = {}
        if key is None or key == "turn":
            out["turn"] = float(-pt.t[-1] if chord is not None and pt.t @ chord < 0 else pt.t[-1])
        if key is None or key.startswith(("pd", "ns")):
            h = pt.hill
            if h.status is Status.OK and h.multipliers.size:
                mu = h.multipliers
                out["pd"] = float(np.real(np.prod(mu + 1.0)))
                if not self.conservative:
                    for k, v in enumerate(np.sort(np.abs(_pairs(mu)))[::-1]):  # the k-th largest |μ_i μ_j| − 1
                        out["ns" if k == 0 else f"ns{k + 1}"] = float(v) - 1.0
        if key is None or key.startswith("graze"):
            p = self.p(pt.y)
            gaps = [el.gap if el.rule is None else 0.0 for el in self.s._entry(p).form.elements]  # (a bearing: smooth)
            for pre, D, ext in zip(self.graze, gaps, pt.ext):
                for side, v in zip(("min", "max"), ext if D > 0 else ()):
                    out[f"{pre}_{side}_plus"], out[f"{pre}_{side}_minus"] = v - D, v + D
        return out

    def locate(self, a: _Pt, b: _Pt, key: str, fa: float, fb: float) -> tuple[_Pt, bool]:
        """The zero of test ``key`` (``fa``, ``fb`` at a and b) on the chord from a to b (:data:`LOCATE_REL_TOL`, or
        :data:`MULTIPLIER_LOCATE_TOL` for the multipliers' tests)."""
        d = b.y - a.y
        e = d / float(np.linalg.norm(d))
        zero = ROOT_REL_TOL * abs(fb - fa)

        def trial(s: float, lo: float, hi: float) -> tuple[float, _Pt, float] | None:
            pt = self.correct(a.y + s * d, e, a.t)
            if pt is None:
                return None
            f = self.tests(pt, d, key).get(key, math.nan)
            return (s, pt, 0.0 if abs(f) <= zero else f) if math.isfinite(f) else None

        tol = MULTIPLIER_LOCATE_TOL if key.startswith(("pd", "ns")) else LOCATE_REL_TOL
        return illinois_on_chord(fa, fb, trial, a if abs(fa) <= abs(fb) else b, tol, LOCATE_MAX_ITER)

    def events(self, a: _Pt, b: _Pt) -> list[HBBifurcation]:
        d = b.y - a.y
        ta, tb = self.tests(a, d), self.tests(b, d)
        out, found = [], []
        for key, (typ, detail) in self.labels.items():
            if key in ta and key in tb and (ta[key] > 0) != (tb[key] > 0):
                zero = SHARED_REL_TOL * abs(tb[key] - ta[key])  # the root within the bracket of a location
                same = (q for q in found if abs(self.tests(q[0], d, key).get(key, math.inf)) <= zero)
                pt, ok = next(same, None) or self.locate(a, b, key, ta[key], tb[key])
                found.append((pt, ok))
                u = map(float, pt.ext[self.s.reference])
                bif = HBBifurcation(typ, self.p(pt.y), *u, pt.hill.multipliers.copy(), detail, ok, pt.y[:-1].copy())
                out.append((float((pt.y - a.y) @ d), bif))
        return [b for _s, b in sorted(out, key=lambda e: e[0])]

    def trace(self, y: np.ndarray, ref: np.ndarray, ds: float, ds_max: float, max_points: int, on_point) -> tuple:
        """The pseudo-arclength loop from the solution ``y`` (unknowns, then p/p_s), the first tangent oriented like
        ``ref``, steps ``ds`` up to ``ds_max``, at most ``max_points``; ``on_point`` gets each point's parameter.
        Returns (points, bifurcations, end)."""
        lo, hi = self.lo, self.hi
        with single_thread_blas():
            pts, bifs, h = [self._finish(y, ref, 0)], [], float(ds)
            end = (
                f"max points: stopped at {max_points} points before the end of the interval (allow more points, or "
                f"a larger ds_max)"
            )
            while len(pts) < max_points:
                cur, nxt, dmu = pts[-1], None, 0.0
                while h >= DS_MIN:
                    nxt = self.correct(cur.y + h * cur.t, cur.t, cur.t)
                    if nxt is not None:
                        if math.degrees(math.acos(float(np.clip(nxt.t @ cur.t, -1, 1)))) <= MAX_TURN_DEG:
                            dmu = self.multiplier_step(cur.hill, nxt.hill)
                            if dmu <= MAX_MULTIPLIER_STEP and (
                                h <= NEAR_CRITICAL_DS * ds_max or not self.near_critical(nxt.hill)
                            ):
                                break
                    nxt = None
                    h *= 0.5
                if nxt is None:
                    end = "corrector failed (step below DS_MIN)"
                    break
                bifs.extend(self.events(cur, nxt))
                pts.append(nxt)
                on_point(self.p(nxt.y))
                # (the multipliers move about linearly in the step: aim below the refusal limit)
                aim = h * MULTIPLIER_STEP_TARGET / dmu if dmu > 0.0 else math.inf
                h = min(ds_max, h * (1.5 if nxt.iters <= 3 else 1.0 if nxt.iters <= 6 else 0.5), aim)
                if self.near_critical(nxt.hill):
                    h = min(h, NEAR_CRITICAL_DS * ds_max)
                if not lo <= self.p(nxt.y) <= hi:
                    end = "reached the end of the interval"
                    bifs = [b for b in bifs if lo <= b.value <= hi]
                    break
        return pts, bifs, end


def hb_continuation(
    model: Any,
    param: str,
    start: float,
    stop: float,
    *,
    harmonics: int | None = None,
    period: int = 1,
    guess: Any = None,
    samples: int | None = None,
    ds: float = DS_INIT,
    ds_max: float | None = None,
    max_points: int = MAX_POINTS,
    state0: Any = None,
    floquet: str = "monodromy",
    progress: Callable[[float, float], None] | None = None,
) -> HBContinuation:
    """Continue the period-n harmonic-balance solution of a system in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    model : System
        The pair (:class:`~geardyn.model.GearModel`) or a multi-DOF system (its value of ``param`` is replaced).
    param : str
        Any parameter of the system (``omega``, ``xi0``, ``kappa1``, ``fp``, ``D`` …; a system's ``omega``,
        ``<mesh>.xi0``, ``<clearance>.D`` …).
    start, stop : float
        The branch starts at ``start`` and is followed (through folds) until the parameter leaves the
        interval between ``start`` and ``stop``.
    harmonics : int, optional
        H per coordinate (default :func:`~geardyn.analysis.hb.equations.default_harmonics`).
    period : int
        n, the response period in forcing periods.
    guess : coefficients, "simulate" or "linear", optional
        Start guess at ``start`` (default: the attractor reached by simulation from ``state0``).
    samples : int, optional
        Time samples per response period.
    ds, ds_max : float
        Initial and largest arclength step in (x, p/|stop − start|) (``ds_max`` default: the form's
        :class:`_StepRules`, 0.02 for the pair, 0.2 for other systems).
    max_points : int
        Largest number of branch points (the branch then ends with ``end`` saying so).
    state0 : (u0, v0) or a full state, optional
        Start of the simulation of the default guess.
    floquet : str
        ``"monodromy"`` (default, :mod:`.monodromy`) or ``"hill"`` (:mod:`.hill`).
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
        Unknown parameter, start/stop outside the parameter's valid range, incommensurate meshes, or a system
        whose stability harmonic balance cannot decide (:func:`~geardyn.analysis.hb.damping.require_decidable`).

    Examples
    --------
    >>> from geardyn import GearModel, hb_continuation
    >>> res = hb_continuation(GearModel(), "omega", 0.5, 0.6, harmonics=8)
    >>> res.converged, float(res.values[0]), res.end
    (True, 0.5, 'reached the end of the interval')
    """
    param = param_name(param)
    start, stop = float(start), float(stop)
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ModelError("start, stop: must be finite and different")
    m0 = model.with_param(param, start)
    conservative = require_decidable(model, param, start, stop)  # (stop checked there too)
    report = _span_reporter(progress, start, stop)  # the one of shooting's branches
    eq = HBEquations(model, harmonics, period, param=param, samples=samples, floquet=floquet)
    sol = hb_solve(m0, eq.H, period, guess, samples=eq.N, stability=False, state0=state0)
    f, N0 = eq.form, eq.basis.size - eq.basis.rigid
    if not sol.converged:  # one point, the start that failed
        ext = np.full((1, len(f.elements), 2), math.nan)
        cols = [[start], sol.unknowns[None, :N0], [sol.multipliers], [int(sol.status)]]  # (the multipliers NaN)
        bifs, end = [], f"start: {sol.status.label}"
    else:
        lo, hi = sorted((start, stop))
        ps = hi - lo
        tr = _Tracer(eq, lo, hi, ps, conservative)
        y = np.concatenate([sol.unknowns, [start / ps]])
        ref = np.zeros(eq.basis.size + 1)
        ref[-1] = 1.0 if stop > start else -1.0
        pts, bifs, end = tr.trace(y, ref, ds, tr.rules.ds_max if ds_max is None else float(ds_max), max_points, report)
        ext = np.array([q.ext for q in pts])
        cols = [[tr.p(q.y) for q in pts], [q.y[:N0] for q in pts], [q.hill.multipliers for q in pts],
                [int(q.hill.status) for q in pts]]  # fmt: skip
    vals, coef, mu, status = map(np.array, cols)
    u_min, u_max, r, els = ext[:, :, 0], ext[:, :, 1], eq.reference, f.elements
    # (the fields in their order)
    return HBContinuation(model, param, eq.H, eq.n, eq.N, vals, coef, u_min[:, r], u_max[:, r], mu, status, bifs, end,
                          eq.elements, tuple(e.kind for e in els), tuple(e.gap for e in els), u_min, u_max, eq,
                          eq.basis.rigid, r, f.labels, conservative)  # fmt: skip
