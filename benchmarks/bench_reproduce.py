"""Wall time of `geardyn reproduce` with the numba cache warm (target: <= 120 s on 2 cores).

Runs the command once per checkout to warm the cache (unless --no-warm), then `--repeat` more
times, each in a fresh process exactly as a user runs it, and prints the wall times and the
machine's load.  With ``--before SRC`` (the ``src`` directory of an earlier checkout, e.g. from
``git worktree add /tmp/prev HEAD~1``) the earlier checkout is timed in the same run, the two
alternating, so that both see the same load on a shared machine.

    python benchmarks/bench_reproduce.py [--repeat 2] [--workers 2] [--out DIR] [--before SRC]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1] / "src"


def run_once(out: str, workers: int, src: Path) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(src))
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "geardyn.cli", "reproduce", "--out", out, "--workers", str(workers), "--json"],
        check=True,
        stdout=subprocess.DEVNULL,
        env=env,
    )
    return {"wall_s": time.perf_counter() - t0, "load_before": load, "load_after": os.getloadavg()[0]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=None, help="keep the last report of this checkout here")
    ap.add_argument("--no-warm", action="store_true")
    ap.add_argument("--before", default=None, help="src directory of an earlier checkout, timed alternately")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="geardyn-reproduce-")
    checkouts = {"this": HERE} | ({"before": Path(args.before).resolve()} if args.before else {})
    try:
        if not args.no_warm:
            for name, src in checkouts.items():
                run_once(os.path.join(tmp, f"warm-{name}"), args.workers, src)
        runs: dict[str, list[dict[str, float]]] = {name: [] for name in checkouts}
        for i in range(args.repeat):
            for name, src in checkouts.items():
                runs[name].append(run_once(os.path.join(tmp, f"{name}{i}"), args.workers, src))
        result = {
            name: {
                "wall_s": [r["wall_s"] for r in rs],
                "min_wall_s": min(r["wall_s"] for r in rs),
                "load_avg_1min": [r["load_before"] for r in rs],
            }
            for name, rs in runs.items()
        }
        result.update(workers=args.workers, cpus=os.cpu_count())
        print(json.dumps(result, indent=2))
        if args.out:
            shutil.rmtree(args.out, ignore_errors=True)
            shutil.copytree(os.path.join(tmp, f"this{args.repeat - 1}"), args.out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
