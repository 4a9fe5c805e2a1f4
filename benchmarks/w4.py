"""Workload W4: the 8-DOF bevel model, 100 values of ω, 300 transient + 200 recorded periods.

Measured in one run: geardyn's N-DOF kernel on one and on two threads, a plain C reference of the same
RK4 (benchmarks/ref_ndof.c, built here with ``gcc -O3 -march=native``), and SciPy ``solve_ivp`` (RK45,
rtol 1e-8, on a few points, scaled to the workload).  Prints a JSON line with the times, the ratios
and the load average (the machine may be shared).  The CPU times (``*_cpu_s``: the process's, over
all its threads; the C program's from the children's usage, its input parsing included) show the
work done when other jobs share the cores: on a loaded machine the wall-time speed-up of two threads
says more about the scheduler than about the kernel, and ``cpu_2threads / cpu_1thread`` near 1
shows that the second thread adds no work.

    python benchmarks/w4.py [--points 100] [--transient 300] [--periods 200] [--no-scipy]
                            [--json benchmarks/results/w4.json]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SYSTEM = HERE.parent / "examples" / "systems" / "paper_bevel_8dof.toml"


def _models(points):
    from geardyn.systems import load_system

    s = load_system(SYSTEM)
    return [s.with_param("omega", w) for w in np.linspace(0.5, 1.5, points)]


def _write_batch(models, path):
    from geardyn import _kernel_ndof as K
    from geardyn.integrate import forcing_period
    from geardyn.systems import SystemModel

    a = SystemModel.pack(models)
    A, B, W, g, _ = K.derived(a)
    n, M, H = a.Mi.shape[1], a.V.shape[1], a.coef.shape[3] - 1
    with open(path, "w") as f:
        f.write(f"{n} {M} {H} {len(models)}\n")
        for p, m in enumerate(models):
            Tf = forcing_period(m)
            N = int(np.ceil(Tf / 0.01))
            vals = [
                m.omega,
                Tf,
                N,
                *A[p].ravel(),
                *B[p].ravel(),
                *W[p].ravel(),
                *a.V[p].ravel(),
                *g[p],
                *a.D[p],
                *a.ratio[p],
                *a.coef[p].ravel(),
                *m.initial_state(),
            ]
            f.write(" ".join(repr(float(v)) for v in vals) + "\n")


def _geardyn(models, transient, periods, threads):
    from geardyn.integrate import integrate_batch
    from geardyn.model import IntegrationOptions

    opts = IntegrationOptions(transient=transient, periods=periods)
    c = time.process_time()
    t = time.perf_counter()
    r = integrate_batch(models, None, opts, record_poincare=False, threads=threads)
    dt = time.perf_counter() - t
    return dt, time.process_time() - c, float(np.sum(r.element_u_min(0) + r.element_u_max(0)))


def _children_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def _scipy(models, transient, periods, sample=2):
    from scipy.integrate import solve_ivp

    from geardyn.integrate import forcing_period

    total = 0.0
    for m in models[:: max(1, len(models) // sample)][:sample]:
        A = m.Mi @ m.Kb
        B = m.Mi @ m.Cb
        W = m.Mi @ m.V[0]
        g = m.Mi @ m.F
        mesh = m.meshes[0]
        c = mesh.coefficients()
        om, n, V = m.omega, m.n, m.V[0]

        def rhs(t, x):
            th = om * t
            C = c[0, 0, 0] + c[0, 1, 0] * np.cos(th) + c[0, 1, 1] * np.sin(th)
            K = c[1, 0, 0] + c[1, 1, 0] * np.cos(th) + c[1, 1, 1] * np.sin(th)
            E = c[2, 1, 0] * np.cos(th) + c[2, 1, 1] * np.sin(th)
            Ed = c[2, 1, 1] * np.cos(th) - c[2, 1, 0] * np.sin(th)
            q, v = x[:n], x[n:]
            d = V @ q - E
            f = d - min(max(d, -mesh.D), mesh.D)
            return np.concatenate([v, g - A @ q - B @ v - W * (C * (V @ v - om * Ed) + K * f)])

        T = forcing_period(m)
        npr = 20  # periods actually integrated per sampled point, scaled below
        t = time.perf_counter()
        solve_ivp(
            rhs, (0, npr * T), m.initial_state(), method="RK45", rtol=1e-8, atol=1e-10, t_eval=np.arange(1, npr + 1) * T
        )
        total += (time.perf_counter() - t) * (transient + periods) / npr
    return total / sample * len(models)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=100)
    ap.add_argument("--transient", type=int, default=300)
    ap.add_argument("--periods", type=int, default=200)
    ap.add_argument("--no-scipy", action="store_true")
    ap.add_argument("--json", type=Path, default=None, help="also write the result to this file")
    a = ap.parse_args()
    models = _models(a.points)
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "ref_ndof"
        subprocess.run(["gcc", "-O3", "-march=native", "-o", str(exe), str(HERE / "ref_ndof.c"), "-lm"], check=True)
        batch = Path(tmp) / "batch.txt"
        _write_batch(models, batch)
        _geardyn(models[:2], 1, 1, 1)  # compile / load the cache
        load0 = os.getloadavg()
        c0 = _children_cpu()
        out = subprocess.run(
            [str(exe), str(batch), str(a.transient), str(a.periods)], check=True, capture_output=True, text=True
        ).stdout.split()
        cpu_c = _children_cpu() - c0
        t_c, sum_c = float(out[0]), float(out[1])
        t1, cpu1, sum1 = _geardyn(models, a.transient, a.periods, 1)
        t2, cpu2, sum2 = _geardyn(models, a.transient, a.periods, 2)
        t_sp = None if a.no_scipy else _scipy(models, a.transient, a.periods)
        load1 = os.getloadavg()
    res = {
        "workload": f"W4: 8-DOF bevel, {a.points} omega, {a.transient} + {a.periods} periods",
        "c_reference_s": t_c,
        "geardyn_1thread_s": t1,
        "geardyn_2threads_s": t2,
        "ratio_1thread_vs_c": t1 / t_c,
        "speedup_2threads": t1 / t2,
        "c_reference_cpu_s": cpu_c,
        "geardyn_1thread_cpu_s": cpu1,
        "geardyn_2threads_cpu_s": cpu2,
        "ratio_1thread_vs_c_cpu": cpu1 / cpu_c,
        "cpu_2threads_over_1thread": cpu2 / cpu1,
        "scipy_rk45_estimated_s": t_sp,
        "checksum_c": sum_c,
        "checksum_geardyn": sum1,
        "checksum_geardyn_2threads": sum2,
        "loadavg_before": load0,
        "loadavg_after": load1,
    }
    text = json.dumps(res, indent=2)
    print(text)
    if a.json is not None:
        a.json.write_text(text + "\n")


if __name__ == "__main__":
    main()
