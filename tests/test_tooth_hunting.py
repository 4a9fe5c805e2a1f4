"""A cracked pinion tooth's excitation over one pinion revolution (20 mesh cycles) through the analyses."""

import numpy as np
import pytest

from geardyn.analysis.hb import hb_solve
from geardyn.analysis.lyapunov import lyapunov_spectrum
from geardyn.analysis.periodic.continuation import continuation
from geardyn.analysis.periodic.orbit import shoot
from geardyn.integrate import trajectory
from geardyn.model import IntegrationOptions
from geardyn.tooth import Crack, mesh_stiffness, pair_geometry, pair_model


@pytest.fixture(scope="module")
def model():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    ms = mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, 0.5)], points=16)
    m, sc = pair_model(ms, 1000.0, harmonics=64)  # mesh orders up to 3.2
    assert sc["cycles"] == 20 and m.cycles == 20
    return m.replace(omega=0.6)  # mesh frequency 0.6 omega_n: forcing period 20 mesh periods


def test_poincare_section_and_shooting_use_the_revolution_period(model):
    assert model.sampling_period == pytest.approx(20 * 2 * np.pi / 0.6, rel=1e-15)
    orb = shoot(model, 1, dtau=0.02)
    assert orb.status == 0
    tr = trajectory(model, orb.state, IntegrationOptions(dtau=0.02, transient=0, periods=3), history_periods=1)
    np.testing.assert_allclose(tr.poincare[-1], orb.state, atol=1e-8)  # a fixed point of the revolution map
    # while the excitation is not periodic over one mesh cycle: the state 1 mesh period later differs
    n_mesh = (tr.tau.size - 1) // 20
    assert abs(tr.u[n_mesh] - tr.u[0]) > 1e-4


def test_lyapunov_sum_is_minus_twice_the_damping(model):
    # the orbit stays in contact (f(u) = u - D), so the system is linear periodic: by Liouville the exponents
    # add up to the trace of the matrix, -2 xi0, whatever the stiffness
    ly = lyapunov_spectrum(model, IntegrationOptions(dtau=0.02, transient=10, periods=40), (model.fp + model.D, 0.0))
    assert sum(ly.exponents) == pytest.approx(-2 * model.xi0, abs=1e-9)


@pytest.mark.slow  # HB at 128 harmonics against shooting at dtau 0.005
def test_harmonic_balance_and_continuation_run(model):
    orb = shoot(model, 1, dtau=0.005)
    # the pair's HB takes P = 20 (harmonics of omega/20, omega the mesh frequency): the equations of its one-cycle
    # form (omega/20); the forcing holds 64 harmonics of omega/20, the response's products with the stiffness
    # reach beyond, so HB takes 128: its state at theta = 0 then agrees with shooting's fixed point
    hb = hb_solve(model, harmonics=128)
    assert hb.status == 0
    np.testing.assert_allclose(
        hb.coefficients, hb_solve(model.forcing_model(), harmonics=128).coefficients, rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(hb.state(), orb.state, rtol=0, atol=1e-4)
    # the continuation parameter is the mesh frequency
    br = continuation(model, "omega", 0.6, 0.61, 1, dtau=0.02, accurate=False, max_points=10)
    assert len(br.branches) >= 1
    w = np.concatenate([b.values for b in br.branches])
    assert w.min() >= 0.6 - 1e-9 and w.max() <= 0.61 + 1e-9
