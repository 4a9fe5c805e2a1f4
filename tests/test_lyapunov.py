"""Lyapunov spectrum: Liouville identity, Floquet multipliers of stable orbits, the damped Mathieu
tongue against an independent scipy calculation, and the motion classification on cases with
known answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from geardyn.analysis.classify import (
    LLE_FLOOR,
    LLE_SIGMAS,
    MOTION_CHAOTIC,
    MOTION_DIVERGED,
    MOTION_PERIODIC,
    MOTION_QUASIPERIODIC,
    MOTION_UNRESOLVED,
    classify_motion,
    count_loops,
    curve_dimension,
    detect_period,
    motion_label,
    settling_ratio,
)
from geardyn.analysis.lyapunov import lyapunov_batch, lyapunov_spectrum, spectrum_from_log
from geardyn.analysis.steady import classify_batch
from geardyn.integrate import integrate_batch, period_map
from geardyn.model import GearModel, IntegrationOptions

PAPER = GearModel()


# ------------------------------------------------------------------------------ Liouville
LIOUVILLE_CASES = [
    PAPER.replace(omega=0.8),  # period-2
    PAPER.replace(omega=1.2),  # chaotic
    PAPER.replace(omega=1.35),  # chaotic
    PAPER.replace(omega=1.05),  # chaotic window
    PAPER.replace(omega=0.6, xi0=0.05, xi=(0.1,)),  # larger damping harmonic
    GearModel(omega=1.3, xi0=0.07, xi=(0.03, 0.02), kappa=(0.15, 0.05), eps=(0.5, 0.1), phi_k=(0.3, 1.0), D=0.8),
]


def test_liouville_sum_of_exponents_equals_minus_two_xi0():
    out = lyapunov_batch(LIOUVILLE_CASES, (0.0, 0.0), IntegrationOptions(transient=200, periods=400))
    lam = out["exponents"]
    for m, l in zip(LIOUVILLE_CASES, lam):
        assert abs(l.sum() + 2.0 * m.xi0) < 1e-6, (m.omega, l)
    # the chaotic cases really are chaotic: λ1 well above its uncertainty
    for k in (1, 2):
        assert lam[k, 0] > 10 * out["uncertainty"][k, 0] > 0


def test_liouville_in_accurate_mode():
    out = lyapunov_batch(
        [PAPER.replace(omega=1.2)], (0.0, 0.0), IntegrationOptions(transient=50, periods=100, accurate=True)
    )
    assert abs(out["exponents"][0].sum() + 0.2) < 1e-6


def test_spectrum_from_log_block_statistics():
    rng = np.random.default_rng(1)
    T = 2.0
    log = np.column_stack([0.1 * T + 0.05 * rng.standard_normal(4000), -0.3 * T + 0.05 * rng.standard_normal(4000)])
    lam, err = spectrum_from_log(log, T, blocks=20)
    # i.i.d. logs: standard error = σ/√m/T
    expect = 0.05 / np.sqrt(0.95 * 4000) / T
    assert np.allclose(err, expect, rtol=0.5)
    assert np.all(np.abs(lam - [0.1, -0.3]) < 4 * err)
    # batch form and λ1 >= λ2 ordering
    lam2, err2 = spectrum_from_log(np.stack([log, log[:, ::-1]]), np.array([T, T]))
    assert np.allclose(lam2[0], lam2[1]) and lam2[0, 0] >= lam2[0, 1]


# ------------------------------------------------------------------------------ Floquet
@pytest.mark.parametrize("omega, n", [(0.75, 1), (0.8, 2), (0.6, 1), (1.08, 4)])
def test_largest_exponent_equals_floquet_rate(omega, n):
    m = PAPER.replace(omega=omega)
    r = integrate_batch([m], (0.0, 0.0), IntegrationOptions(transient=3000, periods=2 * n + 8))
    assert detect_period(r.poincare[0]) == n
    x = r.end_state[0]
    pts, M, _, ok = period_map(m, x, n)
    assert ok and np.allclose(pts[-1], x, atol=1e-8)  # a converged point of the orbit
    mu = np.linalg.eigvals(M)
    T = m.period
    lam_f = np.log(np.max(np.abs(mu))) / (n * T)
    assert abs(np.log(abs(np.linalg.det(M))) / (n * T) + 2 * m.xi0) < 1e-8  # det(monodromy) = exp(-2ξ0 nT)
    res = lyapunov_spectrum(m, IntegrationOptions(transient=0, periods=400 * n), x)
    lam1, err1 = res.exponents[0], res.uncertainty[0]
    assert lam1 < 0
    assert abs(lam1 - lam_f) <= 3 * err1 + 2e-4 * abs(lam_f) + 1e-6, (lam1, err1, lam_f)
    assert res.motion["motion"] == f"period-{n}"


# ------------------------------------------------------------------------------ Mathieu tongue
MATHIEU_XI, MATHIEU_KAPPA = 0.02, 0.3


def _mathieu(omega: float) -> GearModel:
    """The damped Mathieu equation u'' + 2ξ0 u' + (1 + κ1 cos ωτ) u = 0 as a GearModel."""
    return GearModel(omega=omega, xi0=MATHIEU_XI, xi=(), kappa=(MATHIEU_KAPPA,), eps=(), fp=0.0, D=0.0)


def _floquet_rate_scipy(omega: float) -> float:
    """Independent reference: ln|μ_max|/T from the monodromy of the linear Mathieu equation (DOP853)."""
    T = 2 * np.pi / omega

    def rhs(t, y):
        k = 1.0 + MATHIEU_KAPPA * np.cos(omega * t)
        return [y[1], -2 * MATHIEU_XI * y[1] - k * y[0], y[3], -2 * MATHIEU_XI * y[3] - k * y[2]]

    s = solve_ivp(rhs, (0.0, T), [1.0, 0.0, 0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14)
    M = s.y[:, -1].reshape(2, 2).T
    return float(np.log(np.max(np.abs(np.linalg.eigvals(M)))) / T)


def test_damped_mathieu_principal_tongue():
    lo = brentq(_floquet_rate_scipy, 1.6, 2.0, xtol=1e-12)
    hi = brentq(_floquet_rate_scipy, 2.0, 2.4, xtol=1e-12)
    assert 1.8 < lo < 2.0 < hi < 2.2
    d = 1e-3
    inside = [lo + d, 2.0, hi - d]
    outside = [lo - d, hi + d, 1.7, 2.3]
    ws = inside + outside
    out = lyapunov_batch([_mathieu(w) for w in ws], (0.0, 0.0), IntegrationOptions(transient=0, periods=1000))
    lam, err = out["exponents"][:, 0], out["uncertainty"][:, 0]
    for w, l, e in zip(ws, lam, err):
        ref = _floquet_rate_scipy(w)
        assert abs(l - ref) <= 4 * e + 1e-5, (w, l, e, ref)
    assert np.all(lam[: len(inside)] > LLE_SIGMAS * err[: len(inside)])  # zero solution unstable inside
    assert np.all(lam[len(inside) :] < -LLE_SIGMAS * err[len(inside) :])  # and stable outside
    # outside the tongue the multipliers are a complex pair: λ1 = λ2 = -ξ0
    assert abs(lam[-1] + MATHIEU_XI) < 4 * err[-1] + 1e-5


# ------------------------------------------------------------------------------ classification
def test_classify_motion_thresholds():
    band = LLE_SIGMAS * 1e-3 + LLE_FLOOR
    codes = classify_motion(
        [1, 0, 0, 0, 0, -1, 0, 0, 0],
        [0.5, band * 1.01, band * 0.99, -band * 0.99, -band * 1.01, 0.0, np.nan, 0.0, 0.0],
        [1e-3] * 9,
        [True, True, True, True, True, False, True, True, True],
        [np.nan] * 7 + [0.45, 1.0],
        [np.nan] * 8 + [0.5],
    )
    assert codes.tolist() == [
        MOTION_PERIODIC,
        MOTION_CHAOTIC,
        MOTION_QUASIPERIODIC,
        MOTION_QUASIPERIODIC,
        MOTION_UNRESOLVED,
        MOTION_DIVERGED,
        MOTION_UNRESOLVED,
        MOTION_UNRESOLVED,
        MOTION_UNRESOLVED,
    ]
    assert motion_label(MOTION_PERIODIC, 3) == "period-3"
    assert motion_label(MOTION_CHAOTIC) == "chaotic"


def test_geometry_diagnostics():
    th = 2 * np.pi * 0.6180339887 * np.arange(1000)
    ellipse = np.column_stack([np.cos(th), 0.5 * np.sin(th)])
    assert 0.85 < curve_dimension(ellipse) < 1.25
    assert count_loops(ellipse) == 1
    two = np.concatenate([ellipse * 0.1 + [1, 0], ellipse * 0.1 - [1, 0]])
    assert count_loops(two) == 2
    assert curve_dimension(np.tile([[1.0, 2.0], [3.0, 4.0]], (50, 1))) == 0.0
    converging = np.array([[1 + 0.99**k * (-1) ** k, 0.0] for k in range(400)])
    assert settling_ratio(converging) < 0.5
    assert 0.8 < settling_ratio(ellipse) < 1.25


CLASS_CASES = [
    # (model, initial state, expected motion label, expected impact code)
    (GearModel(omega=0.9, fp=2.0), (2.0, 0.0), "period-1", 0),  # linear limit, always in contact
    (PAPER.replace(omega=0.8), (0.0, 0.0), "period-2", 1),
    (PAPER.replace(omega=1.3), (0.0, 0.0), "chaotic", None),
    # undamped linear oscillator forced at an incommensurate frequency: an exact torus
    (
        GearModel(omega=0.6180339887, xi0=0.0, xi=(), kappa=(), eps=(0.5,), fp=0.0, D=0.0),
        (1.0, 0.0),
        "quasi-periodic",
        0,
    ),
    # damped Mathieu inside its tongue: the linear response grows without bound
    (_mathieu(2.0).replace(eps=(0.1,)), (0.1, 0.0), "diverged", -1),
    (PAPER.replace(omega=0.8, xi0=-0.2), (0.0, 0.0), "diverged", -1),  # negative damping
]


def test_classification_known_cases():
    models = [c[0] for c in CLASS_CASES]
    states = np.array([c[1] for c in CLASS_CASES])
    res = integrate_batch(models, states, IntegrationOptions(transient=300, periods=200))
    out = classify_batch(res)
    for i, (m, _, label, impact) in enumerate(CLASS_CASES):
        got = motion_label(out["motion"][i], out["period"][i])
        assert got == label, (m, got, out["lle"][i], out["lle_err"][i], out["curve_dim"][i])
        if impact is not None:
            assert out["impact"][i] == impact
    q = [c[2] for c in CLASS_CASES].index("quasi-periodic")
    assert out["loops"][q] == 1 and abs(out["lle"][q]) < LLE_FLOOR
    c = [c[2] for c in CLASS_CASES].index("chaotic")
    assert out["lle"][c] > 0.03 and out["settled"][c] == 1


def test_slowly_settling_orbit_is_resolved():
    """ω = 1.10 (paper defaults) is a period-8 orbit near a period doubling that needs thousands of
    periods to settle: the settling passes find its period instead of calling it quasi-periodic."""
    res = integrate_batch([PAPER.replace(omega=1.10)], (0.0, 0.0), IntegrationOptions(transient=300, periods=200))
    assert detect_period(res.poincare[0]) == 0
    out = classify_batch(res)
    assert motion_label(out["motion"][0], out["period"][0]) == "period-8"
    assert out["settled"][0] >= 2


def test_simulate_reports_motion():
    from geardyn.analysis.steady import simulate

    s = simulate(PAPER.replace(omega=1.2)).summary
    assert s["motion"] == "chaotic" and s["lle"] > 0
    s = simulate(PAPER.replace(omega=0.8)).summary
    assert s["motion"] == "period-2" and s["lle"] is None


@pytest.mark.slow
def test_liouville_long_records():
    ws = np.linspace(0.5, 1.5, 21)
    out = lyapunov_batch(
        [PAPER.replace(omega=w) for w in ws], (0.0, 0.0), IntegrationOptions(transient=300, periods=3000)
    )
    assert np.all(np.abs(out["exponents"].sum(axis=1) + 0.2) < 1e-6)


@pytest.mark.parametrize("omega", [1.2, 0.8])  # chaotic, periodic
def test_a_run_continued_from_its_tangent_basis_is_the_one_run(omega):
    """``integrate_batch(..., tangent0=)``: a Lyapunov run in two blocks, the second from the state and the
    orthonormal tangent basis the first ended with, gives the one run's logs and end state, bit for bit."""
    m = GearModel(omega=omega)
    o = IntegrationOptions(transient=20, periods=60)
    one = integrate_batch([m], None, o, lyapunov=True)
    a = integrate_batch([m], None, o.replace(periods=25), lyapunov=True)
    b = integrate_batch([m], a.end_state, o.replace(transient=0, periods=35), lyapunov=True, tangent0=a.tangent)
    np.testing.assert_array_equal(np.concatenate([a.lyapunov_log, b.lyapunov_log], axis=1), one.lyapunov_log)
    np.testing.assert_array_equal(b.end_state, one.end_state)
