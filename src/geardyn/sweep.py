"""The sweep engine: a parameter grid cut into chunks, run on any executor, checkpointed.

A sweep is a list of :class:`Chunk` s, each a picklable module-level function and its arguments
returning a dict of NumPy arrays (one row per point of the chunk).  :func:`run_chunks` runs them
in-process (``workers=1``), on a local process pool (``workers=N``), on a running Dask cluster
(``scheduler="tcp://host:port"``) or on any :class:`concurrent.futures.Executor`, and returns the
results in chunk order, so the assembled result is bit-identical whatever the engine or worker
count.

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
  it and exits with code 130.  In process (``workers=1``) a kernel call cannot be interrupted:
  the Ctrl-C takes effect when the running kernel call returns.
- **Lost workers.**  A local worker process that dies breaks the pool: the pool is restarted and
  the unfinished chunks resubmitted (at most :data:`MAX_POOL_RESTARTS` times).  On Dask, a chunk
  whose worker is lost is rescheduled by the scheduler; a chunk that raises is retried
  :data:`DASK_RETRIES` times and one that keeps killing workers is resubmitted at most
  :data:`MAX_RESUBMITS` times.  A lost scheduler stops the sweep with :class:`SweepFailed`
  (one line; the finished chunks are kept for ``--resume``).
- **Divergence** is not a fault: chunk functions mark diverged points in their ``status`` array
  (:data:`ST_DIVERGED`) and the sweep goes on; :func:`divergence_summary` counts them and the
  progress output ends with "N of M points diverged".
"""

from __future__ import annotations

import hashlib
import io as _io
import json
import logging
import multiprocessing
import os
import pickle
import signal
import threading
import time
import zipfile
from concurrent.futures import CancelledError, Executor, Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from .io import atomic_write_bytes
from .model import GearModel, ModelError

__all__ = [
    "Chunk",
    "SweepFailed",
    "SweepInterrupted",
    "checkpoint_dir",
    "chunked",
    "concat_results",
    "divergence_summary",
    "fingerprint",
    "grid_models",
    "remove_checkpoint",
    "run_chunks",
]

#: Default number of parameter points per chunk.
DEFAULT_CHUNK_POINTS = 16
#: File name of the checkpoint manifest (fingerprint of the sweep and its number of chunks).
MANIFEST = "manifest.json"
#: Status code of a diverged point in a chunk's ``status`` array (``integrate.ST_DIVERGED``).
ST_DIVERGED = 1
#: Dask: times a chunk that raised an exception is retried by the scheduler.
DASK_RETRIES = 2
#: Dask: times a chunk whose workers kept dying (``KilledWorker``) is submitted again.
MAX_RESUBMITS = 3
#: Local pool: times a broken process pool (a worker process died) is restarted.
MAX_POOL_RESTARTS = 3
#: Seconds a sweep must run before its progress bar appears (short sweeps stay quiet).
PROGRESS_DELAY = 0.5
#: Seconds between checks of a local worker process that the sweep's main process still exists.
PARENT_CHECK_INTERVAL = 1.0
#: Seconds to wait for a Dask scheduler to answer.
DASK_CONNECT_TIMEOUT = 10


class SweepInterrupted(Exception):
    """A sweep stopped by Ctrl-C; the finished chunks are kept in the checkpoint (if any).

    Attributes
    ----------
    finished, total : int
        Chunks finished (including those loaded on resume) and chunks in the sweep.
    checkpoint : Path or None
        The checkpoint directory holding the finished chunks.
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


class SweepFailed(RuntimeError):
    """A sweep stopped by a fault outside it (e.g. the Dask scheduler was lost); finished chunks are kept.

    Attributes as :class:`SweepInterrupted`, plus ``reason``.
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


class _SchedulerLost(Exception):
    """Internal: the connection to the Dask scheduler was lost."""


@dataclass(frozen=True)
class Chunk:
    """One unit of work: ``fn(*args)`` returns a dict of arrays with one row per point."""

    index: int
    fn: Callable[..., dict[str, np.ndarray]]
    args: tuple


# ------------------------------------------------------------------------------------ grids
def grid_models(base: GearModel, params: Sequence[str], values: Sequence[Sequence[float]]) -> list[GearModel]:
    """Models for the Cartesian grid of ``values`` over ``params`` (last parameter fastest)."""
    if not params:
        raise ModelError("empty parameter grid: give at least one parameter")
    if len(params) != len(values):
        raise ModelError(f"parameter grid: {len(params)} parameters but {len(values)} value lists")
    arrays = [np.asarray(v, dtype=float).ravel() for v in values]
    for p, a in zip(params, arrays):
        if a.size == 0:
            raise ModelError(f"{p}: empty grid (num must be >= 1)")
        if not np.all(np.isfinite(a)):
            raise ModelError(f"{p}: grid values must be finite numbers")
    mesh = np.meshgrid(*arrays, indexing="ij")
    flat = [m.ravel() for m in mesh]
    out = []
    for i in range(flat[0].size):
        m = base
        for p, f in zip(params, flat):
            m = m.with_param(p, float(f[i]))
        out.append(m)
    return out


def chunked(n: int, size: int = DEFAULT_CHUNK_POINTS) -> list[slice]:
    """Slices cutting range(n) into consecutive chunks of at most ``size`` points."""
    if size < 1:
        raise ModelError(f"chunk size: must be >= 1, got {size}")
    return [slice(i, min(i + size, n)) for i in range(0, n, size)]


def concat_results(results: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Concatenate chunk results along their first axis."""
    if not results:
        raise ModelError("empty parameter grid: no chunk results to assemble")
    keys = results[0].keys()
    return {k: np.concatenate([r[k] for r in results], axis=0) for k in keys}


def divergence_summary(results: Sequence[dict[str, np.ndarray]] | dict[str, np.ndarray]) -> tuple[int, int] | None:
    """(diverged, total) over the ``status`` entries of chunk results; None if they have no status."""
    if isinstance(results, dict):
        results = [results]
    st = [np.asarray(r["status"]) for r in results if "status" in r]
    if not st:
        return None
    return int(sum(int(np.count_nonzero(s == ST_DIVERGED)) for s in st)), int(sum(s.size for s in st))


# ------------------------------------------------------------------------------ checkpoints
def checkpoint_dir(out_file: str | Path) -> Path:
    """The checkpoint directory used for the sweep whose final result goes to ``out_file``.

    ``results/bifurcation.nc`` → ``results/bifurcation.nc.chunks``: next to the output, so that
    ``--out`` alone decides where a resumable sweep keeps its finished chunks.
    """
    p = Path(out_file)
    return p.with_name(p.name + ".chunks")


def remove_checkpoint(directory: str | Path) -> None:
    """Delete a checkpoint directory (after the final result has been written)."""
    d = Path(directory)
    if not d.is_dir():
        return
    for p in d.iterdir():
        if p.name == MANIFEST or p.name.startswith(("chunk-", ".chunk-", f".{MANIFEST}")):
            p.unlink(missing_ok=True)
    try:
        d.rmdir()
    except OSError:  # something else lives there: leave it
        pass


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
    """A finished chunk, or None if it is missing or unreadable (it is then run again)."""
    p = _chunk_path(directory, index)
    if not p.exists():
        return None
    try:
        with np.load(p, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile):
        p.unlink(missing_ok=True)
        return None


def _clear_chunks(directory: Path) -> None:
    for p in directory.glob("chunk-*.npz"):
        p.unlink(missing_ok=True)
    _clear_temporaries(directory)


def _clear_temporaries(directory: Path) -> None:
    """Remove temporary files left by a process killed in the middle of a write."""
    for p in directory.glob(".*.tmp"):
        p.unlink(missing_ok=True)


def prepare_checkpoint(directory: Path, chunks: Sequence[Chunk], resume: bool) -> set[int]:
    """Create or check the checkpoint directory; returns the indices of chunks already finished.

    Without ``resume`` any previous content is discarded.  With ``resume`` the manifest must
    hold the fingerprint of the same sweep (same chunk functions and arguments).
    """
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise ModelError(f"out: cannot create checkpoint directory {directory} ({e.strerror or e})") from None
    if not directory.is_dir():
        raise ModelError(f"out: checkpoint path {directory} exists and is not a directory")
    fp = fingerprint(chunks)
    man = directory / MANIFEST
    old: dict[str, Any] = {}
    if man.exists():
        try:
            old = json.loads(man.read_text())
        except (OSError, ValueError):
            old = {}
    if resume and old and old.get("fingerprint") != fp:
        raise ModelError(
            f"resume: checkpoint {directory} holds a different sweep (parameters, options or chunk size differ); "
            "run without --resume to start over, or use another --out"
        )
    if not resume or not old:
        _clear_chunks(directory)  # a fresh start, or chunks without a manifest: not trusted
        atomic_write_bytes(man, json.dumps({"fingerprint": fp, "chunks": len(chunks)}).encode())
        return set()
    _clear_temporaries(directory)
    return {c.index for c in chunks if _chunk_path(directory, c.index).exists()}


# ------------------------------------------------------------------------------ execution
def _init_worker(main_pid: int | None = None) -> None:
    """Local worker processes ignore Ctrl-C (the parent stops them) and use one kernel thread.

    A worker never starts processes itself; its default start method is set to ``spawn`` so that
    numba does not take a named (resource-tracked) semaphore for its threading-layer start-up,
    which a worker terminated on Ctrl-C would leave for the resource tracker to report.  With
    ``main_pid`` a watchdog thread ends the worker once that process is gone (killed with
    SIGKILL, say), which the worker would otherwise never notice.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    multiprocessing.set_start_method("spawn", force=True)
    if main_pid is not None:
        threading.Thread(target=_exit_with, args=(main_pid,), daemon=True, name="geardyn-watchdog").start()
    from .integrate import set_threads

    set_threads(1)


def _exit_with(pid: int) -> None:
    """End this process once the process ``pid`` has ended."""
    while True:
        time.sleep(PARENT_CHECK_INTERVAL)
        if not _alive(pid):
            os._exit(1)


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists and has not ended (a zombie waiting to be reaped has ended)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, but not ours to signal
        return True
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):  # no /proc: trust kill(pid, 0)
        return True


def _call(fn: Callable[..., dict[str, np.ndarray]], args: tuple) -> dict[str, np.ndarray]:
    """Run one chunk.  NumPy's divide and invalid warnings are off: diverged points are NaN by
    design (their ``status`` says so), and a sweep must not print a warning per chunk."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return fn(*args)


def _call_single_thread(fn: Callable[..., dict[str, np.ndarray]], args: tuple) -> dict[str, np.ndarray]:
    """Run a chunk with one kernel thread in the calling thread (Dask: one chunk per worker thread)."""
    from .integrate import set_threads

    set_threads(1)
    return _call(fn, args)


@contextmanager
def _sigint_ignored() -> Iterator[None]:
    """Ignore SIGINT while worker processes are started, so that they inherit SIG_IGN.

    Local worker processes must not receive the terminal's Ctrl-C (it goes to the whole
    foreground process group); a spawned process inherits an ignored signal, so it ignores
    SIGINT from its first instruction.  Only possible in the main thread.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


@contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Hold a Ctrl-C back until the block is done, then raise it (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
    if caught:
        raise KeyboardInterrupt


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
    chunks : sequence of Chunk
        The work; ``Chunk.index`` must be unique (it names the checkpoint file).
    workers : int
        Local worker processes (1: run in this process with every kernel thread).  Worker
        processes come from a fork server (or ``spawn``) and run one kernel thread each.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``); the chunks run on its workers,
        which must have geardyn installed (the ``dask`` extra).
    executor : concurrent.futures.Executor, optional
        Any executor to use instead (overrides ``workers`` and ``scheduler``); it is not shut down.
    checkpoint : path, optional
        Directory where each finished chunk is written durably (see :func:`checkpoint_dir`).
    resume : bool
        Skip the chunks already finished in ``checkpoint``.
    progress : bool
        Show a progress bar with ETA on stderr once the sweep has run :data:`PROGRESS_DELAY`
        seconds, and end with a line "N of M points diverged" (for results with a ``status``).
    description : str
        Label of the progress bar and of the summary line.

    Returns
    -------
    list of dict
        One result per chunk, in the order of ``chunks``.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C; the chunks finished so far are kept in ``checkpoint``.
    SweepFailed
        When the Dask scheduler is lost; the chunks finished so far are kept in ``checkpoint``.
    ModelError
        For invalid arguments, a checkpoint of another sweep, or an unreachable scheduler.
    """
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ModelError(f"workers: must be an integer >= 1, got {workers!r}")
    chunks = list(chunks)
    if len({c.index for c in chunks}) != len(chunks):
        raise ModelError("chunks: indices must be unique")
    ckdir = Path(checkpoint) if checkpoint is not None else None
    done: set[int] = prepare_checkpoint(ckdir, chunks, resume) if ckdir is not None else set()
    results: dict[int, dict[str, np.ndarray]] = {}
    for i in sorted(done):
        r = _load_chunk(ckdir, i)  # type: ignore[arg-type]
        if r is not None:
            results[i] = r
    todo = [c for c in chunks if c.index not in results]

    bar = _Progress(len(chunks), len(results), description) if progress else None

    def finished(c: Chunk, r: dict[str, np.ndarray]) -> None:
        if ckdir is not None:
            _save_chunk(ckdir, c.index, r)
        results[c.index] = r
        if bar:
            bar.advance()

    try:
        try:
            if not todo:
                pass
            elif executor is not None:
                _run_on_executor(executor, todo, finished)
            elif scheduler is not None:
                _run_on_dask(scheduler, todo, finished)
            elif workers == 1:
                for c in todo:
                    finished(c, _call(c.fn, c.args))
            else:
                _run_on_pool(workers, todo, finished)
        finally:
            if bar:
                bar.close()
    except KeyboardInterrupt:
        raise SweepInterrupted(len(results), len(chunks), ckdir) from None
    except _SchedulerLost as e:
        raise SweepFailed(str(e), len(results), len(chunks), ckdir) from None
    out = [results[c.index] for c in chunks]
    if progress:
        _print_summary(description, out)
    return out


def _run_on_executor(executor: Executor, todo: Sequence[Chunk], finished: Callable) -> None:
    """Any concurrent.futures executor (not shut down here); pending chunks cancelled on error."""
    futs: dict[Future, Chunk] = {executor.submit(_call, c.fn, c.args): c for c in todo}
    try:
        for f in as_completed(futs):
            finished(futs[f], f.result())
    except BaseException:
        for f in futs:
            f.cancel()
        raise


#: Modules the local worker processes import before they are forked (forkserver start method).
POOL_PRELOAD = ("geardyn.integrate", "geardyn.sweep", "geardyn.analysis.steady")


def _pool_context():
    """Start method of local worker processes: a fork server, else spawn; never plain fork.

    Forking this process is unsafe once the kernel's OpenMP threads run.  The fork server is a
    fresh process started once (with SIGINT ignored, see :func:`_sigint_ignored`) that imports
    :data:`POOL_PRELOAD` and forks the workers from there, so restarting a pool is cheap.
    """
    methods = multiprocessing.get_all_start_methods()
    if "forkserver" in methods:
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(list(POOL_PRELOAD))
        return ctx
    return multiprocessing.get_context("spawn")


def _start_forkserver() -> None:
    with _sigint_ignored():  # the server, and so every worker forked from it, ignores SIGINT
        from multiprocessing import forkserver

        forkserver.ensure_running()


def _new_pool(ctx, workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_init_worker, initargs=(os.getpid(),))


def local_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of local worker processes (fork server, one kernel thread each) for callers that
    submit their own work, e.g. several sweeps sharing one pool (``executor=`` of the analyses)."""
    ctx = _pool_context()
    if ctx.get_start_method() == "forkserver":
        _start_forkserver()
        return _new_pool(ctx, workers)
    with _sigint_ignored():
        return _new_pool(ctx, workers)


def _run_on_pool(workers: int, todo: Sequence[Chunk], finished: Callable) -> None:
    """A local pool of worker processes, restarted if a worker process dies."""
    ctx = _pool_context()
    remaining = {c.index: c for c in todo}
    restarts = 0
    while remaining:
        pool = None
        futs: dict[Future, Chunk] = {}
        try:
            if ctx.get_start_method() == "forkserver":
                _start_forkserver()
                with _sigint_deferred():  # starting the workers waits for the server: not interruptible
                    pool = _new_pool(ctx, min(workers, len(remaining)))
                    futs = {pool.submit(_call, c.fn, c.args): c for c in remaining.values()}
            else:
                with _sigint_ignored():  # spawned workers inherit SIGINT ignored
                    pool = _new_pool(ctx, min(workers, len(remaining)))
                    futs = {pool.submit(_call, c.fn, c.args): c for c in remaining.values()}
            for f in as_completed(futs):
                c = futs[f]
                r = f.result()
                finished(c, r)
                del remaining[c.index]
        except BrokenProcessPool:
            restarts += 1
            if restarts > MAX_POOL_RESTARTS:
                raise
        finally:
            if pool is not None:
                _stop_pool(pool, futs)


def _stop_pool(pool: ProcessPoolExecutor, futs: dict[Future, Chunk]) -> None:
    """Shut the pool down; if chunks are still pending (an interrupt or an error), stop its workers first.

    The worker processes are terminated (their chunks in flight are lost) and the pool then fails
    the pending futures itself; they are not cancelled here, which would race with that.
    """
    if any(not f.done() for f in futs):
        for p in list((getattr(pool, "_processes", None) or {}).values()):
            try:
                p.terminate()
            except (OSError, AttributeError):
                pass
    pool.shutdown(wait=True)


def _run_on_dask(address: str, todo: Sequence[Chunk], finished: Callable) -> None:
    """Chunks as Dask tasks: rescheduled if their worker is lost, retried if they raise."""
    from distributed import as_completed as dask_as_completed

    try:
        from distributed import KilledWorker
    except ImportError:  # pragma: no cover - older distributed
        from distributed.scheduler import KilledWorker

    client = _dask_client(address)
    futs: dict[Any, Chunk] = {}
    # the client logs a lost scheduler as errors with tracebacks; the sweep reports it in one line
    log = logging.getLogger("distributed.client")
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        def submit(c: Chunk):
            f = client.submit(_call_single_thread, c.fn, c.args, pure=False, retries=DASK_RETRIES)
            futs[f] = c
            return f

        resubmits: dict[int, int] = {}
        ac = dask_as_completed([submit(c) for c in todo], loop=client.loop)
        for f in ac:
            c = futs.pop(f)
            try:
                r = f.result()
            except KilledWorker:
                n = resubmits.get(c.index, 0) + 1
                if n > MAX_RESUBMITS:
                    raise
                resubmits[c.index] = n
                ac.add(submit(c))
                continue
            except (CancelledError, OSError) as e:  # the scheduler went away (or cancelled our work)
                if isinstance(e, OSError) and client.status == "running":
                    raise  # an error of the chunk function itself
                futs.clear()
                raise _SchedulerLost(f"lost the Dask scheduler {address} ({type(e).__name__})") from None
            finished(c, r)
            f.release()
    finally:
        try:
            if futs:
                client.cancel(list(futs))
        finally:
            client.close()
            log.setLevel(level)


def _dask_client(address: str):
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - depends on the optional extra
        raise ModelError("scheduler: dask.distributed is not installed (pip install 'geardyn[dask]')") from None
    try:
        return Client(address, timeout=DASK_CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as e:
        raise ModelError(f"scheduler: cannot connect to {address!r} ({e})") from None


# ------------------------------------------------------------------------------ progress
def _stderr_console():
    from rich.console import Console

    return Console(stderr=True, soft_wrap=True)


def _print_summary(description: str, results: Sequence[dict[str, np.ndarray]]) -> None:
    s = divergence_summary(results) if results else None
    if s is None:
        return
    bad, total = s
    note = " (marked 'diverged', their data masked)" if bad else ""
    _stderr_console().print(f"{description}: {bad} of {total} points diverged{note}", markup=False, highlight=False)


class _Progress:
    """A rich progress bar with ETA on stderr, drawn once the sweep has run :data:`PROGRESS_DELAY` s."""

    def __init__(self, total: int, completed: int, description: str) -> None:
        self._total = total
        self._completed = completed
        self._description = description
        self._lock = threading.Lock()
        self._p = None
        self._t = None
        self._closed = False
        self._timer = threading.Timer(PROGRESS_DELAY, self._start)
        self._timer.daemon = True
        if PROGRESS_DELAY > 0:
            self._timer.start()
        else:
            self._start()

    def _start(self) -> None:
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn,
                                   TimeRemainingColumn)

        with self._lock:
            if self._closed or self._p is not None:
                return
            self._p = Progress(
                TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn("chunks"),
                TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                console=_stderr_console(), transient=False,
            )
            self._p.start()
            self._t = self._p.add_task(self._description, total=self._total, completed=self._completed)

    def advance(self) -> None:
        with self._lock:
            self._completed += 1
            if self._p is not None:
                self._p.update(self._t, completed=self._completed)

    def close(self) -> None:
        self._timer.cancel()
        with self._lock:
            self._closed = True
            if self._p is not None:
                self._p.stop()
