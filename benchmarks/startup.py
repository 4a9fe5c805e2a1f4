"""Start-up cost: short ``geardyn`` commands against ``python -c "import numpy"``, side by side in one run.

Commands, each a fresh process of this interpreter running this checkout (``src`` first on ``PYTHONPATH``)
through the console script's entry point (:func:`geardyn.cli.main`):

* ``numpy``: ``python -c "import numpy"`` (the reference);
* ``help``: ``geardyn --help``;
* ``simulate``: ``geardyn simulate --omega 0.8 --json``.

One warm-up round first (it fills numba's cache and Python's bytecode cache if they are cold, so the timed
rounds run warm, as an installed package does),
then ``--rounds`` rounds, each running the commands one after the other (interleaved, so a change of the
machine's load hits all of them alike).  For each command: the minimum and median wall time and CPU time
(user + system of the child); for each geardyn command, the ratio to the reference in each round, and the
median and minimum of those ratios.  Targets (issue 25): help <= 2x, simulate <= 5x.

Run: ``python benchmarks/startup.py [--rounds 15] [--before OTHER/src]`` (about half a minute; ``--before`` adds
another checkout's ``help`` and ``simulate`` to the same rounds).  Writes
``benchmarks/results/startup.json``.  Where the time goes: ``python -X importtime -m geardyn.cli simulate
--omega 0.8 --json`` (docs/performance.md).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENTRY = "import sys; from geardyn.cli import main; sys.argv[0] = 'geardyn'; sys.exit(main())"
COMMANDS = {
    "numpy": [sys.executable, "-c", "import numpy"],
    "help": [sys.executable, "-c", ENTRY, "--help"],
    "simulate": [sys.executable, "-c", ENTRY, "simulate", "--omega", "0.8", "--json"],
}
TARGETS = {"help": 2.0, "simulate": 5.0}


def _run(cmd: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds of one run of ``cmd`` (its output discarded; a failure stops the benchmark)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def _stats(x: list[float]) -> dict[str, float]:
    return {"min": min(x), "median": statistics.median(x), "max": max(x)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--before", type=Path, default=None,
                    help="the src directory of another checkout: its help and simulate are timed in the same rounds")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "startup.json")
    args = ap.parse_args()

    def environment(src: Path) -> dict[str, str]:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(src), os.environ.get("PYTHONPATH")])))
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # warm means compiled: the bytecode cache as an installed package has it
        return env

    runs = {name: (cmd, environment(ROOT / "src")) for name, cmd in COMMANDS.items()}
    if args.before is not None:
        for name in TARGETS:
            runs[f"{name}_before"] = (COMMANDS[name], environment(args.before.resolve()))
    for cmd, env in runs.values():  # warm-up: numba's cache, the bytecode and file system caches
        _run(cmd, env)
    wall: dict[str, list[float]] = {k: [] for k in runs}
    cpu: dict[str, list[float]] = {k: [] for k in runs}
    load_before = os.getloadavg()
    for _ in range(args.rounds):
        for name, (cmd, env) in runs.items():
            w, c = _run(cmd, env)
            wall[name].append(w)
            cpu[name].append(c)
    load_after = os.getloadavg()
    result: dict = {
        "machine": {"platform": platform.platform(), "python": platform.python_version(), "cpus": os.cpu_count(),
                    "load_before": load_before, "load_after": load_after},
        "rounds": args.rounds,
        "before": args.before is not None,  # another checkout timed beside (its path not recorded)
        "commands": {k: " ".join(["python", *v[1:]]) if k == "numpy" else "geardyn " + " ".join(v[3:])
                     for k, v in COMMANDS.items()},
        "wall_s": {k: _stats(v) for k, v in wall.items()},
        "cpu_s": {k: _stats(v) for k, v in cpu.items()},
        "ratio_to_numpy": {},
    }
    for name, target in [*TARGETS.items(), *((f"{k}_before", None) for k in TARGETS if f"{k}_before" in runs)]:
        rw = [a / b for a, b in zip(wall[name], wall["numpy"])]
        rc = [a / b for a, b in zip(cpu[name], cpu["numpy"])]
        result["ratio_to_numpy"][name] = {"wall": _stats(rw), "cpu": _stats(rc), "target": target,
                                          "met": None if target is None else statistics.median(rw) <= target}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"{'command':16s} {'wall min':>9s} {'median':>8s} {'cpu median':>11s} {'ratio: wall':>12s} {'cpu':>6s}")
    for name in runs:
        r = result["ratio_to_numpy"].get(name)
        ratio = "1" if r is None else f"{r['wall']['median']:.2f}x {r['cpu']['median']:.2f}x"
        target = f"  (target {r['target']:g}x)" if r is not None and r["target"] else ""
        print(f"{name:16s} {result['wall_s'][name]['min']:9.3f} {result['wall_s'][name]['median']:8.3f} "
              f"{result['cpu_s'][name]['median']:11.3f} {ratio:>19s}{target}")
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
