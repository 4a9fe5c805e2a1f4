"""Gearbox files: exact kinematics from the teeth, refusals naming both values, assembly into a system."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from geardyn.errors import ModelError
from geardyn.gearbox.kinematics import forcing_period, solve_speeds
from geardyn.systems import load_description, load_system

ROOT = Path(__file__).resolve().parents[1]

TWO_STAGE = """
title = "two-stage test gearbox"
[operating]
rpm = "1000 rpm"

[[shaft]]
name = "in"
segments = [{{ length = "200 mm", outer = "40 mm" }}]
elements_per_segment = 1

[[shaft]]
name = "mid"
segments = [{{ length = "200 mm", outer = "50 mm" }}]
elements_per_segment = 1

[[shaft]]
name = "out"
segments = [{{ length = "200 mm", outer = "60 mm" }}]
elements_per_segment = 1

[[gear]]
name = "p1"
shaft = "in"
position = "100 mm"
teeth = {z1}
module = "3 mm"
helix_angle = "{beta1}"
hand = "right"
face_width = "30 mm"

[[gear]]
name = "w1"
shaft = "mid"
position = "60 mm"
teeth = {z2}
module = "3 mm"
helix_angle = "{beta1}"
hand = "left"
face_width = "30 mm"

[[gear]]
name = "p2"
shaft = "mid"
position = "140 mm"
teeth = {z3}
module = "4 mm"
face_width = "40 mm"

[[gear]]
name = "w2"
shaft = "out"
position = "100 mm"
teeth = {z4}
module = "4 mm"
face_width = "40 mm"

[[mesh]]
name = "s1"
pinion = "p1"
gear = "w1"
stiffness = "400 N/um"
backlash = "0.1 mm"
{mesh1_extra}

[[mesh]]
name = "s2"
pinion = "p2"
gear = "w2"
stiffness = "500 N/um"
backlash = "0.1 mm"
center_angle = "20 deg"
{mesh2_extra}
{gearbox}
"""

BEARINGS = """
[[bearing]]
name = "{s}_A"
shaft = "{s}"
position = "0 mm"
kx = "2e8 N/m"
ky = "2e8 N/m"
kz = "1e8 N/m"
cx = "3000 N*s/m"
cy = "3000 N*s/m"
cz = "3000 N*s/m"

[[bearing]]
name = "{s}_B"
shaft = "{s}"
position = "200 mm"
kx = "2e8 N/m"
ky = "2e8 N/m"
cx = "3000 N*s/m"
cy = "3000 N*s/m"
"""


def _file(tmp_path, name="gb.toml", z=(23, 64, 19, 56), beta1="15 deg", mesh1_extra="", mesh2_extra="", gearbox=""):
    text = TWO_STAGE.format(
        z1=z[0],
        z2=z[1],
        z3=z[2],
        z4=z[3],
        beta1=beta1,
        mesh1_extra=mesh1_extra,
        mesh2_extra=mesh2_extra,
        gearbox=gearbox,
    )
    text += "".join(BEARINGS.format(s=s) for s in ("in", "mid", "out"))
    p = tmp_path / name
    p.write_text(text)
    return p


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "geardyn.cli", *args], capture_output=True, text=True, cwd=ROOT, timeout=300
    )


def test_two_stage_mesh_ratio_is_19_64_exactly_from_the_teeth(tmp_path):
    d = load_description(_file(tmp_path))
    k = d.kinematics
    assert k["mesh_ratios"] == {"s1": "1", "s2": "19/64"}
    assert k["shaft_speed_ratios"] == {"in": "1", "mid": "23/64", "out": str(Fraction(23, 64) * Fraction(19, 56))}
    assert k["forcing_period_mesh_cycles"] == 64
    s2 = next(m for m in d.meshes if m.name == "s2")
    assert s2.ratio == 19 / 64  # exact in binary
    assert load_system(_file(tmp_path)).period_multiple() == 64


def test_a_correct_ratio_key_is_accepted_and_a_wrong_one_exits_2_naming_both(tmp_path):
    ok = _file(tmp_path, "ok.toml", mesh2_extra="ratio = 0.296875")
    assert load_description(ok).kinematics["mesh_ratios"]["s2"] == "19/64"
    bad = _file(tmp_path, "bad.toml", mesh2_extra="ratio = 0.359375")  # 23/64, the mistake
    with pytest.raises(ModelError, match=r"0\.359375 given.*19/64 = 0\.296875"):
        load_description(bad)
    r = _cli("modes", "--system", str(bad), "--json")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "0.359375" in lines[0] and "19/64" in lines[0] and "ratio" in lines[0]


def test_radii_inconsistent_with_the_teeth_exit_2_naming_both(tmp_path):
    # the gear's base radius from 56 teeth of module 4 mm: 56*4/2*cos(20 deg) = 105.2457 mm
    rb = 56 * 4 / 2 * math.cos(math.radians(20))
    ok = _file(tmp_path, "ok.toml", mesh2_extra=f'base_radius2 = "{rb:.6f} mm"')
    load_description(ok)
    bad = _file(tmp_path, "bad.toml", mesh2_extra='base_radius1 = "30 mm"\nbase_radius2 = "101.3 mm"')
    r = _cli("modes", "--system", str(bad), "--json")
    assert r.returncode == 2
    line = r.stderr.strip()
    assert (
        "\n" not in line
        and "base_radius1" in line
        and "30 mm given" in line
        and f"{19 * 2 * math.cos(math.radians(20)):.6g} mm" in line
    )
    # the case: 997 teeth on the second wheel, radii that fit no tooth ratio
    bad2 = _file(tmp_path, "bad2.toml", z=(23, 64, 19, 997), mesh2_extra='base_radius2 = "105.2457 mm"')
    with pytest.raises(ModelError, match=r"base_radius2: 105\.246 mm given, but 997 teeth"):
        load_description(bad2)


def test_a_long_hunting_period_is_refused_naming_it_unless_rounding_is_asked(tmp_path):
    # a first-stage wheel of 997 teeth (prime): the intermediate shaft turns at 23/997, stage 2's mesh at
    # 19·23/997 / 23 = 19/997 of stage 1's, so the forcing repeats only after 997 stage-1 mesh cycles
    bound = "[gearbox]\nmax_period = 500"
    with pytest.raises(
        ModelError, match=r"forcing period .* is 997 cycles of mesh 's1', above the bound max_period = 500"
    ):
        load_description(_file(tmp_path, "a.toml", z=(23, 997, 19, 56), gearbox=bound))
    r = _cli("modes", "--system", str(_file(tmp_path, "b.toml", z=(23, 997, 19, 56), gearbox=bound)), "--json")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "997" in r.stderr
    d = load_description(_file(tmp_path, "c.toml", z=(23, 997, 19, 56), gearbox=bound + "\nround_ratios = true"))
    r2 = Fraction(d.kinematics["mesh_ratios"]["s2"])
    assert d.kinematics["rounded"] and r2 == Fraction(round(500 * 19 / 997), 500)
    assert any(a.name == "gearbox.round_ratios" for a in d.assumptions)
    d = load_description(_file(tmp_path, "d.toml", z=(23, 997, 19, 56)))  # the default bound is 1000
    assert d.kinematics["forcing_period_mesh_cycles"] == 997 and d.kinematics["mesh_ratios"]["s2"] == "19/997"


def test_speeds_of_a_locked_train_are_refused():
    with pytest.raises(ModelError, match="locked"):
        solve_speeds(
            ["a", "b", "c"], [("m1", "a", "b", 20, 40), ("m2", "b", "c", 20, 20), ("m3", "a", "c", 20, 30)], "a"
        )
    assert forcing_period([Fraction(1), Fraction(19, 64), Fraction(3, 8)]) == 64


def test_the_gearbox_assembles_into_a_system_with_shaft_nodes(tmp_path):
    d = load_description(_file(tmp_path))
    # 3 shafts: nodes at 0, gear(s), 200 mm -> in: 3 nodes, mid: 4, out: 3 -> 10 nodes x 6 DOFs
    assert d.n == 60
    assert [s.name for s in d.shafts] == ["in", "mid", "out"]
    assert d.shafts[1].nodes == ("mid_A", "w1", "p2", "mid_B")
    M = d.mass_matrix()
    assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)
    K, _ = d.bearing_matrices()
    assert np.allclose(K, K.T)
    model = load_system(_file(tmp_path))
    assert model.state_dim == 120
    # senses alternate along the train; the helical stage has axial and tilt entries, the spur stage none
    assert [s.sense for s in d.shafts] == [1, -1, 1]
    v1 = dict(next(m for m in d.meshes if m.name == "s1").vector)
    v2 = dict(next(m for m in d.meshes if m.name == "s2").vector)
    assert abs(v1[("p1", "z")]) > 0.2 and abs(v1[("p1", "ry")]) > 0.005  # the axial force's moment
    assert ("p2", "z") not in v2 and ("p2", "rx") not in v2


def test_modes_json_of_the_shipped_gearbox():
    r = _cli("modes", "--system", "examples/gearbox/two_stage_helical.toml", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    n = len(out["dofs"])
    assert 100 <= n <= 250
    assert len(out["frequencies_hz"]) == n and len(out["modes"]) == n
    e = out["energy_fractions"][5]
    for name in ("input", "intermediate", "output", "in_A", "mid_B", "out_A", "stage1", "stage2"):
        assert name in e
    assert sum(e.values()) == pytest.approx(1.0, abs=1e-9)
    assert out["frequencies_hz"][0] == 0.0 and out["frequencies_hz"][1] > 0  # one rigid rotation of the train
    # each mode's energy grouped per shaft, bearing, coupling and mesh; the shafts' nodes and the kinematics
    g = out["modes"][5]["energy"]
    assert set(g) == {"shafts", "bearings", "couplings", "meshes"}
    assert set(g["shafts"]) == {"input", "intermediate", "output"} and len(g["bearings"]) == 6
    assert set(g["meshes"]) == {"stage1", "stage2"}
    assert sum(sum(x.values()) for x in g.values()) == pytest.approx(1.0, abs=1e-9)
    gb = out["gearbox"]
    assert [s["name"] for s in gb["shafts"]] == ["input", "intermediate", "output"]
    assert all(s["elements"] >= 4 for s in gb["shafts"])
    assert gb["kinematics"]["mesh_ratios"] == {"stage1": "1", "stage2": "19/64"}
    assert len(out["modes"][5]["shape"]) == n


def test_modes_figures_of_the_gearbox_redraw(tmp_path):
    r = _cli(
        "modes", "--system", "examples/gearbox/two_stage_helical.toml", "--rpm-max", "3000", "--out", str(tmp_path)
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "mode_shapes.png").stat().st_size > 10_000 and (tmp_path / "campbell.png").exists()
    import xarray as xr

    ds = xr.open_dataset(tmp_path / "modes.nc")
    assert ds.sizes["node"] == 18 and sorted(set(ds["element_kind"].values.tolist())) == [1, 2, 3, 4]
    assert json.loads(ds.attrs["shafts"]) == ["input", "intermediate", "output"]
    (tmp_path / "mode_shapes.png").unlink()
    r = _cli("plot", str(tmp_path / "modes.nc"), "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "mode_shapes.png").exists()


def test_torque_orders_on_a_gearbox_enter_the_forcing_period_and_the_model(tmp_path):
    """The shipped motor's 2nd order (an engine's firing order) runs at 2/23 of the stage-1 mesh frequency: with
    the meshes' 64 cycles the forcing repeats after lcm(64, 23/2) = 1472 cycles, above the default bound 1000."""
    ex = ROOT / "examples/gearbox/two_stage_helical.toml"
    d = load_description(ex)
    assert d.kinematics["order_ratios"] == {"order 2 of motor": "2/23"}
    assert d.kinematics["forcing_period_mesh_cycles"] == 1472
    motor = next(ld for ld in d.loads if ld.body == "motor")
    assert motor.orders == ((Fraction(2), 30.0, 0.0),) and motor.speed == Fraction(1, 23)
    s = load_system(ex)
    assert s.period_multiple() == 1472
    text = ex.read_text().replace("max_period = 1500", "max_period = 1000")
    f = tmp_path / "bound.toml"
    f.write_text(text)
    with pytest.raises(
        ModelError,
        match=r"is 1472 cycles of mesh 'stage1', above the bound max_period = 1000 "
        r"\(mesh 'stage2' at 19/64, order 2 of motor at 2/23 of",
    ):
        load_description(f)


def test_a_gearbox_simulation_settles_on_its_static_deflection(tmp_path):
    """Linear meshes (no backlash, constant stiffness) and a balanced torque: the simulated steady deflection of
    every mesh is the static one, K q = F solved on the SI matrices (the rigid rotation left free)."""
    f = _file(
        tmp_path,
        z=(20, 40, 20, 40),  # stage 2 at 1/2 of stage 1: a forcing period of 2 cycles
        beta1="15 deg",
        mesh1_extra="xi0 = 0.1",
        mesh2_extra="xi0 = 0.1",
        gearbox='[system]\ncharacteristic_length = "10 um"\n'
        '[[load]]\ngear = "p1"\ntorque = "100 N*m"\n[[load]]\ngear = "w2"\ntorque = "balance"',
    )
    text = f.read_text().replace('backlash = "0.1 mm"', 'backlash = "0 mm"')
    f.write_text(text)
    d = load_description(f)
    K, _ = d.bearing_matrices()
    for m in d.meshes:
        v = d.vector(m)
        K = K + m.stiffness * np.outer(v, v)
    q = np.linalg.lstsq(K, d.load_vector(), rcond=None)[0]
    static = np.array([d.vector(m) @ q for m in d.meshes]) / d.b_c
    from geardyn.integrate import IntegrationOptions, integrate_batch

    s = load_system(f).with_param("omega", 0.5)
    assert s.period_multiple() == 2
    # 600 forcing periods: the shafts' torsion within a shaft has little damping (Rayleigh β K only)
    r = integrate_batch([s], options=IntegrationOptions(dtau=0.05, transient=600, periods=4))
    assert int(np.asarray(r.status)[0]) == 0
    means = r.element_mean()[0]
    spread = r.element_u_max()[0] - r.element_u_min()[0]
    assert np.allclose(means, static, rtol=1e-6), (means, static)
    assert np.all(spread < 1e-6 * np.abs(static))


@pytest.mark.parametrize(
    "material, bound",
    [
        ('rho = "-7850 kg/m^3"', "must be >= 0 (a negative density"),
        ('E = "-3 GPa"', "must be >= 0 (a negative pressure"),
        ('E = "0 GPa"', "E must be > 0 Pa"),
        ("nu = 0.7", "nu must be in (-1, 0.5)"),
    ],
)
def test_a_shaft_material_out_of_bounds_is_refused_naming_its_place_once(tmp_path, material, bound):
    text = _file(tmp_path).read_text().replace('name = "in"\n', f'name = "in"\nmaterial = {{ {material} }}\n', 1)
    path = tmp_path / "m.toml"
    path.write_text(text)
    with pytest.raises(ModelError) as err:
        load_description(path)
    message = str(err.value)
    assert bound in message and message.count("[[shaft]] 'in' material") == 1 and message.count("line ") == 1
