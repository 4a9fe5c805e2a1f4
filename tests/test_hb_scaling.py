"""Harmonic balance at gearbox size: the sparse Jacobian (``SparseJacobian``, forms of more than ``SPARSE_DOFS``
coordinates) and the monodromy kernel's sums over the nonzeros, on the 48-DOF chain of ``benchmarks/hb_scaling.py``.

References: the dense Jacobian and LAPACK's solve of the same equations (the code before the sparse path), and the
chain's simulation and period map (RK4 in the accurate mode), an independent method.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.hb import equations, hb_solve
from geardyn.analysis.periodic import PeriodMap
from geardyn.analysis.periodic.orbit import elastic_multipliers
from geardyn.integrate import integrate_batch
from geardyn.model import IntegrationOptions
from geardyn.status import Status
from geardyn.systems import load_system

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """The 48-DOF chain at ω = 0.75, where every mesh loses contact over part of the period."""
    from ndof_scaling import chain_toml

    path = chain_toml(8, tmp_path_factory.mktemp("chain") / "chain8.toml", fp_torque=30.0, eps_um=10.0)
    return load_system(path).with_param("omega", 0.75)


@pytest.fixture(scope="module")
def sparse_solution(chain):
    sol = hb_solve(chain, 16)
    assert sol.converged and sol.hill.status is Status.OK
    return sol


def test_sparse_jacobian_is_the_dense_one_and_gives_the_same_solution(chain, sparse_solution, monkeypatch):
    """The sparse Jacobian holds the dense one's entries (to 1e-14 relative), and Newton from the same start reaches
    the same solution with either (to 1e-10 relative, a tenth of Newton's tolerance)."""
    sol = sparse_solution
    eq = sol.equations
    x = sol.unknowns
    R, J = eq.residual(x)
    assert isinstance(J, equations.SparseJacobian)
    monkeypatch.setattr(equations, "SPARSE_DOFS", 10**6)
    dense_eq = equations.HBEquations(chain, 16)
    R2, J2 = dense_eq.residual(x)
    assert isinstance(J2, np.ndarray)
    np.testing.assert_array_equal(R, R2)
    assert np.abs(np.asarray(J) - J2).max() <= 1e-14 * np.abs(J2).max()
    # Newton from the same starts with the dense Jacobian and LAPACK, and with the sparse one: the linear response
    # (it leads to another of the three orbits between the folds at ω = 0.724 and 0.775) and the solution disturbed
    starts = [eq.unknowns(eq.linear_guess()), x + 1e-3 * np.random.default_rng(3).standard_normal(x.size)]
    dense = [dense_eq.newton(s0) for s0 in starts]
    monkeypatch.setattr(equations, "SPARSE_DOFS", 8)
    sparse = [equations.HBEquations(chain, 16).newton(s0) for s0 in starts]
    for (xd, st_d, _, _), (xs, st_s, _, _) in zip(dense, sparse):
        assert st_d is Status.OK and st_s is Status.OK
        assert np.abs(xs - xd).max() <= 1e-10 * np.abs(xd).max()
    assert np.abs(sparse[1][0] - x).max() <= 1e-10 * np.abs(x).max()


def test_chain_hb_is_the_simulated_orbit(chain, sparse_solution):
    """HB at H = 16 against simulation (RK4, accurate mode, Δτ = 0.004, 60 forcing periods from the HB state): the
    reference mesh's extremes and the state at θ = 0.  Measured: 2.2e-6 in δ_min/δ_max (the series' truncation at
    the kink of the dead zone, docs/hb.md; 3.5e-7 at H = 32), 2.4e-6 in the elastic positions, 2.1e-5 in the
    velocities.  Asserted: 2e-5, 3e-5 and 2e-4."""
    sol = sparse_solution
    x0, n = sol.state(), chain.n
    run = integrate_batch([chain], x0, IntegrationOptions(dtau=0.004, transient=60, periods=1, accurate=True))
    xs = run.poincare[0, -1]
    D = chain.meshes[0].D
    assert run.element_u_min(0)[0] < D < run.element_u_max(0)[0]  # the reference mesh loses contact
    assert abs(sol.u_min - run.element_u_min(0)[0]) < 2e-5 and abs(sol.u_max - run.element_u_max(0)[0]) < 2e-5
    assert np.abs(sol.equations.elastic.T @ (x0[:n] - xs[:n])).max() < 3e-5  # up to the rigid-body rotation
    assert np.abs(x0[n:] - xs[n:]).max() < 2e-4


def test_chain_multipliers_are_the_period_maps(chain):
    """The elastic Floquet multipliers of the monodromy kernel (its sums over the nonzeros) against the period
    map's monodromy (Δτ = 0.002, accurate mode) at the simulated point, at ω = 0.62 where every mesh stays in
    contact.  Measured 3e-9; asserted 1e-6.  (Where meshes leave contact, as at ω = 0.75 here, both move by at most
    6e-12 under a 1e-13 relative change of the start and agree to 6e-9: docs/hb.md,
    tests/test_periodmap_accurate.py.)"""
    model = chain.with_param("omega", 0.62)
    sol = hb_solve(model, 16)
    assert sol.converged and sol.hill.status is Status.OK and sol.u_min > model.meshes[0].D
    run = integrate_batch([model], sol.state(), IntegrationOptions(dtau=0.004, transient=20, periods=1))
    mu, r = elastic_multipliers(model, PeriodMap(model, 1, dtau=0.002, accurate=True).jacobian(run.poincare[0, -1]))
    assert r == sol.rigid == 1 and mu.size == sol.multipliers.size == 2 * (model.n - 1)
    d = np.abs(sol.multipliers[:, None] - mu[None, :])
    assert max(d.min(axis=0).max(), d.min(axis=1).max()) < 1e-6


def test_twin_elements_switch_together(chain):
    """Two copies of every mesh at half its stiffness and damping (the same deflection, so each pair switches at the
    same instant) give the monodromy multipliers of the chain itself, at ω = 0.75 where the meshes leave contact:
    the second twin's crossing has no bracket in the step after the first's and must switch there, not steps later.
    Measured 6e-14; the kernel before the fix was 0.21 off here."""
    from dataclasses import replace

    from geardyn.analysis.hb.monodromy import monodromy_floquet

    sol = hb_solve(chain.with_param("omega", 0.75), 16)
    eq = sol.equations
    form, nu, x0 = eq.form, eq.nu(), eq.state(sol.unknowns)
    assert sol.u_min < chain.meshes[0].D  # the reference mesh loses contact
    half = [replace(e, C=e.C / 2, K=e.K / 2) for e in form.elements]
    twins = replace(form, elements=tuple(e for h in half for e in (h, h)))
    one, two = (monodromy_floquet(f, nu, x0, eq.elastic).multipliers for f in (form, twins))
    d = np.abs(one[:, None] - two[None, :])
    assert max(d.min(axis=0).max(), d.min(axis=1).max()) < 1e-9
