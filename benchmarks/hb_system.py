"""Harmonic balance against shooting on a multi-DOF system: the 8-DOF bevel pair's frequency response.

Case: ``examples/systems/paper_bevel_8dof.toml`` (the paper's Table 1 pair with three translations per gear
on bearings; one rigid-body mode, the rotation of the pair), period-1 branch continued in ω from 0.6 to
1.2 through its folds (pseudo-arclength both ways, so one run gives the up and the down response):

* HB: :func:`geardyn.analysis.hb.continuation.hb_continuation` at ``--harmonics`` (each DOF),
  with the systems' default largest step ds_max = SYSTEM_DS_MAX (0.2) and with the 1-DOF default DS_MAX (0.02);
* shooting: :func:`geardyn.analysis.periodic.continuation` at its defaults (accurate mode,
  Δτ = 0.01, ds_max = 0.02; events bracketed to one step, not located);

both in this process, one after the other, with the wall time of each, the load average before and after,
and each method's events (type, ω).  The events are matched by type and order; their difference is what
the two methods disagree by (shooting's events are linear interpolations inside one step).

HB runs with the Floquet multipliers from the monodromy matrix (the default) and from Hill's method.
Run: ``python benchmarks/hb_system.py [--harmonics 12] [--small-step]`` (about a minute on a loaded 2-core
machine).  Writes ``benchmarks/results/hb_system.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from geardyn.analysis.hb.continuation import DS_MAX, SYSTEM_DS_MAX, hb_continuation  # noqa: E402
from geardyn.analysis.periodic import continuation as system_continuation  # noqa: E402
from geardyn.systems import load_system  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SYSTEM = ROOT / "examples" / "systems" / "paper_bevel_8dof.toml"
LO, HI = 0.6, 1.2


def _hb(model, H: int, ds_max: float, floquet: str) -> dict:
    t, c = time.perf_counter(), time.process_time()
    r = hb_continuation(model, "omega", LO, HI, harmonics=H, ds_max=ds_max, floquet=floquet)
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    return {
        "method": "hb",
        "floquet": floquet,
        "harmonics": H,
        "ds_max": ds_max,
        "wall_s": wall,
        "cpu_s": cpu,
        "points": int(r.values.size),
        "end": r.end,
        "unresolved_points": int((r.status != 0).sum()),
        "events": [
            {"type": b.type, "omega": b.value, "located": b.located, "detail": b.detail} for b in r.bifurcations
        ],
    }


def _shooting(model) -> dict:
    t, c = time.perf_counter(), time.process_time()
    r = system_continuation(model, "omega", LO, HI, 1)
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    primary = r.branches[0]  # one continuation for every System: its branches and their located events
    return {
        "method": "shooting",
        "accurate": True,
        "wall_s": wall,
        "cpu_s": cpu,
        "points": int(primary.values.size),
        "end": primary.end,
        "events": [
            {"type": b.type, "omega": b.value, "located": b.located, "detail": b.detail}
            for b in r.bifurcations
            if b.branch == 0
        ],
    }


def _match(a: list[dict], b: list[dict]) -> list[dict]:
    """Events of a and b of the same type paired in ω order, with their difference."""
    out = []
    for typ in sorted({e["type"] for e in a} | {e["type"] for e in b}):
        xa = sorted(e["omega"] for e in a if e["type"] == typ)
        xb = sorted(e["omega"] for e in b if e["type"] == typ)
        for i in range(max(len(xa), len(xb))):
            va = xa[i] if i < len(xa) else None
            vb = xb[i] if i < len(xb) else None
            out.append(
                {
                    "type": typ,
                    "hb": va,
                    "shooting": vb,
                    "difference": abs(va - vb) if va is not None and vb is not None else None,
                }
            )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--harmonics", type=int, default=12)
    ap.add_argument(
        "--small-step",
        action="store_true",
        help="also run HB (monodromy) at the 1-DOF default step DS_MAX (several times longer)",
    )
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "hb_system.json")
    args = ap.parse_args()
    model = load_system(SYSTEM)
    for floquet in ("monodromy", "hill"):  # compile the kernels outside the timing
        hb_continuation(model, "omega", LO, LO + 0.01, harmonics=4, floquet=floquet)
    runs = [("monodromy", SYSTEM_DS_MAX), ("hill", SYSTEM_DS_MAX)] + (
        [("monodromy", DS_MAX)] if args.small_step else []
    )
    load0 = os.getloadavg()
    hbs = [_hb(model, args.harmonics, d, f) for f, d in runs]
    sh = _shooting(model)
    load1 = os.getloadavg()
    res = {
        "case": str(SYSTEM.relative_to(ROOT)),
        "param": "omega",
        "interval": [LO, HI],
        "load_average_before": load0,
        "load_average_after": load1,
        "cpus": os.cpu_count(),
        "platform": platform.platform(),
        "hb": hbs,
        "shooting": sh,
        "hb_over_shooting_time": [h["wall_s"] / sh["wall_s"] for h in hbs],
        "hb_over_shooting_cpu": [h["cpu_s"] / sh["cpu_s"] for h in hbs],
        "events": [_match(h["events"], sh["events"]) for h in hbs],
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(res, indent=2) + "\n")
    print("| method | points | wall (s) | CPU (s) | time / shooting (wall, CPU) |\n|---|---|---|---|---|")
    for h, ratio, rc in zip(hbs, res["hb_over_shooting_time"], res["hb_over_shooting_cpu"]):
        print(
            f"| HB, {h['floquet']} (H = {h['harmonics']}, ds_max = {h['ds_max']}) | {h['points']} | {h['wall_s']:.1f} "
            f"| {h['cpu_s']:.1f} | {ratio:.2f}, {rc:.2f} |"
        )
    print(f"| shooting (accurate, Δτ = 0.01) | {sh['points']} | {sh['wall_s']:.1f} | {sh['cpu_s']:.1f} | 1 |")
    print(f"load average {load0[0]:.2f} before, {load1[0]:.2f} after")
    for h, evs in zip(hbs, res["events"]):
        print(f"events, HB with {h['floquet']} (ds_max = {h['ds_max']}):")
        for e in evs:
            print(f"  {e['type']:16s} hb {e['hb']}  shooting {e['shooting']}  difference {e['difference']}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
