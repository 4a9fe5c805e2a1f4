"""The ``geardyn`` command line: parses options, calls the library, prints.  Nothing else.

Layout: :mod:`.app` (the typer app and the entry point :func:`main`), :mod:`.options` (the option groups
every command shares, generated from :mod:`geardyn.params`), the commands (:mod:`.point`, :mod:`.sweeps`,
:mod:`.tools`, ...) and :mod:`.render` (tables for people).  Adding a command: one decorated function in a
command module, its table in :mod:`.render`, and ``python docs/gen_cli.py`` (which also lists it in
:mod:`._commands`).

A command's module is imported when the command runs (or its ``--help`` is asked for), not before:
``geardyn --help`` lists the commands from :mod:`._commands`.  ``from geardyn.cli import app`` gives the
app with every command registered.
"""

from __future__ import annotations

import os
import sys
from importlib import import_module
from typing import Any

if os.path.basename(sys.argv[0] if sys.argv else "") in ("geardyn", "geardyn.exe"):  # the program itself:
    from .guard import leave_on_signals_while_starting  # a signal while it imports leaves at once (130/143)

    leave_on_signals_while_starting()

from .app import EXIT_INTERRUPTED, main  # noqa: E402

del app  # noqa: F821  (the submodule's name, bound by the import above: ``app`` is the typer app, below)

__all__ = ["EXIT_INTERRUPTED", "app", "build_model", "main"]


def __getattr__(name: str) -> Any:
    if name == "app":
        from ._listing import load_all

        value: Any = load_all()
    elif name == "build_model":
        value = import_module(".options", __name__).build_model
    else:
        raise AttributeError(f"module 'geardyn.cli' has no attribute {name!r}")
    globals()[name] = value
    return value
