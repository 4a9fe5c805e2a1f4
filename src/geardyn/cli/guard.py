"""The process around a command: its output streams, its signals and its strict JSON.

* **Streams.**  A standard stream that is closed (``geardyn ... --json >&-``) is replaced by the null
  device, so the command runs and ends quietly; a stream whose encoding cannot write every character
  (``PYTHONIOENCODING=ascii``, an ASCII terminal) writes ASCII fallbacks (``µ`` → ``u``, ``ω`` →
  ``omega``, ``≥`` → ``>=`` ...).  A reader that stops reading (``| head``) ends the command quietly.
* **Signals.**  :func:`run_guarded` runs the command in a worker thread while the main thread waits and
  handles SIGINT and SIGTERM: on the first one it asks the command to stop (a sweep then keeps its
  finished chunks and says how to resume), gives it :data:`GRACE` seconds, removes the temporary files
  of writes in progress, stops the worker processes the command started and leaves with exit code 130
  (SIGINT) or 143 (SIGTERM) after one line on stderr.  A second signal leaves at once.  The kernels
  are never interrupted: they run on, in the threads that are dropped with the process.
* **JSON.**  :func:`strict_json` writes RFC 8259 JSON: a non-finite number becomes ``null`` and its
  place is listed under ``"non_finite"``.
"""

from __future__ import annotations

import codecs
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

# ctypes, json and unicodedata are imported where they are used: every command imports this module.

__all__ = [
    "GRACE",
    "STOP",
    "check_stop",
    "leave_on_signals_while_starting",
    "prepare_streams",
    "quiet_broken_pipe",
    "run_guarded",
    "strict_json",
]

#: Seconds a command is given to stop by itself after SIGINT or SIGTERM (finish its current chunk
#: writes, raise its own "interrupted" message) before the process leaves anyway.
GRACE = 0.7

#: Exit codes by signal (128 + the signal number, the shell convention).
SIGNAL_EXIT = {signal.SIGINT: 130, signal.SIGTERM: 143}

# ---------------------------------------------------------------- streams
#: ASCII spellings of the characters geardyn prints (others: their unaccented letter, else "?").
ASCII = {
    "µ": "u",
    "μ": "u",
    "ω": "omega",
    "Ω": "Omega",
    "τ": "tau",
    "θ": "theta",
    "ξ": "xi",
    "κ": "kappa",
    "ε": "eps",
    "φ": "phi",
    "ϕ": "phi",
    "λ": "lambda",
    "Δ": "d",
    "δ": "d",
    "σ": "sigma",
    "π": "pi",
    "α": "alpha",
    "β": "beta",
    "γ": "gamma",
    "ζ": "zeta",
    "η": "eta",
    "ν": "nu",
    "ρ": "rho",
    "ψ": "psi",
    "≥": ">=",
    "≤": "<=",
    "≠": "!=",
    "≈": "~",
    "±": "+-",
    "×": "x",
    "·": "*",
    "→": "->",
    "←": "<-",
    "…": "...",
    "°": "deg",
    "√": "sqrt",
    "∞": "inf",
    "‖": "||",
    "’": "'",
    "‘": "'",
    "“": '"',
    "”": '"',
    "•": "*",
    "✓": "ok",
    "✗": "x",
    "█": "#",
    "▌": "#",
    "\u00a0": " ",
    **dict.fromkeys("╭╮╰╯┏┓┗┛┡┩├┤┼┌┐└┘╇╈┳┻╋┬┴", "+"),  # box drawing
    **dict.fromkeys("−–—─━", "-"),
    **dict.fromkeys("│┃▏", "|"),
    **{c: "^" + d for c, d in zip("²³⁻¹⁰⁴⁵⁶⁷⁸⁹", "23-10456789")},  # superscripts
    **dict(zip("⠋⠙⠹⠸⠼⠴⠦⠧⠇⠏", "-\\|/-\\|/-\\")),  # the frames of a spinner
}
ERROR_HANDLER = "geardyn-ascii"


def ascii_text(text: str) -> str:
    """``text`` with every non-ASCII character replaced by its ASCII fallback (:data:`ASCII`)."""
    return "".join(c if ord(c) < 128 else _fallback(c) for c in text)


def _fallback(c: str) -> str:
    if c in ASCII:
        return ASCII[c]
    import unicodedata

    folded = unicodedata.normalize("NFKD", c).encode("ascii", "ignore").decode("ascii")
    return folded or "?"


def _ascii_errors(err: UnicodeError) -> tuple[str, int]:
    if not isinstance(err, UnicodeEncodeError):
        raise err
    return ascii_text(err.object[err.start : err.end]), err.end


codecs.register_error(ERROR_HANDLER, _ascii_errors)


def _fd_open(fd: int) -> bool:
    try:
        os.fstat(fd)
        return True
    except OSError:
        return False


def _null_onto(fd: int) -> None:
    """Open the null device on file descriptor ``fd`` (so that nothing else opened later takes it)."""
    nd = os.open(os.devnull, os.O_WRONLY)
    if nd != fd:
        os.dup2(nd, fd)
        os.close(nd)


def prepare_streams() -> None:
    """Make stdout and stderr safe to write: a closed one goes to the null device, one that cannot encode
    every character writes ASCII fallbacks (see the module)."""
    for name, fd in (("stdout", 1), ("stderr", 2)):
        s = getattr(sys, name)
        if s is None or (_is_real(s) and not _fd_open(fd)):
            if not _fd_open(fd):
                _null_onto(fd)
            setattr(sys, name, open(fd, "w", encoding="utf-8", closefd=False))
            continue
        enc = getattr(s, "encoding", None) or "utf-8"
        try:
            utf = codecs.lookup(enc).name.startswith("utf")
        except LookupError:
            utf = False
        if not utf and hasattr(s, "reconfigure"):
            try:
                s.reconfigure(errors=ERROR_HANDLER)
            except (ValueError, OSError):
                pass


def _is_real(stream: Any) -> bool:
    """A stream on a file descriptor (not a test runner's buffer)."""
    try:
        stream.fileno()
        return True
    except (OSError, ValueError, AttributeError):
        return False


def quiet_broken_pipe() -> None:
    """After a reader closed stdout: point it at the null device, so that nothing more fails on it."""
    try:
        if _is_real(sys.stdout) and sys.stdout.fileno() == 1:
            _null_onto(1)
    except (OSError, ValueError):
        pass


# ---------------------------------------------------------------- JSON
def strict_json(obj: Any) -> str:
    """``obj`` as indented RFC 8259 JSON: NumPy values as plain numbers and lists, every non-finite
    number as ``null`` with its place listed under ``"non_finite"`` (for a dict at the top).

    Parameters
    ----------
    obj : object
        A JSON-serialisable value (dicts, lists, strings, numbers, NumPy scalars and arrays).

    Returns
    -------
    str
        The JSON text (ASCII, every other character escaped).

    Raises
    ------
    TypeError
        For a value that is not JSON-serialisable.
    """
    import json

    bad: list[str] = []
    clean = _finite(obj, "", bad)
    if bad and isinstance(clean, dict):
        clean = {**clean, "non_finite": bad[:100]}
    return json.dumps(clean, indent=2, allow_nan=False)


def _finite(o: Any, where: str, bad: list[str]) -> Any:
    if isinstance(o, dict):
        return {str(k): _finite(v, f"{where}.{k}" if where else str(k), bad) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_finite(v, f"{where}[{i}]", bad) for i, v in enumerate(o)]
    if o is None or isinstance(o, (str, int)):  # bool among the int
        return o
    if isinstance(o, float):
        if math.isfinite(o):
            return o
        bad.append(where or "value")
        return None
    import numpy as np

    if isinstance(o, (np.ndarray, np.generic)):  # (a NumPy scalar's tolist is its item)
        return _finite(o.tolist(), where, bad)
    if isinstance(o, (set, frozenset)):
        return _finite(sorted(o, key=str), where, bad)
    if hasattr(o, "__fspath__"):
        return os.fspath(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


# ---------------------------------------------------------------- signals
class _Stop:
    """The signal that asked the command to stop (None while running)."""

    def __init__(self) -> None:
        self.event = threading.Event()
        self.reset()

    def reset(self) -> None:
        self.signum: int | None = None
        self.message: str | None = None
        self.event.clear()


STOP = _Stop()


def check_stop() -> None:
    """Raise :class:`KeyboardInterrupt` once SIGINT or SIGTERM has asked the command to stop (so that it
    never reports success after it)."""
    if STOP.event.is_set():
        raise KeyboardInterrupt


def _inject(thread: threading.Thread, exc: type[BaseException]) -> None:
    """Raise ``exc`` in ``thread`` at its next Python instruction (a kernel call runs on until it returns)."""
    if thread.ident is None or not thread.is_alive():
        return
    import ctypes

    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread.ident), ctypes.py_object(exc))


#: Seconds the worker processes of a stopped command are given to end after SIGTERM, before the process leaves.
CHILDREN_GRACE = 0.15


def _stop_children() -> None:
    """Terminate the worker processes this process started, wait for them a moment (:data:`CHILDREN_GRACE`),
    and release the semaphores their pools hold (their finalizers), so that no worker starting up meets a
    semaphore already gone (a traceback on the shared stderr) and the resource tracker finds nothing leaked."""
    if "multiprocessing" not in sys.modules:
        return
    try:
        import multiprocessing
        import multiprocessing.util

        children = multiprocessing.active_children()
        for p in children:
            p.terminate()
        deadline = time.monotonic() + CHILDREN_GRACE
        for p in children:
            p.join(max(0.0, deadline - time.monotonic()))
        multiprocessing.util._run_finalizers(0)  # unlink and unregister the pools' semaphores
    except Exception:  # noqa: BLE001  (leaving anyway)
        pass


def _leave(code: int, message: str) -> None:
    """Clean up what a stopped command leaves (temporary files, worker processes), say ``message`` on stderr
    and end the process with ``code`` at once."""
    try:
        from ..io import discard_temporaries

        discard_temporaries()
    except Exception:  # noqa: BLE001  (leaving anyway)
        pass
    _stop_children()
    try:  # (a stream that is None or closed: nothing written)
        if sys.stderr.isatty():
            sys.stderr.write("\x1b[?25h")  # a progress display hides the cursor: show it again
        sys.stderr.write(" ".join(message.split()) + "\n")
        sys.stderr.flush()
    except Exception:  # noqa: BLE001
        pass
    try:
        sys.stdout.flush()
    except Exception:  # noqa: BLE001
        pass
    os._exit(code)


def _interrupted_message(exc: BaseException | None) -> str:
    from ..sweep import SweepInterrupted

    if STOP.message:
        return STOP.message
    if isinstance(exc, SweepInterrupted):
        return str(exc)
    from ..sweep.checkpoints import active_checkpoints

    dirs = active_checkpoints()
    if dirs:
        saved = len(list(dirs[-1].glob("chunk-*.npz")))
        if saved == 0:
            return f"interrupted before any chunk of the sweep finished: nothing is saved in {dirs[-1]}"
        return (
            f"interrupted: {saved} finished chunk{'s' if saved > 1 else ''} saved in {dirs[-1]}; run the same "
            f"command again with --resume to complete the sweep"
        )
    return "interrupted"


def _early_handler(signum: int, frame: Any) -> None:
    """Before a command runs (its modules still importing): nothing to keep, nothing to clean but worker
    processes; leave at once with the signal's exit code."""
    _leave(SIGNAL_EXIT.get(signum, 130), "interrupted")


def leave_on_signals_while_starting() -> bool:
    """In the ``geardyn`` program, SIGINT and SIGTERM leave at once (130, 143, one line) from the first
    instant, while the command's modules are still being imported; :func:`run_guarded` takes over once the
    command runs.  Only where the process still has Python's default handlers, on the main thread.

    Returns
    -------
    bool
        Whether the handlers were installed.
    """
    if threading.current_thread() is not threading.main_thread():
        return False
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return False
    if signal.getsignal(signal.SIGTERM) not in (signal.SIG_DFL, None):
        return False
    for s in SIGNAL_EXIT:
        signal.signal(s, _early_handler)
    return True


def run_guarded(body: Callable[[], int]) -> int:
    """Run ``body()`` (which returns an exit code) in a worker thread, the main thread handling signals.

    Off the main thread (where signals cannot be handled) ``body`` runs directly.

    Parameters
    ----------
    body : callable
        The command; it returns its exit code and raises nothing it can report itself.

    Returns
    -------
    int
        ``body``'s exit code.  After SIGINT or SIGTERM the process ends in :func:`_leave` instead (130 or 143).
    """
    if threading.current_thread() is not threading.main_thread():
        return body()
    STOP.reset()
    outcome: dict[str, Any] = {}

    def target() -> None:
        try:
            outcome["code"] = body()
        except BaseException as e:  # noqa: BLE001  (handed to the main thread)
            outcome["exc"] = e

    worker = threading.Thread(target=target, name="geardyn-command", daemon=True)

    def handler(signum: int, frame: Any) -> None:
        if STOP.signum is not None:  # a second signal: leave now
            _leave(SIGNAL_EXIT.get(STOP.signum, 130), "interrupted")
        STOP.signum = signum
        STOP.event.set()

    previous = {s: signal.signal(s, handler) for s in SIGNAL_EXIT}  # (signal.signal returns the handler it replaces)
    if hasattr(signal, "SIGXFSZ"):  # a file-size limit makes a write fail (EFBIG) instead of killing the process
        previous[signal.SIGXFSZ] = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    try:
        worker.start()
        while worker.is_alive() and STOP.signum is None:
            worker.join(0.05)
        if STOP.signum is None:
            if "exc" in outcome:
                raise outcome["exc"]
            return int(outcome.get("code", 0))
        code = SIGNAL_EXIT.get(STOP.signum, 130)
        _inject(worker, KeyboardInterrupt)
        deadline = time.monotonic() + GRACE
        while worker.is_alive() and time.monotonic() < deadline:
            worker.join(0.02)
        _leave(code, _interrupted_message(outcome.get("exc")))
        return code  # (not reached)
    finally:
        for s, h in previous.items():
            if h is not None:
                signal.signal(s, h)
