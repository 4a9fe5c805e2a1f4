"""What the sweeps over many points share: the initial state, the chunks, the rows, the Dataset.

A bifurcation diagram, a two-parameter map and a basin map all cut a :class:`~geardyn.grid.Grid`
into chunks for the sweep engine (:func:`geardyn.sweep.run_chunks`), concatenate the per-point
rows the chunks return and assemble them into one annotated :class:`xarray.Dataset`.  The pieces
here do that once for all of them.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping, Sequence

import numpy as np
import xarray as xr

from ..grid import Grid
from ..io import annotate, result_attrs
from ..model import GearModel, ModelError
from ..sweep import Chunk, SweepOptions, run_chunks

__all__ = ["initial_state", "concat_rows", "run_slices", "result_dataset"]


def initial_state(model: GearModel, state0: Sequence[float] | np.ndarray) -> tuple[float, ...]:
    """The initial state of a sweep as a tuple of floats, checked.

    Parameters
    ----------
    model : GearModel
        The base model (its ``state_dim`` is the length the state must have).
    state0 : sequence of float
        The initial state at θ = 0.

    Returns
    -------
    tuple of float
        One entry per state component (picklable, for the chunks of the sweep engine).

    Raises
    ------
    ModelError
        If a component is not finite.
    ValueError
        If the state does not have ``model.state_dim`` components.
    """
    s0 = np.asarray(state0, dtype=float).reshape(model.state_dim)
    if not np.all(np.isfinite(s0)):
        raise ModelError("initial state (u0, v0): must be finite")
    return tuple(float(x) for x in s0)


def concat_rows(results: Sequence[Mapping[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """The rows of consecutive chunks joined into one array per key (in chunk order).

    Parameters
    ----------
    results : sequence of dict of ndarray
        The chunk results, all with the keys of the first.

    Returns
    -------
    dict of ndarray
    """
    return {k: np.concatenate([r[k] for r in results]) for k in results[0]}


def run_slices(
    function: Callable[..., dict[str, np.ndarray]],
    args_of: Callable[[slice], tuple[Any, ...]],
    grid: Grid,
    engine: SweepOptions,
    default_chunk_points: int,
    description: str,
) -> dict[str, np.ndarray]:
    """Run ``function`` on consecutive slices of ``grid`` (independent points) and join the rows.

    Parameters
    ----------
    function : callable
        The chunk function (module-level, so that workers can import it).
    args_of : callable
        Its positional arguments for one slice of the flat point index.
    grid : Grid
        The points of the sweep.
    engine : SweepOptions
        Where and how the sweep runs; its ``chunk_points`` (else ``default_chunk_points``) sets the
        points per chunk.
    default_chunk_points : int
        Points per chunk when ``engine`` does not say.
    description : str
        Name of the sweep in progress reports.

    Returns
    -------
    dict of ndarray
        One row per grid point, in the grid's flat order.

    Raises
    ------
    SweepError
        When the sweep cannot run (see :func:`geardyn.sweep.run_chunks`).
    """
    chunks = [Chunk(i, function, args_of(sl))
              for i, sl in enumerate(grid.slices(engine.points_per_chunk(default_chunk_points)))]
    return concat_rows(run_chunks(chunks, engine, description=description))


def result_dataset(data: Mapping[str, Any], coords: Mapping[str, Any], kind: str, model: GearModel,
                   options: Any, **extra: Any) -> xr.Dataset:
    """A sweep's Dataset: its variables, the standard attributes and the registry's metadata.

    Parameters
    ----------
    data : mapping
        Variables as ``name -> (dims, values)``.
    coords : mapping
        Coordinates.
    kind : str
        The result's ``geardyn_kind``.
    model : GearModel
        The base model (stored as JSON).
    options : IntegrationOptions
        The integration options (stored as JSON).
    **extra
        Further global attributes (:func:`geardyn.io.result_attrs`).

    Returns
    -------
    xarray.Dataset
        With ``units``/``long_name`` (and flags) of every variable from :data:`geardyn.io.VARIABLES`.
    """
    ds = xr.Dataset(dict(data), coords=dict(coords), attrs=result_attrs(kind, model, options, **extra))
    return annotate(ds)
