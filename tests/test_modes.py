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
    # mesh frequency at n rpm: 20 n/60 Hz; order k crosses f_n at n = 60 f_n/(20 k); the elastic mode is mode 2
    got = {(x["order"], x["mode"]): x["rpm"] for x in c["crossings"]}
    assert got == {(1, 2): pytest.approx(3 * fn), (2, 2): pytest.approx(1.5 * fn)}
    assert [x["order"] for x in c["crossings"]] == [2, 1]  # sorted by speed
    assert c["lines"][0]["hz_per_x"] == pytest.approx(20 / 60)
    assert c["x"] == "rpm" and [ln["label"] for ln in c["lines"]] == ["order 1", "order 2"]
    # a second mesh at ratio 2: its order-1 line is the first mesh's order 2 (one line, both named)
    b = d.bodies + (Body("h", ("theta",), inertia=1.0),)
    m2 = Mesh("m2", ((("g", "theta"), 0.1), (("h", "theta"), -0.1)), 1e8, backlash=1e-4, ratio=2.0)
    d2 = SystemDescription(bodies=b, meshes=d.meshes + (m2,))
    c2 = campbell(d2, rpm_range=(0, 1e7), orders=(1, 2))
    r2 = modal_analysis(d2)
    assert [ln["label"] for ln in c2["lines"]] == [
        "order 1 of mesh",
        "order 1 of m2 = order 2 of mesh",
        "order 2 of m2",
    ]
    assert [ln["harmonic"] for ln in c2["lines"]] == [1.0, 2.0, 4.0]
    assert len(c2["crossings"]) == 3 * 2  # two elastic modes, three distinct lines
    for x in c2["crossings"]:
        harmonic = c2["lines"][x["line"]]["harmonic"]
        assert x["rpm"] == pytest.approx(60 * r2.frequencies_hz[x["mode"] - 1] / (20 * harmonic), rel=1e-12)
    # without teeth: against the mesh frequency, order k crossing f_n at f_n / k
    c3 = campbell(replace(d, meshes=(replace(d.meshes[0], teeth=None),)), orders=(1, 3))
    assert c3["x"] == "mesh_frequency_hz" and "rpm_range" not in c3 and "mesh frequency" in c3["x_label"]
    assert {x["order"]: x["x"] for x in c3["crossings"]} == {1: pytest.approx(fn), 3: pytest.approx(fn / 3)}
    assert c3["x_range"] == [0.0, pytest.approx(float(f"{1.2 * fn:.2g}"))]
    with pytest.raises(ModelError, match="orders"):
        campbell(d, orders=(0,))


def test_planetary_campbell_one_line_per_order_and_one_crossing_per_frequency():
    """The six meshes of the planetary set share one frequency: three lines for orders 1-3, and each
    degenerate pair of modes is one crossing naming both (issue: 288 crossing lines before)."""
    d = load_description(EXAMPLES / "planetary_lin_parker_1999.toml")
    rep = modes_report(d, orders=(1, 2, 3))
    c = rep["campbell"]
    assert [ln["label"] for ln in c["lines"]] == ["order 1", "order 2", "order 3"]
    assert all(len(ln["meshes"]) == 6 for ln in c["lines"])
    distinct = len({round(f, 6) for f in rep["frequencies_hz"] if f > 0})
    assert distinct == 11 and len(c["crossings"]) <= 3 * distinct
    keys = [(x["line"], tuple(x["modes"])) for x in c["crossings"]]
    assert len(keys) == len(set(keys))
    assert [2, 3] in [x["modes"] for x in c["crossings"]] and [2, 3] in rep["degenerate"]
    # every crossing of order 1 lies at the mode's own frequency (the x axis is the mesh frequency)
    for x in c["crossings"]:
        assert x["x"] * c["lines"][x["line"]]["harmonic"] == pytest.approx(x["frequency_hz"], rel=1e-12)


def test_planetary_structure_lin_parker():
    """Lin & Parker (1999): N = 3 equally spaced planets give rotational modes and degenerate
    translational pairs, no planet modes (the published frequencies: the tests below)."""
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


# ---------------------------------------------------------------------------------------------
# Lin & Parker (1999): the published example.
#
# J. Lin, R. G. Parker, "Analytical characterization of the unique properties of planetary gear free
# vibration", J. Vib. Acoust. 121 (1999) 316-321.  Table 1 (parameters, also J. Lin's thesis, Ohio
# State University 2000, Table C.1): masses sun 0.4, ring 2.35, carrier 5.43, planet 0.66 kg;
# I/r^2 0.39, 3.00, 6.29, 0.61 kg; base diameters 77.4, 275.0, 176.8 (carrier: planet centres),
# 100.3 mm; bearings k_s = k_r = k_c = k_p = 1e8 N/m; torsional k_su = k_cu = 0, k_ru = 1e9 N/m;
# meshes k_sp = k_rp = 5e8 N/m; pressure angle 24.6 deg.  Table 2 (the thesis's Table 3.1): the
# natural frequencies (Hz) by mode type for N = 3, 4, 5 equally spaced planets.  The values were read
# from the reproductions of this example in the Drivetrain codes (gfsReboucas/Drivetrain,
# Lin_Parker_99.test_01; gfsReboucas/Drivetrain-python, tests/test_lin_parker_1999.py).

_LP_MASS = {"sun": 0.4, "ring": 2.35, "carrier": 5.43, "planet": 0.66}
_LP_I_R2 = {"sun": 0.39, "ring": 3.00, "carrier": 6.29, "planet": 0.61}
_LP_RADIUS = {"sun": 77.4e-3 / 2, "ring": 275.0e-3 / 2, "carrier": 176.8e-3 / 2, "planet": 100.3e-3 / 2}
_LP_K_BEARING = 1e8  # k_s = k_r = k_c = k_p
_LP_K_RU = 1e9  # ring torsional (on u_r = r_r theta_r); k_su = k_cu = 0
_LP_K_MESH = 5e8  # k_sp = k_rp
_LP_ALPHA = math.radians(24.6)

#: Lin & Parker (1999), Table 2: natural frequencies (Hz) by mode type.  Rotational modes are simple
#: (the first is the rigid-body rotation), translational modes are degenerate pairs, and planet modes
#: (N >= 4) have multiplicity N - 3.
_LP_TABLE2 = {
    3: {
        "rotational": (0.0, 1475.7, 1930.3, 2658.3, 7462.8, 11775.3),
        "translational": (743.2, 1102.4, 1896.0, 2276.4, 6986.3, 9647.9),
        "planet": (),
    },
    4: {
        "rotational": (0.0, 1536.6, 1970.6, 2625.7, 7773.6, 13071.1),
        "translational": (727.0, 1091.0, 1892.8, 2342.5, 7189.9, 10437.6),
        "planet": (1808.2, 5963.8, 6981.7),
    },
    5: {
        "rotational": (0.0, 1567.4, 2006.1, 2614.8, 8065.4, 14253.1),
        "translational": (710.0, 1072.0, 1888.1, 2425.3, 7382.4, 11172.3),
        "planet": (1808.2, 5963.8, 6981.7),
    },
}
_CENTRAL = ("carrier", "ring", "sun")


def _lin_parker_system(n_planets: int) -> SystemDescription:
    """Lin & Parker's Table 1 system with ``n_planets`` equally spaced planets, built from the table.

    Rotations θ with I = (I/r²) r² and the radii in the vectors (Lin & Parker's u = r θ); planet
    translations in the global frame.  Mesh deflections along the lines of action
    n_s = (−sin(ψ_n − α), cos(ψ_n − α)) and n_r = (−sin(ψ_n + α), cos(ψ_n + α)).
    """
    r = _LP_RADIUS
    planets = [f"planet{i + 1}" for i in range(n_planets)]
    bodies = tuple(
        Body(b, ("x", "y", "theta"), mass=_LP_MASS[kind], inertia=_LP_I_R2[kind] * r[kind] ** 2)
        for b, kind in [(c, c) for c in _CENTRAL] + [(p, "planet") for p in planets]
    )
    conns = [Connection.diagonal(f"{b}_bearing", b, {"x": _LP_K_BEARING, "y": _LP_K_BEARING}) for b in _CENTRAL]
    conns.append(Connection.along("ring_torsion", {("ring", "theta"): r["ring"]}, _LP_K_RU))
    meshes = []
    for i, p in enumerate(planets):
        psi = 2 * math.pi * i / n_planets
        er = (math.cos(psi), math.sin(psi))
        et = (-math.sin(psi), math.cos(psi))
        conns.append(
            Connection.along(
                f"{p}_radial",
                {("carrier", "x"): er[0], ("carrier", "y"): er[1], (p, "x"): -er[0], (p, "y"): -er[1]},
                _LP_K_BEARING,
            )
        )
        conns.append(
            Connection.along(
                f"{p}_tangential",
                {
                    ("carrier", "x"): et[0],
                    ("carrier", "y"): et[1],
                    ("carrier", "theta"): r["carrier"],
                    (p, "x"): -et[0],
                    (p, "y"): -et[1],
                },
                _LP_K_BEARING,
            )
        )
        for gear, ang, rp in (("sun", psi - _LP_ALPHA, r["planet"]), ("ring", psi + _LP_ALPHA, -r["planet"])):
            n = (-math.sin(ang), math.cos(ang))
            vec = (
                ((gear, "x"), n[0]),
                ((gear, "y"), n[1]),
                ((gear, "theta"), r[gear]),
                ((p, "x"), -n[0]),
                ((p, "y"), -n[1]),
                ((p, "theta"), rp),
            )
            meshes.append(Mesh(f"{gear}_{p}", vec, _LP_K_MESH, xi0=0.0))
    return SystemDescription(bodies=bodies, meshes=tuple(meshes), connections=tuple(conns), characteristic_length=1e-6)


def _lin_parker_mode_types(d: SystemDescription, r) -> list[str]:
    """Lin & Parker's mode types: planet (central members at rest), rotational (central members
    rotate only), translational (central members translate only)."""
    lab = list(r.labels)
    rot = [lab.index(f"{b}.theta") for b in _CENTRAL]
    tra = [lab.index(f"{b}.{x}") for b in _CENTRAL for x in ("x", "y")]
    out = []
    for i in range(d.n):
        phi = r.shapes[:, i] / np.abs(r.shapes[:, i]).max()
        still_rot, still_tra = np.abs(phi[rot]).max() < 1e-8, np.abs(phi[tra]).max() < 1e-8
        out.append(
            "planet"
            if still_rot and still_tra
            else "rotational"
            if still_tra
            else "translational"
            if still_rot
            else "mixed"
        )
    return out


def _lin_parker(n_planets: int) -> SystemDescription:
    if n_planets == 3:
        return load_description(EXAMPLES / "planetary_lin_parker_1999.toml")
    return _lin_parker_system(n_planets)


def test_lin_parker_example_file_is_table_1():
    """The example file is Lin & Parker's Table 1 system: the same matrices as built from the table."""
    d = load_description(EXAMPLES / "planetary_lin_parker_1999.toml")
    ref = _lin_parker_system(3)
    assert d.labels == ref.labels
    np.testing.assert_allclose(d.mass_matrix(), ref.mass_matrix(), rtol=1e-12, atol=0)
    kb, kb_ref = d.bearing_matrices()[0], ref.bearing_matrices()[0]
    np.testing.assert_allclose(kb, kb_ref, rtol=0, atol=1e-12 * np.abs(kb_ref).max())
    assert sorted(m.name for m in d.meshes) == sorted(m.name for m in ref.meshes)
    for m in ref.meshes:
        mine = next(x for x in d.meshes if x.name == m.name)
        assert mine.stiffness == m.stiffness == 5e8
        np.testing.assert_allclose(d.vector(mine), ref.vector(m), rtol=0, atol=1e-14)
    # nothing of the model is assumed; only the length scale (no backlash) and the operating point
    assert {a.name for a in d.assumptions} <= {"system.characteristic_length", "operating.omega"}


@pytest.mark.parametrize("n_planets", [3, 4, 5])
def test_lin_parker_published_natural_frequencies(n_planets):
    """Lin & Parker (1999), Table 2: every natural frequency within 0.1 %, by mode type, with the
    multiplicities they prove: simple rotational modes, translational pairs, planet modes of
    multiplicity N - 3."""
    d = _lin_parker(n_planets)
    r = modal_analysis(d)
    n = 3 * n_planets + 9
    assert d.n == n
    np.testing.assert_allclose(r.shapes.T @ d.mass_matrix() @ r.shapes, np.eye(n), atol=1e-10)
    table = _LP_TABLE2[n_planets]
    types = _lin_parker_mode_types(d, r)
    assert "mixed" not in types
    f = r.frequencies_hz
    got = {t: np.array([f[i] for i in range(n) if types[i] == t]) for t in ("rotational", "translational", "planet")}
    expected = {
        "rotational": np.array(table["rotational"]),
        "translational": np.repeat(table["translational"], 2),
        "planet": np.repeat(table["planet"], n_planets - 3),
    }
    for t in expected:
        assert got[t].shape == expected[t].shape, t
        np.testing.assert_allclose(got[t], expected[t], rtol=1e-3, atol=0, err_msg=t)
    # the whole spectrum, sorted, against the published table
    allf = np.sort(np.concatenate(list(expected.values())))
    np.testing.assert_allclose(f, allf, rtol=1e-3, atol=0)
    # multiplicities: one rigid-body rotation, simple rotational modes, degenerate pairs, N - 3 planet modes
    assert r.rigid.sum() == 1 and types[int(np.flatnonzero(r.rigid)[0])] == "rotational"
    groups = {tuple(g) for g in r.degenerate_groups()}
    multiplicity = {i: len(g) for g in groups for i in g}
    for i, t in enumerate(types):
        want = {"rotational": 1, "translational": 2, "planet": n_planets - 3}[t]
        assert multiplicity.get(i, 1) == want, (i, t, f[i])


def test_lin_parker_planet_modes_do_not_depend_on_the_number_of_planets():
    """Lin & Parker (1999): planet-mode frequencies depend on the planet parameters only (N >= 4)."""
    fp = []
    for n_planets in (4, 5, 6):
        d = _lin_parker_system(n_planets)
        r = modal_analysis(d)
        types = _lin_parker_mode_types(d, r)
        f = np.array([r.frequencies_hz[i] for i in range(d.n) if types[i] == "planet"])
        assert len(f) == 3 * (n_planets - 3)
        groups = np.sort(f).reshape(3, n_planets - 3)  # three frequencies, each N - 3 times
        np.testing.assert_allclose(groups, groups[:, :1].repeat(n_planets - 3, axis=1), rtol=1e-9)
        fp.append(groups[:, 0])
    for other in fp[1:]:
        np.testing.assert_allclose(other, fp[0], rtol=1e-10)


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
    assert [m["mode"] for m in rep["modes"]] == [1, 2, 3, 4, 5, 6]  # numbered from 1, as the crossings
    assert {x["mode"] for x in rep["campbell"]["crossings"]} <= set(range(2, 7))
    rep_p = modes_report(load_description(EXAMPLES / "planetary_lin_parker_1999.toml"))
    assert rep_p["campbell"]["x"] == "mesh_frequency_hz" and "teeth" in rep_p["campbell_note"]
    assert rep_p["degenerate"][0] == [2, 3]
