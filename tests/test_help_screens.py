"""Every help screen: no value placeholder after ``--help`` and help texts shown as written (no Rich markup eaten)."""

from __future__ import annotations

import re

import pytest
import typer
from typer.testing import CliRunner

from geardyn.cli import app

GROUP = typer.main.get_command(app)
COMMANDS = sorted(GROUP.commands)


def _help(*args: str) -> str:
    r = CliRunner().invoke(app, [*args, "--help"], env={"COLUMNS": "200"}, terminal_width=200)
    assert r.exit_code == 0, r.output
    return r.output


@pytest.mark.parametrize("name", [None, *COMMANDS])
def test_help_screen_shows_no_placeholder_after_help_and_keeps_bracketed_words(name):
    out = _help(*([name] if name else []))
    line = next(ln for ln in out.splitlines() if "--help" in ln)
    assert "<" not in line, f"--help shows a value placeholder: {line.strip()}"
    cmd = GROUP.commands[name] if name else GROUP
    texts = [cmd.help or ""] + [getattr(p, "help", None) or "" for p in cmd.params]
    if name is None:
        texts += [c.help or "" for c in GROUP.commands.values()]
    flat = " ".join(out.split())
    for word in {w for t in texts for w in re.findall(r"\[[a-z][^\[\]]*\]", t)}:
        assert word in flat, f"{word!r} of the help text is lost from the help screen"


def test_te_help_names_the_mesh_section():
    assert "Write the [mesh] section (TOML) to this file." in " ".join(_help("te").split())
