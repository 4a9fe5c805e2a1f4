"""Compiled loops of the AFT dead-zone evaluation (see :mod:`.aft` for the method).

The functions here are the scalar loops behind :func:`~geardyn.analysis.hb.aft.dead_zone_terms` and
:func:`~geardyn.analysis.hb.aft.signal_extrema`: sampling u on the time grid, locating the contact switches by
safeguarded Newton, the closed-form interval integrals of the contact indicator and the convolutions with the stiffness
series, the residual with its Jacobian, ∂R/∂ω and the forcing series, and the real ↔ complex coefficient maps of
:class:`~geardyn.analysis.hb.aft.HarmonicBasis`.  ``tests/test_hb_aft_reference.py`` holds the same method in vectorised
NumPy and checks that the two agree to rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..._cache_guard import install as _install_cache

__all__ = ["dead_zone_kernel", "extrema_kernel", "residual_kernel", "bordered_nu_kernel", "to_complex", "to_real"]


_install_cache()  # the cache follows this directory's sources (see geardyn._cache_guard)


@njit(cache=True)
def _value(a, H, x):
    """u, u_φ and u_φφ at the angle x."""
    u, d1, d2 = a[0], 0.0, 0.0
    for k in range(1, H + 1):
        c, s = math.cos(k * x), math.sin(k * x)
        u += a[k] * c + a[H + k] * s
        d1 += k * (a[H + k] * c - a[k] * s)
        d2 -= k * k * (a[k] * c + a[H + k] * s)
    return u, d1, d2


@njit(cache=True)
def to_complex(a, H):
    """Complex coefficients c_k (k = −H … H) of the real coefficient vector ``a``."""
    c = np.empty(2 * H + 1, dtype=np.complex128)
    c[H] = a[0]
    for k in range(1, H + 1):
        z = 0.5 * (a[k] - 1j * a[H + k])
        c[H + k] = z
        c[H - k] = z.conjugate()
    return c


@njit(cache=True)
def to_real(z, H, out=None):
    """Real coefficient vector of the complex coefficients ``z`` of a real signal (imaginary residue dropped), into
    ``out`` when given."""
    if out is None:
        out = np.empty(2 * H + 1)
    out[0] = z[H].real
    for k in range(1, H + 1):
        pos, neg = z[H + k], z[H - k]
        out[k] = (pos + neg).real
        out[H + k] = (1j * (pos - neg)).real
    return out


@njit(cache=True)
def _samples(a, H, cos_t, sin_t):
    N = cos_t.shape[0]
    u = np.empty(N)
    for j in range(N):
        s = a[0]
        for k in range(H):
            s += a[k + 1] * cos_t[j, k] + a[H + 1 + k] * sin_t[j, k]
        u[j] = s
    return u


@njit(cache=True)
def _crossing(a, H, level, lo, hi, max_iter, tol):
    """Root of u = level in [lo, hi] (sign change assumed): Newton kept in the bracket, else bisection."""
    flo, fhi, x = _value(a, H, lo)[0] - level, _value(a, H, hi)[0] - level, 0.5 * (lo + hi)
    den = fhi - flo
    if den != 0.0:
        xi = lo - flo * (hi - lo) / den
        if math.isfinite(xi) and xi > lo and xi < hi:
            x = xi
    for _ in range(max_iter):
        f, d, _ = _value(a, H, x)
        f -= level
        if f == 0.0:
            return x
        step = f / d if d != 0.0 else math.copysign(math.inf, f)
        if math.isfinite(step) and abs(step) <= tol * (1.0 + abs(x)):
            return x - step
        if np.sign(f) == np.sign(flo):
            lo, flo = x, f
        else:
            hi = x
        xn = x - step
        if (not math.isfinite(xn)) or xn <= lo or xn >= hi:
            x = 0.5 * (lo + hi)
        else:
            x = xn
    return x


@njit(cache=True)
def _convolved(K, x, t0, n):
    """Entries t0 … t0 + n − 1 of the full convolution K * x (entry t = Σ_i K[i] x[t − i], i ascending)."""
    out = np.empty(n, dtype=np.complex128)
    for m in range(n):
        t = t0 + m
        acc = 0.0 + 0.0j
        for i in range(max(0, t - x.shape[0] + 1), min(K.shape[0] - 1, t) + 1):
            acc += K[i] * x[t - i]
        out[m] = acc
    return out


@njit(cache=True)
def dead_zone_kernel(a, K, D, cos_t, sin_t, H, max_iter, tol):
    """G (2H + 1), S (4H + 1) and the switch angles of K(θ) f(u; D) for real coefficients ``a``."""
    N, L, M = cos_t.shape[0], (K.shape[0] - 1) // 2, 2 * H + 1
    c, u = to_complex(a, H), _samples(a, H, cos_t, sin_t)
    state = np.empty(N, dtype=np.int64)
    for j in range(N):
        state[j] = 1 if u[j] > D else (-1 if u[j] < -D else 0)
    h, nev, ev_phi, ev_new = 2.0 * math.pi / N, 0, np.empty(2 * N), np.empty(2 * N, dtype=np.int64)
    if D > 0.0:
        for side in (1, -1):
            for j in range(N):
                s0, s1 = state[j], state[(j + 1) % N]
                if s0 == s1 or not (s0 == side or s1 == side):
                    continue
                lo = 2.0 * math.pi * j / N
                x = _crossing(a, H, side * D, lo, lo + h, max_iter, tol)
                ev_phi[nev] = x
                ev_new[nev] = side if (_value(a, H, x)[1] > 0) == (side > 0) else 0  # the state just after it
                nev += 1
    Q = 2 * H + L
    chi, sig, phis = np.zeros(2 * Q + 1, dtype=np.complex128), np.zeros(2 * Q + 1, dtype=np.complex128), np.empty(nev)
    if nev > 0:
        order = np.argsort(ev_phi[:nev])
        phis, news = ev_phi[order], ev_new[order]
        prev, start = news[nev - 1], 0.0
        for i in range(nev + 1):
            end = phis[i] if i < nev else 2.0 * math.pi
            if prev != 0:
                sv = float(prev)
                for qi in range(2 * Q + 1):
                    q = qi - Q
                    if q == 0:
                        v = (end - start) / (2.0 * math.pi) + 0j
                    else:
                        v = (np.exp(-1j * q * end) - np.exp(-1j * q * start)) / (-2j * math.pi * q)
                    chi[qi] += v
                    sig[qi] += sv * v
            if i < nev:
                start, prev = phis[i], news[i]
    else:
        s = 1 if D == 0.0 else state[0]
        if s != 0:
            chi[Q] = 1.0
            sig[Q] = float(s)
    mid = L + Q
    S = _convolved(K, chi, mid - 2 * H, 4 * H + 1)  # S_m = (K * chi)[mid + m], |m| <= 2H
    G = _convolved(c, S, 2 * H, M)  # G_k = Σ_l S_{k−l} c_l
    if D > 0.0:
        G -= D * _convolved(K, sig, mid - H, M)
    return G, S, phis


@njit(cache=True)
def extrema_kernel(a, H, cos_t, sin_t, max_iter):
    """(u_min, u_max, φ_min, φ_max) with Newton on u_φ = 0 from the extreme samples."""
    u = _samples(a, H, cos_t, sin_t)
    N, jmin, jmax, out = u.shape[0], np.argmin(u), np.argmax(u), np.empty(4)
    h = 2.0 * math.pi / N
    for w, j in enumerate((jmin, jmax)):
        x = 2.0 * math.pi * j / N
        lo, hi = x - h, x + h
        for _ in range(max_iter):
            _, d1, d2 = _value(a, H, x)
            xn = x - d1 / d2 if d2 != 0.0 else x
            if not (lo <= xn <= hi):
                break
            if abs(xn - x) <= 1e-14:
                x = xn
                break
            x = xn
        out[w] = _value(a, H, x)[0]
        out[2 + w] = x
    out[0] = min(out[0], u[jmin])
    out[1] = max(out[1], u[jmax])
    return out


@njit(cache=True)
def real_operator_kernel(A, H):
    """The real matrix ``Wi @ A @ W`` of a complex operator on the c_k of real signals."""
    M = 2 * H + 1
    AW = np.empty((M, M), dtype=np.complex128)
    for r in range(M):
        AW[r, 0] = A[r, H]
        for k in range(1, H + 1):
            P, Nn = A[r, H + k], A[r, H - k]
            AW[r, k] = 0.5 * (P + Nn)
            AW[r, H + k] = 0.5j * (Nn - P)
    out = np.empty((M, M))
    for col in range(M):
        to_real(AW[:, col], H, out[:, col])
    return out


@njit(cache=True)
def centred(z, H):
    """The centred series ``z`` cut or zero-padded to harmonics −H … H."""
    L = (z.shape[0] - 1) // 2
    out = np.zeros(2 * H + 1, dtype=np.complex128)
    for m in range(-min(H, L), min(H, L) + 1):
        out[H + m] = z[L + m]
    return out


@njit(cache=True)
def residual_kernel(a, nu, C, K, G0, G2, D, cos_t, sin_t, H, max_iter, tol, jac):
    """Real residual R (2H + 1) of the HB equations for the forcing G0 + ν² G2 (centred series) and, when ``jac``,
    its Jacobian (else a 0×0 array)."""
    M = 2 * H + 1
    G, S, _phis = dead_zone_kernel(a, K, D, cos_t, sin_t, H, max_iter, tol)
    Fh = centred(G0, H) + nu * nu * centred(G2, H)
    c, Lc = to_complex(a, H), (C.shape[0] - 1) // 2
    TcOm = np.zeros((M, M), dtype=np.complex128)
    for r in range(M):
        for l in range(M):
            d = r - l
            if -Lc <= d <= Lc:
                TcOm[r, l] = C[d + Lc] * (1j * (l - H))
    Rc = np.empty(M, dtype=np.complex128)
    for r in range(M):
        k = r - H
        acc = 0.0 + 0.0j
        for l in range(M):
            acc += TcOm[r, l] * c[l]
        Rc[r] = -((nu * k) ** 2) * c[r] + nu * acc + G[r] - Fh[r]
    R = to_real(Rc, H)
    if not jac:
        return R, np.empty((0, 0))
    Jc = np.empty((M, M), dtype=np.complex128)
    for r in range(M):
        for l in range(M):
            Jc[r, l] = nu * TcOm[r, l] + S[r - l + 2 * H]
        Jc[r, r] += -((nu * (r - H)) ** 2)
    return R, real_operator_kernel(Jc, H)


@njit(cache=True)
def bordered_nu_kernel(a, nu, C, K, G0, G2, D, cos_t, sin_t, H, max_iter, tol, scale):
    """R and the bordered matrix [[∂R/∂a, scale·∂R/∂ν], [0 … 0]] at ν for the forcing G0 + ν² G2 (the last row left
    for the caller)."""
    M = 2 * H + 1
    R, J = residual_kernel(a, nu, C, K, G0, G2, D, cos_t, sin_t, H, max_iter, tol, True)
    c, k = to_complex(a, H), np.arange(-H, H + 1)
    dC = _convolved(1j * k * c, C, (C.shape[0] - 1) // 2, M)  # the damping's C (ik c)
    dRc = -2.0 * nu * k**2 * c + dC - 2.0 * nu * centred(G2, H)
    A = np.zeros((M + 1, M + 1))
    A[:M, :M] = J
    A[:M, M] = to_real(dRc, H) * scale
    return R, A
