"""Torque orders: constant-amplitude load harmonics at orders of a shaft's speed (geardyn.torque_orders).

The linear case (no contact loss: a large mean load, small harmonics, constant mesh stiffness and damping) has
the exact steady state of a linear oscillator with constant coefficients, written here in closed form and
compared with the simulation to 1e-8; HB equals the simulation on the same case; a file's and the command
line's orders change the response.
"""

from __future__ import annotations

import json
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from geardyn.errors import GeardynError, ModelError
from geardyn.integrate import trajectory
from geardyn.model import GearModel, IntegrationOptions
from geardyn.pairpack import pack_models, pack_points
from geardyn.torque_orders import MAX_ORDER_PERIOD, normalise, parse_cli

ROOT = Path(__file__).resolve().parents[1]


def exact_linear(model: GearModel, tau: np.ndarray) -> np.ndarray:
    """Steady state of u'' + 2ξ0 u' + (u − D) = f_p + ω² Σ l² ε_l cos(lωτ + φ_l) + Σ a_o cos(q_o ωτ + φ_o), u > D.

    Each harmonic of frequency Ω and complex amplitude A responds with A/(1 − Ω² + 2iξ0Ω) (the receptance of
    the linear oscillator of unit mass and stiffness); the mean is D + f_p.
    """
    w, z = model.omega, model.xi0
    u = np.full_like(tau, model.D + model.fp, dtype=float)
    terms = [(l * w, w * w * l * l * e, ph) for l, (e, ph) in enumerate(zip(model.eps, model.phi_e), start=1)]
    terms += [(float(q) * w, a, ph) for q, a, ph in model.torque_orders]
    for W, A, ph in terms:
        H = 1.0 / complex(1.0 - W * W, 2.0 * z * W)
        u += np.real(A * np.exp(1j * ph) * H * np.exp(1j * W * tau))
    return u


LINEAR = GearModel(
    omega=0.8,
    xi0=0.06,
    xi=(),
    kappa=(),
    eps=(0.02,),
    phi_e=(0.4,),
    fp=1.5,
    D=0.5,
    torque_orders=((Fraction(1, 2), 0.05, 0.3), (Fraction(3, 1), 0.04, -1.1)),
)


def test_linear_case_is_the_exact_steady_state():
    m = LINEAR
    assert m.period_multiple() == 2  # the half order repeats after two mesh periods
    assert m.sampling_period == pytest.approx(2 * 2 * math.pi / m.omega, rel=1e-15)
    # decay e^(-ξ0 τ) over the transient: below 1e-12
    T = m.sampling_period
    transient = math.ceil(30.0 / m.xi0 / T)
    opts = IntegrationOptions(dtau=0.002, transient=transient, periods=3)
    tr = trajectory(m, (0.0, 0.0), opts, history_periods=3)
    exact = exact_linear(m, tr.tau)
    assert np.min(exact) > m.D + 0.5  # no contact loss
    assert np.max(np.abs(tr.u - exact)) < 1e-8
    # the amplitude of the order: the response's Fourier coefficient at q = 1/2 over the window
    n = tr.tau.size - 1
    c = 2.0 * np.fft.rfft(tr.u[:n])[3] / n  # 3 forcing periods of 2 mesh periods: order 1/2 is bin 3
    H = 1.0 / complex(1 - (0.5 * m.omega) ** 2, 2 * m.xi0 * 0.5 * m.omega)
    assert abs(c - 0.05 * np.exp(0.3j) * H) < 1e-8


def test_hb_equals_simulation_on_the_linear_case():
    from geardyn.analysis.hb.aft import HarmonicBasis
    from geardyn.analysis.hb.solve import hb_solve

    m = LINEAR
    direct = hb_solve(m, harmonics=16, guess="linear", stability=False)  # harmonics of ω/M, M = 2 mesh cycles
    assert direct.converged
    tau, u = direct.signal(256)
    assert np.max(np.abs(u - exact_linear(m, tau))) < 1e-9
    f = m.forcing_model()  # one forcing period as its unit: ω/2, orders 1 and 6, the STE harmonic 2
    assert f.period_multiple() == 1 and f.omega == m.omega / 2
    sol = hb_solve(f, harmonics=8, guess="linear", stability=False)
    assert sol.converged
    tau, u = sol.signal(256)
    assert np.max(np.abs(u - exact_linear(m, tau))) < 1e-9
    T = m.sampling_period
    opts = IntegrationOptions(dtau=0.002, transient=math.ceil(30.0 / m.xi0 / T), periods=1)
    tr = trajectory(m, (0.0, 0.0), opts, history_periods=1)
    hb_u = HarmonicBasis(sol.harmonics, 64).evaluate(sol.coefficients, f.omega * tr.tau)  # u(φ), φ = (ω/2) τ
    assert np.max(np.abs(tr.u - hb_u)) < 1e-8


def test_hb_equals_simulation_with_contact_loss():
    """A nonlinear case (the mesh separates): HB converges onto the simulation (accurate mode) as H grows, and an
    order of amplitude a at the mesh frequency is the STE harmonic ε1 = a/ω² (the same forcing a cos θ)."""
    from geardyn.analysis.hb.aft import HarmonicBasis
    from geardyn.analysis.hb.solve import hb_solve

    m = GearModel(omega=1.2, xi0=0.1, xi=(), kappa=(), eps=(), fp=0.1, D=0.5, torque_orders=((1, 0.15, 0.0),))
    opts = IntegrationOptions(dtau=0.001, transient=400, periods=4, accurate=True)
    tr = trajectory(m, (0.6, 0.0), opts, history_periods=1)
    assert tr.u.min() < m.D - 0.1  # it separates
    ste = trajectory(m.replace(torque_orders=(), eps=(0.15 / 1.44,)), (0.6, 0.0), opts, history_periods=1)
    assert np.max(np.abs(tr.u - ste.u)) < 1e-12
    errors = []
    for H in (40, 160):
        sol = hb_solve(m, harmonics=H, guess="simulate", stability=False)
        assert sol.converged
        u = HarmonicBasis(H, 4 * H + 8).evaluate(sol.coefficients, m.omega * tr.tau)
        errors.append(np.max(np.abs(tr.u - u)))
    assert errors[0] < 1e-6 and errors[1] < 1e-8  # the truncation error of a force with kinks, ~H^-3


def test_no_orders_leaves_the_model_as_it_was():
    m = GearModel()
    assert m.torque_orders == () and "torque_orders" not in m.to_dict()
    assert m.period_multiple() == 1 and m.forcing_omega == m.omega
    with_orders = m.replace(torque_orders=((2, 0.05),))
    assert with_orders.period_multiple() == 1
    c0, c1 = m.coefficients(2), with_orders.coefficients()
    assert np.array_equal(c1[:, :2], c0[:, :2]) and c1[2, 2, 0] == 0.05 and c1[2, 2, 1] == 0.0


def test_orders_of_several_cycles_and_series_placement():
    m = GearModel(kappa=(0.2, 0.1), torque_orders=(("2/23", 0.01, 0.5),))
    assert m.period_multiple() == 23
    assert m.sampling_period == pytest.approx(23 * 2 * math.pi / m.omega, rel=1e-15)
    c = m.coefficients()
    assert c.shape == (3, 47, 2)
    assert c[1, 23, 0] == 0.2 and c[1, 46, 0] == 0.1  # κ_r at mesh order r = harmonic 23 r of ω/23
    assert c[2, 2, 0] == pytest.approx(0.01 * math.cos(0.5)) and c[2, 2, 1] == pytest.approx(-0.01 * math.sin(0.5))
    # the forcing model of one period: the same function of time
    f = m.forcing_model()
    th = np.linspace(0.0, 50.0, 7)
    for tau in th:
        assert np.allclose(m.rhs(tau, (1.3, 0.2)), f.rhs(tau, (1.3, 0.2)), rtol=1e-13, atol=1e-14)
    assert GearModel.from_dict(json.loads(m.to_json())) == m


def test_a_grid_of_points_packs_as_its_models():
    base = GearModel(torque_orders=(("1/3", 0.02, 0.0),))
    pts = np.array([[0.5, 0.1], [1.2, 0.3]])
    got = pack_points(base, ["omega", "fp"], pts)
    want = pack_models([base.replace(omega=0.5, fp=0.1), base.replace(omega=1.2, fp=0.3)])
    for a, b in zip(got, want):
        assert np.array_equal(a, b)


@pytest.mark.parametrize(
    "orders, key",
    [
        (((0, 0.1),), "order"),
        ((("-1/2", 0.1),), "order"),
        (((2, float("nan")),), "amplitude"),
        (((2, 0.1), (2, 0.2)), "given twice"),
        ((("1/2000", 0.1),), str(MAX_ORDER_PERIOD)),
        (((2, 0.1, "x"),), "phase"),
        ("2:0.1", "torque_orders"),
    ],
)
def test_bad_orders_are_refused_naming_the_key(orders, key):
    with pytest.raises(ModelError, match=key):
        GearModel(torque_orders=orders)


def test_cli_text():
    assert parse_cli("2:0.05") == (Fraction(2), 0.05, 0.0)
    assert parse_cli("1/2:0.1:0.3") == (Fraction(1, 2), 0.1, 0.3)
    assert normalise([{"order": 1.5, "amplitude": 1}]) == ((Fraction(3, 2), 1.0, 0.0),)
    for bad in ("2", "a:1", "2:1:2:3", "2:inf"):
        with pytest.raises(ModelError, match="--torque-order"):
            parse_cli(bad)


def test_pinion_orders_of_a_physical_pair(tmp_path):
    """Order k of the pinion speed is k/z1 of the mesh frequency; ΔT on the pinion alone is the force
    m_e R1 ΔT/I1 = I2 R1 ΔT/(I2 R1² + I1 R2²), over k0 b_c."""
    from geardyn.config import load_config

    text = (ROOT / "examples" / "paper_table1.toml").read_text()
    cfg_path = tmp_path / "orders.toml"
    cfg_path.write_text(text + '\n[model]\ntorque_orders = [{order = 2, amplitude = "40 N*m", phase = "90 deg"}]\n')
    cfg = load_config(cfg_path)
    sc = cfg.pair.scales(cfg.b_c)
    (q, a, ph) = cfg.model.torque_orders[0]
    assert q == Fraction(2, 23) and cfg.model.period_multiple() == 23
    I1, I2 = 1.772, 1.873  # the file's inertias (kg m²)
    R1, R2 = sc.R1_m, sc.R2_m
    F = I2 * R1 * 40.0 / (I2 * R1**2 + I1 * R2**2)
    assert a == pytest.approx(F / (sc.k0_N_per_m * sc.b_c_m), rel=1e-12)
    assert ph == pytest.approx(math.pi / 2, rel=1e-15)
    # a sweep over speed keeps the amplitude in N·m: ω changes, the non-dimensional amplitude does not
    faster = cfg.model.with_param("omega", 2.0 * cfg.model.omega)
    assert faster.torque_orders == cfg.model.torque_orders


def test_config_orders_refused_in_one_line(tmp_path):
    from geardyn.config import load_config

    p = tmp_path / "bad.toml"
    p.write_text("[mesh]\nfp = 0.2\n[model]\ntorque_orders = [{order = 0, amplitude = 0.1}]\n")
    with pytest.raises(GeardynError, match="torque_orders") as e:
        load_config(p)
    assert "\n" not in str(e.value)
    p.write_text("[mesh]\nfp = 0.2\n[model]\ntorque_orders = [{order = 2, amplitude = 0.1, speed = 3}]\n")
    with pytest.raises(GeardynError, match="torque_orders"):
        load_config(p)
    # the tables are counted from 1, as a series' elements and a system file's orders are
    p.write_text(
        "[mesh]\nfp = 0.2\n[model]\ntorque_orders = [{order = 2, amplitude = 0.1}, {order = -1, amplitude = 0.1}]\n"
    )
    with pytest.raises(GeardynError, match="torque_orders: element 2: order: must be > 0"):
        load_config(p)


# ---------------------------------------------------------------- the command line
def _simulate(*extra: str) -> dict:
    from cli_run import run_cli

    code, out, err = run_cli(["simulate", "--json", "--transient", "100", "--periods", "20", *extra])
    assert code == 0, err
    return json.loads(out)


def test_cli_torque_order_changes_the_response(tmp_path):
    base = _simulate("--out", str(tmp_path / "a"))
    forced = _simulate("--torque-order", "2:0.05", "--out", str(tmp_path / "b"))
    assert forced["rms"] != base["rms"] and forced["amplitude"] != base["amplitude"]
    import xarray as xr

    nc = next((tmp_path / "b").glob("*.nc"))
    with xr.open_dataset(nc) as ds:
        text = json.dumps(dict(ds.attrs), default=str)
    assert "torque_orders" in text  # the model written with the result carries its orders
    half = _simulate("--torque-order", "1/2:0.05:0.3", "--out", str(tmp_path / "c"))
    assert half["rms"] != base["rms"]


@pytest.mark.parametrize(
    "args, key",
    [
        (["--torque-order", "2"], "--torque-order"),
        (["--torque-order", "0:0.1"], "--torque-order ORDER"),
        (["--torque-order", "2:nan"], "--torque-order AMPLITUDE"),
        (["--system", str(ROOT / "examples" / "systems" / "paper_torsional.toml"), "--torque-order", "2:1"], "system"),
    ],
)
def test_cli_bad_torque_order_exits_2(args, key):
    from cli_run import run_cli

    code, out, err = run_cli(["simulate", "--json", "--periods", "2", "--transient", "0", *args])
    assert code == 2
    assert key in err and len(err.strip().splitlines()) == 1


def test_config_orders_change_the_response(tmp_path):
    base = "[mesh]\nxi0 = 0.1\nxi = [0.05]\nkappa = [0.2]\neps = [0.5]\nfp = 0.2\n[operating]\nomega = 1.0\n"
    plain, forced = tmp_path / "plain.toml", tmp_path / "forced.toml"
    plain.write_text(base)
    forced.write_text(base + '[model]\ntorque_orders = [{ order = "1/2", amplitude = 0.05, phase = "30 deg" }]\n')
    a = _simulate("--config", str(plain))
    b = _simulate("--config", str(forced))
    assert a["rms"] != b["rms"] and a["amplitude"] != b["amplitude"]


def test_hb_continuation_in_omega_keeps_the_orders():
    """A branch over ω of the linear case: every point's coefficients are the exact steady state at its ω (the
    orders' amplitudes do not depend on ω, the STE's grow as ω²)."""
    from geardyn.analysis.hb.aft import HarmonicBasis
    from geardyn.analysis.hb.continuation import hb_continuation

    br = hb_continuation(LINEAR, "omega", 0.7, 0.705, harmonics=8, guess="linear", max_points=40)
    assert br.values.size >= 5 and br.values.max() > 0.703
    for w, a in zip(br.values, br.coefficients):
        m = LINEAR.replace(omega=float(w))
        tau = np.linspace(0.0, m.sampling_period, 40)
        u = HarmonicBasis(8, 64).evaluate(a, m.forcing_omega * tau)
        # to the corrector's tolerance (the orders' terms are 0.05 and 0.04: leaving them out fails by ~0.1)
        assert np.max(np.abs(u - exact_linear(m, tau))) < 1e-6


def test_shooting_finds_the_exact_orbit():
    """Shooting on the forcing period (two mesh periods for the half order): the orbit's state at θ = 0 is the
    exact steady state's, and its multipliers are those of the linear oscillator over that period."""
    from geardyn.analysis.periodic import shoot

    m = LINEAR
    orb = shoot(m, 1, guess=(m.D + m.fp, 0.0), dtau=0.002)
    assert orb.converged
    u0 = exact_linear(m, np.array([0.0]))[0]
    h = 1e-6
    v0 = (exact_linear(m, np.array([h]))[0] - exact_linear(m, np.array([-h]))[0]) / (2 * h)
    assert abs(orb.state[0] - u0) < 1e-8 and abs(orb.state[1] - v0) < 1e-6
    T = m.sampling_period  # |μ| = exp(−ξ0 T) for the underdamped linear oscillator of unit frequency
    assert np.allclose(np.abs(orb.multipliers), math.exp(-m.xi0 * T), rtol=1e-6)
