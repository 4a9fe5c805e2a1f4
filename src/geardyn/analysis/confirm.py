"""Classification that respects F1: a longer exponent run or shooting decides the doubtful labels.

The divergence of the pair's vector field is −2c(θ) whatever the state, so the period map
contracts every area by the same factor exp(−4πξ0/ω) < 1 for ξ0 > 0 (F1; for any System of a planar
state: its :meth:`~geardyn.system.System.mean_trace` < 0, which is −2ξ0 for the pair).  A planar map that
shrinks every area has no invariant closed curve (the disc it bounds would be mapped onto itself
with a smaller area), hence no quasi-periodic attractor.  A sweep's label is therefore re-examined
where it can be wrong:

- **quasi-periodic, unresolved, or λ1 near zero** (|λ1| ≤ :data:`NEAR_ZERO`): a run of
  :data:`LONG_PERIODS` further periods with exponents from the end state decides: periodic if its
  section is, chaotic if λ1 is significantly positive; otherwise shooting from the section points
  (periods 1 … :data:`SHOOT_MAX_PERIOD`) looks for a stable orbit; what is left is unresolved,
  never quasi-periodic (for ξ0 > 0, the pair's contracting map);
- **period-2n**: shooting for period n from the section points; a stable period-n orbit wins (a
  slowly converging period-n orbit next to its flip looks period-2n after a short transient).

:func:`confirm_point` judges one point, :func:`confirm_sweep` every point of a bifurcation-like
Dataset (any sweep with ``motion``, ``period``, ``lle``, ``lle_err``, ``end_state`` and the
Poincaré points), so the same rules serve every sweep.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from ..integrate import integrate_batch
from ..model import IntegrationOptions
from .classify import (
    MOTION_CHAOTIC,
    MOTION_PERIODIC,
    MOTION_QUASIPERIODIC,
    MOTION_UNRESOLVED,
)
from .periodic.orbit import shoot
from .steady import classify_batch

__all__ = [
    "CONFIRM_LABELS",
    "LONG_PERIODS",
    "NEAR_ZERO",
    "SHOOT_MAX_PERIOD",
    "confirm_point",
    "confirm_sweep",
    "needs_confirmation",
]

#: Periods of the longer exponent run.
LONG_PERIODS = 3000
#: |λ1| below this (per unit τ) is "near zero": the label is re-examined.
NEAR_ZERO = 0.01
#: Shooting tries periods 1 … this for a point whose longer run decided nothing.
SHOOT_MAX_PERIOD = 8
#: Codes of the ``confirmed`` variable: what decided a point's label.
CONFIRM_NONE, CONFIRM_LONG, CONFIRM_SHOOT, CONFIRM_HALVED = 0, 1, 2, 3
CONFIRM_LABELS = {
    CONFIRM_NONE: "sweep label kept",
    CONFIRM_LONG: "longer exponent run",
    CONFIRM_SHOOT: "stable orbit by shooting",
    CONFIRM_HALVED: "stable period-n orbit of a period-2n label",
}


def needs_confirmation(motion: int, period: int, lle: float) -> bool:
    """Whether a sweep's label is re-examined (see the module docstring).

    Parameters
    ----------
    motion, period : int
        The sweep's motion code and period.
    lle : float
        Its largest exponent (NaN when not computed).

    Returns
    -------
    bool
    """
    if motion == MOTION_PERIODIC:
        return period >= 2 and period % 2 == 0
    if motion in (MOTION_QUASIPERIODIC, MOTION_UNRESOLVED):
        return True
    return motion == MOTION_CHAOTIC and np.isfinite(lle) and abs(lle) <= NEAR_ZERO


def _stable_orbit(model: Any, n: int, guesses: Sequence[np.ndarray]) -> int:
    """The minimal period of a stable period-n orbit shot from one of ``guesses``, or 0."""
    for g in guesses:
        if not np.all(np.isfinite(g)):
            continue
        orb = shoot(model, n, guess=np.asarray(g, dtype=float))
        if orb.converged and orb.stable:
            return int(orb.minimal_period)
    return 0


def confirm_point(
    model: Any,
    end_state: Sequence[float],
    section: np.ndarray,
    motion: int,
    period: int,
    lle: float,
    lle_err: float,
    *,
    long_periods: int = LONG_PERIODS,
) -> dict[str, Any]:
    """Re-examine one point's label (see the module docstring).

    Parameters
    ----------
    model : System
        The point's model.
    end_state : sequence of float
        Its full state at the end of the sweep's run (θ ≡ 0).
    section : ndarray (m, 2)
        Its recorded Poincaré points: the reference element's (δ, δ') (the pair's state); shooting starts
        from the states :meth:`~geardyn.system.System.initial_state` gives them.
    motion, period : int
        The sweep's label.
    lle, lle_err : float
        The sweep's largest exponent and its standard error.
    long_periods : int
        Periods of the longer exponent run.

    Returns
    -------
    dict
        ``motion``, ``period``, ``lle``, ``lle_err`` (the decided label) and ``confirmed`` (a code
        of :data:`CONFIRM_LABELS`).
    """
    out = {
        "motion": int(motion),
        "period": int(period),
        "lle": float(lle),
        "lle_err": float(lle_err),
        "confirmed": CONFIRM_NONE,
    }
    if not needs_confirmation(motion, period, lle):
        return out
    pts = np.array([model.initial_state(u, v) for u, v in np.asarray(section, dtype=float).reshape(-1, 2)])
    pts = pts.reshape(-1, model.state_dim)
    if motion == MOTION_PERIODIC:
        p = int(period)
        while p >= 2 and p % 2 == 0:
            found = _stable_orbit(model, p // 2, pts[: p // 2][::-1])
            if found == 0 or found >= p:
                break
            p = found
        if p != period:
            out.update(period=p, confirmed=CONFIRM_HALVED)
        return out
    res = integrate_batch(
        [model], np.asarray(end_state, float), IntegrationOptions(transient=0, periods=long_periods), lyapunov=True
    )
    c = classify_batch(res, settle_periods=0)
    lam, err = float(c["lle"][0]), float(c["lle_err"][0])
    out.update(lle=lam, lle_err=err, confirmed=CONFIRM_LONG)
    if int(c["period"][0]) > 0:
        out.update(motion=MOTION_PERIODIC, period=int(c["period"][0]))
        return out
    if int(c["motion"][0]) == MOTION_CHAOTIC:  # λ1 significantly positive
        out.update(motion=MOTION_CHAOTIC, period=0)
        return out
    last = np.asarray(c["poincare"][0], dtype=float)
    for n in range(1, SHOOT_MAX_PERIOD + 1):
        found = _stable_orbit(model, n, [last[-1]])
        if found:
            out.update(motion=MOTION_PERIODIC, period=found, confirmed=CONFIRM_SHOOT)
            return out
    # F1: a planar map that contracts every area (mean trace < 0: ξ0 > 0 for the pair) has no quasi-periodic
    # attractor; what neither test decided stays unresolved
    planar_contracting = model.state_dim == 2 and model.mean_trace() < 0
    out.update(motion=MOTION_UNRESOLVED if planar_contracting else int(motion), period=0)
    return out


def confirm_sweep(ds: xr.Dataset, model: Any, param: str, *, long_periods: int = LONG_PERIODS) -> xr.Dataset:
    """Every doubtful label of a one-parameter sweep re-examined by :func:`confirm_point`.

    Parameters
    ----------
    ds : xarray.Dataset
        A bifurcation-like result over ``param`` (dims ``sweep``, ``param``).
    model : System
        Its base model (``param`` set at each point).
    param : str
        The swept parameter.
    long_periods : int
        Periods of the longer exponent run.

    Returns
    -------
    xarray.Dataset
        A copy with ``motion``, ``period``, ``lle`` and ``lle_err`` decided, the sweep's labels kept
        as ``motion_sweep`` and ``period_sweep``, and ``confirmed`` (codes of :data:`CONFIRM_LABELS`).
    """
    out = ds.copy(deep=True)
    x = ds[param].values
    motion = ds["motion"].values.astype(int)
    period = ds["period"].values.astype(int)
    lle, err = (ds[k].values.astype(float) if k in ds else np.full(motion.shape, np.nan) for k in ("lle", "lle_err"))
    sweep = {"motion": motion, "period": period, "lle": lle, "lle_err": err}  # the sweep's label of each point
    new = {k: v.copy() for k, v in sweep.items()}
    code = np.zeros(motion.shape, dtype=np.int64)
    pu, pv = ds["poincare_u"].values, ds["poincare_v"].values
    end = ds["end_state"].values
    for s, i in np.ndindex(motion.shape):
        if not needs_confirmation(motion[s, i], period[s, i], lle[s, i]):
            continue
        point = model.with_param(param, float(x[i]))
        section = np.column_stack([pu[s, i], pv[s, i]])
        r = confirm_point(point, end[s, i], section, *(v[s, i] for v in sweep.values()), long_periods=long_periods)
        for k in new:
            new[k][s, i] = r[k]
        code[s, i] = r["confirmed"]
    dims = ds["motion"].dims
    out["motion_sweep"] = (dims, motion)
    out["period_sweep"] = (dims, period)
    for k, v in new.items():
        out[k] = (dims, v, ds[k].attrs if k in ds else {})
    out["confirmed"] = (
        dims,
        code,
        {
            "long_name": "what decided the label",
            "flag_values": list(CONFIRM_LABELS),
            "flag_meanings": "kept longer_run shooting halved",
        },
    )
    out.attrs["confirm"] = (
        f"labels re-examined (F1): longer run of {long_periods} periods, shooting up to period "
        f"{SHOOT_MAX_PERIOD}, period-2n labels halved when a stable period-n orbit is found"
    )
    return out
