"""Progress on stderr: a bar with ETA for long sweeps and long single computations, and the divergence summary.

A bar appears only once its computation has run :data:`PROGRESS_DELAY` seconds, so short runs stay
quiet.  A sweep counts **points** when every chunk function says how many points a chunk holds
(:func:`counts_points`) and reports the points it finishes through :func:`tick`:

- in this process (``workers=1``, or an executor running threads here) a tick advances the bar at once;
- in the workers of a local pool a tick adds to a counter in shared memory that the pool's
  initializer hands to every worker (:func:`pool_counter`); the bar polls it;
- elsewhere (Dask workers, a caller's process pool) ticks go nowhere and a chunk counts its points
  when its result arrives.

Chunks loaded from a checkpoint count their points at the start.  Chunk functions that do not say
how many points they hold are counted as chunks.  Single computations report through a callback
``progress(done, total)`` drawn by :func:`task_progress`.

On a terminal the bar is rich's live display.  When stderr is not a terminal (a file, a pipe, a log),
a live display would only be written when it stops, so the progress goes there as plain lines
instead: one when the bar would appear, then at most one every :data:`PLAIN_INTERVAL` seconds, and
a last one when the computation ends, each flushed.
"""

from __future__ import annotations

import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np

from .. import _cache_guard

__all__ = [
    "PLAIN_INTERVAL",
    "PROGRESS_DELAY",
    "POLL_INTERVAL",
    "ST_DIVERGED",
    "Progress",
    "chunk_points",
    "counts_points",
    "divergence_summary",
    "pool_counter",
    "task_progress",
    "tick",
]

#: Seconds a computation must run before its progress bar appears (short runs stay quiet).
PROGRESS_DELAY = 0.5
#: Seconds between two reads of the local pool's shared point counter by the bar.
POLL_INTERVAL = 0.2
#: Seconds between two plain progress lines when stderr is not a terminal.
PLAIN_INTERVAL = 5.0
#: Status code of a diverged point in a chunk's ``status`` array (``integrate.ST_DIVERGED``).
ST_DIVERGED = 1
#: Seconds a worker waits for the shared counter's lock before it drops a tick (a worker killed
#: while holding the lock must not stall the others).
_LOCK_TIMEOUT = 1.0

#: Where :func:`tick` goes in this process: the active bar, a worker's shared counter, or nowhere.
_SINK: Callable[[int], None] | None = None
#: The bars of this process, innermost last (the one a local pool's counter is attached to).
_ACTIVE: list[Progress] = []


# ------------------------------------------------------------------------------ reporting points
def tick(n: int = 1) -> None:
    """Report ``n`` more points finished by the running chunk function (a no-op outside a sweep with a bar).

    Parameters
    ----------
    n : int
        Points finished since the last call.
    """
    sink = _SINK
    if sink is not None and n:
        sink(int(n))


def counts_points(points_of: Callable[[tuple], int]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator of a chunk function: ``points_of(args)`` is the number of points of the chunk ``fn(*args)``.

    The sweep's progress bar then counts points instead of chunks; the function should call
    :func:`tick` as it finishes points (else a chunk counts all its points when it ends).

    Parameters
    ----------
    points_of : callable
        The chunk's argument tuple → its number of points.

    Returns
    -------
    callable
        The decorator (it returns the function itself, still importable by name in workers).
    """

    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        fn.points_of = points_of  # type: ignore[attr-defined]
        return fn

    return decorate


def chunk_points(chunk: Any) -> int | None:
    """Points of a :class:`~geardyn.sweep.Chunk`, or None when its function does not say (:func:`counts_points`).

    Parameters
    ----------
    chunk : Chunk
        A chunk of work (``fn``, ``args``).

    Returns
    -------
    int or None
    """
    f = getattr(chunk.fn, "points_of", None)
    if f is None:
        return None
    try:
        return int(f(chunk.args))
    except (TypeError, ValueError, IndexError):
        return None


def pool_counter(ctx: Any) -> Any:
    """A point counter in shared memory for the workers of a new local pool, watched by the active bar.

    Parameters
    ----------
    ctx : multiprocessing context
        The pool's context (the counter is handed to each worker by the pool's initializer).

    Returns
    -------
    multiprocessing.Value or None
        None when no bar counting points is active in this process (the workers then do not count).
    """
    bar = _ACTIVE[-1] if _ACTIVE else None
    if bar is None or not bar.counts_points:
        return None
    counter = ctx.Value("q", 0)
    bar.watch(counter)
    return counter


def count_into(counter: Any) -> None:
    """In a pool worker: send :func:`tick` to ``counter`` (from :func:`pool_counter`; None: nowhere)."""
    global _SINK
    if counter is None:
        _SINK = None
        return
    lock, raw = counter.get_lock(), counter.get_obj()

    def add(n: int) -> None:
        if lock.acquire(timeout=_LOCK_TIMEOUT):
            try:
                raw.value += n
            finally:
                lock.release()

    _SINK = add


# ------------------------------------------------------------------------------ divergence summary
def divergence_summary(results: Sequence[dict[str, np.ndarray]] | dict[str, np.ndarray]) -> tuple[int, int] | None:
    """(diverged, total) over the ``status`` entries of chunk results.

    Parameters
    ----------
    results : dict of ndarray, or a sequence of them
        Chunk results.

    Returns
    -------
    (int, int) or None
        Diverged points and all points; None if no result has a ``status``.
    """
    if isinstance(results, dict):
        results = [results]
    st = [np.asarray(r["status"]) for r in results if "status" in r]
    if not st:
        return None
    return int(sum(int(np.count_nonzero(s == ST_DIVERGED)) for s in st)), int(sum(s.size for s in st))


def _clock(sec: float) -> str:
    """Seconds as h:mm:ss."""
    sec = max(0, int(sec))
    return f"{sec // 3600}:{sec // 60 % 60:02d}:{sec % 60:02d}"


def _stderr_console():
    from rich.console import Console

    return Console(stderr=True, soft_wrap=True)


def _say(console: Any, text: str) -> None:
    """One plain line on ``console``, flushed."""
    console.print(text, markup=False, highlight=False)
    try:
        console.file.flush()
    except (OSError, ValueError):  # a closed or broken stream: progress is not worth failing for
        pass


def print_summary(description: str, results: Sequence[dict[str, np.ndarray]]) -> None:
    """Print "<description>: N of M points diverged" on stderr (nothing for results without status)."""
    s = divergence_summary(results) if results else None
    if s is None:
        return
    bad, total = s
    note = " (marked 'diverged', their data masked)" if bad else ""
    _say(_stderr_console(), f"{description}: {bad} of {total} points diverged{note}")


# ------------------------------------------------------------------------------ bars
class _DelayedBar(ABC):
    """One rich task on stderr, started :data:`PROGRESS_DELAY` s after creation (never for a shorter run).

    ``columns`` builds the rich columns; ``_current()`` gives (completed, total) when drawn; with
    ``poll`` a thread redraws from ``_current()`` every :data:`POLL_INTERVAL` s.
    """

    def __init__(self, description: str, poll: bool = False) -> None:
        self._description = description
        self._poll = poll
        self._lock = threading.RLock()
        self._p = None
        self._t = None
        self._plain: Any = None  # the console of plain progress lines (stderr not a terminal)
        self._closed = False
        self._stop = threading.Event()
        self._t0 = time.monotonic()
        self._c0 = _cache_guard.compile_seconds()  # ETAs leave out the time numba spends compiling
        self._timer = threading.Timer(PROGRESS_DELAY, self._start)
        self._timer.daemon = True
        self._unwatch = _cache_guard.on_compile(self._compiling)

    def _compiling(self, what: str) -> None:
        """Say, once, that a kernel compiles (a first run: the cache has no code for it yet)."""
        self._unwatch()
        if getattr(self, "_announced", False):
            return
        self._announced = True
        _say(_stderr_console(), f"compiling {what}, first run only")

    def _begin(self) -> None:
        if PROGRESS_DELAY > 0:
            self._timer.start()
        else:
            self._start()

    @abstractmethod
    def _columns(self) -> list:
        """The rich columns of the bar."""

    def _elapsed(self) -> Any:
        """A column with the time since the computation began (the bar itself appears later)."""
        from rich.progress import ProgressColumn
        from rich.text import Text

        t0 = self._t0

        class Elapsed(ProgressColumn):
            def render(self, task: Any) -> Text:
                end = (
                    time.monotonic()
                    if task.finished_time is None or task.start_time is None
                    else (task.start_time + task.finished_time)
                )
                return Text(_clock(end - t0), style="progress.elapsed")

        return Elapsed()

    @abstractmethod
    def _current(self) -> tuple[float, float | None]:
        """(done, total) now; total ``None`` for a spinner."""

    def _fields(self) -> dict[str, Any]:
        return {}

    def _start(self) -> None:
        from rich.progress import Progress as RichProgress

        with self._lock:
            if self._closed or self._p is not None or self._plain is not None:
                return
            console = _stderr_console()
            if not (console.is_terminal or console.is_jupyter):  # a file or a pipe: plain lines at a modest rate
                self._plain = console
                self._line()
                threading.Thread(target=self._plain_loop, daemon=True, name="geardyn-progress").start()
                return
            self._p = RichProgress(*self._columns(), console=console, transient=False)
            self._p.start()
            done, total = self._current()
            self._t = self._p.add_task(self._description, total=total, completed=done, **self._fields())
        if self._poll:
            threading.Thread(target=self._poll_loop, daemon=True, name="geardyn-progress").start()

    def _plain_loop(self) -> None:
        while not self._stop.wait(PLAIN_INTERVAL):
            with self._lock:
                if not self._closed:
                    self._line()

    def _line(self) -> None:
        """Write the current state as one plain line on stderr, flushed (the caller holds the lock)."""
        done, total = self._current()
        sec = time.monotonic() - self._t0
        text = f"{self._description}: {self._numbers(done, total)}, elapsed {_clock(sec)}"
        if total and 0 < done < total:
            busy = max(0.0, sec - (_cache_guard.compile_seconds() - self._c0))
            text += f", ETA {_clock(busy * (total - done) / done)}"
        _say(self._plain, text)

    @abstractmethod
    def _numbers(self, done: float, total: float | None) -> str:
        """The numbers of a plain progress line ("12/40 points (30%)")."""

    def _poll_loop(self) -> None:
        while not self._stop.wait(POLL_INTERVAL):
            self._redraw()

    def _redraw(self) -> None:
        with self._lock:
            if self._p is not None and not self._closed:
                done, total = self._current()
                self._p.update(self._t, completed=done, total=total, **self._fields())

    def close(self) -> None:
        """Stop the bar (or its pending start), drawing its last state."""
        self._unwatch()
        self._timer.cancel()
        self._stop.set()
        self._redraw()
        with self._lock:
            if self._plain is not None and not self._closed:
                self._line()
            self._closed = True
            if self._p is not None:
                self._p.stop()


class Progress(_DelayedBar):
    """The progress bar of a sweep, in points (or chunks), with ETA on stderr.

    Drawn once the sweep has run :data:`PROGRESS_DELAY` s.  While it exists, :func:`tick` in this
    process advances it, and the counters of local pools (:func:`pool_counter`) are polled.

    Parameters
    ----------
    total, completed : int
        Units (points or chunks) in the sweep and already finished (loaded on resume).
    description : str
        Label of the bar.
    unit : {'chunks', 'points'}
        What is counted; with ``points``, ``sizes`` gives the points of each chunk.
    sizes : mapping of int to int, optional
        Points per chunk index (needed to count points as chunks finish).
    """

    def __init__(
        self, total: int, completed: int, description: str, unit: str = "chunks", sizes: Mapping[int, int] | None = None
    ) -> None:
        super().__init__(description, poll=unit == "points")
        self._total = int(total)
        self._base = int(completed)
        self._finished = 0  # units of the chunks finished in this run
        self._ticks = 0  # points ticked in this process
        self._counters: list[Any] = []
        self._unit = unit
        self._sizes = dict(sizes or {})
        self._sink_before = _SINK
        self._install()
        self._begin()

    @classmethod
    def for_chunks(cls, chunks: Sequence[Any], done: Mapping[int, Any] | Sequence[int], description: str) -> Progress:
        """The bar of a sweep over ``chunks`` of which those with index in ``done`` are finished.

        Counts points when every chunk function says how many it holds (:func:`counts_points`),
        else chunks.

        Parameters
        ----------
        chunks : sequence of Chunk
            The sweep's chunks.
        done : mapping or sequence of int
            Indices of the chunks already finished (e.g. the results loaded on resume).
        description : str
            Label of the bar.

        Returns
        -------
        Progress
        """
        sizes = {c.index: chunk_points(c) for c in chunks}
        finished = set(done)
        if chunks and all(v is not None for v in sizes.values()):
            return cls(sum(sizes.values()), sum(sizes[i] for i in finished if i in sizes), description, "points", sizes)
        return cls(len(chunks), len(finished), description)

    @property
    def counts_points(self) -> bool:
        """Whether the bar counts points (and so listens to :func:`tick`)."""
        return self._unit == "points"

    @property
    def completed(self) -> int:
        """Units finished so far (as drawn)."""
        with self._lock:
            return int(self._current()[0])

    def _install(self) -> None:
        global _SINK
        _ACTIVE.append(self)
        if self.counts_points:
            _SINK = self._tick

    def _uninstall(self) -> None:
        global _SINK
        if self in _ACTIVE:
            _ACTIVE.remove(self)
            if _SINK == self._tick:
                _SINK = self._sink_before

    def _columns(self) -> list:
        from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeRemainingColumn

        return [
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn(self._unit),
            self._elapsed(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
        ]

    def _current(self) -> tuple[int, int]:
        live = self._ticks + sum(int(c.get_obj().value) for c in self._counters) if self.counts_points else 0
        return min(self._total, self._base + max(self._finished, live)), self._total

    def _numbers(self, done: float, total: float | None) -> str:
        pct = f" ({100.0 * done / total:.0f}%)" if total else ""
        return f"{int(done)}/{int(total or 0)} {self._unit}{pct}"

    def _tick(self, n: int) -> None:
        with self._lock:
            self._ticks += n
        self._redraw()

    def watch(self, counter: Any) -> None:
        """Also count the points in ``counter`` (a shared counter of a local pool's workers)."""
        with self._lock:
            self._counters.append(counter)

    def advance(self, chunk: Any = None) -> None:
        """One more chunk finished (``chunk``: which one, to count its points)."""
        with self._lock:
            if self.counts_points and chunk is not None:
                self._finished += self._sizes.get(chunk.index, 0)
            else:
                self._finished += 1
        self._redraw()

    def close(self) -> None:
        """Stop the bar (or its pending start) and stop listening to :func:`tick`."""
        with self._lock:
            self._uninstall()
        super().close()


class _TaskBar(_DelayedBar):
    """The bar of :func:`task_progress`: (done, total) from a callback, or a spinner without a fraction."""

    def __init__(self, description: str, unit: str, indeterminate: bool, fmt: str) -> None:
        super().__init__(description)
        self._unit = unit
        self._indeterminate = indeterminate
        self._fmt = fmt
        self._done = 0.0
        self._total: float | None = None
        self._begin()

    def _columns(self) -> list:
        from rich.progress import BarColumn, SpinnerColumn, TaskProgressColumn, TextColumn, TimeRemainingColumn

        if self._indeterminate:
            return [
                SpinnerColumn(finished_text="✓"),
                TextColumn("{task.description}"),
                TextColumn("{task.fields[requested]}"),
                self._elapsed(),
            ]
        return [
            TextColumn("{task.description}"),
            BarColumn(),
            TaskProgressColumn(),
            TextColumn("{task.fields[numbers]}"),
            self._elapsed(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
        ]

    def _fields(self) -> dict[str, Any]:
        t, f = self._total, self._fmt
        if t is None:
            return {"requested": "", "numbers": ""}
        return {"requested": f"{t:{f}} {self._unit} requested", "numbers": f"{self._done:{f}}/{t:{f}} {self._unit}"}

    def _current(self) -> tuple[float, float | None]:
        if self._indeterminate:  # a spinner until the end, then a finished task
            return (1.0, 1.0) if self._total is not None and self._done >= self._total else (0.0, None)
        return self._done, self._total

    def _numbers(self, done: float, total: float | None) -> str:
        if self._indeterminate:
            req = self._fields()["requested"]
            return ("done" if total else "running") + (f" ({req})" if req else "")
        if total is None:
            return "starting"
        pct = f" ({100.0 * done / total:.0f}%)" if total else ""
        return f"{self._fields()['numbers']}{pct}"

    def update(self, done: float, total: float) -> None:
        with self._lock:
            self._done, self._total = float(done), float(total)
        self._redraw()


@contextmanager
def task_progress(
    description: str, *, unit: str = "", enabled: bool = True, indeterminate: bool = False, fmt: str = ".4g"
) -> Iterator[Callable[[float, float], None] | None]:
    """A progress bar on stderr for one long computation that reports ``progress(done, total)``.

    The bar appears after :data:`PROGRESS_DELAY` s (a shorter run shows nothing) and is stopped when
    the block ends.  With ``indeterminate`` it is a spinner with the elapsed time and the total
    requested (for a computation that cannot report partial progress).

    Parameters
    ----------
    description : str
        Label of the bar.
    unit : str
        What ``done`` and ``total`` count (``"periods"``, ``"Δω"``…), shown after the numbers.
    enabled : bool
        False: no bar (e.g. with ``--json``); the block receives None.
    indeterminate : bool
        Draw a spinner with the elapsed time instead of a fraction.
    fmt : str
        Format of the numbers (``".4g"``; ``".0f"`` for counts).

    Yields
    ------
    callable or None
        The callback ``progress(done, total)`` to pass to the computation (None when disabled).
    """
    if not enabled:
        yield None
        return
    bar = _TaskBar(description, unit, indeterminate, fmt)
    try:
        yield bar.update
    finally:
        bar.close()
