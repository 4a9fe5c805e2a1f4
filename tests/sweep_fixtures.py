"""A small steady-state sweep on the sweep engine, shared by the sweep tests.

Worker processes import this module by name: local pools inherit ``sys.path``, and the Dask
test puts this directory on the workers' ``PYTHONPATH``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
import xarray as xr

from geardyn.analysis.steady import summarize_batch
from geardyn.integrate import integrate_batch
from geardyn.io import result_attrs
from geardyn.model import GearModel, IntegrationOptions
from geardyn.sweep import Chunk, chunked, concat_results, run_chunks
from geardyn.system import build_models

#: Options of the test sweeps: short, so that a chunk of one point takes a fraction of a second.
FAST = IntegrationOptions(transient=40, periods=16)


def steady_chunk(
    models: Sequence[GearModel], options: IntegrationOptions, state0: tuple[float, float] = (0.0, 0.0)
) -> dict[str, np.ndarray]:
    """Steady response of each model from the same initial state (one row per point)."""
    res = integrate_batch(models, state0, options)
    out = summarize_batch(res)
    out["poincare"] = res.poincare
    return out


def crash_once_chunk(marker: str, models: Sequence[GearModel], options: IntegrationOptions) -> dict[str, np.ndarray]:
    """Like :func:`steady_chunk`, but the first call (per ``marker`` file) kills its own process."""
    try:
        fd = os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return steady_chunk(models, options)
    os.close(fd)
    os._exit(13)


def interrupt_at_chunk(
    flag: str, stop_at: int, index: int, models: Sequence[GearModel], options: IntegrationOptions
) -> dict[str, np.ndarray]:
    """Like :func:`steady_chunk`, but chunk ``stop_at`` raises KeyboardInterrupt (a Ctrl-C in
    process) while the file ``flag`` exists."""
    if index == stop_at and os.path.exists(flag):
        raise KeyboardInterrupt
    return steady_chunk(models, options)


def make_chunks(
    param: str,
    values: Sequence[float],
    options: IntegrationOptions = FAST,
    chunk_points: int = 2,
    base: GearModel = GearModel(),
) -> list[Chunk]:
    models = build_models(base, [param], np.asarray(values, float)[:, None])
    return [Chunk(i, steady_chunk, (models[s], options)) for i, s in enumerate(chunked(len(models), chunk_points))]


def to_dataset(
    param: str,
    values: Sequence[float],
    results: list[dict[str, np.ndarray]],
    options: IntegrationOptions = FAST,
    base: GearModel = GearModel(),
) -> xr.Dataset:
    r = concat_results(results)
    data = {k: ((param,), v) for k, v in r.items() if k != "poincare"}
    data["poincare_u"] = ((param, "section"), r["poincare"][:, :, 0])
    data["poincare_v"] = ((param, "section"), r["poincare"][:, :, 1])
    return xr.Dataset(
        data,
        coords={param: np.asarray(values, dtype=float), "section": np.arange(r["poincare"].shape[1])},
        attrs=result_attrs("sweep-test", base, options, param=param),
    )


def sweep(
    param: str,
    values: Sequence[float],
    options: IntegrationOptions = FAST,
    chunk_points: int = 2,
    base: GearModel = GearModel(),
    **run_kw,
) -> xr.Dataset:
    """Run the sweep with ``run_chunks(**run_kw)`` and assemble its Dataset."""
    chunks = make_chunks(param, values, options, chunk_points, base)
    return to_dataset(param, values, run_chunks(chunks, **run_kw), options, base)
