"""Basins of attraction: a grid of initial states, each labelled by the attractor it reaches.

At one parameter set (typically inside a hysteresis interval found by
:func:`geardyn.analysis.response.frequency_response`), every initial state (u0, v0) of a grid at
θ = 0 is integrated through the transient and classified.  Attractors are identified by their
Poincaré cycles: two periodic end states belong to the same attractor when they have the same
period and each point of one cycle lies within :data:`CYCLE_TOL` of a point of the other (the
cycle's phase does not matter).  Non-periodic attractors (quasi-periodic, chaotic, unresolved)
are told apart by motion class, amplitude, mean and extremes (to :data:`NONPERIODIC_TOL` of the
largest amplitude).  Labels are numbered by basin size (0 the largest); −1 marks diverged states.
The grid points are independent, so they are cut into chunks for the sweep engine.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ..integrate import ST_OK
from ..io import annotate, result_attrs
from ..model import GearModel, IntegrationOptions, ModelError
from ..sweep import DEFAULT_CHUNK_POINTS, Chunk, chunked, run_chunks
from .bifurcation import fixed_chunk
from .classify import MAX_PERIOD, MOTION_PERIODIC, SETTLE_PERIODS, motion_label

__all__ = ["basins", "basins_json", "identify_attractors", "CYCLE_TOL", "NONPERIODIC_TOL", "BASIN_OPTIONS"]

#: Cycle points closer than this (relative to max(1, largest |coordinate|)) are the same point.
CYCLE_TOL = 1.0e-3
#: Non-periodic attractors are the same when amplitude, mean and extremes agree to this fraction
#: of the largest amplitude among them.
NONPERIODIC_TOL = 0.05
#: Default integration options of a basin map: the usual transient, and just enough recorded
#: periods to detect periods up to MAX_PERIOD.
BASIN_OPTIONS = IntegrationOptions(periods=2 * MAX_PERIOD)
#: Non-periodic attractors are drawn with this many of their Poincaré points.
CLOUD_POINTS = MAX_PERIOD


def basin_chunk(model, states, options, settle_periods):
    """Chunk function: one model, many initial states (one row per state)."""
    r = fixed_chunk([model] * len(states), np.asarray(states, dtype=float), options, False, settle_periods)
    keep = min(r["poincare"].shape[1], max(MAX_PERIOD, CLOUD_POINTS))
    return {k: r[k] for k in ("period", "motion", "impact", "status", "amplitude", "mean", "u_min", "u_max", "lle")} | {
        "poincare": r["poincare"][:, -keep:, :]}


def _grid(name: str, lo: float, hi: float, num: int) -> np.ndarray:
    for n, v in ((f"{name} start", lo), (f"{name} stop", hi)):
        if not np.isfinite(v):
            raise ModelError(f"{n}: must be a finite number, got {v!r}")
    if isinstance(num, bool) or int(num) != num or num < 1:
        raise ModelError(f"{name} num: must be an integer >= 1, got {num!r}")
    return np.linspace(float(lo), float(hi), int(num))


def identify_attractors(rows: dict[str, np.ndarray], *, tol: float = CYCLE_TOL,
                        nonperiodic_tol: float = NONPERIODIC_TOL) -> tuple[np.ndarray, list[dict[str, Any]]]:
    """Label each point by its attractor.

    Parameters
    ----------
    rows : dict of arrays
        Per-point ``period``, ``motion``, ``status``, ``amplitude``, ``mean``, ``u_min``,
        ``u_max`` and ``poincare`` (P, m, 2).

    Returns
    -------
    labels : ndarray (P,)
        Attractor index per point (0 = largest basin), −1 where diverged.
    attractors : list of dict
        Per attractor: ``period`` (0 if not periodic), ``motion`` code, ``points`` (the cycle, or
        a sample of the section), ``amplitude``, ``mean``, ``count`` (points in its basin).
    """
    P = rows["period"].shape[0]
    raw = np.full(P, -1, dtype=np.int64)
    atts: list[dict[str, Any]] = []
    amps = rows["amplitude"][np.isfinite(rows["amplitude"])]
    amp_scale = max(float(np.max(amps)) if amps.size else 0.0, 1e-12)
    for i in range(P):
        if rows["status"][i] != ST_OK:
            continue
        code = int(rows["motion"][i])
        n = int(rows["period"][i])
        found = -1
        if code == MOTION_PERIODIC and n > 0:
            cyc = rows["poincare"][i][-n:]
            scale = max(1.0, float(np.max(np.abs(cyc))))
            for a, att in enumerate(atts):
                if att["motion"] != MOTION_PERIODIC or att["period"] != n:
                    continue
                d = np.max(np.abs(cyc[:, None, :] - att["points"][None, :, :]), axis=2)
                if np.all(d.min(axis=1) <= tol * scale) and np.all(d.min(axis=0) <= tol * scale):
                    found = a
                    break
            if found < 0:
                order = np.lexsort((cyc[:, 1], cyc[:, 0]))
                atts.append({"period": n, "motion": code, "points": cyc[order].copy(),
                             "amplitude": float(rows["amplitude"][i]), "mean": float(rows["mean"][i]), "count": 0})
                found = len(atts) - 1
        else:
            sig = np.array([rows["amplitude"][i], rows["mean"][i], rows["u_min"][i], rows["u_max"][i]])
            for a, att in enumerate(atts):
                if att["motion"] != code or att["period"] != 0:
                    continue
                if np.all(np.abs(sig - att["signature"]) <= nonperiodic_tol * amp_scale):
                    found = a
                    break
            if found < 0:
                atts.append({"period": 0, "motion": code, "points": rows["poincare"][i][-CLOUD_POINTS:].copy(),
                             "amplitude": float(rows["amplitude"][i]), "mean": float(rows["mean"][i]),
                             "signature": sig, "count": 0})
                found = len(atts) - 1
        raw[i] = found
        atts[found]["count"] += 1
    # number by basin size (ties: periodic first, then by period and first cycle point)
    key = sorted(range(len(atts)), key=lambda a: (-atts[a]["count"], atts[a]["period"] == 0, atts[a]["period"],
                                                  float(atts[a]["points"][0, 0])))
    new = {old: k for k, old in enumerate(key)}
    labels = np.array([new[r] if r >= 0 else -1 for r in raw], dtype=np.int64)
    out = []
    for old in key:
        a = dict(atts[old])
        a.pop("signature", None)
        out.append(a)
    return labels, out


def basins(
    model: GearModel,
    u_range: tuple[float, float],
    v_range: tuple[float, float],
    nu: int,
    nv: int,
    *,
    options: IntegrationOptions = BASIN_OPTIONS,
    settle_periods: int = SETTLE_PERIODS,
    workers: int = 1,
    scheduler: str | None = None,
    checkpoint: str | Path | None = None,
    resume: bool = False,
    progress: bool = False,
    chunk_points: int = 4 * DEFAULT_CHUNK_POINTS,
    executor: Any = None,
) -> xr.Dataset:
    """Basins of attraction over a grid of initial states (u0, v0) at θ = 0.

    Parameters
    ----------
    model : GearModel
        The parameter set (where attractors coexist, e.g. inside a hysteresis interval).
    u_range, v_range : (float, float)
        Ranges of the initial displacement u0 and velocity v0 (non-dimensional).
    nu, nv : int
        Grid points along u0 and v0.
    options : IntegrationOptions
        Transient (long enough for every start to settle) and recorded periods (at least
        2·MAX_PERIOD to detect periods up to MAX_PERIOD).
    Other parameters as for :func:`~geardyn.analysis.bifurcation.bifurcation`.

    Returns
    -------
    xarray.Dataset
        Dimensions ``v0``, ``u0`` with ``attractor`` (label), ``period``, ``motion``, ``impact``,
        ``amplitude``, ``status``; and dimensions ``attractor``, ``cycle_point`` with
        ``attractor_period``, ``attractor_motion``, ``attractor_fraction``, ``attractor_amplitude``,
        ``attractor_u``, ``attractor_v`` (the cycle points, NaN-padded).
    """
    options.check_for(model.omega)
    u0 = _grid("u0", *u_range, nu)
    v0 = _grid("v0", *v_range, nv)
    V, U = np.meshgrid(v0, u0, indexing="ij")
    states = np.column_stack([U.ravel(), V.ravel()])
    chunks = [Chunk(i, basin_chunk, (model, states[sl], options, settle_periods))
              for i, sl in enumerate(chunked(states.shape[0], chunk_points))]
    results = run_chunks(chunks, workers=workers, scheduler=scheduler, executor=executor, checkpoint=checkpoint,
                         resume=resume, progress=progress, description="basins")
    rows = {k: np.concatenate([r[k] for r in results]) for k in results[0]}
    labels, atts = identify_attractors(rows)
    shape = (v0.size, u0.size)
    dims = ("v0", "u0")
    A = len(atts)
    width = max([a["points"].shape[0] for a in atts], default=1)
    au = np.full((A, width), np.nan)
    av = np.full((A, width), np.nan)
    for k, a in enumerate(atts):
        au[k, : a["points"].shape[0]] = a["points"][:, 0]
        av[k, : a["points"].shape[0]] = a["points"][:, 1]
    total = float(labels.size)
    ds = xr.Dataset(
        {
            "attractor": (dims, labels.reshape(shape)),
            "period": (dims, rows["period"].reshape(shape)),
            "motion": (dims, rows["motion"].reshape(shape)),
            "impact": (dims, rows["impact"].reshape(shape)),
            "amplitude": (dims, rows["amplitude"].reshape(shape)),
            "status": (dims, rows["status"].reshape(shape)),
            "attractor_period": ("attractor_index", np.array([a["period"] for a in atts], dtype=np.int64)),
            "attractor_motion": ("attractor_index", np.array([a["motion"] for a in atts], dtype=np.int64)),
            "attractor_fraction": ("attractor_index", np.array([a["count"] / total for a in atts])),
            "attractor_amplitude": ("attractor_index", np.array([a["amplitude"] for a in atts])),
            "attractor_u": (("attractor_index", "cycle_point"), au),
            "attractor_v": (("attractor_index", "cycle_point"), av),
        },
        coords={"v0": v0, "u0": u0, "attractor_index": np.arange(A), "cycle_point": np.arange(width)},
        attrs=result_attrs("basins", model, options, settle_periods=int(settle_periods),
                           diverged=int(np.count_nonzero(labels < 0))),
    )
    meta = {
        "u0": ("1", "initial displacement u0 at θ = 0"),
        "v0": ("1", "initial velocity u0' at θ = 0"),
        "attractor": ("1", "attractor reached (index into attractor_index; -1 diverged)"),
        "motion": ("1", "motion class (-1 diverged, 0 unresolved, 1 periodic, 2 quasi-periodic, 3 chaotic)"),
        "attractor_period": ("1", "period of the attractor (0 not periodic)"),
        "attractor_motion": ("1", "motion class of the attractor"),
        "attractor_fraction": ("1", "fraction of the grid in the attractor's basin"),
        "attractor_amplitude": ("1", "half peak-to-peak displacement on the attractor"),
        "attractor_u": ("1", "Poincaré points u of the attractor (its cycle)"),
        "attractor_v": ("1", "Poincaré points u' of the attractor (its cycle)"),
        "attractor_index": ("1", "attractor number (0: largest basin)"),
        "cycle_point": ("1", "index of a Poincaré point of the attractor"),
    }
    for k, (u, ln) in meta.items():
        ds[k].attrs.update(units=u, long_name=ln)
    return annotate(ds)


def basins_json(ds: xr.Dataset) -> dict[str, Any]:
    """The ``basins --json`` summary: the attractors (period, motion, basin fraction, cycle points)
    and the label grid (rows are v0 values)."""
    atts = []
    for k in range(ds.sizes["attractor_index"]):
        u = ds["attractor_u"].values[k]
        v = ds["attractor_v"].values[k]
        ok = np.isfinite(u)
        per = int(ds["attractor_period"].values[k])
        atts.append({
            "label": k,
            "period": per if per > 0 else None,
            "motion": motion_label(int(ds["attractor_motion"].values[k]), per),
            "fraction": float(ds["attractor_fraction"].values[k]),
            "amplitude": float(ds["attractor_amplitude"].values[k]),
            "points": np.column_stack([u[ok], v[ok]]).tolist(),
        })
    lab = ds["attractor"].values
    return {
        "omega": float(__import__("json").loads(ds.attrs["model"])["omega"]),
        "attractors": atts,
        "diverged_fraction": float(np.count_nonzero(lab < 0) / lab.size),
        "u0": [float(x) for x in ds["u0"].values],
        "v0": [float(x) for x in ds["v0"].values],
        "labels": lab.tolist(),
    }
