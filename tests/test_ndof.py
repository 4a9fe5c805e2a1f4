"""The N-DOF kernel and the analyses of multi-DOF systems: exact reduction, exact theory, accuracy."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.lyapunov import lyapunov_spectrum
from geardyn.analysis.periodic import shoot
from geardyn.analysis.steady import simulate
from geardyn.errors import ModelError
from geardyn.geometry.scales import Scales
from geardyn.integrate import forcing_period, integrate_batch, period_map, trajectory
from geardyn.model import GearModel, IntegrationOptions
from geardyn.system import require_periodic
from geardyn.systems import SystemModel, assemble, load_description, load_system
from geardyn.systems.assemble import MeshND

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
KEYS = ("period", "impact", "u_min", "u_max", "amplitude")


@pytest.fixture(scope="module")
def torsional():
    return load_system(EX / "paper_torsional.toml").with_param("omega", 0.8)


def _model(n, Mi, Kb, Cb, V, meshes, F, omega=1.0, Vc=None, kc=(), cc=(), Dc=(), names=()):
    sc = Scales.of_reference_mesh("m0", 1.0, 1.0, 1.0, (1.0,) * n, None)
    return SystemModel(
        labels=tuple(f"b{i}.x" for i in range(n)),
        Mi=Mi,
        Kb=Kb,
        Cb=Cb,
        V=V,
        meshes=meshes,
        F=F,
        omega=omega,
        scaling=sc,
        clearance_names=tuple(names),
        Vc=np.zeros((0, n)) if Vc is None else Vc,
        kc=kc,
        cc=cc,
        Dc=Dc,
    )


def _mesh(name="m0", k=1.0, xi0=0.0, xi=(), kappa=(), eps=(), D=0.0, ratio=1.0):
    return MeshND(name, k, xi0, tuple(xi), (), tuple(kappa), (), tuple(eps), (), D, ratio)


def _four_dof(D=0.5, xi0=0.05, eps=(0.3,), kappa=(0.2,), omega=0.9, clearance=True):
    """Two bodies on bearings with one mesh (and one clearance): 4 DOFs, nonlinear when D > 0."""
    rng = np.random.default_rng(3)
    M = np.diag([1.0, 0.7, 1.3, 0.9])
    Mi = np.linalg.inv(M)
    Kb = np.diag([2.0, 0.0, 1.5, 0.0]) + 0.1 * np.eye(4)
    Cb = 0.02 * Kb
    V = np.array([[0.3, 1.0, -0.2, -1.0]])
    F = np.array([0.0, 0.15, 0.0, -0.1])
    extra = {}
    if clearance:
        extra = dict(Vc=np.array([[1.0, 0.0, -1.0, 0.0]]), kc=(0.5,), cc=(0.01,), Dc=(0.4,), names=("gap",))
    del rng
    return _model(4, Mi, Kb, Cb, V, (_mesh(k=1.0, xi0=xi0, xi=(0.02,), kappa=kappa, eps=eps, D=D),), F, omega, **extra)


# ---------------------------------------------------------------------------- exact reduction
@pytest.mark.parametrize("accurate", [False, True])
def test_simulate_reduces_to_one_dof(torsional, accurate):
    opts = IntegrationOptions(accurate=accurate)
    a = simulate(torsional, opts).to_json()
    b = simulate(GearModel().with_param("omega", 0.8), opts).to_json()
    m = a["meshes"][0]
    for k in KEYS:
        if isinstance(b[k], float):
            assert a[k] == pytest.approx(b[k], abs=1e-6)
            assert m[k] == pytest.approx(b[k], abs=1e-6)
        else:
            assert a[k] == b[k]
            if k in m:
                assert m[k] == b[k]
    assert m["dynamic_factor"] == pytest.approx(simulate_dynamic_factor(b, accurate), rel=1e-6)


def simulate_dynamic_factor(b, accurate):
    from geardyn.analysis.physical import add_physical, simulate_physical

    res = simulate(GearModel().with_param("omega", 0.8), IntegrationOptions(accurate=accurate))
    return simulate_physical(add_physical(res.to_dataset()))["dynamic_factor"]


@pytest.mark.parametrize("accurate", [False, True])
def test_orbit_multipliers_reduce(torsional, accurate):
    o = shoot(torsional, 1, accurate=accurate)
    o1 = shoot(GearModel().with_param("omega", 0.8), 1, accurate=accurate)
    assert o.converged and o1.converged
    mu, r = o.elastic
    assert r == 1  # the rigid-body rotation of the pair: its two multipliers are 1 and are excepted
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(o1.multipliers), atol=1e-6)
    full = np.sort(np.abs(o.multipliers))
    assert np.sum(np.abs(full - 1.0) < 1e-6) == 2
    j = o.to_json()
    for k in ("u_min", "u_max", "amplitude", "impact"):
        assert j[k] == pytest.approx(o1.to_json()[k], abs=1e-6) if k != "impact" else j[k] == o1.impact
    assert len(j["multipliers"]) == 4 and "rigid-body" in j["rigid_body_note"]


def test_incommensurate_refused(torsional):
    two = replace(torsional, meshes=torsional.meshes)
    m2 = replace(torsional.meshes[0], ratio=math.sqrt(2.0))
    two = replace(torsional, meshes=(m2,))
    assert two.period_multiple() is None
    with pytest.raises(ModelError, match="incommensurate"):
        require_periodic(two)
    with pytest.raises(ModelError, match="incommensurate"):
        shoot(two, 1)
    # the time response and the Lyapunov spectrum still work
    r = integrate_batch([two], None, IntegrationOptions(transient=10, periods=10))
    assert r.ok[0]


def test_rigid_bearing_limit():
    """The 8-DOF bevel model tends to the 1-DOF model as the bearing stiffness grows (the mesh deflection's
    extremes over the recorded periods; integrated without ``simulate``'s motion classification, whose Lyapunov
    spectrum of the softer systems is not what is compared)."""
    d = load_description(EX / "paper_bevel_8dof.toml")
    g = GearModel().with_param("omega", 0.6)
    opts = IntegrationOptions(transient=200, periods=64)

    def extremes(model):
        r = integrate_batch([model], None, opts)
        return float(r.u_min[0]), float(r.u_max[0])

    ref = extremes(g)
    errs = []
    for scale in (1.0, 10.0, 100.0, 1000.0):
        conns = tuple(replace(c, stiffness=np.array(c.stiffness) * scale) for c in d.connections)
        a = extremes(assemble(replace(d, connections=conns), omega=0.6))
        errs.append(abs(a[1] - ref[1]) + abs(a[0] - ref[0]))
    assert all(e2 < e1 for e1, e2 in zip(errs, errs[1:])), errs
    assert errs[-1] < 1e-2 * max(errs[0], 1e-12) or errs[-1] < 1e-4, errs


# ---------------------------------------------------------------------------- exact theory
@pytest.mark.parametrize("omega,periods", [(1.5, 600), (0.8, 300)])  # chaotic, periodic (period 2)
def test_lyapunov_sum_is_mean_trace(torsional, omega, periods):
    for model in (torsional.with_param("omega", omega), _four_dof(omega=omega)):
        r = lyapunov_spectrum(model, IntegrationOptions(transient=100, periods=periods))
        assert np.sum(r.exponents) == pytest.approx(model.mean_trace(), rel=1e-6, abs=1e-9)
        assert len(r.exponents) == model.state_dim


@pytest.mark.parametrize("omega", [1.5, 0.8])
def test_monodromy_determinant(omega):
    model = _four_dof(omega=omega)
    n = 7
    x0 = integrate_batch([model], None, IntegrationOptions(transient=50, periods=1)).end_state[0]
    _pts, M, _st, ok = period_map(model, x0, n, dtau=0.005, accurate=True)
    assert ok
    expect = math.exp(model.mean_trace() * n * forcing_period(model))
    assert np.linalg.det(M) == pytest.approx(expect, rel=1e-6)


def _energy_model():
    M = np.diag([1.0, 2.0, 0.5])
    K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -0.5], [0.0, -0.5, 1.0]])
    V = np.array([[1.0, -0.5, 0.2]])
    z = np.zeros((3, 3))
    return _model(3, np.linalg.inv(M), K, z, V, (_mesh(k=0.7),), np.zeros(3), 1.0), M, K + 0.7 * np.outer(V[0], V[0])


def test_energy_conserved_at_rk4_order():
    model, M, K = _energy_model()
    x0 = np.array([0.3, -0.2, 0.1, 0.0, 0.4, -0.1])

    def energy(x):
        q, v = x[:3], x[3:]
        return 0.5 * v @ M @ v + 0.5 * q @ K @ q

    errs = []
    for N in (50, 100, 200):
        r = integrate_batch([model], x0, IntegrationOptions(transient=0, periods=20), steps=N)
        errs.append(abs(energy(r.end_state[0]) - energy(x0)))
    orders = [math.log2(a / b) for a, b in zip(errs, errs[1:])]
    assert all(o > 3.7 for o in orders), (errs, orders)
    assert errs[-1] < 1e-5 * energy(x0)


def test_forced_linear_response_matches_frequency_domain():
    """In contact at constant stiffness the response equals (K − ω²M + iωC)⁻¹F."""
    omega = 1.3
    model = _four_dof(D=0.0, kappa=(), eps=(0.3,), omega=omega, clearance=False)
    model = model.with_param("m0.xi1", 0.0)
    M = np.linalg.inv(model.Mi)
    v = model.V[0]
    k, c = model.meshes[0].k, 2 * model.meshes[0].xi0
    K = model.Kb + k * np.outer(v, v)
    C = model.Cb + c * np.outer(v, v)
    qs = np.linalg.solve(K, model.F)
    Q = np.linalg.solve(K - omega**2 * M + 1j * omega * C, v * (k + 1j * omega * c) * 0.3)
    x_exact = np.concatenate([qs + Q.real, (1j * omega * Q).real])  # at θ = 0
    r = integrate_batch([model], x_exact, IntegrationOptions(transient=0, periods=30, dtau=0.002))
    np.testing.assert_allclose(r.poincare[0], np.broadcast_to(x_exact, r.poincare[0].shape), atol=1e-8)


def test_accurate_mode_order_four_through_contact_loss(torsional):
    model = torsional.with_param("omega", 0.8)
    x0 = integrate_batch([model], None, IntegrationOptions(transient=20, periods=1)).end_state[0]
    # the period from x0 crosses the boundaries (contact loss and regain)
    tr = trajectory(model, x0, IntegrationOptions(transient=0, periods=1), history_periods=1)
    assert np.any(tr.u < 1.0) and np.any(tr.u > 1.0)

    def end(N):
        return integrate_batch(
            [model], x0, IntegrationOptions(transient=0, periods=2, accurate=True), steps=N
        ).end_state[0]

    ref = end(6400)
    errs = [np.max(np.abs(end(N) - ref)) for N in (100, 200, 400)]
    orders = [math.log2(a / b) for a, b in zip(errs, errs[1:])]
    assert all(o > 3.6 for o in orders), (errs, orders)


def test_poincare_matches_dop853_with_events():
    """4-DOF nonlinear case (mesh and clearance with backlash) against SciPy DOP853, events at every boundary."""
    from scipy.integrate import solve_ivp

    model = _four_dof(omega=0.9)
    A = model.Mi @ model.Kb
    B = model.Mi @ model.Cb
    W = model.Mi @ model.V[0]
    Wc = model.Mi @ model.Vc[0]
    g = model.Mi @ model.F
    m = model.meshes[0]
    cf = m.coefficients()
    om = model.omega

    def coefs(t):
        th = om * t
        C = cf[0, 0, 0] + cf[0, 1, 0] * math.cos(th) + cf[0, 1, 1] * math.sin(th)
        K = cf[1, 0, 0] + cf[1, 1, 0] * math.cos(th) + cf[1, 1, 1] * math.sin(th)
        E = cf[2, 1, 0] * math.cos(th) + cf[2, 1, 1] * math.sin(th)
        Ed = cf[2, 1, 1] * math.cos(th) - cf[2, 1, 0] * math.sin(th)
        return C, K, E, Ed

    def fz(d, D):
        return d - min(max(d, -D), D)

    def rhs(t, x):
        q, v = x[:4], x[4:]
        C, K, E, Ed = coefs(t)
        d = model.V[0] @ q - E
        dv = model.V[0] @ v - om * Ed
        dc = model.Vc[0] @ q
        dcv = model.Vc[0] @ v
        a = (
            g
            - A @ q
            - B @ v
            - W * (C * dv + K * fz(d, m.D))
            - Wc * (model.cc[0] * dcv + model.kc[0] * fz(dc, model.Dc[0]))
        )
        return np.concatenate([v, a])

    def ev(sign, which):
        def f(t, x):
            if which == "mesh":
                return model.V[0] @ x[:4] - coefs(t)[2] - sign * m.D
            return model.Vc[0] @ x[:4] - sign * model.Dc[0]

        return f

    events = [ev(s, w) for s in (1, -1) for w in ("mesh", "gap")]
    T = forcing_period(model)
    x = np.zeros(8)
    pts = []
    for k in range(12):
        t0, t1 = k * T, (k + 1) * T
        while True:
            sol = solve_ivp(rhs, (t0, t1), x, method="DOP853", rtol=1e-12, atol=1e-13, events=events)
            x = sol.y[:, -1]
            tev = [te[0] for te in sol.t_events if len(te) and te[0] > t0 + 1e-12]
            if sol.status == 1 and tev and sol.t[-1] < t1 - 1e-12:
                t0 = sol.t[-1]
                x = x + 0.0
                continue
            break
        pts.append(x.copy())
    r = integrate_batch([model], np.zeros(8), IntegrationOptions(transient=0, periods=12, dtau=0.002, accurate=True))
    np.testing.assert_allclose(r.poincare[0], np.array(pts), atol=1e-6)
    # and the boundaries were crossed
    assert 0 < r.element_fractions(0)[0, 1] < 1 or 0 < r.element_fractions(1)[0, 1] < 1
