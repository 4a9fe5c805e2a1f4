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
    batch: :meth:`geardyn.backend.Backend.points`).  Harmonic balance (``hb/``, being moved onto the contract) and
    the pair's rattle analysis (``rattle.py``, which refuses a system) are checked by their own work."""
    pat = re.compile(r"isinstance\([^)]*(GearModel|SystemModel|PointModels)")
    pending = ("analysis/hb/", "analysis/rattle.py")
    bad = [
        f"{p.relative_to(ROOT)}:{i}"
        for p in sorted((ROOT / "src" / "geardyn" / "analysis").rglob("*.py"))
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if pat.search(line) and not any(k in p.as_posix() for k in pending)
    ]
    assert not bad, bad


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


def test_a_simulate_result_has_the_same_variables_for_the_pair_and_a_system():
    """``simulate`` of the pair and of the torsional system: the same variables over the same dimensions (every
    element's deflection and the full Poincaré states over ``element`` and ``state``); the pair's are its (u, u')."""
    from geardyn.analysis.steady import simulate
    from geardyn.systems import load_system

    opts = IntegrationOptions(transient=3, periods=4)
    a = simulate(GearModel(omega=0.8), opts, history_periods=2).to_dataset()
    b = simulate(load_system(TORS, omega=0.8), opts, history_periods=2).to_dataset()
    assert {k: a[k].dims for k in a.variables} == {k: b[k].dims for k in b.variables}
    np.testing.assert_array_equal(a["delta"].sel(element="mesh"), a["u"])
    np.testing.assert_array_equal(a["delta_rate"].sel(element="mesh"), a["v"])
    np.testing.assert_array_equal(a["poincare"].sel(state="u"), a["poincare_u"])
    assert list(a["state"].values) == ["u", "u'"]


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


def test_one_scales_for_the_pair_and_its_system():
    """The torsional system is the paper's pair as a 2-DOF system: its scales (those of its reference mesh) are the
    pair's, every conversion agrees, and the operating points have the same keys (a system has no single torque)."""
    from geardyn.config import load_config
    from geardyn.geometry.scales import PhysicalScales, Scales
    from geardyn.systems import load_system
    from geardyn.systems.report import physical_scales

    pair = load_config().scales
    s = load_system(TORS)
    sys_sc = physical_scales(s)
    assert PhysicalScales is Scales and type(pair) is type(sys_sc) is Scales
    for k in ("b_c_m", "k0_N_per_m", "m_e_kg", "omega_n_rad_s", "z1", "D"):
        assert getattr(sys_sc, k) == pytest.approx(getattr(pair, k), rel=1e-12), k
    for f, x in (("rpm_from_omega", 0.8), ("hz_from_omega", 0.8), ("um_from_u", 1.5), ("N_from_force", 0.3)):
        assert float(getattr(sys_sc, f)(x)) == pytest.approx(float(getattr(pair, f)(x)), rel=1e-12), f
    a, b = pair.operating_point(GearModel(omega=0.8)), sys_sc.operating_point(s.with_param("omega", 0.8))
    assert a.keys() == b.keys() and b["torque_N_m"] is None and b["fp"] is None
    assert b["rpm"] == pytest.approx(a["rpm"], rel=1e-12)
    assert b["static_force_N"] == pytest.approx(a["static_force_N"], rel=1e-9)
    assert Scales.from_json(sys_sc.to_json()) == sys_sc and Scales.from_json(pair.to_json()) == pair
    nt = Scales.of_reference_mesh("m", 1e8, 2.0, 1e-5, (1e-5,), None)
    assert np.isnan(nt.rpm_from_omega(1.0))
    with pytest.raises(Exception, match="teeth"):
        nt.omega_from_rpm(1000.0)
    assert float(Scales.dynamic_factor(3.0, 2.0)) == 1.5 and np.isnan(Scales.dynamic_factor(1.0, 0.0))


def test_a_rolling_element_bearing_is_one_more_law():
    """The law interface takes the gearbox's nonlinear bearing as a value: a radial Hertzian bearing of Z rolling
    elements, force K Σ_j max(δ cos ψ_j − c, 0)^n (ψ_j = 2πj/Z), written as a :class:`Law` subclass here, is
    carried by an element and names its own counters in a run's statistics; nothing else changes."""
    from dataclasses import dataclass
    from typing import ClassVar

    from geardyn.backend import NSTAT, S_LAW, S_N
    from geardyn.integrate import BatchResult
    from geardyn.system import Element, Law, ModelList

    @dataclass(frozen=True)
    class Hertz(Law):
        K: float
        c: float
        n: float
        Z: int

        code: ClassVar[int] = 1
        name: ClassVar[str] = "hertz_bearing"
        counters: ClassVar[tuple[str, ...]] = ("loaded", "unloaded")

        def _psi(self):
            return 2 * np.pi * np.arange(self.Z) / self.Z

        def params(self):
            return (self.K, self.c, self.n, float(self.Z))

        def force(self, delta):
            d = np.asarray(delta, dtype=float)[..., None] * np.cos(self._psi())
            return self.K * np.sum(np.maximum(d - self.c, 0.0) ** self.n * np.cos(self._psi()), axis=-1)

        def stiffness(self, delta):
            d = np.asarray(delta, dtype=float)[..., None] * np.cos(self._psi())
            act = d > self.c
            g = self.n * np.where(act, np.maximum(d - self.c, 0.0), 0.0) ** (self.n - 1)
            return self.K * np.sum(np.where(act, g, 0.0) * np.cos(self._psi()) ** 2, axis=-1)

        def surfaces(self):
            return (self.c,)

        def counter(self, delta):
            return np.where(np.abs(np.asarray(delta, dtype=float)) > self.c, 0, 1)

    law = Hertz(K=2.0, c=0.1, n=1.5, Z=4)
    el = Element("bearing", 0.1, "clearance", law)
    assert el.law is law and el.law.code != Element("mesh", 0.1).law.code
    # δ = 0.5 along ψ = 0: only the element at ψ = 0 is loaded (ψ = π/2, 3π/2 at δ cos ψ = 0, ψ = π unloaded)
    assert float(law.force(0.5)) == pytest.approx(2.0 * 0.4**1.5, rel=1e-12)
    h = 1e-6
    assert float(law.stiffness(0.5)) == pytest.approx(float(law.force(0.5 + h) - law.force(0.5 - h)) / (2 * h), 1e-6)

    class _Point:
        elements = (el,)
        reference = 0

    stats = np.zeros((1, 1, NSTAT))
    stats[0, 0, S_LAW : S_LAW + 2] = (30.0, 70.0)
    stats[0, 0, S_N] = 100.0
    res = BatchResult(
        ModelList([_Point()]),
        IntegrationOptions(),
        np.zeros((1, 1, 2)),
        np.zeros((1, 2)),
        np.zeros(1, dtype=np.int64),
        stats,
        np.ones(1, dtype=np.int64),
        elements=("bearing",),
        laws=(law,),
    )
    assert {k: float(v[0]) for k, v in res.law_fractions().items()} == {"loaded": 0.3, "unloaded": 0.7}
    # until a kernel has its branch, the door refuses it in one line (never integrated as a dead zone)
    from geardyn.errors import ModelError
    from geardyn.integrate import integrate_batch

    class WithBearing(GearModel):
        @property
        def elements(self):
            return (Element("mesh", self.D, "mesh", law),)

    with pytest.raises(ModelError, match=r"^element 'mesh': law hertz_bearing: the pair kernel does not implement it"):
        integrate_batch([WithBearing()], None, IntegrationOptions(transient=1, periods=1))


def test_a_systems_physical_mesh_force_is_its_reference_meshs():
    """``add_physical`` of a system's ``simulate`` result draws the force its reference mesh transmits (from every
    element's deflection and the system it reopens as); for the torsional system, the paper's pair as a 2-DOF
    system, that is the pair's mesh force (the two integrations agree to about 1e-10)."""
    from geardyn.analysis.physical import add_physical
    from geardyn.analysis.steady import simulate
    from geardyn.config import load_config
    from geardyn.systems import load_system
    from geardyn.systems.report import physical_scales

    s = load_system(TORS, omega=0.8)
    opts = IntegrationOptions(transient=300, periods=8)
    a = add_physical(simulate(s, opts, history_periods=2).to_dataset(), physical_scales(s))
    b = add_physical(simulate(GearModel(omega=0.8), opts, history_periods=2).to_dataset(), load_config())
    np.testing.assert_allclose(a["mesh_force"].values, b["mesh_force"].values, atol=1e-8)
    scale = physical_scales(s).force_scale_N
    np.testing.assert_allclose(a["mesh_force_N"].values, b["mesh_force_N"].values, atol=1e-8 * scale)
