"""The command line's habits: version, flags, required options, bounded counts, conflicting options, units in tables."""

from __future__ import annotations

import json

import pytest
import typer.main
from cli_run import run_cli

import geardyn
from geardyn.cli import app
from geardyn.params import cli_options

FAST = ["--transient", "20", "--periods", "8"]


def refused(argv: list[str]) -> str:
    """The one line a refused command prints (exit code 2, no traceback, no warning)."""
    code, out, err = run_cli(argv)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err and "Warning" not in err, err
    assert lines[0].startswith("error: ")
    return lines[0]


def test_version():
    code, out, _ = run_cli(["--version"])
    assert code == 0 and out.strip() == f"geardyn {geardyn.__version__}"


def test_flags_take_no_value_and_required_options_are_marked():
    group = typer.main.get_command(app)
    flags = 0
    for name, cmd in group.commands.items():
        for p in cmd.params:
            if getattr(p, "is_flag", False) and p.name != "help":
                flags += 1
                assert p.metavar == "", f"{name} {p.opts}: an on/off flag shows a value placeholder"
    assert flags > 20
    mp = {p.name: p for p in group.commands["map"].params}
    assert mp["x"].required and mp["y"].required
    code, out, _ = run_cli(["map", "--help"])
    assert code == 0 and "required" in out


def test_every_analysis_command_takes_the_registry_model_options():
    group = typer.main.get_command(app)
    flags = {o.flag for o in cli_options()}
    for name in ("simulate", "lyapunov", "orbit", "continuation", "bifurcation", "map", "basins"):
        opts = {o for p in group.commands[name].params for o in p.opts}
        assert flags <= opts, f"{name} lacks {flags - opts}"
    opts = {o for p in group.commands["response"].params for o in p.opts}
    assert flags - {"--omega"} <= opts and "--omega" not in opts  # response sweeps ω itself


def test_simulate_json_lists_the_poincare_points_after_the_summary():
    code, out, err = run_cli(["simulate", "--omega", "0.8", *FAST, "--json"])
    assert code == 0, err
    keys = list(json.loads(out))
    assert keys.index("motion") < keys.index("poincare") and keys[-2:] == ["poincare", "files"]


@pytest.mark.parametrize(
    "argv, starts",
    [
        (
            [
                "bifurcation",
                "--param",
                "omega",
                "--start",
                "0.5",
                "--stop",
                "1",
                "--num",
                "3",
                "--settle",
                "99999999999999999999999",
            ],
            "error: settle: must be an integer >= 0 and <= 100000000",
        ),
        (
            [
                "response",
                "--omega-start",
                "0.5",
                "--omega-stop",
                "1",
                "--num",
                "3",
                "--settle",
                "99999999999999999999999",
            ],
            "error: settle: must be an integer >= 0 and <= 100000000",
        ),
        (
            ["bifurcation", "--param", "omega", "--start", "0.5", "--stop", "1", "--num", "3", "--dtau", "1e-320"],
            "error: dtau: ω = 0.5 with Δτ",
        ),
        (
            ["simulate", "--omega", "0.8", "--dtau", "1e-6", "--periods", "100000000"],
            "error: transient/periods: 300 + 100000000 periods of 7853982 steps",
        ),
        (
            ["bifurcation", "--param", "omega", "--start", "0.5", "--stop", "1", "--num", "3", "--omega", "1e308"],
            "error: omega: --omega 1e+308 conflicts with the swept parameter omega",
        ),
        (
            ["continuation", "--param", "omega", "--start", "0.5", "--stop", "1", "--omega", "1e308"],
            "error: omega: --omega 1e+308 conflicts with the swept parameter omega",
        ),
        (
            [
                "map",
                "--x",
                "omega",
                "--y",
                "D",
                "--x-start",
                "0.5",
                "--x-stop",
                "1",
                "--y-start",
                "0.1",
                "--y-stop",
                "1",
                "--backlash",
                "0.3",
            ],
            "error: backlash: --backlash 0.3 conflicts with the swept parameter D",
        ),
        (
            ["bifurcation", "--rpm-start", "1000", "--rpm-stop", "2000", "--num", "3", "--rpm", "1500"],
            "error: rpm: --rpm 1500 conflicts with the swept parameter omega",
        ),
        (
            [
                "map",
                "--x",
                "omega",
                "--y",
                "xi0",
                "--x-start",
                "0.5",
                "--x-stop",
                "1",
                "--y-start",
                "0",
                "--y-stop",
                "1",
                "--x-num",
                "1000",
                "--y-num",
                "1000",
                "--periods",
                "1000",
            ],
            "error: periods: 1000000 points × 1000 recorded",
        ),
        (["simulate", "--rpm", "1e308"], "error: "),
    ],
)
def test_bad_counts_and_conflicts_are_refused_with_one_line(argv, starts):
    assert refused(argv).startswith(starts)


def test_tables_carry_physical_units_and_the_exponent():
    code, out, err = run_cli(["orbit", "--rpm", "2400", "--period", "2"])
    assert code == 0, err
    assert "pinion speed (rpm)" in out and "amplitude (µm)" in out
    code, out, err = run_cli(["simulate", "--omega", "0.8", *FAST])
    assert code == 0 and "Lyapunov exponent λ1" in out, err
    code, out, err = run_cli(["bifurcation", "--rpm-start", "1500", "--rpm-stop", "3000", "--num", "5", *FAST])
    assert code == 0 and "from (rpm)" in out and "1500.0" in out, err


def test_map_takes_pinion_speed_and_torque_axes():
    code, out, err = run_cli(
        [
            "map",
            "--x",
            "rpm",
            "--x-start",
            "1500",
            "--x-stop",
            "3000",
            "--y",
            "torque",
            "--y-start",
            "500",
            "--y-stop",
            "2000",
            "--x-num",
            "3",
            "--y-num",
            "2",
            *FAST,
            "--json",
        ]
    )
    assert code == 0, err
    s = json.loads(out)
    from geardyn.config import load_config
    from geardyn.units import PhysicalScales

    sc = PhysicalScales.from_config(load_config(None))
    assert (s["x"], s["y"]) == ("omega", "fp")
    assert s["x_values"][0] == pytest.approx(sc.omega_from_rpm(1500.0), rel=1e-12)
    assert s["x_values_rpm"][-1] == pytest.approx(3000.0, rel=1e-12)
    assert s["y_values"][-1] == pytest.approx(sc.fp_from_torque(2000.0), rel=1e-12)


def test_a_released_output_reads_back_as_write_netcdf_and_draws_the_figures_of_the_registry(tmp_path):
    """``cli.output.write_released`` (the map's output): the file equals ``write_netcdf``'s, the result's
    variables are dropped once written, the figures are those of the registry, the collector is left as found."""
    import gc

    import numpy as np

    from geardyn import GearModel, IntegrationOptions
    from geardyn.analysis.maps import parameter_map
    from geardyn.cli.output import write_released
    from geardyn.io import read_netcdf, write_netcdf
    from geardyn.plot import figures_for

    ds = parameter_map(
        GearModel(),
        "omega",
        np.array([0.8, 1.2]),
        "xi0",
        np.array([0.05, 0.1, 0.2]),
        options=IntegrationOptions(transient=10, periods=4),
        settle_periods=0,
        progress=False,
    )
    ref = read_netcdf(write_netcdf(ds.copy(deep=True), tmp_path / "ref.nc"))
    frozen = gc.get_freeze_count()
    files = write_released(ds, tmp_path / "out" / "map.nc", tmp_path / "out")
    assert gc.get_freeze_count() == frozen
    assert not ds.data_vars
    back = read_netcdf(files[0])
    assert back.identical(ref)
    assert [f.rsplit("/", 1)[-1] for f in files[1:]] == [f"{spec.stem}.png" for spec in figures_for(ref)]
