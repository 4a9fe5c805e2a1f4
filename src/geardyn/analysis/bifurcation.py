"""Bifurcation diagrams over any model parameter.

Every point of the sweep is integrated through the transient, its Poincaré points recorded and
classified (:func:`geardyn.analysis.steady.classify_batch`: period, motion, impact state,
amplitude measures and, on request, the largest Lyapunov exponent).  Two modes:

- ``fixed``: every point starts from the same initial state.  The points are independent, so the
  grid is cut into many chunks that run in parallel on the sweep engine.
- ``continue``: each point starts from the end state of the previous one (natural-parameter
  continuation of the attractor, as on a test rig whose speed is ramped slowly).  A continuation
  sweep is sequential: one chunk per direction.  ``up`` runs the values in increasing order,
  ``down`` in decreasing order, ``both`` runs both; where they disagree, attractors coexist.

The result is one :class:`xarray.Dataset` with the swept parameter (canonical name, e.g. ``omega``
or ``xi0``) as a dimension and a ``sweep`` dimension labelled ``up``/``down`` (``fixed`` in fixed
mode); see :func:`bifurcation`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import xarray as xr

from .._docfill import parameters, result_of
from ..grid import Grid, build_models, linspace_values, param_name, point_models
from ..integrate import ST_OK, integrate_batch
from ..io import json_values
from ..model import GearModel, IntegrationOptions, ModelError
from ..params import FAMILIES, slot
from ..sweep import Chunk, chunk_slices, run_chunks
from ..sweep.progress import counts_points, tick
from ..system import as_batch, state_names
from .classify import SETTLE_PERIODS
from .points import concat_rows, grid_variables, initial_state, result_dataset, run_slices, sweep_function
from .steady import classify_batch

__all__ = [
    "MODES",
    "SWEEPS",
    "bifurcation",
    "sweep_values",
    "fixed_chunk",
    "continuation_chunk",
    "grid_chunk",
    "bifurcation_json",
    "class_intervals",
]

MODES = ("fixed", "continue")
SWEEPS = ("up", "down", "both")

#: Per-point scalar variables of a sweep result, with their dtype: the class codes and the status
#: in one byte, periods and loop counts (at most a few hundred) in two, so that a 10⁶-point map
#: holds 8 MB of codes instead of 40 MB (the values are the same).
_SCALARS = {
    "period": np.int16,
    "motion": np.int8,
    "impact": np.int8,
    "status": np.int8,
    "loops": np.int16,
    "settled": np.int64,
    "restarted": np.int64,
    "amplitude": float,
    "rms": float,
    "mean": float,
    "u_min": float,
    "u_max": float,
    "fraction_drive": float,
    "fraction_separation": float,
    "fraction_back": float,
    "lle": float,
    "lle_err": float,
    "lambda2": float,
    "curve_dim": float,
    "settle_ratio": float,
}

#: Prefix of the time fractions of the reference element's law counters (``fraction_drive`` … of the dead zone).
FRACTION = "fraction_"

#: Evenly spaced values start … stop (num >= 1), validated: :func:`geardyn.grid.linspace_values`.
sweep_values = linspace_values


#: Per-point, per-element variables of a system of several elements (P, elements), with their dtype.
ELEMENT_VARIABLES = {
    "element_u_min": float,
    "element_u_max": float,
    "element_mean": float,
    "element_rms": float,
    "element_impact": np.int8,
}


def _rows(out: dict[str, np.ndarray], start: np.ndarray, models: Any) -> dict[str, np.ndarray]:
    """Chunk result: one row per point (plain arrays only, for checkpoint files); the Poincaré points are the
    reference element's (δ, δ'), the start and end states the full states."""
    n = out["period"].shape[0]
    types = {**_SCALARS, **{k: float for k in out if k.startswith(FRACTION)}, **ELEMENT_VARIABLES}
    r = {k: np.asarray(out[k], dtype=t) for k, t in types.items() if k in out}
    r["restarted"] = np.zeros(n, np.int64)
    r["poincare"] = models.reference_section(np.asarray(out["poincare"], dtype=float))
    r["start"] = np.asarray(start, dtype=float).reshape(n, -1)
    r["end"] = np.asarray(out["end_state"], dtype=float)
    return r


@counts_points(lambda args: len(args[0]))
def fixed_chunk(
    models: Sequence[GearModel],
    state0: Sequence[float] | np.ndarray,
    options: IntegrationOptions,
    lyapunov: bool = False,
    settle_periods: int = SETTLE_PERIODS,
) -> dict[str, np.ndarray]:
    """Chunk function: independent points (one batch), each from its initial state.

    Parameters
    ----------
    models : Batch or sequence of System
        The points.
    state0 : ndarray (d,) or (P, d)
        One initial state for all points or one per point, d = ``state_dim``.
    options : IntegrationOptions
        Transient and recorded periods.
    lyapunov : bool
        Exponents for every point.
    settle_periods : int
        Settling periods of :func:`~geardyn.analysis.steady.classify_batch`.

    Returns
    -------
    dict of ndarray
        One row per point: the scalars of :func:`~geardyn.analysis.steady.classify_batch`,
        ``restarted``, ``poincare``, ``start`` and ``end`` states.
    """
    models = as_batch(models)
    s0 = np.broadcast_to(np.asarray(state0, dtype=float), (len(models), models.state_dim)).copy()
    res = integrate_batch(models, s0, options, lyapunov=lyapunov)
    out = _rows(classify_batch(res, settle_periods=settle_periods), s0, models)
    tick(len(models))
    return out


@counts_points(lambda args: len(args[0]))
def continuation_chunk(
    models: Sequence[GearModel],
    state0: Sequence[float],
    options: IntegrationOptions,
    lyapunov: bool = False,
    settle_periods: int = SETTLE_PERIODS,
) -> dict[str, np.ndarray]:
    """Chunk function: points in the given order, each starting from the previous end state.

    After a diverged point the next one restarts from ``state0`` (flagged in ``restarted``).  Each
    finished point is reported to the sweep's progress bar (:func:`geardyn.sweep.progress.tick`).

    Parameters
    ----------
    models : sequence of GearModel
        The points, in continuation order.
    state0 : sequence of float
        Initial state of the first point.
    options, lyapunov, settle_periods
        As for :func:`fixed_chunk`.

    Returns
    -------
    dict of ndarray
        As :func:`fixed_chunk`.
    """
    models = list(models)
    d = models[0].state_dim
    s0 = np.asarray(state0, dtype=float).reshape(d)
    state = s0.copy()
    rows = []
    restarted = np.zeros(len(models), np.int64)
    for i, m in enumerate(models):
        if not np.all(np.isfinite(state)):
            state = s0.copy()
            restarted[i] = 1
        rows.append(fixed_chunk([m], state, options, lyapunov, settle_periods))  # one point from ``state``
        state = rows[-1]["end"][0].copy() if rows[-1]["status"][0] == ST_OK else np.full(d, np.nan)
    return concat_rows(rows) | {"restarted": restarted}


@counts_points(lambda args: len(args[2]))
def grid_chunk(
    model: GearModel,
    names: Sequence[str],
    points: np.ndarray,
    state0: Sequence[float],
    options: IntegrationOptions,
    lyapunov: bool = False,
    settle_periods: int = SETTLE_PERIODS,
    continuation: bool = False,
    keep: Sequence[str] | None = None,
) -> dict[str, np.ndarray]:
    """Chunk function on compact parameter points: the models are built here, in the worker.

    Parameters
    ----------
    model : GearModel
        The base model.
    names : sequence of str
        Parameter names (columns of ``points``, set in this order).
    points : ndarray (n, len(names))
        The chunk's parameter points (:meth:`geardyn.grid.Grid.points`), in sweep order.
    state0, options, lyapunov, settle_periods
        As for :func:`fixed_chunk`.
    continuation : bool
        Run the points as :func:`continuation_chunk` (each from the previous end state) instead
        of :func:`fixed_chunk`.
    keep : sequence of str, optional
        Keep only these result variables.

    Returns
    -------
    dict of ndarray
        One row per point.
    """
    if continuation:
        r = continuation_chunk(build_models(model, names, points), state0, options, lyapunov, settle_periods)
    else:  # the backend's batch of the points (the pair's: kernel arrays straight from them)
        r = fixed_chunk(point_models(model, names, points), state0, options, lyapunov, settle_periods)
    return r if keep is None else {k: r[k] for k in keep if k in r}


def param_symbol(name: str) -> str:
    """The symbol of a canonical parameter name for labels (``"omega"`` → ``"ω"``, ``"kappa2"`` → ``"κ2"``)."""
    if "." in name:  # an element's parameter of a system: its name
        return name
    fam, idx = slot(name)
    sym = FAMILIES[fam].symbol
    return sym.replace("_{k}", "{k}").replace("{k}", str(idx + 1)) if idx is not None else sym


@sweep_function("bifurcation")
def bifurcation(
    model: GearModel,
    param: str,
    values: Sequence[float] | np.ndarray,
    *,
    mode: str = "fixed",
    sweep: str = "up",
    description: str | None = None,
    state0,
    options,
    lyapunov,
    settle_periods,
    engine,  # shared sweep keywords (SWEEP_KEYWORDS)
) -> xr.Dataset:
    """Bifurcation diagram of ``param`` over ``values``.

    Parameters
    ----------
    model : GearModel
        The base model; ``param`` is set to each value in turn.
    param : str
        Any parameter name of :data:`geardyn.model.PARAMETER_HELP` (``omega``, ``xi0``, ``xi1``,
        ``kappa1``, ``fp``, ``eps1``/``fe``, ``D``/``backlash``, ``phi_c1``, …).
    values : sequence of float
        The parameter values (sorted ascending in the result; the sweep's :meth:`geardyn.grid.Grid.range`).
    mode : {'fixed', 'continue'}
        Every point from ``state0``, or continuation of the previous end state.
    sweep : {'up', 'down', 'both'}
        Direction(s) of a continuation sweep (ignored in fixed mode, whose sweep label is 'fixed').
    description : str, optional
        Label of the progress bar and of the divergence summary on stderr (with ``progress=True``);
        default ``"bifurcation <symbol>"``, e.g. ``"bifurcation ω"``.

    Returns
    -------
    xarray.Dataset
        Dimensions ``sweep``, ``<param>``, ``section`` (recorded Poincaré points); variables
        ``poincare_u``, ``poincare_v`` (sweep, param, section); ``period``, ``motion``, ``impact``,
        ``amplitude``, ``rms``, ``mean``, ``u_min``, ``u_max``, contact fractions, ``lle``,
        ``lle_err``, ``lambda2``, ``loops``, ``status`` (sweep, param); the full start and end states
        ``start_state``, ``end_state`` (sweep, param, state), the same for every System (the pair's state
        coordinates ``u``, ``u'``).

    Raises
    ------
    ModelError
        For an unknown parameter, mode or sweep, an empty or non-finite grid, a value the model
        refuses, a non-finite initial state or invalid engine options.
    SweepError
        When the sweep cannot run (checkpoint, resume, scheduler; see :func:`geardyn.sweep.run_chunks`).
    TypeError
        For a keyword that is not an engine option.

    References
    ----------
    R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010 (brute-force
    bifurcation diagrams and natural-parameter continuation of attractors).

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, bifurcation
    >>> ds = bifurcation(GearModel(), "omega", [0.6, 0.8], options=IntegrationOptions(transient=50, periods=8),
    ...                  progress=False)
    >>> ds["period"].values.ravel().tolist()
    [1, 2]
    """
    name = param_name(param)
    if mode not in MODES:
        raise ModelError(f"mode: must be one of {', '.join(MODES)}, got {mode!r}")
    if sweep not in SWEEPS:
        raise ModelError(f"sweep: must be one of {', '.join(SWEEPS)}, got {sweep!r}")
    grid = Grid.range(name, values)
    vals = grid.values(name)
    models = grid.models(model)
    for m in models:
        options.check_for(m.omega)
    s0t = initial_state(model, state0)
    label = description if description is not None else f"bifurcation {param_symbol(name)}"

    common = (s0t, options, lyapunov, settle_periods)
    if mode == "fixed":
        labels = ["fixed"]
        per_sweep = [
            run_slices(
                grid_chunk,
                lambda sl: (model, grid.names, grid.points(sl)) + common,
                chunk_slices(grid, model, options, engine, lyapunov=lyapunov),
                engine,
                label,
            )
        ]
    else:
        labels = ["up", "down"] if sweep == "both" else [sweep]
        pts = grid.points()
        chunks = [
            Chunk(i, grid_chunk, (model, grid.names, pts if lab == "up" else pts[::-1].copy()) + common + (True,))
            for i, lab in enumerate(labels)
        ]
        results = run_chunks(chunks, engine, description=label)
        per_sweep = [r if lab == "up" else {k: v[::-1] for k, v in r.items()} for lab, r in zip(labels, results)]
    dims, shape = ("sweep", name), (len(labels), vals.size)
    rows = concat_rows(per_sweep)  # the sweeps one after the other: reshaped to (sweep, point)
    fractions = sorted(k for k in rows if k.startswith(FRACTION) and k not in _SCALARS)
    data, _ = grid_variables(rows, [*_SCALARS, *fractions], dims, shape, model)
    pc = rows["poincare"].reshape(shape + rows["poincare"].shape[1:])
    data.update(poincare_u=(dims + ("section",), pc[..., 0]), poincare_v=(dims + ("section",), pc[..., 1]))
    for k in ("start", "end"):  # the full states, (u, u') for the pair
        data[f"{k}_state"] = (dims + ("state",), rows[k].reshape(shape + (-1,)))
    elements, element_coord = grid_variables(rows, list(ELEMENT_VARIABLES), dims, shape, model)
    data.update(elements)
    coords = {
        "sweep": list(labels),
        name: np.asarray(vals, float),
        "section": np.arange(pc.shape[2]),
        "state": state_names(model, rows["start"].shape[-1]),
        **element_coord,
    }
    return result_dataset(
        data,
        coords,
        "bifurcation",
        model,
        options,
        param=name,
        mode=mode,
        sweep=sweep,
        state0=list(s0t),
        lyapunov=bool(lyapunov),
        settle_periods=int(settle_periods),
    )


def point_labels(ds: xr.Dataset, sweep: str) -> dict[str, list[Any]]:
    """JSON-ready per-point lists of one sweep (converted by :func:`geardyn.io.json_values`).

    Parameters
    ----------
    ds : xarray.Dataset
        A bifurcation (or frequency-response) Dataset.
    sweep : str
        The sweep label (``up``, ``down`` or ``fixed``).

    Returns
    -------
    dict of list
        ``period`` (None where not periodic), ``motion`` and ``impact`` (labels), ``lle`` and
        ``amplitude`` (None where not finite), ``status`` (labels).
    """
    s = ds.sel(sweep=sweep)
    per = s["period"].values
    return {
        k: json_values(s[k], period=per if k == "motion" else None)
        for k in ("period", "motion", "impact", "lle", "amplitude", "status")
    }


def class_intervals(ds: xr.Dataset, sweep: str) -> list[dict[str, Any]]:
    """Runs of consecutive grid points with the same motion label.

    Parameters
    ----------
    ds : xarray.Dataset
        A bifurcation Dataset.
    sweep : str
        The sweep label.

    Returns
    -------
    list of dict
        ``{"from", "to", "motion", "points"}`` per run, in grid order.
    """
    name = str(ds.attrs["param"])
    x = ds[name].values
    labels = point_labels(ds, sweep)["motion"]
    out: list[dict[str, Any]] = []
    for xv, lab in zip(x, labels):
        if out and out[-1]["motion"] == lab:
            out[-1]["to"] = float(xv)
            out[-1]["points"] += 1
        else:
            out.append({"from": float(xv), "to": float(xv), "motion": lab, "points": 1})
    return out


@parameters(result_of("bifurcation"))
def bifurcation_json(ds: xr.Dataset) -> dict[str, Any]:
    """The ``bifurcation --json`` summary (DESIGN §5: ``param``, ``values``, ``period``, ``motion``,
    ``impact``, ``lle``).

    With one sweep the per-point entries are lists aligned with ``values``; with both sweeps each
    is a dict ``{"up": [...], "down": [...]}``.

    Returns
    -------
    dict
        ``param``, ``values``, ``mode``, ``sweep``, the per-point entries and ``intervals``
        (:func:`class_intervals`).
    """
    param = str(ds.attrs["param"])
    labels = [str(x) for x in ds["sweep"].values]
    one = len(labels) == 1
    per = {lab: point_labels(ds, lab) for lab in labels}

    def per_sweep(f: Callable[[str], Any]) -> Any:  # one sweep's entry, or a dict of them
        return f(labels[0]) if one else {lab: f(lab) for lab in labels}

    out = {
        "param": param,
        "values": [float(v) for v in ds[param].values],
        "mode": ds.attrs.get("mode"),
        "sweep": labels[0] if one else labels,
    }
    for key in ("period", "motion", "impact", "lle", "amplitude", "status"):
        out[key] = per_sweep(lambda lab: per[lab][key])
    out["intervals"] = per_sweep(lambda lab: class_intervals(ds, lab))
    return out
