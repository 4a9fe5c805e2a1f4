"""Compiled loops of Hill's method (see :mod:`.hill` for the method and the selection rule).

:func:`hill_real_matrix` builds the companion (Hill) matrix of y'' + c(τ)y' + s(τ)y = 0 directly in the
real coefficients [a_0, a_1 … a_H, b_1 … b_H] (the blocks 0, I; −K0, −K1 of :func:`~.hill.hill_matrix`
mapped by ``Wi · W``), in Fortran order for LAPACK.  :func:`hill_select` applies the selection rule to
the real eigen-decomposition that LAPACK's ``dgeev`` returns (eigenvalues wr + i·wi, eigenvectors as
real columns, a complex pair as the real and imaginary parts in two consecutive columns).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..._cache_guard import install as _install_cache
from ._aftkernel import real_operator_kernel

__all__ = ["hill_real_matrix", "hill_select"]


_install_cache()  # the cache follows this directory's sources (see geardyn._cache_guard)


@njit(cache=True)
def hill_real_matrix(c_hat, s_hat, nu, H):
    """The real 2(2H + 1) companion matrix (Fortran order) and whether all its entries are finite."""
    M = 2 * H + 1
    Lc = (c_hat.shape[0] - 1) // 2
    Ls = (s_hat.shape[0] - 1) // 2
    K0 = np.zeros((M, M), dtype=np.complex128)
    K1 = np.zeros((M, M), dtype=np.complex128)
    for r in range(M):
        for col in range(M):
            d = r - col
            om = 1j * nu * (col - H)
            if -Lc <= d <= Lc:
                K0[r, col] = c_hat[d + Lc] * om
                K1[r, col] = c_hat[d + Lc]
            if -Ls <= d <= Ls:
                K0[r, col] += s_hat[d + Ls]
        om = 1j * nu * (r - H)
        K0[r, r] += om * om
        K1[r, r] += 2.0 * om
    K0r = real_operator_kernel(K0, H)
    K1r = real_operator_kernel(K1, H)
    At = np.zeros((2 * M, 2 * M))  # the transpose, so that At.T is the matrix in Fortran order
    finite = True
    for r in range(M):
        At[M + r, r] = 1.0
        for col in range(M):
            At[col, M + r] = -K0r[r, col]
            At[M + col, M + r] = -K1r[r, col]
            if not (math.isfinite(K0r[r, col]) and math.isfinite(K1r[r, col])):
                finite = False
    return At.T, finite


@njit(cache=True)
def hill_select(wr, wi, vr, Tn, ref, H, candidates):
    """The rule of :mod:`.hill` on a real eigen-decomposition of the Hill matrix.

    Returns the two selected exponents λ (the most central eigenvalue and its Liouville partner among
    the ``candidates`` next most central), their multipliers exp(λ T_n), their energy centroids, all
    three with the larger multiplier first, and Liouville's error |μ₁μ₂/ref − 1|."""
    n = wr.shape[0]
    M = 2 * H + 1
    cent = np.empty(n)
    j = 0
    while j < n:
        pair = wi[j] != 0.0 and j + 1 < n
        num = 0.0
        tot = 0.0
        for i in range(M):
            w = vr[i, j] ** 2
            if pair:
                w += vr[i, j + 1] ** 2
            kk = i if i <= H else i - H  # |k| of entry i of [a_0, a_1 … a_H, b_1 … b_H]
            if i == 0:
                tot += w
            else:
                # |c_k|² + |c_−k|² = (|a_k|² + |b_k|²)/2 for the complex coefficients of entry pairs
                tot += 0.5 * w
                num += 0.5 * kk * w
        c = num / tot if tot > 0.0 else math.inf
        if not math.isfinite(c):
            c = math.inf
        cent[j] = c
        if pair:
            cent[j + 1] = c
            j += 2
        else:
            j += 1
    order = np.argsort(cent, kind="mergesort")
    lam = wr + 1j * wi
    i1 = order[0]
    mu1 = np.exp(lam[i1] * Tn)
    partner = ref / mu1 if mu1 != 0 else complex(math.inf, 0.0)
    i2 = order[1]
    best = math.inf
    for q in range(1, min(1 + candidates, n)):
        dist = abs(np.exp(lam[order[q]] * Tn) - partner)
        if dist < best:
            best = dist
            i2 = order[q]
    ex = np.empty(2, dtype=np.complex128)
    cc = np.empty(2)
    first = 0
    mu_a, mu_b = np.exp(lam[i1] * Tn), np.exp(lam[i2] * Tn)
    if abs(mu_b) > abs(mu_a):  # largest modulus first (a stable sort of the two)
        first = 1
    sel = (i1, i2) if first == 0 else (i2, i1)
    mu = np.empty(2, dtype=np.complex128)
    for q in range(2):
        ex[q] = lam[sel[q]]
        mu[q] = np.exp(ex[q] * Tn)
        cc[q] = cent[sel[q]]
    liou = abs(mu[0] * mu[1] / ref - 1.0)
    return ex, mu, cc, liou
