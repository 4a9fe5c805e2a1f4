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

from geardyn.analysis.hb.equations import HBEquations
from geardyn.analysis.hb.hill import hill_floquet
from geardyn.analysis.hb.solve import hb_solve
from geardyn.model import GearModel
from geardyn.status import Status


def _match(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two pairs of multipliers, matched as sets."""
    a, b = np.asarray(a), np.asarray(b)
    return min(max(abs(a[0] - b[0]), abs(a[1] - b[1])), max(abs(a[0] - b[1]), abs(a[1] - b[0])))


#: Largest multiplier error of each Floquet method on the exact cases: Hill's method is exact for constant
#: coefficients; the monodromy matrix carries RK4's error, T ρ STEP_ANGLE⁴/120 (docs/hb.md), below 1e-7 here.
EXACT_TOL = {"hill": 1e-10, "monodromy": 1e-7}


# ------------------------------------------------------------------ linear response
@pytest.mark.parametrize("floquet", ["hill", "monodromy"])
@pytest.mark.parametrize("D, fp", [(0.0, 0.2), (1.0, 5.0)])
@pytest.mark.parametrize("omega", [0.4, 0.9, 1.7])
def test_linear_response_h1(D, fp, omega, floquet):
    m = GearModel(omega=omega, xi0=0.07, xi=(), kappa=(), eps=(0.3,), fp=fp, D=D)
    sol = hb_solve(m, 1, guess="linear", floquet=floquet)
    assert sol.status is Status.OK
    z = omega**2 * 0.3 / (1.0 - omega**2 + 2j * 0.07 * omega)
    exact = np.array([fp + D, z.real, -z.imag])
    assert np.max(np.abs(sol.coefficients - exact)) <= 1e-10
    # Floquet multipliers of u'' + 2ξ0u' + u = 0 over T: exp((−ξ0 ± i√(1 − ξ0²))T)
    lam = -0.07 + 1j * math.sqrt(1 - 0.07**2)
    T = 2 * math.pi / omega
    assert _match(sol.multipliers, [np.exp(lam * T), np.exp(np.conj(lam) * T)]) <= EXACT_TOL[floquet]


# ------------------------------------------------------------------ Mathieu
def _mathieu_boundary(kappa: float, zeta: float, m: int, kind: str, bracket: tuple[float, float]) -> float:
    char = mathieu_a if kind == "a" else mathieu_b

    def g(w: float) -> float:
        return 4.0 * (1.0 - zeta**2) / w**2 - char(m, 2.0 * kappa / w**2)

    return brentq(g, *bracket, xtol=1e-14)


def _gear_mathieu(omega: float, kappa: float, zeta: float, H: int, floquet: str = "hill"):
    """The gear model reduced to the damped Mathieu equation: D = 0, no load, no STE, u = 0."""
    m = GearModel(omega=omega, xi0=zeta, xi=(), kappa=(kappa,), eps=(), fp=0.0, D=0.0)
    return HBEquations(m, H, floquet=floquet).stability(np.zeros(2 * H + 1))


@pytest.mark.parametrize("floquet", ["hill", "monodromy"])
@pytest.mark.parametrize("zeta", [0.0, 0.02])
@pytest.mark.parametrize(
    "m, kind, bracket", [(1, "a", (1.5, 2.6)), (1, "b", (1.5, 2.6)), (2, "a", (0.8, 1.3)), (2, "b", (0.8, 1.3))]
)
def test_mathieu_boundaries_dlmf(zeta, m, kind, bracket, floquet):
    kappa = 0.3
    w = _mathieu_boundary(kappa, zeta, m, kind, bracket)
    res = _gear_mathieu(w, kappa, zeta, 16, floquet)
    assert res.status is Status.OK
    T = 2 * math.pi / w
    trace = complex(np.sum(res.multipliers))
    assert abs(trace - 2 * (-1) ** m * math.exp(-zeta * T)) <= 1e-8


@pytest.mark.parametrize("floquet", ["hill", "monodromy"])
def test_mathieu_first_tongue_first_order(floquet):
    kappa = 0.02

    def rho(zeta: float) -> float:
        return _gear_mathieu(2.0, kappa, zeta, 8, floquet).max_modulus

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


@pytest.mark.parametrize("omega, kappa, zeta", [(1.3, 0.3, 0.05), (2.0, 0.3, 0.02), (0.8, 0.5, 0.1), (1.0, 0.4, 0.0)])
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


# ------------------------------------------------------------------ against shooting
# Events of geardyn's own shooting continuation (geardyn.analysis.periodic.continuation, period 1,
# ω from 0.5 to 1.0, switch=False) in the accurate mode (steps split at u = ±D) with Δτ = 0.0005;
# Δτ = 0.001 gives the same values to ~1e-14, so the RK4 error is negligible.  Recomputed live by
# the slow test below.
SHOOTING_EVENTS = {
    "defaults": [
        ("grazing", 0.5653637910409205),
        ("fold", 0.6196583031679641),
        ("fold", 0.5549281687177483),
        ("period-doubling", 0.7840304635925194),
    ],
    "piecewise-linear": [
        ("grazing", 0.5366682782768969),
        ("fold", 0.5950030552494947),
        ("fold", 0.5406506774697525),
        ("period-doubling", 0.7904529595603209),
    ],
}
CASES = {"defaults": GearModel(), "piecewise-linear": GearModel(kappa=(0.0,), xi=(0.0,))}


def _check_events(res, ref, tol):
    got = [(b.type, b.value) for b in res.bifurcations]
    assert len(got) == len(ref), got
    for (t, v), (tr, vr) in zip(got, ref):
        assert t == tr
        assert abs(v - vr) <= tol, (t, v, vr)


def test_events_match_shooting_defaults():
    from geardyn.analysis.hb import hb_continuation

    res = hb_continuation(CASES["defaults"], "omega", 0.5, 1.0)  # default H = 16
    assert res.end == "reached the end of the interval"
    assert np.all(res.status == int(Status.OK))
    _check_events(res, SHOOTING_EVENTS["defaults"], 1e-3)
    # stable, unstable between the folds, stable again, unstable after the period doubling
    folds = sorted(b.value for b in res.of_type("fold"))
    pd = res.of_type("period-doubling")[0].value
    st = res.stable
    w = res.values
    assert np.all(st[(w < folds[0] - 1e-3)])
    assert np.all(
        st[(w > folds[1] + 1e-3) & (w < pd - 1e-3)] | (res.amplitude[(w > folds[1] + 1e-3) & (w < pd - 1e-3)] < 0.5)
    )
    assert not np.any(st[w > pd + 1e-3])


def test_events_with_hill_and_monodromy():
    """Both Floquet methods find the same events on the defaults' branch; the monodromy's period doubling is
    shooting's to its RK4 error (measured 1.3e-9; Hill's 3.3e-6 at H = 16, its truncation)."""
    from geardyn.analysis.hb import hb_continuation

    ref = SHOOTING_EVENTS["defaults"]
    hill = hb_continuation(CASES["defaults"], "omega", 0.5, 1.0, floquet="hill")
    mono = hb_continuation(CASES["defaults"], "omega", 0.5, 1.0, floquet="monodromy")
    _check_events(hill, ref, 1e-3)
    _check_events(mono, ref, 1e-3)
    pd = mono.of_type("period-doubling")[0].value
    assert abs(pd - ref[-1][1]) <= 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("case", list(CASES))
def test_events_match_live_shooting(case):
    from geardyn.analysis.hb import hb_continuation
    from geardyn.analysis.periodic import continuation

    m = CASES[case]
    ref = continuation(m, "omega", 0.5, 1.0, 1, switch=False, accurate=True, dtau=0.001)
    refev = [(b.type, b.value) for b in ref.bifurcations]
    _check_events(hb_continuation(m, "omega", 0.5, 1.0), refev, 1e-3)
    _check_events(hb_continuation(m, "omega", 0.5, 1.0), SHOOTING_EVENTS[case], 1e-3)


@pytest.mark.parametrize("floquet", ["hill", "monodromy"])
def test_hb_multipliers_match_shooting_floquet(floquet):
    from geardyn.analysis.periodic import shoot

    for w in (0.58, 0.7, 0.9):
        m = GearModel(omega=w)
        sol = hb_solve(m, floquet=floquet)
        orb = shoot(m, 1, dtau=0.002, accurate=True)
        assert sol.status is Status.OK and sol.hill.status is Status.OK
        # H = 16; measured: Hill 2e-4 (2e-6 at H = 32), monodromy 7e-8 (at any H from 8)
        assert _match(sol.multipliers, orb.multipliers) <= 1e-3
        assert abs(sol.u_min - orb.u_min) <= 1e-4 and abs(sol.u_max - orb.u_max) <= 1e-4  # H = 16


def test_monodromy_beats_hill_at_few_harmonics():
    """At H = 8 the monodromy of the period started on the (Newton-corrected) HB state is closer to shooting's
    multipliers than Hill's (measured 7e-8 against 3.6e-3 at ω = 0.7): the trajectory switches where the
    equation says, while Hill's eigenvectors are truncated at H."""
    from geardyn.analysis.periodic import shoot

    m = GearModel(omega=0.7)
    orb = shoot(m, 1, dtau=0.002, accurate=True)
    mono, hill = (hb_solve(m, 8, floquet=f) for f in ("monodromy", "hill"))
    assert _match(mono.multipliers, orb.multipliers) <= 1e-6 and _match(hill.multipliers, orb.multipliers) > 1e-3


@pytest.mark.parametrize("floquet", ["hill", "monodromy"])
def test_statuses_are_honest(floquet):
    # too few harmonics for the contact-loss orbit: the multipliers flagged, not silently wrong (Hill: the
    # centroids and Liouville's check; monodromy: the period started on the solution does not close)
    sol = hb_solve(GearModel(omega=0.7), 2, floquet=floquet)
    assert sol.status is Status.OK
    assert sol.hill.status is Status.UNRESOLVED and sol.stable is None
    # Newton refused: no iterations allowed from a poor guess
    bad = hb_solve(GearModel(omega=0.7), 16, guess="linear", max_iter=1)
    assert bad.status is Status.NOT_CONVERGED and not bad.converged
