"""The conformance suite of the System contract: every kind of system shipped passes it, or is not a System.

Parametrised over the 1-DOF pair and the shipped systems (``examples/systems/``): the torsional pair, the
6-DOF spur pair with compliant bearings, the 8-DOF bevel pair and the planetary set.  The checks are exact
theory (Liouville's formula, the sum of the Lyapunov exponents), an exact reduction (the torsional pair is
the 1-DOF model) and two computations that must agree (shooting and direct integration).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from geardyn.backend import Backend
from geardyn.integrate import integrate_batch, period_map, trajectory
from geardyn.model import GearModel, IntegrationOptions
from geardyn.system import LAW_COUNTERS, DeadZone, Element, Law, System
from geardyn.systems import load_system

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
KINDS = ["pair", "paper_torsional", "spur_bending_torsional", "paper_bevel_8dof", "planetary_lin_parker_1999"]


@pytest.fixture(scope="module", params=KINDS)
def system(request):
    if request.param == "pair":
        return GearModel(omega=0.8)
    return load_system(EX / f"{request.param}.toml")


@pytest.fixture(scope="module")
def torsional():
    return load_system(EX / "paper_torsional.toml").with_param("omega", 0.8)


def _settled(model, periods: int = 20) -> np.ndarray:
    return integrate_batch([model], None, IntegrationOptions(transient=periods, periods=1)).end_state[0]


def test_the_contract(system):
    assert isinstance(system, System) and isinstance(system.backend, Backend)
    d = system.state_dim
    els = system.elements
    assert els and all(isinstance(e, Element) and e.gap >= 0 for e in els)
    assert 0 <= system.reference < len(els) and els[system.reference].kind == "mesh"
    assert system.period_multiple() >= 1
    assert system.sampling_period == pytest.approx(system.period_multiple() * 2 * math.pi / system.omega, rel=1e-15)
    assert system.with_param("omega", 0.7).get("omega") == 0.7
    # the initial state puts the reference element at (u0, v0)
    x = system.initial_state(0.25, -0.5)
    assert x.shape == (d,)
    np.testing.assert_allclose(system.element_series(x, 0.0)[system.reference], (0.25, -0.5), atol=1e-12)
    # the rigid-body basis: orthonormal columns of the coordinates (the pair has none)
    R = system.rigid_basis()
    assert R.shape[0] == d // 2
    np.testing.assert_allclose(R.T @ R, np.eye(R.shape[1]), atol=1e-12)
    # every element carries a law (the dead zone of its gap, today) whose counters fit the kernels' slots
    assert all(isinstance(e.law, Law) and len(e.law.counters) <= LAW_COUNTERS for e in els)
    assert all(e.law == DeadZone(e.gap) for e in els)
    # the system a result stores is the system: the same class, parameters and numbers
    back = type(system).from_attrs(system.to_attrs())
    assert type(back) is type(system) and back.to_attrs() == system.to_attrs()
    assert back.parameters() == system.parameters() and back.elements == system.elements
    np.testing.assert_array_equal(back.initial_state(0.25, -0.5), x)
    assert math.isfinite(system.static_force())
    # the mesh forces from the elements' deflections: one column per mesh, the reference mesh's among them
    tau = np.linspace(0.0, system.sampling_period, 5)
    deltas = np.stack([system.element_series(x, t) for t in tau])
    f = system.element_forces(tau, deltas)
    assert f.shape[0] == tau.size and f.shape[1] >= 1 and np.all(np.isfinite(f[:, system.reference]))


def test_one_batch_result_with_an_element_axis(system):
    res = integrate_batch(
        [system, system.with_param("omega", 1.1 * system.omega)], None, IntegrationOptions(transient=2, periods=3)
    )
    E = len(system.elements)
    assert res.poincare.shape == (2, 3, system.state_dim) and res.stats.shape[:2] == (2, E)
    assert res.elements == tuple(e.name for e in system.elements) and res.reference == system.reference
    np.testing.assert_array_equal(res.u_min, res.element_u_min()[:, system.reference])
    tr = trajectory(system, None, IntegrationOptions(transient=2, periods=3), history_periods=1)
    assert tr.deltas.shape == (tr.tau.size, E, 2)
    np.testing.assert_array_equal(tr.x[-1], res.poincare[0, -1])
    assert tr.u.min() >= res.u_min[0] - 1e-12


@pytest.mark.parametrize("accurate", [False, True])
def test_liouville_determinant_of_the_monodromy(system, accurate):
    """det of the n-period monodromy = exp(∫ trace of the Jacobian) = exp(mean trace · n T_f): exact for the
    linear damping of every element (Liouville's formula); the RK4 discretisation error is far below 1e-8.
    One period: the stiff bearings of the spur pair contract some directions by e^-100 a period, and over
    more periods the monodromy's smallest singular values fall below its round-off."""
    n = 1
    _pts, M, _st, ok = period_map(system, _settled(system), n, accurate=accurate)
    assert ok
    sign, logdet = np.linalg.slogdet(M)
    expect = system.mean_trace() * n * system.sampling_period
    assert sign == 1.0
    assert logdet == pytest.approx(expect, rel=1e-8, abs=1e-8)


@pytest.mark.parametrize("accurate", [False, True])
def test_torsional_pair_is_the_one_dof_model(torsional, accurate):
    opts = IntegrationOptions(transient=200, periods=32, accurate=accurate)
    a = integrate_batch([torsional], None, opts)
    b = integrate_batch([GearModel(omega=0.8)], None, opts)
    for k in ("u_min", "u_max", "amplitude", "mean", "rms"):
        assert getattr(a, k)[0] == pytest.approx(getattr(b, k)[0], abs=1e-6), k
    np.testing.assert_allclose(a.contact_fractions, b.contact_fractions, atol=1e-3)


def test_sum_of_lyapunov_exponents_is_the_mean_trace(system):
    """Gram–Schmidt keeps log|det| of the tangent flow: Σλ = mean trace of the Jacobian, whatever the motion."""
    from geardyn.analysis.lyapunov import lyapunov_spectrum

    r = lyapunov_spectrum(system, IntegrationOptions(transient=20, periods=40), classify=False)
    assert r.exponents.shape == (system.state_dim,)
    assert np.sum(r.exponents) == pytest.approx(system.mean_trace(), rel=1e-7, abs=1e-9)
    assert r.to_json()["expected_sum"] == system.mean_trace()


def test_shooting_agrees_with_direct_integration(system):
    """The fixed point of the period map found by Newton is reproduced by integrating one period from it, and
    a stable one is the attractor the simulation settles on."""
    from geardyn.analysis.classify import detect_period
    from geardyn.analysis.periodic import shoot

    settled = integrate_batch([system], None, IntegrationOptions(transient=400, periods=8)).poincare[0]
    if detect_period(settled) == 0:
        # the spur pair's mean torques do not balance along its free rotation: it spins up, no orbit exists
        pytest.skip("no periodic orbit: the load drives a zero-stiffness mode")
    o = shoot(system, 1)
    assert o.converged
    end = integrate_batch([system], o.state, IntegrationOptions(transient=0, periods=1)).poincare[0, -1]
    np.testing.assert_allclose(end, o.state, atol=1e-8 * (1 + np.abs(o.state).max()))
    mu, r = o.elastic
    assert r == system.rigid_basis().shape[1] and mu.size == system.state_dim - 2 * r
    if o.stable and np.max(np.abs(mu)) < 0.9:
        far = integrate_batch([system], None, IntegrationOptions(transient=800, periods=1)).end_state[0]
        np.testing.assert_allclose(far, o.state, atol=1e-7 * (1 + np.abs(o.state).max()))


@pytest.mark.parametrize("accurate", [False, True])
def test_torsional_pair_orbit_is_the_one_dof_orbit(torsional, accurate):
    from geardyn.analysis.periodic import shoot

    o = shoot(torsional, 1, accurate=accurate)
    o1 = shoot(GearModel(omega=0.8), 1, accurate=accurate)
    mu, r = o.elastic
    assert o.converged and o1.converged and r == 1
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(o1.multipliers), atol=1e-6)
    assert o.u_min == pytest.approx(o1.u_min, abs=1e-6) and o.u_max == pytest.approx(o1.u_max, abs=1e-6)
    assert o.stable == o1.stable and o.impact == o1.impact


def test_torsional_pair_continuation_switches_and_equals_the_one_dof(torsional):
    """Continuation of a system: its events (period doubling located by Newton, grazing) are the 1-DOF
    model's to 1e-8, and at the period doubling it switches onto the period-2 branch."""
    from geardyn.analysis.periodic import continuation

    # ds_max 0.05 (at least 20 steps over the interval, not 100): the events are located by Newton either way;
    # Δτ = 0.02 and 100 settling periods for the first guess: the same for both models, a third of the cost
    kw = {"max_period": 2, "ds_max": 0.05, "dtau": 0.02, "transient": 100}
    a = continuation(torsional, "omega", 0.6, 1.0, **kw)
    b = continuation(GearModel(), "omega", 0.6, 1.0, **kw)
    ea = [(x.type, x.n, x.value) for x in a.bifurcations]
    eb = [(x.type, x.n, x.value) for x in b.bifurcations]
    assert [x[:2] for x in ea] == [x[:2] for x in eb] and ("period-doubling", 1) in [x[:2] for x in ea]
    np.testing.assert_allclose([x[2] for x in ea], [x[2] for x in eb], rtol=0, atol=1e-8)
    assert [br.n for br in a.branches] == [br.n for br in b.branches] and 2 in [br.n for br in a.branches]
    two = next(br for br in a.branches if br.n == 2)
    assert two.origin is not None and two.origin.type == "period-doubling" and len(two) > 3
    assert two.multipliers.shape[1] == 2  # the elastic multipliers: the rigid-body pair is left out
    assert bool(np.any(two.stable))
