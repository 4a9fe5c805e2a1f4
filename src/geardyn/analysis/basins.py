"""Basins of attraction: a grid of initial states, each labelled by the attractor it reaches.

At one parameter set (typically inside a hysteresis interval found by
:func:`geardyn.analysis.response.frequency_response`), every initial state (u0, v0) of a grid at
θ = 0 is integrated through the transient and classified.  Attractors are identified by their
Poincaré cycles (:mod:`geardyn.analysis.attractors`, the test the frequency response uses too):
two periodic end states belong to the same attractor when they have the same period and each
point of one cycle lies within :data:`CYCLE_TOL` of a point of the other (the cycle's phase does
not matter).  Non-periodic attractors (quasi-periodic, chaotic, unresolved) are told apart by
motion class, amplitude, mean and extremes (to :data:`NONPERIODIC_TOL` of the largest amplitude).
Labels are numbered by basin size (0 the largest); −1 marks diverged states.
The grid of initial states (:meth:`geardyn.grid.Grid.states`) has independent points, so they
are cut into chunks for the sweep engine.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from .._docfill import parameters, result_of
from ..grid import Grid, linspace_values
from ..io import json_values
from ..model import IntegrationOptions, ModelError
from ..sweep import DEFAULT_CHUNK_POINTS
from ..sweep.progress import counts_points
from ..system import state_names
from .attractors import CLOUD_POINTS, CYCLE_TOL, NONPERIODIC_TOL, identify_attractors
from .bifurcation import ELEMENT_VARIABLES, fixed_chunk
from .classify import MAX_PERIOD
from .points import grid_variables, result_dataset, run_slices, sweep_function

__all__ = [
    "basins",
    "basins_json",
    "coordinate_index",
    "identify_attractors",
    "CYCLE_TOL",
    "NONPERIODIC_TOL",
    "BASIN_OPTIONS",
]

#: Default integration options of a basin map: the usual transient, and just enough recorded
#: periods to detect periods up to MAX_PERIOD.
BASIN_OPTIONS = IntegrationOptions(periods=2 * MAX_PERIOD)


@counts_points(lambda args: len(args[1]))
def basin_chunk(model, states, options, settle_periods):
    """Chunk function: one model, many initial states (one row per state; the points are reported to the
    sweep's progress bar by :func:`~geardyn.analysis.bifurcation.fixed_chunk`)."""
    r = fixed_chunk([model] * len(states), np.asarray(states, dtype=float), options, False, settle_periods)
    return {
        k: r[k]
        for k in ("period", "motion", "impact", "status", "amplitude", "mean", "u_min", "u_max", "lle")
        + tuple(ELEMENT_VARIABLES)
        if k in r
    } | {"poincare": r["poincare"][:, -max(MAX_PERIOD, CLOUD_POINTS) :, :]}  # the latest points


def coordinate_index(model: Any, name: str) -> int:
    """Index in a system's state (q̃, q̃') of a coordinate: a DOF label, ``label'`` (its rate) or an integer.

    Parameters
    ----------
    model : System
        The system whose state is indexed (its DOF ``labels``, if it has them).
    name : str
        The coordinate: ``x``, ``x'`` for a DOF label x, or an index into the state.

    Returns
    -------
    int

    Raises
    ------
    ModelError
        For an unknown coordinate.
    """
    labels = list(getattr(model, "labels", ()) or ())
    d = int(model.state_dim)
    s = str(name).strip()
    if s in labels:
        return labels.index(s)
    if s.endswith("'") and s[:-1] in labels:
        return d // 2 + labels.index(s[:-1])
    try:
        i = int(s)
    except ValueError:
        raise ModelError(
            f"coordinates: unknown coordinate {s!r}; the system's are {', '.join(labels)} and their "
            f"rates {', '.join(lab + chr(39) for lab in labels)} (or indices 0..{d - 1})"
        ) from None
    if not 0 <= i < d:
        raise ModelError(f"coordinates: index {i} out of range 0..{d - 1}")
    return i


def _start_states(
    model: Any, grid: Grid, coordinates: tuple[int, int] | None, base_state: Sequence[float] | None
) -> np.ndarray | None:
    """The full initial states of a state grid (None for the pair's (u0, v0), taken straight from the grid)."""
    if coordinates is None:
        if model.state_dim == 2:
            return None
        return np.array([model.initial_state(float(u), float(v)) for u, v in grid.state_points()])
    i, j = coordinates
    if i == j:
        raise ModelError("coordinates: give two different coordinates for the basin slice")
    base = model.initial_state() if base_state is None else np.asarray(base_state, dtype=float)
    pts = grid.state_points()
    states = np.tile(base, (pts.shape[0], 1))
    states[:, i], states[:, j] = pts[:, 0], pts[:, 1]
    return states


@sweep_function("basins", options=BASIN_OPTIONS)
def basins(
    model: Any,
    u_range: tuple[float, float],
    v_range: tuple[float, float],
    nu: int,
    nv: int,
    *,
    coordinates: tuple[int, int] | None = None,
    base_state: Sequence[float] | None = None,
    options,
    settle_periods,
    engine,  # shared sweep keywords (SWEEP_KEYWORDS)
) -> xr.Dataset:
    """Basins of attraction over a grid of initial states (u0, v0) at θ = 0.

    Parameters
    ----------
    model : System
        The parameter set (where attractors coexist, e.g. inside a hysteresis interval).
    u_range, v_range : (float, float)
        Ranges of the initial displacement u0 and velocity v0 (non-dimensional).
    nu, nv : int
        Grid points along u0 and v0.
    coordinates : (int, int), optional
        Two state coordinates of a system (:func:`coordinate_index`) that u0 and v0 set, the others those of
        ``base_state``; default the reference element's (δ, δ') through
        :meth:`~geardyn.system.System.initial_state` (the pair's (u, u')).
    base_state : sequence of float, optional
        The other coordinates with ``coordinates`` (default ``model.initial_state()``).
    options : IntegrationOptions
        Transient (long enough for every start to settle) and recorded periods (at least
        2·MAX_PERIOD to detect periods up to MAX_PERIOD); default :data:`BASIN_OPTIONS`.
    engine : SweepOptions, optional
        Where and how the sweep runs; ``chunk_points`` is the number of initial states per chunk
        (default 4 × :data:`geardyn.sweep.DEFAULT_CHUNK_POINTS`).

    Returns
    -------
    xarray.Dataset
        Dimensions ``v0``, ``u0`` with ``attractor`` (label), ``period``, ``motion``, ``impact``,
        ``amplitude``, ``status``; and dimensions ``attractor``, ``cycle_point`` with
        ``attractor_period``, ``attractor_motion``, ``attractor_fraction``, ``attractor_amplitude``,
        ``attractor_u``, ``attractor_v`` (the cycle points, NaN-padded).

    Raises
    ------
    ModelError
        For a non-finite range end, a count not an integer >= 1, options the model refuses or
        invalid engine options.
    SweepError
        When the sweep cannot run (see :func:`geardyn.sweep.run_chunks`).
    TypeError
        For a keyword that is not an engine option.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, basins
    >>> ds = basins(GearModel(omega=0.8), (-1, 1), (-1, 1), 2, 2, options=IntegrationOptions(transient=50, periods=64),
    ...             progress=False)
    >>> ds["period"].shape
    (2, 2)
    """
    options.check_for(model.omega)
    u0 = linspace_values(*u_range, nu, label="u0")
    v0 = linspace_values(*v_range, nv, label="v0")
    grid = Grid.states(u0, v0)
    full = _start_states(model, grid, coordinates, base_state)
    rows = run_slices(
        basin_chunk,
        lambda sl: (model, grid.state_points(sl) if full is None else full[sl], options, settle_periods),
        grid.slices(engine.points_per_chunk(4 * DEFAULT_CHUNK_POINTS)),
        engine,
        "basins",
    )
    labels, atts = identify_attractors(rows)
    A = len(atts)
    width = max([a["points"].shape[0] for a in atts], default=1)
    auv = np.full((A, width, 2), np.nan)
    for k, a in enumerate(atts):
        auv[k, : a["points"].shape[0]] = a["points"][:, :2]
        a["fraction"] = a["count"] / labels.size
    keep = ("attractor", "period", "motion", "impact", "amplitude", "status", *ELEMENT_VARIABLES)
    data, extra = grid_variables({**rows, "attractor": labels}, keep, grid.names, grid.shape, model)
    extra_attrs = {}
    if full is not None:
        names = state_names(model, model.state_dim)
        extra_attrs["coordinates"] = (
            [names[c] for c in coordinates]
            if coordinates is not None
            else ["δ (reference element)", "δ' (reference element)"]
        )
    for k, dtype in (("period", np.int64), ("motion", np.int64), ("fraction", float), ("amplitude", float)):
        data["attractor_" + k] = ("attractor_index", np.array([a[k] for a in atts], dtype=dtype))
    for k, c in (("u", 0), ("v", 1)):
        data["attractor_" + k] = (("attractor_index", "cycle_point"), auv[..., c])
    coords = {"v0": v0, "u0": u0, "attractor_index": np.arange(A), "cycle_point": np.arange(width), **extra}
    return result_dataset(
        data,
        coords,
        "basins",
        model,
        options,
        settle_periods=int(settle_periods),
        diverged=int(np.count_nonzero(labels < 0)),
        **extra_attrs,
    )


@parameters(result_of("basins"))
def basins_json(ds: xr.Dataset) -> dict[str, Any]:
    """The ``basins --json`` summary: the attractors and the label grid.

    Returns
    -------
    dict
        ``omega``; ``attractors`` (``label``, ``period``, ``motion``, ``fraction`` of the grid,
        ``amplitude``, cycle ``points``); ``diverged_fraction``; the axes ``u0``, ``v0``; ``labels``
        (rows are v0 values).
    """
    per = ds["attractor_period"].values
    atts = []
    for k in range(ds.sizes["attractor_index"]):
        u = ds["attractor_u"].values[k]
        v = ds["attractor_v"].values[k]
        ok = np.isfinite(u)
        atts.append(
            {
                "label": k,
                "period": json_values(per[k], name="attractor_period"),
                "motion": json_values(ds["attractor_motion"].values[k], name="motion", period=per[k]),
                "fraction": float(ds["attractor_fraction"].values[k]),
                "amplitude": float(ds["attractor_amplitude"].values[k]),
                "points": np.column_stack([u[ok], v[ok]]).tolist(),
            }
        )
    lab = ds["attractor"].values
    return {
        "omega": float(json.loads(ds.attrs["model"])["omega"]),
        **({"coordinates": json.loads(ds.attrs["coordinates"])} if "coordinates" in ds.attrs else {}),
        "attractors": atts,
        "diverged_fraction": float(np.count_nonzero(lab < 0) / lab.size),
        "u0": json_values(ds["u0"]),
        "v0": json_values(ds["v0"]),
        "labels": lab.tolist(),
    }
