"""``--system`` on the commands and ``geardyn modes``: JSON contracts and the exact reduction from the command line."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from cli_run import run_cli

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
TORS = str(EX / "paper_torsional.toml")
BEVEL = str(EX / "paper_bevel_8dof.toml")


def run(*args: str, code: int = 0) -> subprocess.CompletedProcess:
    """``geardyn ARGS`` run in this process (the kernels compile or load once for the whole file)."""
    p = subprocess.CompletedProcess(["geardyn", *args], *run_cli(args))
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
    assert set(b) - {
        "pair",
        "assumed",
        "spectrum_peaks",
        "history_periods",
        "fp",
        "torque_N_m",
        "backlash_um",
        "dte_mean_um",
        "dte_rms_um",
        "mesh_force_mean_N",
    } <= set(a)
    for k in ("mesh_force_max_N", "contact_force_max_N", "contact_force_min_N"):  # the same pair's forces in N
        assert m[k] == a[k]
        assert a[k] == pytest.approx(b[k], rel=1e-6, abs=1e-6)
    for e in a["meshes"]:
        assert {"name", "u_min", "u_max", "amplitude", "impact", "dynamic_factor"} <= set(e)


def test_lyapunov_and_orbit_system_json():
    ly = json.loads(
        run("lyapunov", "--system", BEVEL, "--omega", "0.8", "--periods", "100", "--transient", "50", "--json").stdout
    )
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
    p = run(
        "map",
        "--system",
        TORS,
        "--x",
        "omega",
        "--y",
        "mesh.xi0",
        "--x-start",
        "0.7",
        "--x-stop",
        "0.9",
        "--y-start",
        "0.05",
        "--y-stop",
        "0.1",
        "--mode",
        "sideways",
        "--json",
        code=2,
    )
    assert "mode" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    p = run("simulate", "--system", TORS, "--fp", "0.3", code=2)
    assert "system" in p.stderr and len(p.stderr.strip().splitlines()) == 1


def test_bifurcation_and_response_on_a_system():
    b = json.loads(
        run(
            "bifurcation",
            "--system",
            TORS,
            "--param",
            "omega",
            "--start",
            "0.6",
            "--stop",
            "1.0",
            "--num",
            "5",
            "--transient",
            "50",
            "--periods",
            "32",
            "--json",
        ).stdout
    )
    assert b["values"] == pytest.approx([0.6, 0.7, 0.8, 0.9, 1.0]) and len(b["period"]) == 5
    assert b["meshes"][0]["name"] == "mesh" and len(b["meshes"][0]["amplitude"]) == 5
    r = json.loads(
        run(
            "response",
            "--system",
            TORS,
            "--omega-start",
            "0.6",
            "--omega-stop",
            "1.0",
            "--num",
            "5",
            "--transient",
            "50",
            "--periods",
            "32",
            "--json",
        ).stdout
    )
    pair = json.loads(
        run(
            "response",
            "--omega-start",
            "0.6",
            "--omega-stop",
            "1.0",
            "--num",
            "5",
            "--transient",
            "50",
            "--periods",
            "32",
            "--json",
        ).stdout
    )
    assert {"up", "down", "jumps", "hysteresis", "coexistence", "meshes"} <= set(r)
    assert set(r) - {"meshes", "note"} <= set(pair)


OUT_RUNS = {
    "simulate": ["simulate", "--system", TORS, "--omega", "0.8", "--transient", "300", "--periods", "8"],
    "lyapunov": ["lyapunov", "--system", TORS, "--omega", "0.8", "--transient", "20", "--periods", "40"],
    "orbit": ["orbit", "--system", TORS, "--omega", "0.8"],
    "bifurcation": [
        "bifurcation",
        "--system",
        TORS,
        "--param",
        "omega",
        "--start",
        "0.7",
        "--stop",
        "0.9",
        "--num",
        "3",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "response": [
        "response",
        "--system",
        TORS,
        "--omega-start",
        "0.7",
        "--omega-stop",
        "0.9",
        "--num",
        "3",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "map": [
        "map",
        "--system",
        TORS,
        "--x",
        "omega",
        "--y",
        "mesh.xi0",
        "--x-start",
        "0.7",
        "--x-stop",
        "0.9",
        "--x-num",
        "2",
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
    "basins": [
        "basins",
        "--system",
        TORS,
        "--omega",
        "0.8",
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
    ],
    "continuation": [
        "continuation",
        "--system",
        TORS,
        "--param",
        "omega",
        "--start",
        "1.3",
        "--stop",
        "1.35",
        "--sweep-num",
        "2",
        "--ds-max",
        "0.1",
        "--transient",
        "20",
    ],
}


@pytest.mark.parametrize("kind", ["bifurcation", "response", "map", "basins", "continuation", "orbit", "simulate"])
def test_tables_of_a_system_run_without_json(kind, tmp_path):
    """Without --json every system command prints the pair's tables (in rpm and µm where the pair's are) after the
    table of its meshes: each mesh's half backlash and DTE in µm, and no dynamic-factor column where the command
    computes none (issue 23 item 6: no "dynamic factor —"); a response prints its jump table."""
    p = run(*OUT_RUNS[kind], "--out", str(tmp_path))
    pair = {
        "bifurcation": "Motion over omega",
        "response": "Jumps",
        "map": "map of mesh.xi0 × omega",
        "basins": "Attractors at ω = 0.8",
        "continuation": "Branches in omega from 1.3 to 1.35",
        "orbit": "Period-1 orbit at ω = 0.8",
        "simulate": "Steady response at ω = 0.8",
    }[kind]
    out = " ".join(p.stdout.split())
    assert pair in out and "1 mesh(es) of the system" in out and "wrote " in out
    assert "—" not in out
    assert "backlash" in out
    assert "DTE" in out and "(µm)" in out
    if kind in ("simulate", "orbit"):  # one point with its history: forces and the dynamic factor
        assert "dynamic factor" in out and "pinion speed (rpm)" in out
    else:
        assert "dynamic factor" not in out


@pytest.mark.slow  # the same events, with switching, at 1e-8: test_conformance.py (system continuation)
def test_continuation_on_a_system_finds_the_1dof_period_doubling():
    a = json.loads(
        run(
            "continuation",
            "--system",
            TORS,
            "--param",
            "omega",
            "--start",
            "0.6",
            "--stop",
            "1.0",
            "--no-switch",
            "--json",
        ).stdout
    )
    b = json.loads(
        run("continuation", "--param", "omega", "--start", "0.6", "--stop", "1.0", "--no-switch", "--json").stdout
    )
    pa = [x["omega"] for x in a["bifurcations"] if x["type"] == "period-doubling"]
    pb = [x["omega"] for x in b["bifurcations"] if x["type"] == "period-doubling"]
    assert len(pa) == len(pb) == 1 and pa[0] == pytest.approx(pb[0], abs=1e-8)
    assert a["rigid_body_modes"] == 1 and len(a["branch"][0]["multipliers"]) == 2


def test_response_hysteresis_on_a_system_matches_1dof():
    args = [
        "--omega-start",
        "0.6",
        "--omega-stop",
        "1.0",
        "--num",
        "9",
        "--transient",
        "300",
        "--periods",
        "32",
        "--json",
    ]
    a = json.loads(run("response", "--system", TORS, *args).stdout)
    b = json.loads(run("response", *args).stdout)
    assert a["hysteresis"] == b["hysteresis"]
    assert [j["omega"] for j in a["jumps"]] == [j["omega"] for j in b["jumps"]]


def test_incommensurate_meshes_refuse_continuation_in_one_line():
    import math
    from dataclasses import replace

    from geardyn.analysis.periodic import continuation as system_continuation
    from geardyn.errors import ModelError
    from geardyn.systems import load_system

    s = load_system(TORS)
    two = replace(s, meshes=(replace(s.meshes[0], ratio=math.sqrt(2.0)),))
    with pytest.raises(ModelError, match="incommensurate") as e:
        system_continuation(two, "omega", 0.8, 0.9)
    assert "\n" not in str(e.value)


def test_basins_on_a_slice_of_two_coordinates(tmp_path):
    from geardyn.systems import load_system

    lab = load_system(BEVEL).labels
    s = json.loads(
        run(
            "basins",
            "--system",
            BEVEL,
            "--omega",
            "0.8",
            "--coords",
            f"{lab[0]},{lab[0]}'",
            "--u-min",
            "-0.1",
            "--u-max",
            "0.1",
            "--v-min",
            "-0.1",
            "--v-max",
            "0.1",
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
            "--json",
        ).stdout
    )
    assert s["coordinates"] == [lab[0], lab[0] + "'"] and len(s["labels"]) == 2 and s["attractors"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["simulate", "--system", TORS, "--coords", "foo,bar"], "No such option: --coords"),
        (
            ["bifurcation", "--system", TORS, "--coords", "x,y", "--param", "omega", "--start", "0.8", "--stop", "0.9"],
            "No such option: --coords",
        ),
        (["basins", "--coords", "x,y", "--nu", "2", "--nv", "2"], "coords: --coords picks the state coordinates"),
    ],
)
def test_coords_is_an_option_of_a_systems_basins_only(args, message):
    """--coords slices a system's state space for basins: any other command, or the pair's basins, refuses it in
    one line before computing (it used to be accepted and ignored by every --system command)."""
    p = run(*args, code=2)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and message in lines[0], p.stderr


OLD_KINDS = Path(__file__).resolve().parent / "data" / "system_kinds"


OLD_FIGURES = {
    "system_simulate": ["element_deflections.png", "phase_portrait.png"],
    "system_bifurcation": ["bifurcation.png", "mesh_amplitudes.png"],
    "system_response": ["mesh_amplitudes.png", "response.png"],
    "system_lyapunov": ["lyapunov_spectrum.png"],
    "system_orbit": ["multipliers.png"],
    "system_map": ["map_amplitude.png", "map_impact.png", "map_motion.png"],
    "system_basins": ["basins.png"],
    "system_continuation": ["continuation.png"],
}


@pytest.mark.parametrize("kind", list(OLD_FIGURES))
def test_files_of_the_earlier_system_kinds_are_still_redrawn(kind, tmp_path):
    """Files of the ``system_*`` kinds the previous version wrote (``tests/data/system_kinds``, written by it on the
    torsional pair) are read and redrawn by ``geardyn plot``: the figures that version drew."""
    drawn = OLD_FIGURES[kind]
    r = json.loads(run("plot", str(OLD_KINDS / f"{kind}.nc"), "--out", str(tmp_path), "--json").stdout)
    assert sorted(p.rsplit("/", 1)[-1] for p in r["files"]) == drawn
    assert all((tmp_path / f).stat().st_size > 0 for f in drawn)


def test_system_figures_name_the_mesh_and_draw_its_backlash_an_rpm_axis_and_coexistence(tmp_path):
    """Issue 23 item 6 and 2: a system's bifurcation diagram draws u = ±D of its reference mesh, a top axis in
    pinion speed (ω_n 60/(2π z) rpm per unit ω of its reference pinion) and a title naming the mesh; its response
    figure shades the coexistence intervals (hatched) as well as the hysteresis ones."""
    import math

    from geardyn.io import read_netcdf
    from geardyn.plot import draw
    from geardyn.systems import load_system

    s = load_system(TORS)
    run(*OUT_RUNS["response"], "--out", str(tmp_path), "--json")
    ds = read_netcdf(tmp_path / "response.nc")
    art = draw(ds, "response_bifurcation")
    lines = [a for a in art.axes[0].get_lines() if a.get_gid() == "contact"]
    assert sorted(float(line.get_ydata()[0]) for line in lines) == [-s.elements[0].gap, s.elements[0].gap]
    assert "reference mesh 'mesh'" in " ".join(ax.get_title() for ax in art.figure.axes)
    tops = [a for ax in art.figure.axes for a in ax.child_axes]
    assert any(t.get_xlabel() == "pinion speed of mesh 'mesh' [rpm]" for t in tops)
    sec = tops[0]
    per = s.scaling.omega_n_rad_s * 60.0 / (2.0 * math.pi * s.scaling.z1)
    assert sec._functions[0](1.0) == pytest.approx(per, rel=1e-12)
    ds.attrs["coexistence"] = json.dumps([[0.75, 0.85]])
    art = draw(ds, "response")
    hatched = [p for p in art.axes[0].patches if p.get_hatch() == "//"]
    assert len(hatched) == 1
    r = hatched[0]
    assert r.get_x() == pytest.approx(0.75) and r.get_x() + r.get_width() == pytest.approx(0.85)
    assert "coexisting" in art.axes[0].get_title()
