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
    names = [info.name for info in app.registered_commands]  # every command is registered by its name
    return {
        name: (group.commands[name].callback.__module__.rsplit(".", 1)[1], group.commands[name].help or "")
        for name in names
    }


#: Longest line of the generated list (the line length of ``ruff format``).
LINE_LENGTH = 120


def _quoted(text: str) -> str:
    """``text`` as a double-quoted Python literal (as ``ruff format`` writes it: JSON's escapes of a help text)."""
    import json

    return json.dumps(text, ensure_ascii=False)


def _pieces(help_: str) -> list[str]:
    """The help text as string literals of at most :data:`LINE_LENGTH` characters once indented, cut after spaces
    (their implicit concatenation is the text)."""
    width = LINE_LENGTH - 12
    out: list[str] = []
    for line in help_.splitlines(True):
        piece = ""
        for word in line.split(" "):
            cand = word if not piece else piece + " " + word
            if piece and len(_quoted(cand + " ")) > width:
                out.append(_quoted(piece + " "))
                piece = word
            else:
                piece = cand
        out.append(_quoted(piece))
    return out


def _help_rows(help_: str) -> str:
    """The parenthesised help text of one command, laid out as ``ruff format`` lays it out."""
    pieces = _pieces(help_)
    if len(pieces) == 1 and 11 + len(pieces[0]) <= LINE_LENGTH:
        return f"        ({pieces[0]}),\n"
    return "        (\n" + "".join(f"            {p}\n" for p in pieces) + "        ),\n"


def write() -> bool:
    """Rewrite :data:`._commands.COMMANDS` in its file from the commands (:func:`table`); True if the file changed."""
    path = Path(_commands.__file__)
    text = path.read_text(encoding="utf-8")
    head, rest = text.split(_BEGIN, 1)
    _, tail = rest.split(_END, 1)
    rows = "".join(
        f"    {_quoted(name)}: (\n        {_quoted(module)},\n{_help_rows(help_)}    ),\n"
        for name, (module, help_) in table().items()
    )
    new = head + _BEGIN + rows + _END + tail
    if new != text:
        path.write_text(new, encoding="utf-8")
    return new != text
