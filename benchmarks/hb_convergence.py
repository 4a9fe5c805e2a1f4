"""Convergence of harmonic balance in the number of harmonics H against a fine shooting reference.

For the paper's defaults (GearModel()) and the piecewise-linear case (κ1 = ξ1 = 0), ω from 0.5 to 1.0:

* reference: geardyn's shooting continuation in the accurate mode (steps split at u = ±D) with
  Δτ = 0.0005 (fold, grazing and period-doubling values agree with Δτ = 0.001 to about 1e-14, so
  the RK4 error is below what is measured here);
* HB continuation at H = 8, 16, 32, 64, 128: error of each event's ω, and the amplitude error
  (u_max − u_min)/2 of HB solved at the reference's ω = 0.70 and 0.90 (on the branch that exists
  there: the large-amplitude one, which is in contact-loss), against the shooting orbit there.

Run: ``python benchmarks/hb_convergence.py [--quick] [--harmonics H ...]`` (``--quick`` stops at H = 32;
``--harmonics`` runs only the rows given).  Prints a
Markdown table and the wall times.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from geardyn.analysis.hb import hb_continuation, hb_solve  # noqa: E402
from geardyn.analysis.periodic import continuation, shoot  # noqa: E402
from geardyn.model import GearModel  # noqa: E402

CASES = {"defaults": GearModel(), "piecewise-linear": GearModel(kappa=(0.0,), xi=(0.0,))}
DTAU_REF = 0.0005
OMEGA_AMP = (0.70, 0.90)


def _key(b) -> str:
    return f"{b.type}@{b.value:.3f}"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--harmonics", type=int, nargs="*", help="only these H (e.g. --harmonics 128)")
    args = ap.parse_args()
    Hs = tuple(args.harmonics) if args.harmonics else (8, 16, 32) if args.quick else (8, 16, 32, 64, 128)
    for name, m in CASES.items():
        t0 = time.perf_counter()
        ref = continuation(m, "omega", 0.5, 1.0, 1, switch=False, accurate=True, dtau=DTAU_REF)
        t_ref = time.perf_counter() - t0
        ref_ev = [(b.type, b.value) for b in ref.bifurcations]
        ref_amp = {w: shoot(m.replace(omega=w), 1, dtau=DTAU_REF, accurate=True).amplitude for w in OMEGA_AMP}
        print(
            f"\n## {name}  (shooting reference: {t_ref:.1f} s; events "
            + ", ".join(f"{t} {v:.8f}" for t, v in ref_ev)
            + ")\n"
        )
        print(
            "| H | N | "
            + " | ".join(f"{t} ω err" for t, _ in ref_ev)
            + " | "
            + " | ".join(f"amp err ω={w}" for w in OMEGA_AMP)
            + " | HB time (s) |"
        )
        print("|---" * (3 + len(ref_ev) + len(OMEGA_AMP)) + "|")
        for H in Hs:
            t0 = time.perf_counter()
            r = hb_continuation(m, "omega", 0.5, 1.0, harmonics=H)
            t_hb = time.perf_counter() - t0
            errs = []
            for typ, v in ref_ev:
                cand = [b.value for b in r.bifurcations if b.type == typ]
                errs.append(min(abs(c - v) for c in cand) if cand else float("nan"))
            amps = []
            for w in OMEGA_AMP:
                s = hb_solve(m.replace(omega=w), H, stability=False)
                amps.append(abs(s.amplitude - ref_amp[w]))
            print(
                f"| {H} | {r.samples} | "
                + " | ".join(f"{e:.1e}" for e in errs)
                + " | "
                + " | ".join(f"{e:.1e}" for e in amps)
                + f" | {t_hb:.1f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
