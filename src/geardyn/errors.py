"""The errors geardyn raises on purpose, one family per cause.

Every error's ``str()`` is a one-line message that names what is wrong and what is allowed (the CLI
prints it as it is and exits with code 2)::

    GeardynError
    ├── ModelError      an invalid model parameter, option or run limit  (also a ValueError)
    ├── ConfigError     a configuration file: missing, unreadable, bad TOML, unknown keys, wrong units
    ├── SweepError      a sweep that cannot run: checkpoint directory, resume mismatch, scheduler
    │   ├── SweepInterrupted   stopped by Ctrl-C (finished chunks kept)
    │   └── SweepFailed        stopped by a fault outside it (e.g. a lost Dask scheduler)
    └── PlotError       a Dataset geardyn cannot draw

Catch :class:`GeardynError` to handle all of them; a bug in geardyn surfaces as any other exception.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "ConfigError",
    "GeardynError",
    "ModelError",
    "PlotError",
    "SweepError",
]  # the sweep stops: from geardyn.sweep


class GeardynError(Exception):
    """Base of every error geardyn raises on purpose; the message is one line."""


class ModelError(GeardynError, ValueError):
    """An invalid model parameter or option; the message names the parameter and what is allowed.

    Examples
    --------
    >>> from geardyn import GearModel, ModelError
    >>> try:
    ...     GearModel(omega=-1.0)
    ... except ModelError as e:
    ...     print(str(e).split(":")[0])
    omega
    """


class ConfigError(GeardynError, ValueError):
    """A configuration file that cannot be used; the message names the file (and line or key where known)."""


class SweepError(GeardynError):
    """A sweep that cannot start or go on (checkpoint directory, resume mismatch, scheduler address)."""


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
            tail = (
                f"{finished} of {total} chunks finished and saved in {checkpoint}; "
                "run the same command again with --resume to complete the sweep"
            )
        else:
            tail = f"{finished} of {total} chunks finished, none saved (no --out)"
        super().__init__(f"sweep stopped: {reason}; {tail}")


class PlotError(GeardynError, ValueError):
    """A Dataset geardyn cannot draw (not a geardyn result, or no figure for its kind)."""
