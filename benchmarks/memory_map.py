"""Peak memory of a 10⁶-point 2-D parameter map streamed to disk.

Usage (from the project root)::

    python benchmarks/memory_map.py                      # 1000 x 1000 map, 2 workers
    python benchmarks/memory_map.py --num 316 --workers 2 --out /tmp/map-bench

Runs the user-facing command ``geardyn map`` (ω × ξ0, fixed initial state, no settling passes,
short integration: the point is memory, not physics) with ``--out``: the sweep engine checkpoints
every finished chunk to disk as it completes and writes the NetCDF file at the end; no
trajectory or Poincaré sequence is kept beyond its chunk.  The chunks run on ``--workers``
threads of the command (or, with ``--processes``, in as many worker processes).  The resident
memory of the whole process tree (the command and any worker processes) is sampled every 0.1 s;
the peak of the sum must stay under 2 GB (issue 6).

``--engine lean`` measures the kernel's own footprint instead: this process integrates the grid
in chunks with ``integrate_batch(..., record_poincare=False)`` on all kernel threads and appends
each chunk's per-point results (amplitude, mean, RMS, contact fractions, status) to a binary file
on disk; only one chunk is ever in memory.
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

LIMIT_MB = 2048.0


def _children(pid: int) -> list[int]:
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as f:
            return [int(x) for x in f.read().split()]
    except OSError:
        return []


def _tree(pid: int) -> list[int]:
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        todo.extend(_children(p))
    return out


def _rss_mb(pid: int) -> float:
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return 0.0


FIELDS = ("u_min", "u_max", "mean", "rms", "fraction_drive", "fraction_separation", "fraction_back", "status")


def lean(num: int, transient: int, periods: int, out: Path, chunk: int = 8192) -> dict:
    """Stream a num x num map through integrate_batch in chunks, appending results to ``out/map.f64``."""
    import resource

    import numpy as np

    from geardyn.integrate import integrate_batch
    from geardyn.model import GearModel, IntegrationOptions

    xs = np.linspace(0.5, 0.75, num)
    ys = np.linspace(0.05, 0.3, num)
    opts = IntegrationOptions(transient=transient, periods=periods)
    base = GearModel()
    path = out / "map.f64"
    t0 = time.perf_counter()
    with open(path, "wb") as f:
        for start in range(0, num * num, chunk):
            idx = np.arange(start, min(start + chunk, num * num))
            models = [base.replace(omega=float(xs[i % num]), xi0=float(ys[i // num])) for i in idx]
            r = integrate_batch(models, options=opts, record_poincare=False)
            cols = np.column_stack([r.u_min, r.u_max, r.mean, r.rms, r.contact_fractions, r.status.astype(float)])
            f.write(np.ascontiguousarray(cols).tobytes())
    wall = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {
        "wall_s": wall,
        "peak_rss_tree_mb": rss,
        "peak_rss_single_process_mb": rss,
        "processes": 1,
        "output_bytes": {path.name: path.stat().st_size},
        "columns": list(FIELDS),
        "chunk_points": chunk,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--num", type=int, default=1000, help="grid values per axis (num² points; default 1000)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--transient", type=int, default=20)
    ap.add_argument("--periods", type=int, default=10)
    ap.add_argument("--out", type=Path, help="output directory (default: a temporary one, removed)")
    ap.add_argument("--json", type=Path, help="write the measurements to this file")
    ap.add_argument(
        "--engine",
        choices=("map", "lean"),
        default="map",
        help="map: the geardyn map command (sweep engine); lean: integrate_batch in chunks in this process",
    )
    ap.add_argument("--processes", action="store_true", help="map: run the workers as local worker processes")
    a = ap.parse_args(argv)

    out = a.out or Path(tempfile.mkdtemp(prefix="geardyn-map-bench-"))
    out.mkdir(parents=True, exist_ok=True)
    if a.engine == "lean":
        res = lean(a.num, a.transient, a.periods, out)
        res.update(
            points=a.num * a.num,
            engine="lean",
            transient=a.transient,
            periods=a.periods,
            limit_mb=LIMIT_MB,
            under_limit=res["peak_rss_tree_mb"] < LIMIT_MB,
            load_average=list(os.getloadavg()),
        )
        print(
            f"lean: {a.num}x{a.num} = {a.num * a.num:,} points: {res['wall_s']:.0f} s, peak RSS "
            f"{res['peak_rss_tree_mb']:.0f} MB (limit {LIMIT_MB:.0f} MB); "
            f"{res['output_bytes']['map.f64'] / 1e6:.1f} MB written"
        )
        if a.json:
            a.json.write_text(json.dumps(res, indent=2) + "\n")
        if a.out is None:
            shutil.rmtree(out, ignore_errors=True)
        return 0 if res["under_limit"] else 1
    cmd = [
        sys.executable,
        "-m",
        "geardyn.cli",
        "map",
        "--x",
        "omega",
        "--x-start",
        "0.5",
        "--x-stop",
        "0.75",
        "--x-num",
        str(a.num),
        "--y",
        "xi0",
        "--y-start",
        "0.05",
        "--y-stop",
        "0.3",
        "--y-num",
        str(a.num),
        "--settle",
        "0",
        "--transient",
        str(a.transient),
        "--periods",
        str(a.periods),
        "--workers",
        str(a.workers),
        "--out",
        str(out),
    ] + (["--processes"] if a.processes else [])
    print(" ".join(cmd), file=sys.stderr)
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    peak_total = peak_single = 0.0
    peak_procs = 0
    while proc.poll() is None:
        pids = _tree(proc.pid)
        rss = [_rss_mb(p) for p in pids]
        peak_total = max(peak_total, sum(rss))
        peak_single = max(peak_single, max(rss, default=0.0))
        peak_procs = max(peak_procs, len(pids))
        time.sleep(0.1)
    wall = time.perf_counter() - t0
    err = proc.stderr.read() if proc.stderr else ""
    if proc.returncode != 0:
        print(err, file=sys.stderr)
        return proc.returncode
    files = {p.name: p.stat().st_size for p in out.iterdir() if p.is_file()}
    res = {
        "engine": "map",
        "points": a.num * a.num,
        "workers": a.workers,
        "worker_processes": a.processes,
        "transient": a.transient,
        "periods": a.periods,
        "wall_s": wall,
        "peak_rss_tree_mb": peak_total,
        "peak_rss_single_process_mb": peak_single,
        "processes": peak_procs,
        "limit_mb": LIMIT_MB,
        "under_limit": peak_total < LIMIT_MB,
        "output_bytes": files,
        "load_average": list(os.getloadavg()),
    }
    print(
        f"{a.num}x{a.num} = {a.num * a.num:,} points, {a.workers} workers: {wall:.0f} s, peak RSS of the process "
        f"tree {peak_total:.0f} MB (largest process {peak_single:.0f} MB; limit {LIMIT_MB:.0f} MB); "
        f"map.nc {files.get('map.nc', 0) / 1e6:.1f} MB"
    )
    if a.json:
        a.json.write_text(json.dumps(res, indent=2) + "\n")
    if a.out is None:
        shutil.rmtree(out, ignore_errors=True)
    return 0 if res["under_limit"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
