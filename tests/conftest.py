"""Before a run spread over several workers (pytest-xdist), compile the numba kernels once, in three processes at
once (``tests/warm_kernels.py``): otherwise every worker of a fresh checkout compiles each kernel it meets itself.
From a warm cache this costs the processes' imports (about two seconds)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

#: The groups of tests/warm_kernels.py (not imported here: the controller itself needs no kernel).
GROUPS = ("pair", "systems", "hb")


def pytest_configure(config):
    workers = getattr(config.option, "numprocesses", None)
    if hasattr(config, "workerinput") or not workers or config.option.collectonly:
        return  # a worker, a run in one process, or no run
    script = Path(__file__).with_name("warm_kernels.py")
    procs = [subprocess.Popen([sys.executable, str(script), group], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL) for group in GROUPS]
    for p in procs:
        p.wait()  # a failure shows in the tests that use the kernel
