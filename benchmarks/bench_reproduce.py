"""Wall time of `geardyn reproduce` with the numba cache warm (target: <= 60 s on 2 cores).

Runs the command once to warm the cache (unless --no-warm), then `--repeat` more times, each in a
fresh process exactly as a user runs it, and prints the wall times and the machine's load.

    python benchmarks/bench_reproduce.py [--repeat 2] [--workers 2] [--out DIR]
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


def run_once(out: str, workers: int) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "geardyn.cli", "reproduce", "--out", out, "--workers", str(workers), "--json"],
                   check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=None, help="keep the last report here")
    ap.add_argument("--no-warm", action="store_true")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="geardyn-reproduce-")
    try:
        if not args.no_warm:
            run_once(os.path.join(tmp, "warm"), args.workers)
        times = [run_once(os.path.join(tmp, f"run{i}"), args.workers) for i in range(args.repeat)]
        result = {"wall_s": times, "min_wall_s": min(times), "workers": args.workers, "cpus": os.cpu_count(),
                  "load_avg_1min": os.getloadavg()[0]}
        print(json.dumps(result, indent=2))
        if args.out:
            shutil.rmtree(args.out, ignore_errors=True)
            shutil.copytree(os.path.join(tmp, f"run{args.repeat - 1}"), args.out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
