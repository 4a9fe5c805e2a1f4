"""Figures from saved data: ``geardyn plot FILE.nc`` and the ``ds.geardyn`` accessor."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import geardyn  # noqa: F401  (registers the accessor)
from geardyn.cli import app
from geardyn.io import read_netcdf, write_netcdf
from geardyn.model import GearModel, IntegrationOptions
from geardyn.plot import FIGURES, FigureSpec, PlotUnavailable, save_figures

SIMULATE_FIGURES = {
    "time_history.png",
    "phase_portrait.png",
    "spectrum.png",
    "physical_time_history.png",
    "spectrum_hz.png",
}


@pytest.fixture(scope="module")
def sim_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("sim")
    r = CliRunner().invoke(
        app,
        [
            "simulate",
            "--rpm",
            "2400",
            "--torque",
            "1500",
            "--transient",
            "50",
            "--periods",
            "8",
            "--json",
            "--out",
            str(d),
        ],
    )
    assert r.exit_code == 0, r.output
    return d / "simulate.nc"


def test_plot_command_redraws_a_saved_simulation(sim_file, tmp_path):
    out = tmp_path / "again"
    r = CliRunner().invoke(app, ["plot", str(sim_file), "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert s["kind"] == "simulate"
    assert {p.name for p in out.iterdir()} == SIMULATE_FIGURES
    assert sorted(s["files"]) == sorted(str(out / n) for n in SIMULATE_FIGURES)
    assert all((out / n).stat().st_size > 1000 for n in SIMULATE_FIGURES)


def test_plot_defaults_to_the_files_directory(sim_file, tmp_path):
    f = tmp_path / "copy.nc"
    f.write_bytes(sim_file.read_bytes())
    r = CliRunner().invoke(app, ["plot", str(f)])
    assert r.exit_code == 0, r.output
    assert SIMULATE_FIGURES <= {p.name for p in tmp_path.iterdir()}


def test_accessor_does_the_same_in_python(sim_file, tmp_path):
    ds = read_netcdf(sim_file)
    assert ds.geardyn.kind == "simulate"
    assert isinstance(ds.geardyn.model, GearModel)
    assert ds.geardyn.scales is not None and ds.geardyn.scales.k0_N_per_m == pytest.approx(2e9)
    paths = ds.geardyn.plot(tmp_path)
    assert {p.name for p in paths} == SIMULATE_FIGURES and all(p.exists() for p in paths)
    # physical variables for a result saved without them, with the default pair's scales
    bare = ds.drop_vars([v for v in ds.variables if str(v).endswith(("_um", "_N", "_s", "_Hz")) or v == "mesh_force"])
    bare.attrs = {k: v for k, v in ds.attrs.items() if not k.startswith("physical")}
    assert "mesh_force_N" not in bare and bare.geardyn.scales is None
    phys = bare.geardyn.physical()
    np.testing.assert_allclose(phys["mesh_force_N"].values, ds["mesh_force_N"].values, rtol=1e-12)
    f = tmp_path / "written.nc"
    bare.geardyn.to_netcdf(f)
    assert read_netcdf(f).geardyn.kind == "simulate"


def test_axis_labels_carry_units_from_the_dataset_attributes(sim_file):
    from geardyn.plot import physical as pphys
    from geardyn.plot import simulate as psim

    ds = read_netcdf(sim_file)
    fig = pphys.time_history(ds)
    a1, a2 = fig.axes[:2]
    assert a1.get_ylabel() == f"{ds['dte_um'].attrs['long_name']} [µm]"
    assert a2.get_ylabel().endswith("[kN]") and a2.get_xlabel() == "time [ms]"
    fig = pphys.spectrum_hz(ds)
    assert fig.axes[0].get_xlabel() == "frequency [Hz]" and fig.axes[0].get_ylabel().endswith("[µm]")
    fig = psim.time_history(ds)
    assert fig.axes[0].get_xlabel() == ds["tau"].attrs["long_name"]  # non-dimensional: no unit shown
    import matplotlib.pyplot as plt

    plt.close("all")


def test_plot_dispatches_a_sweep_and_draws_it_against_rpm(tmp_path):
    from geardyn.analysis.bifurcation import bifurcation
    from geardyn.analysis.physical import add_physical

    ds = bifurcation(
        GearModel(),
        "omega",
        np.array([0.8, 1.0, 1.2]),
        options=IntegrationOptions(transient=20, periods=8),
        settle_periods=0,
    )
    f = write_netcdf(add_physical(ds), tmp_path / "bif.nc")
    r = CliRunner().invoke(app, ["plot", str(f), "--json"])
    assert r.exit_code == 0, r.output
    names = {p.split("/")[-1] for p in json.loads(r.stdout)["files"]}
    assert "bifurcation.png" in names and "amplitude_um_vs_rpm.png" in names
    from geardyn.plot.physical import rpm_curve

    fig = rpm_curve(read_netcdf(f), "amplitude_um")
    assert fig.axes[0].get_xlabel() == "pinion speed [rpm]" and fig.axes[0].get_ylabel().endswith("[µm]")


def test_physical_figures_on_request_for_a_file_without_them(tmp_path):
    from geardyn.analysis.bifurcation import bifurcation

    ds = bifurcation(
        GearModel(),
        "omega",
        np.array([0.8, 1.0]),
        options=IntegrationOptions(transient=10, periods=4),
        settle_periods=0,
    )
    f = write_netcdf(ds, tmp_path / "bif.nc")
    r = CliRunner().invoke(app, ["plot", str(f), "--json"])
    assert "amplitude_um_vs_rpm.png" not in r.stdout
    r = CliRunner().invoke(app, ["plot", str(f), "--physical", "--json"])
    assert r.exit_code == 0, r.output
    assert "amplitude_um_vs_rpm.png" in r.stdout


def test_every_known_kind_has_a_drawer():
    for kind in (
        "simulate",
        "lyapunov",
        "bifurcation",
        "response",
        "map",
        "basins",
        "orbit",
        "continuation",
        "stability_boundary",
        "mathieu_boundary",
        "stability_comparison",
    ):
        assert FIGURES[kind] and all(isinstance(f, FigureSpec) and callable(f.draw) for f in FIGURES[kind])


def test_unplottable_files_are_refused_with_one_line(tmp_path):
    run = CliRunner()
    r = run.invoke(app, ["plot", str(tmp_path / "missing.nc")])
    assert r.exit_code == 2 and "not found" in r.output
    bad = tmp_path / "bad.nc"
    bad.write_text("not netcdf")
    r = run.invoke(app, ["plot", str(bad)])
    assert r.exit_code == 2 and "cannot read" in r.output
    weird = tmp_path / "weird.nc"
    xr.Dataset({"x": ("i", [1.0])}, attrs={"geardyn_kind": "weird"}).to_netcdf(weird, engine="h5netcdf")
    r = run.invoke(app, ["plot", str(weird)])
    assert r.exit_code == 2 and "no figures for results of kind 'weird'" in r.output
    assert len(r.output.strip().splitlines()) == 1
    plain = tmp_path / "plain.nc"
    xr.Dataset({"x": ("i", [1.0])}).to_netcdf(plain, engine="h5netcdf")
    r = run.invoke(app, ["plot", str(plain)])
    assert r.exit_code == 2 and "not a geardyn result" in r.output
    with pytest.raises(PlotUnavailable):
        save_figures(xr.Dataset(), tmp_path)


def test_import_geardyn_stays_light():
    code = (
        "import sys, geardyn; import xarray as xr; assert hasattr(xr.Dataset(), 'geardyn'); "
        "print(sorted(m for m in ('matplotlib', 'numba', 'pint', 'scipy') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
    from geardyn import GearModel as G  # noqa: F401

    assert G is GearModel


def test_simulate_json_builds_no_dataset_and_says_the_same_as_with_out(tmp_path):
    """Without --out, ``simulate --json`` imports none of the Dataset's or figures' libraries nor pint, and its
    summary is the one computed from the written Dataset (every key, every value)."""
    args = ["simulate", "--omega", "0.8", "--transient", "40", "--periods", "8", "--json"]
    code = (
        f"import sys; from geardyn.cli import main; main({args!r}); "
        "print(sorted(m for m in ('xarray', 'pandas', 'dask', 'matplotlib', 'pint') if m in sys.modules), "
        "file=sys.stderr)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stderr.strip().splitlines()[-1] == "[]"
    bare = json.loads(r.stdout)
    with_out = CliRunner().invoke(app, [*args, "--out", str(tmp_path)])
    assert with_out.exit_code == 0, with_out.output
    full = json.loads(with_out.stdout)
    assert bare.pop("files") == [] and full.pop("files")
    assert list(bare) == list(full) and json.dumps(bare) == json.dumps(full)
