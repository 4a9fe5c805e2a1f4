"""``geardyn runup --system``: the run-up of any system file, through the one System contract."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from geardyn import runup
from geardyn.analysis.rattle import pair_of_system
from geardyn.systems import load_system

TORSIONAL = Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_torsional.toml"


def _diff(a, b) -> float:
    return max(
        float(np.max(np.abs(a.order_amplitude - b.order_amplitude))),
        float(np.max(np.abs(a.amplitude - b.amplitude))),
        float(np.nanmax(np.abs(a.dynamic_factor - b.dynamic_factor))),
    )


def test_system_runup_is_its_pairs_run_up():
    """paper_torsional.toml is the paper's pair as two rotating bodies: its run-up through the mesh-vector kernel
    and the pair's through the 1-DOF kernel (ω 0.3 → 0.6 over τ = 1500, 108 blocks) are the same ramp, the same
    blocks, and the same order-tracked DTE, amplitude and dynamic factor to RK4's error, which falls as Δτ⁴
    between the two forms of the STE forcing (measured 3.8e-6 at Δτ = 0.05)."""
    s = load_system(TORSIONAL)
    m = pair_of_system(s)
    errs = []
    for dtau in (0.05, 0.025):
        a = runup(s, 0.3, 0.6, 1500.0, settle=100, dtau=dtau)
        b = runup(m, 0.3, 0.6, 1500.0, settle=100, dtau=dtau)
        assert np.array_equal(a.omega, b.omega) and a.cycles == b.cycles and not a.diverged
        errs.append(_diff(a, b))
    assert errs[0] < 1e-5 and errs[1] < errs[0] / 8, errs
    ds = a.to_dataset()
    assert ds.attrs["geardyn_system"] == "mesh" and "system_model" in ds.attrs


def test_cli_runup_system_in_rpm_with_its_figure(tmp_path):
    from cli_run import run_cli

    code, out, err = run_cli(
        ["runup", "--system", TORSIONAL, "--rpm-start", "800", "--rpm-stop", "1600", "--duration", "0.05",
         "--num", "0", "--json", "--out", tmp_path]
    )  # fmt: skip
    assert code == 0, err
    s = json.loads(out)
    assert 800 < s["rpm"][0] < s["rpm"][-1] <= 1600 * (1 + 1e-12) and len(s["rpm"]) == s["blocks"]
    assert s["model"]["reference_mesh"] == "mesh" and s["model"]["dofs"] == 2
    assert {"runup.nc", "runup.png"} <= {Path(f).name for f in s["files"]}
    # the pair's run-up of the same speeds (the file is the paper's pair): the same blocks in rpm
    code, out2, err = run_cli(
        ["runup", "--rpm-start", "800", "--rpm-stop", "1600", "--duration", "0.05", "--num", "0", "--json"]
    )
    assert code == 0, err
    np.testing.assert_allclose(s["rpm"], json.loads(out2)["rpm"], rtol=1e-12)
