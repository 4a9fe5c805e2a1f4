"""Harmonic balance on a system with a rolling-element bearing, against independent references.

The system is ``examples/systems/ball_bearing.toml``: a shaft (x, y, θ) on a ball bearing of 8 balls with radial
clearance under a constant radial load, driving a gear through a torsional mesh.  The mesh acts on the rotations
only, so the shaft's (x, y) obey on their own, in SI,

    m x'' = F_x − c x' − K Σ_j max(δ_j, 0)^n cos ψ_j,   m y'' = F_y − c y' − K Σ_j max(δ_j, 0)^n sin ψ_j,
    δ_j = x cos ψ_j + y sin ψ_j − c_r,   ψ_j = Ω_c t + 2πj/Z,   Ω_c = Ω (1 − d_b/d_m)/2,

periodic in the forcing period (20 mesh cycles: the balls pass the load line at 3/20 of the mesh frequency).  The
reference writes these equations and their variational equation from the file's numbers and finds the periodic
orbit by Newton's method on the period map of SciPy's DOP853 (rtol 1e-12), with its monodromy matrix: none of it
is the code under test.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from geardyn import hb_solve, load_system

FILE = "examples/systems/ball_bearing.toml"
# the file's numbers (SI)
MASS, Z, K, N_EXP, CLEAR = 2.0, 8, 8e9, 1.5, 5e-6
DM, DB = 0.040, 0.010
FX, FY, DAMP = 500.0, -2000.0, 200.0
K_MESH, R1, R2, I1, I2, TEETH = 2e8, 0.030, 0.060, 1e-3, 4e-3, 20
BC = 0.05e-3  # half the backlash: the unit of length
WN = math.sqrt(K_MESH * (R1**2 / I1 + R2**2 / I2))  # ω_n (rad/s) of the mesh's equivalent mass


def _orbit(omega: float, clearance: float = CLEAR, fx: float = FX, fy: float = FY, settle: int = 8):
    """The shaft's periodic (x, y, x', y') at θ = 0 (SI) and its monodromy matrix, by DOP853 (module docstring)."""
    cage = omega * WN / TEETH * (1.0 - DB / DM) / 2.0
    T = TEETH * 2.0 * math.pi / (omega * WN)  # the forcing period: 20 mesh cycles
    ang = 2.0 * np.pi * np.arange(Z) / Z

    def rhs(t, s):
        x, y, vx, vy = s[:4]
        c, sn = np.cos(cage * t + ang), np.sin(cage * t + ang)
        d = x * c + y * sn - clearance
        dp = np.maximum(d, 0.0)
        q = K * dp**N_EXP
        w = np.where(d > 0.0, K * N_EXP * dp ** (N_EXP - 1.0), 0.0)
        kxx, kxy, kyy = np.sum(w * c * c), np.sum(w * c * sn), np.sum(w * sn * sn)
        A = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-kxx, -kxy, -DAMP, 0], [-kxy, -kyy, 0, -DAMP]])
        A[2:] /= MASS
        f = [vx, vy, (fx - DAMP * vx - np.sum(q * c)) / MASS, (fy - DAMP * vy - np.sum(q * sn)) / MASS]
        return np.concatenate([f, (A @ s[4:].reshape(4, 4)).ravel()])

    def period(s):
        y = solve_ivp(rhs, (0.0, T), np.concatenate([s, np.eye(4).ravel()]), "DOP853", rtol=1e-12, atol=1e-16).y
        return y[:4, -1], y[4:, -1].reshape(4, 4)

    s = np.zeros(4)
    for _ in range(settle):
        s = period(s)[0]
    for _ in range(6):
        e, J = period(s)
        ds = np.linalg.solve(J - np.eye(4), s - e)
        s = s + ds
        if np.max(np.abs(ds[:2])) < 1e-15 * BC * 1e3:
            break
    return s, period(s)[1]


def _shaft_state(sol) -> np.ndarray:
    """HB's (x, y, x', y') of the shaft at θ = 0 in SI."""
    st = sol.state()
    n = st.size // 2
    return np.array([st[0], st[1], st[n] * WN, st[n + 1] * WN]) * BC


def _nearest(mu: np.ndarray, ref: np.ndarray) -> float:
    return float(max(np.min(np.abs(mu - z)) for z in ref))


def test_hb_on_the_ball_bearing_is_the_dop853_orbit():
    """H = 160 harmonics of the forcing period (N = 4096 samples) from the linear start (the bearing at its static
    deflection): the shaft's position at θ = 0 is the DOP853 orbit's to 1.9e-9 relative and its velocity to 7.5e-7
    (H = 60, 100, 240, 320: positions 1.8e-7, 5.5e-9, 7.1e-10, 3.2e-10; velocities 3.7e-5, 7.3e-6, 4.7e-7, 2.9e-8),
    and its Floquet multipliers from the monodromy of one period are the DOP853 monodromy's."""
    m = load_system(FILE)
    ref, Jref = _orbit(m.omega)
    sol = hb_solve(m, 160, guess="linear")
    assert sol.converged and sol.samples == 4096
    mine = _shaft_state(sol)
    scale = np.abs(ref)
    assert np.max(np.abs(mine[:2] - ref[:2]) / scale[:2].max()) < 1e-7  # measured 1.9e-9
    assert np.max(np.abs(mine[2:] - ref[2:]) / scale[2:].max()) < 2e-6  # measured 7.5e-7
    # the shaft's four multipliers (two complex pairs, |μ| = exp(-c T/2m) each: 0.5157) are among HB's six
    mu_ref = np.linalg.eigvals(Jref)
    assert np.allclose(np.abs(mu_ref), math.exp(-DAMP / (2 * MASS) * TEETH * 2 * math.pi / (m.omega * WN)), rtol=1e-9)
    assert sol.hill.status.name == "OK" and sol.stable
    assert _nearest(sol.multipliers, mu_ref) < 1e-5  # measured 1.3e-6


def test_hills_method_takes_the_bearing_too():
    """Hill's method (the Jacobian's bearing blocks, with their cross terms) gives the same multipliers."""
    m = load_system(FILE)
    _, Jref = _orbit(m.omega)
    sol = hb_solve(m, 60, guess="linear", floquet="hill")
    assert sol.converged and sol.hill.status.name == "OK"
    assert _nearest(sol.multipliers, np.linalg.eigvals(Jref)) < 2e-4  # measured 6.0e-5 (monodromy: 1.3e-6)


def test_zero_clearance(tmp_path):
    """No clearance: the balls on the load side are always loaded, the load zone's edges are where a ball carries
    nothing, and the bearing is nearly linear (its two pairs of multipliers nearly equal, 0.4537 ± 0.2452i and
    0.4516 ± 0.2489i): at H = 100 the shaft's position is the DOP853 orbit's to 5.3e-8 and its velocity (only the
    varying compliance moves it, 1e-4 m/s) to 7.8e-5 of its size (H = 40, 60: 1.1e-2, 1.4e-3)."""
    text = open(FILE).read().replace('radial_clearance = "5 um"', 'radial_clearance = "0 um"')
    p = tmp_path / "no_clearance.toml"
    p.write_text(text)
    m = load_system(p)
    ref, Jref = _orbit(m.omega, 0.0)
    sol = hb_solve(m, 100, guess="linear")
    assert sol.converged
    mine = _shaft_state(sol)
    assert np.max(np.abs(mine[:2] - ref[:2])) / np.max(np.abs(ref[:2])) < 1e-6
    assert np.max(np.abs(mine[2:] - ref[2:])) / np.max(np.abs(ref[2:])) < 3e-4
    assert _nearest(sol.multipliers, np.linalg.eigvals(Jref)) < 1e-5  # measured 3.4e-6


def test_the_jacobian_with_the_bearings_cross_blocks_is_the_derivative_of_the_residual(monkeypatch):
    """The analytic Jacobian (the sampled law's 2 × 2 blocks, the cross blocks (W_x V_yᵀ) ⊗ T(S_xy) included) against
    central differences of the residual (measured 4e-11 relative), and the sparse assembly equal to the dense."""
    import geardyn.analysis.hb.equations as E

    m = load_system(FILE)
    eq = E.HBEquations(m, 24)
    x = eq.newton(eq.unknowns(eq.linear_guess()))[0]
    x = x + 1e-3 * np.random.default_rng(0).standard_normal(x.size)  # off the solution: every term counts
    R, J = eq.residual(x)
    J = np.asarray(J)
    fd = np.empty_like(J)
    for j in range(x.size):
        h = 1e-6 * max(1.0, abs(x[j]))
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        fd[:, j] = (eq.residual(xp, jacobian=False)[0] - eq.residual(xm, jacobian=False)[0]) / (2 * h)
    assert np.max(np.abs(fd - J)) < 1e-8 * np.max(np.abs(J))
    monkeypatch.setattr(E, "SPARSE_DOFS", 0)
    R2, J2 = E.HBEquations(m, 24).residual(x)
    assert isinstance(J2, E.SparseJacobian)
    assert np.array_equal(R2, R) and np.array_equal(np.asarray(J2), J)


def test_a_larger_clearance_keeps_its_static_deflection_and_its_branch():
    """With 15 µm clearance the linear-spring start of the static problem lies inside the clearance (no stiffness
    there): it is pushed out and Newton finds the shaft's static (x, y), against SciPy's root of the two force
    equations written here (cage at 0); the HB branch in the clearance then runs from 5 to 25 µm."""
    from scipy.optimize import root

    from geardyn import hb_continuation

    m = load_system(FILE).with_param("brg.clearance", 0.3)  # 0.3 b_c = 15 µm
    psi = 2.0 * np.pi * np.arange(Z) / Z
    c = 0.3 * BC

    def balance(s):
        d = np.maximum(s[0] * np.cos(psi) + s[1] * np.sin(psi) - c, 0.0)
        return [(K * np.sum(d**N_EXP * np.cos(psi)) - FX) / 1e3, (K * np.sum(d**N_EXP * np.sin(psi)) - FY) / 1e3]

    sol = root(balance, [2 * c, -4 * c], tol=1e-14)
    assert sol.success
    from geardyn.systems.rolling import static_deflection

    Kt = np.array(m.Kb) + sum(me.k * np.outer(v, v) for me, v in zip(m.meshes, m.V))
    F = np.array(m.F) + sum(me.k * me.D * v for me, v in zip(m.meshes, m.V))
    b = m.bearings[0]
    q, _ = static_deflection(Kt, F, [(m.Vb, b.elements, b.K, b.exponent, b.clearance, b.phase)])
    assert np.max(np.abs(q[:2] * BC - sol.x)) < 1e-9 * np.max(np.abs(sol.x))
    res = hb_continuation(load_system(FILE), "brg.clearance", 0.1, 0.5, harmonics=60, guess="linear")
    assert res.converged and res.values[-1] >= 0.5


def test_the_whole_state_is_on_the_kernels_orbit_with_its_multipliers():
    """All four DOFs (the torsional mesh too): the N-DOF kernel's period map (RK4, Δτ = 0.005) started on HB's state
    (H = 100) returns to it to 4.3e-8, and the kernel's monodromy there has HB's six elastic multipliers (its two
    rigid-body ones are 1) within 1.6e-6."""
    from geardyn.integrate import period_map

    m = load_system(FILE)
    sol = hb_solve(m, 100, guess="linear")
    x0 = sol.state()
    x1, J, _, ok = period_map(m, x0, 1, dtau=0.005)
    assert ok
    assert np.max(np.abs(x1[-1] - x0)) < 1e-6 * np.max(np.abs(x0))
    mu = np.linalg.eigvals(J)
    rigid = np.abs(mu - 1.0) < 1e-9
    assert rigid.sum() == 2
    assert _nearest(sol.multipliers, mu[~rigid]) < 1e-5 and _nearest(mu[~rigid], sol.multipliers) < 1e-5


def test_the_default_harmonics_reach_the_mesh_frequency_of_a_long_forcing_period():
    """The ball pass makes the forcing period 20 mesh cycles (T in ``_orbit``): the mesh is harmonic 20 of
    ω/20, so the default takes 16 mesh harmonics, 20·16 = 320 (16, the pair's default, would leave the mesh out
    of the balance); the shipped gearbox's 1472 cycles would need 23 552 and are refused in one line."""
    import pytest

    from geardyn.analysis.hb.equations import default_harmonics
    from geardyn.errors import ModelError

    assert default_harmonics(load_system(FILE)) == 20 * 16
    with pytest.raises(ModelError, match="spans 1472 mesh cycles"):
        default_harmonics(load_system("examples/gearbox/two_stage_helical.toml"))


def test_harmonics_below_the_mesh_frequency_are_said(tmp_path):
    import subprocess
    import sys

    args = ["hb", "--system", FILE, "--param", "omega", "--start", "0.5", "--stop", "0.5005", "--harmonics", "12"]
    run = subprocess.run([sys.executable, "-m", "geardyn.cli", *args, "--json"], capture_output=True, text=True)
    assert "warning: --harmonics 12 stops below the mesh frequency (harmonic 20 of ω/20" in run.stderr
