"""The rolling-element bearing law (:mod:`geardyn.systems.bearings`) against Harris's load distribution.

References: T. A. Harris, M. N. Kotzalas, *Rolling Bearing Analysis*, 5th ed. (2006), vol. 1, ch. 7 ("Distribution of
internal loading in statically loaded bearings"): the load of the element at ψ from the load line is
Q_ψ = Q_max [1 − (1 − cos ψ)/(2ε)]^n with ε = (1 − P_d/(2δ_r))/2, and the radial load F_r = Z Q_max J_r(ε) with the
radial integral J_r(ε) = (1/2π) ∫_{−ψ_l}^{ψ_l} [1 − (1 − cos ψ)/(2ε)]^n cos ψ dψ (Sjövall), Q_max = K (δ_r − P_d/2)^n.
Stribeck's zero-clearance result F_r = Z Q_max/4.37 (ball) and Z Q_max/4.08 (roller), i.e. J_r(1/2) = 0.2288 and
0.2453 (Harris's table of J_r(ε)), checks the quadrature first.  The references below use SciPy's quadrature and
root finding of that formulation only, not the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from geardyn.errors import ModelError
from geardyn.systems.bearings import (
    BALL_EXPONENT,
    ROLLER_EXPONENT,
    RollingBearing,
    ball_bearing_forces,
    bearing_forces,
    bearing_stiffness,
    loaded_elements,
)


def harris_jr(eps: float, n: float) -> float:
    """Sjövall's radial integral J_r(ε) by quadrature (ε <= 1: a partial load zone)."""
    psi_l = math.acos(max(-1.0, 1.0 - 2.0 * eps))

    def f(psi: float) -> float:
        return max(0.0, 1.0 - (1.0 - math.cos(psi)) / (2.0 * eps)) ** n * math.cos(psi)

    return quad(f, -psi_l, psi_l, epsabs=1e-12, epsrel=1e-10, limit=200)[0] / (2.0 * math.pi)


def harris_radial_load(delta_r: float, Pd: float, Z: int, K: float, n: float) -> float:
    """F_r = Z K (δ_r − P_d/2)^n J_r(ε) of a deflection δ_r (clearance P_d/2 = c)."""
    if delta_r <= Pd / 2:
        return 0.0
    eps = 0.5 * (1.0 - Pd / (2.0 * delta_r))
    return Z * K * (delta_r - Pd / 2) ** n * harris_jr(eps, n)


# a 6210-like deep-groove ball bearing (Harris's example bearing: Z = 10, ball 12.7 mm, d_m 70 mm)
BALL = RollingBearing("ball", 10, 0.070, 0.0127, 0.0, 10e-6, 8.0e9)


def _cage_mean_force(b: RollingBearing, delta_r: float, samples: int = 4096) -> float:
    """The radial force of the discrete bearing averaged over the cage angle (one ball pass, midpoint rule)."""
    phase = (np.arange(samples) + 0.5) / samples * 2.0 * np.pi / b.elements
    fx, _fy = bearing_forces(delta_r, 0.0, phase, b.elements, b.stiffness, b.exponent, b.clearance)
    return float(-np.mean(fx))


@pytest.mark.parametrize(
    "eps, n, table",
    [(0.1, 1.5, 0.1156), (0.5, 1.5, 0.2288), (1.0, 1.5, 0.2546), (0.5, 1.1, 0.2453)],  # Harris's J_r(ε) table
)
def test_harris_table_checks_the_reference_quadrature(eps, n, table):
    """J_r(ε) as Harris tabulates it (point contact n = 1.5; line contact with his n = 1.1), to its 4 digits;
    J_r(1/2) is Stribeck's 1/4.37 (ball) and 1/4.08 (roller)."""
    assert harris_jr(eps, n) == pytest.approx(table, abs=6e-5)


def test_roller_exponent_is_ten_ninths():
    assert ROLLER_EXPONENT == 10.0 / 9.0 and BALL_EXPONENT == 1.5
    assert RollingBearing("roller", 12, 0.06, 0.01, 0.0, 0.0, 1e9).exponent == ROLLER_EXPONENT


@pytest.mark.parametrize("ratio", [1.2, 2.0, 5.0])
def test_cage_averaged_load_equals_harris_load_distribution(ratio):
    """The cage-angle mean of the discrete force is Z/(2π) ∫ … dψ, Harris's F_r = Z Q_max J_r(ε), exactly."""
    delta_r = ratio * BALL.clearance
    ref = harris_radial_load(delta_r, 2 * BALL.clearance, BALL.elements, BALL.stiffness, BALL.exponent)
    assert _cage_mean_force(BALL, delta_r) == pytest.approx(ref, rel=1e-6)


@pytest.mark.parametrize("kind", ["ball", "roller"])
def test_static_load_deflection_with_clearance(kind):
    """Deflection under a radial load F_r: the discrete bearing (cage-averaged) against Harris's closed form."""
    b = RollingBearing(kind, 12, 0.060, 0.010, 0.0, 15e-6, 6.0e9 if kind == "ball" else 1.0e9)
    for Fr in (200.0, 2000.0, 20000.0):
        ref = brentq(
            lambda d: harris_radial_load(d, 2 * b.clearance, b.elements, b.stiffness, b.exponent) - Fr,
            b.clearance * (1 + 1e-9),
            1e-2,
            xtol=1e-16,
            rtol=1e-14,
        )
        got = brentq(lambda d: _cage_mean_force(b, d) - Fr, b.clearance * (1 + 1e-9), 1e-2, xtol=1e-16, rtol=1e-14)
        assert got == pytest.approx(ref, rel=1e-6)
        assert got > b.clearance


def test_zero_clearance_stribeck_ratio():
    """Without clearance the most loaded ball carries Q_max = F_r J_r(1/2)⁻¹/Z ≈ 4.37 F_r/Z (Stribeck)."""
    b = RollingBearing("ball", 10, 0.070, 0.0127, 0.0, 0.0, 8.0e9)
    delta = 20e-6
    Fr = _cage_mean_force(b, delta)
    Qmax = b.stiffness * delta**1.5
    assert Fr > 0
    assert Qmax * b.elements / Fr == pytest.approx(1 / harris_jr(0.5, 1.5), rel=1e-6)
    assert Qmax * b.elements / Fr == pytest.approx(4.37, abs=0.01)


def test_stiffness_is_the_derivative_of_the_force():
    x, y, ph = 23e-6, -7e-6, 0.3
    k = bearing_stiffness(x, y, ph, BALL.elements, BALL.stiffness, BALL.exponent, BALL.clearance)
    h = 1e-10
    for j, (dx, dy) in enumerate(((h, 0.0), (0.0, h))):
        fp = bearing_forces(x + dx, y + dy, ph, BALL.elements, BALL.stiffness, BALL.exponent, BALL.clearance)
        fm = bearing_forces(x - dx, y - dy, ph, BALL.elements, BALL.stiffness, BALL.exponent, BALL.clearance)
        col = -(np.array(fp) - np.array(fm)) / (2 * h)
        np.testing.assert_allclose(k[:, j], col, rtol=1e-6)


def test_inside_the_clearance_there_is_no_force():
    fx, fy = bearing_forces(6e-6, 5e-6, 0.1, 10, 1e9, 1.5, 10e-6)
    assert fx == 0.0 and fy == 0.0
    assert loaded_elements(6e-6, 5e-6, 0.1, 10, 10e-6) == 0


def test_cage_and_ball_pass_frequencies():
    """ω_cage = Ω (1 − d_b cos α/d_m)/2 and the force repeats with the ball pass Z ω_cage (Harris ch. 9)."""
    b = RollingBearing("ball", 9, 0.0395, 0.0079, math.radians(15), 5e-6, 1e10)
    assert b.cage_ratio == pytest.approx(0.5 * (1 - 0.0079 * math.cos(math.radians(15)) / 0.0395), rel=1e-15)
    om = 2 * math.pi * 30.0
    Tb = 2 * math.pi / (b.ball_pass_ratio * om)
    t = np.linspace(0, 0.01, 7)
    f0 = ball_bearing_forces(b, 20e-6, 3e-6, t, om)
    f1 = ball_bearing_forces(b, 20e-6, 3e-6, t + Tb, om)
    np.testing.assert_allclose(f0, f1, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize(
    "kw, key",
    [
        (dict(kind="needle"), "type"),
        (dict(elements=2), "elements"),
        (dict(element_diameter=0.08), "element_diameter"),
        (dict(contact_angle=math.pi / 2), "contact_angle"),
        (dict(clearance=-1e-6), "clearance"),
        (dict(stiffness=0.0), "stiffness"),
    ],
)
def test_bad_bearings_are_refused_naming_the_key(kw, key):
    args = dict(
        kind="ball",
        elements=10,
        pitch_diameter=0.07,
        element_diameter=0.0127,
        contact_angle=0.0,
        clearance=1e-5,
        stiffness=1e9,
    )
    args.update(kw)
    with pytest.raises(ModelError, match=key):
        RollingBearing(**args)


def test_varying_compliance_frequency_in_the_spectrum():
    """A rotor of mass m on one ball bearing with clearance under a constant radial load W, integrated with SciPy
    (DOP853) on the law's forces: the loaded zone passes the load line Z times per cage revolution, so the
    vertical response's strongest line (DC aside) is the ball-pass frequency Z f_cage, f_cage = f_s (1 − d_b cos α /
    d_m)/2 (Harris & Kotzalas ch. 9; Sopanen & Mikkola 2003), not the shaft or cage frequency."""
    from scipy.integrate import solve_ivp

    b = RollingBearing("ball", 8, 0.0395, 0.0079, 0.0, 5e-6, 1.0e10)
    m, W, fs = 2.0, 500.0, 50.0
    om = 2 * math.pi * fs
    n = float(b.exponent)
    # linearised stiffness at the static deflection (cage-averaged), for a damping ratio of 5 %
    k_lin = bearing_stiffness(0.0, -2.2e-5, 0.0, b.elements, b.stiffness, n, b.clearance)[1, 1]
    c = 2 * 0.05 * math.sqrt(k_lin * m)

    def rhs(t, s):
        x, y, vx, vy = s
        fx, fy = ball_bearing_forces(b, x, y, t, om)
        return [vx, vy, (fx - c * vx) / m, (fy - c * vy - W) / m]

    fs_sample, t0, T = 20000.0, 0.2, 0.5
    t = t0 + np.arange(int(T * fs_sample)) / fs_sample
    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, -2.2e-5, 0.0, 0.0], method="DOP853", t_eval=t, rtol=1e-9, atol=1e-14)
    assert sol.success
    y = sol.y[1] - np.mean(sol.y[1])
    spec = np.abs(np.fft.rfft(y * np.hanning(y.size)))
    f = np.fft.rfftfreq(y.size, 1 / fs_sample)
    peak = f[np.argmax(spec[1:]) + 1]
    f_bp = b.elements * b.cage_ratio * fs
    assert abs(peak - f_bp) <= 2 * (f[1] - f[0])
    assert abs(f_bp - fs) > 10 and abs(f_bp - b.cage_ratio * fs) > 10
