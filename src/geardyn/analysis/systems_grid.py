"""Two-dimensional studies of multi-DOF systems: parameter maps and basins of attraction.

:func:`system_map` sweeps two system parameters (every point from the same initial state) and
:func:`system_basins` a grid over a 2-D slice of the state space — two chosen coordinates of the
state (q̃, q̃') at θ = 0, the others those of ``model.initial_state`` — each
start labelled by the attractor it reaches (:func:`geardyn.analysis.attractors.identify_attractors`
on the full-state Poincaré cycles).  Both run on the sweep engine (module-level chunk functions of
:mod:`geardyn.analysis.systems_sweep`) and give Datasets with the 1-DOF layouts (kinds
``system_map``, ``system_basins``) plus per-mesh variables.
"""

from __future__ import annotations

import json
from typing import Any, Sequence

import numpy as np
import xarray as xr

from ..errors import ModelError
from ..grid import Grid, chunked
from ..io import system_attrs
from ..model import IntegrationOptions
from .systems_sweep import SYSTEM_CHUNK_POINTS, _MESH_LONG, _engine, _per_point, continue_chunk, point_rows, \
    points_chunk

__all__ = ["system_map", "system_basins", "basin_chunk", "coordinate_index", "grid_json"]


def coordinate_index(model: Any, name: str) -> int:
    """Index in the state (q̃, q̃') of a coordinate: a DOF label (q̃), ``label'`` (its rate) or an integer.

    Parameters
    ----------
    model : SystemModel
        The system whose state is indexed.
    name : str
        The coordinate: ``x``, ``x'`` for a DOF label x, or an index into the state.

    Returns
    -------
    int
        Its index in the state vector (the rate of DOF i is at n + i).

    Raises
    ------
    ModelError
        For an unknown coordinate.
    """
    labels = list(model.labels)
    s = str(name).strip()
    if s in labels:
        return labels.index(s)
    if s.endswith("'") and s[:-1] in labels:
        return model.n + labels.index(s[:-1])
    try:
        i = int(s)
    except ValueError:
        raise ModelError(f"coordinates: unknown coordinate {s!r}; the system's are {', '.join(labels)} and their "
                         f"rates {', '.join(lab + chr(39) for lab in labels)} (or indices 0..{2 * model.n - 1})") from None
    if not 0 <= i < 2 * model.n:
        raise ModelError(f"coordinates: index {i} out of range 0..{2 * model.n - 1}")
    return i


def basin_chunk(model: Any, states: np.ndarray, options: IntegrationOptions) -> dict[str, np.ndarray]:
    """Chunk function: one system point, many initial states.

    Parameters
    ----------
    model : SystemModel
    states : ndarray (P, 2n)
    options : IntegrationOptions

    Returns
    -------
    dict of ndarray
        :func:`~geardyn.analysis.systems_sweep.point_rows`.
    """
    from ..integrate import integrate_batch

    return point_rows([model] * len(states), integrate_batch([model] * len(states), states, options, threads=1))


def _run(fn, args: list[tuple], engine: dict[str, Any] | None, what: str) -> dict[str, np.ndarray]:
    """The rows of the chunks ``fn(*a)`` for ``a`` in ``args``, run on the sweep engine, in chunk order."""
    from ..sweep import Chunk, run_chunks

    res = run_chunks([Chunk(i, fn, a) for i, a in enumerate(args)], description=what, **_engine(engine))
    return {k: np.concatenate([r[k] for r in res]) for k in res[0]}


def _mesh_vars(per: dict[str, np.ndarray], dims: tuple[str, ...], shape: tuple[int, ...], ref: int) -> dict[str, Any]:
    M = per["mesh_u_min"].shape[1]
    out: dict[str, Any] = {k: (dims + ("mesh",), per[k].reshape(shape + (M,))) for k in _MESH_LONG}
    for k, src in (("u_min", "mesh_u_min"), ("u_max", "mesh_u_max"), ("amplitude", "mesh_amplitude"),
                   ("mean", "mesh_mean"), ("impact", "mesh_impact")):
        out[k] = (dims, per[src][:, ref].reshape(shape))
    for k in ("period", "motion", "status"):
        out[k] = (dims, per[k].reshape(shape))
    return out


def system_map(model: Any, xname: str, xvalues: Sequence[float], yname: str, yvalues: Sequence[float], *,
               mode: str = "fixed", options: IntegrationOptions = IntegrationOptions(),
               state0: Sequence[float] | None = None, engine: dict[str, Any] | None = None) -> xr.Dataset:
    """A 2-D parameter map of a system: period, motion, impact and amplitudes per (y, x) point.

    Parameters
    ----------
    model : SystemModel
    xname, yname : str
        System parameter names (``omega``, ``<mesh>.xi0``, ...; spelled as :func:`geardyn.grid.param_name`).
    xvalues, yvalues : sequence of float
        Their values (sorted, as the axes of :meth:`geardyn.grid.Grid.product`).
    mode : {"fixed", "continue"}
        ``fixed``: every point from ``state0``; ``continue``: along each row (x increasing) every
        point from the end state of its left neighbour, the first from ``state0`` (one chunk per
        row, rows in parallel), as the 1-DOF map's ``continue`` mode.
    options : IntegrationOptions
    state0 : (2n,), optional
        Initial state of every point, or of every row's first point (default
        ``model.initial_state`` of each).
    engine : dict, optional
        Keywords of :func:`geardyn.sweep.run_chunks`.

    Returns
    -------
    xarray.Dataset
        Kind ``system_map``, dimensions (``yname``, ``xname``) and ``mesh``.
    """
    from ..io import annotate

    if mode not in ("fixed", "continue"):
        raise ModelError(f"mode: must be one of fixed, continue, got {mode!r}")
    grid = Grid.product((yname, yvalues), (xname, xvalues))  # x fastest
    yname, xname = grid.names
    yv, xv = grid.values(yname), grid.values(xname)
    grid.check(model)
    s0 = None if state0 is None else np.asarray(state0, float)
    if mode == "fixed":
        rows = _run(points_chunk, [(model, grid.names, grid.points(s), s0, options)
                                   for s in grid.slices(SYSTEM_CHUNK_POINTS)], engine, "system map")
    else:
        rows = _run(continue_chunk, [(m, xname, xv, s0, options) for m in Grid.range(yname, yv).models(model)],
                    engine, "system map (continued rows)")
    per = _per_point(model, rows, model.reference)
    dims = (yname, xname)
    ds = xr.Dataset(_mesh_vars(per, dims, (yv.size, xv.size), model.reference),
                    coords={yname: yv, xname: xv, "mesh": [m.name for m in model.meshes]},
                    attrs=system_attrs(model, "system_map", options, {"x": xname, "y": yname, "mode": mode}))
    ds["lle"] = (dims, np.full((yv.size, xv.size), np.nan))
    return annotate(ds)


def system_basins(model: Any, coords: tuple[int, int], a_range: tuple[float, float], b_range: tuple[float, float],
                  na: int, nb: int, *, options: IntegrationOptions = IntegrationOptions(periods=64),
                  engine: dict[str, Any] | None = None, base_state: Sequence[float] | None = None) -> xr.Dataset:
    """Basins of attraction of a system over a 2-D slice of its state space at θ = 0.

    Parameters
    ----------
    model : SystemModel
    coords : (int, int) or None
        The two state coordinates varied (:func:`coordinate_index`); ``None``: the reference mesh's
        (δ, δ') through ``model.initial_state`` (the 1-DOF basins' (u0, v0)).
    a_range, b_range : (float, float)
        Their ranges (non-dimensional q̃ or q̃').
    na, nb : int
        Grid points along each.
    options : IntegrationOptions
        Transient and recorded periods (>= 2 × the largest period detected).
    engine : dict, optional
        Keywords of :func:`geardyn.sweep.run_chunks`.
    base_state : (2n,), optional
        The other coordinates (default ``model.initial_state``).

    Returns
    -------
    xarray.Dataset
        Kind ``system_basins``: dimensions ``v0`` (second coordinate), ``u0`` (first) with
        ``attractor``, ``period``, ``motion``, ``impact``, ``amplitude``, ``status``, and the
        attractor table of :func:`geardyn.analysis.basins.basins` (cycle points of the reference
        mesh's δ, δ').
    """
    from ..io import annotate
    from .attractors import identify_attractors

    i, j = coords if coords is not None else (-1, -2)
    if i == j:
        raise ModelError("coordinates: give two different coordinates for the basin slice")
    a = np.linspace(float(a_range[0]), float(a_range[1]), int(na))
    b = np.linspace(float(b_range[0]), float(b_range[1]), int(nb))
    if coords is None:  # the reference mesh's (δ, δ') at θ = 0, the 1-DOF model's (u0, v0)
        states = np.array([model.initial_state(float(u), float(v)) for v in b for u in a])
    else:
        base = model.initial_state() if base_state is None else np.asarray(base_state, float)
        states = np.tile(base, (a.size * b.size, 1))
        states[:, i] = np.tile(a, b.size)
        states[:, j] = np.repeat(b, a.size)
    rows = _run(basin_chunk, [(model, states[s], options) for s in chunked(len(states), SYSTEM_CHUNK_POINTS)],
                engine, "system basins")
    ref = model.reference
    per = _per_point(model, rows, ref)
    ok = per["status"] == 0
    sec = model.element_series(rows["poincare"], 0.0)[:, :, ref]  # (P, m, 2): the reference mesh's δ, δ'
    ident = {"period": np.where(per["period"] > 0, per["period"] // max(model.period_multiple() or 1, 1), 0),
             "motion": per["motion"], "status": per["status"], "amplitude": per["mesh_amplitude"][:, ref],
             "mean": per["mesh_mean"][:, ref], "u_min": per["mesh_u_min"][:, ref],
             "u_max": per["mesh_u_max"][:, ref], "poincare": np.where(ok[:, None, None], sec, np.nan)}
    labels, atts = identify_attractors(ident)
    shape = (b.size, a.size)
    dims = ("v0", "u0")
    data = _mesh_vars(per, dims, shape, ref)
    data["attractor"] = (dims, labels.reshape(shape))
    A = len(atts)
    width = max([t["points"].shape[0] for t in atts], default=1)
    au, av = np.full((A, width), np.nan), np.full((A, width), np.nan)
    for k, t in enumerate(atts):
        au[k, : t["points"].shape[0]] = t["points"][:, 0]
        av[k, : t["points"].shape[0]] = t["points"][:, 1]
    p = model.period_multiple() or 1
    data.update({
        "attractor_period": ("attractor_index", np.array([t["period"] * p for t in atts], dtype=np.int64)),
        "attractor_motion": ("attractor_index", np.array([t["motion"] for t in atts], dtype=np.int64)),
        "attractor_fraction": ("attractor_index", np.array([t["count"] / labels.size for t in atts])),
        "attractor_amplitude": ("attractor_index", np.array([t["amplitude"] for t in atts])),
        "attractor_u": (("attractor_index", "cycle_point"), au),
        "attractor_v": (("attractor_index", "cycle_point"), av),
    })
    st = [f"{lab}" for lab in model.labels] + [f"{lab}'" for lab in model.labels]
    if coords is None:
        st, i, j = st + ["δ (reference mesh)", "δ' (reference mesh)"], len(st), len(st) + 1
    ds = xr.Dataset(data, coords={"v0": b, "u0": a, "mesh": [m.name for m in model.meshes],
                                  "attractor_index": np.arange(A), "cycle_point": np.arange(width)},
                    attrs=system_attrs(model, "system_basins", options, {"coordinates": [st[i], st[j]],
                                       "diverged": int(np.count_nonzero(labels < 0))}))
    return annotate(ds)


def grid_json(ds: xr.Dataset) -> dict[str, Any]:
    """JSON summary of a system map or basin map: the grid, per-point labels (reference mesh) and ``meshes``.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``system_map`` or ``system_basins`` result.

    Returns
    -------
    dict
    """
    from ..io import json_values

    kind = ds.attrs["geardyn_kind"]
    dims = ds["status"].dims
    out: dict[str, Any] = {"kind": kind, "system": json.loads(ds.attrs["system"]),
                           "coords": {d: json_values(ds[d]) for d in dims}}
    for k in ("period", "motion", "impact", "amplitude", "u_min", "u_max", "status"):
        out[k] = json_values(ds[k], period=ds["period"].values if k == "motion" else None)
    meshes = []
    for e, name in enumerate(ds["mesh"].values):
        ent: dict[str, Any] = {"name": str(name)}
        for k in ("u_min", "u_max", "amplitude"):
            ent[k] = json_values(ds[f"mesh_{k}"].isel(mesh=e))
        ent["impact"] = json_values(ds["mesh_impact"].isel(mesh=e), name="impact")
        ent["dynamic_factor"] = None
        meshes.append(ent)
    out["meshes"] = meshes
    if kind == "system_basins":
        out["coordinates"] = json.loads(ds.attrs["coordinates"])
        out["attractors"] = [{"period": int(p) if p > 0 else None, "fraction": float(f), "amplitude": float(a)}
                             for p, f, a in zip(ds["attractor_period"].values, ds["attractor_fraction"].values,
                                                ds["attractor_amplitude"].values)]
        out["diverged"] = int(json.loads(ds.attrs.get("diverged", "0")))
    return out
