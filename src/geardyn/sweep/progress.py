"""Progress of a sweep on stderr: a bar with ETA for long sweeps, and the divergence summary."""

from __future__ import annotations

import threading
from typing import Sequence

import numpy as np

__all__ = ["PROGRESS_DELAY", "ST_DIVERGED", "divergence_summary"]

#: Seconds a sweep must run before its progress bar appears (short sweeps stay quiet).
PROGRESS_DELAY = 0.5
#: Status code of a diverged point in a chunk's ``status`` array (``integrate.ST_DIVERGED``).
ST_DIVERGED = 1


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


def _stderr_console():
    from rich.console import Console

    return Console(stderr=True, soft_wrap=True)


def print_summary(description: str, results: Sequence[dict[str, np.ndarray]]) -> None:
    """Print "<description>: N of M points diverged" on stderr (nothing for results without status)."""
    s = divergence_summary(results) if results else None
    if s is None:
        return
    bad, total = s
    note = " (marked 'diverged', their data masked)" if bad else ""
    _stderr_console().print(f"{description}: {bad} of {total} points diverged{note}", markup=False, highlight=False)


class Progress:
    """A rich progress bar with ETA on stderr, drawn once the sweep has run :data:`PROGRESS_DELAY` s.

    Parameters
    ----------
    total, completed : int
        Chunks in the sweep and chunks already finished.
    description : str
        Label of the bar.
    """

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
        """One more chunk finished."""
        with self._lock:
            self._completed += 1
            if self._p is not None:
                self._p.update(self._t, completed=self._completed)

    def close(self) -> None:
        """Stop the bar (or its pending start)."""
        self._timer.cancel()
        with self._lock:
            self._closed = True
            if self._p is not None:
                self._p.stop()
