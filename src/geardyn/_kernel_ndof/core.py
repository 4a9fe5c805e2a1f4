"""Arithmetic of the N-DOF kernel: coefficients, the vector field, RK4 of the state and of tangents.

The system (non-dimensional, see :mod:`geardyn.systems.assemble`) in first-order form, state
``x = (q, q')`` of length 2n::

    q'' = g − A q − B q' − Σ_m W[m] s_m − Σ_c Wc[c] s_c,
    s_m = C_m(θ) δ_m' + K_m(θ) f(δ_m; D_m),     δ_m = V[m]·q − E_m(θ),  δ_m' = V[m]·q' − ω E_m'(θ),
    s_c = cc_c δ_c' + kc_c f(δ_c; Dc_c),          δ_c = Vc[c]·q,

with ``A = M̃⁻¹K̃_b``, ``B = M̃⁻¹C̃_b``, ``W[m] = M̃⁻¹V[m]``, ``Wc[c] = M̃⁻¹Vc[c]``, ``g = M̃⁻¹F̃`` formed once
per point by the caller.  ``mode`` arrays select, per element, the dead zone (``LOCK_FREE``) or
one branch of it locked (``-1, 0, +1``: back contact, separation, drive contact) for the
accurate mode's sub-steps.
"""

from __future__ import annotations

import math

from numba import njit

# Layout of the per-element statistics (sampled at every step end of the recorded periods).
S_UMIN, S_UMAX, S_USUM, S_USQ, S_VMIN, S_VMAX, S_NDRIVE, S_NSEP, S_NBACK, S_N = range(10)
NSTAT = 10
TAN_NONE, TAN_LYAPUNOV, TAN_MONODROMY = 0, 1, 2
ST_OK, ST_DIVERGED = 0, 1
DIVERGENCE_BOUND = 1.0e6
#: Mode value of an element whose dead zone is evaluated as it is (default mode).
LOCK_FREE = 2


@njit(inline="always")
def _fz(u, D):
    c = min(max(u, -D), D)
    return u - c


@njit(inline="always")
def _flock(u, D, mode):
    """Dead zone, or its branch ``mode`` (−1: u + D, 0: 0, +1: u − D)."""
    if mode == LOCK_FREE:
        return _fz(u, D)
    if mode == 1:
        return u - D
    if mode == -1:
        return u + D
    return 0.0


@njit(inline="always")
def _slope(u, D, mode):
    """f'(u) for the branch in use (1 in contact, 0 in separation; D = 0: always 1)."""
    if mode == LOCK_FREE:
        return 1.0 if (D == 0.0 or abs(u) > D) else 0.0
    return 0.0 if mode == 0 else 1.0


@njit(nogil=True)
def coef_at(coef, ratio, theta, out):
    """C_m, K_m, E_m, E_m' (= dE_m/dθ) of every mesh at the base angle θ into out[m, 0:4]."""
    M = coef.shape[0]
    H = coef.shape[2] - 1
    for m in range(M):
        ph = ratio[m] * theta
        c0 = coef[m, 0, 0, 0]
        k0 = coef[m, 1, 0, 0]
        e0 = coef[m, 2, 0, 0]
        ed = 0.0
        for j in range(1, H + 1):
            cj = math.cos(j * ph)
            sj = math.sin(j * ph)
            c0 += coef[m, 0, j, 0] * cj + coef[m, 0, j, 1] * sj
            k0 += coef[m, 1, j, 0] * cj + coef[m, 1, j, 1] * sj
            e0 += coef[m, 2, j, 0] * cj + coef[m, 2, j, 1] * sj
            ed += j * ratio[m] * (coef[m, 2, j, 1] * cj - coef[m, 2, j, 0] * sj)
        out[m, 0] = c0
        out[m, 1] = k0
        out[m, 2] = e0
        out[m, 3] = ed


@njit(nogil=True)
def field(x, cf, A, B, W, V, D, Wc, Vc, kc, cc, Dc, g, omega, mode, out):
    """out = x' at coefficients cf (meshes, 4); ``mode`` per element (meshes then clearances)."""
    n = g.shape[0]
    M = V.shape[0]
    for i in range(n):
        out[i] = x[n + i]
    for i in range(n):
        acc = g[i]
        for j in range(n):
            acc -= A[i, j] * x[j] + B[i, j] * x[n + j]
        out[n + i] = acc
    for m in range(M):
        d = 0.0
        dv = 0.0
        for j in range(n):
            d += V[m, j] * x[j]
            dv += V[m, j] * x[n + j]
        d -= cf[m, 2]
        dv -= omega * cf[m, 3]
        s = cf[m, 0] * dv + cf[m, 1] * _flock(d, D[m], mode[m])
        for i in range(n):
            out[n + i] -= W[m, i] * s
    for c in range(Vc.shape[0]):
        d = 0.0
        dv = 0.0
        for j in range(n):
            d += Vc[c, j] * x[j]
            dv += Vc[c, j] * x[n + j]
        s = cc[c] * dv + kc[c] * _flock(d, Dc[c], mode[M + c])
        for i in range(n):
            out[n + i] -= Wc[c, i] * s


@njit(nogil=True)
def jac_blocks(x, cf, A, B, W, V, D, Wc, Vc, kc, cc, Dc, mode, Gq, Gv):
    """The lower blocks of the Jacobian at x: q''-part = −Gq dq − Gv dq'."""
    n = A.shape[0]
    M = V.shape[0]
    for i in range(n):
        for j in range(n):
            Gq[i, j] = A[i, j]
            Gv[i, j] = B[i, j]
    for m in range(M):
        d = -cf[m, 2]
        for j in range(n):
            d += V[m, j] * x[j]
        gk = cf[m, 1] * _slope(d, D[m], mode[m])
        gc = cf[m, 0]
        for i in range(n):
            wi = W[m, i]
            for j in range(n):
                Gq[i, j] += gk * wi * V[m, j]
                Gv[i, j] += gc * wi * V[m, j]
    for c in range(Vc.shape[0]):
        d = 0.0
        for j in range(n):
            d += Vc[c, j] * x[j]
        gk = kc[c] * _slope(d, Dc[c], mode[M + c])
        gc = cc[c]
        for i in range(n):
            wi = Wc[c, i]
            for j in range(n):
                Gq[i, j] += gk * wi * Vc[c, j]
                Gv[i, j] += gc * wi * Vc[c, j]


@njit(nogil=True)
def tan_field(Y, Gq, Gv, out):
    """out = J Y for the tangent columns Y (2n, k)."""
    n = Gq.shape[0]
    k = Y.shape[1]
    for c in range(k):
        for i in range(n):
            out[i, c] = Y[n + i, c]
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Gq[i, j] * Y[j, c] + Gv[i, j] * Y[n + j, c]
            out[n + i, c] = -acc


@njit(nogil=True)
def gram_schmidt(Y, logs):
    """Modified Gram–Schmidt on the columns of Y in place; logs[k] = log r_kk."""
    d, k = Y.shape
    for c in range(k):
        for b in range(c):
            r = 0.0
            for i in range(d):
                r += Y[i, b] * Y[i, c]
            for i in range(d):
                Y[i, c] -= r * Y[i, b]
        r = 0.0
        for i in range(d):
            r += Y[i, c] * Y[i, c]
        r = math.sqrt(r)
        logs[c] = math.log(r)
        for i in range(d):
            Y[i, c] /= r


@njit(nogil=True)
def diverged_state(x):
    for i in range(x.shape[0]):
        if not (abs(x[i]) <= DIVERGENCE_BOUND):
            return True
    return False


@njit(nogil=True, inline="always")
def element_values(q, v, vo, cf, V, Vc, omega, out):
    """δ, δ' of every element (meshes then clearances) into out[e, 0:2]; q̃ = q[0:n], q̃' = v[vo:vo+n]."""
    n = V.shape[1]
    M = V.shape[0]
    for m in range(M):
        d = -cf[m, 2]
        dv = -omega * cf[m, 3]
        for j in range(n):
            d += V[m, j] * q[j]
            dv += V[m, j] * v[vo + j]
        out[m, 0] = d
        out[m, 1] = dv
    for c in range(Vc.shape[0]):
        d = 0.0
        dv = 0.0
        for j in range(n):
            d += Vc[c, j] * q[j]
            dv += Vc[c, j] * v[vo + j]
        out[M + c, 0] = d
        out[M + c, 1] = dv


@njit(nogil=True, inline="always")
def accumulate(st, ev, gaps):
    """Add one sample of every element's (δ, δ') to its statistics row st[e]."""
    for e in range(ev.shape[0]):
        d = ev[e, 0]
        dv = ev[e, 1]
        if st[e, S_N] == 0.0:
            st[e, S_UMIN] = d
            st[e, S_UMAX] = d
            st[e, S_VMIN] = dv
            st[e, S_VMAX] = dv
        else:
            st[e, S_UMIN] = min(st[e, S_UMIN], d)
            st[e, S_UMAX] = max(st[e, S_UMAX], d)
            st[e, S_VMIN] = min(st[e, S_VMIN], dv)
            st[e, S_VMAX] = max(st[e, S_VMAX], dv)
        st[e, S_USUM] += d
        st[e, S_USQ] += d * d
        D = gaps[e]
        if D == 0.0:
            st[e, S_NDRIVE] += 1.0
        elif d > D:
            st[e, S_NDRIVE] += 1.0
        elif d < -D:
            st[e, S_NBACK] += 1.0
        else:
            st[e, S_NSEP] += 1.0
        st[e, S_N] += 1.0


@njit(nogil=True, inline="always")
def forces_tab(q, v, tab, r, V, D, Vc, kc, cc, Dc, omega, s):
    """Element forces s[e] of :func:`field` (default mode) at (q̃, q̃') = (q[0:n], v[0:n]), coefficients
    from row r of a table (T, meshes, 4); meshes, then clearances, in :func:`field`'s arithmetic."""
    n = V.shape[1]
    M = V.shape[0]
    for m in range(M):
        d = 0.0
        dv = 0.0
        for j in range(n):
            d += V[m, j] * q[j]
            dv += V[m, j] * v[j]
        d -= tab[r, m, 2]
        dv -= omega * tab[r, m, 3]
        s[m] = tab[r, m, 0] * dv + tab[r, m, 1] * _fz(d, D[m])
    for c in range(Vc.shape[0]):
        d = 0.0
        dv = 0.0
        for j in range(n):
            d += Vc[c, j] * q[j]
            dv += Vc[c, j] * v[j]
        s[M + c] = cc[c] * dv + kc[c] * _fz(d, Dc[c])
