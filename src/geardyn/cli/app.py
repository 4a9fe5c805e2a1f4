"""The typer application, its consoles, and the entry point that turns every input error into one line."""

from __future__ import annotations

import atexit
import errno
import gc
import json
import sys
from typing import Any, Optional

import typer
from rich.console import Console
from typer.core import TyperCommand, TyperGroup

from .. import __version__
from ..errors import GeardynError, SweepFailed, SweepInterrupted

__all__ = ["EXIT_INTERRUPTED", "app", "console", "emit_json", "err_console", "fail", "main"]

#: Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
EXIT_INTERRUPTED = 130

class _HelpScreen:
    """What every help screen shares, built here once: ``--help`` shows no value placeholder (it takes none),
    and help texts are shown as written (a ``[mesh]`` is text, not Rich markup)."""

    def get_help_option(self, ctx: Any) -> Any:
        opt = super().get_help_option(ctx)  # type: ignore[misc]
        if opt is not None:
            opt.metavar = ""
        return opt

    def format_help(self, ctx: Any, formatter: Any) -> None:
        from rich.markup import escape

        objs = [self, *self.get_params(ctx), *getattr(self, "commands", {}).values()]  # type: ignore[attr-defined]
        saved = [(o, o.help) for o in objs if getattr(o, "help", None)]
        try:
            for o, text in saved:
                o.help = escape(text)
            super().format_help(ctx, formatter)  # type: ignore[misc]
        finally:
            for o, text in saved:
                o.help = text


class GeardynCommand(_HelpScreen, TyperCommand):
    """A geardyn command (see :class:`_HelpScreen`)."""


class GeardynGroup(_HelpScreen, TyperGroup):
    """The ``geardyn`` command group (see :class:`_HelpScreen`)."""


app = typer.Typer(
    name="geardyn",
    cls=GeardynGroup,
    help="Nonlinear dynamics of gear pairs with backlash.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True)


def _version(value: bool) -> None:
    if value:
        console.print(f"geardyn {__version__}", markup=False, highlight=False)
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", help="Print the version and exit.", callback=_version,
                                 is_eager=True, metavar=""),
) -> None:
    """geardyn: simulate and analyse the nonlinear dynamics of a gear pair with backlash."""


def say_error(message: str) -> None:
    """Print ``message`` on stderr as one line (never wrapped, no markup).

    Parameters
    ----------
    message : str
        The text; runs of whitespace (newlines included) become single spaces.
    """
    err_console.print(" ".join(str(message).split()), markup=False, highlight=False, soft_wrap=True)


def fail(message: str) -> "typer.Exit":
    """Print one line naming the bad input and return the exit (code 2) to raise.

    Parameters
    ----------
    message : str
        What is wrong, printed after ``error:`` on stderr.

    Returns
    -------
    typer.Exit
        The exit with code 2, for the caller to ``raise``.
    """
    say_error(f"error: {message}")
    return typer.Exit(code=2)


def emit_json(obj: Any) -> None:
    """Write ``obj`` as indented JSON on stdout (NumPy scalars and arrays as plain numbers and lists).

    Parameters
    ----------
    obj : object
        A JSON-serialisable value; NaN and infinities are written as ``NaN`` and ``Infinity``.

    Raises
    ------
    TypeError
        For a value that is neither JSON-serialisable nor a NumPy scalar or array.
    """
    sys.stdout.write(json.dumps(obj, indent=2, allow_nan=True, default=_json_default) + "\n")


def _json_default(o: Any) -> Any:
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def is_stop(e: BaseException) -> bool:
    """A sweep stopped from outside (Ctrl-C, a lost scheduler): not an input error, :func:`main` reports it."""
    return isinstance(e, (SweepInterrupted, SweepFailed))


def main(argv: Optional[list[str]] = None) -> None:
    """Entry point: run the app; every input error becomes one line on stderr, never a traceback.

    Exit codes: 0 success; 2 invalid input (model and option errors, unknown options, values
    that do not parse, bad configuration files); 130 interrupted by Ctrl-C (a sweep says how to
    resume); 1 other failures such as an unwritable output or a lost Dask scheduler.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name; default ``sys.argv[1:]``.

    Raises
    ------
    SystemExit
        With the exit code above (also on success when a command returns a code).
    """
    # typer's parser exceptions (its own vendored click, or click itself in older versions)
    cx = sys.modules[typer.BadParameter.__module__]
    usage_error, click_exception = cx.UsageError, cx.ClickException
    no_args_is_help = getattr(cx, "NoArgsIsHelpError", ())
    # What the imports made lives as long as the process: frozen out of the garbage collector while
    # the command runs (its full collections would walk it again and again), and what the process
    # holds at its exit is frozen first, so that the interpreter's exit does not walk the whole heap
    # again (about 0.5 s after a sweep; files are closed where they are written).
    atexit.unregister(gc.freeze)
    atexit.register(gc.freeze)
    gc.freeze()
    try:
        rv = app(args=argv, prog_name="geardyn", standalone_mode=False)
    except no_args_is_help as e:  # type: ignore[misc]
        print(e.ctx.get_help() if e.ctx is not None else e.format_message())
        raise SystemExit(0) from None
    except usage_error as e:
        where = f" (see 'geardyn {e.ctx.info_name} --help')" if e.ctx is not None and e.ctx.parent is not None else ""
        say_error(f"error: {e.format_message()}{where}")
        raise SystemExit(2) from None
    except SweepInterrupted as e:
        say_error(str(e))
        raise SystemExit(EXIT_INTERRUPTED) from None
    except SweepFailed as e:
        say_error(f"error: {e}")
        raise SystemExit(1) from None
    except GeardynError as e:
        say_error(f"error: {e}")
        raise SystemExit(2) from None
    except typer.Abort:
        say_error("interrupted")
        raise SystemExit(EXIT_INTERRUPTED) from None
    except click_exception as e:
        say_error(f"error: {e.format_message()}")
        raise SystemExit(e.exit_code) from None
    except OSError as e:
        if e.errno == errno.EPIPE:  # output piped into a program that stopped reading
            raise SystemExit(1) from None
        name = f" {e.filename}" if getattr(e, "filename", None) else ""
        say_error(f"error: cannot access{name}: {e.strerror or e}")
        raise SystemExit(1) from None
    finally:
        gc.unfreeze()  # as found, for a caller in the same process
    if rv == EXIT_INTERRUPTED:  # Ctrl-C outside a sweep (typer maps it to exit code 130)
        say_error("interrupted")
    if isinstance(rv, int) and not isinstance(rv, bool):
        raise SystemExit(rv)
