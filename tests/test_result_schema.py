"""One Dataset schema per kind for every System, results that reopen as their System, files of 0.1.0 still read;
the Batch protocol and the element laws of the contract."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from cli_run import run_cli

from geardyn.model import GearModel, IntegrationOptions

ROOT = Path(__file__).resolve().parents[1]
TORS = str(ROOT / "examples" / "systems" / "paper_torsional.toml")
#: A pair bifurcation written by geardyn 0.1.0 (continuation up and down over ω; start_u/start_v/end_u/end_v).
OLD_BIFURCATION = Path(__file__).resolve().parent / "data" / "v0_1_0" / "bifurcation.nc"
SWEEP = ("--param", "omega", "--start", "0.8", "--stop", "1.0", "--num", "3", "--transient", "5", "--periods", "4")


def _run(*args: str) -> str:
    code, out, err = run_cli(args)
    assert code == 0, err
    return out


def test_a_bifurcation_has_the_same_variables_with_and_without_system(tmp_path):
    """``geardyn bifurcation`` on the pair and on the torsional system (the same pair as a 2-DOF system) writes
    Datasets with the same variables and dimensions; each reopens as the System it was computed on."""
    from geardyn.systems import SystemModel, load_system

    _run("bifurcation", *SWEEP, "--settle", "0", "--out", str(tmp_path / "pair"))
    _run("bifurcation", "--system", TORS, *SWEEP, "--settle", "0", "--out", str(tmp_path / "sys"))
    with (
        xr.open_dataset(tmp_path / "pair" / "bifurcation.nc") as a,
        xr.open_dataset(tmp_path / "sys" / "bifurcation.nc") as b,
    ):
        assert set(a.variables) == set(b.variables)
        assert {k: a[k].dims for k in a.variables} == {k: b[k].dims for k in b.variables}
        assert {"start_state", "end_state", "state"} <= set(a.variables)
        assert not {"start_u", "start_v", "end_u", "end_v"} & set(a.variables)
        assert list(a["state"].values) == ["u", "u'"] and a["end_state"].dims == ("sweep", "omega", "state")
        assert isinstance(a.geardyn.model, GearModel) and a.geardyn.model == GearModel()
        s = b.geardyn.model
        assert isinstance(s, SystemModel)
        ref = load_system(TORS)
        assert s.labels == ref.labels and s.meshes == ref.meshes and s.omega == ref.omega
        for k in ("Mi", "Kb", "Cb", "V", "F"):
            np.testing.assert_array_equal(getattr(s, k), getattr(ref, k))
        # the rebuilt system integrates to the numbers stored (bit for bit: the same arrays)
        from geardyn.integrate import integrate_batch

        opts = IntegrationOptions(transient=5, periods=4)
        r = integrate_batch([s.with_param("omega", 0.9)], b["start_state"].values[0, 1], opts)
        np.testing.assert_array_equal(r.end_state[0], b["end_state"].values[0, 1])


def test_a_pair_bifurcation_of_0_1_0_is_read_and_redrawn(tmp_path):
    """The fixture was written by geardyn 0.1.0 (``geardyn bifurcation --mode continue --sweep both``).  Read, its
    start and end states are ``start_state``/``end_state`` over ``state`` = (u, u'), equal to the components it
    stored; ``geardyn plot`` redraws it."""
    from geardyn.io import read_netcdf

    with xr.open_dataset(OLD_BIFURCATION) as raw:
        raw = raw.load()
    assert {"start_u", "start_v", "end_u", "end_v"} <= set(raw.variables)
    ds = read_netcdf(OLD_BIFURCATION)
    assert not {"start_u", "start_v", "end_u", "end_v"} & set(ds.variables)
    np.testing.assert_array_equal(ds["start_state"].sel(state="u"), raw["start_u"])
    np.testing.assert_array_equal(ds["start_state"].sel(state="u'"), raw["start_v"])
    np.testing.assert_array_equal(ds["end_state"].sel(state="u"), raw["end_u"])
    np.testing.assert_array_equal(ds["end_state"].sel(state="u'"), raw["end_v"])
    assert ds.geardyn.model == GearModel.from_dict(json.loads(raw.attrs["model"]))
    r = json.loads(_run("plot", str(OLD_BIFURCATION), "--out", str(tmp_path), "--json"))
    assert r["files"] and all(Path(f).stat().st_size > 0 for f in r["files"])
    assert any(Path(f).name == "bifurcation.png" for f in r["files"])


def test_a_0_1_0_file_read_equals_todays_sweep_and_confirms_alike():
    """The same sweep run today gives the 0.1.0 file's numbers bit for bit (the pair's numbers are unchanged) with
    the states under today's names; :func:`confirm_sweep`, which starts from ``end_state``, decides alike on both."""
    from geardyn.analysis.bifurcation import bifurcation
    from geardyn.analysis.confirm import confirm_sweep
    from geardyn.io import read_netcdf

    old = read_netcdf(OLD_BIFURCATION)
    opts = IntegrationOptions(**json.loads(old.attrs["options"]))
    new = bifurcation(
        GearModel(), "omega", old["omega"].values, mode="continue", sweep="both", options=opts, settle_periods=0
    )
    for k in ("start_state", "end_state", "poincare_u", "poincare_v", "motion", "period", "amplitude"):
        np.testing.assert_array_equal(new[k].values, old[k].values)
    assert new["end_state"].dims == old["end_state"].dims
    pick = {"omega": slice(0, 4)}
    a = confirm_sweep(old.isel(pick), GearModel(), "omega", long_periods=60)
    b = confirm_sweep(new.isel(pick), GearModel(), "omega", long_periods=60)
    for k in ("motion", "period", "confirmed"):
        np.testing.assert_array_equal(a[k].values, b[k].values)


def test_no_analysis_asks_which_kind_of_system_it_has():
    """No ``isinstance`` test of a model class or of the pair's batch in the analyses (the backend supplies the
    batch: :meth:`geardyn.backend.Backend.points`)."""
    pat = re.compile(r"isinstance\([^)]*(GearModel|SystemModel|PointModels)")
    bad = [
        f"{p.relative_to(ROOT)}:{i}"
        for p in sorted((ROOT / "src" / "geardyn" / "analysis").rglob("*.py"))
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if pat.search(line)
    ]
    assert not [b for b in bad if "/hb/" not in b], bad


def test_the_two_batches_answer_alike():
    """The pair's points packed from a grid and the list of their models: the same kernel arrays, sampling periods,
    steps, gaps and reference section."""
    from geardyn.grid import point_models
    from geardyn.pairpack import PointModels
    from geardyn.system import ModelList, build_models

    names, pts = ["omega", "D"], np.array([[0.5, 1.0], [0.9, 0.5], [1.7, 0.0]])
    pm = point_models(GearModel(), names, pts)
    ml = ModelList(build_models(GearModel(), names, pts))
    assert isinstance(pm, PointModels)
    for a, b in zip(pm.packed(), ml.packed()):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(pm.sampling_periods(), ml.sampling_periods())
    np.testing.assert_array_equal(pm.sampling_periods(), [2 * np.pi / w for w in (0.5, 0.9, 1.7)])
    np.testing.assert_array_equal(pm.natural_steps(0.01), ml.natural_steps(0.01))
    np.testing.assert_array_equal(pm.reference_gaps(), [1.0, 0.5, 0.0])
    np.testing.assert_array_equal(ml.element_gaps(), pm.element_gaps())
    pc = np.random.default_rng(1).normal(size=(3, 4, 2))
    np.testing.assert_array_equal(pm.reference_section(pc), ml.reference_section(pc))
    assert isinstance(pm[[0, 2]], PointModels) and pm[[0, 2]][1] == ml[2]
    assert isinstance(ml[1:], ModelList) and ml[1:][0] == pm[1]


def test_the_dead_zone_law_is_the_pairs_restoring_function_and_names_its_counters():
    """The default law of an element is the dead zone of its half gap: its force is the model's f(u; D), its counters
    are the contact fractions a run reports (drive u > D, separation, back u < −D), read by the law's names."""
    from geardyn.backend import S_LAW, S_N
    from geardyn.integrate import integrate_batch
    from geardyn.system import LAW_COUNTERS, DeadZone, Element

    m = GearModel(D=0.7)
    (el,) = m.elements
    assert el.law == DeadZone(0.7) and Element("x", 0.7).law == el.law
    u = np.linspace(-3, 3, 61)
    np.testing.assert_array_equal(el.law.force(u), m.restoring(u))
    assert el.law.surfaces() == (-0.7, 0.7) and S_N == S_LAW + LAW_COUNTERS
    # the fractions of a run against the samples of its trajectory, counted by the law
    from geardyn.integrate import trajectory

    opts = IntegrationOptions(transient=50, periods=8)
    t = trajectory(m, (0.0, 0.0), opts, history_periods=8)
    counts = np.bincount(el.law.counter(t.x[1:, 0]), minlength=3) / (t.x.shape[0] - 1)
    res = integrate_batch([m], (0.0, 0.0), opts)
    fr = res.law_fractions()
    assert list(fr) == ["drive", "separation", "back"]
    np.testing.assert_allclose([fr[k][0] for k in fr], counts, atol=2.0 / (t.x.shape[0] - 1))
    np.testing.assert_array_equal(res.contact_fractions[0], [fr[k][0] for k in fr])


@pytest.mark.parametrize("kind", ["pair", "system"])
def test_a_result_reopens_as_its_system(kind):
    from geardyn.analysis.steady import simulate
    from geardyn.systems import load_system

    model = GearModel(omega=0.7, kappa=(0.1, 0.02)) if kind == "pair" else load_system(TORS, omega=0.7)
    ds = simulate(model, IntegrationOptions(transient=3, periods=4), history_periods=2).to_dataset()
    back = ds.geardyn.model
    assert type(back) is type(model)
    if kind == "pair":
        assert back == model
    else:
        assert back.to_attrs() == model.to_attrs()
