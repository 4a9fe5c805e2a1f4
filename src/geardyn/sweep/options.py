"""The engine options of a sweep, one small frozen object that every analysis accepts."""

from __future__ import annotations

import dataclasses
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..model import ModelError

__all__ = ["ENGINE_KEYWORDS", "SweepOptions"]

#: The keyword arguments of :class:`SweepOptions`, also accepted one by one by the analyses.
ENGINE_KEYWORDS = ("workers", "scheduler", "executor", "checkpoint", "resume", "progress", "chunk_points", "processes")


@dataclass(frozen=True)
class SweepOptions:
    """Where and how a sweep runs: executor, checkpoint, resume, progress and chunk size.

    Parameters
    ----------
    workers : int
        Chunks integrated at once.  In this process (the default) they run on threads, the
        kernel releasing the GIL: 1 runs one chunk at a time on every kernel thread (the next one
        prepared meanwhile), N runs N chunks at a time on 1/N of the kernel threads each
        (:func:`geardyn.sweep.executors.run_on_threads`).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``); the chunks run on its workers,
        which must have geardyn installed (the ``dask`` extra).
    executor : concurrent.futures.Executor, optional
        Any executor to use instead (overrides ``workers`` and ``scheduler``), e.g.
        :func:`geardyn.sweep.local_pool` or ``distributed.Client.get_executor()``; it is not shut
        down by the sweep.
    checkpoint : path, optional
        Directory where each finished chunk is written durably
        (see :func:`geardyn.sweep.checkpoint_dir` and :class:`geardyn.sweep.CheckpointStore`).
    resume : bool
        Skip the chunks already finished in ``checkpoint``.
    progress : bool
        Show a progress bar with ETA on stderr and end with a line "N of M points diverged".
    chunk_points : int, optional
        Points per chunk; None: chunks sized by estimated cost (:func:`geardyn.sweep.chunk_slices`).
    processes : bool
        Run the ``workers`` chunks in local worker processes instead (a process pool from a fork
        server, or ``spawn``, one kernel thread each; a worker process that dies is replaced).
        Each process holds its own copy of NumPy and the compiled kernel (140–190 MB).

    Raises
    ------
    ModelError
        For ``workers`` not an integer >= 1, ``chunk_points`` not an integer >= 1, or
        ``processes`` not a bool.
    """

    workers: int = 1
    scheduler: str | None = None
    executor: Executor | None = None
    checkpoint: str | Path | None = None
    resume: bool = False
    progress: bool = False
    chunk_points: int | None = None
    processes: bool = False

    def __post_init__(self) -> None:
        w = self.workers
        if isinstance(w, bool) or not isinstance(w, (int, np.integer)) or w < 1:
            raise ModelError(f"workers: must be an integer >= 1, got {w!r}")
        if not isinstance(self.processes, (bool, np.bool_)):
            raise ModelError(f"processes: must be True or False, got {self.processes!r}")
        c = self.chunk_points
        if c is not None and (isinstance(c, bool) or not isinstance(c, (int, np.integer)) or c < 1):
            raise ModelError(f"chunk size: must be >= 1, got {c!r}")

    def replace(self, **changes: Any) -> SweepOptions:
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)

    def points_per_chunk(self, default: int) -> int:
        """``chunk_points``, or ``default`` when it is not set."""
        return int(self.chunk_points) if self.chunk_points is not None else int(default)

    @classmethod
    def merge(cls, engine: SweepOptions | None = None, caller: str = "sweep", **keywords: Any) -> SweepOptions:
        """``engine`` (or the defaults) with the engine keywords given one by one applied on top.

        Parameters
        ----------
        engine : SweepOptions, optional
            The options object; None for the defaults.
        caller : str
            Name of the calling function, for the message of an unknown keyword.
        **keywords
            Any of :data:`ENGINE_KEYWORDS`.

        Returns
        -------
        SweepOptions

        Raises
        ------
        TypeError
            For a keyword that is not an engine option (as Python does for an unknown keyword).
        ModelError
            For invalid values (see :class:`SweepOptions`).
        """
        base = cls() if engine is None else engine
        if not isinstance(base, SweepOptions):
            raise TypeError(f"{caller}() engine must be a SweepOptions, got {type(base).__name__}")
        for k in keywords:
            if k not in ENGINE_KEYWORDS:
                raise TypeError(f"{caller}() got an unexpected keyword argument {k!r}")
        return dataclasses.replace(base, **keywords) if keywords else base
