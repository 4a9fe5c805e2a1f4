"""One grid for every sweep (ranges, products, curves, initial states) and the engine options object."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import xarray as xr

from geardyn.grid import Grid, build_models, linspace_values
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.sweep import SweepOptions

FAST = IntegrationOptions(transient=40, periods=16)


def test_range_sorts_canonicalises_and_validates():
    g = Grid.range("backlash", [0.3, 0.1, 0.3, 0.2])
    assert g.kind == "range" and g.names == ("D",) and g.shape == (3,) and g.size == len(g) == 3
    np.testing.assert_array_equal(g.values("D"), [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(g.points(slice(1, 3)), [[0.2], [0.3]])
    assert [m.D for m in g.models(GearModel(), slice(0, 2))] == [0.1, 0.2]
    with pytest.raises(ModelError, match=r"^omega: empty grid"):
        Grid.range("omega", [])
    with pytest.raises(ModelError, match=r"^xi0: values must be finite"):
        Grid.range("xi0", [0.1, np.nan])
    with pytest.raises(ModelError, match="unknown parameter"):
        Grid.range("zeta", [1.0])


def test_linspace_messages():
    np.testing.assert_array_equal(Grid.linspace("omega", 0.5, 1.5, 3).values("omega"), [0.5, 1.0, 1.5])
    with pytest.raises(ModelError, match=r"^start: must be a finite number"):
        linspace_values(np.nan, 1.0, 3)
    with pytest.raises(ModelError, match=r"^u0 num: must be an integer >= 1"):
        linspace_values(0.0, 1.0, 0, label="u0")


def test_product_is_row_major_and_matches_the_models_of_its_points():
    g = Grid.product(("xi0", [0.05, 0.1]), ("omega", [0.8, 0.9, 1.0]))
    assert g.shape == (2, 3) and g.size == 6
    pts = g.points()
    np.testing.assert_array_equal(pts[:, 0], [0.05] * 3 + [0.1] * 3)
    np.testing.assert_array_equal(pts[:, 1], [0.8, 0.9, 1.0] * 2)
    np.testing.assert_array_equal(g.points(slice(2, 5)), pts[2:5])
    base = GearModel()
    want = [base.with_param("xi0", x).with_param("omega", w) for x in (0.05, 0.1) for w in (0.8, 0.9, 1.0)]
    assert g.models(base) == want
    assert [s.indices(6) for s in g.slices(4)] == [(0, 4, 1), (4, 6, 1)]
    with pytest.raises(ModelError, match="at most once"):
        Grid.product(("omega", [1.0]), ("omega", [2.0]))
    with pytest.raises(ModelError, match="at least one parameter"):
        Grid.product()


def test_curve_lists_points_together():
    g = Grid.curve({"omega": [0.8, 1.0, 1.2], "xi0": [0.1, 0.05, 0.02]})
    assert g.kind == "curve" and g.shape == (3,)
    ms = g.models(GearModel())
    assert [(m.omega, m.xi0) for m in ms] == [(0.8, 0.1), (1.0, 0.05), (1.2, 0.02)]
    with pytest.raises(ModelError, match="one value per point"):
        Grid.curve({"omega": [0.8, 1.0], "xi0": [0.1]})


def test_state_grid_rows_of_v0_u_fastest():
    g = Grid.states([-1.0, 0.0, 1.0], [0.0, 0.5])
    assert g.names == ("v0", "u0") and g.shape == (2, 3)
    s = g.state_points()
    np.testing.assert_array_equal(s[:, 0], [-1.0, 0.0, 1.0] * 2)
    np.testing.assert_array_equal(s[:, 1], [0.0] * 3 + [0.5] * 3)
    with pytest.raises(ModelError, match="no parameter points"):
        g.models(GearModel())
    with pytest.raises(ModelError, match="not initial states"):
        Grid.range("omega", [1.0]).state_points()


def test_build_models_applies_names_in_order():
    ms = build_models(GearModel(), ("fe", "omega"), np.array([[0.2, 0.9]]))
    assert ms[0].omega == 0.9 and ms[0] == GearModel().with_param("eps1", 0.2).with_param("omega", 0.9)


def test_sweep_options_validate_and_merge():
    o = SweepOptions.merge(None, "f", workers=2, progress=True)
    assert (o.workers, o.progress, o.points_per_chunk(16)) == (2, True, 16)
    assert SweepOptions.merge(o, "f", chunk_points=4).points_per_chunk(16) == 4
    with pytest.raises(ModelError, match="^workers: "):
        SweepOptions(workers=0)
    with pytest.raises(ModelError, match="^chunk size: "):
        SweepOptions(chunk_points=0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'worker'"):
        SweepOptions.merge(None, "f", worker=2)
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.workers = 3  # frozen


def test_analyses_take_one_options_object_or_the_keywords():
    from geardyn.analysis.bifurcation import bifurcation
    from geardyn.analysis.maps import parameter_map

    vals = np.linspace(0.8, 1.2, 5)
    a = bifurcation(GearModel(), "omega", vals, options=FAST, settle_periods=0, chunk_points=2)
    b = bifurcation(GearModel(), "omega", vals, options=FAST, settle_periods=0, engine=SweepOptions(chunk_points=3))
    xr.testing.assert_identical(a, b)
    with pytest.raises(TypeError, match="bifurcation\\(\\) got an unexpected keyword argument 'chunks'"):
        bifurcation(GearModel(), "omega", vals, options=FAST, chunks=2)
    m1 = parameter_map(
        GearModel(), "omega", [0.9, 1.1], "xi0", [0.05, 0.1], options=FAST, settle_periods=0, mode="continue"
    )
    m2 = parameter_map(
        GearModel(),
        "omega",
        [0.9, 1.1],
        "xi0",
        [0.05, 0.1],
        options=FAST,
        settle_periods=0,
        mode="continue",
        engine=SweepOptions(chunk_points=1),
    )
    xr.testing.assert_identical(m1, m2)


def test_grid_over_a_systems_mesh_parameters():
    """A product over ω and the second stiffness harmonic of the second mesh of the planetary set: the
    names keep their element, the alias after the dot is spelled canonically, and every model is the
    base with the two parameters set (what ``with_param`` gives), the other meshes untouched."""
    from pathlib import Path

    from geardyn.grid import param_name, point_models
    from geardyn.pairpack import PointModels
    from geardyn.system import ModelList
    from geardyn.systems import load_system

    base = load_system(Path(__file__).resolve().parents[1] / "examples" / "systems" / "planetary_lin_parker_1999.toml")
    assert param_name("ring_planet1.kappa2") == "ring_planet1.kappa2"
    assert param_name("ring_planet1.backlash") == "ring_planet1.D"
    assert param_name("ring_planet1.k") == "ring_planet1.k"
    g = Grid.product(("omega", [0.5, 0.4]), ("ring_planet1.kappa2", [0.1, 0.0, 0.05]))
    assert g.names == ("omega", "ring_planet1.kappa2") and g.shape == (2, 3)
    ms = g.models(base)
    assert [(m.omega, m.get("ring_planet1.kappa2")) for m in ms] == [
        (0.4, 0.0),
        (0.4, 0.05),
        (0.4, 0.1),
        (0.5, 0.0),
        (0.5, 0.05),
        (0.5, 0.1),
    ]
    assert all(m.meshes[1].kappa[:1] == (0.0,) and m.meshes[0] == base.meshes[0] for m in ms)
    assert ms[2].meshes[1].kappa == (0.0, 0.1)
    g.check(base)
    assert g.lazy_models(base)[5].get("ring_planet1.kappa2") == 0.1
    np.testing.assert_array_equal(g.omegas(base), [0.4] * 3 + [0.5] * 3)
    pm = point_models(base, g.names, g.points())
    assert isinstance(pm, ModelList) and [m.get("omega") for m in pm] == [m.omega for m in ms]
    assert isinstance(point_models(GearModel(), ["omega"], np.array([[0.9]])), PointModels)
    with pytest.raises(ModelError):
        Grid.range("no_such_mesh.kappa1", [0.1]).check(base)
    with pytest.raises(ModelError, match="unknown parameter"):
        Grid.range("zeta", [1.0])


def test_system_sweep_over_the_backlash_of_the_second_mesh():
    """A system sweep over ``ring_planet1.backlash`` (an alias, spelled ``ring_planet1.D`` on the grid): its points are
    the direct integrations of the base set to each value (integrate_batch, one point at a time), in sorted order."""
    from pathlib import Path

    from geardyn.analysis.bifurcation import bifurcation
    from geardyn.integrate import integrate_batch
    from geardyn.systems import load_system

    base = load_system(Path(__file__).resolve().parents[1] / "examples" / "systems" / "planetary_lin_parker_1999.toml")
    opts = IntegrationOptions(transient=4, periods=3)
    ds = bifurcation(base, "ring_planet1.backlash", [1.2, 0.8], options=opts, settle_periods=0)
    assert ds.attrs["param"] == "ring_planet1.D"
    np.testing.assert_array_equal(ds["ring_planet1.D"].values, [0.8, 1.2])
    for i, v in enumerate((0.8, 1.2)):
        m = base.with_param("ring_planet1.D", v)
        ref = integrate_batch([m], None, opts)
        np.testing.assert_array_equal(ds["end_state"].values[0, i], ref.end_state[0])
        np.testing.assert_array_equal(ds["element_u_min"].values[0, i], ref.element_u_min()[0])
