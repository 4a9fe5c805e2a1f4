"""Record the regression values of ``tests/test_regression.py`` (run once, on the commit named in the file).

``python tests/data/record_regression.py`` writes ``tests/data/regression_values.json``: every float as
``float.hex`` so that the comparison is bit for bit.  It is run only when the numbers are meant to change
(an issue that says so); a refactoring must leave them as they are.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from geardyn import GearModel, IntegrationOptions
from geardyn.analysis.bifurcation import bifurcation
from geardyn.analysis.lyapunov import lyapunov_spectrum
from geardyn.analysis.periodic import continuation, shoot
from geardyn.analysis.steady import simulate

HERE = Path(__file__).parent


def hexes(a) -> list:
    return [float(x).hex() for x in np.asarray(a, dtype=float).ravel()]


def compute() -> dict:
    out: dict = {}
    ds = bifurcation(
        GearModel(), "omega", np.linspace(0.6, 1.4, 9), options=IntegrationOptions(transient=120, periods=24)
    )
    out["bifurcation"] = {
        k: hexes(ds[k].values)
        for k in ("poincare_u", "poincare_v", "period", "motion", "impact", "amplitude", "u_min", "u_max", "lle")
    }
    orb = shoot(GearModel(omega=0.8), n=2)
    out["orbit"] = {
        "state": hexes(orb.state),
        "monodromy": hexes(orb.monodromy),
        "u_min": hexes([orb.u_min]),
        "u_max": hexes([orb.u_max]),
    }
    ly = lyapunov_spectrum(GearModel(omega=1.2), IntegrationOptions(transient=100, periods=300))
    out["lyapunov"] = {"exponents": hexes(ly.exponents), "uncertainty": hexes(ly.uncertainty)}
    st = simulate(GearModel(omega=0.8), IntegrationOptions(transient=100, periods=16))
    out["simulate"] = {"poincare": hexes(st.poincare), "amplitude": hexes([st.summary["amplitude"]])}
    cr = continuation(GearModel(), "omega", 0.9, 1.1, switch=False)
    out["continuation"] = {
        "param": hexes(np.concatenate([b.values for b in cr.branches])),
        "amplitude": hexes(np.concatenate([b.amplitude for b in cr.branches])),
        "monodromy": hexes(np.concatenate([b.monodromy for b in cr.branches])),
    }
    return out


if __name__ == "__main__":
    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, cwd=HERE).stdout.strip()
    values = compute()
    values["_recorded_at"] = commit
    (HERE / "regression_values.json").write_text(json.dumps(values, indent=1, sort_keys=True) + "\n")
    print("recorded", {k: len(v) for k, v in values.items() if isinstance(v, dict)}, file=sys.stderr)
