"""Pseudo-arclength continuation of periodic orbits of multi-DOF systems, with their bifurcations.

The unknowns are y = (x, p): the state x (2n) at θ = 0 of a period-n orbit and the parameter p
scaled by the interval, p̂ = p/|stop − start|.  The residual G(x, p) = P^n(x; p) − x is the
system's period map (:func:`geardyn.integrate.period_map`, whose Jacobian is the monodromy
M); ∂G/∂p by a central difference.  A free rigid-body mode makes M − I singular (a rigidly
rotated orbit is again an orbit): its position directions S are fixed by the constraints
Sᵀ(x − x_ref) = 0 (the rigid velocity is pinned by G = 0 itself), so the bordered system

    [ M − I   G_p ]            [ G(x, p)            ]
    [ Sᵀ       0  ] Δy = −     [ Sᵀ (x − x_ref)     ]
    [ tᵀ (unit tangent) ]      [ tᵀ(y − y_pred) = 0 ]

is solved by least squares (predictor y + ds·t, Newton corrector; the step is halved on failure and
grows after easy corrections).  Along the branch the *elastic* multipliers (the monodromy on the
quotient by the rigid subspace, :func:`~geardyn.analysis.periodic.orbit.elastic_multipliers`) are
watched, and a bifurcation is reported where between two points

- ``fold``: the parameter component of the tangent changes sign (a real multiplier through +1);
- ``period-doubling``: the number of real multipliers below −1 changes;
- ``neimark-sacker``: the number of complex (Im ≠ 0) multipliers outside the unit circle changes;
- ``grazing``: for any element (mesh or clearance) u_min or u_max of the orbit crosses ±D.

Its parameter value is the linear interpolation of the test function between the two points
(``located`` False: bracketed to one step, which ``ds_max`` controls).  The periodic forcing is
required: incommensurate meshes are refused with one line.

References
----------
R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010;
Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import xarray as xr

from ..errors import ModelError
from ..integrate import period_map
from ..model import DEFAULT_DTAU
from ..systems.elements import rigid_modes
from .periodic.orbit import elastic_multipliers, require_periodic, shoot

__all__ = ["SystemContinuation", "system_continuation", "DS_MAX", "MAX_POINTS"]

#: Largest arclength step (in (x, p̂)) by default, and the first step.
DS_MAX = 0.02
DS_INIT = 0.005
DS_MIN = 1e-6
#: Largest number of branch points.
MAX_POINTS = 2000
NEWTON_TOL = 1e-9
NEWTON_ITER = 8


@dataclass
class _Pt:
    y: np.ndarray
    M: np.ndarray
    stats: np.ndarray
    mu: np.ndarray
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass
class SystemContinuation:
    """A continued branch of period-n orbits of a system and its bifurcations (non-dimensional).

    Parameters
    ----------
    model : SystemModel
    param : str
    start, stop : float
    n : int
    values : ndarray (K,)
    states : ndarray (K, 2n)
    multipliers : list of ndarray
        Elastic multipliers per point.
    u_min, u_max : ndarray (K, elements)
    bifurcations : list of dict
    end : str
        Why the branch ended.
    rigid : int
        Rigid-body modes left out.
    reference : int
        Index of the reference mesh.
    """

    model: Any
    param: str
    start: float
    stop: float
    n: int
    values: np.ndarray
    states: np.ndarray
    multipliers: list[np.ndarray]
    u_min: np.ndarray  # (K, elements)
    u_max: np.ndarray
    bifurcations: list[dict[str, Any]]
    end: str
    rigid: int
    reference: int = 0

    @property
    def stable(self) -> np.ndarray:
        return np.array([bool(np.all(np.abs(m) < 1.0)) for m in self.multipliers])

    @property
    def amplitude(self) -> np.ndarray:
        r = self.reference
        return 0.5 * (self.u_max[:, r] - self.u_min[:, r])

    def to_json(self) -> dict[str, Any]:
        """Keys of ``continuation --json`` (``branch`` points, ``bifurcations``, ``branches``) plus ``meshes``."""
        p = self.model.period_multiple() or 1
        names = list((e.name for e in self.model.elements))
        M = len(self.model.meshes)
        st = self.stable
        pts = [{self.param: float(self.values[i]), "amplitude": float(self.amplitude[i]), "stable": bool(st[i]),
                "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers[i]],
                "period": self.n * p, "branch": 0, "state": [float(s) for s in self.states[i]],
                "u_min": float(self.u_min[i, self.reference]), "u_max": float(self.u_max[i, self.reference])}
               for i in range(self.values.size)]
        meshes = [{"name": names[e], "u_min": self.u_min[:, e].tolist(), "u_max": self.u_max[:, e].tolist(),
                   "amplitude": (0.5 * (self.u_max[:, e] - self.u_min[:, e])).tolist(),
                   "impact": [_impact(self.u_min[i, e], self.model.meshes[e].D) for i in range(self.values.size)],
                   "dynamic_factor": None} for e in range(M)]
        return {"param": self.param, "start": self.start, "stop": self.stop, "branch": pts,
                "bifurcations": self.bifurcations,
                "branches": [{"branch": 0, "period": self.n * p, "points": int(self.values.size), "end": self.end,
                              "from": None}],
                "rigid_body_modes": self.rigid,
                "notes": ([f"{2 * self.rigid} multipliers equal to 1 belong to the rigid-body mode(s) and are left "
                           f"out; the multipliers listed are the elastic ones"] if self.rigid else []),
                "meshes": meshes}

    def to_dataset(self) -> xr.Dataset:
        """Dataset of kind ``system_continuation`` (point and bifurcation tables, per-element extremes)."""
        import json

        from .systems_sweep import system_attrs

        names = list((e.name for e in self.model.elements))
        bt = [b["type"] for b in self.bifurcations]
        ds = xr.Dataset({
            "value": ("point", self.values), "amplitude": ("point", self.amplitude),
            "stable": ("point", self.stable.astype(np.int64)), "branch": ("point", np.zeros(self.values.size, np.int64)),
            "state": (("point", "coordinate"), self.states),
            "element_u_min": (("point", "element"), self.u_min), "element_u_max": (("point", "element"), self.u_max),
            "bifurcation_type": ("bifurcation", np.array(bt, dtype=str) if bt else np.zeros(0, dtype=str)),
            "bifurcation_value": ("bifurcation", np.array([b[self.param] for b in self.bifurcations], float)),
            "bifurcation_amplitude": ("bifurcation", np.array([b["amplitude"] for b in self.bifurcations], float)),
        }, coords={"point": np.arange(self.values.size), "element": names,
                   "coordinate": [f"{lab}" for lab in self.model.labels] + [f"{lab}'" for lab in self.model.labels],
                   "bifurcation": np.arange(len(bt))},
            attrs=system_attrs(self.model, "system_continuation", None, {"param": self.param}))
        ds.attrs["summary"] = json.dumps(self.to_json())
        from ..io import annotate

        return annotate(ds)


def _impact(lo: float, D: float) -> str:
    from .classify import IMPACT_LABELS, impact_state

    return IMPACT_LABELS[impact_state(lo, D)]


class _Problem:
    def __init__(self, model, param, span, n, dtau, accurate, x_ref):
        from ..integrate import natural_steps

        self.model, self.param, self.span, self.n = model, param, span, n
        self.dtau, self.accurate = dtau, accurate
        self.steps = natural_steps(model, dtau)  # held along the branch: a smooth family of maps
        R = rigid_modes(model)
        d, nn, r = model.state_dim, model.n, R.shape[1]
        S = np.zeros((d, r))  # the free rigid positions (their velocities are pinned by G = 0)
        S[:nn, :] = R
        self.S, self.r, self.x_ref = S, r, np.asarray(x_ref, float)
        self.D = [m.D for m in model.meshes] + list(model.Dc)

    def at(self, y: np.ndarray):
        m = self.model.with_param(self.param, float(y[-1] * self.span))
        pts, M, stats, ok = period_map(m, y[:-1], self.n, dtau=self.dtau, accurate=self.accurate, steps=self.steps)
        return m, pts, M, stats, ok

    def residual(self, y: np.ndarray):
        m, pts, M, stats, ok = self.at(y)
        if not ok:
            return None
        G = pts[-1] - y[:-1]
        h = 1e-6 * max(1.0, abs(y[-1]))
        gp = []
        for s in (1.0, -1.0):
            yy = y.copy()
            yy[-1] += s * h
            _, pp, _, _, okp = self.at(yy)
            if not okp:
                return None
            gp.append(pp[-1])
        Gp = (gp[0] - gp[1]) / (2 * h)
        J = np.hstack([M - np.eye(M.shape[0]), Gp[:, None]])
        C = np.hstack([self.S.T, np.zeros((self.S.shape[1], 1))])
        res = np.concatenate([G, self.S.T @ (y[:-1] - self.x_ref)])
        return res, np.vstack([J, C]), M, stats, m

    def tangent(self, A: np.ndarray, prev: np.ndarray | None) -> np.ndarray:
        _, _, Vt = np.linalg.svd(A)
        t = Vt[-1]
        if prev is not None and float(t @ prev) < 0:
            t = -t
        return t / np.linalg.norm(t)


def _mu(model, M):
    return elastic_multipliers(model, M)[0]


def _correct(prob: _Problem, y0: np.ndarray, t: np.ndarray):
    y = y0.copy()
    for _ in range(NEWTON_ITER):
        r = prob.residual(y)
        if r is None:
            return None
        res, A, M, stats, m = r
        full = np.concatenate([res, [float(t @ (y - y0))]])
        if np.linalg.norm(full) <= NEWTON_TOL * (1 + np.linalg.norm(y)):
            return _Pt(y, M, stats, _mu(m, M)), A
        Aa = np.vstack([A, t[None, :]])
        y = y - np.linalg.lstsq(Aa, full, rcond=1e-12)[0]
    return None


def _tests(pt: _Pt, D: list[float]) -> dict[str, float]:
    from .. import backend as K

    mu = pt.mu
    real = mu.real[np.abs(mu.imag) < 1e-9]
    out = {"pd": float(np.sum(real < -1.0)), "pdv": float(real.min() + 1.0) if real.size else math.nan,
           "ns": float(np.sum((np.abs(mu.imag) > 1e-9) & (np.abs(mu) > 1.0)))}
    for e, d in enumerate(D):
        if d > 0:
            lo, hi = pt.stats[e, K.S_UMIN], pt.stats[e, K.S_UMAX]
            out[f"g{e}_min+"], out[f"g{e}_min-"] = lo - d, lo + d
            out[f"g{e}_max+"], out[f"g{e}_max-"] = hi - d, hi + d
    return out


def system_continuation(model: Any, param: str, start: float, stop: float, n: int = 1,
                        guess: Sequence[float] | None = None, *, dtau: float = DEFAULT_DTAU, accurate: bool = True,
                        ds_max: float | None = None, max_points: int = MAX_POINTS,
                        state0: Sequence[float] | None = None) -> SystemContinuation:
    """Pseudo-arclength continuation of a system's period-n orbits in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    model : SystemModel
    param : str
        A system parameter (``omega``, ``<mesh>.xi0``, ``<mesh>.D``, ...).
    start, stop : float
        The interval (``stop`` may lie below ``start``).
    n : int
        Period of the orbit in forcing periods.
    guess : (2n,) state, optional
        Shooting guess at ``start`` (default: the attractor reached by simulation from ``state0``).
    dtau : float
    accurate : bool
        Accurate integration mode (default: multipliers vary smoothly along the branch).
    ds_max : float, optional
        Largest arclength step in (x, p/|stop − start|); default :data:`DS_MAX`.
    max_points : int
    state0 : (u0, v0) or (2n,), optional

    Returns
    -------
    SystemContinuation

    Raises
    ------
    ModelError
        For incommensurate meshes, a bad interval, or when the first orbit cannot be found.

    References
    ----------
    R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010.
    """
    require_periodic(model, "continuation (shooting on the period map)")
    start, stop = float(start), float(stop)
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ModelError("stop: the interval needs two different finite values (--start, --stop)")
    m0 = model.with_param(param, start)
    model.with_param(param, stop)
    orb = shoot(m0, n, guess, dtau=dtau, accurate=accurate, state0=state0)
    if not orb.converged:
        raise ModelError(f"guess: shooting for the period-{n} orbit at {param} = {start:g} did not converge; "
                         f"give a better --guess")
    span = abs(stop - start)
    prob = _Problem(m0, param, span, n, dtau, accurate, orb.state)
    lo, hi = sorted((start / span, stop / span))
    direction = 1.0 if stop > start else -1.0
    y = np.concatenate([orb.state, [start / span]])
    r = prob.residual(y)
    if r is None:
        raise ModelError(f"guess: the orbit at {param} = {start:g} diverged")
    _, A, M, stats, m = r
    t = prob.tangent(A, None)
    if t[-1] * direction < 0:
        t = -t
    pts = [_Pt(y, M, stats, _mu(m, M), t)]
    bifs: list[dict[str, Any]] = []
    dsm = float(ds_max) if ds_max is not None else DS_MAX
    ds = min(DS_INIT, dsm)
    end = "max points"
    while len(pts) < max_points:
        a = pts[-1]
        got = _correct(prob, a.y + ds * a.t, a.t)
        if got is None:
            ds *= 0.5
            if ds < DS_MIN:
                end = "step too small"
                break
            continue
        b, A = got
        b.t = prob.tangent(A, a.t)
        ds = min(dsm, ds * 1.5)
        pts.append(b)
        _events(a, b, prob, bifs, param, span, len(pts) - 1)
        if not lo - 1e-12 <= b.y[-1] <= hi + 1e-12:
            end = "interval end"
            break
    return _result(model, param, start, stop, n, pts, prob, span, bifs, end)


def _events(a: _Pt, b: _Pt, prob: _Problem, out: list, param: str, span: float, k: int) -> None:
    ta, tb = _tests(a, prob.D), _tests(b, prob.D)

    def add(typ: str, s: float, detail: str) -> None:
        y = (1 - s) * a.y + s * b.y
        mu = b.mu if s > 0.5 else a.mu
        out.append({"type": typ, param: float(y[-1] * span), "period": prob.n * (prob.model.period_multiple() or 1),
                    "branch": 0, "state": [float(v) for v in y[:-1]],
                    "amplitude": float((1 - s) * _amp(a) + s * _amp(b)),
                    "multipliers": [[float(z.real), float(z.imag)] for z in mu], "detail": detail,
                    "located": False, "point": k})

    if a.t[-1] * b.t[-1] < 0:
        s = abs(a.t[-1]) / (abs(a.t[-1]) + abs(b.t[-1]))
        add("fold", s, "real multiplier through +1 at a turning point")
    if ta["pd"] != tb["pd"]:
        fa, fb = ta["pdv"], tb["pdv"]
        s = fa / (fa - fb) if np.isfinite(fa) and np.isfinite(fb) and fa * fb < 0 else 0.5
        add("period-doubling", s, "real multiplier through −1")
    if ta["ns"] != tb["ns"]:
        add("neimark-sacker", 0.5, "complex pair through the unit circle")
    names = list((e.name for e in prob.model.elements))
    for key, va in ta.items():
        if key[0] != "g" or key not in tb:
            continue
        vb = tb[key]
        if va * vb < 0:
            e = int(key[1:key.index("_")])
            side = {"min+": "u_min = +D (contact loss)", "min-": "u_min = −D (back-side contact)",
                    "max+": "u_max = +D", "max-": "u_max = −D"}[key[key.index("_") + 1:]]
            add("grazing", va / (va - vb), f"{names[e]}: {side}")


def _amp(p: _Pt) -> float:
    from .. import backend as K

    return 0.5 * float(p.stats[0, K.S_UMAX] - p.stats[0, K.S_UMIN])


def _result(model, param, start, stop, n, pts, prob, span, bifs, end) -> SystemContinuation:
    from .. import backend as K

    names = [mm.name for mm in model.meshes]
    ref = names.index(model.scaling.reference) if model.scaling.reference in names else 0
    vals = np.array([p.y[-1] * span for p in pts])
    keep = (vals >= min(start, stop) - 1e-12 * span) & (vals <= max(start, stop) + 1e-12 * span)
    keep[0] = True
    sel = [p for p, k in zip(pts, keep) if k]
    for b in bifs:  # amplitudes of the reference mesh
        b["amplitude"] = float(b["amplitude"])
    return SystemContinuation(model, param, start, stop, n, vals[keep], np.array([p.y[:-1] for p in sel]),
                              [p.mu for p in sel], np.array([p.stats[:, K.S_UMIN] for p in sel]),
                              np.array([p.stats[:, K.S_UMAX] for p in sel]),
                              [b for b in bifs if min(start, stop) <= b[param] <= max(start, stop)], end, prob.r, ref)
