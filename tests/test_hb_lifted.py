"""The lifted sparse solve of the harmonic-balance Jacobian (``SparseJacobian``: auxiliary unknowns z = (Vᵀ ⊗ I) x
and y = Op z, whose Schur complement onto x is J) gives the solution of J itself.

Reference: the dense Jacobian of the same equations (``SPARSE_DOFS`` raised: assembled by Kronecker products, the
code's dense path) solved by LAPACK (``numpy.linalg.solve``), plain and bordered as the continuation borders it, on
the 48-DOF chain of ``benchmarks/hb_scaling.py`` (8 meshes, a rigid-body mode) with every mesh in contact and with
contact loss, and on the ball-bearing system (a rolling bearing's cross blocks) taken sparse.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.hb import equations
from geardyn.systems import load_system

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

OMEGA = 0.75


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    from ndof_scaling import chain_toml

    path = chain_toml(8, tmp_path_factory.mktemp("chain") / "chain8.toml", fp_torque=30.0, eps_um=10.0)
    return load_system(path).with_param("omega", OMEGA)


def _pair(model, H, monkeypatch):
    """The equations with the sparse (lifted) Jacobian and with the dense one."""
    monkeypatch.setattr(equations, "SPARSE_DOFS", 0)
    sparse = equations.HBEquations(model, H, param="omega")
    sparse._entry(None)  # (the base point: the pattern is made with it)
    monkeypatch.setattr(equations, "SPARSE_DOFS", 10**6)
    dense = equations.HBEquations(model, H, param="omega")
    return sparse, dense


def _scaled(eq, omega, factor):
    """The linear response at ``omega`` with its dynamic part times ``factor`` (larger: the meshes leave contact)."""
    Q = eq.linear_guess(omega)
    Q[:, 1:] *= factor
    return eq.unknowns(Q)


def _rel(a, b):
    return float(np.abs(a - b).max() / np.abs(b).max())


def _check_solves(sparse_eq, dense_eq, x, omega, rng):
    R, J = sparse_eq.residual(x, omega)
    Rd, Jd = dense_eq.residual(x, omega)
    assert isinstance(J, equations.SparseJacobian) and isinstance(Jd, np.ndarray)
    assert J.lifted().shape[0] > Jd.shape[0]  # the lifted system is solved
    assert np.abs(np.asarray(J) - Jd).max() <= 1e-14 * np.abs(Jd).max()  # tocsc: J itself
    b = rng.standard_normal(Jd.shape[0])
    assert _rel(J.solve(b), np.linalg.solve(Jd, b)) <= 1e-10
    assert _rel(equations.solve(J, b), np.linalg.solve(Jd, b)) <= 1e-10
    # bordered as the continuation's corrector borders it: ∂R/∂p as the last column, a normal as the last row
    (_, A), (_, Ad) = sparse_eq.bordered(x, omega, 0.3), dense_eq.bordered(x, omega, 0.3)
    row = rng.standard_normal(Ad.shape[0])
    A[-1], Ad[-1] = row, row
    b = rng.standard_normal(Ad.shape[0])
    assert np.abs(np.asarray(A) - Ad).max() <= 1e-14 * np.abs(Ad).max()
    assert _rel(A.solve(b), np.linalg.solve(Ad, b)) <= 1e-10
    return A, Ad, b


def test_chain_lifted_solves_are_the_dense_ones(chain, monkeypatch):
    """Plain and bordered, in contact (the linear response at ω = 0.6: δ_min > D on every mesh) and with contact
    loss (three times its dynamic part at ω = 0.75: δ_min < D < δ_max on every mesh); and
    a chord step: the factors of another lifted matrix of the same values give the same solution."""
    sparse_eq, dense_eq = _pair(chain, 16, monkeypatch)
    assert sparse_eq.basis.dofs == 48 and sparse_eq.basis.rigid == 1
    rng = np.random.default_rng(34)
    D = np.array([el.gap for el in sparse_eq.form.elements])
    x_contact, x_loss = _scaled(sparse_eq, 0.6, 1.0), _scaled(sparse_eq, OMEGA, 3.0)
    ext = sparse_eq.element_extremes(x_contact, 0.6)
    assert np.all(ext[:, 0] > D)
    ext = sparse_eq.element_extremes(x_loss, OMEGA)
    assert np.all((ext[:, 0] < D) & (D < ext[:, 1]))
    for x, omega in ((x_contact, 0.6), (x_loss, OMEGA)):
        A, Ad, b = _check_solves(sparse_eq, dense_eq, x, omega, rng)
        # a chord step with the factors of a copy of A (the same values): the solution of A
        B = equations.SparseJacobian(A.pattern, A.values.copy(), A.col.copy())
        B[-1] = A.row
        B.solve(rng.standard_normal(b.size))
        assert _rel(A.solve(b, B.lu), np.linalg.solve(Ad, b)) <= 1e-10
        assert A.lu is B.lu


def test_chain_chord_step_refines_towards_the_solution(chain, monkeypatch):
    """The factors of a neighbouring point's lifted matrix (ω and the unknowns 1e-7 apart, relative): one step of
    refinement with the current matrix's residual brings the answer a thousand times closer to the current matrix's
    solution (the dense LAPACK solve) than the neighbour's factors alone."""
    sparse_eq, dense_eq = _pair(chain, 16, monkeypatch)
    rng = np.random.default_rng(7)
    x = _scaled(sparse_eq, OMEGA, 3.0)
    _, A = sparse_eq.bordered(x, OMEGA)
    _, Ad = dense_eq.bordered(x, OMEGA)
    _, A0 = sparse_eq.bordered(x * (1 + 1e-7), OMEGA + 1e-7)
    row = rng.standard_normal(Ad.shape[0])
    A[-1], Ad[-1], A0[-1] = row, row, row
    b = rng.standard_normal(Ad.shape[0])
    exact = np.linalg.solve(Ad, b)
    A0.solve(b)
    rhs = np.zeros(A0.lifted().shape[0])
    rhs[: b.size] = b
    unrefined = A0.lu.solve(rhs)[: b.size]
    chord = A.solve(b, A0.lu)
    assert A.lu is A0.lu
    assert _rel(unrefined, exact) > 1e-6  # (measured 5.5e-5: the neighbour's factors alone)
    assert _rel(chord, exact) < 1e-3 * _rel(unrefined, exact)  # (measured 3.1e-9)


def test_ball_bearing_lifted_solves_are_the_dense_ones(monkeypatch):
    """The ball-bearing system (a mesh and a rolling bearing's x and y rows with their cross blocks, a rigid-body
    mode) assembled sparse: plain and bordered solves against LAPACK on the dense Jacobian, at the linear response
    and at three times its dynamic part."""
    model = load_system(ROOT / "examples" / "systems" / "ball_bearing.toml").with_param("omega", OMEGA)
    sparse_eq, dense_eq = _pair(model, 40, monkeypatch)
    assert any(i != j for i, j in equations._couplings(sparse_eq.form))  # the bearing's cross blocks
    rng = np.random.default_rng(5)
    for factor in (1.0, 3.0):
        _check_solves(sparse_eq, dense_eq, _scaled(sparse_eq, OMEGA, factor), OMEGA, rng)
