"""geardyn's kernel side by side with the C reference and the Python peers, in one run.

Usage (from the project root)::

    python benchmarks/compare.py                 # everything: C reference, geardyn 1 and 2 threads, peers
    python benchmarks/compare.py --no-peers      # C reference and geardyn only
    python benchmarks/compare.py --json benchmarks/results.json --wait-idle 600
    python benchmarks/compare.py --no-peers --widths 256,0 --before OLD/src
        # also the forced 256-bit lanes, the compiler-vectorised ones (width 0) and an earlier
        # checkout (``git archive COMMIT src | tar -x -C OLD``), in the same rounds

What it does, in this order, in one process:

1. builds the C reference with ``bash ../shared/bench/run-ref.sh`` (``--ref-dir`` or
   ``GEARDYN_CREF_DIR`` name another directory; skipped without gcc) and warms geardyn up (JIT
   compilation or cache load) on every workload;
2. runs ``--rounds`` rounds; each round runs every workload once with each implementation, one
   right after the other: the C reference binary (one thread; ``batch`` for W1 and W3, ``scalar``
   for W2), geardyn on one thread, geardyn on two threads, and geardyn on one thread with the
   lanes' SIMD width forced to each of ``--widths`` (``GEARDYN_SIMD_WIDTH``; W1 and W3, the
   workloads that run the lanes) and, with ``--before``, an earlier checkout's ``geardyn bench``
   (one thread, a fresh process per run).  Interleaving run by run makes the machine's load (other
   processes, a shared host) hit every implementation alike; the load average is recorded per round;
3. reports, per workload, the minimum over the rounds of each implementation, the ratio of the
   minima and the median of the per-round ratios;
4. runs pynamicalsys (same fixed RK4 step) and SciPy ``solve_ivp`` RK45 on reduced grids and
   extrapolates them to the full workloads (see ``benchmarks/peers.py``);
5. prints a Markdown table and, with ``--json``, writes every number.

Peak RSS is the process's ``ru_maxrss`` after the geardyn timings (before the peers run).
Targets (issue 25): one thread, W1, W2 and W3 <= 1.0x the C reference (batch, scalar, batch);
two threads >= 1.9x faster than one on W1 and W3 (idle machine); the forced 256-bit lanes no slower
than the kernel before its explicit vectors (width 0).  Earlier (issue 6): >= 100x faster than
pynamicalsys on W1.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from geardyn import bench as B  # noqa: E402
from geardyn._kernel import lanes as _lanes  # noqa: E402
from geardyn.integrate import set_threads  # noqa: E402

#: The C reference variant each workload is compared with (issue 6).
C_VARIANT = {"W1": "batch", "W2": "scalar", "W3": "batch"}
TARGETS = {"W1": 1.0, "W2": 1.0, "W3": 1.0}
#: Workloads that run the lanes (W2 is one point: the scalar path), timed at the forced widths.
LANE_WORKLOADS = ("W1", "W3")


def ref_script(ref_dir: str | None = None) -> Path:
    """run-ref.sh of the C reference: ``ref_dir``, ``GEARDYN_CREF_DIR``, or ``shared/bench`` beside
    the checkout (or beside its parent directory, for a worktree one level down)."""
    if ref_dir or os.environ.get("GEARDYN_CREF_DIR"):
        return Path(ref_dir or os.environ["GEARDYN_CREF_DIR"]) / "run-ref.sh"
    for base in (ROOT.parent, ROOT.parent.parent):
        if (base / "shared" / "bench" / "run-ref.sh").exists():
            return base / "shared" / "bench" / "run-ref.sh"
    return ROOT.parent / "shared" / "bench" / "run-ref.sh"


def cpu_busy_fraction(interval: float = 1.0) -> float:
    """Fraction of all CPUs busy over ``interval`` seconds (from /proc/stat); NaN if unavailable."""

    def snap():
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        idle = v[3] + (v[4] if len(v) > 4 else 0)
        return sum(v), idle

    try:
        t0, i0 = snap()
        time.sleep(interval)
        t1, i1 = snap()
    except OSError:
        return float("nan")
    return 1.0 - (i1 - i0) / max(t1 - t0, 1)


def wait_idle(timeout: float, threshold: float = 0.1) -> float:
    """Wait (at most ``timeout`` s) until other processes use less than ``threshold`` of the CPUs."""
    t_end = time.time() + timeout
    busy = cpu_busy_fraction()
    while busy > threshold and time.time() < t_end:
        busy = cpu_busy_fraction(2.0)
    return busy


def build_c_reference(script: Path) -> Path | None:
    """Build (if needed) and run the C reference once with run-ref.sh; returns its binary's path."""
    if shutil.which("gcc") is None or not script.exists():
        return None
    subprocess.run(["bash", str(script), "1"], capture_output=True, text=True, check=True)
    binary = Path(os.environ.get("TMPDIR", "/tmp")) / "geardyn-cref" / "ref"
    return binary if binary.exists() else None


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_c(binary: Path, name: str) -> dict[str, float]:
    """One run of the C reference on one workload: {variant, steps, wall_s, cpu_s, ns_per_step}
    (``cpu_s``: the CPU time of the whole process, its few milliseconds of set-up included)."""
    c0 = _children_cpu()
    out = subprocess.run(
        [str(binary), name.lower(), C_VARIANT[name], "1", "1"], capture_output=True, text=True, check=True
    ).stdout
    cpu = _children_cpu() - c0
    m = re.search(r"RESULT (\w+) (\w+) (\d+) (\d+) ([\d.]+) ([\d.]+) ([\d.]+)", out)
    return {
        "variant": m.group(2),
        "steps": int(m.group(4)),
        "wall_s": float(m.group(5)),
        "cpu_s": cpu,
        "ns_per_step": float(m.group(7)),
    }


def run_geardyn(name: str, threads: int, width: int | None = None) -> dict[str, float]:
    """One timed run of a workload; ``width``: the lanes' SIMD width for this run (None: native)."""
    set_threads(threads)
    old = _lanes._set_simd_width(_lanes.native_simd_width() if width is None else width)
    try:
        w = B.workload(name)
        models = w.models()
        t0, c0 = time.perf_counter(), time.process_time()
        w.run(models)
        return {"wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0}
    finally:
        _lanes._set_simd_width(old)


_BEFORE = """
import json, sys, time
from geardyn import bench as B
from geardyn.integrate import set_threads
set_threads(1)
w = B.workload(sys.argv[1])
models = w.models()
w.run(models)
t0, c0 = time.perf_counter(), time.process_time()
w.run(models)
print(json.dumps({"wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0}))
"""


def run_before(src: Path, name: str) -> dict[str, float]:
    """One run of a workload on one thread in another checkout (``src``: its ``src`` directory), in a
    fresh process after an untimed warm-up run: {wall_s, cpu_s}."""
    env = {k: v for k, v in os.environ.items() if k != _lanes.SIMD_ENV}
    env["PYTHONPATH"] = str(src)
    out = subprocess.run(
        [sys.executable, "-c", _BEFORE, name], capture_output=True, text=True, check=True, env=env
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


def peers(verbose: bool = True) -> dict[str, dict]:
    """pynamicalsys and SciPy on reduced grids, extrapolated to the full workloads."""
    import peers as P

    w1, w3 = B.workload("W1"), B.workload("W3")
    full_w1_steps, full_w3_steps, full_w2_steps = w1.steps, w3.steps, B.workload("W2").steps
    tau = lambda ws, n: float(np.sum(2 * np.pi / np.asarray(ws))) * n  # noqa: E731
    out: dict[str, dict] = {}

    def note(msg):
        if verbose:
            print(msg, file=sys.stderr, flush=True)

    # pynamicalsys
    try:
        import pynamicalsys  # noqa: F401

        ws = np.asarray(w1.omegas)[::10]
        s, n, pts = P.pynamicalsys_poincare(ws, 300, 200)
        note(f"pynamicalsys W1: {len(ws)} of 200 ω, {s:.2f} s")
        out.setdefault("pynamicalsys", {})["W1"] = {
            "measured_s": s,
            "measured_steps": n,
            "wall_s": P.extrapolate(s, n, full_w1_steps),
            "grid": f"every 10th ω of W1 ({len(ws)} ω), full 300 + 200 periods; extrapolated by RK4 steps",
            "max_poincare_diff_vs_geardyn_periodic": _poincare_check(ws, pts, 300, 200),
        }
        s, n, _ = P.pynamicalsys_poincare([1.2], 0, 10_000)
        note(f"pynamicalsys W2: {s:.2f} s")
        out["pynamicalsys"]["W2"] = {"measured_s": s, "measured_steps": n, "wall_s": s, "grid": "full workload"}
        ws = np.asarray(w3.omegas)[::10]
        s, n, lam = P.pynamicalsys_lyapunov(ws, 300, 400)
        note(f"pynamicalsys W3: {len(ws)} of 50 ω, {s:.2f} s")
        out["pynamicalsys"]["W3"] = {
            "measured_s": s,
            "measured_steps": n,
            "wall_s": P.extrapolate(s, n, full_w3_steps),
            "grid": f"every 10th ω of W3 ({len(ws)} ω), 300 + 400 periods; extrapolated by RK4 steps",
            "max_abs_l1_plus_l2_plus_2xi0": float(np.max(np.abs(lam.sum(axis=1) + 2 * P.XI0))),
        }
    except ImportError:
        note("pynamicalsys not installed: skipped")

    # SciPy RK45
    ws = np.asarray(w1.omegas)[::40]
    s, t, pts = P.scipy_poincare(ws, 30, 20)
    note(f"scipy W1: {len(ws)} ω, {s:.2f} s")
    out.setdefault("scipy_rk45", {})["W1"] = {
        "measured_s": s,
        "measured_tau": t,
        "wall_s": P.extrapolate(s, t, tau(w1.omegas, 500)),
        "grid": f"every 40th ω of W1 ({len(ws)} ω), 30 + 20 periods; extrapolated by integrated time τ",
        "tolerances": [P.SCIPY_RTOL, P.SCIPY_ATOL],
    }
    s, t, _ = P.scipy_poincare([1.2], 0, 200)
    note(f"scipy W2: {s:.2f} s")
    out["scipy_rk45"]["W2"] = {
        "measured_s": s,
        "measured_tau": t,
        "wall_s": P.extrapolate(s, t, tau([1.2], 10_000)),
        "grid": "200 of 10,000 periods; extrapolated by τ",
    }
    ws = np.asarray(w3.omegas)[::25]
    s, t, lam = P.scipy_lyapunov(ws, 10, 20)
    note(f"scipy W3: {len(ws)} ω, {s:.2f} s")
    out["scipy_rk45"]["W3"] = {
        "measured_s": s,
        "measured_tau": t,
        "wall_s": P.extrapolate(s, t, tau(w3.omegas, 2300)),
        "grid": f"every 25th ω of W3 ({len(ws)} ω), 10 + 20 periods; extrapolated by τ",
    }
    for impl in out.values():
        for name, r in impl.items():
            r["ns_per_step"] = 1e9 * r["wall_s"] / {"W1": full_w1_steps, "W2": full_w2_steps, "W3": full_w3_steps}[name]
    return out


def _poincare_check(ws, pts, transient, periods) -> float:
    """Largest difference of a peer's Poincaré points from geardyn's, over the periodic ω of the subset."""
    from geardyn.integrate import integrate_batch
    from geardyn.model import GearModel, IntegrationOptions

    res = integrate_batch(
        [GearModel(omega=float(w)) for w in ws], options=IntegrationOptions(transient=transient, periods=periods)
    )
    diffs = []
    for i, p in enumerate(pts):
        q = res.poincare[i]
        if np.max(np.abs(q[-1] - q[-3])) < 1e-9 or np.max(np.abs(q[-1] - q[-2])) < 1e-9:  # period 1 or 2
            diffs.append(float(np.max(np.abs(p[-20:] - q[-20:]))))
    return max(diffs) if diffs else float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--rounds",
        type=int,
        default=15,
        help="rounds; each runs every workload once with every implementation (default 15)",
    )
    ap.add_argument("--no-peers", action="store_true", help="skip pynamicalsys and SciPy")
    ap.add_argument(
        "--wait-idle",
        type=float,
        default=0.0,
        metavar="SECONDS",
        help="before each round, wait up to this long for the CPUs to be idle",
    )
    ap.add_argument("--json", type=Path, help="write all numbers to this file")
    ap.add_argument(
        "--widths",
        default="",
        help="comma-separated SIMD widths (256, 0) also timed on one thread on W1 and W3 "
        "(default: none; 0 = the compiler-vectorised lanes)",
    )
    ap.add_argument(
        "--ref-dir",
        help="directory of the C reference's run-ref.sh (default: shared/bench "
        "beside the checkout, or GEARDYN_CREF_DIR)",
    )
    ap.add_argument(
        "--before",
        type=Path,
        metavar="SRC",
        help="the src directory of an earlier checkout: its W1 and W3 on one thread are timed in the "
        "same rounds (geardyn bench in a fresh process)",
    )
    ap.add_argument(
        "--cpu-time",
        action="store_true",
        help="compare the one-thread runs by CPU time (geardyn: the process's; C: the child "
        "process's) instead of wall time, for a loaded machine; two threads stay wall time",
    )
    a = ap.parse_args(argv)
    one = "cpu_s" if a.cpu_time else "wall_s"
    widths = [int(w) for w in a.widths.split(",") if w.strip()]

    info = B.machine_info()
    info["simd_width_native"] = _lanes.native_simd_width()
    print(
        f"machine: {info['cpu']}, {info['cores']} cores, LLVM target {info['llvm_cpu']}; "
        f"python {info['python']}, numpy {info['numpy']}, numba {info['numba']}; "
        f"lanes: {info['simd_width_native']}-bit SIMD",
        file=sys.stderr,
    )
    t0 = time.perf_counter()
    binary = build_c_reference(ref_script(a.ref_dir))
    if binary is None:
        print("no gcc or no C reference: C columns skipped", file=sys.stderr)
    set_threads(1)
    for n in ("W1", "W2", "W3"):
        B.workload(n).run()  # JIT warm-up (or cache load)
    for w in widths:
        for n in LANE_WORKLOADS:
            run_geardyn(n, 1, w)  # compile (or load) the lanes at this width
    set_threads(2)
    B.workload("W1").run()
    print(f"build and warm-up {time.perf_counter() - t0:.1f} s", file=sys.stderr)

    if a.before:
        for n in LANE_WORKLOADS:
            run_before(a.before, n)  # compile or load the earlier checkout's kernel
    impls = (
        (["c"] if binary else [])
        + ["geardyn_1", "geardyn_2"]
        + [f"geardyn_1_w{w}" for w in widths]
        + (["before_1"] if a.before else [])
    )
    runs: dict[str, dict[str, list[float]]] = {k: {n: [] for n in ("W1", "W2", "W3")} for k in impls}
    busy = []
    loads = []
    wall_1: dict[str, list[float]] = {n: [] for n in ("W1", "W2", "W3")}  # one thread, wall time (speed-up)
    for r in range(a.rounds):
        busy.append(wait_idle(a.wait_idle) if a.wait_idle > 0 else cpu_busy_fraction(0.2))
        loads.append(os.getloadavg()[0])
        for n in ("W1", "W2", "W3"):
            if binary:
                runs["c"][n].append(run_c(binary, n)[one])
            r1 = run_geardyn(n, 1)
            runs["geardyn_1"][n].append(r1[one])
            wall_1[n].append(r1["wall_s"])
            if n != "W2":
                runs["geardyn_2"][n].append(run_geardyn(n, 2)["wall_s"])
            if n in LANE_WORKLOADS:
                for w in widths:
                    runs[f"geardyn_1_w{w}"][n].append(run_geardyn(n, 1, w)[one])
                if a.before:
                    runs["before_1"][n].append(run_before(a.before, n)[one])
        print(
            f"round {r + 1}/{a.rounds} (busy {busy[-1]:.0%}, load {loads[-1]:.2f}): "
            + " ".join(
                f"{k} {n} {1e9 * runs[k][n][-1] / B.workload(n).steps:.2f}"
                for k in impls
                for n in ("W1", "W2", "W3")
                if runs[k][n]
            )
            + " ns/step",
            file=sys.stderr,
            flush=True,
        )
    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    best = {k: {n: min(v) for n, v in runs[k].items() if v} for k in impls}
    have_c = binary is not None
    steps = {n: B.workload(n).steps for n in ("W1", "W2", "W3")}
    peer = {} if a.no_peers else peers()
    set_threads(None)

    # ---------------------------------------------------------------- report
    if a.cpu_time:
        print("one-thread columns and ratios: CPU time; two threads and the speed-up: wall time")
    lines = [
        "| workload | C reference (1 thread) | geardyn 1 thread | ratio to C (target) | geardyn 2 threads | "
        "2-thread speed-up | pynamicalsys | SciPy RK45 |",
        "|---|---|---|---|---|---|---|---|",
    ]
    summary = {
        "machine": info,
        "runs_wall_s": runs,
        "geardyn_1_wall_s": wall_1,
        "cpu_busy_before_round": busy,
        "load_average_1min": loads,
        "simd_widths_forced": widths,
        "one_thread_time": one,
        "best_wall_s": best,
        "steps": steps,
        "peak_rss_mb": rss_mb,
        "peers": peer,
        "ratios": {},
        "rounds": a.rounds,
        "load_average_end": list(os.getloadavg()),
    }
    for n in ("W1", "W2", "W3"):
        g1 = best["geardyn_1"][n]
        g2 = best["geardyn_2"].get(n)
        ns = lambda s: 1e9 * s / steps[n]  # noqa: E731
        c = best["c"][n] if have_c else None
        ratio = g1 / c if c else None
        sp = min(wall_1[n]) / g2 if g2 else None
        pn = peer.get("pynamicalsys", {}).get(n)
        sc = peer.get("scipy_rk45", {}).get(n)
        med = float(np.median(np.array(runs["geardyn_1"][n]) / np.array(runs["c"][n]))) if c else None
        med_sp = float(np.median(np.array(wall_1[n]) / np.array(runs["geardyn_2"][n]))) if g2 else None
        summary["ratios"][n] = {
            "geardyn_over_c": ratio,
            "median_round_ratio": med,
            "c_variant": C_VARIANT[n],
            "speedup_2_threads": sp,
            "median_round_speedup": med_sp,
            "pynamicalsys_over_geardyn": pn["wall_s"] / g1 if pn else None,
            "scipy_over_geardyn": sc["wall_s"] / g1 if sc else None,
        }
        cell = lambda t: f"{t:.3f} s ({ns(t):.2f} ns/step)"  # noqa: E731
        lines.append(
            " | ".join(
                [
                    f"| {n}",
                    f"{cell(c)} {C_VARIANT[n]}" if c else "n/a (no gcc)",
                    cell(g1),
                    f"{ratio:.2f}x, median {med:.2f}x (<= {TARGETS[n]}x)" if ratio else "n/a",
                    cell(g2) if g2 else "(one point)",
                    f"{sp:.2f}x, median {med_sp:.2f}x" if sp else "-",
                    f"{pn['wall_s']:.1f} s = {pn['wall_s'] / g1:.0f}x slower" if pn else "-",
                    f"{sc['wall_s']:.0f} s = {sc['wall_s'] / g1:.0f}x slower" if sc else "-",
                ]
            )
            + " |"
        )
    others = [f"geardyn_1_w{w}" for w in widths] + (["before_1"] if a.before else [])
    if others:
        heads = [f"width {w} (ratio to native; to C)" for w in widths] + (
            ["earlier checkout (ratio to native; to C)"] if a.before else []
        )
        lines += [
            "",
            "| workload | geardyn 1 thread, native width | " + " | ".join(heads) + " |",
            "|---|---|" + "---|" * len(heads),
        ]
        for n in LANE_WORKLOADS:
            g1 = best["geardyn_1"][n]
            c = best["c"][n] if have_c else None
            cells = []
            for k in others:
                key = k.replace("geardyn_1_", "")
                t = best[k][n]
                med = float(np.median(np.array(runs[k][n]) / np.array(runs["geardyn_1"][n])))
                summary["ratios"][n][f"{key}_over_native"] = t / g1
                summary["ratios"][n][f"{key}_over_native_median"] = med
                if c:
                    summary["ratios"][n][f"{key}_over_c"] = t / c
                cells.append(f"{t:.3f} s ({t / g1:.2f}x, median {med:.2f}x" + (f"; {t / c:.2f}x C)" if c else ")"))
            lines.append(f"| {n} | {g1:.3f} s | " + " | ".join(cells) + " |")
    print("\n".join(lines))
    print(f"\nload average (1 min) before the rounds: {min(loads):.2f}-{max(loads):.2f}")
    print(f"\npeak RSS of the benchmark process after the geardyn runs: {rss_mb:.0f} MB")
    for impl, d in peer.items():
        for n, r in d.items():
            print(f"{impl} {n}: measured {r['measured_s']:.2f} s on {r['grid']}")
    if a.json:
        a.json.write_text(json.dumps(summary, indent=2, default=float) + "\n")
        print(f"wrote {a.json}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
