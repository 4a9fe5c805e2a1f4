"""``geardyn ARGS`` run in the test's process, for the tests of the command line (imported by them by name)."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Sequence


def run_cli(argv: Sequence[str]) -> tuple[int, str, str]:
    """Run ``geardyn ARGV`` in this process (the kernels load once per process); (exit code, stdout, stderr).

    The exit code is the ``SystemExit`` code: 0 when the command returns or exits with no code, 1 for a
    non-integer code (as the interpreter does).
    """
    from geardyn.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([str(a) for a in argv])
            code = 0
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    return code, out.getvalue(), err.getvalue()
