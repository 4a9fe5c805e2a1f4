"""The sweep engine: chunks of work run on an executor, checkpointed, returned in chunk order."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SweepError, SweepFailed, SweepInterrupted  # noqa: F401  (raised here; defined with the errors)
from ..grid import Grid
from ..grid import chunked as _chunked
from ..model import GearModel, IntegrationOptions, ModelError
from .checkpoints import CheckpointStore
from .executors import SchedulerLost, run_on_dask, run_on_executor, run_on_pool, run_on_threads
from .options import SweepOptions
from .progress import Progress, print_summary

__all__ = [
    "CHUNK_SECONDS",
    "DEFAULT_CHUNK_POINTS",
    "MIN_CHUNKS",
    "MIN_CHUNK_POINTS",
    "STEP_SECONDS",
    "Chunk",
    "SweepFailed",
    "SweepInterrupted",
    "chunk_slices",
    "chunked",
    "concat_results",
    "run_chunks",
]

#: Points per chunk of a sweep cut by count (``chunk_points``), the former default.
DEFAULT_CHUNK_POINTS = 16
#: Wall time aimed at per chunk when the chunks are sized by cost (s).  Long enough that what a chunk
#: costs besides its integration (building its models, classifying its points, the durable
#: checkpoint write with two fsyncs: a few ms) stays around 1 % of it; short enough that a kill -9
#: loses at most a second or so per worker, the progress bar moves, and the temporaries of the
#: chunks in flight stay small next to the result (about 11 000 points a chunk on a 10⁶-point map
#: of 30 periods).
CHUNK_SECONDS = 1.0
#: Nominal kernel time of one RK4 step on one thread (s), to turn estimated steps into seconds: the
#: default mode with statistics runs at about 3 ns per step (``docs/performance.md``, W1).
STEP_SECONDS = 3.0e-9
#: Fewest points in a cost-sized chunk: one set of SIMD lanes (``geardyn._kernel.LANES``).
MIN_CHUNK_POINTS = 16
#: Fewest chunks of a cost-sized sweep (when it has points enough), so that a small grid still keeps
#: up to 12 workers busy (12 divides evenly among 1, 2, 3, 4 and 6).
MIN_CHUNKS = 12


@dataclass(frozen=True)
class Chunk:
    """One unit of work: ``fn(*args)`` returns a dict of arrays with one row per point.

    Parameters
    ----------
    index : int
        Unique within a sweep (it names the checkpoint file).
    fn : callable
        A picklable module-level function.
    args : tuple
        Its arguments (picklable; compact arrays rather than model objects where possible).
    """

    index: int
    fn: Callable[..., dict[str, np.ndarray]]
    args: tuple


def chunked(n: int, size: int = DEFAULT_CHUNK_POINTS) -> list[slice]:
    """Slices cutting range(n) into consecutive chunks of at most ``size`` points (:func:`geardyn.grid.chunked`).

    Parameters
    ----------
    n : int
        Number of points.
    size : int
        Points per chunk, default :data:`DEFAULT_CHUNK_POINTS`.

    Returns
    -------
    list of slice
    """
    return _chunked(n, size)


def chunk_slices(
    grid: Grid,
    base: GearModel,
    options: IntegrationOptions,
    engine: SweepOptions,
    *,
    lyapunov: bool = False,
    default: int | None = None,
) -> list[slice]:
    """How a sweep over ``grid`` is cut into chunks.

    ``engine.chunk_points`` (or ``default``) given: slices of that many points.  Otherwise the
    chunks are sized by estimated cost: a point costs N(ω) · (transient + periods) RK4 steps (twice
    that with tangents for exponents), and each chunk holds about :data:`CHUNK_SECONDS` of work at
    :data:`STEP_SECONDS` per step, with at least :data:`MIN_CHUNK_POINTS` points and at least
    :data:`MIN_CHUNKS` chunks (:meth:`geardyn.grid.Grid.cost_slices`).  The cut depends on the grid
    and the options only, never on the worker count, and the results never depend on the cut.

    Parameters
    ----------
    grid : Grid
        The sweep's points.
    base : GearModel
        The base model (its ω where ω is not swept).
    options : IntegrationOptions
        Step and periods per point.
    engine : SweepOptions
        Its ``chunk_points`` (None: by cost).
    lyapunov : bool
        Exponents for every point (tangent propagation over the recorded periods).
    default : int, optional
        Points per chunk when ``engine.chunk_points`` is None (None: by cost).

    Returns
    -------
    list of slice

    Raises
    ------
    ModelError
        With ``lyapunov``, where the damping contracts the perturbations below double precision within a
        forcing period at some ω of the grid (:func:`geardyn.validate.exponents_computable`).
    """
    if lyapunov:
        from ..validate import exponents_computable

        exponents_computable(base, grid.omegas(base))
    if engine.chunk_points is not None or default is not None:
        return grid.slices(engine.points_per_chunk(default if default is not None else DEFAULT_CHUNK_POINTS))
    n = grid.steps_per_period(base, options.dtau).astype(float)
    costs = n * (options.transient + options.periods * (2.0 if lyapunov else 1.0))
    return grid.cost_slices(costs, CHUNK_SECONDS / STEP_SECONDS, MIN_CHUNK_POINTS, MIN_CHUNKS)


def concat_results(results: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Concatenate chunk results along their first axis.

    Parameters
    ----------
    results : sequence of dict of ndarray
        Chunk results with the same keys.

    Returns
    -------
    dict of ndarray

    Raises
    ------
    ModelError
        For no results (an empty grid).
    """
    if not results:
        raise ModelError("empty parameter grid: no chunk results to assemble")
    return {k: np.concatenate([r[k] for r in results], axis=0) for k in results[0]}


def run_chunks(
    chunks: Sequence[Chunk],
    engine: SweepOptions | None = None,
    *,
    store: CheckpointStore | None = None,
    description: str = "sweep",
    sink: Callable[[int, dict[str, np.ndarray]], None] | None = None,
    **engine_kw: Any,
) -> list[dict[str, np.ndarray]] | None:
    """Run ``chunks`` and return their results in chunk order (or hand each to ``sink`` as it finishes).

    The results are the same whatever the executor, worker count or resumption: each chunk is a
    pure function of its arguments, and the results are put back in chunk order.  With ``sink``
    nothing is kept: each result, computed or loaded from the checkpoint on resume, is handed to
    ``sink(position, result)`` (``position``: its place in ``chunks``) in the order they finish,
    so that the caller can write it where it belongs (:class:`geardyn.analysis.points.RowSink`)
    and the sweep never holds more than the chunks in flight.

    Parameters
    ----------
    chunks : sequence of Chunk
        The work; ``Chunk.index`` must be unique (it names the checkpoint file).
    engine : SweepOptions, optional
        Executor (``executor``, else a Dask ``scheduler``, else ``workers`` chunks at a time on
        threads of this process, or in ``workers`` local processes with ``processes``),
        checkpoint, resume and progress.  ``chunk_points`` is not used here (the
        chunks are already cut).
    store : CheckpointStore, optional
        Where finished chunks are saved (overrides ``engine.checkpoint`` and ``engine.resume``).
    description : str
        Label of the progress bar and of the summary line.
    sink : callable, optional
        ``sink(position, result)``, called once per chunk in the calling thread; the results are
        then not returned.
    **engine_kw
        Fields of :class:`SweepOptions` given one by one (``workers=2``, ``checkpoint=path``, …),
        applied on top of ``engine``.

    Returns
    -------
    list of dict or None
        One result per chunk, in the order of ``chunks``; None with ``sink``.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C; the chunks finished so far are kept in the store.
    SweepFailed
        When the Dask scheduler is lost; the chunks finished so far are kept in the store.
    SweepError
        For a checkpoint directory that cannot be used, a checkpoint of another sweep, or an
        unreachable scheduler.
    ModelError
        For invalid options (``workers``) or chunk indices that are not unique.
    """
    opts = SweepOptions.merge(engine, "run_chunks", **engine_kw)
    chunks = list(chunks)
    if len({c.index for c in chunks}) != len(chunks):
        raise ModelError("chunks: indices must be unique")
    if store is None and opts.checkpoint is not None:
        store = CheckpointStore(opts.checkpoint, resume=opts.resume)
    position = {c.index: k for k, c in enumerate(chunks)}
    results: dict[int, dict[str, np.ndarray]] = {}
    done: set[int] = set()
    statuses: list[dict[str, np.ndarray]] = []  # with a sink: what the summary line counts

    def accept(index: int, r: dict[str, np.ndarray]) -> None:
        done.add(index)
        if sink is None:
            results[index] = r
            return
        sink(position[index], r)
        if opts.progress and "status" in r:
            statuses.append({"status": np.asarray(r["status"], dtype=np.int8)})  # small codes, 1 byte a point

    if store is not None:
        for i, r in store.finished(chunks):
            accept(i, r)
    todo = [c for c in chunks if c.index not in done]
    bar = Progress.for_chunks(chunks, done, description) if opts.progress else None

    def finished(c: Chunk, r: dict[str, np.ndarray]) -> None:
        if store is not None:
            store.save_later(c.index, r)
        accept(c.index, r)
        if bar:
            bar.advance(c)

    where = store.directory if store is not None else None
    try:
        try:
            if not todo:
                pass
            elif opts.executor is not None:
                run_on_executor(opts.executor, todo, finished)
            elif opts.scheduler is not None:
                run_on_dask(opts.scheduler, todo, finished)
            elif opts.processes:
                run_on_pool(int(opts.workers), todo, finished)
            else:
                run_on_threads(int(opts.workers), todo, finished)
        finally:
            if bar:
                bar.close()
            if store is not None:
                store.flush()  # every finished chunk is on disk before the sweep returns or raises
    except KeyboardInterrupt:
        raise SweepInterrupted(len(done), len(chunks), where) from None
    except SchedulerLost as e:
        raise SweepFailed(str(e), len(done), len(chunks), where) from None
    if sink is not None:
        if opts.progress:
            print_summary(description, statuses)
        return None
    out = [results[c.index] for c in chunks]
    if opts.progress:
        print_summary(description, out)
    return out
