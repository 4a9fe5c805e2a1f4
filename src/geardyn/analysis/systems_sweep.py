"""Parameter sweeps of multi-DOF systems: the bifurcation diagram and the up/down frequency response.

Every point runs on the N-DOF kernel through the sweep engine (:func:`geardyn.sweep.run_chunks`:
local workers, a Dask scheduler, checkpoints and resume).  A fixed-initial-state sweep is cut into
chunks of points (each chunk one kernel batch); a continuation sweep (``mode="continue"``)
integrates each point from the previous one's end state, so each direction (up, down) is one
chunk and the two directions run side by side on two workers.  The chunk functions are
module-level and return compact arrays (per point: status, the full-state Poincaré points, the
element statistics and the end state).

The result is an :class:`xarray.Dataset` of kind ``system_bifurcation`` (or ``system_response``)
with the layout of the 1-DOF bifurcation Dataset along the reference mesh — dimensions ``sweep``,
the parameter and ``section``; ``poincare_u``/``poincare_v`` (the reference mesh's δ, δ'),
``period``, ``motion``, ``impact``, ``amplitude``, ``mean``, ``u_min``, ``u_max``, ``status`` —
plus per-mesh variables over a ``mesh`` dimension (``mesh_u_min``, ``mesh_u_max``,
``mesh_amplitude``, ``mesh_impact``), so the jumps and the hysteresis intervals are found by the
1-DOF response's functions (:func:`geardyn.analysis.response.detect_jumps`,
:func:`~geardyn.analysis.response.hysteresis_intervals`, which compare attractors through
:mod:`geardyn.analysis.attractors`).  Incommensurate meshes give ``period`` 0 (not periodic: the
samples are then in the base period only).
"""

from __future__ import annotations

import json
from typing import Any, Sequence

import numpy as np
import xarray as xr

from .._docfill import SYSTEM, fill, parameters, result_of
from ..grid import Grid, build_models
from ..integrate import integrate_batch
from ..io import system_attrs
from ..model import IntegrationOptions
from .bifurcation import sweep_summary
from .classify import IMPACT_LABELS, MOTION_DIVERGED, MOTION_PERIODIC, MOTION_UNRESOLVED, detect_period, \
    impact_state, period_label

__all__ = ["system_sweep", "system_sweep_dataset", "sweep_json", "system_response_jumps", "points_chunk",
           "continue_chunk", "point_rows"]

#: Points per chunk of a fixed-initial-state system sweep.
SYSTEM_CHUNK_POINTS = 16


def point_rows(models: list[Any], res: Any) -> dict[str, np.ndarray]:
    """The compact per-point arrays of a kernel batch (what a chunk returns).

    Parameters
    ----------
    models : list of SystemModel
    res : BatchResult

    Returns
    -------
    dict of ndarray
        ``status``, ``poincare``, ``end_state``, ``u_min``, ``u_max``, ``mean``, ``rms``, ``fractions``.
    """
    return {"status": np.asarray(res.status, dtype=np.int64), "poincare": res.poincare,
            "end_state": res.end_state, "u_min": res.element_u_min(), "u_max": res.element_u_max(),
            "mean": res.element_mean(), "rms": res.element_rms(), "fractions": res.element_fractions()}


#: Docstring entries of the chunk functions.
_CHUNK = (SYSTEM, "param : str\n    The swept parameter.",
          "values : ndarray\n    Its values at the chunk's points.",
          "options : IntegrationOptions\n    Integration settings of every point.")


def points_chunk(model: Any, names: Sequence[str], points: np.ndarray, state0: np.ndarray | None,
                 options: IntegrationOptions) -> dict[str, np.ndarray]:
    """Chunk function: parameter points (:meth:`geardyn.grid.Grid.points`), each from ``state0`` (default per point).

    Parameters
    ----------
    model : System
        The base system.
    names : sequence of str
        The grid's parameter names (columns of ``points``).
    points : ndarray (P, len(names))
    state0 : ndarray (2n,) or None
        Start of every point (default ``model.initial_state`` of each).
    options : IntegrationOptions
        Integration settings of every point.

    Returns
    -------
    dict of ndarray
        :func:`point_rows`.
    """
    models = build_models(model, names, points)
    return point_rows(models, integrate_batch(models, state0, options, threads=1))


@fill(*_CHUNK)
def continue_chunk(model: Any, param: str, values: np.ndarray, state0: np.ndarray | None,
                   options: IntegrationOptions) -> dict[str, np.ndarray]:
    """Chunk function: the points ``values`` in their order, each from the previous point's end state.

    Parameters
    ----------
    {{model, param, values}}
    state0 : ndarray (2n,) or None
        Start of the first point (default ``model.initial_state``).
    {{options}}

    Returns
    -------
    dict of ndarray
        :func:`point_rows`.
    """
    x = None if state0 is None else np.asarray(state0, float)
    rows: list[dict[str, np.ndarray]] = []
    for m in build_models(model, [param], np.asarray(values, float)[:, None]):
        s = m.initial_state() if x is None else x
        res = integrate_batch([m], s, options, threads=1)
        rows.append(point_rows([m], res))
        if res.ok[0]:
            x = res.end_state[0]
    return {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}


def _engine(engine: dict[str, Any] | None) -> dict[str, Any]:
    e = dict(engine or {})
    e.setdefault("progress", False)
    return e


def _per_point(model: Any, rows: dict[str, np.ndarray], ref: int) -> dict[str, np.ndarray]:
    """Reference-mesh and per-mesh variables of stacked chunk rows (P points)."""
    P = rows["status"].shape[0]
    M = len(model.meshes)
    ok = rows["status"] == 0
    p = model.period_multiple()
    period = np.zeros(P, np.int64)
    motion = np.full(P, MOTION_UNRESOLVED, np.int64)
    pu = np.full((P, rows["poincare"].shape[1]), np.nan)
    pv = np.full_like(pu, np.nan)
    for i in range(P):
        if not ok[i]:
            period[i], motion[i] = -1, MOTION_DIVERGED
            continue
        d = model.element_series(rows["poincare"][i], 0.0)[:, ref]
        pu[i], pv[i] = d[:, 0], d[:, 1]
        n = detect_period(rows["poincare"][i]) if p else 0
        if n > 0:
            period[i], motion[i] = n * p, MOTION_PERIODIC
    lo, hi = rows["u_min"][:, :M], rows["u_max"][:, :M]
    imp = np.array([[impact_state(lo[i, e], model.meshes[e].D) if ok[i] else -1 for e in range(M)]
                    for i in range(P)], np.int64).reshape(P, M)
    return {"period": period, "motion": motion, "poincare_u": pu, "poincare_v": pv, "status": rows["status"],
            "mesh_u_min": lo, "mesh_u_max": hi, "mesh_amplitude": 0.5 * (hi - lo), "mesh_impact": imp,
            "mesh_mean": rows["mean"][:, :M], "mesh_rms": rows["rms"][:, :M], "end_state": rows["end_state"]}


_MESH_LONG = {"mesh_u_min": "smallest deflection δ of the mesh", "mesh_u_max": "largest deflection δ of the mesh",
              "mesh_amplitude": "half peak-to-peak deflection δ of the mesh",
              "mesh_impact": "impact state of the mesh (0 none, 1 single-sided, 2 double-sided)",
              "mesh_mean": "mean deflection δ of the mesh", "mesh_rms": "RMS of δ of the mesh about its mean"}


def system_sweep_dataset(model: Any, param: str, values: Sequence[float], runs: dict[str, dict[str, np.ndarray]],
                         *, mode: str, options: IntegrationOptions, kind: str = "system_bifurcation",
                         coordinate: int | None = None) -> xr.Dataset:
    """The Dataset of a system sweep from the stacked chunk rows of each direction (in grid order).

    Parameters
    ----------
    model : SystemModel
    param : str
    values : sequence of float
    runs : dict
        Direction label → :func:`point_rows` arrays over the grid.
    mode : str
    options : IntegrationOptions
    kind : str
    coordinate : int, optional

    Returns
    -------
    xarray.Dataset
    """
    from ..io import annotate

    ref = model.reference
    dirs = list(runs)
    per = {d: _per_point(model, runs[d], ref) for d in dirs}
    st = lambda k: np.stack([per[d][k] for d in dirs])  # noqa: E731
    meshes = [m.name for m in model.meshes]
    dv: dict[str, Any] = {
        "poincare_u": (("sweep", param, "section"), st("poincare_u")),
        "poincare_v": (("sweep", param, "section"), st("poincare_v")),
        "period": (("sweep", param), st("period")),
        "motion": (("sweep", param), st("motion")),
        "status": (("sweep", param), st("status")),
        "impact": (("sweep", param), st("mesh_impact")[:, :, ref]),
        "u_min": (("sweep", param), st("mesh_u_min")[:, :, ref]),
        "u_max": (("sweep", param), st("mesh_u_max")[:, :, ref]),
        "amplitude": (("sweep", param), st("mesh_amplitude")[:, :, ref]),
        "mean": (("sweep", param), st("mesh_mean")[:, :, ref]),
        "rms": (("sweep", param), st("mesh_rms")[:, :, ref]),
        "end_state": (("sweep", param, "state"), st("end_state")),
    }
    for k in _MESH_LONG:
        dv[k] = (("sweep", param, "mesh"), st(k))
    if coordinate is not None:
        dv["poincare_coordinate"] = (("sweep", param, "section"),
                                     np.stack([runs[d]["poincare"][:, :, coordinate] for d in dirs]))
    ds = xr.Dataset(dv, coords={"sweep": dirs, param: np.asarray(values, float), "mesh": meshes,
                                "state": [f"{lab}" for lab in model.labels] + [f"{lab}'" for lab in model.labels],
                                "section": np.arange(st("poincare_u").shape[-1])},
                    attrs=system_attrs(model, kind, options, {"param": param, "mode": mode}))
    return annotate(ds)


def system_sweep(model: Any, param: str, values: Sequence[float], *, mode: str = "fixed", sweep: str = "up",
                 options: IntegrationOptions = IntegrationOptions(), state0: Sequence[float] | None = None,
                 coordinate: int | None = None, engine: dict[str, Any] | None = None,
                 kind: str = "system_bifurcation") -> xr.Dataset:
    """A sweep of a system parameter (bifurcation diagram / frequency response) on the sweep engine.

    Parameters
    ----------
    model : SystemModel
    param : str
        Parameter name (``omega``, ``<mesh>.kappa1``, ...; spelled as :func:`geardyn.grid.param_name`).
    values : sequence of float
        Its values (sorted, as :meth:`geardyn.grid.Grid.range`).
    mode : {"fixed", "continue"}
        Every point from ``state0`` (default ``model.initial_state`` of each
        point), or each from the previous point's end state.
    sweep : {"up", "down", "both"}
        Directions of a continuation sweep.
    options : IntegrationOptions
    state0 : (2n,) state, optional
    coordinate : int, optional
        A state coordinate whose Poincaré points are kept as well (``poincare_coordinate``).
    engine : dict, optional
        Keywords of :func:`geardyn.sweep.run_chunks` (``workers``, ``scheduler``, ``checkpoint``,
        ``resume``, ``progress``).
    kind : str
        ``geardyn_kind`` of the Dataset.

    Returns
    -------
    xarray.Dataset
        See the module docstring.
    """
    from ..sweep import Chunk, run_chunks

    grid = Grid.range(param, values)
    param = grid.names[0]
    vals = grid.values(param)
    grid.check(model)
    s0 = None if state0 is None else np.asarray(state0, float)
    if mode == "fixed":
        dirs = ["fixed"]
        sl = grid.slices(SYSTEM_CHUNK_POINTS)
        chunks = [Chunk(i, points_chunk, (model, grid.names, grid.points(s), s0, options)) for i, s in enumerate(sl)]
        res = run_chunks(chunks, description=f"system {param}", **_engine(engine))
        runs = {"fixed": {k: np.concatenate([r[k] for r in res]) for k in res[0]}}
    else:
        dirs = {"up": ["up"], "down": ["down"], "both": ["up", "down"]}[sweep]
        chunks = [Chunk(i, continue_chunk, (model, param, vals if d == "up" else vals[::-1], s0, options))
                  for i, d in enumerate(dirs)]
        res = run_chunks(chunks, description=f"system {param}", **_engine(engine))
        runs = {}
        for d, r in zip(dirs, res):
            runs[d] = r if d == "up" else {k: v[::-1] for k, v in r.items()}
    return system_sweep_dataset(model, param, vals, runs, mode=mode, options=options, kind=kind, coordinate=coordinate)


def _labels(ds: xr.Dataset, d: str) -> dict[str, list[Any]]:
    per = ds["period"].sel(sweep=d).values
    mot = ds["motion"].sel(sweep=d).values
    motion = [period_label(int(p)) if m == MOTION_PERIODIC else ("diverged" if m == MOTION_DIVERGED else "unresolved")
              for p, m in zip(per, mot)]
    return {"period": [int(p) if p > 0 else None for p in per], "motion": motion,
            "impact": [IMPACT_LABELS[int(c)] for c in ds["impact"].sel(sweep=d).values],
            "status": ["ok" if s == 0 else "diverged" for s in ds["status"].sel(sweep=d).values]}


@parameters(result_of("system_sweep"))
def sweep_json(ds: xr.Dataset) -> dict[str, Any]:
    """The JSON summary of a system sweep: ``param``, ``values``, per point (per direction for two)
    ``period``, ``motion``, ``impact``, ``amplitude``, ``u_min``, ``u_max``, ``status`` of the
    reference mesh, ``meshes`` (per mesh ``name``, ``u_min``, ``u_max``, ``amplitude``, ``impact``,
    ``dynamic_factor`` None: the sweeps keep no histories) and ``poincare_u``.

    Returns
    -------
    dict
    """
    num = lambda a: [float(x) if np.isfinite(x) else None for x in np.asarray(a, float)]  # noqa: E731
    out, pick = sweep_summary(ds, num)
    dirs = [str(s) for s in ds["sweep"].values]
    lab = {d: _labels(ds, d) for d in dirs}
    for k in ("period", "motion", "impact", "status"):
        out[k] = pick(lambda d: lab[d][k])
    for k in ("amplitude", "u_min", "u_max"):
        out[k] = pick(lambda d: num(ds[k].sel(sweep=d).values))
    meshes = []
    for e, name in enumerate(ds["mesh"].values):
        entry: dict[str, Any] = {"name": str(name)}
        for k in ("u_min", "u_max", "amplitude"):
            entry[k] = pick(lambda d: num(ds[f"mesh_{k}"].sel(sweep=d).values[:, e]))
        entry["impact"] = pick(lambda d: [IMPACT_LABELS[int(c)] for c in ds["mesh_impact"].sel(sweep=d).values[:, e]])
        entry["dynamic_factor"] = None
        meshes.append(entry)
    out["meshes"] = meshes
    out["poincare_u"] = {d: [[float(x) for x in row if np.isfinite(x)] for row in ds["poincare_u"].sel(sweep=d).values]
                         for d in dirs}
    if "poincare_coordinate" in ds:
        out["poincare_coordinate"] = {d: [[float(x) for x in row if np.isfinite(x)]
                                          for row in ds["poincare_coordinate"].sel(sweep=d).values] for d in dirs}
    return out


def system_response_jumps(ds: xr.Dataset, measure: str = "amplitude") -> tuple[list[dict[str, Any]], list[list[float]]]:
    """Jumps and hysteresis intervals of an up/down system sweep (the 1-DOF response's tests on the reference mesh).

    Parameters
    ----------
    ds : xarray.Dataset
        A two-direction :func:`system_sweep` result.
    measure : str

    Returns
    -------
    jumps : list of dict
        As :func:`geardyn.analysis.response.detect_jumps`.
    hysteresis : list of [float, float]
        As :func:`geardyn.analysis.response.hysteresis_intervals` (attractors compared by their
        Poincaré cycles, :mod:`geardyn.analysis.attractors`).
    """
    from .response import detect_jumps, hysteresis_intervals

    return detect_jumps(ds, measure), hysteresis_intervals(ds)
