"""Gearbox validation: meshes from geometry against the hand-built systems, β = 0 against spur, the rigid-shaft
limit against a lumped model built by hand."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from geardyn.gearbox.gear import Gear
from geardyn.gearbox.mesh import mesh_vector, pair_geometry_of
from geardyn.systems import load_description
from geardyn.systems.description import Body, Connection, Mesh, SystemDescription
from geardyn.systems.modes import modal_analysis
from geardyn.systems.vectors import cylindrical_mesh_vector

ROOT = Path(__file__).resolve().parents[1]
DOFS = ("x", "y", "z", "rx", "ry", "theta")

# Luo et al. (2019) spur pair of examples/systems/spur_bending_torsional.toml
Z1, Z2, MOD, ALPHA = 16, 48, 3.175e-3, math.radians(20.0)
M1, M2, I1, I2 = 1.2728, 3.5367, 1.751e-4, 6.828e-3
KB, CB, KM, JN = 8.5364e7, 2.134e4, 3.2e8, 1e-4


def _gears(beta=0.0, z=(Z1, Z2), x=(0.0, 0.0)):
    g1 = Gear("p", "s1", 0.0, z[0], MOD, 0.016, ALPHA, beta, x[0], "right")
    g2 = Gear("g", "s2", 0.0, z[1], MOD, 0.016, ALPHA, beta, x[1], "left")
    return g1, g2


def _as_dict(entries1, entries2):
    out = {}
    for body, e in (("p", entries1), ("g", entries2)):
        for d, c in zip(DOFS, e):
            out[(body, d)] = float(c)
    return out


@pytest.mark.parametrize("psi_deg", [0.0, 30.0, -75.0])
@pytest.mark.parametrize("sense", [1, -1])
def test_spur_mesh_from_geometry_equals_the_spur_vector_of_the_systems(psi_deg, sense):
    g1, g2 = _gears()
    geo = pair_geometry_of("m", g1, g2)
    v = _as_dict(*mesh_vector(geo, math.radians(psi_deg), sense, -sense, "right"))
    ref = dict(
        cylindrical_mesh_vector(
            "p",
            "g",
            ("x", "y", "z", "theta"),
            ("x", "y", "z", "theta"),
            pressure_angle=ALPHA,
            base_radius1=Z1 * MOD / 2 * math.cos(ALPHA),
            base_radius2=Z2 * MOD / 2 * math.cos(ALPHA),
            center_angle=math.radians(psi_deg),
            pinion_rotation="counterclockwise" if sense > 0 else "clockwise",
        )
    )
    for key, c in ref.items():
        assert v[key] == pytest.approx(c, rel=1e-12, abs=1e-15)
    for b in ("p", "g"):  # a spur pair: no axial force, no tilting moment
        assert v[(b, "z")] == 0.0 and v[(b, "rx")] == pytest.approx(0.0, abs=1e-18)
        assert v[(b, "ry")] == pytest.approx(0.0, abs=1e-18)


def test_spur_mesh_reproduces_the_hand_built_example_to_its_printed_digits():
    ex = load_description(ROOT / "examples/systems/spur_bending_torsional.toml")
    mesh = ex.meshes[0]
    g1, g2 = _gears()
    v = _as_dict(*mesh_vector(pair_geometry_of("m", g1, g2), 0.0, 1, -1, "right"))
    names = {"pinion": "p", "gear": "g"}
    for (body, d), c in mesh.vector:
        # the example writes the base radii to 6 digits (23.8682 mm, 71.6047 mm)
        assert v[(names[body], d)] == pytest.approx(c, rel=5e-6)
    # with the exact radii the same construction gives the same vector to 1e-12 (test above)


def test_helical_mesh_with_beta_zero_equals_the_spur_mesh_and_the_helical_vector():
    g1, g2 = _gears(0.0)
    spur = mesh_vector(pair_geometry_of("m", g1, g2), 0.3, 1, -1, "right")
    for hand in ("right", "left"):  # at β = 0 the hand changes nothing
        hel = mesh_vector(pair_geometry_of("m", g1, g2), 0.3, 1, -1, hand)
        assert np.array_equal(spur[0], hel[0]) and np.array_equal(spur[1], hel[1])
    h1, h2 = _gears(1e-9)  # the helical vector is continuous at β = 0
    hel = mesh_vector(pair_geometry_of("m", h1, h2), 0.3, 1, -1, "right")
    assert np.allclose(spur[0], hel[0], rtol=0, atol=1e-8) and np.allclose(spur[1], hel[1], rtol=0, atol=1e-8)
    # a 15 deg helical pair: x, y, z, theta as the systems' helical vector; the tilt arms are r × n
    beta = math.radians(15.0)
    g1, g2 = _gears(beta)
    geo = pair_geometry_of("m", g1, g2)
    v = _as_dict(*mesh_vector(geo, 0.0, 1, -1, "right"))
    at = math.atan(math.tan(ALPHA) / math.cos(beta))
    rb1 = Z1 * MOD / (2 * math.cos(beta)) * math.cos(at)
    rb2 = Z2 * MOD / (2 * math.cos(beta)) * math.cos(at)
    ref = dict(
        cylindrical_mesh_vector(
            "p",
            "g",
            ("x", "y", "z", "theta"),
            ("x", "y", "z", "theta"),
            pressure_angle=ALPHA,
            base_radius1=rb1,
            base_radius2=rb2,
            helix_angle=beta,
        )
    )
    for key, c in ref.items():
        assert v[key] == pytest.approx(c, rel=1e-12, abs=1e-15)
    # centres along +x: r1 = r1 e_x, r2 = -r2 e_x with the pitch radii; (r × n)_y = -r n_z, (r × n)_x = 0
    nz = v[("p", "z")]
    assert v[("p", "ry")] == pytest.approx(-rb1 / math.cos(at) * nz, rel=1e-12)
    assert v[("g", "ry")] == pytest.approx(-(rb2 / math.cos(at)) * nz, rel=1e-12)
    assert v[("p", "rx")] == pytest.approx(0.0, abs=1e-18)


RIGID = """
[system]
reference = "mesh"
[operating]
rpm = "1800 rpm"
[gearbox]
input_rotation = "counterclockwise"

[[shaft]]
name = "s1"
material = {{ E = "{E} Pa", nu = 0.3, rho = "7850 kg/m^3" }}
segments = [{{ length = "40 mm", outer = "20 mm" }}]
elements_per_segment = 2
rayleigh_beta = "0 s"

[[shaft]]
name = "s2"
material = {{ E = "{E} Pa", nu = 0.3, rho = "7850 kg/m^3" }}
segments = [{{ length = "40 mm", outer = "20 mm" }}]
elements_per_segment = 2
rayleigh_beta = "0 s"

[[gear]]
name = "pinion"
shaft = "s1"
position = "20 mm"
teeth = 16
module = "3.175 mm"
face_width = "16 mm"
mass = "{mg1} kg"
inertia = "{ig1} kg*m^2"
diametral_inertia = "1e-4 kg*m^2"

[[gear]]
name = "gear"
shaft = "s2"
position = "20 mm"
teeth = 48
module = "3.175 mm"
face_width = "16 mm"
mass = "{mg2} kg"
inertia = "{ig2} kg*m^2"
diametral_inertia = "3e-3 kg*m^2"

[[mesh]]
name = "mesh"
pinion = "pinion"
gear = "gear"
stiffness = "3.2e8 N/m"
backlash = "0.1 mm"
xi0 = 0.07

[[bearing]]
name = "b1"
shaft = "s1"
position = "20 mm"
kx = "8.5364e7 N/m"
ky = "8.5364e7 N/m"
kz = "1e10 N/m"
krx = "1e7 N*m/rad"
kry = "1e7 N*m/rad"
cx = "2.134e4 N*s/m"
cy = "2.134e4 N*s/m"

[[bearing]]
name = "b2"
shaft = "s2"
position = "20 mm"
kx = "8.5364e7 N/m"
ky = "8.5364e7 N/m"
kz = "1e10 N/m"
krx = "1e7 N*m/rad"
kry = "1e7 N*m/rad"
cx = "2.134e4 N*s/m"
cy = "2.134e4 N*s/m"
"""


def _lumped(ms: float, js: float) -> SystemDescription:
    """The spur example's 6-DOF model by hand (exact base radii), each gear carrying its shaft's mass."""
    vec = cylindrical_mesh_vector(
        "pinion",
        "gear",
        ("x", "y", "theta"),
        ("x", "y", "theta"),
        pressure_angle=ALPHA,
        base_radius1=Z1 * MOD / 2 * math.cos(ALPHA),
        base_radius2=Z2 * MOD / 2 * math.cos(ALPHA),
    )
    return SystemDescription(
        bodies=(
            Body("pinion", ("x", "y", "theta"), M1, I1),
            Body("gear", ("x", "y", "theta"), M2, I2),
        ),
        meshes=(Mesh("mesh", vec, KM, JN, xi0=0.07, teeth=Z1),),
        connections=(
            Connection.diagonal("b1", "pinion", {"x": KB, "y": KB}, {"x": CB, "y": CB}),
            Connection.diagonal("b2", "gear", {"x": KB, "y": KB}, {"x": CB, "y": CB}),
        ),
    )


def test_rigid_shaft_limit_has_the_lumped_models_modes(tmp_path):
    """Very stiff shafts, each gear at the middle of its shaft on one bearing: the in-plane modes (x, y, θ) are
    the lumped 6-DOF model's, whose bodies are the gears with the shafts' mass (ρAL) and polar inertia (ρJL)."""
    rho, d, L = 7850.0, 0.02, 0.04
    ms = rho * math.pi * d**2 / 4 * L
    js = rho * math.pi * d**4 / 32 * L
    lumped = modal_analysis(_lumped(ms, js)).frequencies_hz
    errs = []
    for factor in (1e2, 1e3, 1e4):
        f = tmp_path / f"rigid{int(factor)}.toml"
        f.write_text(RIGID.format(E=2.1e11 * factor, mg1=M1 - ms, mg2=M2 - ms, ig1=I1 - js, ig2=I2 - js))
        fe = modal_analysis(load_description(f)).frequencies_hz
        assert fe[0] == 0.0 and fe[1] > 0  # one rigid rotation of the pair, as the lumped model
        # the lumped model's modes among the FE modes: the nearest of each
        near = np.array([fe[np.argmin(np.abs(fe - x))] for x in lumped[1:]])
        errs.append(np.max(np.abs(near / lumped[1:] - 1)))
    assert errs[-1] < 1e-6, errs
    assert errs[0] > errs[1] > errs[2]  # converging as the shafts stiffen
