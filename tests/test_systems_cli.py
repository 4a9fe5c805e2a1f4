"""``--system`` on the commands and ``geardyn modes``: JSON contracts and the exact reduction from the command line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
TORS = str(EX / "paper_torsional.toml")
BEVEL = str(EX / "paper_bevel_8dof.toml")


def run(*args: str, code: int = 0) -> subprocess.CompletedProcess:
    p = subprocess.run([sys.executable, "-m", "geardyn.cli", *args], capture_output=True, text=True)
    assert p.returncode == code, p.stderr
    return p


def test_simulate_system_reduces_exactly():
    a = json.loads(run("simulate", "--system", TORS, "--omega", "0.8", "--accurate", "--json").stdout)
    b = json.loads(run("simulate", "--omega", "0.8", "--accurate", "--json").stdout)
    m = a["meshes"][0]
    assert a["period"] == b["period"] == 2
    assert m["impact"] == a["impact"] == b["impact"]
    for k in ("u_min", "u_max", "amplitude"):
        assert m[k] == pytest.approx(b[k], abs=1e-6)
        assert a[k] == pytest.approx(b[k], abs=1e-6)
    assert m["dynamic_factor"] == pytest.approx(b["dynamic_factor"], rel=1e-6)
    assert set(b) - {"pair", "assumed", "spectrum_peaks", "history_periods", "fp", "torque_N_m", "backlash_um",
                     "dte_mean_um", "dte_rms_um", "mesh_force_mean_N"} <= set(a)
    for e in a["meshes"]:
        assert {"name", "u_min", "u_max", "amplitude", "impact", "dynamic_factor"} <= set(e)


def test_lyapunov_and_orbit_system_json():
    ly = json.loads(run("lyapunov", "--system", BEVEL, "--omega", "0.8", "--periods", "100", "--transient", "50",
                        "--json").stdout)
    assert len(ly["exponents"]) == 16 and len(ly["meshes"]) == 1
    assert ly["sum"] == pytest.approx(ly["expected_sum"], rel=1e-6)
    o = json.loads(run("orbit", "--system", TORS, "--omega", "0.8", "--json").stdout)
    o1 = json.loads(run("orbit", "--omega", "0.8", "--json").stdout)
    assert len(o["multipliers"]) == 4 and o["rigid_body_modes"] == 1
    got = sorted(x[0] for x in o["elastic_multipliers"])
    want = sorted(x[0] for x in o1["multipliers"])
    assert got == pytest.approx(want, abs=1e-6)
    assert o["meshes"][0]["name"] == "mesh"


def test_modes_json_and_figure(tmp_path):
    r = json.loads(run("modes", "--system", BEVEL, "--json").stdout)
    f = r["frequencies_hz"]
    assert f == sorted(f) and f[0] == 0.0 and len(f) == 8
    assert len(r["modes"]) == 8 and len(r["energy_fractions"]) == 8
    run("modes", "--system", BEVEL, "--out", str(tmp_path))
    assert (tmp_path / "campbell.png").stat().st_size > 0


def test_unavailable_and_bad_combinations_one_line():
    p = run("map", "--system", TORS, "--json", code=2)
    assert len(p.stderr.strip().splitlines()) == 1
    p = run("simulate", "--system", TORS, "--fp", "0.3", code=2)
    assert "system" in p.stderr and len(p.stderr.strip().splitlines()) == 1


def test_bifurcation_and_response_on_a_system():
    b = json.loads(run("bifurcation", "--system", TORS, "--start", "0.6", "--stop", "1.0", "--num", "5",
                       "--transient", "50", "--periods", "32", "--json").stdout)
    assert b["values"] == pytest.approx([0.6, 0.7, 0.8, 0.9, 1.0]) and len(b["period"]) == 5
    assert b["meshes"][0]["name"] == "mesh" and len(b["meshes"][0]["amplitude"]) == 5
    r = json.loads(run("response", "--system", TORS, "--omega-start", "0.6", "--omega-stop", "1.0", "--num", "5",
                       "--transient", "50", "--periods", "32", "--json").stdout)
    assert set(r["amplitude"]) == {"up", "down"} and "jumps" in r
