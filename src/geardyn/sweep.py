"""The sweep engine: a parameter grid cut into chunks, run on any executor, checkpointed.

A sweep is a list of :class:`Chunk` s, each a picklable module-level function and its arguments
returning a dict of NumPy arrays (one row per point of the chunk).  :func:`run_chunks` runs them
in-process (``workers=1``), on a local process pool (``workers=N``) or on a running Dask cluster
(``scheduler="tcp://host:port"``), and returns the results in chunk order, so the assembled
result is the same whatever the engine or worker count.  With a checkpoint directory each
finished chunk is written atomically as it completes; ``resume=True`` skips chunks already there.
"""

from __future__ import annotations

import hashlib
import io as _io
import json
import pickle
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from .io import atomic_write_bytes
from .model import GearModel, ModelError

#: Default number of parameter points per chunk.
DEFAULT_CHUNK_POINTS = 16
MANIFEST = "manifest.json"


@dataclass(frozen=True)
class Chunk:
    """One unit of work: ``fn(*args)`` returns a dict of arrays with one row per point."""

    index: int
    fn: Callable[..., dict[str, np.ndarray]]
    args: tuple


def grid_models(base: GearModel, params: Sequence[str], values: Sequence[Sequence[float]]) -> list[GearModel]:
    """Models for the Cartesian grid of ``values`` over ``params`` (last parameter fastest)."""
    if not params:
        raise ModelError("empty parameter grid: give at least one parameter")
    arrays = [np.asarray(v, dtype=float) for v in values]
    for p, a in zip(params, arrays):
        if a.size == 0:
            raise ModelError(f"{p}: empty grid (num must be >= 1)")
    mesh = np.meshgrid(*arrays, indexing="ij")
    flat = [m.ravel() for m in mesh]
    out = []
    for i in range(flat[0].size):
        m = base
        for p, f in zip(params, flat):
            m = m.with_param(p, float(f[i]))
        out.append(m)
    return out


def fingerprint(chunks: Sequence[Chunk]) -> str:
    """A hash identifying the work of a sweep (functions and arguments of all chunks)."""
    h = hashlib.sha256()
    for c in chunks:
        h.update(f"{c.index}:{c.fn.__module__}.{c.fn.__qualname__}:".encode())
        h.update(pickle.dumps(c.args, protocol=4))
    return h.hexdigest()


def _chunk_path(directory: Path, index: int) -> Path:
    return directory / f"chunk-{index:06d}.npz"


def _save_chunk(directory: Path, index: int, result: dict[str, np.ndarray]) -> None:
    buf = _io.BytesIO()
    np.savez(buf, **result)
    atomic_write_bytes(_chunk_path(directory, index), buf.getvalue())


def _load_chunk(directory: Path, index: int) -> dict[str, np.ndarray] | None:
    p = _chunk_path(directory, index)
    if not p.exists():
        return None
    with np.load(p, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _init_worker() -> None:
    """Worker processes use one kernel thread each: parallelism comes from the processes."""
    from .integrate import set_threads

    set_threads(1)


def _call(fn: Callable[..., dict[str, np.ndarray]], args: tuple) -> dict[str, np.ndarray]:
    return fn(*args)


def prepare_checkpoint(directory: Path, chunks: Sequence[Chunk], resume: bool) -> set[int]:
    """Create or check the checkpoint directory; returns the indices of chunks already finished."""
    directory.mkdir(parents=True, exist_ok=True)
    fp = fingerprint(chunks)
    man = directory / MANIFEST
    if man.exists():
        old = json.loads(man.read_text())
        if old.get("fingerprint") != fp:
            raise ModelError(
                f"checkpoint {directory}: it holds a different sweep; use another --out or delete it"
            )
        if not resume:
            for c in chunks:
                _chunk_path(directory, c.index).unlink(missing_ok=True)
    atomic_write_bytes(man, json.dumps({"fingerprint": fp, "chunks": len(chunks)}).encode())
    if not resume:
        return set()
    return {c.index for c in chunks if _chunk_path(directory, c.index).exists()}


def run_chunks(
    chunks: Sequence[Chunk],
    *,
    workers: int = 1,
    scheduler: str | None = None,
    executor: Executor | None = None,
    checkpoint: str | Path | None = None,
    resume: bool = False,
    progress: bool = False,
    description: str = "sweep",
) -> list[dict[str, np.ndarray]]:
    """Run ``chunks`` and return their results in chunk order.

    Parameters
    ----------
    workers : int
        Local worker processes (1: run in this process).
    scheduler : str, optional
        Address of a running Dask scheduler; the chunks run on its workers (needs the ``dask`` extra).
    executor : concurrent.futures.Executor, optional
        Any executor to use instead (overrides ``workers`` and ``scheduler``).
    checkpoint : path, optional
        Directory where each finished chunk is written atomically.
    resume : bool
        Skip the chunks already finished in ``checkpoint``.
    progress : bool
        Show a progress bar with ETA on stderr.
    """
    if workers < 1:
        raise ModelError(f"workers: must be >= 1, got {workers}")
    chunks = list(chunks)
    ckdir = Path(checkpoint) if checkpoint is not None else None
    done: set[int] = prepare_checkpoint(ckdir, chunks, resume) if ckdir is not None else set()
    results: dict[int, dict[str, np.ndarray]] = {}
    for i in done:
        r = _load_chunk(ckdir, i)  # type: ignore[arg-type]
        if r is not None:
            results[i] = r
    todo = [c for c in chunks if c.index not in results]

    bar = _Progress(len(chunks), len(results), description) if progress else None

    def finished(c: Chunk, r: dict[str, np.ndarray]) -> None:
        results[c.index] = r
        if ckdir is not None:
            _save_chunk(ckdir, c.index, r)
        if bar:
            bar.advance()

    try:
        if executor is None and scheduler is None and workers == 1:
            for c in todo:
                finished(c, c.fn(*c.args))
        else:
            own = executor is None
            client = None
            if executor is None and scheduler is not None:
                client = _dask_client(scheduler)
                executor = client.get_executor()
            elif executor is None:
                executor = ProcessPoolExecutor(max_workers=workers, initializer=_init_worker)
            try:
                futs: dict[Future, Chunk] = {executor.submit(_call, c.fn, c.args): c for c in todo}
                for f in as_completed(futs):
                    finished(futs[f], f.result())
            finally:
                if own:
                    executor.shutdown(wait=True, cancel_futures=True)
                if client is not None:
                    client.close()
    finally:
        if bar:
            bar.close()
    return [results[c.index] for c in chunks]


def _dask_client(address: str):
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - depends on the optional extra
        raise ModelError("scheduler: dask.distributed is not installed (pip install 'geardyn[dask]')") from None
    try:
        return Client(address, timeout=10)
    except (OSError, TimeoutError) as e:
        raise ModelError(f"scheduler: cannot connect to {address!r} ({e})") from None


def concat_results(results: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Concatenate chunk results along their first axis."""
    keys = results[0].keys()
    return {k: np.concatenate([r[k] for r in results], axis=0) for k in keys}


class _Progress:
    """A rich progress bar with ETA on stderr (only drawn on a terminal or when forced)."""

    def __init__(self, total: int, completed: int, description: str) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        self._p = Progress(
            TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn("chunks"),
            TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
            console=Console(stderr=True), transient=False,
        )
        self._p.start()
        self._t = self._p.add_task(description, total=total, completed=completed)

    def advance(self) -> None:
        self._p.advance(self._t)

    def close(self) -> None:
        self._p.stop()


def chunked(n: int, size: int = DEFAULT_CHUNK_POINTS) -> list[slice]:
    """Slices cutting range(n) into consecutive chunks of at most ``size`` points."""
    if size < 1:
        raise ModelError(f"chunk size: must be >= 1, got {size}")
    return [slice(i, min(i + size, n)) for i in range(0, n, size)]
