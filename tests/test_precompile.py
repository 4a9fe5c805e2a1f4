"""The install-time compile (:mod:`geardyn._precompile`): its commands are valid CLI calls, and the driver runs each.

A command the CLI refuses would fail silently at install time (a failure only costs that command's compile at
first use), so every command of :data:`COMMANDS` is parsed here by the CLI itself, without running it.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import typer

from geardyn import _precompile
from geardyn.cli import app

GROUP = typer.main.get_command(app)
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
BEVEL = EXAMPLES / "systems" / "paper_bevel_8dof.toml"


@pytest.mark.parametrize("cmd", _precompile.COMMANDS, ids=[" ".join(c) for c in _precompile.COMMANDS])
def test_every_command_is_one_the_cli_accepts(cmd):
    name, *args = (str(BEVEL) if a == "{bevel}" else a for a in cmd)
    assert name in GROUP.commands, f"{name}: no such command"
    command = GROUP.commands[name]
    with command.make_context(name, list(args)) as ctx:  # parses and converts every option; runs nothing
        assert ctx.params


def test_the_examples_directory_setup_passes_holds_the_system():
    assert BEVEL.is_file()


def test_main_runs_each_command_once_and_skips_the_system_ones_without_examples(monkeypatch, capsys):
    ran: list[list[str]] = []
    monkeypatch.setattr(_precompile, "_run", lambda argv: (ran.append(argv), (0, 0.0))[1])
    monkeypatch.chdir(Path.cwd())  # main changes directory: restore it afterwards
    assert _precompile.main([]) == 0
    pair = [list(c) for c in _precompile.COMMANDS if "{bevel}" not in c]
    assert ran == pair
    assert capsys.readouterr().err.count("compiled") == len(pair)

    ran.clear()
    assert _precompile.main(["--examples", str(EXAMPLES)]) == 0
    assert len(ran) == len(_precompile.COMMANDS)
    assert all("{bevel}" not in a for argv in ran for a in argv)
    assert sum(str(BEVEL) in argv for argv in ran) == sum("{bevel}" in c for c in _precompile.COMMANDS)


def test_a_refused_command_is_reported_not_raised():
    code, seconds = _precompile._run(["simulate", "--omega", "-1", "--json"])
    assert code == 2 and seconds >= 0.0
