"""Where the chunks of a sweep run: in process, a local process pool, Dask, or any Executor.

Every way of running goes through one loop, :func:`drain`: submit every chunk to a
:class:`concurrent.futures.Executor`, hand each result to the engine as it completes, resubmit a
chunk when the executor's fault policy says so.  What differs is the executor and its policy:

- **in process** (the default): the chunks run on threads of this process, whose kernel releases
  the GIL while it integrates.  ``workers=1``: :data:`PIPELINE` chunks at a time, each on every
  kernel thread of the caller (the kernel's thread pool integrates one chunk while the next is
  built or the last classified); ``workers=N``: N chunks at a time, each on 1/N of the caller's
  kernel threads (at least one).  No process is started and nothing is pickled.  A Ctrl-C stops
  the sweep once the chunks running are finished (their results are kept).
- **local pool** (``processes=True``, ``workers=N``): worker processes from a fork server (never
  plain fork: the kernel's OpenMP threads make forking unsafe), one kernel thread each, ignoring
  SIGINT (the parent stops them).  A worker that dies breaks the pool: it is restarted and the
  unfinished chunks resubmitted, at most :data:`MAX_POOL_RESTARTS` times.
- **Dask** (``scheduler="tcp://host:port"``): ``Client.get_executor()`` of a client of that
  scheduler.  A chunk whose worker is lost is rescheduled by the scheduler, one that raises is
  retried :data:`DASK_RETRIES` times, one that keeps killing workers is resubmitted at most
  :data:`MAX_RESUBMITS` times; a lost scheduler stops the sweep (:class:`SchedulerLost`).
- **any executor** given by the caller (not shut down here); a Dask ``ClientExecutor`` gets the
  Dask policy.
"""

from __future__ import annotations

import functools
import logging
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import (
    CancelledError,
    Executor,
    Future,
    InvalidStateError,
    ProcessPoolExecutor,
    ThreadPoolExecutor,
    as_completed,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager

import numpy as np

from ..errors import SweepError
from .progress import count_into, pool_counter

__all__ = [
    "DASK_CONNECT_TIMEOUT",
    "DASK_RETRIES",
    "MAX_POOL_RESTARTS",
    "MAX_RESUBMITS",
    "PIPELINE",
    "POOL_PRELOAD",
    "SchedulerLost",
    "dask_executor",
    "drain",
    "local_pool",
    "release_free_memory",
    "run_on_executor",
    "run_on_pool",
    "run_on_threads",
]

#: Dask: times a chunk that raised an exception is retried by the scheduler.
DASK_RETRIES = 2
#: Dask: times a chunk whose workers kept dying (``KilledWorker``) is submitted again.
MAX_RESUBMITS = 3
#: Local pool: times a broken process pool (a worker process died) is restarted.
MAX_POOL_RESTARTS = 3
#: Seconds between checks of a local worker process that the sweep's main process still exists.
PARENT_CHECK_INTERVAL = 1.0
#: Seconds to wait for a Dask scheduler to answer.
DASK_CONNECT_TIMEOUT = 10
#: In process with ``workers=1``: chunks at a time, each on every kernel thread (one integrating
#: while another is prepared or classified in Python).
PIPELINE = 2
#: In process: arrays at least this large (bytes) are given back to the system when freed (glibc's
#: ``M_MMAP_THRESHOLD``, fixed instead of growing with the largest block freed), so that the
#: temporaries of chunks run on several threads do not stay resident in per-thread heaps.
MMAP_THRESHOLD = 64 * 1024
#: Modules the local worker processes import before they are forked (forkserver start method).
POOL_PRELOAD = (
    "geardyn._forkserver_quiet",
    "geardyn.integrate",
    "geardyn.sweep",
    "geardyn.analysis.steady",
    "geardyn.analysis.bifurcation",
)

Finished = Callable[[object, dict], None]


class SchedulerLost(Exception):
    """The connection to the Dask scheduler was lost (the engine reports it as ``SweepFailed``)."""


# ------------------------------------------------------------------------------ chunk calls
def call_chunk(fn: Callable[..., dict[str, np.ndarray]], args: tuple) -> dict[str, np.ndarray]:
    """Run one chunk.  NumPy's divide and invalid warnings are off: diverged points are NaN by
    design (their ``status`` says so), and a sweep must not print a warning per chunk."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return fn(*args)


def call_chunk_single_thread(fn: Callable[..., dict[str, np.ndarray]], args: tuple) -> dict[str, np.ndarray]:
    """Run a chunk with one kernel thread in the calling thread (Dask: one chunk per worker thread)."""
    from ..integrate import set_threads

    set_threads(1)
    return call_chunk(fn, args)


# ------------------------------------------------------------------------------ the one loop
def submit_all(executor: Executor, todo: Sequence, call: Callable = call_chunk) -> dict[Future, object]:
    """Submit every chunk of ``todo``; future → chunk."""
    return {executor.submit(call, c.fn, c.args): c for c in todo}


def drain(
    executor: Executor,
    futs: dict[Future, object],
    finished: Finished,
    *,
    call: Callable = call_chunk,
    resubmit: Callable[[BaseException, object], bool] | None = None,
) -> None:
    """Hand each result of ``futs`` to ``finished`` as it completes.

    Parameters
    ----------
    executor : concurrent.futures.Executor
        Where a failed chunk is submitted again.
    futs : dict
        The submitted futures and their chunks.  Consumed: a future leaves it once its result has
        been handed on (so that the result is not held any longer), a resubmission enters it; what
        is left when this returns or raises is what did not finish.
    finished : callable
        ``finished(chunk, result)`` for each result.
    call : callable
        What a resubmission runs (default :func:`call_chunk`).
    resubmit : callable, optional
        ``resubmit(error, chunk) -> bool``: whether a chunk that raised runs again.

    A chunk whose future raises is submitted again when ``resubmit(error, chunk)`` returns True
    (the policy may also raise an error of its own); otherwise the error propagates.  On any
    error (a Ctrl-C included) the pending futures are cancelled.
    """
    try:
        while futs:
            for f in as_completed(list(futs)):
                c = futs.pop(f)
                try:
                    r = f.result()
                except BaseException as e:
                    if resubmit is None or not resubmit(e, c):
                        raise
                    futs[executor.submit(call, c.fn, c.args)] = c
                    continue
                finished(c, r)
                del f, r
    except SchedulerLost:
        raise  # nothing left to cancel on a lost scheduler
    except BaseException:
        for f in list(futs):
            f.cancel()
        raise


def run_on_threads(workers: int, todo: Sequence, finished: Finished) -> None:
    """Run the chunks on threads of this process (the kernel releases the GIL while it integrates).

    ``workers=1``: :data:`PIPELINE` chunks at a time, each on every kernel thread of the calling
    thread (``geardyn.integrate.set_threads``); ``workers=N``: N chunks at a time, each on 1/N of
    them (at least one).  On a Ctrl-C (or a chunk that raises) the chunks not started are
    cancelled and those running are waited for: their results are handed to ``finished`` (a
    kernel call cannot be interrupted), then the error propagates.

    Parameters
    ----------
    workers : int
        Chunks integrated at once (1: one at a time on every kernel thread, the next one prepared
        meanwhile).
    todo : sequence of Chunk
        The chunks.
    finished : callable
        ``finished(chunk, result)`` for each result, called in the calling thread.
    """
    import numba

    from ..integrate import set_threads

    _return_large_blocks()
    threads = max(1, int(numba.get_num_threads()))
    per_chunk = max(1, threads // workers)
    at_once = min(PIPELINE if workers == 1 else workers, len(todo))
    pool = ThreadPoolExecutor(
        max_workers=max(1, at_once), thread_name_prefix="geardyn-chunk", initializer=set_threads, initargs=(per_chunk,)
    )

    def done(c, r) -> None:
        finished(c, r)
        release_free_memory()

    futs = submit_all(pool, todo)
    try:
        drain(pool, futs, done)
    except BaseException:
        try:
            _finish_running(futs, finished)
        finally:
            pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


@functools.lru_cache(maxsize=1)
def _libc():
    """The C library when it is glibc (``mallopt``, ``malloc_trim``), else None."""
    import ctypes

    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:
        return None
    return libc if hasattr(libc, "malloc_trim") and hasattr(libc, "mallopt") else None


def _return_large_blocks() -> None:
    """Have glibc map every block of :data:`MMAP_THRESHOLD` bytes or more on its own (no-op elsewhere)."""
    libc = _libc()
    if libc is not None:
        libc.mallopt(-3, MMAP_THRESHOLD)  # M_MMAP_THRESHOLD


def release_free_memory() -> None:
    """Give the free pages of the heaps back to the system (glibc ``malloc_trim``; no-op elsewhere).

    Between the chunks of a sweep on threads, and between large figures, so that memory freed
    in one step is not counted in the process's resident size through the next.
    """
    libc = _libc()
    if libc is not None:
        libc.malloc_trim(0)


def _finish_running(futs: dict[Future, object], finished: Finished) -> None:
    """Wait for the chunks still running (not cancelled) and hand on those that succeed.

    A second Ctrl-C while waiting stops the wait (the threads finish their chunks unobserved).
    """
    running = [f for f in futs if not f.cancelled()]
    for f in wait(running).done:
        if not f.cancelled() and f.exception() is None:
            finished(futs[f], f.result())


def run_on_executor(executor: Executor, todo: Sequence, finished: Finished) -> None:
    """Any concurrent.futures executor (not shut down here); a Dask ClientExecutor gets the Dask policy.

    Parameters
    ----------
    executor : concurrent.futures.Executor
        The caller's executor.
    todo : sequence of Chunk
        The chunks.
    finished : callable
        ``finished(chunk, result)`` for each result.
    """
    if type(executor).__module__.startswith("distributed."):  # a Dask executor
        _run_dask_policy(executor, todo, finished, address=None)
        return
    drain(executor, submit_all(executor, todo), finished)


# ------------------------------------------------------------------------------ local pool
def _init_worker(main_pid: int | None = None, counter=None) -> None:
    """Local worker processes ignore Ctrl-C (the parent stops them) and use one kernel thread.

    A worker never starts processes itself; its default start method is set to ``spawn`` so that
    numba does not take a named (resource-tracked) semaphore for its threading-layer start-up,
    which a worker terminated on Ctrl-C would leave for the resource tracker to report.  With
    ``main_pid`` a watchdog thread ends the worker once that process is gone (killed with
    SIGKILL, say), which the worker would otherwise never notice.  With ``counter`` (a shared
    value from :func:`geardyn.sweep.progress.pool_counter`) the points the chunk functions report
    (:func:`geardyn.sweep.progress.tick`) are added to it for the parent's progress bar.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    count_into(counter)
    multiprocessing.set_start_method("spawn", force=True)
    if main_pid is not None:
        threading.Thread(target=_exit_with, args=(main_pid,), daemon=True, name="geardyn-watchdog").start()
    from ..integrate import set_threads

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


@contextmanager
def _sigint_handled(handler) -> Iterator[None]:
    """SIGINT goes to ``handler`` while the block runs (main thread only: elsewhere nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def _sigint_ignored():
    """Ignore SIGINT while worker processes are started, so that they inherit SIG_IGN.

    Local worker processes must not receive the terminal's Ctrl-C (it goes to the whole
    foreground process group); a spawned process inherits an ignored signal, so it ignores
    SIGINT from its first instruction.  Only possible in the main thread.
    """
    return _sigint_handled(signal.SIG_IGN)


@contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Hold a Ctrl-C back until the block is done, then raise it (main thread only)."""
    caught: list[int] = []
    with _sigint_handled(lambda signum, frame: caught.append(signum)):
        yield
    if caught:
        raise KeyboardInterrupt


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


@contextmanager
def _sigint_blocked() -> Iterator[None]:
    """Block SIGINT in this thread while the block runs (any thread): a process started meanwhile inherits the
    blocked signal from its first instruction (its interpreter's start-up included) and never sees a Ctrl-C."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _start_forkserver() -> None:
    """Start the fork server with SIGINT blocked (and ignored where this is the main thread): the server, its
    interpreter's start-up and imports, and every worker forked from it never see the terminal's Ctrl-C; the
    main process handles it and stops them.  The resource tracker is started first (its own start unblocks
    SIGINT in this thread)."""
    from multiprocessing import forkserver, resource_tracker

    resource_tracker.ensure_running()
    with _sigint_ignored(), _sigint_blocked():
        forkserver.ensure_running()


def _new_pool(ctx, workers: int, counter=None) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_init_worker, initargs=(os.getpid(), counter)
    )


def local_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of local worker processes (fork server, one kernel thread each).

    For callers that submit their own work, e.g. several sweeps sharing one pool
    (``executor=`` of :class:`~geardyn.sweep.SweepOptions`).  The caller shuts it down.

    Parameters
    ----------
    workers : int
        Worker processes.

    Returns
    -------
    concurrent.futures.ProcessPoolExecutor
    """
    ctx = _pool_context()
    if ctx.get_start_method() == "forkserver":
        _start_forkserver()
        return _new_pool(ctx, workers)
    with _sigint_ignored():
        return _new_pool(ctx, workers)


def run_on_pool(workers: int, todo: Sequence, finished: Finished) -> None:
    """A local pool of worker processes owned by the sweep, restarted if a worker process dies.

    Parameters
    ----------
    workers : int
        Worker processes.
    todo : sequence of Chunk
        The chunks.
    finished : callable
        ``finished(chunk, result)`` for each result.

    Raises
    ------
    concurrent.futures.process.BrokenProcessPool
        When the pool broke more than :data:`MAX_POOL_RESTARTS` times.
    """
    ctx = _pool_context()
    remaining = {c.index: c for c in todo}
    restarts = 0

    def done(c, r) -> None:
        finished(c, r)
        del remaining[c.index]

    while remaining:
        pool = None
        futs: dict[Future, object] = {}
        try:
            # starting the workers (on submit) is not interruptible; spawned workers inherit SIGINT ignored
            if ctx.get_start_method() == "forkserver":
                _start_forkserver()
                guard = _sigint_deferred()
            else:
                guard = _sigint_ignored()
            with guard:
                # a fresh point counter per pool: a worker killed while holding its lock cannot stall the next
                pool = _new_pool(ctx, min(workers, len(remaining)), pool_counter(ctx))
                futs = submit_all(pool, list(remaining.values()))
            drain(pool, futs, done)
        except BrokenProcessPool:
            restarts += 1
            if restarts > MAX_POOL_RESTARTS:
                raise
        finally:
            if pool is not None:
                _stop_pool(pool, futs)


def _stop_pool(pool: ProcessPoolExecutor, futs: dict[Future, object]) -> None:
    """Shut the pool down; if chunks are still pending (an interrupt or an error), stop its workers first.

    The worker processes are terminated (their chunks in flight are lost) and the pool then fails
    the pending futures itself.
    """
    if not any(not f.done() for f in futs):
        pool.shutdown(wait=True)
        return
    with _pool_thread_quiet():
        for p in list((getattr(pool, "_processes", None) or {}).values()):
            try:
                p.terminate()
            except (OSError, AttributeError):
                pass
        pool.shutdown(wait=True, cancel_futures=True)  # joins the pool's management thread


def _from_pool_thread(args) -> bool:
    """Whether an uncaught thread exception is the pool's management thread failing a cancelled future.

    When its workers are terminated, the management thread of a ``ProcessPoolExecutor`` (Python < 3.12)
    marks every pending future as failed, and raises ``InvalidStateError`` for a future the sweep has
    already cancelled; nothing is lost (the sweep is stopping), so the traceback is not printed.
    """
    if not isinstance(args.exc_value, InvalidStateError):
        return False
    tb = args.exc_traceback
    while tb is not None:
        if tb.tb_frame.f_code.co_filename.endswith(os.path.join("concurrent", "futures", "process.py")):
            return True
        tb = tb.tb_next
    return False


@contextmanager
def _pool_thread_quiet() -> Iterator[None]:
    """Swallow the management thread's ``InvalidStateError`` while a pool is stopped (see :func:`_from_pool_thread`)."""
    old = threading.excepthook

    def hook(args) -> None:
        if not _from_pool_thread(args):
            old(args)

    threading.excepthook = hook
    try:
        yield
    finally:
        threading.excepthook = old


# ------------------------------------------------------------------------------ Dask
def _dask_client(address: str):
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - depends on the optional extra
        raise SweepError("scheduler: dask.distributed is not installed (pip install 'geardyn[dask]')") from None
    try:
        return Client(address, timeout=DASK_CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as e:
        raise SweepError(f"scheduler: cannot connect to {address!r} ({e})") from None


@contextmanager
def dask_executor(address: str) -> Iterator[Executor]:
    """``Client.get_executor()`` of a new client of the Dask scheduler at ``address`` (closed on exit).

    Chunks are submitted impure (every submission runs) with :data:`DASK_RETRIES` retries.

    Parameters
    ----------
    address : str
        ``tcp://host:port`` of a running scheduler.

    Yields
    ------
    concurrent.futures.Executor

    Raises
    ------
    SweepError
        When dask.distributed is not installed or the scheduler does not answer within
        :data:`DASK_CONNECT_TIMEOUT` seconds.
    """
    client = _dask_client(address)
    try:
        yield client.get_executor(pure=False, retries=DASK_RETRIES)
    finally:
        client.close()


def run_on_dask(address: str, todo: Sequence, finished: Finished) -> None:
    """Chunks on the Dask scheduler at ``address``: rescheduled if their worker is lost, retried if they raise."""
    with dask_executor(address) as ex:
        _run_dask_policy(ex, todo, finished, address=address)


def _run_dask_policy(executor: Executor, todo: Sequence, finished: Finished, address: str | None) -> None:
    try:
        from distributed import KilledWorker
    except ImportError:  # pragma: no cover - older distributed
        from distributed.scheduler import KilledWorker

    client = getattr(executor, "_client", None)
    where = address if address is not None else getattr(getattr(client, "scheduler", None), "address", "?")
    resubmits: dict[int, int] = {}

    def resubmit(e: BaseException, c) -> bool:
        if isinstance(e, KilledWorker):
            n = resubmits.get(c.index, 0) + 1
            if n > MAX_RESUBMITS:
                return False
            resubmits[c.index] = n
            return True
        if isinstance(e, (CancelledError, OSError)):  # the scheduler went away (or cancelled our work)
            if isinstance(e, OSError) and client is not None and client.status == "running":
                return False  # an error of the chunk function itself
            raise SchedulerLost(f"lost the Dask scheduler {where} ({type(e).__name__})") from None
        return False

    # the client logs a lost scheduler as errors with tracebacks; the sweep reports it in one line
    log = logging.getLogger("distributed.client")
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        drain(
            executor,
            submit_all(executor, todo, call_chunk_single_thread),
            finished,
            call=call_chunk_single_thread,
            resubmit=resubmit,
        )
    finally:
        log.setLevel(level)
