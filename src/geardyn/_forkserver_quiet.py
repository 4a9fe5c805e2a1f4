"""Imported first by the fork server of local worker processes (:data:`geardyn.sweep.executors.POOL_PRELOAD`).

The fork server protects itself from Ctrl-C only once it has imported its preload modules, and restores the
handlers it found in every process it forks.  Importing this module in the fork server's main thread, before
anything else, makes SIGINT ignored there from then on, so that a Ctrl-C to the terminal's process group
while the server imports or forks prints no traceback from the server or a worker: the main process handles
the signal and stops its workers.  It acts only in a fork server (a process started as ``python -c`` that
imported :mod:`multiprocessing.forkserver`), never where it is imported by anything else.
"""

from __future__ import annotations

import signal
import sys
import threading


def _in_fork_server() -> bool:
    return (
        sys.argv[:1] == ["-c"]
        and "multiprocessing.forkserver" in sys.modules
        and threading.current_thread() is threading.main_thread()
    )


if _in_fork_server():
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _quiet_start() -> None:
    """A worker forked after the main process left (a pool stopped on a signal) finds the pool's semaphores
    gone while it unpickles its process object: it ends with exit code 1 without a traceback on the
    terminal's stderr.  Its process object never ran, so nothing is lost; a pool whose main process is
    alive sees the worker fail as a broken pool and says so."""
    from multiprocessing import spawn

    start = spawn._main

    def main(fd: int, parent_sentinel: int) -> int:
        try:
            return start(fd, parent_sentinel)
        except (FileNotFoundError, EOFError, ConnectionError):
            return 1

    spawn._main = main


if _in_fork_server():
    _quiet_start()
