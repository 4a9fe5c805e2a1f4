"""The figure registry: every command's figures are redrawn from its file, every figure function takes
``ax=`` and returns its artists, no backend is forced; the variable registry and the JSON summary."""

from __future__ import annotations

import inspect
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.artist import Artist
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.io import annotate, attach, attached, detach, read_netcdf, summary_json, variable, write_netcdf
from geardyn.plot import FIGURES, PHYSICAL_FIGURES, PlotArtists, PlotError, draw, figures_for, save_figures
from geardyn.plot.common import new_figure

#: Tiny runs of every command that writes figures with --out.
COMMANDS = {
    "simulate": ["simulate", "--omega", "1.2", "--transient", "20", "--periods", "8"],
    "lyapunov": ["lyapunov", "--omega", "1.2", "--transient", "20", "--periods", "100", "--blocks", "4"],
    "orbit": ["orbit", "--omega", "1.2", "--transient", "50"],
    "continuation": [
        "continuation",
        "--param",
        "omega",
        "--start",
        "1.2",
        "--stop",
        "1.3",
        "--sweep-num",
        "5",
        "--transient",
        "20",
        "--no-switch",
    ],
    "bifurcation": [
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "0.8",
        "--stop",
        "1.2",
        "--num",
        "4",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "response": [
        "response",
        "--omega-start",
        "0.8",
        "--omega-stop",
        "1.2",
        "--num",
        "4",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "map": [
        "map",
        "--x",
        "omega",
        "--y",
        "xi0",
        "--x-start",
        "0.8",
        "--x-stop",
        "1.2",
        "--x-num",
        "3",
        "--y-start",
        "0.05",
        "--y-stop",
        "0.1",
        "--y-num",
        "2",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "basins": ["basins", "--omega", "1.2", "--nu", "3", "--nv", "3", "--transient", "20", "--periods", "16"],
    "runup": ["runup", "--omega-start", "0.8", "--omega-stop", "0.9", "--tau-duration", "300", "--num", "2"],
    "hb": ["hb", "--param", "omega", "--start", "1.2", "--stop", "1.3", "--harmonics", "4"],
}
_SYSTEM = str(Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_torsional.toml")
#: The same commands on a multi-DOF system (the same kinds, ``<command>.nc``; the figures only a system has come
#: from geardyn.plot.systems).
COMMANDS.update(
    {f"system_{k}": v[:1] + ["--system", _SYSTEM] + v[1:] for k, v in COMMANDS.items() if k not in ("runup", "hb")}
)  # hb refuses --system for now
COMMANDS["system_basins"] = [
    "basins",
    "--system",
    _SYSTEM,
    "--omega",
    "1.2",
    "--nu",
    "2",
    "--nv",
    "2",
    "--transient",
    "20",
    "--periods",
    "8",
    "--settle",
    "0",
]
COMMANDS["modes"] = ["modes", "--system", _SYSTEM]
#: (a gearbox's modes: its shafts' mode shapes beside the Campbell diagram)
COMMANDS["gearbox_modes"] = [
    "modes",
    "--system",
    str(Path(__file__).resolve().parents[1] / "examples" / "gearbox" / "two_stage_helical.toml"),
    "--rpm-max",
    "3000",
]
#: (a system's continuation over a brute-force sweep of two points)
COMMANDS["system_continuation"] = [
    "continuation",
    "--system",
    _SYSTEM,
    "--param",
    "omega",
    "--start",
    "1.3",
    "--stop",
    "1.35",
    "--ds-max",
    "0.1",
    "--sweep-num",
    "2",
    "--transient",
    "20",
]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """name -> (output directory, command JSON) of each command run with --out."""
    out = {}
    for name, args in COMMANDS.items():
        d = tmp_path_factory.mktemp(name)
        r = CliRunner().invoke(app, args + ["--json", "--out", str(d)])
        assert r.exit_code == 0, r.output
        out[name] = (d, json.loads(r.stdout))
    return out


def _file_stem(name):
    """The file a run writes: its command's name (``system_bifurcation``, ``gearbox_modes``: the same command)."""
    return name.removeprefix("system_").removeprefix("gearbox_")


def _figures_in(directory):
    return {p.name for p in directory.iterdir() if p.suffix == ".png"}


@pytest.mark.parametrize("name", list(COMMANDS))
def test_plot_redraws_the_figures_the_command_drew(runs, name, tmp_path):
    d, summary = runs[name]
    drawn = _figures_in(d)
    assert drawn, f"{name} --out wrote no figure"
    assert {p.split("/")[-1] for p in summary["files"] if p.endswith(".png")} == drawn
    nc = d / f"{_file_stem(name)}.nc"
    r = CliRunner().invoke(app, ["plot", str(nc), "--out", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    assert _figures_in(tmp_path) == drawn
    if name.startswith("system_"):  # a system's JSON adds its meshes
        assert (
            all(
                {"name", "u_min", "u_max", "amplitude", "impact", "dynamic_factor"} <= set(m) for m in summary["meshes"]
            )
            and summary["meshes"]
        )
    if name == "system_continuation":  # the torsional pair's rigid rotation is left out of the multipliers
        assert summary["rigid_body_modes"] == 1 and len(summary["branch"][0]["multipliers"]) == 2
        assert (d / "continuation_sweep.nc").exists()
    assert {p.split("/")[-1] for p in json.loads(r.stdout)["files"]} == drawn
    # the accessor and save_figures are the same path
    assert {p.name for p in read_netcdf(nc).geardyn.plot(tmp_path / "acc")} == drawn


def test_continuation_file_carries_its_brute_force_sweep(runs):
    d, summary = runs["continuation"]
    ds = read_netcdf(d / "continuation.nc")
    sweep = attached(ds, "sweep")
    alone = read_netcdf(d / "continuation_sweep.nc")
    assert sweep is not None and sweep.attrs["geardyn_kind"] == "bifurcation"
    for v in ("amplitude", "poincare_u"):
        np.testing.assert_array_equal(sweep[v].values, alone[v].values)
    assert list(sweep["sweep"].values) == list(alone["sweep"].values)
    np.testing.assert_array_equal(sweep["omega"].values, alone["omega"].values)
    art = draw(ds, "continuation")
    labels = {line.get_label() for line in art.axes[0].get_lines()}
    assert "simulation, sweep up" in labels and "simulation, sweep down" in labels
    # the main result is unchanged by what is attached to it
    assert set(detach(ds).data_vars) == {k for k in ds.data_vars if not str(k).startswith("sweep__")}


def _synthetic():
    """Datasets of the kinds no command writes (report and stability studies)."""
    om = np.array([0.8, 1.0, 1.2])
    model = json.dumps({"omega": 1.0, "D": 1.0, "xi0": 0.1, "fp": 0.2, "kappa1": 0.2})
    comp = xr.Dataset(
        {
            "xi0_critical": ("omega", [0.05, 0.12, 0.08]),
            "bifurcation_type": ("omega", ["period-doubling", "fold", "stable"]),
            "xi0_critical_linear": ("omega", [0.02, 0.1, 0.04]),
            "xi0_paper": 0.4899,
        },
        coords={"omega": om},
        attrs={"geardyn_kind": "stability_comparison", "model": model},
    )
    mathieu = xr.Dataset(
        {"xi0_critical": ("omega", [0.02, 0.1, 0.04])},
        coords={"omega": om},
        attrs={"geardyn_kind": "mathieu_boundary", "model": model},
    )
    boundary = comp[["xi0_critical", "bifurcation_type"]].assign_attrs(geardyn_kind="stability_boundary")
    fit = xr.Dataset(
        {
            "omega": ("p", np.tile(om, 2)),
            "xi0": ("p", [0.1] * 6),
            "b_mm": ("p", [0.2] * 3 + [0.7] * 3),
            "amplitude": ("p", [0.5, 0.9, 0.6, 0.55, 0.95, 0.65]),
        },
        attrs={"geardyn_kind": "formula_fit", "A0": 0.6, "dA": 0.3, "beta": 0.1, "r2": 0.9},
    )
    readings = xr.Dataset(
        {"hold_fraction": (("claim", "omega"), [[0.2, 1.0, 0.5], [0.0, 0.5, 1.0]])},
        coords={"claim": ["T2-1", "T3-2"], "omega": [0.9, 1.0, 1.1]},
        attrs={"geardyn_kind": "readings_map", "default_omega": 1.0},
    )
    search = xr.Dataset(
        {"match_fraction": (("omega", "claim"), [[0.2, 1.0], [0.5, np.nan], [0.9, 0.0]])},
        coords={"omega": om, "claim": ["T2-1", "T2-2"]},
        attrs={"geardyn_kind": "search", "param": "xi1"},
    )
    from test_reproduce_figures import overlay

    return {
        "stability_comparison": comp,
        "mathieu_boundary": mathieu,
        "stability_boundary": boundary,
        "formula_fit": fit,
        "search": search,
        "readings_map": readings,
        "response_overlay": overlay(),
        **_tooth_synthetic(),
        **_rattle_synthetic(),
    }


def _rattle_synthetic():
    """Short ``rattle`` and ``rattle_map`` results of a pair driven by a torque order (geardyn.analysis.rattle)."""
    from geardyn.analysis.rattle import rattle, rattle_map
    from geardyn.model import GearModel, IntegrationOptions

    m = GearModel(omega=0.5, xi0=0.02, xi=(), eps=(), fp=0.002, torque_orders=(("1/4", 0.02, 0.0),))
    opts = IntegrationOptions(dtau=0.05, transient=2, periods=1, accurate=True)
    return {"rattle": rattle(m, opts).to_dataset(), "rattle_map": rattle_map(m, [0.4, 0.5], [0.5, 1.0], opts)}


def _tooth_synthetic():
    """A small ``stiffness`` result and synthetic ``signature`` / ``signature_sweep`` results."""
    from geardyn.signature.run import INDICATORS
    from geardyn.tooth import Crack, mesh_stiffness, pair_geometry
    from geardyn.tooth.result import stiffness_dataset, stiffness_summary

    ms = mesh_stiffness(pair_geometry(20, 40, 0.003), 100.0, faults=[Crack(0, 0, 0.5)], points=8)
    stiff = stiffness_dataset(ms, stiffness_summary(ms))
    n, order = np.arange(64), np.arange(100) / 2.0
    ind = {k: 1.0 + i for i, k in enumerate(INDICATORS)}
    run = {"z1": 20, "z2": 40, "indicators": {"pinion": ind, "wheel": ind}}
    sig = xr.Dataset(
        {
            "accel": (("run", "time"), np.sin(n)[None]),
            "tach": (("run", "time"), (n % 16 == 0)[None] * 5.0),
            "order_amplitude": (("run", "order"), (1e-3 + (order % 20 == 0))[None]),
            **{
                v: (("run", "angle_pinion"), np.cos(n)[None])
                for v in ("tsa_pinion", "regular", "residual", "difference")
            },
        },
        coords={"run": ["a"], "time": n / 1e3, "order": order, "angle_pinion": n * 360 / 64},
        attrs={"geardyn_kind": "signature", "summary": json.dumps({"runs": [run]})},
    )
    sweep = xr.Dataset(
        {k: (("size", "shaft"), [[1.0, 1.0], [2.0, 1.5]]) for k in INDICATORS},
        coords={"size": [0.0, 0.5], "shaft": ["pinion", "wheel"]},
        attrs={"geardyn_kind": "signature_sweep"},
    )
    pts, lv = np.arange(7), np.array([0.5, 1.0])
    c = 30.0 + 5.0 * pts
    fe = xr.Dataset(
        {
            "radius": (("tooth", "point"), [28.0 + pts]),
            "compliance_geardyn": (("tooth", "point"), [c]),
            "compliance_fe": (("tooth", "point"), [1.02 * c]),
            "compliance_fe_level": (("tooth", "level", "point"), [[1.01 * c, 1.02 * c]]),
            "crack_ratio_geardyn": (("crack", "point"), [1.0 + 0.01 * pts]),
            "crack_ratio_fe": (("crack", "point"), [1.0 + 0.012 * pts]),
        },
        coords={"tooth": ["a pinion"], "point": pts, "level": lv, "crack": ["a 25 %"]},
        attrs={"geardyn_kind": "tooth_fe", "summary": "{}"},
    )
    return {"stiffness": stiff, "signature": sig, "signature_sweep": sweep, "tooth_fe": fe}


def test_every_registered_figure_takes_ax_and_returns_its_artists(runs):
    datasets = {k: read_netcdf(d / f"{_file_stem(k)}.nc") for k, (d, _) in runs.items()} | _synthetic()
    old = Path(__file__).resolve().parent / "data" / "system_kinds"  # the system_* kinds earlier versions wrote
    datasets |= {f"earlier_{f.stem}": read_netcdf(f) for f in old.glob("system_*.nc")}
    assert set(FIGURES) <= set(datasets), "a registered kind without a test Dataset"
    mp, bif = datasets["map"], datasets["bifurcation"]
    variants = [mp.assign(lle=mp["amplitude"] * 0 + 0.01)]  # a map with exponents computed
    rpm = [float(x) for x in datasets["response"]["rpm"].values]
    iso_kv = {
        "rpm": rpm,
        "K_v": [1.1] * len(rpm),
        "resonance_speed_rpm": rpm[1],
        "torque_N_m": 1000.0,
        "sector_bounds_rpm": {
            "subcritical_end": 0.75 * rpm[1],
            "main_resonance_end": 1.25 * rpm[1],
            "supercritical_start": 1.5 * rpm[1],
        },
        "model_resonance_rpm": rpm[1],
        "simulated": {"up": [1.2] * len(rpm), "down": [1.3] * len(rpm)},
    }
    variants.append(datasets["response"].assign_attrs(iso_kv=json.dumps(iso_kv)))  # a pair with ISO inputs
    sig = json.loads(datasets["signature"].attrs["summary"])  # a system's signature: its runs name a sensor
    sig["runs"][0].update(sensor="pinion.y", mesh="mesh")
    variants.append(datasets["signature"].assign_attrs(summary=json.dumps(sig)))
    for drop in (["amplitude_um"], ["amplitude_um", "rms_um"], ["amplitude_um", "rms_um", "u_max_um"]):
        variants.append(bif.drop_vars(drop))  # the next variable drawn against rpm
    for k in ("system_bifurcation", "system_response"):  # a system of two meshes: its per-element variables
        one = datasets[k]
        two = xr.concat([one["u_min"], one["u_max"]], dim="element").transpose(*one["u_min"].dims, "element")
        sysinfo = json.loads(one.attrs["system"])
        sysinfo["elements"] = [{"name": n, "kind": "mesh", "gap": 1.0} for n in ("m1", "m2")]
        variants.append(
            one.assign(element_u_min=two - 1.0, element_u_max=two + 1.0)
            .assign_coords(element=["m1", "m2"])
            .assign_attrs(system=json.dumps(sysinfo))
        )
    one = datasets["system_simulate"]  # a system of two elements: their deflections beside the time history
    sysinfo = json.loads(one.attrs["system"])
    sysinfo["elements"] = [{"name": n, "kind": "mesh", "gap": 1.0} for n in ("m1", "m2")]
    per_element = [v for v in one.data_vars if "element" in one[v].dims]
    variants.append(
        one.drop_dims("element")
        .assign({v: xr.concat([one[v], 0.5 * one[v]], dim="element").transpose(*one[v].dims) for v in per_element})
        .assign_coords(element=["m1", "m2"])
        .assign_attrs(system=json.dumps(sysinfo))
    )
    checked = set()
    for ds in list(datasets.values()) + variants:
        for spec in figures_for(ds):
            p = inspect.signature(spec.draw).parameters
            assert "ax" in p and p["ax"].default is None, spec
            fig = new_figure()
            ax = fig.add_subplot()
            art = spec(ds, ax=ax)
            assert isinstance(art, PlotArtists) and art.figure is fig and art.axes[0] is ax, spec.stem
            assert art.artists and all(isinstance(a, Artist) for a in art.artists), spec.stem
            alone = spec(ds)  # without ax: a figure of its own
            assert isinstance(alone, PlotArtists) and alone.figure is not fig and alone.artists
            checked.add(id(spec))
    every = {id(s) for specs in FIGURES.values() for s in specs} | {id(s) for s in PHYSICAL_FIGURES}
    unchecked = [s.stem for specs in list(FIGURES.values()) + [PHYSICAL_FIGURES] for s in specs if id(s) not in checked]
    assert checked == every, f"figures not drawn by the test: {unchecked}"


def test_multi_panel_figures_take_one_axes_per_panel(runs):
    ds = read_netcdf(runs["simulate"][0] / "simulate.nc")
    fig = new_figure()
    axes = fig.subplots(2, 1)
    art = draw(ds, "physical_time_history", ax=axes)
    assert art.axes == list(axes) and axes[1].get_ylabel().endswith("[kN]")
    with pytest.raises(PlotError, match="2 panels"):
        draw(ds, "physical_time_history", ax=list(fig.subplots(1, 3)))
    with pytest.raises(PlotError, match="not a figure"):
        draw(ds, "basins")


def test_svg_and_other_formats_without_a_display(runs, tmp_path):
    ds = read_netcdf(runs["lyapunov"][0] / "lyapunov.nc")
    (path,) = save_figures(ds, tmp_path, fmt="svg")
    assert path.name == "lyapunov.svg" and path.read_text().lstrip().startswith("<?xml")


def test_no_backend_is_forced_at_import():
    code = "import geardyn.plot, geardyn.plot.registry, matplotlib; print(matplotlib.get_backend())"
    env = dict(os.environ, MPLBACKEND="svg")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    assert out.strip() == "svg"
    code = "import sys, geardyn.plot; import xarray as xr; print('matplotlib.pyplot' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    assert out.strip() == "False"


_META = ("units", "long_name", "flag_values", "flag_meanings")


@pytest.mark.parametrize("name", list(COMMANDS))
def test_variable_registry_gives_every_variable_its_metadata(runs, name):
    """Stripped of its metadata, every command's Dataset gets it back from the registry alone."""
    for f in runs[name][0].glob("*.nc"):
        ds = read_netcdf(f)
        bare = ds.copy()
        for v in bare.variables:
            bare[v].attrs = {k: x for k, x in bare[v].attrs.items() if k not in _META}
        annotate(bare)
        for v in ds.variables:
            old, new = ds[v].attrs, bare[v].attrs
            if str(v).endswith("_um") and old.get("long_name", "").startswith(str(v)[:-3]):
                continue  # a copy in µm named after its variable before that had a long name
            for k in _META:
                if k in old:
                    assert np.array_equal(np.asarray(new.get(k)), np.asarray(old[k])), (f.name, v, k, new.get(k))
            assert "units" in new and "long_name" in new, (f.name, v)


def test_parameters_without_an_entry_are_named_by_rule():
    # names from the parameter registry (a number, not text: Variable.text marks the variables that hold names)
    assert variable("phi_e1") == ("rad", "phase of STE harmonic 1", None, False)
    assert variable("kappa1").long_name == "stiffness harmonic κ_1"
    assert variable("xi1", "continuation").long_name == "damping harmonic ξ_1"
    assert variable("bifurcation_xi0", "continuation").long_name == "parameter xi0 at the bifurcation"
    assert variable("status").flags == {0: "ok", 1: "diverged", 2: "not converged", 3: "unresolved"}
    assert variable("no_such_variable") is None


def test_summary_json_holds_the_common_part_of_the_json_outputs(runs):
    from geardyn.analysis.bifurcation import bifurcation_json
    from geardyn.analysis.maps import map_json

    bif = read_netcdf(runs["bifurcation"][0] / "bifurcation.nc")
    s = summary_json(bif, ["period", "motion", "impact", "lle", "amplitude", "status"])
    assert s["kind"] == "bifurcation" and s["model"]["omega"] == pytest.approx(1.0) and s["options"]["transient"] == 20
    assert s["status"] == {"ok": 4} and s["coords"]["omega"] == bifurcation_json(bif)["values"]
    ref = bifurcation_json(bif)
    for k, v in s["points"].items():
        assert v[0] == ref[k], k  # one sweep: the lists of `bifurcation --json`
    mp = read_netcdf(runs["map"][0] / "map.nc")
    ref = map_json(mp)
    s = summary_json(mp, ["motion", "impact", "period", "amplitude", "lle"])
    for k, v in s["points"].items():
        assert v == ref[k], k
    assert sum(s["status"].values()) == mp["status"].size


def test_attach_round_trip_through_a_file(tmp_path):
    main = xr.Dataset({"a": ("x", [1.0, 2.0])}, coords={"x": [0, 1]}, attrs={"geardyn_kind": "simulate", "k": "v"})
    ctx = xr.Dataset(
        {"amplitude": (("sweep", "omega"), [[1.0, 2.0, 3.0]])},
        coords={"sweep": ["up"], "omega": [0.5, 1.0, 1.5]},
        attrs={"geardyn_kind": "bifurcation"},
    )
    both = attach(main, "brute", ctx)
    f = write_netcdf(both, tmp_path / "both.nc")
    back = read_netcdf(f)
    got = attached(back, "brute")
    xr.testing.assert_equal(got, annotate(ctx.copy()))
    assert got.attrs == ctx.attrs and back["brute__amplitude"].attrs["long_name"] == "half peak-to-peak displacement"
    assert attached(back, "other") is None
    xr.testing.assert_equal(detach(back), main)
    with pytest.raises(ValueError):
        attach(main, "a__b", ctx)


def test_time_history_draws_the_poincare_section_once_a_forcing_period():
    """A half-order torque order makes the forcing repeat after P = 2 mesh cycles: the Poincaré section (the
    red lines) is taken once every 2·2π/ω, not at every mesh period of the window (it was drawn at every one)."""
    from fractions import Fraction

    import matplotlib.pyplot as plt

    from geardyn import GearModel, simulate
    from geardyn.model import IntegrationOptions
    from geardyn.plot.simulate import TIME_PERIODS_SHOWN, time_history

    model = GearModel(omega=0.8, torque_orders=((Fraction(1, 2), 0.05, 0.0),))
    assert model.period_multiple() == 2
    ds = simulate(model, IntegrationOptions(transient=4, periods=6), classify=False).to_dataset()
    fig, ax = plt.subplots()
    try:
        time_history(ds, ax=ax)
        xs = sorted(line.get_xdata()[0] for line in ax.lines if line.get_color() == "C3")
    finally:
        plt.close(fig)
    Tf = 2 * 2 * np.pi / 0.8
    assert len(xs) == TIME_PERIODS_SHOWN // 2 + 1
    assert np.allclose(np.diff(xs), Tf, rtol=1e-12)
    assert xs[-1] == pytest.approx(float(ds["tau"][-1]), rel=1e-15)


def test_signature_figure_names_a_systems_sensor_on_its_acceleration_axis():
    """A system's record is that of a bearing sensor, not the pair's relative acceleration along the line of
    action; its axis said the line of action for a sensor too."""
    import matplotlib.pyplot as plt

    from geardyn.plot.registry import draw

    pair = _tooth_synthetic()["signature"]
    summary = json.loads(pair.attrs["summary"])
    summary["runs"][0].update(sensor="in_A.x", mesh="stage1")
    system = pair.assign_attrs(summary=json.dumps(summary))
    labels = {}
    for name, ds in (("pair", pair), ("system", system)):
        fig, axes = plt.subplots(4, 1)
        try:
            draw(ds, "signature", ax=axes)
            labels[name] = axes[0].get_ylabel()
        finally:
            plt.close(fig)
    assert labels == {"pair": "relative accel. along LoA [m/s²]", "system": "accel. of in_A.x [m/s²]"}
