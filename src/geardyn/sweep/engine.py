"""The sweep engine: chunks of work run on an executor, checkpointed, returned in chunk order."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from ..errors import SweepError
from ..grid import chunked as _chunked
from ..model import ModelError
from .checkpoints import CheckpointStore
from .executors import SchedulerLost, run_in_process, run_on_dask, run_on_executor, run_on_pool
from .options import SweepOptions
from .progress import Progress, print_summary

__all__ = ["DEFAULT_CHUNK_POINTS", "Chunk", "SweepFailed", "SweepInterrupted", "chunked", "concat_results",
           "run_chunks"]

#: Default number of parameter points per chunk.
DEFAULT_CHUNK_POINTS = 16


class SweepInterrupted(SweepError):
    """A sweep stopped by Ctrl-C; the finished chunks are kept in the checkpoint (if any).

    Parameters
    ----------
    finished, total : int
        Chunks finished (including those loaded on resume) and chunks in the sweep.
    checkpoint : Path or None
        The checkpoint directory holding the finished chunks.

    Attributes
    ----------
    finished, total, checkpoint
        As given.
    """

    def __init__(self, finished: int, total: int, checkpoint: Path | None) -> None:
        self.finished = finished
        self.total = total
        self.checkpoint = checkpoint
        if checkpoint is not None:
            msg = (
                f"interrupted: {finished} of {total} chunks finished and saved in {checkpoint}; "
                "run the same command again with --resume to complete the sweep"
            )
        else:
            msg = (
                f"interrupted: {finished} of {total} chunks finished, none saved (no --out); "
                "give --out to make a sweep resumable"
            )
        super().__init__(msg)


class SweepFailed(SweepError, RuntimeError):
    """A sweep stopped by a fault outside it (e.g. the Dask scheduler was lost); finished chunks are kept.

    Parameters
    ----------
    reason : str
        What stopped the sweep.
    finished, total, checkpoint
        As for :class:`SweepInterrupted`.
    """

    def __init__(self, reason: str, finished: int, total: int, checkpoint: Path | None) -> None:
        self.reason = reason
        self.finished = finished
        self.total = total
        self.checkpoint = checkpoint
        if checkpoint is not None:
            tail = (f"{finished} of {total} chunks finished and saved in {checkpoint}; "
                    "run the same command again with --resume to complete the sweep")
        else:
            tail = f"{finished} of {total} chunks finished, none saved (no --out)"
        super().__init__(f"sweep stopped: {reason}; {tail}")


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
    """Slices cutting range(n) into consecutive chunks of at most ``size`` points (:func:`geardyn.grid.chunked`)."""
    return _chunked(n, size)


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
    keys = results[0].keys()
    return {k: np.concatenate([r[k] for r in results], axis=0) for k in keys}


def run_chunks(
    chunks: Sequence[Chunk],
    engine: SweepOptions | None = None,
    *,
    store: CheckpointStore | None = None,
    description: str = "sweep",
    **engine_kw: Any,
) -> list[dict[str, np.ndarray]]:
    """Run ``chunks`` and return their results in chunk order.

    The results are the same whatever the executor, worker count or resumption: each chunk is a
    pure function of its arguments, and the results are put back in chunk order.

    Parameters
    ----------
    chunks : sequence of Chunk
        The work; ``Chunk.index`` must be unique (it names the checkpoint file).
    engine : SweepOptions, optional
        Executor (``executor``, else a Dask ``scheduler``, else ``workers`` local processes, 1: in
        this process), checkpoint, resume and progress.  ``chunk_points`` is not used here (the
        chunks are already cut).
    store : CheckpointStore, optional
        Where finished chunks are saved (overrides ``engine.checkpoint`` and ``engine.resume``).
    description : str
        Label of the progress bar and of the summary line.
    **engine_kw
        Fields of :class:`SweepOptions` given one by one (``workers=2``, ``checkpoint=path``, …),
        applied on top of ``engine``.

    Returns
    -------
    list of dict
        One result per chunk, in the order of ``chunks``.

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
    results: dict[int, dict[str, np.ndarray]] = store.open(chunks) if store is not None else {}
    todo = [c for c in chunks if c.index not in results]
    bar = Progress(len(chunks), len(results), description) if opts.progress else None

    def finished(c: Chunk, r: dict[str, np.ndarray]) -> None:
        if store is not None:
            store.save(c.index, r)
        results[c.index] = r
        if bar:
            bar.advance()

    where = store.directory if store is not None else None
    try:
        try:
            if not todo:
                pass
            elif opts.executor is not None:
                run_on_executor(opts.executor, todo, finished)
            elif opts.scheduler is not None:
                run_on_dask(opts.scheduler, todo, finished)
            elif opts.workers == 1:
                run_in_process(todo, finished)
            else:
                run_on_pool(int(opts.workers), todo, finished)
        finally:
            if bar:
                bar.close()
    except KeyboardInterrupt:
        raise SweepInterrupted(len(results), len(chunks), where) from None
    except SchedulerLost as e:
        raise SweepFailed(str(e), len(results), len(chunks), where) from None
    out = [results[c.index] for c in chunks]
    if opts.progress:
        print_summary(description, out)
    return out
