"""Harmonic balance (AFT) with Hill stability: exact cases and agreement with shooting.

Exact cases
-----------
* Linear response (no contact loss, constant coefficients): u'' + 2ξ0 u' + f(u) = f_p + ω²ε cos θ has
  u = f_p + D + Re[ω²ε e^{iθ} / (1 − ω² + 2iξ0ω)] (D = 0, or f_p so large that u > D always).
* Mathieu equation (DLMF §28.2, 28.17): with w = e^{ζτ}u, u'' + 2ζu' + (1 + κ cos ωτ)u = 0 becomes
  w_tt + (a − 2q cos 2t) w = 0, t = ωτ/2, a = 4(1 − ζ²)/ω², q = −2κ/ω².  On the curves a = a_m(|q|),
  b_m(|q|) (scipy.special.mathieu_a/_b) w has period π or 2π in t, so over one forcing period the
  multipliers of u are a double (−1)^m e^{−ζT}: tr M = 2(−1)^m e^{−ζT}.  First-order averaging
  (Nayfeh & Mook, Nonlinear Oscillations, §5.4) gives the critical damping of the first tongue at
  ω = 2 as ζ_c = κ/4 + O(κ²).
* Meissner equation (rectangular-wave stiffness 1 + κ sgn cos θ): the monodromy is the product of
  closed-form matrix exponentials exp(A₊T/4) exp(A₋T/2) exp(A₊T/4).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq
from scipy.special import mathieu_a, mathieu_b

from geardyn.analysis.hb.hill import hill_floquet
from geardyn.analysis.hb.solve import HBSystem, hb_solve
from geardyn.model import GearModel
from geardyn.status import Status


def _match(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two pairs of multipliers, matched as sets."""
    a, b = np.asarray(a), np.asarray(b)
    return min(max(abs(a[0] - b[0]), abs(a[1] - b[1])), max(abs(a[0] - b[1]), abs(a[1] - b[0])))


# ------------------------------------------------------------------ linear response
@pytest.mark.parametrize("D, fp", [(0.0, 0.2), (1.0, 5.0)])
@pytest.mark.parametrize("omega", [0.4, 0.9, 1.7])
def test_linear_response_h1(D, fp, omega):
    m = GearModel(omega=omega, xi0=0.07, xi=(), kappa=(), eps=(0.3,), fp=fp, D=D)
    sol = hb_solve(m, 1, guess="linear")
    assert sol.status is Status.OK
    z = omega**2 * 0.3 / (1.0 - omega**2 + 2j * 0.07 * omega)
    exact = np.array([fp + D, z.real, -z.imag])
    assert np.max(np.abs(sol.coefficients - exact)) <= 1e-10
    # Floquet multipliers of u'' + 2ξ0u' + u = 0 over T: exp((−ξ0 ± i√(1 − ξ0²))T)
    lam = -0.07 + 1j * math.sqrt(1 - 0.07**2)
    T = 2 * math.pi / omega
    assert _match(sol.multipliers, [np.exp(lam * T), np.exp(np.conj(lam) * T)]) <= 1e-10


# ------------------------------------------------------------------ Mathieu
def _mathieu_boundary(kappa: float, zeta: float, m: int, kind: str, bracket: tuple[float, float]) -> float:
    char = mathieu_a if kind == "a" else mathieu_b

    def g(w: float) -> float:
        return 4.0 * (1.0 - zeta**2) / w**2 - char(m, 2.0 * kappa / w**2)

    return brentq(g, *bracket, xtol=1e-14)


def _gear_mathieu(omega: float, kappa: float, zeta: float, H: int):
    """The gear model reduced to the damped Mathieu equation: D = 0, no load, no STE, u = 0."""
    m = GearModel(omega=omega, xi0=zeta, xi=(), kappa=(kappa,), eps=(), fp=0.0, D=0.0)
    return HBSystem(m, H).stability(np.zeros(2 * H + 1))


@pytest.mark.parametrize("zeta", [0.0, 0.02])
@pytest.mark.parametrize("m, kind, bracket", [(1, "a", (1.5, 2.6)), (1, "b", (1.5, 2.6)),
                                              (2, "a", (0.8, 1.3)), (2, "b", (0.8, 1.3))])
def test_mathieu_boundaries_dlmf(zeta, m, kind, bracket):
    kappa = 0.3
    w = _mathieu_boundary(kappa, zeta, m, kind, bracket)
    res = _gear_mathieu(w, kappa, zeta, 16)
    assert res.status is Status.OK
    T = 2 * math.pi / w
    trace = complex(np.sum(res.multipliers))
    assert abs(trace - 2 * (-1) ** m * math.exp(-zeta * T)) <= 1e-8


def test_mathieu_first_tongue_first_order():
    kappa = 0.02

    def rho(zeta: float) -> float:
        return _gear_mathieu(2.0, kappa, zeta, 8).max_modulus

    zc = brentq(lambda z: rho(z) - 1.0, 1e-4, 0.05, xtol=1e-12)
    assert abs(zc - kappa / 4) <= kappa**2
    assert rho(0.9 * kappa / 4) > 1.0 > rho(1.1 * kappa / 4)


# ------------------------------------------------------------------ Meissner
def _meissner_exact(omega: float, kappa: float, zeta: float) -> np.ndarray:
    T = 2 * math.pi / omega
    Ap = np.array([[0.0, 1.0], [-(1.0 + kappa), -2.0 * zeta]])
    Am = np.array([[0.0, 1.0], [-(1.0 - kappa), -2.0 * zeta]])
    return np.linalg.eigvals(expm(Ap * T / 4) @ expm(Am * T / 2) @ expm(Ap * T / 4))


MEISSNER_HARMONICS = 64  # the number of harmonics at which the 1e-6 agreement is claimed


@pytest.mark.parametrize("omega, kappa, zeta", [(1.3, 0.3, 0.05), (2.0, 0.3, 0.02), (0.8, 0.5, 0.1),
                                                (1.0, 0.4, 0.0)])
def test_meissner_multipliers(omega, kappa, zeta):
    H = MEISSNER_HARMONICS
    L = 2 * H
    c = np.zeros(2 * L + 1, complex)
    c[L] = 2 * zeta
    s = np.zeros(2 * L + 1, complex)
    s[L] = 1.0
    for j in range(1, L + 1, 2):  # sgn(cos θ) = (4/π) Σ_{j odd} (−1)^((j−1)/2) cos(jθ)/j
        s[L + j] = s[L - j] = kappa * (2 / math.pi) * (-1) ** ((j - 1) // 2) / j
    res = hill_floquet(c, s, omega, H)
    assert res.status is Status.OK
    assert _match(res.multipliers, _meissner_exact(omega, kappa, zeta)) <= 1e-6
