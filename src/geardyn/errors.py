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

__all__ = ["ConfigError", "GeardynError", "ModelError", "PlotError", "SweepError"]


class GeardynError(Exception):
    """Base of every error geardyn raises on purpose; the message is one line."""


class ModelError(GeardynError, ValueError):
    """An invalid model parameter or option; the message names the parameter and what is allowed."""


class ConfigError(GeardynError, ValueError):
    """A configuration file that cannot be used; the message names the file (and line or key where known)."""


class SweepError(GeardynError):
    """A sweep that cannot start or go on (checkpoint directory, resume mismatch, scheduler address)."""


class PlotError(GeardynError, ValueError):
    """A Dataset geardyn cannot draw (not a geardyn result, or no figure for its kind)."""
