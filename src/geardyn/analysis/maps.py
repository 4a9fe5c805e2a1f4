"""Two-parameter maps: motion, impact state, amplitude and largest exponent over a grid.

The grid is x values × y values of any two model parameters (e.g. ω × ξ0, ω × D).  Like a
bifurcation sweep, each point either starts from the same initial state (``fixed``: the points
are independent and cut into many chunks) or continues the end state of its left neighbour along
each row (``continue``: one chunk per row, rows in parallel, x increasing).  The result is one
Dataset with dimensions named after the two parameters, ``(y, x)``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from .._docfill import parameters, result_of
from ..grid import Grid, build_models, param_name
from ..io import json_values
from ..model import ModelError
from ..sweep import chunk_slices
from .bifurcation import ELEMENT_VARIABLES, MODES, grid_chunk
from .classify import MOTION_LABELS
from .points import grid_variables, initial_state, result_dataset, run_slices, sweep_function

__all__ = ["parameter_map", "map_json", "MAP_VARIABLES"]

#: Per-point variables kept in a map (Poincaré points are not kept: a map can hold 10⁶ points).
MAP_VARIABLES = (
    "period",
    "motion",
    "impact",
    "status",
    "loops",
    "amplitude",
    "rms",
    "mean",
    "u_min",
    "u_max",
    "fraction_separation",
    "fraction_back",
    "lle",
    "lle_err",
    "lambda2",
)
#: What a map keeps of each point: :data:`MAP_VARIABLES` and, for a system of several elements, its per-element ones.
_KEEP = MAP_VARIABLES + tuple(ELEMENT_VARIABLES)


@sweep_function("parameter_map")
def parameter_map(
    model: Any,
    x_param: str,
    x_values: Sequence[float],
    y_param: str,
    y_values: Sequence[float],
    *,
    mode: str = "fixed",
    state0,
    options,
    lyapunov,
    settle_periods,
    engine,  # shared sweep keywords (SWEEP_KEYWORDS)
) -> xr.Dataset:
    """Map of the steady response over a grid of two parameters.

    Parameters
    ----------
    model : System
        Base model; ``x_param`` and ``y_param`` are set at each grid point.
    x_param, y_param : str
        Two different parameter names (see :data:`geardyn.model.PARAMETER_HELP`).
    x_values, y_values : sequence of float
        Grid values (sorted ascending).
    mode : {'fixed', 'continue'}
        Every point from ``state0``, or continuation along x within each row (one chunk per row).

    Returns
    -------
    xarray.Dataset
        Dimensions ``(y_param, x_param)``; variables :data:`MAP_VARIABLES`.

    Raises
    ------
    ModelError
        For unknown or equal parameters, an unknown mode, an empty or non-finite axis, a grid
        value the model refuses, a non-finite initial state or invalid engine options.
    SweepError
        When the sweep cannot run (see :func:`geardyn.sweep.run_chunks`).
    TypeError
        For a keyword that is not an engine option.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, parameter_map
    >>> ds = parameter_map(GearModel(), "omega", [0.6, 0.8], "xi0", [0.05, 0.1],
    ...                    options=IntegrationOptions(transient=50, periods=8), progress=False)
    >>> ds["period"].values.tolist()
    [[1, 2], [1, 2]]
    """
    xn, yn = param_name(x_param), param_name(y_param)
    if xn == yn:
        raise ModelError(f"map: x and y must be different parameters, got {xn!r} twice")
    if mode not in MODES:
        raise ModelError(f"mode: must be one of {', '.join(MODES)}, got {mode!r}")
    xv, yv = Grid.range(xn, x_values).values(xn), Grid.range(yn, y_values).values(yn)
    grid = Grid("product", [yn, xn], [yv, xv])  # row-major: y rows, x fastest
    # validate without building the whole grid: every value of each axis, and the four corners (the only
    # constraint that couples two parameters, Σ|κ_r| < 1, is largest at a corner); the step must be
    # smaller than the shortest forcing period, i.e. that of the largest ω
    for name, axis in ((xn, xv), (yn, yv)):
        for v in axis:
            model.with_param(name, float(v))
    corners = build_models(model, grid.names, np.array([[y, x] for y in yv[[0, -1]] for x in xv[[0, -1]]]))
    options.check_for(max(m.omega for m in corners))
    s0t = initial_state(model, state0)
    cont = mode != "fixed"  # one continuation row per chunk, x increasing
    cat = run_slices(
        grid_chunk,
        lambda sl: (model, grid.names, grid.points(sl), s0t, options, lyapunov, settle_periods, cont, _KEEP),
        grid.slices(xv.size) if cont else chunk_slices(grid, model, options, engine, lyapunov=lyapunov),
        engine,
        f"map {yn} × {xn}",
    )
    data, coords = grid_variables(cat, _KEEP, (yn, xn), (yv.size, xv.size), model)
    return result_dataset(
        data,
        {yn: yv, xn: xv, **coords},
        "map",
        model,
        options,
        x=xn,
        y=yn,
        mode=mode,
        state0=list(s0t),
        lyapunov=bool(lyapunov),
        settle_periods=int(settle_periods),
    )


@parameters(result_of("parameter_map"))
def map_json(ds: xr.Dataset) -> dict[str, Any]:
    """The ``map --json`` summary: parameters, grid values and per-point grids (rows are y values).

    Returns
    -------
    dict
        ``x``, ``y``, ``x_values``, ``y_values``; grids ``motion``, ``impact``, ``period``,
        ``amplitude``, ``lle`` (converted by :func:`geardyn.io.json_values`); ``motion_counts``.
    """
    xn, yn = str(ds.attrs["x"]), str(ds.attrs["y"])
    per = ds["period"].values
    codes, counts = np.unique(ds["motion"].values, return_counts=True)
    out: dict[str, Any] = {"x": xn, "y": yn, "x_values": json_values(ds[xn]), "y_values": json_values(ds[yn])}
    for k in ("motion", "impact", "period", "amplitude", "lle"):
        out[k] = json_values(ds[k], period=per if k == "motion" else None)
    out["motion_counts"] = {MOTION_LABELS[int(c)]: int(n) for c, n in zip(codes, counts)}
    return out
