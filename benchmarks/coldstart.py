"""The first answer of a fresh install: each command's first run against its second, on a new venv.

Creates a new virtual environment, installs this checkout into it with ``pip install`` (which compiles the
kernels into the package: ``setup.py``, ``geardyn._precompile``), points numba's and geardyn's user caches at
an empty directory, then runs each command of :data:`COMMANDS` twice in a row — the first run of a fresh
install, then the second — as whole processes of the venv's console script, and reports the CPU time
(user + system of the child) and wall time of each run and the ratio first/second.  Target (issue 34):
first ≤ 2× second for ``simulate``, ``bifurcation``, ``hb`` and ``simulate --system`` (8-DOF).

``--no-precompile`` installs with ``GEARDYN_NO_PRECOMPILE=1`` (the install before this change: every kernel is
compiled at its first use), for the same table side by side.

Run: ``python benchmarks/coldstart.py [--no-precompile] [--venv DIR]`` (the install takes a few minutes: it
compiles).  Writes ``benchmarks/results/coldstart.json`` (``coldstart_no_precompile.json``).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BEVEL = str(ROOT / "examples" / "systems" / "paper_bevel_8dof.toml")
COMMANDS = {
    "simulate": ["simulate", "--omega", "0.8", "--json"],
    "bifurcation": ["bifurcation", "--param", "omega", "--start", "0.5", "--stop", "1.5", "--json"],
    "hb": ["hb", "--param", "omega", "--start", "0.5", "--stop", "1.5", "--json"],
    "simulate --system": ["simulate", "--system", BEVEL, "--omega", "0.8", "--json"],
}
TARGET = 2.0


def _timed(cmd: list[str], env: dict[str, str], cwd: str) -> tuple[float, float, int]:
    """(CPU s of the child, wall s, exit code) of one whole process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, p.returncode


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-precompile", action="store_true", help="install without compiling the kernels")
    ap.add_argument("--venv", type=Path, default=None, help="where to create the venv (default: a temporary one)")
    ns = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="geardyn-cold-")
    venv = ns.venv or Path(tmp) / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    py = venv / "bin" / "python"
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    env.pop("NUMBA_CACHE_DIR", None)
    if ns.no_precompile:
        env["GEARDYN_NO_PRECOMPILE"] = "1"
    t0 = time.perf_counter()
    subprocess.run([str(py), "-m", "pip", "install", "--quiet", str(ROOT)], env=env, check=True)
    install_s = time.perf_counter() - t0
    env["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")  # an empty user cache
    script = str(venv / "bin" / "geardyn")
    rows = {}
    for name, args in COMMANDS.items():
        first = _timed([script, *args], env, tmp)
        second = _timed([script, *args], env, tmp)
        rows[name] = {
            "first_cpu_s": first[0],
            "second_cpu_s": second[0],
            "first_wall_s": first[1],
            "second_wall_s": second[1],
            "ratio_cpu": first[0] / second[0],
            "ratio_wall": first[1] / second[1],
            "exit_codes": [first[2], second[2]],
        }
        print(
            f"{name:18s} first {first[0]:6.2f} s CPU ({first[1]:6.2f} s wall)  second {second[0]:6.2f} s CPU "
            f"({second[1]:6.2f} s wall)  ratio CPU {first[0] / second[0]:.2f}  wall {first[1] / second[1]:.2f}"
            f"  (target <= {TARGET})",
            flush=True,
        )
    out = ROOT / "benchmarks" / "results" / ("coldstart_no_precompile.json" if ns.no_precompile else "coldstart.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(
        json.dumps(
            {
                "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "node": platform.machine()},
                "precompiled_at_install": not ns.no_precompile,
                "install_s": install_s,
                "target_first_over_second": TARGET,
                "commands": rows,
            },
            indent=2,
        )
        + "\n"
    )
    print(f"install {install_s:.0f} s; written {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
