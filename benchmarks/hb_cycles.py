"""Harmonic balance of the pair with an excitation of P = 20 mesh cycles against shooting: accuracy and time.

Case: the 20/40 spur pair (m = 3 mm, b = 20 mm, 100 N·m, 1000 rpm scales) with a 50 % root crack on pinion tooth 0
(``tests/test_tooth_hunting.py``): the excitation repeats every pinion revolution, P = 20, 64 harmonics of ω/20
kept (mesh orders up to 3.2).  ω is the mesh frequency.

* one point at ω = 0.6 (in contact all round) and ω = 0.95 (contact loss, u_min < D): HB at H = 160, 320 (the
  default, 16·P), 640 and 1024 harmonics of ω/20 — the state (u, u') at θ = 0, the half peak-to-peak amplitude and
  the Floquet multipliers against shooting's fixed point of the revolution map (accurate mode, Δτ = 0.0025);
  the time of Newton from the simulated guess, of the guess, and of the multipliers (monodromy);
* shooting's time for the same point (Δτ = 0.02 accurate, from HB's state and from its own simulated guess);
* a continuation in ω from 0.9 to 0.96 by HB (H = 320) and by shooting (Δτ = 0.02, default mode): points, time
  and the grazing both find.

Run: ``python benchmarks/hb_cycles.py``.  Prints the tables, the load average before and after, and writes
``benchmarks/results/hb_cycles.json``.
"""

from __future__ import annotations

import json
import os
import platform
import resource
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from geardyn.analysis.hb import hb_continuation, hb_solve  # noqa: E402
from geardyn.analysis.hb.equations import HBEquations  # noqa: E402
from geardyn.analysis.periodic import continuation  # noqa: E402
from geardyn.analysis.periodic.orbit import shoot  # noqa: E402
from geardyn.tooth import Crack, mesh_stiffness, pair_geometry, pair_model  # noqa: E402

OUT = Path(__file__).parent / "results" / "hb_cycles.json"


def cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def timed(f):
    t, c = time.perf_counter(), cpu()
    out = f()
    return out, time.perf_counter() - t, cpu() - c


def model():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    m, _ = pair_model(mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, 0.5)], points=16), 1000.0, harmonics=64)
    return m


def main() -> None:
    load0 = os.getloadavg()
    m0 = model()
    hb_solve(m0.replace(omega=0.6), harmonics=32)  # compile
    shoot(m0.replace(omega=0.6), 1, dtau=0.05, accurate=True)
    points = []
    for w in (0.6, 0.95):
        m = m0.replace(omega=w)
        ref = shoot(m, 1, dtau=0.0025, accurate=True, guess=hb_solve(m).state())
        mu_ref = np.sort_complex(np.linalg.eigvals(ref.monodromy))
        amp_ref = 0.5 * (ref.u_max - ref.u_min)
        for H in (160, 320, 640, 1024):
            g, tg, cg = timed(lambda: HBEquations(m, H).simulated_guess()[0])
            s, tn, cn = timed(lambda: hb_solve(m, harmonics=H, guess=g, stability=False))
            st, tt, ct = timed(lambda: hb_solve(m, harmonics=H, guess=s.coefficients))
            points.append(
                {
                    "omega": w,
                    "method": "hb",
                    "harmonics": H,
                    "status": int(st.status),
                    "state_error": float(np.max(np.abs(st.state() - ref.state))),
                    "amplitude_error": float(abs(st.amplitude - amp_ref)),
                    "multiplier_error": float(np.max(np.abs(np.sort_complex(st.multipliers) - mu_ref))),
                    "guess_s": tg,
                    "newton_s": tn,
                    "newton_cpu_s": cn,
                    "with_multipliers_s": tt,
                    "u_min": st.u_min,
                    "D": m.D,
                }
            )
        for dt in (0.02, 0.005):
            o, t1, c1 = timed(lambda: shoot(m, 1, dtau=dt, accurate=True, guess=ref.state))
            o2, t2, c2 = timed(lambda: shoot(m, 1, dtau=dt, accurate=True))
            points.append(
                {
                    "omega": w,
                    "method": "shooting",
                    "dtau": dt,
                    "state_error": float(np.max(np.abs(o.state - ref.state))),
                    "multiplier_error": float(np.max(np.abs(np.sort_complex(np.linalg.eigvals(o.monodromy)) - mu_ref))),
                    "from_hb_state_s": t1,
                    "from_simulation_s": t2,
                    "from_simulation_cpu_s": c2,
                }
            )
    r, th, ch = timed(lambda: hb_continuation(m0, "omega", 0.9, 0.96))
    sr, ts, cs = timed(lambda: continuation(m0, "omega", 0.9, 0.96, 1, dtau=0.02, switch=False))
    cont = {
        "hb": {
            "harmonics": r.harmonics,
            "points": int(r.values.size),
            "wall_s": th,
            "cpu_s": ch,
            "events": [(b.type, b.value) for b in r.bifurcations],
            "end": r.end,
        },
        "shooting": {
            "dtau": 0.02,
            "points": sum(len(b) for b in sr.branches),
            "wall_s": ts,
            "cpu_s": cs,
            "events": [(b.type, b.value) for b in sr.bifurcations],
        },
    }
    res = {
        "case": "20/40 spur pair, 50 % crack on pinion tooth 0, P = 20, 64 harmonics of ω/20",
        "points": points,
        "continuation": cont,
        "load_before": load0,
        "load_after": os.getloadavg(),
        "machine": platform.processor() or platform.machine(),
        "python": platform.python_version(),
    }
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text(json.dumps(res, indent=1))
    print("| ω | method | H / Δτ | state error | amplitude error | multiplier error | time (s) |")
    print("|---|---|---|---|---|---|---|")
    for p in points:
        if p["method"] == "hb":
            print(
                f"| {p['omega']} | HB | {p['harmonics']} | {p['state_error']:.1e} | {p['amplitude_error']:.1e} | "
                f"{p['multiplier_error']:.1e} | guess {p['guess_s']:.2f} + Newton {p['newton_s']:.2f}; with "
                f"multipliers {p['with_multipliers_s']:.2f} |"
            )
        else:
            print(
                f"| {p['omega']} | shooting | {p['dtau']} | {p['state_error']:.1e} | — | {p['multiplier_error']:.1e} "
                f"| {p['from_hb_state_s']:.2f} from HB's state, {p['from_simulation_s']:.2f} from simulation |"
            )
    for k, v in cont.items():
        print(f"{k}: {v}")
    print(f"load average before {load0}, after {os.getloadavg()}")


if __name__ == "__main__":
    main()
