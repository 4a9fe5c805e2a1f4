"""geardyn stiffness on the example files."""

import json
from pathlib import Path

from typer.testing import CliRunner

from geardyn.cli import app

EX = Path(__file__).resolve().parents[1] / "examples"


def test_stiffness_json_and_files(tmp_path):
    r = CliRunner().invoke(
        app, ["stiffness", str(EX / "tooth_crack_25.toml"), "--json", "--points", "16", "--out", str(tmp_path)]
    )
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert s["cycles"] == 20 and s["faults"][0]["depth"] == 0.25
    assert 0.8 < s["iso6336"]["mesh_mean_over_c_gamma"] < 1.2
    assert {Path(f).name for f in s["files"]} == {"stiffness.nc", "stiffness.png", "compliance.png"}


def test_stiffness_fault_option_and_errors(tmp_path):
    r = CliRunner().invoke(
        app,
        [
            "stiffness",
            str(EX / "tooth_healthy_spur.toml"),
            "--json",
            "--points",
            "16",
            "--fault",
            "broken:gear=1,tooth=3,remaining=0.8",
        ],
    )
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["cycles"] == 40
    bad = tmp_path / "bad.toml"
    bad.write_text("[tooth_pair]\nz1 = 20\n")
    r = CliRunner().invoke(app, ["stiffness", str(bad)])
    assert r.exit_code == 2 and "needs" in r.output
