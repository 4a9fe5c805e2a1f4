"""Speed of harmonic balance on the 1-DOF pair and the 8-DOF bevel pair (continuation in ω).

Cases (each the full period-1 branch with its events, the multipliers from the monodromy matrix, the default):

* ``pair16``: the paper's defaults with ξ0 = 0.08, ω from 0.3 to 1.0, H = 16, ds_max = 0.02 (the defaults);
* ``pair8``: the same at H = 8, ds_max = 0.1;
* ``bevel``: ``examples/systems/paper_bevel_8dof.toml``, ω from 0.6 to 1.2, H = 12 (default ds_max of a system).

Each case is run ``--repeats`` times after one warm-up run (the kernels compiled outside the timing); the
minimum wall and CPU times are kept.  With ``--general`` the pair cases are also run with the pair's specialised
(compiled scalar) residual switched off, so that the general residual of every system form does the work: the
two timings side by side show whether the specialisation earns its place.  Run against another source tree with
``PYTHONPATH=<tree>/src``; the output (JSON on stdout and ``--out``) holds the times, the point counts and the
events, so that two trees can be compared (``--compare A.json B.json`` prints the ratios B/A).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

ROOT = Path(__file__).resolve().parents[1]
SYSTEM = ROOT / "examples" / "systems" / "paper_bevel_8dof.toml"


def _cases():
    from geardyn.model import GearModel
    from geardyn.systems import load_system

    pair = GearModel(xi0=0.08)
    bevel = load_system(SYSTEM)
    return {
        "pair16": (pair, 0.3, 1.0, dict(harmonics=16, ds_max=0.02)),
        "pair8": (pair, 0.3, 1.0, dict(harmonics=8, ds_max=0.1)),
        "bevel": (bevel, 0.6, 1.2, dict(harmonics=12)),
    }


def _continuation():
    """The continuation of the tree on PYTHONPATH: one function for every system, or (a tree from before harmonic
    balance was written once) the pair's and the systems' own."""
    from geardyn.analysis import hb

    if hasattr(hb, "hb_system_continuation"):
        return lambda m, *a, **k: (hb.hb_continuation if m.state_dim == 2 else hb.hb_system_continuation)(m, *a, **k)
    return hb.hb_continuation


def _run(fn, case, repeats):
    model, lo, hi, kw = case
    fn(model, "omega", lo, hi, **kw)  # warm-up (compilation)
    walls, cpus = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        r = fn(model, "omega", lo, hi, **kw)
        walls.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
    return {
        "wall_s": min(walls),
        "cpu_s": min(cpus),
        "points": int(r.values.size),
        "events": [[b.type, float(b.value)] for b in r.bifurcations],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", nargs="*", default=["pair16", "pair8", "bevel"])
    ap.add_argument("--general", action="store_true", help="also run the pair cases on the general residual")
    ap.add_argument("--out", type=Path)
    ap.add_argument("--compare", nargs=2, type=Path, metavar=("BEFORE", "AFTER"))
    args = ap.parse_args()
    if args.compare:
        a, b = (json.loads(p.read_text()) for p in args.compare)
        print("| case | before CPU (s) | after CPU (s) | ratio CPU | ratio wall | events max diff |")
        print("|---|---|---|---|---|---|")
        for k in a["runs"]:
            if k not in b["runs"]:
                continue
            ra, rb = a["runs"][k], b["runs"][k]
            ea, eb = sorted(ra["events"]), sorted(rb["events"])
            d = max((abs(x[1] - y[1]) for x, y in zip(ea, eb)), default=0.0) if len(ea) == len(eb) else "differ"
            print(
                f"| {k} | {ra['cpu_s']:.3f} | {rb['cpu_s']:.3f} | {rb['cpu_s'] / ra['cpu_s']:.3f} | "
                f"{rb['wall_s'] / ra['wall_s']:.3f} | {d} |"
            )
        return
    fn = _continuation()
    cases = _cases()
    runs = {}
    load0 = os.getloadavg()
    for name in args.cases:
        runs[name] = _run(fn, cases[name], args.repeats)
        if args.general and name.startswith("pair"):
            from geardyn.analysis.hb import equations

            equations.SPECIALISE = False
            try:
                runs[name + "_general"] = _run(fn, cases[name], args.repeats)
            finally:
                equations.SPECIALISE = True
    out = {"load_average_before": load0, "load_average_after": os.getloadavg(), "runs": runs}
    text = json.dumps(out, indent=1)
    if args.out:
        args.out.write_text(text + "\n")
    sys.stdout.write(text + "\n")


if __name__ == "__main__":
    main()
