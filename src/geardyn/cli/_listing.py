"""The list of commands in :mod:`._commands`, rewritten from the commands themselves (``python docs/gen_cli.py``)."""

from __future__ import annotations

from importlib import import_module
from pathlib import Path
from typing import Any

from . import _commands

__all__ = ["load_all", "table", "write"]

_BEGIN, _END = "    # generated: begin\n", "    # generated: end\n"


def load_all() -> Any:
    """Import every command module (registering its commands in the order of :data:`._commands.MODULES`) and return
    the typer app."""
    for module in _commands.MODULES:
        import_module(f"{__package__}.{module}")
    from .app import app

    return app


def table() -> dict[str, tuple[str, str]]:
    """:data:`._commands.COMMANDS` as the commands themselves give it (every command module imported)."""
    import typer.main

    app = load_all()
    group = typer.main.get_command(app)
    names = [info.name or typer.main.get_command_name(info.callback.__name__) for info in app.registered_commands]
    return {
        name: (group.commands[name].callback.__module__.rsplit(".", 1)[1], group.commands[name].help or "")
        for name in names
    }


def write() -> bool:
    """Rewrite :data:`._commands.COMMANDS` in its file from the commands (:func:`table`); True if the file changed."""
    path = Path(_commands.__file__)
    text = path.read_text(encoding="utf-8")
    head, rest = text.split(_BEGIN, 1)
    _, tail = rest.split(_END, 1)
    rows = "".join(
        f"    {name!r}: ({module!r}, (\n"
        + "".join(f"        {line!r}\n" for line in help_.splitlines(True))
        + "    )),\n"
        for name, (module, help_) in table().items()
    )
    new = head + _BEGIN + rows + _END + tail
    if new != text:
        path.write_text(new, encoding="utf-8")
    return new != text
