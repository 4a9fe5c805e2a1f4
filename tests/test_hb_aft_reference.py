"""The AFT evaluation in NumPy, the reference the compiled kernels of ``geardyn.analysis.hb`` are checked against.

The same method as :mod:`geardyn.analysis.hb.aft` (switches bracketed on the time grid, located by
Newton kept in the bracket, exact interval integrals of the contact indicator, exact convolutions),
written with vectorised NumPy instead of compiled scalar loops: the dead-zone projection, the
extrema of u, the residual with its Jacobian and ∂R/∂ω.
"""

from __future__ import annotations

import numpy as np

from geardyn.analysis.hb import aft
from geardyn.analysis.hb.aft import ROOT_MAX_ITER, ROOT_TOL, DeadZoneTerms, HarmonicBasis, toeplitz
from geardyn.analysis.hb.equations import HBEquations as HBSystem
from geardyn.analysis.hb.solve import hb_solve
from geardyn.model import GearModel


def _value_slope(basis: HarmonicBasis, a: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """u and u_φ at ``phi`` from one evaluation of the harmonics."""
    H = basis.H
    kk = np.arange(1, H + 1)
    arg = np.multiply.outer(phi, kk)
    c, s = np.cos(arg), np.sin(arg)
    A, B = a[1 : H + 1], a[H + 1 :]
    return a[0] + c @ A + s @ B, c @ (kk * B) - s @ (kk * A)


def _crossings(basis: HarmonicBasis, a: np.ndarray, level: float, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Roots of u(φ) = level in the brackets [lo, hi] (sign change assumed): Newton kept in the bracket.

    A root is converged when its Newton step is below ROOT_TOL·(1 + |φ|); steps that would leave the
    bracket are replaced by bisection."""
    a = np.asarray(a, dtype=float)
    lo, hi = lo.astype(float).copy(), hi.astype(float).copy()
    flo = basis.evaluate(a, lo) - level
    fhi = basis.evaluate(a, hi) - level
    with np.errstate(divide="ignore", invalid="ignore"):
        x = lo - flo * (hi - lo) / (fhi - flo)  # linear interpolation of the samples
    x = np.where(np.isfinite(x) & (x > lo) & (x < hi), x, 0.5 * (lo + hi))
    todo = np.arange(x.size)
    for _ in range(ROOT_MAX_ITER):
        xs = x[todo]
        f, d = _value_slope(basis, a, xs)
        f = f - level
        with np.errstate(divide="ignore", invalid="ignore"):
            step = f / d
        done = (f == 0.0) | (np.isfinite(step) & (np.abs(step) <= ROOT_TOL * (1.0 + np.abs(xs))))
        x[todo[done]] = np.where(f[done] == 0.0, xs[done], xs[done] - step[done])
        keep = ~done
        todo, xs, f, step = todo[keep], xs[keep], f[keep], step[keep]
        if todo.size == 0:
            break
        same = np.sign(f) == np.sign(flo[todo])
        lo[todo] = np.where(same, xs, lo[todo])
        flo[todo] = np.where(same, f, flo[todo])
        hi[todo] = np.where(same, hi[todo], xs)
        xn = xs - step
        bad = ~np.isfinite(xn) | (xn <= lo[todo]) | (xn >= hi[todo])
        x[todo] = np.where(bad, 0.5 * (lo[todo] + hi[todo]), xn)
    return x


def _indicator(intervals: list[tuple[float, float, float]], Q: int) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients (index q + Q, |q| <= Q) of χ (1 on every interval) and σ (its sign on each)."""
    q = np.arange(-Q, Q + 1)
    chi = np.zeros(2 * Q + 1, dtype=complex)
    sig = np.zeros(2 * Q + 1, dtype=complex)
    nz = q != 0
    for alpha, beta, s in intervals:
        v = np.empty(2 * Q + 1, dtype=complex)
        v[~nz] = (beta - alpha) / (2.0 * np.pi)
        qq = q[nz]
        v[nz] = (np.exp(-1j * qq * beta) - np.exp(-1j * qq * alpha)) / (-2j * np.pi * qq)
        chi += v
        sig += s * v
    return chi, sig


def dead_zone_terms_numpy(basis: HarmonicBasis, a: np.ndarray, K: np.ndarray, D: float) -> DeadZoneTerms:
    """:func:`geardyn.analysis.hb.aft.dead_zone_terms` (same arguments and result) in NumPy."""
    H, N = basis.H, basis.N
    L = (len(K) - 1) // 2
    c = basis.to_complex(a)
    u = samples(basis, a)
    state = np.where(u > D, 1, np.where(u < -D, -1, 0))
    # events: (angle, new state); a jump of two levels inside one step has two switches
    j = np.nonzero(state != np.roll(state, -1))[0] if D > 0.0 else np.zeros(0, dtype=int)
    ev_phi: list[np.ndarray] = []
    ev_new: list[np.ndarray] = []
    if j.size:
        lo = basis.phi[j]
        hi = lo + 2.0 * np.pi / N
        s0, s1 = state[j], state[(j + 1) % N]
        for level, here in ((D, (s0 == 1) | (s1 == 1)), (-D, (s0 == -1) | (s1 == -1))):
            if np.any(here):
                x = _crossings(basis, a, level, lo[here], hi[here])
                up = basis.evaluate(a, x, 1) > 0  # the state just after the switch
                ev_phi.append(x)
                ev_new.append(np.where(up, 1 if level > 0 else 0, 0 if level > 0 else -1))
    Q = 2 * H + L
    if ev_phi:
        phis = np.concatenate(ev_phi)
        news = np.concatenate(ev_new)
        order = np.argsort(phis)
        phis, news = phis[order], news[order]
        intervals = []
        prev_state = int(news[-1])  # the state at φ = 0⁻ continues from the last switch
        start = 0.0
        for p_, s_ in zip(phis, news):
            if prev_state != 0:
                intervals.append((start, float(p_), float(prev_state)))
            start, prev_state = float(p_), int(s_)
        if prev_state != 0:
            intervals.append((start, 2.0 * np.pi, float(prev_state)))
        chi, sig = _indicator(intervals, Q)
    else:
        phis = np.zeros(0)
        s = 1 if D == 0.0 else int(state[0])  # D = 0: f(u) = u, always in contact
        chi = np.zeros(2 * Q + 1, dtype=complex)
        sig = np.zeros(2 * Q + 1, dtype=complex)
        if s != 0:
            chi[Q] = 1.0
            sig[Q] = float(s)
    S_full = np.convolve(K, chi)  # centred at L + Q
    mid = L + Q
    S = S_full[mid - 2 * H : mid + 2 * H + 1]
    G = toeplitz(S, H) @ c
    if D > 0.0:
        Ks = np.convolve(K, sig)
        G = G - D * Ks[mid - H : mid + H + 1]
    return DeadZoneTerms(G, S, phis)


def signal_extrema_numpy(basis: HarmonicBasis, a: np.ndarray) -> tuple[float, float, float, float]:
    """Smallest and largest u over the period and where (φ_min, φ_max), refined by Newton on u_φ = 0.

    Parameters
    ----------
    basis : HarmonicBasis
    a : ndarray
        Real coefficients of u.

    Returns
    -------
    (u_min, u_max, phi_min, phi_max) : floats
    """
    u = samples(basis, a)
    h = 2.0 * np.pi / basis.N
    out = []
    for j in (int(np.argmin(u)), int(np.argmax(u))):
        x = basis.phi[j]
        lo, hi = x - h, x + h
        for _ in range(ROOT_MAX_ITER):
            d1 = float(basis.evaluate(a, np.array([x]), 1)[0])
            d2 = float(basis.evaluate(a, np.array([x]), 2)[0])
            xn = x - d1 / d2 if d2 != 0.0 else x
            if not (lo <= xn <= hi):
                break
            if abs(xn - x) <= 1e-14:
                x = xn
                break
            x = xn
        out.append((float(basis.evaluate(a, np.array([x]))[0]), x))
    (umin, pmin), (umax, pmax) = out
    umin = min(umin, float(u.min()))
    umax = max(umax, float(u.max()))
    return umin, umax, pmin, pmax


def samples(basis: HarmonicBasis, a: np.ndarray) -> np.ndarray:
    """u(φ_j) at the N time samples of ``basis`` (inverse real FFT)."""
    H, N = basis.H, basis.N
    X = np.zeros(N // 2 + 1, dtype=complex)
    X[0] = a[0] * N
    X[1 : H + 1] = 0.5 * N * (a[1 : H + 1] - 1j * a[H + 1 :])
    return np.fft.irfft(X, N)


def real_operator(basis: HarmonicBasis, A: np.ndarray) -> np.ndarray:
    """The real (2H + 1)² matrix Wi A W of a complex operator on the c_k of real signals (a = Wi c)."""
    H, M = basis.H, 2 * basis.H + 1
    Wi = np.zeros((M, M), dtype=complex)
    Wi[0, H] = 1.0
    for k in range(1, H + 1):
        Wi[k, H + k], Wi[k, H - k] = 1.0, 1.0
        Wi[H + k, H + k], Wi[H + k, H - k] = 1.0j, -1.0j
    return (Wi @ A @ basis.W).real


def model_series(model: GearModel, n: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centred complex coefficients in φ = θ/n of the pair's C, K and F from ``GearModel.coefficients``."""
    cf = model.coefficients()
    Hm = cf.shape[1] - 1
    L = n * Hm
    out = []
    for i in range(3):
        z = np.zeros(2 * L + 1, dtype=complex)
        z[L] = cf[i, 0, 0]
        for j in range(1, Hm + 1):
            z[L + n * j] = 0.5 * (cf[i, j, 0] - 1j * cf[i, j, 1])
            z[L - n * j] = 0.5 * (cf[i, j, 0] + 1j * cf[i, j, 1])
        out.append(z)
    return out[0], out[1], out[2]


def centred(z: np.ndarray, L: int) -> np.ndarray:
    """Centred coefficients cut or zero-padded to half-length L."""
    Lz = (len(z) - 1) // 2
    m = min(L, Lz)
    out = np.zeros(2 * L + 1, dtype=complex)
    out[L - m : L + m + 1] = z[Lz - m : Lz + m + 1]
    return out


def pair_series(sysm: HBSystem, p: float | None):
    """ν, C, K, F (at that ν) and D of the pair's form at parameter ``p``."""
    f = sysm._entry(p).form
    el, nu = f.elements[0], sysm.nu(p)
    return nu, el.C, el.K, f.G0[0] + nu * nu * f.G2[0], el.gap


def residual_numpy(
    sysm: HBSystem, a: np.ndarray, p: float | None = None, jacobian: bool = True
) -> tuple[np.ndarray, np.ndarray | None]:
    """``HBEquations.residual`` of the pair in NumPy."""
    nu, C, K, F, D = pair_series(sysm, p)
    H, b = sysm.H, sysm.dbasis
    k = b.k
    c = b.to_complex(a)
    dz = dead_zone_terms_numpy(b, a, K, D)
    TcOm = toeplitz(C, H) * (1j * k)[None, :]
    Rc = -((nu * k) ** 2) * c + nu * (TcOm @ c) + dz.G - centred(F, H)
    R = b.to_real(Rc)
    if not jacobian:
        return R, None
    Jc = np.diag(-((nu * k) ** 2)).astype(complex) + nu * TcOm + toeplitz(dz.S, H)
    return R, real_operator(b, Jc)


def dR_domega_numpy(sysm: HBSystem, a: np.ndarray, p: float) -> np.ndarray:
    """``HBEquations.dR_dp`` of the pair for ω in NumPy."""
    nu, C, K, F, D = pair_series(sysm, p)
    b, H = sysm.dbasis, sysm.H
    k = b.k
    c = b.to_complex(a)
    Fh = centred(F, H)
    Fh[H] = 0.0  # f_p does not depend on ω; the STE harmonics go as ω²
    dRc = (-2.0 * nu * k**2 * c + toeplitz(C, H) @ (1j * k * c)) / sysm.periods - 2.0 / p * Fh
    return b.to_real(dRc)


def test_compiled_aft_matches_numpy():
    # the compiled dead-zone projection, extrema, residual and Jacobian against the NumPy formulation
    m = GearModel(omega=0.7, xi0=0.08)
    for H, D in ((12, m.D), (7, 0.0), (16, 0.3)):
        s = HBSystem(m.with_param("D", D), H)
        sol = hb_solve(s.base, H, stability=False)
        assert sol.converged
        K = s.form.elements[0].K
        for a in (sol.coefficients, sol.coefficients * 1.3 + 0.05):
            x, y = aft.dead_zone_terms(s.dbasis, a, K, D), dead_zone_terms_numpy(s.dbasis, a, K, D)
            assert x.switches.size == y.switches.size
            np.testing.assert_allclose(np.sort(x.switches), np.sort(y.switches), rtol=0, atol=1e-12)
            np.testing.assert_allclose(x.G, y.G, rtol=0, atol=1e-12)
            np.testing.assert_allclose(x.S, y.S, rtol=0, atol=1e-12)
            np.testing.assert_allclose(
                aft.signal_extrema(s.dbasis, a), signal_extrema_numpy(s.dbasis, a), rtol=0, atol=1e-12
            )
            R, J = s.residual(a)
            R2, J2 = residual_numpy(s, a)
            np.testing.assert_allclose(R, R2, rtol=0, atol=1e-12 * (1 + np.abs(R2).max()))
            np.testing.assert_allclose(J, J2, rtol=0, atol=1e-12 * np.abs(J2).max())
    s = HBSystem(m, 12, param="omega")
    a = hb_solve(m, 12, stability=False).coefficients
    np.testing.assert_allclose(s.dR_dp(a, 0.7), dR_domega_numpy(s, a, 0.7), rtol=0, atol=1e-13)
    for w in (0.3, 0.7123456789, 1.9):
        for n in (1, 2):
            sn = HBSystem(m, 8, n, param="omega")
            ref = model_series(m.with_param("omega", w), n)
            got = pair_series(sn, w)[1:4]
            assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])
            np.testing.assert_allclose(got[2], ref[2], rtol=0, atol=1e-14 * np.abs(ref[2]).max())
            assert sn.model_at(w) == m.with_param("omega", w)
