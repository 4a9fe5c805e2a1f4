"""Harmonic-balance continuation at gearbox size: the 48-DOF chain against the 8-DOF bevel pair, per point.

The two systems, at H = 16, each continued in ω with the library call ``geardyn hb --system FILE --param omega
--start A --stop B --harmonics 16`` makes (:func:`geardyn.analysis.hb.continuation.hb_continuation`, monodromy
Floquet multipliers, the default steps):

* the 8-DOF bevel pair, ``examples/systems/paper_bevel_8dof.toml``, ω from 0.6 to 1.2 (a grazing, two folds and
  three Neimark–Sacker points, as ``benchmarks/hb_system.py``);
* the 48-DOF chain of 8 spur stages of ``benchmarks/ndof_scaling.py`` (:func:`chain_toml`; 6 DOF a stage) at
  30 N·m and 10 µm of STE, ω from 0.6 to 0.8 (the meshes lose contact from about ω = 0.65, two folds, two
  Neimark–Sacker points and grazings of every mesh).  At the generator's defaults (10 N·m, 20 µm) the chain's
  response is not periodic about ω = 0.8 and harmonic balance has no branch to follow.

Each run is a fresh subprocess (one BLAS thread) of the code here or of ``--before`` (the source tree before the
change), after a compile run on a short interval; the two systems and the two checkouts interleaved and repeated.
The CPU time of the continuation (process time: the work, whatever else shares the machine) is divided by the
branch's points and by its Jacobian evaluations (Newton iterations, tangents and event trials alike); the ratio
chain/pair per point is the figure of merit (issue: at most 5).  ``--profile`` adds where the chain's time goes
(cProfile in CPU time, cumulative per function: the Jacobian's assembly, its compressed-column matrix, SuperLU's
factorisation, the linear solves as a whole, the AFT, the Floquet multipliers and their compiled kernel).
``--leading`` adds the chain's multipliers at ω = 0.6 and 0.75 (their moduli) and the cost of leading ones computed
matrix-free: the kernel's time per period against its number of tangent columns, and ARPACK's matrix-vector products
for the 4 and 8 leading eigenvalues of the monodromy matrix (each would be one period of the kernel).

    python benchmarks/hb_scaling.py [--before ../hb-before/src] [--repeat 2] [--profile] [--leading]
                                    [--json benchmarks/results/hb_scaling.json]
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
sys.path.insert(0, str(HERE))
from ndof_scaling import chain_toml  # noqa: E402

BEVEL = ROOT / "examples" / "systems" / "paper_bevel_8dof.toml"
H = 16
CASES = {"bevel_8dof": (0.6, 1.2), "chain_48dof": (0.6, 0.8)}

_CHILD = r"""
import cProfile, json, pstats, sys, time
from geardyn.systems import load_system
from geardyn.analysis.hb import equations, continuation
path, lo, hi, H, profile = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), sys.argv[5] == "1"
m = load_system(path)
continuation.hb_continuation(m, "omega", lo, lo + 0.01 * (hi - lo), harmonics=H, max_points=3)  # compile
calls = {"jacobians": 0, "stability": 0}
for name, key in (("_jacobian", "jacobians"), ("stability", "stability")):
    f = getattr(equations.HBEquations, name)
    def counted(*a, _f=f, _k=key, **k):
        calls[_k] += 1
        return _f(*a, **k)
    setattr(equations.HBEquations, name, counted)
pr = cProfile.Profile(time.process_time) if profile else None
t = time.process_time()
if pr: pr.enable()
r = continuation.hb_continuation(m, "omega", lo, hi, harmonics=H)
if pr: pr.disable()
cpu = time.process_time() - t
out = {"cpu_s": cpu, "points": int(r.values.size), "dofs": int(r.equations.basis.dofs), "end": r.end,
       "events": [[b.type, round(float(b.value), 6)] for b in r.bifurcations], **calls,
       "amplitude_max": float(max(r.amplitude))}
if pr:
    st = pstats.Stats(pr).stats
    parts = {"jacobian_assembly": ("equations.py", "_jacobian"), "csc_matrix": ("equations.py", "tocsc"),
             "sparse_lu": ("linsolve.py", "splu"), "linear_solve": ("equations.py", "solve"),
             "aft": ("aft.py", "dead_zone_terms"), "floquet": ("monodromy.py", "monodromy_floquet"),
             "tangent_kernel": ("_monodromykernel.py", "monodromy_kernel")}
    out["profile_cumulative_s"] = {k: max([v[3] for (f, _l, fn), v in st.items() if fn == name and f.endswith(mod)],
                                          default=0.0) for k, (mod, name) in parts.items()}
    out["profile_total_s"] = sum(v[2] for v in st.values())
print("RESULT " + json.dumps(out))
"""

_LEADING = r"""
import json, sys, time
import numpy as np
import scipy.sparse.linalg as sla
from geardyn.systems import load_system
from geardyn.analysis.hb import monodromy
from geardyn.analysis.hb.solve import hb_solve
path, H = sys.argv[1], int(sys.argv[2])
calls = []
kernel = monodromy.monodromy_kernel
def recording(*a):
    x0, Y0 = a[0].copy(), a[1].copy()
    r = kernel(*a)
    calls.append((x0, Y0, a[1].copy(), a))
    return r
monodromy.monodromy_kernel = recording
out = {}
for omega in (0.6, 0.75):
    calls.clear()
    sol = hb_solve(load_system(path).with_param("omega", omega), H)
    x0, Q, Y, args = calls[-1]  # the period the multipliers come from
    Phi = Q.T @ Y
    mu = np.linalg.eigvals(Phi)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    cpu = {}
    for m in (1, 4, 16, Q.shape[1]):
        a = list(args)
        a[0], a[1] = x0.copy(), np.ascontiguousarray(Q[:, :m])
        t = time.process_time()
        for _ in range(3):
            a[0], a[1] = x0.copy(), np.ascontiguousarray(Q[:, :m])
            kernel(*a)
        cpu[m] = (time.process_time() - t) / 3
    arnoldi = {}
    for k in (4, 8):
        count = [0]
        def mv(v):
            count[0] += 1
            return Phi @ v
        L = sla.LinearOperator(Phi.shape, matvec=mv, dtype=float)
        w = sla.eigs(L, k=k, which="LM", tol=1e-10, return_eigenvectors=False)
        w = np.sort(np.abs(w))[::-1]
        arnoldi[k] = {"matvecs": count[0], "modulus_error": float(np.max(np.abs(w - np.abs(mu[:k]))))}
    out[str(omega)] = {"multipliers": int(mu.size), "modulus_largest": float(abs(mu[0])),
                       "modulus_smallest": float(abs(mu[-1])),
                       "moduli_above": {str(r): int(np.sum(np.abs(mu) > r)) for r in (0.9, 0.5, 0.3)},
                       "kernel_cpu_s_by_columns": {str(m): v for m, v in cpu.items()},
                       "arnoldi_leading": {str(k): v for k, v in arnoldi.items()}}
print("RESULT " + json.dumps(out))
"""


def leading(system: Path) -> dict:
    """The chain's spectrum of multipliers and what leading multipliers computed matrix-free would cost: the
    moduli, the monodromy kernel's CPU time per period with 1, 4, 16 and all tangent columns, and the matrix-vector
    products ARPACK (``scipy.sparse.linalg.eigs``) takes for the 4 and 8 leading eigenvalues of the monodromy matrix."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", _LEADING, str(system), str(H)], env=env, check=True,
                         capture_output=True, text=True)  # fmt: skip
    return json.loads([ln for ln in out.stdout.splitlines() if ln.startswith("RESULT ")][-1][7:])


def _run(src: Path, system: Path, lo: float, hi: float, profile: bool = False) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(system), str(lo), str(hi), str(H), "1" if profile else "0"],
        env=env, check=True, capture_output=True, text=True,
    )  # fmt: skip
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("RESULT ")][-1]
    r = json.loads(line[7:])
    r["s_per_point"] = r["cpu_s"] / r["points"]
    r["s_per_jacobian"] = r["cpu_s"] / max(r["jacobians"], 1)
    return r


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", type=Path, help="source tree (the src directory) of the code before the change")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--before-repeat", type=int, default=1, help="repeats of the (slow) code before the change")
    ap.add_argument("--profile", action="store_true", help="also profile the chain once (cProfile)")
    ap.add_argument("--leading", action="store_true", help="also measure the chain's multipliers (leading ones)")
    ap.add_argument("--json", type=Path, default=HERE / "results" / "hb_scaling.json")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        systems = {"bevel_8dof": BEVEL, "chain_48dof": chain_toml(8, Path(tmp) / "chain8.toml", fp_torque=30.0,
                                                                    eps_um=10.0)}  # fmt: skip
        trees = {"after": ROOT / "src"} | ({"before": a.before.resolve()} if a.before else {})
        runs: dict[str, dict[str, list[dict]]] = {t: {c: [] for c in CASES} for t in trees}
        for rep in range(max(a.repeat, a.before_repeat if a.before else 0)):
            for tree, src in trees.items():
                if rep >= (a.before_repeat if tree == "before" else a.repeat):
                    continue
                for case, (lo, hi) in CASES.items():
                    r = _run(src, systems[case], lo, hi)
                    runs[tree][case].append(r)
                    print(f"{tree:6s} {case:12s} {r['points']:4d} points {r['jacobians']:5d} Jacobians "
                          f"{r['stability']:4d} Floquet  {r['cpu_s']:8.2f} s CPU  {1e3 * r['s_per_point']:8.1f} "
                          f"ms/point  {1e3 * r['s_per_jacobian']:7.2f} ms/Jacobian", flush=True)  # fmt: skip
        profile = _run(ROOT / "src", systems["chain_48dof"], *CASES["chain_48dof"], profile=True) if a.profile else None
        lead = leading(systems["chain_48dof"]) if a.leading else None
        if lead:
            print(json.dumps(lead, indent=1))
    summary = {}
    for tree, cases in runs.items():
        med = {c: {k: statistics.median(r[k] for r in rs) for k in ("s_per_point", "s_per_jacobian", "cpu_s")}
               for c, rs in cases.items()}  # fmt: skip
        summary[tree] = {
            "median": med,
            "ratio_per_point": med["chain_48dof"]["s_per_point"] / med["bevel_8dof"]["s_per_point"],
            "ratio_per_jacobian": med["chain_48dof"]["s_per_jacobian"] / med["bevel_8dof"]["s_per_jacobian"],
        }
        print(f"{tree}: chain/pair per point {summary[tree]['ratio_per_point']:.2f}x, "
              f"per Jacobian {summary[tree]['ratio_per_jacobian']:.2f}x")  # fmt: skip
    if "before" in summary:
        b, f = summary["before"]["median"]["chain_48dof"], summary["after"]["median"]["chain_48dof"]
        summary["chain_speedup_per_point"] = b["s_per_point"] / f["s_per_point"]
        print(f"48-DOF chain: {summary['chain_speedup_per_point']:.1f}x faster per point than before")
    out = {
        "harmonics": H,
        "intervals": {c: list(v) for c, v in CASES.items()},
        "chain": "chain_toml(8, fp_torque=30 N*m, eps_um=10 um): 48 DOF, 8 meshes",
        "load_average": os.getloadavg(),
        "runs": runs,
        "summary": summary,
        "profile_chain": profile,
        "leading_multipliers_chain": lead,
    }
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
