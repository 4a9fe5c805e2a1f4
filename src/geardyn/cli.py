"""The ``geardyn`` command line: parses options, calls the library, prints.  Nothing else."""

from __future__ import annotations

import json
import sys
from typing import Any

import typer
from rich.console import Console

from .model import ModelError

app = typer.Typer(
    name="geardyn",
    help="Nonlinear dynamics of gear pairs with backlash.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True)


def fail(message: str) -> "typer.Exit":
    """Print one line naming the bad input and return the exit (code 2) to raise."""
    err_console.print(f"error: {message}", markup=False, highlight=False)
    return typer.Exit(code=2)


def emit_json(obj: Any) -> None:
    sys.stdout.write(json.dumps(obj, indent=2, allow_nan=True, default=_json_default) + "\n")


def _json_default(o: Any) -> Any:
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def main() -> None:
    """Entry point: run the app, turning model errors into one-line messages with exit code 2."""
    try:
        app()
    except ModelError as e:
        err_console.print(f"error: {e}", markup=False, highlight=False)
        raise SystemExit(2) from None


if __name__ == "__main__":
    main()
