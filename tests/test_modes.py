"""Linear analysis of systems: natural frequencies, mode shapes, strain energy, Campbell diagrams."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from geardyn.config import load_config
from geardyn.errors import ModelError
from geardyn.systems import (
    Body,
    Connection,
    Mesh,
    SystemDescription,
    campbell,
    load_description,
    modal_analysis,
    modes_report,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "systems"


def _torsional_pair(I1=1.5, I2=4.0, R1=0.05, R2=0.12, k=3e8, teeth=20) -> SystemDescription:
    b = (Body("p", ("theta",), inertia=I1), Body("g", ("theta",), inertia=I2))
    m = Mesh("mesh", ((("p", "theta"), R1), (("g", "theta"), -R2)), k, backlash=1e-4, teeth=teeth)
    return SystemDescription(bodies=b, meshes=(m,))


def test_two_dof_torsional_pair_closed_form():
    I1, I2, R1, R2, k = 1.5, 4.0, 0.05, 0.12, 3e8
    r = modal_analysis(_torsional_pair(I1, I2, R1, R2, k))
    assert list(r.rigid) == [True, False]
    assert r.frequencies_hz[0] == 0.0
    w2 = k * (R1**2 / I1 + R2**2 / I2)
    assert r.omega2[1] == pytest.approx(w2, rel=1e-12)
    assert r.frequencies_hz[1] == pytest.approx(math.sqrt(w2) / (2 * math.pi), rel=1e-12)
    M = np.diag([I1, I2])
    np.testing.assert_allclose(r.shapes.T @ M @ r.shapes, np.eye(2), atol=1e-12)
    # rigid mode: both pitch points move together, R1 θ1 = R2 θ2
    phi0 = r.shapes[:, 0]
    assert R1 * phi0[0] - R2 * phi0[1] == pytest.approx(0.0, abs=1e-12)
    assert r.energy[1].tolist() == [1.0] and r.mesh_dominated.tolist() == [False, True]


def test_paper_pair_mode_is_the_1dof_natural_frequency():
    d = load_description(EXAMPLES / "paper_torsional.toml")
    r = modal_analysis(d)
    assert r.frequencies_hz[1] == pytest.approx(load_config().pair.omega_n / (2 * math.pi), rel=1e-12)


def test_spring_mass_chain():
    # ground -k- m -k- m: ω² = (k/m)(3 ∓ √5)/2
    m, k = 2.0, 5e6
    b = (Body("a", ("x",), mass=m), Body("b", ("x",), mass=m))
    spring = Mesh("spring", ((("a", "x"), 1.0), (("b", "x"), -1.0)), k, backlash=1e-4)
    ground = Connection.diagonal("ground", "a", {"x": k})
    r = modal_analysis(SystemDescription(bodies=b, meshes=(spring,), connections=(ground,)))
    expected = np.sqrt((k / m) * np.array([(3 - math.sqrt(5)) / 2, (3 + math.sqrt(5)) / 2])) / (2 * math.pi)
    np.testing.assert_allclose(r.frequencies_hz, expected, rtol=1e-12)
    assert not r.rigid.any()
    np.testing.assert_allclose(r.energy.sum(axis=1), 1.0, rtol=1e-12)
    # mode 1 (in phase): golden-ratio shape; its energy split k x1² : k (x1 - x2)²
    x = r.shapes[:, 0]
    assert x[1] / x[0] == pytest.approx((1 + math.sqrt(5)) / 2, rel=1e-12)
    e_ground = x[0] ** 2 / (x[0] ** 2 + (x[0] - x[1]) ** 2)
    assert r.energy[0, r.elements.index("ground")] == pytest.approx(e_ground, rel=1e-12)


def test_campbell_crossings_by_hand():
    d = _torsional_pair(teeth=20)
    r = modal_analysis(d)
    fn = r.frequencies_hz[1]
    c = campbell(d, r, rpm_range=(0.0, 1e6), orders=(1, 2))
    # mesh frequency at n rpm: 20 n/60 Hz; order k crosses f_n at n = 60 f_n/(20 k)
    got = {(x["order"], x["mode"]): x["rpm"] for x in c["crossings"]}
    assert got == {(1, 1): pytest.approx(3 * fn), (2, 1): pytest.approx(1.5 * fn)}
    assert [x["order"] for x in c["crossings"]] == [2, 1]  # sorted by speed
    assert c["lines"][0]["hz_per_rpm"] == pytest.approx(20 / 60)
    # a second mesh at ratio 2: its order-1 line is the first mesh's order 2
    b = d.bodies + (Body("h", ("theta",), inertia=1.0),)
    m2 = Mesh("m2", ((("g", "theta"), 0.1), (("h", "theta"), -0.1)), 1e8, backlash=1e-4, ratio=2.0)
    d2 = SystemDescription(bodies=b, meshes=d.meshes + (m2,))
    c2 = campbell(d2, rpm_range=(0, 1e7), orders=(1,))
    r2 = modal_analysis(d2)
    for x in c2["crossings"]:
        ratio = 1.0 if x["mesh"] == "mesh" else 2.0
        assert x["rpm"] == pytest.approx(60 * r2.frequencies_hz[x["mode"]] / (20 * ratio), rel=1e-12)
    with pytest.raises(ModelError, match="teeth"):
        campbell(replace(d, meshes=(replace(d.meshes[0], teeth=None),)))


def test_planetary_structure_lin_parker():
    """Lin & Parker (1999): N = 3 equally spaced planets give rotational modes and degenerate
    translational pairs, no planet modes.  (Their published frequencies could not be consulted:
    the values are not compared.)"""
    d = load_description(EXAMPLES / "planetary_lin_parker_1999.toml")
    r = modal_analysis(d)
    assert d.n == 18
    M = d.mass_matrix()
    np.testing.assert_allclose(r.shapes.T @ M @ r.shapes, np.eye(18), atol=1e-10)
    assert r.rigid.sum() == 1  # sun and carrier are free torsionally: the rigid-body rotation
    pairs = r.degenerate_groups()
    assert len(pairs) == 6 and all(len(g) == 2 for g in pairs)
    in_pairs = {i for g in pairs for i in g}
    singles = [i for i in range(18) if i not in in_pairs]
    assert len(singles) == 6  # rotational modes, the rigid one included
    lab = list(r.labels)
    central = ("carrier", "ring", "sun")
    for i in singles:  # rotational modes: no translation of the central members
        phi = r.shapes[:, i]
        for b in central:
            for dof in ("x", "y"):
                assert abs(phi[lab.index(f"{b}.{dof}")]) < 1e-9 * np.abs(phi).max()
    for i in in_pairs:  # translational modes: no rotation of the central members
        phi = r.shapes[:, i]
        for b in central:
            assert abs(phi[lab.index(f"{b}.theta")]) < 1e-9 * np.abs(phi).max()


def test_bevel_8dof_tends_to_the_torsional_mode_as_bearings_stiffen():
    d = load_description(EXAMPLES / "paper_bevel_8dof.toml")
    f1 = load_config().pair.omega_n / (2 * math.pi)
    errs = []
    for scale in (1.0, 1e2, 1e4, 1e6):
        conns = tuple(replace(c, stiffness=np.array(c.stiffness) * scale) for c in d.connections)
        r = modal_analysis(replace(d, connections=conns))
        i = int(np.argmax(r.energy[:, r.elements.index("mesh")]))
        errs.append(abs(r.frequencies_hz[i] - f1) / f1)
    assert errs[-1] < 1e-5
    assert all(b < a for a, b in zip(errs, errs[1:]))


def test_modes_report_is_json_ready():
    d = load_description(EXAMPLES / "spur_bending_torsional.toml")
    rep = modes_report(d, rpm_range=(0, 20000), orders=(1, 2))
    json.dumps(rep)
    f = rep["frequencies_hz"]
    assert f == sorted(f) and len(rep["modes"]) == len(f) == 6
    assert set(rep["energy_fractions"][-1]) == {"pinion_bearing", "gear_bearing", "mesh"}
    assert rep["modes"][0]["rigid"] and rep["frequencies_hz"][0] == 0.0
    assert any(m["mesh_dominated"] for m in rep["modes"])
    assert rep["campbell"]["crossings"] and {"rpm", "mode", "order", "mesh"} <= set(rep["campbell"]["crossings"][0])
    rep_p = modes_report(load_description(EXAMPLES / "planetary_lin_parker_1999.toml"))
    assert rep_p["campbell"] is None and "teeth" in rep_p["campbell_note"]
