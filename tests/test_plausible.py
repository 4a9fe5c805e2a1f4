"""Physical plausibility at every door: impossible input is refused with one line naming the key and its bound.

One test per finding of the hostile round (bevel geometry, excitation tables, result files, physical values
of a non-dimensional run, the contact force); the bounds are those of ``geardyn.plausible``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from cli_run import run_cli

from geardyn import plausible
from geardyn.config import packaged_config_path
from geardyn.errors import ConfigError, ModelError
from geardyn.geometry import SpiralBevelGearPair
from geardyn.geometry.summary import geometry_summary

DEG = math.pi / 180
PAPER = packaged_config_path().read_text()


def table1(**changes):
    kw = dict(
        z1=23,
        z2=47,
        m_mn=7.28e-3,
        beta_m=35 * DEG,
        alpha_n=20 * DEG,
        j_n=0.1e-3,
        I1=1.772,
        I2=1.873,
        r1=0.1255,
        r2=0.256,
        face_width=0.1,
    )
    kw.update(changes)
    return SpiralBevelGearPair(**kw)


def one_line_exit_2(code: int, err: str, *words: str) -> None:
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for w in words:
        assert w in lines[0], (w, err)


# ------------------------------------------------------------------------------------------ bevel geometry
@pytest.mark.parametrize(
    "change,key,bound",
    [
        (dict(alpha_n=89.9 * DEG), "alpha_n", "[10, 40] deg"),
        (dict(alpha_n=5 * DEG), "alpha_n", "[10, 40] deg"),
        (dict(beta_m=85 * DEG), "beta_m", "70 deg"),
        (dict(r2=0.1255), "r2", "z2/z1"),  # r2/r1 = 1 for a 23/47 pair
        (dict(r2=0.3), "r2", "z2/z1"),  # r2/r1 = 2.39 > 47/23 (1.05 tolerance)
        (dict(j_n=5.0), "j_n", "0.5 x the module"),
        (dict(face_width=50.0), "face_width", "outer cone distance"),
        (dict(m_mn=7.28, r1=None, r2=None, face_width=None), "m_mn", "mm"),
        (dict(r1=0.01, r2=0.0204), "r1", "mean pitch radius"),
    ],
)
def test_implausible_bevel_geometry_is_refused(change, key, bound):
    with pytest.raises(ModelError) as e:
        table1(**change)
    msg = str(e.value)
    assert msg.startswith(f"{key}:") and bound in msg and "\n" not in msg


def test_the_paper_pair_and_a_hypoid_pass():
    table1()
    # a hypoid's pitch radii are in the ratio z2/z1 times cos β_m1/cos β_m2 (ISO/TR 10300-30 sample 2: 13/42,
    # β_m1 = 50°, β_m2 = 38.61°): inside the rule's band
    q = math.cos(50 * DEG) / math.cos(38.61 * DEG)
    r1 = 2.64e-3 * 13 / (2 * math.cos(50 * DEG))
    SpiralBevelGearPair(
        z1=13, z2=42, m_mn=2.64e-3, beta_m=50 * DEG, alpha_n=20 * DEG, j_n=1e-4, I1=1, I2=1, r1=r1, r2=r1 * 42 / 13 * q
    )


def test_an_undercut_pinion_gets_a_note():
    """A 5-tooth spiral bevel pinion (5/47, β_m = 35°, α_n = 20°): z_vn = 5/(cos δ1 cos³β_m) ≈ 9.2 is below the
    undercut limit 2/sin²20° ≈ 17.1 of full-depth teeth."""
    p = table1(z1=5, r1=None, r2=None, face_width=None)
    zvn = 5 / (math.cos(math.atan(5 / 47)) * math.cos(35 * DEG) ** 3)
    assert zvn == pytest.approx(9.15, abs=0.01) and 2 / math.sin(20 * DEG) ** 2 == pytest.approx(17.1, abs=0.01)
    notes = geometry_summary(p)["notes"]
    assert any("undercut" in n and "9.15" in n for n in notes)
    assert not any("undercut" in n for n in geometry_summary(table1())["notes"])


@pytest.mark.parametrize(
    "old,new,key",
    [
        ('alpha_n = "20 deg"', 'alpha_n = "89.9 deg"', "alpha_n"),
        ('r2 = "256 mm"', 'r2 = "125.5 mm"', "r2"),
        ('j_n = "0.1 mm"', 'j_n = "5 m"', "j_n"),
        ('value = "100 mm"', 'value = "50 m"', "face_width"),
    ],
)
def test_geometry_command_refuses_in_one_line(tmp_path, old, new, key):
    cfg = tmp_path / "c.toml"
    assert old in PAPER
    cfg.write_text(PAPER.replace(old, new))
    code, out, err = run_cli(["geometry", "--config", cfg])
    one_line_exit_2(code, err, key, str(cfg))


# ------------------------------------------------------------------------------------------ excitation tables
def _csv(path, k, e):
    n = len(k)
    path.write_text(
        "phase_cycles,stiffness_N_per_m,ste_m\n" + "".join(f"{i / n},{k[i]!r},{e[i]!r}\n" for i in range(n))
    )
    return path


@pytest.mark.parametrize(
    "k,e,word",
    [
        (2e9, 1e300, "|STE|"),
        (2e9, 2e-3, "|STE|"),
        (1e20, 1e-6, "stiffness"),
        (1e-3, 1e-6, "stiffness"),
    ],
)
def test_an_excitation_table_outside_the_physical_range_is_refused(tmp_path, k, e, word):
    f = _csv(tmp_path / "t.csv", [k] * 16, [e] * 16)
    code, out, err = run_cli(["simulate", "--excitation", f, "--transient", "2", "--periods", "2"])
    one_line_exit_2(code, err, word, "t.csv")
    from geardyn.tooth.table import read_table

    with pytest.raises(ConfigError, match="t.csv"):
        read_table(f)


def test_an_excitation_table_over_the_size_limit_is_refused_before_reading(tmp_path):
    """A table file of 150 MB (10⁷ rows) is refused from its size, before it is parsed."""
    f = tmp_path / "big.csv"
    with open(f, "wb") as fh:  # a sparse file: its size without writing 150 MB
        fh.write(b"phase_cycles,stiffness_N_per_m,ste_m\n")
        fh.truncate(150_000_000)
    code, out, err = run_cli(["simulate", "--excitation", f])
    one_line_exit_2(code, err, "big.csv", "150.0 MB", "64 MB")
    with pytest.raises(ConfigError):
        plausible.file_size(f, plausible.MAX_TABLE_BYTES, "excitation table")


# ------------------------------------------------------------------------------------------ result files
@pytest.fixture(scope="module")
def simulate_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("sim")
    code, out, err = run_cli(["simulate", "--omega", "0.8", "--transient", "20", "--periods", "8", "--out", d])
    assert code == 0, err
    return d / "simulate.nc"


def test_a_result_variable_turned_to_text_is_refused(simulate_file, tmp_path):
    import xarray as xr

    ds = xr.open_dataset(simulate_file).load()
    ds["u"] = ds["u"].astype(str)
    bad = tmp_path / "bad.nc"
    ds.to_netcdf(bad)
    code, out, err = run_cli(["plot", bad, "--out", tmp_path / "figs"])
    one_line_exit_2(code, err, "'u'", "bad.nc")
    assert not (tmp_path / "figs").exists() or not list((tmp_path / "figs").iterdir())


def test_a_result_variable_of_another_shape_is_refused(simulate_file, tmp_path):
    import xarray as xr

    ds = xr.open_dataset(simulate_file).load()
    ds["v"] = (("tau", "copy"), np.stack([ds["v"].values] * 2, axis=1))
    bad = tmp_path / "bad.nc"
    ds.to_netcdf(bad)
    code, out, err = run_cli(["plot", bad, "--out", tmp_path / "figs"])
    one_line_exit_2(code, err, "'v'", "('tau',)")


# ------------------------------------------------------------------------------------------ physical values
def test_a_non_dimensional_run_reports_no_physical_values(tmp_path):
    cfg = tmp_path / "nd.toml"
    cfg.write_text('title = "non-dimensional"\n[mesh]\nxi0 = 0.1\n')
    code, out, err = run_cli(["simulate", "--config", cfg, "--transient", "20", "--periods", "8", "--json"])
    assert code == 0, err
    d = json.loads(out)
    invented = {"rpm", "torque_N_m", "dte_rms_um", "backlash_um", "mesh_force_max_N", "mesh_force_min_N"}
    assert not invented & set(d), invented & set(d)
    assert d["physical"] is None and d["omega"] == 1.0


def test_the_contact_force_is_not_negative_without_back_flank_contact():
    """ω = 0.8 (paper defaults): single-sided impacts.  The model's mesh force (elastic + viscous) dips below 0
    in separation through its viscous term; the contact force K f(u) is 0 there and never negative."""
    from geardyn.analysis.physical import steady_physical
    from geardyn.analysis.steady import simulate
    from geardyn.model import GearModel

    res = simulate(GearModel(omega=0.8))
    assert res.summary["impact"] == "single-sided impact"
    s = steady_physical(res, None)
    assert s["mesh_force_min_N"] < 0.0
    assert s["contact_force_min_N"] == 0.0  # separation: no contact force
    assert 0.0 < s["contact_force_max_N"] <= s["mesh_force_max_N"] * 1.5
    # with back-flank contact the contact force does go negative (D = 0.3 at ω = 0.8)
    res = simulate(GearModel(omega=0.8, D=0.3))
    assert res.summary["impact"] == "double-sided impact"
    assert steady_physical(res, None)["contact_force_min_N"] < 0.0


# ------------------------------------------------------------------------------------------ budgets
def test_a_modal_analysis_over_its_memory_budget_is_refused_before_it_runs(monkeypatch):
    """The estimate is (E + 3) n² 8 bytes of dense matrices plus n² report entries of 100 bytes: for the 8-DOF
    bevel pair (n = 8, E = 3 elements) 6·64·8 + 6400 = 9472 bytes; a budget below it refuses the run in one
    line with the estimate (a 1000-body system, 4000 DOFs, needs 130 GB against the 2 GB budget)."""
    from pathlib import Path

    from geardyn.systems import load_description, modes

    desc = load_description(Path(__file__).parents[1] / "examples" / "systems" / "paper_bevel_8dof.toml")
    assert len(desc.labels) == 8
    n, e = 8, len(desc.connections) + len(desc.meshes) + len(desc.clearances)
    assert modes.modes_budget(desc) == (e + 3) * n * n * 8.0 + n * n * 100.0
    monkeypatch.setattr(modes, "MODES_MEMORY_BUDGET", 1000.0)
    with pytest.raises(ModelError, match=r"^system: a modal analysis of 8 DOFs .* would need .* above the budget"):
        modes.modal_analysis(desc)
    assert (4 * 1000) ** 2 * (1001 + 3) * 8 > 2e9 * 60  # the 1000-body case is refused by a wide margin


# ------------------------------------------------------------------------------------------ the Python API
@pytest.mark.parametrize(
    "call",
    [
        lambda g: g.simulate(None),
        lambda g: g.lyapunov_spectrum("omega"),
        lambda g: g.bifurcation(None, "omega", [1.0]),
        lambda g: g.shoot(3, 1),
        lambda g: g.trajectory(None, (0.0, 0.0)),
        lambda g: g.period_map({}, (0.0, 0.0)),
        lambda g: g.integrate_batch([None]),
        lambda g: g.integrate_batch([]),
    ],
)
def test_public_functions_refuse_a_model_that_is_no_system_in_one_line(call):
    import geardyn

    with pytest.raises(ModelError, match=r"^models?: expected "):
        call(geardyn)


# ------------------------------------------------------------------------------------------ help screens
def test_help_descriptions_are_reflowed_and_arguments_named_in_capitals():
    code, out, err = run_cli(["--help"])
    assert code == 0
    # the simulate line of the listing: its source breaks after "amplitudes)," are joined, so the terminal
    # wraps the text as a whole (no line ending right after the comma with the next words on a short line)
    from geardyn.cli.app import _reflowed

    assert _reflowed("a b,\nc d\n\n e\nf ") == "a b, c d\n\ne f"
    code, out, err = run_cli(["te", "--help"])
    assert code == 0 and "Usage: geardyn te [OPTIONS] FILE" in out and "{file}" not in out


def test_gitignore_ignores_virtual_environments():
    from pathlib import Path

    lines = (Path(__file__).parents[1] / ".gitignore").read_text().split()
    assert ".venv/" in lines and "venv/" in lines


# ------------------------------------------------------------------------------------------ uniform sweep options
@pytest.mark.parametrize(
    "argv",
    [
        ["response", "--param", "omega", "--start", "0.9", "--stop", "1.0", "--num", "3"],
        ["response", "--omega-start", "0.9", "--omega-stop", "1.0", "--num", "3"],
        ["bifurcation", "--omega-start", "0.9", "--omega-stop", "1.0", "--num", "3"],
        ["bifurcation", "--param", "omega", "--start", "0.9", "--stop", "1.0", "--num", "3"],
    ],
)
def test_every_sweep_command_accepts_both_spellings_of_its_range(argv):
    code, out, err = run_cli([*argv, "--transient", "20", "--periods", "10", "--json"])
    assert code == 0, err
    d = json.loads(out)
    assert min(d.get("values") or d.get("omega") or [0.9]) == pytest.approx(0.9)


@pytest.mark.parametrize(
    "argv,key",
    [
        (["response", "--param", "xi0", "--start", "0.1", "--stop", "0.2"], "param"),
        (["bifurcation", "--omega-start", "0.9", "--omega-stop", "1", "--start", "1", "--stop", "2"], "omega_start"),
        (["bifurcation", "--param", "xi0", "--omega-start", "0.9", "--omega-stop", "1"], "param"),
        (["continuation", "--omega-start", "0.9", "--stop", "1"], "omega_start"),
    ],
)
def test_mixed_or_wrong_spellings_are_refused(argv, key):
    code, out, err = run_cli(argv)
    one_line_exit_2(code, err, key)


# ------------------------------------------------------------------------------------------ figures
def test_a_sweep_of_separate_settings_is_drawn_as_separate_cells_and_markers():
    """Table 3's three backlash values are separate settings: no band or line joins them (the bands are cells
    with gaps, λ1 markers with ±3σ bars, the contact boundaries a mark at each D); a dense grid keeps its bands."""
    import matplotlib.collections as mc

    import geardyn
    from geardyn.model import IntegrationOptions
    from geardyn.plot.bifurcation import is_discrete
    from geardyn.plot.registry import draw

    assert is_discrete(np.array([0.1, 0.35, 0.75])) and not is_discrete(np.linspace(0.5, 1.5, 101))
    ds = geardyn.bifurcation(
        geardyn.GearModel(), "D", [0.1, 0.35, 0.75], lyapunov=True, options=IntegrationOptions(transient=50, periods=20)
    )
    art = draw(ds, "bifurcation")
    fig = art.figure if hasattr(art, "figure") else art.fig
    axes = fig.axes
    assert not any(isinstance(c, mc.QuadMesh) for a in axes for c in a.collections)  # no continuous band
    assert not any(isinstance(c, mc.PolyCollection) for a in axes for c in a.collections)  # no filled σ band
    contact = [ln for ln in axes[0].lines if ln.get_gid() == "contact"]
    assert contact and all(ln.get_linestyle() in ("None", "none", "") for ln in contact)


def test_a_rescaled_figure_names_its_pair_and_a_fixed_sweep_has_no_legend():
    from pathlib import Path

    import geardyn
    from geardyn.analysis.physical import add_physical
    from geardyn.model import IntegrationOptions
    from geardyn.plot.registry import draw, figures_for
    from geardyn.units import scales_of

    cfg = Path(__file__).parents[1] / "examples" / "automotive_hypoid_like.toml"
    ds = geardyn.bifurcation(
        geardyn.GearModel(), "omega", np.linspace(0.8, 1.0, 15), options=IntegrationOptions(transient=20, periods=10)
    )
    sc = scales_of(cfg)
    phys = add_physical(ds, sc)
    stem = next(f.stem for f in figures_for(phys) if "rpm" in f.stem)
    art = draw(phys, stem)
    fig = art.figure if hasattr(art, "figure") else art.fig
    ax = fig.axes[0]
    assert sc.title and sc.title in ax.get_title()
    assert ax.get_legend() is None  # one fixed sweep: no "sweep = fixed" legend


def test_a_system_file_too_large_for_a_modal_analysis_is_refused_before_it_is_loaded(tmp_path):
    """A 1000-body file (4 DOFs each, a bearing each, one mesh): (1001 + 3)·4000²·8 + 4000²·100 bytes = 130 GB
    against the 2 GB budget, refused from the file's own tables in one line (before 1000 bodies are built)."""
    body = '[[body]]\nname = "b{i}"\ndofs = ["x", "y", "z", "theta"]\nmass = "50 kg"\ninertia = "1 kg*m^2"\n\n'
    conn = '[[connection]]\nname = "c{i}"\nbody = "b{i}"\nkx = "1e9 N/m"\n\n'
    f = tmp_path / "big.toml"
    f.write_text("".join(body.format(i=i) + conn.format(i=i) for i in range(1000)) + '[[mesh]]\nname = "m"\n')
    code, out, err = run_cli(["modes", "--system", f])
    one_line_exit_2(code, err, "system:", "4000 DOFs", "1001 elements", "130 GB", "2 GB")
