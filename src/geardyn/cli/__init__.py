"""The ``geardyn`` command line: parses options, calls the library, prints.  Nothing else.

Layout: :mod:`.app` (the typer app and the entry point :func:`main`), :mod:`.options` (the option groups
every command shares, generated from :mod:`geardyn.params`), the commands (:mod:`.point`, :mod:`.sweeps`,
:mod:`.tools`) and :mod:`.render` (tables for people).  Adding a command: one decorated function in a
command module, its table in :mod:`.render`, and ``python docs/gen_cli.py``.
"""

from __future__ import annotations

from .app import EXIT_INTERRUPTED, app, main
from .options import build_model
from . import point, sweeps, tools  # noqa: F401  (register the commands, in this order)
from . import engineering, hb, systems  # noqa: F401,E402  (te, runup; hb; modes)
from . import diagnostics  # noqa: F401,E402  (stiffness, signature)

__all__ = ["EXIT_INTERRUPTED", "app", "build_model", "main"]
