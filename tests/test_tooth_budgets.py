"""Options a run cannot honour are refused before computing, exit 2, one line naming the option and the bound
(with the estimate for a run too large); a fault of size 0 on the command line gives the healthy pair."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from geardyn.cli import app

PAIR = str(Path(__file__).resolve().parents[1] / "examples" / "tooth_19_48.toml")


@pytest.mark.parametrize(
    "cmd, args, words",
    [
        ("stiffness", ["--points", "100000000"], ["points x cycles x slices", "GB"]),
        ("stiffness", ["--slices", "100000000"], ["points x cycles x slices", "GB"]),
        ("stiffness", ["--cycles", "1000000000"], ["points x cycles x slices", "GB"]),
        ("stiffness", ["--slices", "0"], ["slices", "at least 1"]),
        ("stiffness", ["--harmonics", "100000000"], ["harmonics", "32"]),
        ("signature", ["--fs", "1e12"], ["fs x revolutions", "samples"]),
        ("signature", ["--revolutions", "100000000"], ["fs x revolutions", "samples"]),
        ("signature", ["--fs", "nan"], ["fs"]),
        ("signature", ["--noise", "nan"], ["noise", "[0, 1]"]),
        ("signature", ["--noise", "-1"], ["noise", "[0, 1]"]),
        ("signature", ["--noise", "1e12"], ["noise", "[0, 1]"]),
        ("signature", ["--sweep-depths", "-0.5,0.2"], ["sweep-depths", "[0, 0.95]"]),
    ],
)
def test_refused_in_one_line_with_exit_2(cmd, args, words):
    r = CliRunner().invoke(app, [cmd, PAIR, *args, "--json"])
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and all(w in lines[0] for w in words), r.output


@pytest.mark.parametrize(
    "fault",
    [
        "crack:gear=0,tooth=0,depth=0",
        "crack:gear=1,tooth=5,depth=0,length=0.5",
        "spall:gear=0,tooth=0,at=0.5,length=0,width=0.004",
        "spall:gear=0,tooth=0,at=0.5,length=0.001,width=0.004,depth=0",
        "wear:gear=0,depth=0",
        "broken:gear=1,tooth=2,remaining=1",
    ],
)
def test_fault_of_size_zero_gives_the_healthy_mean_and_minimum(fault):
    def run(*extra):
        r = CliRunner().invoke(app, ["stiffness", PAIR, "--json", *extra])
        assert r.exit_code == 0, r.output
        return json.loads(r.stdout)

    h, f = run("--cycles", "48"), run("--cycles", "48", "--fault", fault)
    assert f["k_mean_N_per_um"] == pytest.approx(h["k_mean_N_per_um"], rel=1e-9)
    assert f["k_min_N_per_um"] == pytest.approx(h["k_min_N_per_um"], rel=1e-9)
