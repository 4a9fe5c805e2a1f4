"""Signals at any moment: a Ctrl-C to the terminal's process group never reaches the fork server of local
worker processes or a worker (they would print a KeyboardInterrupt traceback); the main process handles it."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

SCRIPT = r"""
import threading
from multiprocessing import forkserver
from geardyn.sweep.executors import _start_forkserver

t = threading.Thread(target=_start_forkserver)  # a command's sweep runs off the main thread
t.start(); t.join()
import time
pid = forkserver._forkserver._forkserver_pid
def fields():
    status = open(f"/proc/{pid}/status").read()
    return dict(line.split(":\t") for line in status.splitlines() if ":\t" in line)
blocked = int(fields()["SigBlk"], 16) & 2
end = time.monotonic() + 60
while not int(fields()["SigIgn"], 16) & 2 and time.monotonic() < end:  # ignored once its imports are done
    time.sleep(0.05)
print(blocked, int(fields()["SigIgn"], 16) & 2)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_the_fork_server_starts_with_sigint_blocked():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    r = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    blocked, ignored = (int(x) for x in r.stdout.split())
    assert blocked == 2  # SIGINT (signal 2, bit 1) blocked from the server's first instruction
    assert ignored == 2  # and ignored once its imports are done, its workers forked with it ignored


def test_a_worker_that_finds_its_pool_gone_starts_quietly():
    """The fork server's start of a worker ends with code 1, no traceback, when the pool's semaphores are gone."""
    code = (
        "import sys; sys.argv[:1] = ['-c']; import multiprocessing.forkserver, multiprocessing.spawn as s; "
        "s._main = lambda fd, ps: (_ for _ in ()).throw(FileNotFoundError(2, 'gone')); "
        "import geardyn._forkserver_quiet; print(s._main(0, 0))"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=env)
    assert r.returncode == 0 and r.stdout.strip() == "1" and "Traceback" not in r.stderr, r.stderr
