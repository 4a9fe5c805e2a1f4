"""Pseudo-arclength continuation of harmonic-balance solutions of multi-DOF systems.

The 1-DOF continuation (:mod:`.continuation`) is run on the system's equations
(:class:`~geardyn.analysis.hb.system.HBSystemEquations`, whose unknown vector holds every DOF's
coefficients and the gauge multipliers of the rigid-body modes): the same predictor, bordered
corrector, step control and event location (:func:`~geardyn.analysis.hb.continuation.trace_branch`).
What differs is taken by a subclass of its tracer:

* the extremes are those of the reference mesh's deflection δ;
* the multipliers are the 2(n − r) elastic ones (:mod:`.system_hill`), so the tests take all of them:
  ``pd`` = Π(μ_i + 1) (a real multiplier through −1), ``ns``, ``ns2``, … = the largest, second largest …
  |μ_i μ_j| − 1 of the complex-conjugate pairs (the k-th pair through the unit circle; for one DOF the
  1-DOF test), the fold from the tangent as before;
* grazing is watched on every element (meshes and clearances): δ_min or δ_max through ±D;
* the step control compares multiplier *sets* (Hausdorff distance) of their moduli and real values
  (:func:`_radial`: the turn of a pair's argument, which no test sees, does not limit the step), and caps the
  step while any real multiplier is near −1 or a complex pair within :data:`NEAR_CRITICAL_PAIR` of the unit
  circle.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ModelError
from ...status import Status, flag_attrs
from .continuation import DS_INIT, KIND, MAX_POINTS, NEAR_CRITICAL, HBContinuation, _Tracer, span_reporter, trace_branch
from .damping import require_damping
from .hill import HillResult
from .solve import DEFAULT_HARMONICS
from .system import HBSystemEquations, dynamic_factors, hb_system_solve

__all__ = ["HBSystemContinuation", "hb_system_continuation", "NEAR_CRITICAL_PAIR", "SYSTEM_DS_MAX"]

#: The step is capped (as in :mod:`.continuation`) while a complex pair is within this of the unit circle.  The
#: 1-DOF value (NEAR_CRITICAL = 0.1) would cap every step of a system with lightly damped elastic modes: on the
#: 8-DOF bevel pair the bearing modes keep 0.968 <= |μ| <= 0.984 over the whole response 0.6 <= ω <= 1.2 (at
#: H = 12; a band of 0.1 gave 929 points and 139 s, a band of 0.02 capped three steps in four), while the pairs
#: that cross the circle (three Neimark–Sacker points) are within 0.01 of it only near their crossings.
#: Real multipliers near −1 keep the 1-DOF cap.
NEAR_CRITICAL_PAIR = 0.01
#: Default largest arclength step of a system's branch.  The arclength is over every DOF's 2H + 1 coefficients
#: (n(2H + 1) + 1 components against shooting's 2n + 1), so a step of the 1-DOF default DS_MAX covers a few
#: times less of ω than shooting's step of the same size; the step is also bounded by the multiplier motion
#: (MAX_MULTIPLIER_STEP), the tangent's turn and the corrector's iterations, and near a critical multiplier it
#: is NEAR_CRITICAL_DS·SYSTEM_DS_MAX = 0.02 (shooting's largest step).  Every event is located (not bracketed),
#: so its value does not depend on the step: on the bevel pair the events at ds_max = 0.02 and 0.2 agree to
#: 1e-9 (``benchmarks/hb_system.py``).
SYSTEM_DS_MAX = 0.2
#: Side of a grazing test → its description.
_SIDES = {
    "min_plus": "δ_min = +D (drive-side contact loss)",
    "min_minus": "δ_min = −D (back-side contact)",
    "max_plus": "δ_max = +D (drive-side contact)",
    "max_minus": "δ_max = −D",
}


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


def _radial(mu: np.ndarray) -> np.ndarray:
    """What the step control sees of the multipliers: their moduli |μ|.

    The argument of a lightly damped mode's pair turns by ω_d ΔT when the period T = 2π/ν changes: on the 8-DOF
    bevel pair the bearing modes' pairs turn several times round the circle between ω = 0.6 and 1.2, at
    |μ| ≈ 0.98.  No test depends on that turn (``ns`` is a product of moduli, ``pd`` = Π(μ + 1) changes sign only
    on the real axis), so the step control measures only the moduli.  The moduli stay continuous where a pair
    meets on the real axis and splits into two real multipliers (on the bevel pair near ω = 0.883, on the negative
    axis); a real multiplier's sign cannot change along a branch (μ = 0 is impossible), so nothing is lost."""
    return np.abs(mu)


class _SystemTracer(_Tracer):
    """The tracer of :mod:`.continuation` on the equations of a system (see the module docstring)."""

    def __init__(self, sysm: HBSystemEquations, lo: float, hi: float, ps: float):
        super().__init__(sysm, lo, hi, ps)
        names = sysm.elements
        self.labels = dict(_Tracer.labels)
        self.labels.update({f"ns{k}": self.labels["ns"] for k in range(2, sysm.basis.dofs - sysm.basis.rigid + 1)})
        for e, nm in enumerate(names):
            if e != sysm.reference:
                self.labels.update({f"graze{e}_{k}": ("grazing", f"{nm}: {v}") for k, v in _SIDES.items()})

    def extremes(self, a: np.ndarray, p: float) -> tuple[float, float]:
        return self.s.extremes(a, p)

    def tests(self, pt: Any, chord: np.ndarray | None = None, key: str | None = None) -> dict[str, float]:
        flip = chord is not None and pt.t @ chord < 0
        out = {"turn": float(-pt.t[-1] if flip else pt.t[-1])}
        if key is not None and key.startswith("graze"):
            return self._grazing(pt, out)
        if key is not None and not key.startswith(("pd", "ns")):
            return out
        h = pt.hill
        if h.status is Status.OK and h.multipliers.size:
            mu = h.multipliers
            out["pd"] = float(np.real(np.prod(mu + 1.0)))
            for k, v in enumerate(np.sort(np.abs(_pairs(mu)))[::-1]):  # the k-th largest |μ_i μ_j| − 1
                out["ns" if k == 0 else f"ns{k + 1}"] = float(v) - 1.0
        return out if key is not None else self._grazing(pt, out)

    def _grazing(self, pt: Any, out: dict[str, float]) -> dict[str, float]:
        """``out`` with the grazing tests of every element with a gap."""
        p = self.p(pt.y)
        ext = self.s.element_extremes(pt.y[:-1], p)
        for e, el in enumerate(self.s._entry(p).elements):
            if el.D <= 0:
                continue
            pre = "graze" if e == self.s.reference else f"graze{e}"
            for side, v in (("min", ext[e, 0]), ("max", ext[e, 1])):
                out[f"{pre}_{side}_plus"], out[f"{pre}_{side}_minus"] = v - el.D, v + el.D
        return out

    def multiplier_step(self, a: HillResult, b: HillResult) -> float:
        """Hausdorff distance between the :func:`_radial` multiplier sets of two resolved points (0 if either
        is not)."""
        if a.status is not Status.OK or b.status is not Status.OK or not a.multipliers.size:
            return 0.0
        d = np.abs(_radial(a.multipliers)[:, None] - _radial(b.multipliers)[None, :])
        return float(max(d.min(axis=1).max(), d.min(axis=0).max()))

    def near_critical(self, h: HillResult) -> bool:
        if h.status is not Status.OK or not h.multipliers.size:
            return False
        mu = h.multipliers
        return bool(
            np.any(np.abs(np.sqrt(np.abs(_pairs(mu))) - 1.0) < NEAR_CRITICAL_PAIR)
            or np.any(np.abs(mu + 1.0) < NEAR_CRITICAL)
        )


@dataclass
class HBSystemContinuation(HBContinuation):
    """A continued HB branch of a system (the fields of :class:`~geardyn.analysis.hb.continuation.HBContinuation`,
    for the system).

    Attributes
    ----------
    param : str
        The continued system parameter.
    model : System
        The system at its base point; ``param`` takes the values along the branch.
    values : ndarray (P,)
        Those values.
    harmonics, period, samples : int
        H per DOF, n and the time samples N per response period.
    coefficients : ndarray (P, n_dof(2H + 1))
        Every DOF's coefficients, DOF by DOF.
    u_min, u_max : ndarray (P,)
        Extremes of the reference mesh's δ.
    multipliers : complex ndarray (P, 2(n − r))
        The elastic multipliers.
    status : ndarray of int (P,)
        :class:`~geardyn.status.Status` per point.
    bifurcations : list of HBBifurcation
    end : str
        Why the continuation stopped.
    elements : tuple of str
        Element names (meshes, then clearances).
    element_u_min, element_u_max : ndarray (P, elements)
        Every element's δ extremes.
    dynamic_factor : ndarray (P, meshes)
        Largest mesh force over the period / static mesh force (NaN where the static force is 0).
    rigid : int
        Rigid-body modes (their multipliers, exactly 1, left out).
    reference : int
        Index of the reference mesh.
    """

    elements: tuple[str, ...] = ()
    element_u_min: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    element_u_max: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    dynamic_factor: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    rigid: int = 0
    reference: int = 0

    def to_json(self) -> dict[str, Any]:
        """The keys of :meth:`HBContinuation.to_json` (reference mesh) plus ``meshes`` (per mesh: ``name`` and,
        per point, ``u_min``, ``u_max``, ``amplitude``, ``impact``, ``dynamic_factor``), ``clearances``,
        ``labels``, ``reference_mesh``, ``rigid_body_modes`` and ``notes``."""
        from ..classify import IMPACT_LABELS, impact_state

        out = super().to_json()

        def num(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        M = len(self.model.meshes)
        D = [m.D for m in self.model.meshes] + list(self.model.Dc)
        rows = []
        for e, nm in enumerate(self.elements):
            lo, hi = self.element_u_min[:, e], self.element_u_max[:, e]
            row = {
                "name": nm,
                "u_min": [num(v) for v in lo],
                "u_max": [num(v) for v in hi],
                "amplitude": [num(0.5 * (b - a)) for a, b in zip(lo, hi)],
                "impact": [IMPACT_LABELS[impact_state(v, D[e])] if np.isfinite(v) else None for v in lo],
            }
            if e < M:
                row["dynamic_factor"] = [num(v) for v in self.dynamic_factor[:, e]]
            rows.append(row)
        out.update(
            meshes=rows[:M],
            clearances=rows[M:],
            labels=list(self.model.labels),
            reference_mesh=self.elements[self.reference] if self.elements else None,
            rigid_body_modes=self.rigid,
            notes=[
                f"{2 * self.rigid} Floquet multipliers equal to 1 belong to the {self.rigid} rigid-body "
                f"mode(s) and are left out; the multipliers listed are the elastic ones"
            ]
            if self.rigid
            else [],
        )
        return out

    def to_dataset(self):
        """The branch as a Dataset of kind ``hb`` (the figures of the 1-DOF branch, for the reference mesh), with
        the system's coordinates and every element's extremes; the JSON summary in the ``summary`` attribute."""
        import xarray as xr

        from ...io import annotate, system_attrs

        P = self.values.size
        nd = len(self.model.labels)
        ref = self.model.meshes[self.reference]
        attrs = system_attrs(
            self.model,
            KIND,
            None,
            {
                "param": self.param,
                "harmonics": self.harmonics,
                "period": self.period,
                "samples": self.samples,
                "end": self.end,
                "rigid_body_modes": self.rigid,
                "coefficient_layout": "[a0, a1..aH, b1..bH] per DOF of q(φ) = a0 + Σ a_k cos kφ + b_k sin kφ, "
                "φ = ωτ/(n p)",
                "bifurcations": json.dumps(self.to_json()["bifurcations"]),
            },
        )
        attrs["model"] = json.dumps({"omega": self.model.omega, "D": ref.D, "xi0": ref.xi0})
        ds = xr.Dataset(
            {
                self.param: ("point", self.values),
                "u_min": ("point", self.u_min),
                "u_max": ("point", self.u_max),
                "amplitude": ("point", self.amplitude),
                "stable": ("point", self.stable.astype(np.int8)),
                "multiplier_re": (("point", "multiplier"), self.multipliers.real),
                "multiplier_im": (("point", "multiplier"), self.multipliers.imag),
                "coefficients": (("point", "dof", "coefficient"), self.coefficients.reshape(P, nd, -1)),
                "element_u_min": (("point", "element"), self.element_u_min),
                "element_u_max": (("point", "element"), self.element_u_max),
                "status": ("point", self.status.astype(np.int64)),
            },
            coords={
                "point": np.arange(P),
                "multiplier": np.arange(self.multipliers.shape[1]),
                "dof": list(self.model.labels),
                "coefficient": np.arange(2 * self.harmonics + 1),
                "element": list(self.elements),
            },
            attrs=attrs,
        )
        ds["status"].attrs.update(flag_attrs())
        ds.attrs["summary"] = json.dumps(self.to_json())
        return annotate(ds)


def hb_system_continuation(
    model: Any,
    param: str,
    start: float,
    stop: float,
    *,
    harmonics: int = DEFAULT_HARMONICS,
    period: int = 1,
    guess: Any = None,
    samples: int | None = None,
    ds: float = DS_INIT,
    ds_max: float = SYSTEM_DS_MAX,
    max_points: int = MAX_POINTS,
    state0: Any = None,
    floquet: str = "monodromy",
    progress: Callable[[float, float], None] | None = None,
) -> HBSystemContinuation:
    """Continue the period-n HB solution of a system in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    model : System
        Base system (its value of ``param`` is replaced; the forcing must be periodic).
    param : str
        A system parameter (``omega``, ``<mesh>.xi0``, ``<mesh>.kappa1``, ``<clearance>.D`` ...).
    start, stop : float
        The branch starts at ``start`` and is followed (through folds) until the parameter leaves the interval.
    harmonics : int
        H per DOF (default :data:`~geardyn.analysis.hb.solve.DEFAULT_HARMONICS`).
    period : int
        n, the response period in forcing periods.
    guess : coefficients (n_dof, 2H + 1), "simulate" or "linear", optional
        Start guess at ``start`` (default: the attractor reached by simulation from ``state0``).
    samples : int, optional
        Time samples per response period.
    ds, ds_max : float
        Initial and largest arclength step (defaults :data:`~geardyn.analysis.hb.continuation.DS_INIT` and
        :data:`SYSTEM_DS_MAX`).
    max_points : int
        Largest number of points (the branch then ends with ``end`` saying so).
    state0 : (u0, v0) or (2n,), optional
        Start of the simulation of the default guess.
    floquet : str
        How the multipliers are computed: ``"monodromy"`` (default, :mod:`.monodromy`) or ``"hill"``
        (Hill's method, :mod:`.system_hill`).
    progress : callable, optional
        Called as ``progress(done, total)`` with the parameter distance covered towards ``stop`` and
        |stop − start|.

    Returns
    -------
    HBSystemContinuation

    Raises
    ------
    ModelError
        Unknown parameter, incommensurate meshes, start/stop outside the parameter's valid range, or a system
        without damping (:func:`~geardyn.analysis.hb.damping.require_damping`).
    """
    start, stop = float(start), float(stop)
    lo, hi = sorted((start, stop))
    ps = hi - lo
    if not (ps > 0 and math.isfinite(ps)):
        raise ModelError("start, stop: must be finite and different")
    require_damping(model, param, start, stop)
    report = span_reporter(progress, start, stop)
    sysm = HBSystemEquations(
        model.with_param(param, stop), harmonics, period, param=param, samples=samples, floquet=floquet
    )
    sol = hb_system_solve(
        model.with_param(param, start), sysm.H, period, guess, samples=sysm.N, state0=state0, stability=False
    )  # Hill: at the first point of the branch
    names = sysm.elements
    if not sol.converged:
        nan = np.full((1, len(names)), math.nan)
        return HBSystemContinuation(
            model,
            param,
            sysm.H,
            sysm.n,
            sysm.N,
            np.array([start]),
            sol.unknowns[None, : sysm.basis.size - sysm.basis.rigid],
            np.array([math.nan]),
            np.array([math.nan]),
            np.full((1, 2 * (model.n - sysm.basis.rigid)), np.nan + 0j),
            np.array([int(sol.status)]),
            [],
            f"start: {sol.status.label}",
            names,
            nan,
            nan,
            np.full((1, len(model.meshes)), math.nan),
            sysm.basis.rigid,
            sysm.reference,
        )
    tr = _SystemTracer(sysm, lo, hi, ps)
    y = np.concatenate([sol.unknowns, [start / ps]])
    ref = np.zeros(sysm.basis.size + 1)
    ref[-1] = 1.0 if stop > start else -1.0
    pts, bifs, end = trace_branch(tr, y, ref, ds, ds_max, max_points, report)
    vals = np.array([tr.p(q.y) for q in pts])
    N0 = sysm.basis.size - sysm.basis.rigid
    ext = np.array([sysm.element_extremes(q.y[:-1], v) for q, v in zip(pts, vals)])
    dyn = np.array(
        [[np.nan if f is None else f for f in dynamic_factors(sysm, q.y[:-1], v)] for q, v in zip(pts, vals)]
    )
    return HBSystemContinuation(
        model,
        param,
        sysm.H,
        sysm.n,
        sysm.N,
        vals,
        np.array([q.y[:N0] for q in pts]),
        np.array([q.u_min for q in pts]),
        np.array([q.u_max for q in pts]),
        np.array([q.hill.multipliers for q in pts]),
        np.array([int(q.hill.status) for q in pts]),
        bifs,
        end,
        names,
        ext[:, :, 0],
        ext[:, :, 1],
        dyn,
        sysm.basis.rigid,
        sysm.reference,
    )
