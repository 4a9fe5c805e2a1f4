"""Running geardyn commands in process and in a child process, and the failure contract they must keep.

The contract (docs/cli.md): exit code 0, 1 or 2 (130/143 after a signal); stderr one line per problem,
never a traceback or a library warning; ``--json`` output strict RFC 8259 JSON.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from geardyn.cli import main

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"
EXAMPLES = ROOT / "examples"
#: Most lines a refusal or a failure may print on stderr (one line per problem; a command may add a
#: summary line of its own, e.g. a checkpoint note).
MAX_ERROR_LINES = 3


def run(args: Sequence[str]) -> tuple[int, str, str]:
    """Run ``geardyn ARGS`` in this process; (exit code, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([str(a) for a in args])
            code = 0
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    return code, out.getvalue(), err.getvalue()


def _no_constants(name: str) -> None:
    raise ValueError(f"not RFC 8259 JSON: {name}")


def strict_json(text: str):
    """``text`` parsed as RFC 8259 JSON (NaN and Infinity refused)."""
    return json.loads(text, parse_constant=_no_constants)


def check_contract(code: int, out: str, err: str, *, json_mode: bool = False, args: Sequence[str] = ()) -> None:
    """Assert the failure contract on one run."""
    where = f"geardyn {' '.join(map(str, args))[:300]}\nstderr: {err[-2000:]}"
    assert code in (0, 1, 2), f"exit code {code}: {where}"
    assert "Traceback" not in err and "Traceback" not in out, where
    assert "Warning" not in err, where
    assert "internal error" not in err, where
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if code != 0:
        errors = [ln for ln in lines if ln.startswith("error:")]
        assert len(errors) == 1, where
        assert len(lines) <= MAX_ERROR_LINES, where
    if json_mode and code == 0:
        strict_json(out)


def child_env(**extra: str) -> dict[str, str]:
    """The environment of a geardyn child process running this checkout."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(SRC) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env.update(extra)
    return env


def start(args: Sequence[str], **popen) -> subprocess.Popen:
    """Start ``python -m geardyn.cli ARGS`` as a child process."""
    popen.setdefault("stdout", subprocess.PIPE)
    popen.setdefault("stderr", subprocess.PIPE)
    env = popen.pop("env", None) or child_env()
    return subprocess.Popen([sys.executable, "-m", "geardyn.cli", *map(str, args)], env=env, text=True, **popen)


def run_child(args: Sequence[str], timeout: float = 300, **popen) -> tuple[int, str, str]:
    """Run ``python -m geardyn.cli ARGS`` to its end; (exit code, stdout, stderr)."""
    p = start(args, **popen)
    out, err = p.communicate(timeout=timeout)
    return p.returncode, out or "", err or ""


def interrupt(
    args: Sequence[str], *, after: float, sig: int = signal.SIGINT, marker: str | None = None, timeout: float = 120
) -> tuple[int, str, str, float]:
    """Start a command, signal it once it has run ``after`` seconds (or once the regular expression ``marker``
    matches its stderr), and return (exit code, stdout, stderr, seconds from the signal to its end)."""
    p = start(args)
    t0 = time.monotonic()
    if marker is not None:  # read the pipe's bytes as they come (the text wrapper's buffer stays empty)
        fd, raw, want = p.stderr.fileno(), b"", re.compile(marker.encode())
        os.set_blocking(fd, False)
        while not want.search(raw) and time.monotonic() - t0 < timeout and p.poll() is None:
            try:
                raw += os.read(fd, 1 << 16)
            except BlockingIOError:
                time.sleep(0.02)
        os.set_blocking(fd, True)
        pre = raw.decode(errors="replace")
    else:
        time.sleep(after)
        pre = ""
    assert p.poll() is None, f"the command ended before the signal: {' '.join(map(str, args))}"
    p.send_signal(sig)
    ts = time.monotonic()
    out, err = p.communicate(timeout=timeout)
    return p.returncode, out, pre + err, time.monotonic() - ts


def datasets_equal(a, b) -> None:
    """Every data variable of two results identical (NaN where NaN)."""
    assert sorted(a.data_vars) == sorted(b.data_vars)
    for name in a.data_vars:
        x, y = a[name].values, b[name].values
        if x.dtype.kind == "f":
            np.testing.assert_array_equal(x, y, err_msg=name)
        else:
            assert np.array_equal(x, y), name
