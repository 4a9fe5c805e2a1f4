"""The arithmetic every execution path shares, and the layout of the per-point outputs.

The constants the callers read (statistics indices, tangent modes, status codes, the divergence
bound); the intrinsics ``_fetch_add`` (the workers' shared queue counter) and ``_fma`` (explicit
fused multiply-adds); the branch-free dead zone; the rotation recurrence and the Fourier series of
the coefficients; one RK4 step of the state and of a tangent vector; Gram–Schmidt; and the writers
of a point's results.  The scalar and the lane kernels are built from these functions, so both
perform the same floating-point operations in the same order.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.core import types
from numba.extending import intrinsic

# Layout of the per-point statistics array (accumulated over the recorded periods, sampled at
# every step end).
S_UMIN, S_UMAX, S_USUM, S_USQ, S_VMIN, S_VMAX, S_NDRIVE, S_NSEP, S_NBACK, S_N = range(10)
NSTAT = 10
#: Fields of a statistics snapshot (the workers' accumulators, the adaptive transient's snapshot): u min, u max,
#: u' min, u' max, Σu, Σu², drive and back-side counts; their indices in the statistics.
SNAP_STATS = (S_UMIN, S_UMAX, S_VMIN, S_VMAX, S_USUM, S_USQ, S_NDRIVE, S_NBACK)
NSNAP = 8

#: Tangent modes.  ``TAN_CONTINUE`` is ``TAN_LYAPUNOV`` starting from the basis given in ``tan_out`` (a run
#: continued in blocks of periods; one point at a time).
TAN_NONE, TAN_LYAPUNOV, TAN_MONODROMY, TAN_CONTINUE = 0, 1, 2, 3

#: Status codes per point.
ST_OK, ST_DIVERGED = 0, 1

#: |u| or |u'| beyond this (or non-finite) marks a trajectory as diverged.
DIVERGENCE_BOUND = 1.0e6


# ----------------------------------------------------------------------------- intrinsics
@intrinsic
def _fetch_add(typingctx, counter, value):
    """Atomically add ``value`` to ``counter[0]`` (an int64 array) and return the old value.

    The workers of one batch share a counter: each takes the next point of the batch's queue
    with it, so faster threads take more points (dynamic load balance).
    """
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64 and counter.ndim == 1):
        return None
    sig = types.int64(counter, value)

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        val = context.cast(builder, args[1], signature.args[1], types.int64)
        return builder.atomic_rmw("add", ary.data, val, "seq_cst")

    return sig, codegen


@intrinsic
def _fma(typingctx, a, b, c):
    """a * b + c with a single rounding (``llvm.fma``; one instruction on FMA hardware).

    The default-mode arithmetic writes its fused multiply-adds explicitly and compiles without
    any fast-math flag, so the scalar and the vectorised (lane) code perform exactly the same
    operations and give the same bits.
    """
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


# ----------------------------------------------------------------------------- dead zone, rotations, series
@njit(inline="always")
def _fz(u, D):
    """Dead zone f(u; D) = u - clamp(u, -D, D) (branch-free)."""
    c = min(max(u, -D), D)
    return u - c


@njit(inline="always")
def _rot(c, s, ca, sa):
    """Rotate the angle with cosine c, sine s by the angle with cosine ca, sine sa."""
    return _fma(c, ca, -(s * sa)), _fma(s, ca, c * sa)


@njit(inline="always")
def _rot_small(c, s, cm1, sa):
    """Rotate (c, s) by a small angle δ given as cm1 = cos δ - 1 = -2 sin²(δ/2) and sa = sin δ.

    Adding the small increment to (c, s), rather than multiplying by cos δ, keeps the recurrence
    free of the drift the rounding of cos δ would cause: over the 2N half steps of a period the
    error stays near 1e-15 instead of growing to ~1e-13.
    """
    return c + _fma(cm1, c, -(s * sa)), s + _fma(cm1, s, c * sa)


@njit(inline="always")
def _half_step_rotation(N):
    """(cos δ - 1, sin δ) of the half-step angle δ = π/N."""
    d = math.pi / N
    sh = math.sin(0.5 * d)
    return -2.0 * sh * sh, math.sin(d)


@njit(inline="always")
def _series1(a, c, s):
    """a0 + a1 cos θ + b1 sin θ of a = (a0, a1, b1), accumulated term by term (as :func:`_series_acc`)."""
    return _fma(a[2], s, _fma(a[1], c, a[0]))


@njit(inline="always")
def _series_acc(x, a, b, c, s):
    """x + a cos jθ + b sin jθ, accumulated term by term."""
    return _fma(b, s, _fma(a, c, x))


@njit(nogil=True)
def _coef_seq(cf, c1, s1):
    """C, K, F at the angle (c1, s1) with any number of harmonics (default mode).

    The same operations, in the same order, as the lane kernels.
    """
    C = cf[0, 0, 0]
    K = cf[1, 0, 0]
    F = cf[2, 0, 0]
    ck = c1
    sk = s1
    for j in range(1, cf.shape[1]):
        C = _series_acc(C, cf[0, j, 0], cf[0, j, 1], ck, sk)
        K = _series_acc(K, cf[1, j, 0], cf[1, j, 1], ck, sk)
        F = _series_acc(F, cf[2, j, 0], cf[2, j, 1], ck, sk)
        ck, sk = _rot(ck, sk, c1, s1)
    return C, K, F


# ----------------------------------------------------------------------------- RK4 of the state and of tangents
@njit(inline="always")
def _acc(u, v, C, K, F, D):
    """Acceleration u'' = F - C u' - K f(u)."""
    return _fma(-K, _fz(u, D), _fma(-C, v, F))


@njit(inline="always")
def _rk4(u, v, h, hh, h6, C0, K0, F0, C1, K1, F1, C2, K2, F2, D):
    """One RK4 step of the state; returns the new state and the stage displacements u2, u3, u4."""
    k1 = _acc(u, v, C0, K0, F0, D)
    u2 = _fma(hh, v, u)
    v2 = _fma(hh, k1, v)
    k2 = _acc(u2, v2, C1, K1, F1, D)
    u3 = _fma(hh, v2, u)
    v3 = _fma(hh, k2, v)
    k3 = _acc(u3, v3, C1, K1, F1, D)
    u4 = _fma(h, v3, u)
    v4 = _fma(h, k3, v)
    k4 = _acc(u4, v4, C2, K2, F2, D)
    un = _fma(h6, _fma(2.0, v3, _fma(2.0, v2, v)) + v4, u)
    vn = _fma(h6, _fma(2.0, k3, _fma(2.0, k2, k1)) + k4, v)
    return un, vn, u2, u3, u4


@njit(inline="always")
def _rk4_tan(a, b, h, hh, h6, C0, C1, C2, g1, g2, g3, g4):
    """One RK4 step of a tangent vector (a, b) with stiffness slopes g_i = K f'(u_i) per stage."""
    kb1 = _fma(-g1, a, -(C0 * b))
    a2 = _fma(hh, b, a)
    b2 = _fma(hh, kb1, b)
    kb2 = _fma(-g2, a2, -(C1 * b2))
    a3 = _fma(hh, b2, a)
    b3 = _fma(hh, kb2, b)
    kb3 = _fma(-g3, a3, -(C1 * b3))
    a4 = _fma(h, b3, a)
    b4 = _fma(h, kb3, b)
    kb4 = _fma(-g4, a4, -(C2 * b4))
    return (_fma(h6, _fma(2.0, b3, _fma(2.0, b2, b)) + b4, a), _fma(h6, _fma(2.0, kb3, _fma(2.0, kb2, kb1)) + kb4, b))


@njit(inline="always")
def _slope(K, u, dtan):
    """K f'(u): K in contact (|u| > dtan), 0 in separation; dtan = -1 when there is no backlash."""
    return K if abs(u) > dtan else 0.0


@njit(nogil=True)
def _gs(a1, b1, a2, b2):
    """Modified Gram–Schmidt on the columns (a1, b1), (a2, b2); returns them and log r11, log r22."""
    r11 = math.sqrt(a1 * a1 + b1 * b1)
    a1 /= r11
    b1 /= r11
    r12 = a1 * a2 + b1 * b2
    a2 -= r12 * a1
    b2 -= r12 * b1
    r22 = math.sqrt(a2 * a2 + b2 * b2)
    a2 /= r22
    b2 /= r22
    return a1, b1, a2, b2, math.log(r11), math.log(r22)


@njit(nogil=True)
def _thresholds(D):
    """(drive, back, tangent) thresholds: drive u > t1, back u < t2, contact |u| > t3."""
    if D == 0.0:
        return -np.inf, -np.inf, -1.0
    return D, -D, D


# ----------------------------------------------------------------------------- outputs
@njit(nogil=True)
def _diverged(p, poincare, end_state, status):
    status[p] = ST_DIVERGED
    poincare[p] = np.nan
    end_state[p] = np.nan


@njit(nogil=True)
def _write_stats(stats, p, n, st):
    """Point p's statistics over n samples from the snapshot fields ``st`` (:data:`SNAP_STATS`, in their order)."""
    for i in range(NSNAP):
        stats[p, SNAP_STATS[i]] = st[i]
    stats[p, S_NSEP] = n - st[6] - st[7]
    stats[p, S_N] = n


# ----------------------------------------------------------------------------- adaptive transient
@njit(nogil=True)
def _adapt_reset(ring, streak, l, u, v):
    """Start the convergence test of slot ``l`` at the initial state P_0 = (u, v)."""
    ring[l, 0, 0] = u
    ring[l, 0, 1] = v
    streak[l] = 0


@njit(nogil=True)
def _adapt_check(ring, streak, l, k, u, v, tol):
    """Push the Poincaré point P_k = (u, v) of slot ``l`` and test convergence onto a period-n cycle.

    For every n (1 … ``streak.shape[1] - 1``) with P_{k-2n} known: d = |P_k - P_{k-n}|, e =
    |P_{k-n} - P_{k-2n}| (max norm).  Under geometric convergence with ratio r = d/e < 1 the
    distance of P_k to its cycle is about d r/(1 - r) = d²/(e - d); the test passes when that
    estimate and d itself are at most ``tol`` · max(1, |u|, |u'|) (d = 0 passes).  A period n is
    converged once the test has passed at n + 1 consecutive period ends (each point of the cycle
    at least once).  Returns the smallest converged n, 0 if none.
    """
    R = ring.shape[1]
    ring[l, k % R, 0] = u
    ring[l, k % R, 1] = v
    lim = tol * max(1.0, max(abs(u), abs(v)))
    found = 0
    for n in range(1, streak.shape[1]):
        if 2 * n > k:
            break
        a = (k - n) % R
        b = (k - 2 * n) % R
        d = max(abs(u - ring[l, a, 0]), abs(v - ring[l, a, 1]))
        e = max(abs(ring[l, a, 0] - ring[l, b, 0]), abs(ring[l, a, 1] - ring[l, b, 1]))
        ok = d == 0.0 or (d <= lim and d < e and d * d <= lim * (e - d))
        if ok:
            streak[l, n] += 1
        else:
            streak[l, n] = 0
        if found == 0 and streak[l, n] >= n + 1:
            found = n
    return found


@njit(nogil=True)
def _adapt_finish(p, l, n, n_record, N, cbuf, snap, poincare, end_state, stats):
    """Results of a point that recorded one cycle of n periods in place of ``n_record`` periods.

    The recorded Poincaré points repeat the cycle ``cbuf[l, :n]``; the end state is the cycle's
    point of the last recorded period; the statistics already written (one cycle) become those of
    ``n_record`` periods: q = n_record // n whole cycles plus the snapshot taken after the first
    n_record % n recorded periods (extremes: those of the cycle).
    """
    for j in range(poincare.shape[1]):
        poincare[p, j] = cbuf[l, j % n]
    end_state[p] = cbuf[l, (n_record - 1) % n]
    q = float(n_record // n)
    for i in range(4, NSNAP):  # Σu, Σu² and the counts
        stats[p, SNAP_STATS[i]] *= q
        if n_record % n > 0:
            stats[p, SNAP_STATS[i]] += snap[l, i]
    stats[p, S_N] = N * n_record
    stats[p, S_NSEP] = stats[p, S_N] - stats[p, S_NDRIVE] - stats[p, S_NBACK]
