"""The sweep engine: a grid cut into chunks, run on any executor, checkpointed.

A sweep is a list of :class:`Chunk` s, each a picklable module-level function and its arguments
returning a dict of NumPy arrays (one row per point of the chunk).  :func:`run_chunks` runs them
on a :class:`concurrent.futures.Executor` — on threads of this process (the default: ``workers``
chunks at a time over the kernel, which releases the GIL), a local process pool
(``processes=True``), a running Dask cluster (``scheduler="tcp://host:port"``, through
``Client.get_executor()``) or any executor given — with an optional :class:`CheckpointStore`,
and returns the results in chunk order, so the assembled result is bit-identical whatever the
engine or worker count.  The analyses take these choices as one :class:`SweepOptions`.

Layout: :mod:`.engine` (chunks, :func:`run_chunks`, the interruption errors),
:mod:`.options` (:class:`SweepOptions`), :mod:`.checkpoints` (the store), :mod:`.executors`
(in process, local pool, Dask) and :mod:`.progress`.  The grid of a sweep is
:class:`geardyn.grid.Grid`.

Faults
------
- **Checkpoint and resume.**  With a checkpoint directory each finished chunk is written durably
  as it completes (temporary file, fsync, rename, fsync of the directory), next to a manifest
  holding a fingerprint of the sweep.  ``resume=True`` loads the chunks already there and runs
  only the others; a checkpoint of a different sweep is refused.  A process killed at any moment
  (even ``kill -9``) loses at most the chunks in flight, and a resumed sweep returns exactly the
  arrays of an uninterrupted one.
- **Ctrl-C.**  A :class:`KeyboardInterrupt` cancels the pending chunks, stops the local worker
  processes (which ignore SIGINT themselves, so they print nothing), keeps every finished chunk
  and raises :class:`SweepInterrupted`, whose one-line message says how to resume; the CLI prints
  it and exits with code 130.  In process a kernel call cannot be interrupted: the Ctrl-C takes
  effect once the chunks running have finished (they are kept too).
- **Lost workers.**  A local worker process that dies breaks the pool: the pool is restarted and
  the unfinished chunks resubmitted (at most :data:`MAX_POOL_RESTARTS` times).  On Dask, a chunk
  whose worker is lost is rescheduled by the scheduler; a chunk that raises is retried
  :data:`DASK_RETRIES` times and one that keeps killing workers is resubmitted at most
  :data:`MAX_RESUBMITS` times.  A lost scheduler stops the sweep with :class:`SweepFailed`
  (one line; the finished chunks are kept for ``--resume``).
- **Divergence** is not a fault: chunk functions mark diverged points in their ``status`` array
  (:data:`ST_DIVERGED`) and the sweep goes on; :func:`divergence_summary` counts them and the
  progress output ends with "N of M points diverged".

Errors: :class:`SweepInterrupted` and :class:`SweepFailed` are :class:`geardyn.errors.SweepError`
s, as are an unusable checkpoint directory, a resume of another sweep and an unreachable scheduler.
"""

from __future__ import annotations

from ..errors import SweepError
from ..grid import Grid
from .checkpoints import MANIFEST, CheckpointStore, checkpoint_dir, fingerprint, prepare_checkpoint, remove_checkpoint
from .engine import (
    CHUNK_SECONDS,
    DEFAULT_CHUNK_POINTS,
    MIN_CHUNK_POINTS,
    MIN_CHUNKS,
    STEP_SECONDS,
    Chunk,
    SweepFailed,
    SweepInterrupted,
    chunk_slices,
    chunked,
    concat_results,
    run_chunks,
)
from .executors import (
    DASK_CONNECT_TIMEOUT,
    DASK_RETRIES,
    MAX_POOL_RESTARTS,
    MAX_RESUBMITS,
    PIPELINE,
    POOL_PRELOAD,
    dask_executor,
    local_pool,
)
from .options import ENGINE_KEYWORDS, SweepOptions
from .progress import PROGRESS_DELAY, ST_DIVERGED, divergence_summary

__all__ = [
    "CHUNK_SECONDS",
    "MIN_CHUNKS",
    "MIN_CHUNK_POINTS",
    "STEP_SECONDS",
    "chunk_slices",
    "DASK_CONNECT_TIMEOUT",
    "DASK_RETRIES",
    "DEFAULT_CHUNK_POINTS",
    "ENGINE_KEYWORDS",
    "MANIFEST",
    "MAX_POOL_RESTARTS",
    "MAX_RESUBMITS",
    "PIPELINE",
    "POOL_PRELOAD",
    "PROGRESS_DELAY",
    "ST_DIVERGED",
    "CheckpointStore",
    "Chunk",
    "Grid",
    "SweepError",
    "SweepFailed",
    "SweepInterrupted",
    "SweepOptions",
    "checkpoint_dir",
    "chunked",
    "concat_results",
    "dask_executor",
    "divergence_summary",
    "fingerprint",
    "local_pool",
    "prepare_checkpoint",
    "remove_checkpoint",
    "run_chunks",
]
