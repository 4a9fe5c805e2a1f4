"""The commands themselves timed side by side with the kernel, in one run (issue 15).

Usage (from the project root)::

    python benchmarks/commands.py map --num 1000        # geardyn map on 10^6 points vs the lean kernel path
    python benchmarks/commands.py steps --num 500       # 250 000-point map per RK4 step vs geardyn bench W1
    python benchmarks/commands.py steps --before ../old/src   # ... and an earlier checkout's map beside it
    python benchmarks/commands.py adaptive              # bifurcation --adaptive vs the fixed transient (W1 grid)
    python benchmarks/commands.py all --rounds 2 --json benchmarks/results/commands.json

Every measurement runs a fresh process (the command as a user runs it, or the lean path of
``memory_map.py --engine lean``) and samples the resident memory of its whole process tree every
0.1 s.  A and B alternate round by round; the load average is recorded next to each number,
since the machine may be shared.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from memory_map import _rss_mb, _tree  # noqa: E402

GEARDYN = [sys.executable, "-m", "geardyn.cli"]


def run_tree(cmd: list[str], env: dict | None = None) -> dict:
    """Run ``cmd``; wall time, peak RSS of its process tree, load average before and after."""
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    peak = 0.0
    while proc.poll() is None:
        peak = max(peak, sum(_rss_mb(p) for p in _tree(proc.pid)))
        time.sleep(0.1)
    wall = time.perf_counter() - t0
    out, err = proc.communicate()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {err.strip()[-400:]}")
    return {
        "wall_s": wall,
        "peak_rss_tree_mb": peak,
        "load_before": load0,
        "load_after": os.getloadavg()[0],
        "stdout": out,
    }


def map_cmd(
    num: int, workers: int, out: Path, transient: int = 20, periods: int = 10, processes: bool = False
) -> list[str]:
    return (
        GEARDYN
        + [
            "map",
            "--x",
            "omega",
            "--x-start",
            "0.5",
            "--x-stop",
            "0.75",
            "--x-num",
            str(num),
            "--y",
            "xi0",
            "--y-start",
            "0.05",
            "--y-stop",
            "0.3",
            "--y-num",
            str(num),
            "--settle",
            "0",
            "--transient",
            str(transient),
            "--periods",
            str(periods),
            "--workers",
            str(workers),
            "--out",
            str(out),
        ]
        + (["--processes"] if processes else [])
    )


def lean_cmd(num: int, out: Path) -> list[str]:
    return [sys.executable, str(HERE / "memory_map.py"), "--engine", "lean", "--num", str(num), "--out", str(out)]


def map_steps(num: int, transient: int = 20, periods: int = 10) -> int:
    import numpy as np

    from geardyn.pairpack import steps_per_period

    return int(steps_per_period(np.linspace(0.5, 0.75, num), 0.01).sum()) * num * (transient + periods)


def bench_map(a) -> dict:
    """geardyn map (A) vs the lean chunked kernel path (B), alternated."""
    rows = []
    for r in range(a.rounds):
        for which in ("map", "lean"):
            with tempfile.TemporaryDirectory(prefix="geardyn-cmd-") as d:
                cmd = (
                    map_cmd(a.num, a.workers, Path(d), processes=a.processes)
                    if which == "map"
                    else lean_cmd(a.num, Path(d))
                )
                m = run_tree(cmd)
            m.pop("stdout")
            rows.append({"round": r, "run": which, **m})
            print(
                f"[map {a.num}^2] {which}: {m['wall_s']:.1f} s, {m['peak_rss_tree_mb']:.0f} MB "
                f"(load {m['load_before']:.1f})",
                file=sys.stderr,
            )
    best = {w: min(x["wall_s"] for x in rows if x["run"] == w) for w in ("map", "lean")}
    return {
        "points": a.num**2,
        "workers": a.workers,
        "processes": a.processes,
        "rows": rows,
        "wall_ratio": best["map"] / best["lean"],
        "peak_rss_map_mb": max(x["peak_rss_tree_mb"] for x in rows if x["run"] == "map"),
    }


def bench_steps(a) -> dict:
    """ns per RK4 step of a num² map (in process, the kernel threads) vs geardyn bench W1, same threads.

    With ``a.before`` (the ``src`` directory of another checkout), that checkout's map runs too,
    alternating with this one's in every round, against the same W1 runs.
    """
    rows = []
    steps = map_steps(a.num)
    trees = [("map", None)] + ([("before", str(Path(a.before).resolve()))] if a.before else [])
    for r in range(a.rounds):
        for which, src in trees:
            env = None if src is None else {**os.environ, "PYTHONPATH": src}
            with tempfile.TemporaryDirectory(prefix="geardyn-cmd-") as d:
                m = run_tree(map_cmd(a.num, 1, Path(d)), env)
            b = run_tree(GEARDYN + ["bench", "--workload", "W1", "--threads", str(a.threads), "--json"])
            w1 = json.loads(b.pop("stdout"))
            w1_ns = _w1_ns_per_step(w1)
            m.pop("stdout")
            rows.append(
                {
                    "round": r,
                    "run": which,
                    "map_ns_per_step": m["wall_s"] / steps * 1e9,
                    "map": m,
                    "w1_ns_per_step": w1_ns,
                    "w1_load": b["load_before"],
                }
            )
            print(
                f"[steps {a.num}^2] {which}: map {rows[-1]['map_ns_per_step']:.2f} ns/step ({m['wall_s']:.1f} s), "
                f"W1 {w1_ns:.2f} ns/step (load {m['load_before']:.1f})",
                file=sys.stderr,
            )
    best_w1 = min(x["w1_ns_per_step"] for x in rows)
    out = {
        "points": a.num**2,
        "threads": a.threads,
        "rk4_steps": steps,
        "rows": rows,
        "ratio": min(x["map_ns_per_step"] for x in rows if x["run"] == "map") / best_w1,
    }
    if a.before:
        out["ratio_before"] = min(x["map_ns_per_step"] for x in rows if x["run"] == "before") / best_w1
    return out


def _w1_ns_per_step(js) -> float:
    w = js["workloads"]["W1"]
    return float(w["ns_per_step"]) if "ns_per_step" in w else float(w["wall_s"]) / float(w["steps"]) * 1e9


W1_BIF = [
    "bifurcation",
    "--param",
    "omega",
    "--start",
    "0.5",
    "--stop",
    "1.5",
    "--num",
    "200",
    "--transient",
    "300",
    "--periods",
    "200",
    "--settle",
    "0",
    "--json",
]


def bench_adaptive(a) -> dict:
    """bifurcation on the W1 grid: --adaptive (A) vs the fixed transient (B), alternated; labels and points."""
    import numpy as np

    from geardyn.io import read_netcdf

    rows, data = [], {}
    for r in range(a.rounds):  # timed: the command with --json, no --out (no figures, no checkpoint)
        for which in ("fixed", "adaptive"):
            extra = ["--adaptive"] if which == "adaptive" else []
            m = run_tree(GEARDYN + W1_BIF + extra)
            m.pop("stdout")
            rows.append({"round": r, "run": which, **m})
            print(f"[adaptive] {which}: {m['wall_s']:.2f} s (load {m['load_before']:.1f})", file=sys.stderr)
    for which in ("fixed", "adaptive"):  # not timed: the Poincaré points, from the NetCDF file
        with tempfile.TemporaryDirectory(prefix="geardyn-cmd-") as d:
            extra = ["--adaptive"] if which == "adaptive" else []
            run_tree(GEARDYN + W1_BIF + extra + ["--out", str(Path(d) / "bif.nc")])
            ds = read_netcdf(Path(d) / "bif.nc")
            data[which] = (
                ds["period"].values[0].copy(),
                ds["poincare_u"].values[0].copy(),
                ds["poincare_v"].values[0].copy(),
            )
    pf, uf, vf = data["fixed"]
    pa, ua, va = data["adaptive"]
    both = (pf > 0) & (pa > 0)
    diff = float(max(np.max(np.abs(uf[both] - ua[both])), np.max(np.abs(vf[both] - va[both])))) if both.any() else 0.0
    best = {w: min(x["wall_s"] for x in rows if x["run"] == w) for w in ("fixed", "adaptive")}
    return {
        "rows": rows,
        "speedup": best["fixed"] / best["adaptive"],
        "same_label": float(np.mean(pf == pa)),
        "periodic_both": int(both.sum()),
        "max_poincare_diff": diff,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=("map", "steps", "adaptive", "all"))
    ap.add_argument("--num", type=int, help="grid values per axis (map: 1000, steps: 500)")
    ap.add_argument("--workers", type=int, default=2, help="map: --workers of the command (threads; default 2)")
    ap.add_argument(
        "--processes",
        action="store_true",
        help="map: run the command's workers as local worker processes (--processes)",
    )
    ap.add_argument("--threads", type=int, default=2, help="kernel threads of the steps comparison")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument(
        "--before",
        type=Path,
        help="steps: the src directory of another checkout, whose map runs "
        "alternating with this one's (e.g. a git worktree of an earlier commit)",
    )
    ap.add_argument("--json", type=Path)
    a = ap.parse_args(argv)
    res: dict = {"machine_load_start": list(os.getloadavg())}
    if a.what in ("map", "all"):
        res["map"] = bench_map(argparse.Namespace(**{**vars(a), "num": a.num or 1000}))
    if a.what in ("steps", "all"):
        res["steps"] = bench_steps(argparse.Namespace(**{**vars(a), "num": a.num or 500}))
    if a.what in ("adaptive", "all"):
        res["adaptive"] = bench_adaptive(a)
    summary = {k: {kk: vv for kk, vv in v.items() if kk != "rows"} for k, v in res.items() if isinstance(v, dict)}
    print(json.dumps(summary, indent=2))
    if a.json:
        a.json.write_text(json.dumps(res, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
