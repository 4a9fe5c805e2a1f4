"""Cost per forcing period of the N-DOF kernel against the system's size, before and after a change.

The systems: a generated chain of ``n`` 1:1 spur stages (:func:`chain_toml`: each gear with x, y and θ on linear
bearings, a torsional coupling between one stage's gear and the next stage's pinion; 6n DOF), and the 8-DOF bevel
pair of workload W4 (``examples/systems/paper_bevel_8dof.toml``, a batch of ω as in ``benchmarks/w4.py``).  Both
checkouts are timed the same way, side by side in one run (``--before``: the root of a checkout of the code before
the change, e.g. a ``git worktree`` of main; the code here otherwise):

- each size in a fresh subprocess per checkout, one thread, the two checkouts interleaved (``--rounds`` rounds,
  before then after, then after then before, …);
- in each subprocess: a warm-up run (the compile or cache load, first-call costs), then p periods chosen from a
  second warm-up so that a run of p periods takes about ``--target`` seconds of work (the per-call setup, packing
  the arrays, is then small beside it); then ``--repeat`` pairs of runs of p and 2p periods, each pair giving
  (CPU(2p) − CPU(p)) / p: the setup cancels; the median of the pairs;
- CPU time of the process (one thread: the work, whatever else shares the machine); the median over rounds, and
  the range, are printed and written.

    python benchmarks/ndof_scaling.py --before ../kernel-before [--stages 1 8 16 32] [--rounds 3] [--repeat 3]
                                      [--target 0.4] [--json benchmarks/results/ndof_scaling.json]

``--classify`` measures instead what classifying a point that is not periodic costs: ``geardyn simulate --system
CHAIN_96DOF.toml --omega 0.8 --json`` (16 stages, the generator's defaults: 10 N·m, 20 µm of STE, a chaotic point)
against the same command with ``--no-classify``, as whole
processes of the console script (the CPU time of the child: user + system), interleaved and repeated:

    python benchmarks/ndof_scaling.py --classify [--stages 16] [--repeat 3]
                                      [--json benchmarks/results/classify_96dof.json]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BEVEL = ROOT / "examples" / "systems" / "paper_bevel_8dof.toml"

#: One stage's numbers (a 1:1 spur pair of 32 teeth, module 3 mm, pressure angle 20°; steel disc gears).
TEETH = 32
BASE_RADIUS_MM = 3.0 * TEETH / 2 * 0.9396926207859084


def chain_toml(stages: int, path: str | Path, *, fp_torque: float = 10.0, eps_um: float = 20.0) -> Path:
    """Write a system file of ``stages`` 1:1 spur stages in a chain (6 DOF a stage) and return its path.

    Stage s has a pinion ``p{s}`` and a gear ``g{s}`` (x, y, θ each, on linear bearings to ground) in mesh
    ``m{s}``; a torsional coupling ``c{s}`` joins ``g{s}`` to ``p{s+1}``.  A torque drives ``p1`` and the same
    torque, reversed, loads the last gear (the ratio is 1: balanced).  The first mesh is the reference.
    """
    lines = [
        f'title = "Chain of {stages} 1:1 spur stages ({6 * stages} DOF), generated"',
        "",
        "[system]",
        'reference = "m1"',
        "",
        "[operating]",
        "omega = 0.8",
        "",
    ]
    for s in range(1, stages + 1):
        for g in (f"p{s}", f"g{s}"):
            lines += [
                "[[body]]",
                f'name = "{g}"',
                'dofs = ["x", "y", "theta"]',
                'mass = "1.6 kg"',
                'inertia = "1.9e-3 kg*m^2"',
                "",
                "[[connection]]",
                f'name = "{g}_bearing"',
                f'body = "{g}"',
                'kx = "2e8 N/m"',
                'ky = "2e8 N/m"',
                'cx = "2e3 N*s/m"',
                'cy = "2e3 N*s/m"',
                "",
            ]
        lines += [
            "[[mesh]]",
            f'name = "m{s}"',
            'type = "spur"',
            f'pinion = "p{s}"',
            f'gear = "g{s}"',
            f"teeth = {TEETH}",
            'pressure_angle = "20 deg"',
            f'base_radius1 = "{BASE_RADIUS_MM} mm"',
            f'base_radius2 = "{BASE_RADIUS_MM} mm"',
            'center_angle = "0 deg"',
            'pinion_rotation = "counterclockwise"',
            'stiffness = "3e8 N/m"',
            "kappa = [0.25]",
            "xi0 = 0.05",
            f'e = ["{eps_um} um"]',
            'backlash = "0.1 mm"',
            "",
        ]
        if s < stages:
            lines += [
                "[[connection]]",
                f'name = "c{s}"',
                f"vector = {{ g{s} = {{ theta = 1.0 }}, p{s + 1} = {{ theta = -1.0 }} }}",
                'kind = "torsional"',
                'stiffness = "2e5 N*m/rad"',
                'damping = "5 N*m*s/rad"',
                "",
            ]
    lines += [
        "[[load]]",
        'body = "p1"',
        f'torque = "{fp_torque} N*m"',
        "",
        "[[load]]",
        f'body = "g{stages}"',
        f'torque = "{-fp_torque} N*m"',
        "",
    ]
    path = Path(path)
    path.write_text("\n".join(lines))
    return path


_CHILD = r"""
import json, math, statistics, sys, time
import numpy as np
from geardyn.systems import load_system
from geardyn.integrate import integrate_batch
from geardyn.model import IntegrationOptions
path, points, target, repeat = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
s = load_system(path)
models = [s.with_param("omega", w) for w in np.linspace(0.5, 1.5, points)] if points > 1 else [s]
def run(k):
    t = time.process_time()
    r = integrate_batch(models, None, IntegrationOptions(transient=0, periods=k), record_poincare=False, threads=1)
    return time.process_time() - t, r
run(2)  # warm-up: compile or cache load, first-call costs
t0, r4 = run(4)  # a second warm-up: an upper bound of the cost of a period (setup included); the checksum's run
p = max(2, math.ceil(target / max(t0 / 4, 1e-6)))
per, setup = [], []
for _ in range(repeat):
    t1, r = run(p)
    t2, r = run(2 * p)
    per.append((t2 - t1) / (p * len(models)))
    setup.append(t1 - per[-1] * p * len(models))
print(json.dumps({"s_per_period": statistics.median(per), "pairs": per, "setup_s": statistics.median(setup),
                  "periods": p, "n": s.n, "steps": int(np.sum(r.nsteps)) // len(models),
                  "check": float(np.sum(r4.element_u_max(0)))}))
"""


def _time(src: Path, system: Path, points: int, target: float, repeat: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_NUM_THREADS="1")
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(system), str(points), str(target), str(repeat)],
        env=env,
        check=True,
        capture_output=True,
        text=True,
        cwd=tempfile.gettempdir(),
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def _cli_cpu(args: list[str], cwd: str) -> tuple[float, dict]:
    """CPU seconds (user + system) of one ``geardyn`` process of this checkout, and its JSON output."""
    import resource
    import shutil

    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    exe = shutil.which("geardyn") or "geardyn"
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([exe, *args], env=env, check=True, capture_output=True, text=True, cwd=cwd)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return cpu, json.loads(out.stdout)


def classify_cost(stages: int, repeat: int, path: Path | None) -> None:
    """The CPU time of ``simulate --system`` of a chain at ω = 0.8, classified and plain (``--no-classify``)."""
    with tempfile.TemporaryDirectory() as tmp:
        f = chain_toml(stages, Path(tmp) / f"chain_{6 * stages}dof.toml")
        args = ["simulate", "--system", str(f), "--omega", "0.8", "--json"]
        _cli_cpu([*args, "--no-classify"], tmp)  # compile / load the cache
        plain, full = [], []
        for _ in range(repeat):
            cp, jp = _cli_cpu([*args, "--no-classify"], tmp)
            cf, jf = _cli_cpu(args, tmp)
            plain.append(cp)
            full.append(cf)
        res = {
            "command": "geardyn simulate --system CHAIN.toml --omega 0.8 --json",
            "dof": 6 * stages,
            "plain_cpu_s": statistics.median(plain),
            "classified_cpu_s": statistics.median(full),
            "ratio": statistics.median(full) / statistics.median(plain),
            "motion_plain": jp["motion"],
            "motion_classified": jf["motion"],
            "lle": jf.get("lle"),
            "loadavg": os.getloadavg(),
        }
    print(json.dumps(res, indent=2))
    if path is not None:
        path.write_text(json.dumps(res, indent=2) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--before", type=Path, default=None, help="root of the checkout before the change")
    ap.add_argument("--classify", action="store_true", help="the classification's cost instead (see above)")
    ap.add_argument("--stages", type=int, nargs="+", default=[1, 8, 16, 32])
    ap.add_argument("--rounds", type=int, default=3, help="fresh processes per checkout and size, interleaved")
    ap.add_argument("--repeat", type=int, default=3, help="pairs of runs (p and 2p periods) in each process")
    ap.add_argument("--target", type=float, default=0.4, help="CPU seconds of a run of p periods")
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args()
    if a.classify:
        classify_cost(a.stages[0] if a.stages != [1, 8, 16, 32] else 16, a.repeat, a.json)
        return
    if a.before is None:
        ap.error("--before is required (the root of the checkout to compare with)")
    after_src, before_src = ROOT / "src", a.before.resolve() / "src"
    if not (before_src / "geardyn").is_dir():
        ap.error(f"--before: no src/geardyn under {a.before} (give the checkout's root)")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        cases = [("W4 bevel", BEVEL, 8)]
        for n in a.stages:
            # the scaling's chains: 40 N·m, 10 µm of STE (the step's cost does not depend on them)
            f = chain_toml(n, Path(tmp) / f"chain{n}.toml", fp_torque=40.0, eps_um=10.0)
            cases.append((f"chain {n}", f, 1))
        for name, path, points in cases:
            res = {"before": [], "after": []}
            for k in range(a.rounds):  # interleaved: before, after; after, before; ...
                for which in ("before", "after") if k % 2 == 0 else ("after", "before"):
                    src = before_src if which == "before" else after_src
                    res[which].append(_time(src, path, points, a.target, a.repeat))
            tb = [r["s_per_period"] for r in res["before"]]
            ta = [r["s_per_period"] for r in res["after"]]
            ra = res["after"][-1]
            row = {
                "case": name,
                "dof": ra["n"],
                "steps_per_period": ra["steps"],
                "before_ms_per_period": 1e3 * statistics.median(tb),
                "after_ms_per_period": 1e3 * statistics.median(ta),
                "speedup": statistics.median(tb) / statistics.median(ta),
                "before_ms_range": [1e3 * min(tb), 1e3 * max(tb)],
                "after_ms_range": [1e3 * min(ta), 1e3 * max(ta)],
                "before_periods_timed": res["before"][-1]["periods"],
                "after_periods_timed": ra["periods"],
                "before_setup_ms": 1e3 * statistics.median([r["setup_s"] for r in res["before"]]),
                "after_setup_ms": 1e3 * statistics.median([r["setup_s"] for r in res["after"]]),
                "same_result": all(r["check"] == res["before"][0]["check"] for r in res["before"] + res["after"]),
            }
            rows.append(row)
            print(
                f"{name:10s} {row['dof']:4d} DOF  before {row['before_ms_per_period']:9.3f} ms/period "
                f"({row['before_ms_range'][0]:.3f}-{row['before_ms_range'][1]:.3f})  "
                f"after {row['after_ms_per_period']:8.3f} "
                f"({row['after_ms_range'][0]:.3f}-{row['after_ms_range'][1]:.3f})"
                f"  speed-up {row['speedup']:6.2f}x  same numbers: {row['same_result']}  "
                f"(setup {row['before_setup_ms']:.0f} / {row['after_setup_ms']:.0f} ms)",
                flush=True,
            )
    res = {
        "rows": rows,
        "rounds": a.rounds,
        "repeat": a.repeat,
        "target_s": a.target,
        "threads": 1,
        "loadavg": os.getloadavg(),
    }
    if a.json is not None:
        a.json.write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
