"""Parameter sweeps of multi-DOF systems: the bifurcation diagram and the up/down frequency response.

Every point runs on the N-DOF kernel: a fixed-initial-state sweep is one kernel batch (threads over
the points); a continuation sweep (``mode="continue"``) integrates each point from the previous
one's end state, up, down or both, so the response follows a branch and the jumps between the two
directions show the hysteresis.  Per point and per mesh: period, impact state, δ extremes and
amplitude; the Poincaré points of the reference mesh's (δ, δ') and, with ``coordinate``, of any
state coordinate.  The periodic forcing is needed only for the period count (incommensurate
meshes give ``period`` None: the samples are then in the base period).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..integrate_ndof import element_series, integrate_batch, initial_state
from ..model import IntegrationOptions
from .classify import IMPACT_LABELS, detect_period, impact_state, period_label

__all__ = ["system_sweep", "system_response_jumps"]


def _point(model: Any, res: Any, i: int, coordinate: int | None) -> dict[str, Any]:
    ok = bool(res.ok[i])
    pc = res.poincare[i]
    n = detect_period(pc) if ok else -1
    p = model.period_multiple()
    num = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731
    meshes = []
    for e, m in enumerate(model.meshes):
        lo, hi = float(res.element_u_min(e)[i]), float(res.element_u_max(e)[i])
        meshes.append({"name": m.name, "u_min": num(lo), "u_max": num(hi), "amplitude": num(0.5 * (hi - lo)),
                       "impact": IMPACT_LABELS[impact_state(lo, m.D)]})
    ref = meshes[res.reference]
    sec = element_series(model, pc, 0.0)[:, res.reference, 0] if ok else np.zeros(0)
    out = {"period": (n * (p or 1)) if (n > 0 and p) else None, "motion": period_label(n) if ok else "diverged",
           "impact": ref["impact"], "amplitude": ref["amplitude"], "u_min": ref["u_min"], "u_max": ref["u_max"],
           "status": "ok" if ok else "diverged", "meshes": meshes, "poincare_u": [float(x) for x in sec]}
    if coordinate is not None:
        out["poincare_coordinate"] = [float(x) for x in pc[:, coordinate]] if ok else []
    return out


def system_sweep(model: Any, param: str, values: Sequence[float], *, mode: str = "fixed", sweep: str = "up",
                 options: IntegrationOptions = IntegrationOptions(), state0: Sequence[float] | None = None,
                 coordinate: int | None = None, threads: int | None = None) -> dict[str, Any]:
    """A sweep of a system parameter (bifurcation diagram / frequency response).

    Parameters
    ----------
    model : SystemModel
        The system at its base point.
    param : str
        Parameter name (``omega``, ``<mesh>.kappa1``, ...).
    values : sequence of float
        The parameter values, in sweep order.
    mode : {"fixed", "continue"}
        Every point from ``state0`` (default :func:`~geardyn.integrate_ndof.initial_state`), or each
        from the previous point's end state.
    sweep : {"up", "down", "both"}
        Directions of a continuation sweep.
    options : IntegrationOptions
        Transient and recorded periods of every point.
    state0 : (2n,) state, optional
        Initial state of every point (``fixed``) or of the first point (``continue``).
    coordinate : int, optional
        A state coordinate whose Poincaré points are kept as well.
    threads : int, optional
        Kernel threads (default: the integrator's thread policy).

    Returns
    -------
    dict
        ``param``, ``values``, ``mode``, ``sweep`` and per direction the per-point lists ``period``,
        ``motion``, ``impact``, ``amplitude``, ``status`` (of the reference mesh) and ``meshes``
        (per mesh the per-point ``u_min``, ``u_max``, ``amplitude``, ``impact``).
    """
    vals = [float(v) for v in values]
    models = [model.with_param(param, v) for v in vals]
    dirs = {"up": ["up"], "down": ["down"], "both": ["up", "down"]}[sweep] if mode == "continue" else ["up"]
    runs: dict[str, list[dict[str, Any]]] = {}
    for d in dirs:
        order = list(range(len(vals))) if d == "up" else list(range(len(vals)))[::-1]
        pts: list[dict[str, Any] | None] = [None] * len(vals)
        if mode == "fixed":
            s0 = None if state0 is None else np.asarray(state0, float)
            res = integrate_batch(models, s0, options, threads=threads)
            for i in range(len(vals)):
                pts[i] = _point(models[i], res, i, coordinate)
        else:
            x = initial_state(models[order[0]]) if state0 is None else np.asarray(state0, float)
            for i in order:
                res = integrate_batch([models[i]], x, options, threads=threads)
                pts[i] = _point(models[i], res, 0, coordinate)
                if res.ok[0]:
                    x = res.end_state[0]
        runs[d] = pts  # type: ignore[assignment]
    out: dict[str, Any] = {"param": param, "values": vals, "mode": mode, "sweep": dirs[0] if len(dirs) == 1 else dirs}
    for key in ("period", "motion", "impact", "amplitude", "status", "u_min", "u_max"):
        per = {d: [p[key] for p in runs[d]] for d in dirs}
        out[key] = per[dirs[0]] if len(dirs) == 1 else per
    meshes = []
    for e, m in enumerate(model.meshes):
        entry: dict[str, Any] = {"name": m.name}
        for key in ("u_min", "u_max", "amplitude", "impact"):
            per = {d: [p["meshes"][e][key] for p in runs[d]] for d in dirs}
            entry[key] = per[dirs[0]] if len(dirs) == 1 else per
        meshes.append(entry)
    out["meshes"] = meshes
    out["poincare_u"] = {d: [p["poincare_u"] for p in runs[d]] for d in dirs}
    if coordinate is not None:
        out["poincare_coordinate"] = {d: [p["poincare_coordinate"] for p in runs[d]] for d in dirs}
    return out


def system_response_jumps(sw: dict[str, Any], measure: str = "amplitude", rel: float = 0.25) -> list[dict[str, Any]]:
    """Jumps of a continuation sweep: neighbouring ω where the measure changes by more than ``rel`` of its range.

    Parameters
    ----------
    sw : dict
        A :func:`system_sweep` result (``values`` and the per-direction series of ``measure``).
    measure : {"amplitude", "u_min", "u_max"}
        The reference-mesh quantity compared between neighbours.
    rel : float
        Threshold as a fraction of the measure's range over the sweep (per direction).

    Returns
    -------
    list of dict
        One entry per jump, in sweep order: ``omega`` (midpoint of the two values), ``direction``
        (``up`` or ``down``) and ``size`` (signed change of the measure).
    """
    vals = sw["values"]
    out = []
    series = sw[measure] if isinstance(sw[measure], dict) else {sw["sweep"]: sw[measure]}
    for d, ys in series.items():
        y = np.array([np.nan if v is None else v for v in ys], float)
        span = np.nanmax(y) - np.nanmin(y) if np.any(np.isfinite(y)) else 0.0
        idx = range(len(y) - 1) if d == "up" else range(len(y) - 1, 0, -1)
        for i in idx:
            j = i + 1 if d == "up" else i - 1
            if np.isfinite(y[i]) and np.isfinite(y[j]) and abs(y[j] - y[i]) > rel * max(span, 1e-300):
                out.append({"omega": 0.5 * (vals[i] + vals[j]), "direction": d, "size": float(y[j] - y[i])})
    return out
