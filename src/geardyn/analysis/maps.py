"""Two-parameter maps: motion, impact state, amplitude and largest exponent over a grid.

The grid is x values × y values of any two model parameters (e.g. ω × ξ0, ω × D).  Like a
bifurcation sweep, each point either starts from the same initial state (``fixed``: the points
are independent and cut into many chunks) or continues the end state of its left neighbour along
each row (``continue``: one chunk per row, rows in parallel, x increasing).  The result is one
Dataset with dimensions named after the two parameters, ``(y, x)``.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import xarray as xr

from ..grid import Grid, build_models
from ..io import annotate, result_attrs
from ..model import GearModel, IntegrationOptions, ModelError, canonical_param
from ..sweep import Chunk, SweepOptions, chunk_slices, run_chunks
from .bifurcation import MODES, _LONG_NAMES, grid_chunk
from .classify import IMPACT_LABELS, MOTION_LABELS, SETTLE_PERIODS, motion_label

__all__ = ["parameter_map", "map_json", "MAP_VARIABLES"]

#: Per-point variables kept in a map (Poincaré points are not kept: a map can hold 10⁶ points).
MAP_VARIABLES = ("period", "motion", "impact", "status", "loops", "amplitude", "rms", "mean", "u_min", "u_max",
                 "fraction_separation", "fraction_back", "lle", "lle_err", "lambda2")


def parameter_map(
    model: GearModel,
    x_param: str,
    x_values: Sequence[float],
    y_param: str,
    y_values: Sequence[float],
    *,
    mode: str = "fixed",
    state0: Sequence[float] = (0.0, 0.0),
    options: IntegrationOptions = IntegrationOptions(),
    lyapunov: bool = False,
    settle_periods: int = SETTLE_PERIODS,
    engine: SweepOptions | None = None,
    **engine_kw: Any,
) -> xr.Dataset:
    """Map of the steady response over a grid of two parameters.

    Parameters
    ----------
    model : GearModel
        Base model; ``x_param`` and ``y_param`` are set at each grid point.
    x_param, y_param : str
        Two different parameter names (see :data:`geardyn.model.PARAMETER_HELP`).
    x_values, y_values : sequence of float
        Grid values (sorted ascending).
    mode : {'fixed', 'continue'}
        Every point from ``state0``, or continuation along x within each row.
    lyapunov : bool
        Largest exponent for every point (otherwise only for non-periodic points).
    engine : SweepOptions, optional
        Where and how the sweep runs; ``chunk_points`` is the number of grid points per chunk in
        fixed mode (default: sized by cost, :func:`geardyn.sweep.chunk_slices`).
    **engine_kw
        Fields of :class:`~geardyn.sweep.SweepOptions` given one by one.
    Other parameters as for :func:`~geardyn.analysis.bifurcation.bifurcation`.

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
    """
    eng = SweepOptions.merge(engine, "parameter_map", **engine_kw)
    xn, yn = canonical_param(x_param), canonical_param(y_param)
    if xn == yn:
        raise ModelError(f"map: x and y must be different parameters, got {xn!r} twice")
    if mode not in MODES:
        raise ModelError(f"mode: must be one of {', '.join(MODES)}, got {mode!r}")
    xv, yv = Grid.range(xn, x_values).values(xn), Grid.range(yn, y_values).values(yn)
    grid = Grid("product", [yn, xn], [yv, xv])  # row-major: y rows, x fastest
    # validate without building the whole grid: every value of each axis, and the four corners (the only
    # constraint that couples two parameters, Σ|κ_r| < 1, is largest at a corner); the step must be
    # smaller than the shortest forcing period, i.e. that of the largest ω
    for v in xv:
        model.with_param(xn, float(v))
    for v in yv:
        model.with_param(yn, float(v))
    corners = build_models(model, grid.names, np.array([[yv[0], xv[0]], [yv[0], xv[-1]], [yv[-1], xv[0]],
                                                        [yv[-1], xv[-1]]]))
    options.check_for(max(m.omega for m in corners))
    s0 = np.asarray(state0, dtype=float).reshape(2)
    if not np.all(np.isfinite(s0)):
        raise ModelError("initial state (u0, v0): must be finite")
    s0t = (float(s0[0]), float(s0[1]))
    common = (s0t, options, lyapunov, settle_periods)
    if mode == "fixed":
        chunks = [Chunk(i, grid_chunk, (model, grid.names, grid.points(sl)) + common + (False, MAP_VARIABLES))
                  for i, sl in enumerate(chunk_slices(grid, model, options, eng, lyapunov=lyapunov))]
    else:  # one continuation row per chunk, x increasing
        nx = xv.size
        chunks = [Chunk(i, grid_chunk, (model, grid.names, grid.points(slice(i * nx, (i + 1) * nx))) + common
                        + (True, MAP_VARIABLES)) for i in range(yv.size)]
    results = run_chunks(chunks, eng, description=f"map {yn} × {xn}")
    cat = {k: np.concatenate([r[k] for r in results]) for k in results[0]}
    shape = (yv.size, xv.size)
    ds = xr.Dataset({k: ((yn, xn), v.reshape(shape)) for k, v in cat.items()}, coords={yn: yv, xn: xv})
    for k, (u, ln) in _LONG_NAMES.items():
        if k in ds.variables:
            ds[k].attrs.update(units=u, long_name=ln)
    for n in (xn, yn):
        if n not in ("omega", "xi0", "fp", "D"):
            ds[n].attrs.update(units="rad" if n.startswith("phi") else "1", long_name=f"parameter {n}")
    ds["motion"].attrs.update(flag_values=list(MOTION_LABELS),
                              flag_meanings=" ".join(v.replace(" ", "_") for v in MOTION_LABELS.values()))
    ds["impact"].attrs.update(flag_values=list(IMPACT_LABELS),
                              flag_meanings=" ".join(v.replace(" ", "_") for v in IMPACT_LABELS.values()))
    ds.attrs.update(result_attrs("map", model, options, x=xn, y=yn, mode=mode, state0=list(s0t),
                                 lyapunov=bool(lyapunov), settle_periods=int(settle_periods)))
    return annotate(ds)


def map_json(ds: xr.Dataset) -> dict[str, Any]:
    """The ``map --json`` summary: parameters, grid values and per-point grids (rows are y values)."""
    xn, yn = str(ds.attrs["x"]), str(ds.attrs["y"])

    def grid(var: str, f) -> list[list[Any]]:
        return [[f(v, i, j) for j, v in enumerate(row)] for i, row in enumerate(ds[var].values)]

    per = ds["period"].values

    def num(v, i, j):
        return float(v) if np.isfinite(v) else None

    codes, counts = np.unique(ds["motion"].values, return_counts=True)
    return {
        "x": xn, "y": yn,
        "x_values": [float(v) for v in ds[xn].values],
        "y_values": [float(v) for v in ds[yn].values],
        "motion": grid("motion", lambda v, i, j: motion_label(v, per[i, j])),
        "impact": grid("impact", lambda v, i, j: IMPACT_LABELS[int(v)]),
        "period": grid("period", lambda v, i, j: int(v) if v > 0 else None),
        "amplitude": grid("amplitude", num),
        "lle": grid("lle", num),
        "motion_counts": {MOTION_LABELS[int(c)]: int(n) for c, n in zip(codes, counts)},
    }
