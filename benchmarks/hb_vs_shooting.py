"""Speed of harmonic balance against shooting for the full up/down frequency response with its folds.

Case: the paper's defaults with ξ0 = 0.08, ω from 0.3 to 1.0 (period-1 branch: grazing, two folds — the
jumps of the up and down sweeps and the ends of the hysteresis loop — and a period doubling).  Both
methods continue the period-1 branch through the folds (pseudo-arclength; shooting without branch
switching), so one run gives the up and the down response.

* reference events: shooting continuation in the accurate mode at Δτ = 0.001 (its events agree with
  Δτ = 0.0005 to about 1e-14, see ``hb_convergence.py``);
* timed settings (each run in this process, the two methods alternated, ``--repeats`` rounds, the
  minimum wall time of each kept, and the minimum CPU time of the process, less disturbed by other
  load on the machine): HB at its defaults (H = 16, ds_max = 0.02) and at fewer harmonics
  with larger steps; shooting at its defaults (default mode, Δτ = 0.01, ds_max = 0.01) and cheaper ones
  (larger Δτ, larger steps: the same ds_max = 0.05 and 0.1 as HB);
* HB's multipliers from the monodromy matrix of one period started on the solution (the default) and, for
  comparison, from Hill's method (``floquet = hill``);
* for each method the fastest setting that finds every reference event (both folds, the grazing and the
  period doublings) within 1e-3 of the reference is compared.

Run: ``python benchmarks/hb_vs_shooting.py [--repeats 2]``.  Prints a Markdown table, the load
average before and after, and writes ``benchmarks/results/hb_vs_shooting.json``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from geardyn.analysis.hb import hb_continuation  # noqa: E402
from geardyn.analysis.periodic import continuation  # noqa: E402
from geardyn.model import GearModel  # noqa: E402

MODEL = GearModel(xi0=0.08)
LO, HI = 0.3, 1.0
FOLD_ACCURACY = 1e-3
HB_SETTINGS = [
    dict(harmonics=16, ds_max=0.02),
    dict(harmonics=16, ds_max=0.05),
    dict(harmonics=12, ds_max=0.05),
    dict(harmonics=10, ds_max=0.05),
    dict(harmonics=8, ds_max=0.05),
    dict(harmonics=8, ds_max=0.1),
    dict(harmonics=6, ds_max=0.1),
    dict(harmonics=8, ds_max=0.1, floquet="hill"),
    dict(harmonics=16, ds_max=0.02, floquet="hill"),
]
SHOOTING_SETTINGS = [
    dict(accurate=False, dtau=0.01),
    dict(accurate=False, dtau=0.02, ds_max=0.05),
    dict(accurate=False, dtau=0.02, ds_max=0.1),
    dict(accurate=False, dtau=0.05, ds_max=0.05),
    dict(accurate=True, dtau=0.02, ds_max=0.05),
]


def _hb(kw):
    r = hb_continuation(MODEL, "omega", LO, HI, **kw)
    return [(b.type, b.value) for b in r.bifurcations], int(r.values.size)


def _shooting(kw):
    r = continuation(MODEL, "omega", LO, HI, 1, switch=False, **kw)
    return [(b.type, b.value) for b in r.bifurcations], sum(len(b) for b in r.branches)


def _errors(events, ref):
    out = {}
    for typ in ("fold", "grazing", "period-doubling"):
        rv = sorted(v for t, v in ref if t == typ)
        ev = sorted(v for t, v in events if t == typ)
        out[typ] = max((min(abs(e - r) for e in ev) for r in rv), default=0.0) if ev else float("inf")
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    load0 = os.getloadavg()
    _hb(dict(harmonics=4, ds_max=0.2))  # warm-up: imports and numba compilation of the kernel
    _shooting(dict(accurate=False, dtau=0.05, ds_max=0.1))
    t0 = time.perf_counter()
    ref, _ = _shooting(dict(accurate=True, dtau=0.001))
    t_ref = time.perf_counter() - t0
    ref = [(t, v) for t, v in ref if t in ("fold", "grazing", "period-doubling")]
    runs = [("HB", kw, _hb) for kw in HB_SETTINGS] + [("shooting", kw, _shooting) for kw in SHOOTING_SETTINGS]
    nh = len(HB_SETTINGS)
    order = [r for pair in itertools.zip_longest(runs[:nh], runs[nh:]) for r in pair if r is not None]
    # HB, shooting, HB, shooting, ...
    best: dict[int, float] = {}
    best_cpu: dict[int, float] = {}
    found: dict[int, tuple] = {}
    for _ in range(args.repeats):
        for method, kw, fn in order:
            i = runs.index((method, kw, fn))
            t, c = time.perf_counter(), time.process_time()
            ev, pts = fn(kw)
            dt, dc = time.perf_counter() - t, time.process_time() - c
            best[i] = min(best.get(i, float("inf")), dt)
            best_cpu[i] = min(best_cpu.get(i, float("inf")), dc)
            found[i] = (ev, pts)
    load1 = os.getloadavg()
    rows = []
    for i, (method, kw, _fn) in enumerate(runs):
        ev, pts = found[i]
        err = _errors(ev, ref)
        rows.append(
            {
                "method": method,
                "settings": kw,
                "seconds": best[i],
                "cpu_seconds": best_cpu[i],
                "points": pts,
                "errors": err,
                "events": ev,
                "meets": max(err.values()) <= FOLD_ACCURACY,
            }
        )
    print(f"reference (shooting, accurate, Δτ = 0.001, {t_ref:.1f} s): " + ", ".join(f"{t} {v:.8f}" for t, v in ref))
    print(
        "\n| method | settings | points | wall (s), min of "
        f"{args.repeats} | CPU (s), min | fold error | grazing error | period-doubling error |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        s = ", ".join(f"{k} = {v}" for k, v in r["settings"].items())
        e = r["errors"]
        print(
            f"| {r['method']} | {s} | {r['points']} | {r['seconds']:.2f} | {r['cpu_seconds']:.2f} | "
            f"{e['fold']:.1e} | {e['grazing']:.1e} | {e['period-doubling']:.1e} |"
        )
    fast = {
        m: min((r for r in rows if r["method"] == m and r["meets"]), key=lambda r: r["seconds"], default=None)
        for m in ("HB", "shooting")
    }
    if fast["HB"] and fast["shooting"]:
        ratio = fast["HB"]["seconds"] / fast["shooting"]["seconds"]
        print(
            f"\nfastest with every event within {FOLD_ACCURACY:g}: HB {fast['HB']['seconds']:.2f} s "
            f"({fast['HB']['settings']}), shooting {fast['shooting']['seconds']:.2f} s "
            f"({fast['shooting']['settings']}); HB/shooting = {ratio:.2f} (goal <= 0.5); in CPU time "
            f"{fast['HB']['cpu_seconds']:.2f} s against {fast['shooting']['cpu_seconds']:.2f} s, "
            f"{fast['HB']['cpu_seconds'] / fast['shooting']['cpu_seconds']:.2f}"
        )
    print(
        f"load average before {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, after {load1[0]:.2f} {load1[1]:.2f} "
        f"{load1[2]:.2f} ({os.cpu_count()} cores, {platform.processor() or platform.machine()})"
    )
    out = Path(__file__).with_name("results") / "hb_vs_shooting.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(
        json.dumps(
            {
                "reference": ref,
                "reference_seconds": t_ref,
                "rows": rows,
                "load_before": load0,
                "load_after": load1,
                "repeats": args.repeats,
            },
            indent=1,
            default=str,
        )
    )
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
