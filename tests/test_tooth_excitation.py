"""The excitation as a table over one or several mesh cycles through the model's Fourier inputs."""

import numpy as np
import pytest

from geardyn.errors import ModelError
from geardyn.integrate import trajectory
from geardyn.model import GearModel, IntegrationOptions
from geardyn.tooth.excitation import Excitation, excitation_model, fourier_series, pair_model, series_table
from geardyn.tooth.faults import Crack
from geardyn.tooth.geometry import pair_geometry
from geardyn.tooth.mesh import mesh_stiffness

OPT = IntegrationOptions(dtau=0.02, transient=20, periods=5)
BASE = GearModel(omega=0.8, xi0=0.05, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=(), fp=1.0, D=0.2)


def _run(model, periods=5, steps=None, transient=20):
    return trajectory(
        model,
        (0.1, 0.0),
        IntegrationOptions(dtau=0.02, transient=transient, periods=periods),
        history_periods=periods,
        steps=steps,
    )


def test_constant_stiffness_table_equals_the_series_to_rounding():
    exc = Excitation(np.full(64, 3.2e8), np.full(64, 1e-6))
    m_table = excitation_model(BASE, exc)
    assert max(abs(k) for k in m_table.kappa) < 1e-15 and max(abs(e) for e in m_table.eps) < 1e-15
    a, b = _run(m_table), _run(BASE)
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-13)
    np.testing.assert_allclose(a.v, b.v, rtol=0, atol=1e-13)


def test_harmonics_given_both_ways_agree_to_1e_10():
    kappa, phi_k = (0.2, 0.07, 0.03, 0.01), (0.3, -1.1, 2.0, 0.5)
    eps, phi_e = (0.4, 0.1, 0.02), (0.0, 1.2, -0.7)
    series_model = BASE.replace(kappa=kappa, phi_k=phi_k, eps=eps, phi_e=phi_e)
    N = 32
    k_tab = series_table(2.0e8, 2.0e8 * np.array(kappa), np.array(phi_k), N)
    e_tab = series_table(0.0, 5e-6 * np.array(eps), np.array(phi_e), N)
    mean, amp, ph = fourier_series(k_tab)
    assert mean == pytest.approx(2.0e8, rel=1e-14)
    np.testing.assert_allclose(amp[:4] / mean, kappa, atol=1e-12)
    np.testing.assert_allclose(ph[:4], phi_k, atol=1e-10)
    assert np.max(amp[4:]) / mean < 1e-14
    table_model = excitation_model(BASE, Excitation(k_tab, e_tab), b_c=5e-6)
    a, b = _run(table_model), _run(series_model)
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-10)
    np.testing.assert_allclose(a.v, b.v, rtol=0, atol=1e-10)


def test_table_is_its_full_fourier_series_at_the_nodes():
    x = np.random.default_rng(1).normal(size=48)
    mean, amp, ph = fourier_series(x)
    np.testing.assert_allclose(series_table(mean, amp, ph, 48), x, atol=1e-13)


def test_multi_cycle_excitation_is_the_same_equation():
    # a one-cycle series repeated over P = 3 cycles: as a 3-cycle table the model keeps the mesh frequency,
    # its series are the harmonics 3, 6, 9 ... of omega/3; its trajectory equals the one-cycle model's
    kappa, phi_k, eps, phi_e = (0.2, 0.05), (0.4, 1.0), (0.3, 0.05), (0.2, -0.3)
    one = BASE.replace(kappa=kappa, phi_k=phi_k, eps=eps, phi_e=phi_e)
    N, P = 16, 3
    k0, b_c = 3.0e8, 10e-6  # a physical table (N/m, m): the model takes k/k0 and e/b_c
    k1 = series_table(k0, k0 * np.array(kappa), np.array(phi_k), N)
    e1 = series_table(0.0, b_c * np.array(eps), np.array(phi_e), N)
    exc = Excitation(np.tile(k1, P), np.tile(e1, P), cycles=P)
    three = excitation_model(BASE, exc, b_c=b_c)
    assert three.omega == BASE.omega and three.cycles == P and three.period_multiple() == P
    assert three.sampling_period == pytest.approx(P * one.period, rel=1e-15)
    np.testing.assert_allclose(three.kappa[2::3][:2], kappa, atol=1e-15)
    assert max(abs(k) for j, k in enumerate(three.kappa) if (j + 1) % 3) < 1e-15
    a = _run(three, periods=2, steps=3 * 400)
    b = _run(one, periods=6, steps=400, transient=60)
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-10)


def test_damping_harmonic_of_the_base_is_a_mesh_order():
    exc = Excitation(np.full(40, 3.0e8), None, cycles=4)
    m = excitation_model(BASE.replace(xi=(0.05,), phi_c=(0.3,)), exc)
    assert m.xi == (0.0, 0.0, 0.0, 0.05) and m.phi_c == (0.0, 0.0, 0.0, 0.3)


def test_hunting_excitation_of_a_cracked_pinion_tooth_runs():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    ms = mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, 0.5)], points=64)
    assert ms.cycles == 20
    model, sc = pair_model(ms, 3000.0)  # the full series: 640 harmonics of omega/20 (mesh orders up to 32)
    assert len(model.kappa) == 640 and sum(abs(k) for k in model.kappa) > 1  # positive by the certified minimum
    assert model.omega == sc["mesh_omega"] and model.cycles == 20
    with pytest.raises(ModelError, match="at most 1280"):
        excitation_model(BASE, Excitation(np.repeat(ms.stiffness, 5), None, cycles=20), harmonics=1281)
    tr = trajectory(model, (model.fp, 0.0), IntegrationOptions(dtau=0.05, transient=5, periods=2), history_periods=1)
    assert np.all(np.isfinite(tr.u))


def test_a_stiffness_that_is_not_positive_is_refused():
    k = np.full(64, 3.0e8)
    k[:8] = 6.0e6  # the interpolant rings below zero next to the drop
    with pytest.raises(ModelError, match="sum of"):
        excitation_model(BASE, Excitation(k, None, cycles=4))


def test_table_files_round_trip_and_feed_the_configuration_and_the_options(tmp_path):
    from geardyn.cli.options import build_model
    from geardyn.config import load_config
    from geardyn.tooth.table import read_table, write_table

    k = series_table(3.0e8, 3.0e8 * np.array([0.2, 0.05]), np.array([0.3, -1.0]), 24)
    e = series_table(0.0, np.array([2e-6, 0.5e-6]), np.array([0.1, 0.7]), 24)
    exc = Excitation(np.tile(k, 2), np.tile(e, 2), cycles=2)
    for name in ("t.csv", "t.json"):
        back = read_table(write_table(exc, tmp_path / name))
        assert back.cycles == 2
        np.testing.assert_array_equal(back.stiffness, exc.stiffness)
        np.testing.assert_array_equal(back.ste, exc.ste)
    (tmp_path / "c.toml").write_text(
        '[mesh]\nxi0 = 0.05\nxi = []\n[operating]\nomega = 0.8\n[excitation]\nfile = "t.csv"\nb_c = "1 um"\n'
    )
    cfg = load_config(tmp_path / "c.toml")
    want = excitation_model(GearModel(omega=0.8, xi0=0.05, xi=()), exc, b_c=1e-6)
    assert cfg.model.cycles == 2 and cfg.model.omega == 0.8
    np.testing.assert_allclose(cfg.model.kappa, want.kappa, rtol=0, atol=1e-15)
    np.testing.assert_allclose(cfg.model.eps, want.eps, rtol=0, atol=1e-12)
    assert cfg.model.eps[1] == pytest.approx(2.0, rel=1e-12)  # 2 um over b_c = 1 um at mesh order 1 = member 2
    m = build_model(tmp_path / "c.toml", omega=0.9)
    assert m.omega == 0.9 and m.cycles == 2
    with pytest.raises(ModelError, match="--kappa1"):
        build_model(tmp_path / "c.toml", kappa1=0.1)
    with pytest.raises(ModelError, match="--fe"):
        build_model(None, excitation=tmp_path / "t.json", fe=0.1)


def test_runup_takes_a_multi_cycle_excitation():
    # blocks of whole forcing periods (tests/test_runup_cycles.py checks the run-up itself)
    from geardyn.analysis.runup import runup

    m = excitation_model(BASE, Excitation(np.full(40, 3.0e8), None, cycles=4))
    r = runup(m, 0.5, 0.6, 500.0, settle=4)
    assert r.cycles % 4 == 0 and not r.diverged
    with pytest.raises(ModelError, match="multiple of the excitation's 4"):
        runup(m, 0.5, 0.6, 500.0, cycles_per_block=6)
