"""Multi-DOF systems: description, system files, the assembled non-dimensional form, kernel arrays."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from geardyn.config import load_config
from geardyn.errors import ConfigError, ModelError
from geardyn.system import System
from geardyn.systems import (
    Body,
    Connection,
    Load,
    Mesh,
    SystemDescription,
    SystemModel,
    assemble,
    load_description,
    load_system,
    modal_analysis,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "systems"
TORSIONAL = EXAMPLES / "paper_torsional.toml"


# ---------------------------------------------------------------------------- exact reduction
def test_paper_torsional_reduces_exactly_to_the_1dof_model():
    s = load_system(TORSIONAL)
    model = load_config().model  # the packaged paper pair (Table 1)
    a = s.arrays()
    V, Mi, F = a.V[0], a.Mi, a.F
    # the relative coordinate u = V q - E: u'' + (V Mi V) C u' + (V Mi V) K f(u) = V Mi F - E''
    gain = V @ Mi @ V
    assert gain == pytest.approx(1.0, abs=1e-12)
    ref = model.coefficients(1)
    coef = a.coef[0]
    np.testing.assert_allclose(gain * coef[0], ref[0], rtol=0, atol=1e-12)  # 2ξ(θ)
    np.testing.assert_allclose(gain * coef[1], ref[1], rtol=0, atol=1e-12)  # 1 + κ cos
    w = s.omega
    ste_forcing = np.array([(w * j * a.ratio[0]) ** 2 * coef[2, j] for j in range(coef.shape[1])])
    np.testing.assert_allclose(ste_forcing[1:], ref[2, 1:], rtol=0, atol=1e-12)  # ω² l² ε_l
    assert V @ Mi @ F == pytest.approx(model.fp, abs=1e-12)
    assert a.D[0] == pytest.approx(model.D, abs=1e-12)
    assert s.omega == pytest.approx(model.omega, rel=1e-12)
    # the other mode is the rigid-body rotation of the pair (q̃1 = q̃2: no bearing, V·(1, 1) = 0)
    assert np.all(a.Kb == 0.0) and np.all(a.Cb == 0.0)
    assert abs(V @ np.array([1.0, 1.0])) < 1e-15
    assert list(modal_analysis(s.description).rigid) == [True, False]


def test_omega_from_rpm_matches_the_1dof_configuration_and_can_be_overridden():
    cfg = load_config()
    s = load_system(TORSIONAL)
    assert s.scaling.rpm_from_omega(s.omega) == pytest.approx(cfg.rpm, rel=1e-12)
    assert s.scaling.omega_n_rad_s == pytest.approx(cfg.pair.omega_n, rel=1e-12)
    assert load_system(TORSIONAL, omega=0.8).omega == 0.8


# ---------------------------------------------------------------------------- the protocol
def test_system_model_implements_the_protocol():
    s = load_system(TORSIONAL)
    assert isinstance(s, System)
    assert s.state_dim == 4 and s.n == 2
    assert s.period == pytest.approx(2 * math.pi / s.omega)
    assert s.get("mesh.kappa1") == pytest.approx(0.2) and s.get("kappa1") == s.get("mesh.kappa1")
    assert s.get("mesh.kappa3") == 0.0 and s.get("fe") == pytest.approx(0.5)
    s2 = s.with_param("mesh.kappa1", 0.1).with_param("omega", 0.8).with_param("mesh.phi_e2", 0.3)
    assert s2.get("kappa1") == 0.1 and s2.omega == 0.8 and s2.mesh("mesh").eps == (0.5, 0.0)
    assert s.get("kappa1") == pytest.approx(0.2)  # frozen: the original is unchanged
    p = s.parameters()
    assert {"omega", "mesh.kappa1", "mesh.xi0", "mesh.D", "mesh.ratio"} <= set(p)
    (b,) = s.contact_boundaries()
    assert b.element == "mesh" and b.gap == pytest.approx(1.0) and b.vector == pytest.approx((1, -1, 0, 0))
    with pytest.raises(ModelError, match="sum of .kappa"):
        s.with_param("mesh.kappa1", 1.2)
    with pytest.raises(ModelError, match="unknown mesh"):
        s.get("nomesh.kappa1")


def test_pack_contract_shapes_and_dtypes():
    s = load_system(EXAMPLES / "paper_bevel_8dof.toml")
    batch = [s.with_param("omega", w) for w in (0.5, 0.8, 1.2)]
    a = SystemModel.pack(batch)
    n, m = 8, 1
    shapes = {
        "Mi": (3, n, n),
        "Kb": (3, n, n),
        "Cb": (3, n, n),
        "V": (3, m, n),
        "coef": (3, m, 3, 2, 2),
        "D": (3, m),
        "ratio": (3, m),
        "F": (3, n),
        "Vc": (3, 0, n),
        "kc": (3, 0),
        "cc": (3, 0),
        "Dc": (3, 0),
        "omega": (3,),
    }
    for name, shape in shapes.items():
        arr = getattr(a, name)
        assert arr.shape == shape, name
        assert arr.dtype == np.float64 and arr.flags.c_contiguous, name
    assert list(a.omega) == [0.5, 0.8, 1.2]
    np.testing.assert_allclose(a.Mi[0], a.Mi[0].T)
    assert np.all(np.linalg.eigvalsh(a.Mi[0]) > 0)
    with pytest.raises(ModelError, match="same DOFs"):
        SystemModel.pack([s, load_system(TORSIONAL)])
    with pytest.raises(ModelError, match="empty"):
        SystemModel.pack([])


def _two_mesh(ratio2: float) -> SystemDescription:
    bodies = (
        Body("a", ("theta",), inertia=1.0),
        Body("b", ("theta",), inertia=2.0),
        Body("c", ("theta",), inertia=3.0),
    )
    m1 = Mesh("m1", ((("a", "theta"), 0.1), (("b", "theta"), -0.2)), 1e8, backlash=1e-4, kappa=(0.1,))
    m2 = Mesh("m2", ((("b", "theta"), 0.1), (("c", "theta"), -0.3)), 2e8, backlash=1e-4, ratio=ratio2)
    return SystemDescription(bodies=bodies, meshes=(m1, m2))


def test_commensurate_and_incommensurate_mesh_frequencies():
    assert assemble(_two_mesh(2.0)).period_multiple() == 1
    s = assemble(_two_mesh(0.5))
    assert s.period_multiple() == 2 and s.forcing_period == pytest.approx(2 * s.period)
    assert assemble(_two_mesh(47 / 23)).period_multiple() == 23
    q = assemble(_two_mesh(math.sqrt(2)))
    assert q.period_multiple() is None
    with pytest.raises(ModelError, match="incommensurate") as e:
        _ = q.forcing_period
    assert "\n" not in str(e.value)


def test_geometry_vectors_spur_and_bevel():
    s = load_description(EXAMPLES / "spur_bending_torsional.toml")
    v = s.vector(s.meshes[0])
    a = math.radians(20)
    np.testing.assert_allclose(v, [math.sin(a), math.cos(a), 23.8682e-3, -math.sin(a), -math.cos(a), -71.6047e-3])
    b = load_description(EXAMPLES / "paper_bevel_8dof.toml")
    pair = load_config().pair
    mv = pair.mesh_vectors()
    v = b.vector(b.meshes[0])
    np.testing.assert_allclose(v[:3], mv.n1, atol=1e-15)
    np.testing.assert_allclose(v[4:7], -mv.n1, atol=1e-15)
    assert v[3] == pytest.approx(pair.R1, rel=1e-14) and v[7] == pytest.approx(-pair.R2, rel=1e-14)


def test_every_example_loads_and_marks_its_assumptions():
    for f in sorted(EXAMPLES.glob("*.toml")):
        d = load_description(f)
        s = assemble(d)
        assert np.all(np.isfinite(s.Mi)), f.name
        assert d.assumptions, f.name
        json.dumps([a.to_dict() for a in d.assumptions])
    names = {a.name for a in load_description(TORSIONAL).assumptions}
    assert {"mesh.stiffness", "mesh.hand", "mesh.drive_side", "operating.rpm"} <= names


def test_defaults_are_marked_assumed(tmp_path):
    p = tmp_path / "min.toml"
    p.write_text(_MIN)
    d = load_description(p)
    names = {a.name for a in d.assumptions}
    assert {"mesh.xi0", "operating.omega"} <= names
    assert d.meshes[0].xi0 == 0.1


# ---------------------------------------------------------------------------- bad files
_MIN = """title = "minimal"
[[body]]
name = "p"
dofs = ["theta"]
inertia = "1 kg*m^2"
[[body]]
name = "g"
dofs = ["theta"]
inertia = "2 kg*m^2"
[[mesh]]
name = "mesh"
vector = { p = { theta = "50 mm" }, g = { theta = "-100 mm" } }
stiffness = "1e8 N/m"
backlash = "0.1 mm"
"""

_EXTRA_BODY = """[[body]]
name = "lonely"
dofs = ["x"]
mass = "3 kg"
"""

BAD = {
    "negative mass": (
        _MIN.replace(
            'dofs = ["theta"]\ninertia = "2 kg*m^2"', 'dofs = ["theta", "x"]\ninertia = "2 kg*m^2"\nmass = "-1 kg"'
        ),
        ModelError,
        "mass",
        "'g'",
    ),
    "zero inertia": (_MIN.replace('inertia = "1 kg*m^2"', 'inertia = "0 kg*m^2"'), ModelError, "inertia", "'p'"),
    "unknown body": (
        _MIN + '[[connection]]\nname = "brg"\nbody = "pinon"\nkx = "1e8 N/m"\n',
        ModelError,
        "pinon",
        "'brg'",
    ),
    "singular mass matrix": (
        _MIN + '[[body]]\nname = "s"\ndofs = ["x", "y"]\nmass_matrix = [[1.0, 1.0], [1.0, 1.0]]\n'
        '[[connection]]\nname = "b"\nbody = "s"\nkx = "1e8 N/m"\n',
        ModelError,
        "mass_matrix",
        "'s'",
    ),
    "body with no connection": (_MIN + _EXTRA_BODY, ModelError, 'name = "lonely"', "'lonely'"),
    "unknown key": (
        _MIN.replace('stiffness = "1e8 N/m"', 'stiffness = "1e8 N/m"\nstifness = "1e8 N/m"'),
        ConfigError,
        "stifness",
        "'mesh'",
    ),
    "unknown section": (_MIN + "[gearbox]\nx = 1\n", ConfigError, "[gearbox]", "gearbox"),
    "wrong units": (_MIN.replace('inertia = "2 kg*m^2"', 'inertia = "2 kg"'), ConfigError, "inertia", "'g'"),
    "wrong unit of a stiffness": (
        _MIN.replace('stiffness = "1e8 N/m"', 'stiffness = "1e8 N"'),
        ConfigError,
        "stiffness",
        "'mesh'",
    ),
    "TOML syntax": (_MIN.replace('name = "mesh"', 'name = "mesh'), ConfigError, 'name = "mesh', "TOML"),
    # the reference mesh's backlash is read first (the characteristic length): a KeyError escaped there before
    "inline table without its value": (
        _MIN.replace('backlash = "0.1 mm"', 'backlash = { assumed = "typical" }'),
        ConfigError,
        "backlash",
        "inline table must have the keys 'value'",
    ),
    "phases for fewer harmonics": (
        _MIN.replace('stiffness = "1e8 N/m"', 'stiffness = "1e8 N/m"\nkappa = [0.2, 0.1]\nphi_k = ["0 deg"]'),
        ModelError,
        "phi_k",
        "1 phases for 2 kappa harmonics",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_files_are_refused_with_one_line_naming_file_line_and_element(tmp_path, case):
    text, exc, line_has, element = BAD[case]
    p = tmp_path / "bad.toml"
    p.write_text(text)
    before = sorted(tmp_path.iterdir())
    with pytest.raises(exc) as e:
        load_system(p)
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(str(p) + ": line "), msg
    assert element in msg, msg
    n = int(re.match(r".*?: line (\d+):", msg).group(1))
    assert line_has in text.splitlines()[n - 1], (msg, text.splitlines()[n - 1])
    assert sorted(tmp_path.iterdir()) == before  # nothing written


def test_missing_file_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_system(tmp_path / "nope.toml")


def test_python_description_validates():
    b = (Body("p", ("theta",), inertia=1.0), Body("g", ("theta",), inertia=1.0))
    m = Mesh("m", ((("p", "theta"), 0.1), (("g", "theta"), -0.1)), 1e8, backlash=1e-4)
    with pytest.raises(ModelError, match="unknown body 'q'"):
        SystemDescription(bodies=b, meshes=(m,), connections=(Connection.diagonal("c", "q", {"x": 1.0}),))
    with pytest.raises(ModelError, match="has no DOF 'x'"):
        SystemDescription(bodies=b, meshes=(m,), loads=(Load("p", "x", 1.0),))
    with pytest.raises(ModelError, match="mass: must be > 0"):
        Body("p", ("x",), mass=-2.0)
    with pytest.raises(ModelError, match="no gear mesh"):
        SystemDescription(bodies=b, meshes=())


def test_clearance_element_in_the_arrays_and_boundaries(tmp_path):
    p = tmp_path / "clear.toml"
    p.write_text(
        _MIN.replace(
            'dofs = ["theta"]\ninertia = "2 kg*m^2"', 'dofs = ["x", "theta"]\ninertia = "2 kg*m^2"\nmass = "4 kg"'
        )
        + '[[connection]]\nname = "gap"\nvector = { g = { x = 1 } }\nstiffness = "1e8 N/m"\n'
        'damping = "10 N*s/m"\nclearance = "0.02 mm"\n'
    )
    s = load_system(p)
    a = s.arrays()
    assert s.clearance_names == ("gap",) and a.Vc.shape == (1, 3)
    assert a.Dc[0] == pytest.approx(0.02e-3 / 0.05e-3)
    assert a.kc[0] == pytest.approx(1.0)  # k / k_ref
    assert [b.element for b in s.contact_boundaries()] == ["mesh", "gap"]
    assert s.with_param("gap.D", 0.5).Dc == (0.5,)
    assert np.all(a.Kb == 0.0)  # a clearance is not a linear connection
    d = s.description
    assert modal_analysis(d, clearances="open").rigid.sum() == 2
    assert modal_analysis(d, clearances="contact").rigid.sum() == 1


def test_system_map_continued_rows_follow_the_1dof_map_and_its_coexisting_branch():
    """``mode="continue"``: each row continues along x from its left neighbour.  On the torsional pair
    (which reduces exactly to the 1-DOF model) the continued map equals the 1-DOF continued map
    (default mode, to 1e-9; the accurate mode is held to the 1-DOF model in tests/test_conformance.py), stays on
    the upper branch of the hysteresis at ξ0 = 0.05 where the fixed-start map drops to the lower one, and each
    row equals the system's continuation sweep."""
    from geardyn.analysis.bifurcation import bifurcation
    from geardyn.analysis.maps import parameter_map
    from geardyn.model import GearModel, IntegrationOptions

    def system_map(*a, **k):
        return parameter_map(*a, settle_periods=0, **k)

    s = load_system(TORSIONAL)
    xv, yv = np.linspace(0.5, 0.7, 6), np.array([0.05, 0.08])
    o = IntegrationOptions(transient=50, periods=8)
    cont = system_map(s, "omega", xv, "mesh.xi0", yv, mode="continue", options=o)
    fixed = system_map(s, "omega", xv, "mesh.xi0", yv[:1], mode="fixed", options=o)
    one = parameter_map(GearModel(), "omega", xv, "xi0", yv, mode="continue", options=o, settle_periods=0)
    assert cont.attrs["mode"] == "continue"
    for k in ("u_min", "u_max", "amplitude"):
        np.testing.assert_allclose(cont[k].values, one[k].values, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(cont["period"].values, one["period"].values)
    # at ξ0 = 0.05 and ω = 0.64 the continued row is still on the upper branch (u_max ≈ 2.38), the
    # points started from rest are on the lower one (≈ 1.99)
    assert cont["u_max"].values[0, 3] > fixed["u_max"].values[0, 3] + 0.3
    for j, y in enumerate(yv[:1]):  # one row: every row is continued the same way
        row = bifurcation(
            s.with_param("mesh.xi0", float(y)), "omega", list(xv), mode="continue", options=o, settle_periods=0
        )
        np.testing.assert_array_equal(row["u_max"].values.ravel(), cont["u_max"].values[j])
    with pytest.raises(ModelError, match="mode"):
        system_map(s, "omega", xv, "mesh.xi0", yv, mode="sideways", options=o)
