"""The typer application, its consoles, and the entry point that turns every input error into one line."""

from __future__ import annotations

import atexit
import errno
import gc
import re
import sys
from collections.abc import Callable, Iterator, MutableMapping
from importlib import import_module
from typing import Any

import typer
from rich.console import Console
from typer.core import TyperCommand, TyperGroup

from .. import __version__
from ..errors import GeardynError, SweepFailed, SweepInterrupted
from ._commands import COMMANDS

__all__ = [
    "EXIT_FAILURE",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_TERMINATED",
    "EXIT_USAGE",
    "app",
    "console",
    "emit_json",
    "err_console",
    "fail",
    "main",
]

#: Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
EXIT_INTERRUPTED = 130


class _HelpScreen:
    """What every help screen shares, built here once: ``--help`` and every on/off flag show no value placeholder
    (they take none), and help texts are shown as written (a ``[mesh]`` is text, not Rich markup).  Also what every
    command's parsing shares: its options are converted by :func:`_direct_values`."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[call-arg]
        _direct_values(self.params)  # type: ignore[attr-defined]
        for p in self.params:  # type: ignore[attr-defined]
            if getattr(p, "param_type_name", "") == "argument" and p.name:
                p._usage_display_name = _usage_name(p)  # FILE, [FILE] optional, not typer's {file}
            elif getattr(p, "is_flag", False) and p.metavar is None:
                p.metavar = ""

    def get_help_option(self, ctx: Any) -> Any:
        opt = super().get_help_option(ctx)  # type: ignore[misc]
        if opt is not None:
            opt.metavar = ""
            _direct_values([opt])
        return opt

    def format_help(self, ctx: Any, formatter: Any) -> None:
        from rich.markup import escape

        _import_help_renderer()
        objs = [self, *self.get_params(ctx), *getattr(self, "commands", {}).values()]  # type: ignore[attr-defined]
        saved = [(o, o.help) for o in objs if getattr(o, "help", None)]
        try:
            for o, text in saved:
                o.help = escape(_reflowed(text))
            super().format_help(ctx, formatter)  # type: ignore[misc]
        finally:
            for o, text in saved:
                o.help = text


def _usage_name(p: Any) -> Callable[[], str]:
    """The usage line's name of an argument: its name in capitals (``FILE``; ``[FILE]`` when optional)."""

    def name() -> str:
        text = (p.metavar or p.name).upper()
        text = text if p.required else f"[{text}]"
        return text + ("..." if p.nargs != 1 else "")

    return name


def _reflowed(text: str) -> str:
    """A help text as the terminal should wrap it: the line breaks of its source joined within each paragraph
    (paragraphs, separated by a blank line, kept)."""
    return "\n\n".join(" ".join(p.split()) for p in re.split(r"\n\s*\n", text.strip()) if p.strip())


class GeardynCommand(_HelpScreen, TyperCommand):
    """A geardyn command (see :class:`_HelpScreen`)."""


class _Commands(MutableMapping):  # type: ignore[type-arg]
    """The group's commands by name, in the order of :data:`._commands.COMMANDS`: a command not registered when
    the group was made is built (its module imported) when it is first looked up."""

    def __init__(self, built: Any, build: Callable[[str], Any]) -> None:
        self._built = dict(built)
        self._build = build

    def __getitem__(self, name: str) -> Any:
        cmd = self._built.get(name)
        if cmd is None:
            if name not in COMMANDS:
                raise KeyError(name)
            cmd = self._built[name] = self._build(name)
        return cmd

    def __setitem__(self, name: str, cmd: Any) -> None:
        self._built[name] = cmd

    def __delitem__(self, name: str) -> None:
        del self._built[name]

    def __iter__(self) -> Iterator[str]:
        return iter(dict.fromkeys([*COMMANDS, *self._built]))

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __contains__(self, name: object) -> bool:
        return name in COMMANDS or name in self._built

    def listing(self) -> dict[str, Any]:
        """Every command for the group's help screen, those not built yet by their name and help text only."""
        return {name: self._built.get(name) or GeardynCommand(name=name, help=COMMANDS[name][1]) for name in self}


class GeardynGroup(_HelpScreen, TyperGroup):
    """The ``geardyn`` command group (see :class:`_HelpScreen`).  Its commands are imported on first use
    (:class:`_Commands`); its help screen lists them from :data:`._commands.COMMANDS` without importing them."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.commands = _Commands(self.commands, self._build_command)

    def _build_command(self, name: str) -> Any:
        import typer.main

        import_module(f"{__package__}.{COMMANDS[name][0]}")
        for info in app.registered_commands:
            if info.name == name:  # every command is registered by its name (geardyn.cli.options.command)
                return typer.main.get_command_from_info(
                    info, pretty_exceptions_short=app.pretty_exceptions_short, rich_markup_mode=self.rich_markup_mode
                )
        raise KeyError(name)

    def list_commands(self, ctx: Any) -> list[str]:
        return list(self.commands)

    def format_help(self, ctx: Any, formatter: Any) -> None:
        commands = self.commands
        if isinstance(commands, _Commands):
            self.commands = commands.listing()
        try:
            super().format_help(ctx, formatter)
        finally:
            self.commands = commands


_INT = re.compile(r"-?[0-9]{1,18}")
_FLOAT = re.compile(r"-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?")


def _direct(annotation: Any, value: Any) -> Any:
    """``value`` converted to ``annotation`` where that needs no validation library: a plain decimal number
    (``0.8``, ``-2``, ``1e-3``) for a float or an int option, a value already of the option's type (a default),
    a string for a string option.  Else ``_direct`` itself (the caller then converts as typer does)."""
    if annotation is float:
        if type(value) in (float, int) or (type(value) is str and _FLOAT.fullmatch(value)):
            return float(value)
    elif annotation is int:
        if type(value) is int or (type(value) is str and _INT.fullmatch(value)):
            return int(value)
    elif annotation is str or annotation is bool:
        if type(value) is annotation:
            return value
    return _direct


def _direct_values(params: list[Any]) -> None:
    """Convert the values of ``params`` (a command's typer parameters) to their types without pydantic where
    :func:`_direct` can: typer's own conversion imports pydantic and builds a validator per option (about a
    tenth of a short command), which stays the conversion for every other value, with its messages.  The
    same values result either way (``tests/test_startup.py`` compares them)."""
    if _Direct is None:  # another typer: its own conversion throughout
        return
    for p in params:
        desc = getattr(p, "type_descriptor", None)
        if getattr(p, "_runtime_param", 0) is None and desc is not None and desc.file_annotation is None:
            p._runtime_param = _Direct(parameter_info=desc.parameter_info, annotation=desc.annotation)


try:
    from typer._coercion import RuntimeParam, build_runtime_param

    class _Direct(RuntimeParam):  # type: ignore[misc, valid-type]
        """Typer's conversion of one parameter, :func:`_direct` first."""

        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            out = _direct(self.annotation, value)
            if out is _direct:
                param._runtime_param = build_runtime_param(param.type_descriptor)
                out = param._runtime_param._coerce_value(value, param=param, ctx=ctx)
            return out
except ImportError:  # pragma: no cover  (a typer without a pluggable conversion)
    _Direct = None  # type: ignore[assignment, misc]


def _import_help_renderer() -> None:
    """Import typer's help renderer (``typer.rich_utils``) without ``rich.markdown`` and ``rich.traceback``
    (half of its import time), which it imports for Markdown help texts and pretty tracebacks, neither of
    which geardyn uses: while it is imported they are stand-ins that import the real class on first use."""
    if "typer.rich_utils" in sys.modules:
        return

    class _OnFirstUse(type):
        def __call__(cls, *args: Any, **kwargs: Any) -> Any:
            return cls.real()(*args, **kwargs)

        def __getattr__(cls, attr: str) -> Any:
            return getattr(cls.real(), attr)

    from types import ModuleType

    stand_ins = {}
    for module, name in (("rich.markdown", "Markdown"), ("rich.traceback", "Traceback")):
        if module not in sys.modules:
            stand_ins[module] = ModuleType(module)

            def real(module: str = module, name: str = name) -> Any:
                return getattr(import_module(module), name)

            setattr(stand_ins[module], name, _OnFirstUse(name, (), {"real": staticmethod(real)}))
    sys.modules.update(stand_ins)
    try:
        import_module("typer.rich_utils")
    finally:
        for module, stand_in in stand_ins.items():
            if sys.modules.get(module) is stand_in:
                del sys.modules[module]


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
    version: bool = typer.Option(
        False, "--version", help="Print the version and exit.", callback=_version, is_eager=True
    ),
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


def fail(message: str, code: int = 2) -> typer.Exit:
    """Print one line naming the bad input (or the failure) and return the exit to raise.

    Parameters
    ----------
    message : str
        What is wrong, printed after ``error:`` on stderr.
    code : int
        The exit code: 2 for bad input (:data:`EXIT_USAGE`), 1 for a computation that failed.

    Returns
    -------
    typer.Exit
        The exit with ``code``, for the caller to ``raise``.
    """
    say_error(f"error: {message}")
    return typer.Exit(code=code)


def emit_json(obj: Any) -> None:
    """Write ``obj`` as indented, strict JSON on stdout (RFC 8259; see :func:`geardyn.cli.guard.strict_json`).

    NumPy scalars and arrays are written as plain numbers and lists; a non-finite number is written as
    ``null`` and its place listed under ``"non_finite"``.  Nothing is written once SIGINT or SIGTERM has
    asked the command to stop.

    Parameters
    ----------
    obj : object
        A JSON-serialisable value.

    Raises
    ------
    TypeError
        For a value that is neither JSON-serialisable nor a NumPy scalar or array.
    KeyboardInterrupt
        After SIGINT or SIGTERM.
    """
    from .guard import check_stop, strict_json

    text = strict_json(obj) + "\n"
    check_stop()
    sys.stdout.write(text)
    sys.stdout.flush()


#: Exit codes: success, a runtime or I/O failure, bad input or usage, interrupted by SIGINT / SIGTERM.
EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_TERMINATED = 0, 1, 2, 143


def main(argv: list[str] | None = None) -> None:
    """Entry point: run a command under the failure contract of ``docs/cli.md``.

    Exit codes: 0 success; 1 a runtime or I/O failure (an unwritable output, a full disk, a lost Dask
    scheduler); 2 invalid input (model and option errors, unknown options, values that do not parse,
    bad configuration, system or result files); 130 interrupted by SIGINT, 143 by SIGTERM (a sweep
    keeps its finished chunks and says how to resume).  Every problem is one line on stderr, never a
    traceback or a library warning (``GEARDYN_TRACEBACK=1`` shows the traceback of an unexpected
    error).  The command runs in a worker thread while the main thread handles the signals
    (:func:`geardyn.cli.guard.run_guarded`).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name; default ``sys.argv[1:]``.

    Raises
    ------
    SystemExit
        With the exit code above, unless it is 0.
    """
    import warnings

    from .guard import prepare_streams, run_guarded

    prepare_streams()
    # What the imports made lives as long as the process: frozen out of the garbage collector while
    # the command runs (its full collections would walk it again and again), and what the process
    # holds at its exit is frozen first, so that the interpreter's exit does not walk the whole heap
    # again (about 0.5 s after a sweep; files are closed where they are written).
    atexit.unregister(gc.freeze)
    atexit.register(gc.freeze)
    gc.freeze()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # no library warning reaches the user; problems are refused in words
            code = run_guarded(lambda: _invoke(argv))
    finally:
        gc.unfreeze()  # as found, for a caller in the same process
    _flush_quietly()
    if code:  # success returns, as it always has, to a caller in the same process
        raise SystemExit(code)


def _flush_quietly() -> None:
    from .guard import quiet_broken_pipe

    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):
            quiet_broken_pipe()


def _invoke(argv: list[str] | None) -> int:
    """Run the app on ``argv``; every error it raises becomes one line on stderr and an exit code."""
    from .guard import STOP, quiet_broken_pipe

    # typer's parser exceptions (its own vendored click, or click itself in older versions)
    cx = sys.modules[typer.BadParameter.__module__]
    usage_error, click_exception = cx.UsageError, cx.ClickException
    no_args_is_help = getattr(cx, "NoArgsIsHelpError", ())
    empty = _empty_path_option(sys.argv[1:] if argv is None else argv)
    if empty is not None:  # a path option given as "": typer would take it for the current directory
        say_error(f"error: {empty.lstrip('-')}: empty; give a directory or a file name")
        return EXIT_USAGE
    try:
        rv = app(args=argv, prog_name="geardyn", standalone_mode=False)
    except no_args_is_help as e:  # type: ignore[misc]
        print(e.ctx.get_help() if e.ctx is not None else e.format_message())
        return EXIT_OK
    except usage_error as e:
        where = f" (see 'geardyn {e.ctx.info_name} --help')" if e.ctx is not None and e.ctx.parent is not None else ""
        say_error(f"error: {e.format_message()}{where}")
        return EXIT_USAGE
    except SweepInterrupted as e:
        if STOP.event.is_set():  # the main thread says it as it leaves
            STOP.message = str(e)
        else:
            say_error(str(e))
        return EXIT_INTERRUPTED
    except GeardynError as e:  # a sweep that failed (1), else bad input (2)
        say_error(f"error: {e}")
        return EXIT_FAILURE if isinstance(e, SweepFailed) else EXIT_USAGE
    except (typer.Abort, KeyboardInterrupt):
        if not STOP.event.is_set():
            say_error("interrupted")
        return EXIT_INTERRUPTED
    except click_exception as e:
        say_error(f"error: {e.format_message()}")
        return e.exit_code
    except OSError as e:
        if e.errno == errno.EPIPE:  # output piped into a program that stopped reading
            quiet_broken_pipe()
            return EXIT_FAILURE
        say_error(f"error: {describe_os_error(e)}")
        return EXIT_FAILURE
    except MemoryError:
        say_error("error: out of memory (use fewer points, periods or a smaller grid)")
        return EXIT_FAILURE
    except RecursionError:
        say_error("error: input nested too deeply")
        return EXIT_USAGE
    except Exception as e:  # noqa: BLE001  (a bug: one line, never a traceback)
        import os

        if os.environ.get("GEARDYN_TRACEBACK"):
            import traceback

            traceback.print_exc()
        say_error(
            f"error: internal error ({type(e).__name__}: {' '.join(str(e).split())[:300]}); "
            f"please report it with the command line"
        )
        return EXIT_FAILURE
    if rv == EXIT_INTERRUPTED and not STOP.event.is_set():  # Ctrl-C outside a sweep (typer maps it to 130)
        say_error("interrupted")
    if isinstance(rv, int) and not isinstance(rv, bool):
        return rv
    return EXIT_OK


#: Options whose value is a path, which may not be empty.
PATH_OPTIONS = ("--out", "--config", "--system")


def _empty_path_option(args: list[str]) -> str | None:
    """The first path option of ``args`` given an empty value (``--out ""`` or ``--out=``), else None."""
    args = [str(a) for a in args]
    for i, a in enumerate(args):
        if a == "--":
            return None
        if a in PATH_OPTIONS and i + 1 < len(args) and not args[i + 1].strip():
            return a
        name, eq, value = a.partition("=")
        if eq and name in PATH_OPTIONS and not value.strip():
            return name
    return None


def describe_os_error(e: OSError) -> str:
    """One line naming the file of an I/O error and the reason (``FILE: No space left on device``).

    Parameters
    ----------
    e : OSError
        The error.

    Returns
    -------
    str
    """
    import os

    name = getattr(e, "filename", None)
    reason = e.strerror or (os.strerror(e.errno) if e.errno else None) or str(e) or type(e).__name__
    return f"{name}: {reason}" if name else f"I/O failure: {reason}"
