"""Start-up cost: short ``geardyn`` commands against ``python -c "import numpy"``, side by side in one run.

Commands, each a fresh process running this checkout (``src`` first on ``PYTHONPATH``) through the console
script ``geardyn`` that pip installed beside this interpreter, as a user runs it (the entry point
:func:`geardyn.cli.main` run by this interpreter where there is no such script):

* ``numpy``: ``python -c "import numpy"`` (the reference);
* ``help``: ``geardyn --help``;
* ``simulate``: ``geardyn simulate --omega 0.8 --json``.

One warm-up round first (it fills numba's cache and Python's bytecode cache if they are cold, so the timed
rounds run warm, as an installed package does),
then ``--rounds`` rounds, each running the commands one after the other (interleaved, so a change of the
machine's load hits all of them alike).  For each command: the minimum and median wall time and CPU time
(user + system of the child); for each geardyn command, the ratio to the reference in each round, and the
median and minimum of those ratios.  Targets (issue 25): help <= 2x, simulate <= 5x.

Floors, timed in the same rounds with ``--floors``: ``python -c pass`` (the interpreter), ``python -c "import
numba"``, and ``numba_call``: a process that imports nothing but a one-line ``@njit(cache=True)`` function from a
temporary directory and calls it from numba's warm cache (what any command that runs a compiled kernel pays
before its own work: ``import numba`` and the first call's set-up of numba's typing and lowering registries).

Where the time goes, ``--where``: each geardyn command run ``--where-runs`` times with ``python -X importtime``
and timers on numba's cache load; the wall time of each part, median over the runs (the interpreter's start
from ``python -c pass`` timed in the same runs):

* the imports, grouped by package (a module's own time, its imports excluded; a standard-library module
  counts for the package that imported it first); the modules imported during numba's first call in a
  group of their own (with numba's own loader: its typing and lowering registries, which import
  ``scipy.linalg`` and ``cffi``);
* numba's first call without those imports: the rest of its set-up (with numba's own loader: its
  registries), then reading the cached machine code and linking it (the modules that the cached code's
  environment names are imported as it is read: a group of their own);
* the rest: parsing the options, the computation, the output and the exit.

Run: ``python benchmarks/startup.py [--rounds 15] [--before OTHER/src] [--floors] [--where]`` (about half a
minute; ``--before`` adds another checkout's ``help`` and ``simulate`` to the same rounds).  Writes
``benchmarks/results/startup.json`` (``--where``: ``startup_where.json``).
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
#: The console script pip installed beside this interpreter (what a user types), else the entry point run by it.
SCRIPT = (
    [str(Path(sys.executable).with_name("geardyn"))]
    if Path(sys.executable).with_name("geardyn").is_file()
    else [sys.executable, "-c", ENTRY]
)
COMMANDS = {
    "numpy": [sys.executable, "-c", "import numpy"],
    "help": [*SCRIPT, "--help"],
    "simulate": [*SCRIPT, "simulate", "--omega", "0.8", "--json"],
}
#: The arguments of a geardyn command (after the script).
ARGS = {name: cmd[len(SCRIPT) :] for name, cmd in COMMANDS.items() if name != "numpy"}
TARGETS = {"help": 2.0, "simulate": 5.0}
FLOOR_KERNEL = "from numba import njit\n\n\n@njit(cache=True)\ndef f(x):\n    return x + 1.0\n"
#: Import groups of ``--where``: a module's group is the first whose prefix its name has.
GROUPS = [
    ("numpy", ("numpy",)),
    ("typer and click", ("typer", "click", "shellingham", "annotated_doc")),
    ("rich", ("rich", "pygments", "markdown_it", "mdurl")),
    ("pydantic", ("pydantic", "pydantic_core", "annotated_types", "typing_inspection")),
    ("geardyn.cli", ("geardyn.cli",)),
    ("geardyn (model, analysis, kernel modules)", ("geardyn",)),
    ("import numba (numba, llvmlite, what they import)", ("numba", "llvmlite")),
    ("Python's standard library (imported by none of the above)", ("",)),
]
#: Run in the child of ``--where`` before the command: times numba's loads of cached functions.
PROBE = r"""
import json, sys, time
_BEFORE = set(sys.modules)
_LOADS = []  # per first call of a compiled function: its wall time and the modules it imported
_LINKS = []  # per cached function read: the time to read and link its machine code


def _timed(module):
    if module.__name__ == "numba.core.dispatcher":
        compile_ = module.Dispatcher.compile

        def compile(self, sig):
            if self.overloads:
                return compile_(self, sig)
            before, t = set(sys.modules), time.perf_counter()
            try:
                return compile_(self, sig)
            finally:
                _LOADS.append({"wall": time.perf_counter() - t, "modules": sorted(set(sys.modules) - before)})

        module.Dispatcher.compile = compile
    else:
        read = module.Cache._load_overload

        def _load_overload(self, *a, **k):
            before, t = set(sys.modules), time.perf_counter()
            try:
                return read(self, *a, **k)
            finally:
                _LINKS.append({"wall": time.perf_counter() - t, "modules": sorted(set(sys.modules) - before)})

        module.Cache._load_overload = _load_overload


class _Probe:
    names = {"numba.core.dispatcher", "numba.core.caching"}

    def find_spec(self, name, path=None, target=None):
        if name not in self.names:
            return None
        self.names = self.names - {name}
        sys.meta_path.remove(self)
        try:
            import importlib.util

            spec = importlib.util.find_spec(name)
        finally:
            if self.names:
                sys.meta_path.insert(0, self)
        run = spec.loader.exec_module

        def exec_module(module):
            run(module)
            _timed(module)

        spec.loader.exec_module = exec_module
        return spec


sys.meta_path.insert(0, _Probe())


def _report():
    print("STARTUP-PROBE " + json.dumps({"before": sorted(_BEFORE), "loads": _LOADS, "links": _LINKS}),
          file=sys.stderr)


import atexit
atexit.register(_report)
"""


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


def _group(module: str) -> str:
    return next(
        name for name, prefixes in GROUPS if any(module == p or module.startswith(p + ".") or p == "" for p in prefixes)
    )


def _where_run(cmd: list[str], env: dict[str, str]) -> tuple[float, dict[str, float]]:
    """Wall seconds of one ``--where`` run of ``cmd`` and the seconds of each part (see the module)."""
    t = time.perf_counter()
    r = subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t
    rows: list[tuple[int, str, float]] = []  # (nesting level, module, its own seconds), in importtime's order
    probe: dict = {"before": [], "loads": []}
    for line in r.stderr.splitlines():
        if line.startswith("STARTUP-PROBE "):
            probe = json.loads(line.split(" ", 1)[1])
        elif line.startswith("import time:") and "|" in line and "self [us]" not in line:
            us, _, name = line[len("import time:") :].split("|")
            rows.append(((len(name) - len(name.lstrip()) - 1) // 2, name.strip(), int(us) / 1e6))
    before = set(probe["before"])
    in_read = {m for read in probe.get("links", []) for m in read["modules"]}
    in_load = {m for load in probe["loads"] for m in load["modules"]} - in_read
    first = "numba's first call: imports (set-up)"
    unpickled = "numba's first call: imports (the modules the cached code's environment names)"
    parts: dict[str, float] = {}
    # A module imported by another (printed before it, one level deeper) counts for the other's group unless
    # it is of a named package itself: ``inspect`` first imported by numba is numba's cost.
    stack: list[tuple[int, str]] = []
    for level, name, sec in reversed(rows):
        while stack and stack[-1][0] >= level:
            stack.pop()
        own = first if name in in_load else unpickled if name in in_read else _group(name)
        group = stack[-1][1] if own == GROUPS[-1][0] and stack else own
        stack.append((level, group))
        if name not in before:
            key = group if group in (first, unpickled) else f"import: {group}"
            parts[key] = parts.get(key, 0.0) + sec
    load = sum(one["wall"] for one in probe["loads"])
    read = sum(one["wall"] for one in probe.get("links", []))
    if probe["loads"]:
        parts["numba's first call: the rest of its set-up"] = max(0.0, load - read - parts.get(first, 0.0))
        parts["numba's first call: the cached code read and linked"] = max(0.0, read - parts.get(unpickled, 0.0))
    return wall, parts


def where(runs: int, env: dict[str, str]) -> dict:
    """``--where``: each geardyn command's wall time split into parts (medians over ``runs`` runs)."""
    out: dict = {}
    start: list[float] = []
    walls: dict[str, list[float]] = {name: [] for name in TARGETS}
    parts: dict[str, list[dict[str, float]]] = {name: [] for name in TARGETS}
    for _ in range(runs):
        start.append(_run([sys.executable, "-c", "pass"], env)[0])
        for name in TARGETS:
            cmd = [sys.executable, "-X", "importtime", "-c", PROBE + "\n" + ENTRY, *ARGS[name]]
            w, p = _where_run(cmd, env)
            walls[name].append(w)
            parts[name].append(p)
    py = statistics.median(start)
    for name in TARGETS:
        keys = sorted({k for p in parts[name] for k in p})
        med = {k: statistics.median([p.get(k, 0.0) for p in parts[name]]) for k in keys}
        rest = [w - py - sum(p.values()) for w, p in zip(walls[name], parts[name])]
        table = {
            "Python's start (python -c pass)": py,
            **med,
            "the rest: options parsed, the computation, the output, the exit": statistics.median(rest),
        }
        out[name] = {"wall_median_s": statistics.median(walls[name]), "parts_s": table}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument(
        "--before",
        type=Path,
        default=None,
        help="the src directory of another checkout: its help and simulate are timed in the same rounds",
    )
    ap.add_argument(
        "--floors",
        action="store_true",
        help="also time python -c pass, import numba and one cached numba function in the same rounds",
    )
    ap.add_argument("--where", action="store_true", help="split each command's time into parts instead")
    ap.add_argument("--where-runs", type=int, default=7)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    out = args.out or ROOT / "benchmarks" / "results" / ("startup_where.json" if args.where else "startup.json")

    def environment(src: Path) -> dict[str, str]:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(src), os.environ.get("PYTHONPATH")])))
        env.pop(
            "PYTHONDONTWRITEBYTECODE", None
        )  # warm means compiled: the bytecode cache as an installed package has it
        return env

    if args.where:
        env = environment(ROOT / "src")
        for name in TARGETS:  # warm-up
            _run(COMMANDS[name], env)
        result = where(args.where_runs, env)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(result, indent=2) + "\n")
        for name, r in result.items():
            print(f"geardyn {' '.join(ARGS[name])}: {r['wall_median_s']:.3f} s wall (median; under importtime)")
            for part, sec in sorted(r["parts_s"].items(), key=lambda kv: -kv[1]):
                print(f"  {sec * 1000:7.1f} ms  {part}")
        print(f"written {out}")
        return

    runs = {name: (cmd, environment(ROOT / "src")) for name, cmd in COMMANDS.items()}
    tmp = None
    if args.floors:
        import tempfile

        tmp = tempfile.TemporaryDirectory()
        Path(tmp.name, "floor_kernel.py").write_text(FLOOR_KERNEL)
        runs["pass"] = ([sys.executable, "-c", "pass"], environment(ROOT / "src"))
        runs["numba"] = ([sys.executable, "-c", "import numba"], environment(ROOT / "src"))
        runs["numba_call"] = (
            [sys.executable, "-c", "import floor_kernel; floor_kernel.f(1.0)"],
            environment(Path(tmp.name)),
        )
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
        "machine": {
            "platform": platform.platform(),
            "python": platform.python_version(),
            "cpus": os.cpu_count(),
            "load_before": load_before,
            "load_after": load_after,
        },
        "rounds": args.rounds,
        "before": args.before is not None,  # another checkout timed beside (its path not recorded)
        "commands": {
            k: " ".join(["python", *v[1:]]) if k == "numpy" else "geardyn " + " ".join(v[len(SCRIPT) :])
            for k, v in COMMANDS.items()
        },
        "wall_s": {k: _stats(v) for k, v in wall.items()},
        "cpu_s": {k: _stats(v) for k, v in cpu.items()},
        "ratio_to_numpy": {},
    }
    if tmp is not None:
        result["commands"].update(
            {
                "pass": "python -c pass",
                "numba": 'python -c "import numba"',
                "numba_call": "python -c <a one-line @njit(cache=True) function, called from the cache>",
            }
        )
    extra = [f"{k}_before" for k in TARGETS if f"{k}_before" in runs] + [
        k for k in ("pass", "numba", "numba_call") if k in runs
    ]
    for name, target in [*TARGETS.items(), *((k, None) for k in extra)]:
        rw = [a / b for a, b in zip(wall[name], wall["numpy"])]
        rc = [a / b for a, b in zip(cpu[name], cpu["numpy"])]
        result["ratio_to_numpy"][name] = {
            "wall": _stats(rw),
            "cpu": _stats(rc),
            "target": target,
            "met": None if target is None else statistics.median(rw) <= target,
        }
    if tmp is not None:
        tmp.cleanup()
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"{'command':16s} {'wall min':>9s} {'median':>8s} {'cpu median':>11s} {'ratio: wall':>12s} {'cpu':>6s}")
    for name in runs:
        r = result["ratio_to_numpy"].get(name)
        ratio = "1" if r is None else f"{r['wall']['median']:.2f}x {r['cpu']['median']:.2f}x"
        target = f"  (target {r['target']:g}x)" if r is not None and r["target"] else ""
        print(
            f"{name:16s} {result['wall_s'][name]['min']:9.3f} {result['wall_s'][name]['median']:8.3f} "
            f"{result['cpu_s'][name]['median']:11.3f} {ratio:>19s}{target}"
        )
    print(f"written {out}")


if __name__ == "__main__":
    main()
