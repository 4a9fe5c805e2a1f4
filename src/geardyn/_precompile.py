"""Compile geardyn's kernels once, into numba's cache beside them: run at install time by ``setup.py``.

``pip install .`` builds the package, then runs ``python -m geardyn._precompile`` on the built copy: each
command of :data:`COMMANDS` runs once, small, in one process, so that numba compiles exactly the
specialisations a user's first run of that command needs and saves them in the ``__pycache__`` beside the
sources; the wheel ships them.  The cache is keyed on the sources' contents (:mod:`geardyn._cache_guard`), so
the installed copy finds it, and a user's first ``geardyn simulate`` reads the compiled code instead of
compiling.  A command that fails here only costs that command its compile at first use.

Run by hand: ``python -m geardyn._precompile [--examples DIR]`` (DIR holds ``systems/paper_bevel_8dof.toml``;
without it the system commands are skipped).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import tempfile
import time
from pathlib import Path

#: The commands whose kernels are compiled at install time (``{bevel}``: the 8-DOF bevel pair's system file).
COMMANDS: tuple[tuple[str, ...], ...] = tuple(
    tuple(c.split())
    for c in (
        "simulate --omega 0.8 --json",
        "simulate --omega 0.8 --accurate --json",
        "lyapunov --omega 0.8 --json",
        "orbit --omega 0.8 --json",
        "bifurcation --param omega --start 0.5 --stop 1.5 --json",
        "response --omega-start 0.5 --omega-stop 1.5 --num 21 --json",
        "hb --param omega --start 0.5 --stop 1.5 --json",
        "simulate --system {bevel} --json",
        "bifurcation --system {bevel} --param omega --start 0.8 --stop 0.9 --num 4 --json",
        "hb --system {bevel} --param omega --start 0.8 --stop 0.9 --json",
    )
)


def _run(argv: list[str]) -> tuple[int, float]:
    from geardyn.cli import main

    t0 = time.perf_counter()
    code = 0
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            code = int(main(argv) or 0)
        except SystemExit as exc:  # the CLI exits with the command's code
            code = exc.code if isinstance(exc.code, int) else 1
        except Exception:  # noqa: BLE001  (a failed command costs only its compile at first use)
            code = 1
    return code, time.perf_counter() - t0


def main(args: list[str] | None = None) -> int:
    """Run every command of :data:`COMMANDS` once; report each on stderr; exit 0 whatever happened."""
    ap = argparse.ArgumentParser(prog="python -m geardyn._precompile", description=__doc__.splitlines()[0])
    ap.add_argument("--examples", type=Path, default=None, help="directory holding systems/paper_bevel_8dof.toml")
    ns = ap.parse_args(args)
    bevel = (ns.examples / "systems" / "paper_bevel_8dof.toml").resolve() if ns.examples else None
    os.environ.pop("NUMBA_CACHE_DIR", None)
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        for cmd in COMMANDS:
            if "{bevel}" in cmd and (bevel is None or not bevel.is_file()):
                continue
            argv = [str(bevel) if a == "{bevel}" else a for a in cmd]
            code, sec = _run(argv)
            state = "compiled" if code == 0 else f"exit {code}"
            print(f"geardyn: {' '.join(cmd)}: {state} in {sec:.1f} s", file=sys.stderr, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
