"""The integrator kernel: numba functions on plain arrays.

Only :mod:`geardyn.integrate` imports this module.  One entry point, :func:`run_batch`,
advances a batch of parameter points (each with its own coefficients, backlash and step count)
through ``n_transient + n_record`` forcing periods with classic fixed-step RK4, and serves
every analysis: Poincaré sections, streaming amplitude statistics, time histories, Lyapunov
spectra (tangent vectors with Gram–Schmidt each period) and monodromy matrices.

How the default mode is made fast
---------------------------------
* **Lock-step lanes.**  A worker keeps ``LANES`` parameter points in a structure of arrays (one
  flat float64 array, each field ``LANES`` consecutive values) and advances all lanes together in
  chunks of ``m`` steps, ``m`` being the distance to the nearest period end among the active
  lanes.  The lanes are the innermost loop, so LLVM vectorises the RK4 step across points
  (SIMD).  At a period end the lane's Poincaré point, divergence check and Gram–Schmidt are done
  in scalar code; a finished lane is refilled from the worker's queue of points.
* **Coefficients without trigonometric calls.**  cos θ, sin θ at the step start, midpoint and end
  come from a rotation recurrence by the half-step angle π/N (in increment form, see
  ``_rot_small``: error ~1e-15 over a period), re-seeded exactly (cos 0 = 1, sin 0 = 0) at every
  period start.  The Fourier series are summed by the same recurrence.
* **Branch-free dead zone** ``f(u) = u - clamp(u, -D, D)`` and contact indicators as selects.
* **Specialised chunk kernels** (built once from one template): first harmonic only with or
  without sine terms, or any number of harmonics; without statistics (every lane still in its
  transient), with statistics, with statistics and tangent propagation.  All variants perform
  the same floating-point operations in the same order on the terms they share, and a zero
  coefficient contributes exactly nothing, so a point gets bit-identical results whichever
  variant, lane, batch or thread runs it.  The lanes worker is compiled (and cached) per kind,
  selected by the type of a token argument, so a program compiles only the kinds it uses.
* **Packing the tail.**  Once a worker's queue is empty, the lanes still running are moved into
  the first groups of ``GROUP`` lanes and the chunks run over those groups only, so the last
  points of a batch do not pay for idle lanes.
* **Scalar path** for batches with fewer than ``LANE_MIN_POINTS`` points per worker (e.g. a
  single long trajectory or a shooting iteration): the same arithmetic, state and statistics in registers.
* **Threads balanced dynamically.**  :func:`run_batch` queues the points by decreasing cost
  (steps per period) and runs T workers on T Python threads over ``nogil`` compiled functions;
  each worker takes the next point of the shared queue (an atomic counter) whenever one of its
  lanes is free, so a faster or less loaded core takes more points.  T is numba's thread setting
  (``geardyn.integrate.set_threads``).  No result depends on T or on which worker ran a point.
* Fused multiply-adds are written explicitly (``_fma``) and no fast-math flag is used: the
  compiler neither contracts nor reassociates on its own, so the scalar and the vectorised code
  round identically, and results differ from a plain RK4 loop only by rounding.

The accurate mode locks the vector field to one contact region per sub-step and splits each step
at the crossings u = ±D (dense Hermite output, then Newton on the sub-step length), which keeps
RK4 fourth order through contact changes; it runs one point at a time (scalar).
"""

from __future__ import annotations

import math
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit
from numba.core import types
from numba.extending import intrinsic, overload

# Layout of the per-point statistics array (accumulated over the recorded periods, sampled at
# every step end).
S_UMIN, S_UMAX, S_USUM, S_USQ, S_VMIN, S_VMAX, S_NDRIVE, S_NSEP, S_NBACK, S_N = range(10)
NSTAT = 10

#: Tangent modes.
TAN_NONE, TAN_LYAPUNOV, TAN_MONODROMY = 0, 1, 2

#: Status codes per point.
ST_OK, ST_DIVERGED = 0, 1

#: |u| or |u'| beyond this (or non-finite) marks a trajectory as diverged.
DIVERGENCE_BOUND = 1.0e6

#: Accurate mode: at most this many splits of one step, and Hermite samples per step searched.
MAX_SPLITS = 8
HERMITE_SAMPLES = 8
#: Accurate mode: Newton iterations on the sub-step length, and the tolerance on |u - boundary|.
NEWTON_ITERS = 6
CROSSING_TOL = 1.0e-14

#: Parameter points advanced in lock-step by one worker, in groups of GROUP lanes (one SIMD
#: vector of doubles); when the queue is empty the remaining lanes are packed into the first groups.
GROUP = 4
LANES = 16
#: Batches with fewer points per worker than this are integrated one point at a time (scalar path).
LANE_MIN_POINTS = 3
#: Batches with fewer RK4 steps than this run on the calling thread only.
THREAD_MIN_STEPS = 200_000

# Lane state: field f of lane l is S[f * LANES + l].
(F_U, F_V, F_C, F_S, F_CM1, F_SA, F_H, F_HH, F_H6,
 F_CA0, F_CA1, F_CB1, F_KA0, F_KA1, F_KB1, F_FA0, F_FA1, F_FB1,
 F_D, F_DRV, F_BCK, F_DTAN,
 F_UMIN, F_UMAX, F_VMIN, F_VMAX, F_USUM, F_USQ, F_NDRV, F_NBCK,
 F_Y00, F_Y10, F_Y01, F_Y11,
 # scratch of the general (any number of harmonics) chunk
 F_XC0, F_XK0, F_XF0, F_XC1, F_XK1, F_XF1, F_XC2, F_XK2, F_XF2,
 F_P0C, F_P0S, F_P1C, F_P1S, F_P2C, F_P2S,
 F_R1C, F_R1S, F_R2C, F_R2S,
 NFIELDS) = range(54)

#: Chunk kinds: first harmonic with cosine terms only, first harmonic with sine terms, general.
KIND_COS, KIND_SIN, KIND_GEN = 0, 1, 2
#: Chunk modes: no statistics, statistics, statistics and tangent propagation.
MODE_PLAIN, MODE_STATS, MODE_TAN = 0, 1, 2

#: Steps-per-period of an idle lane: never the nearest period end.
_BIG = 1 << 62


# ----------------------------------------------------------------------------- shared helpers
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


@njit(inline="always")
def _fz(u, D):
    """Dead zone f(u; D) = u - clamp(u, -D, D) (branch-free)."""
    c = min(max(u, -D), D)
    return u - c


@njit(inline="always")
def _coef(cf, c1, s1):
    """Evaluate C, K, F at the angle θ whose cosine and sine are c1, s1 (accurate mode)."""
    C = cf[0, 0, 0]
    K = cf[1, 0, 0]
    F = cf[2, 0, 0]
    ck = c1
    sk = s1
    for j in range(1, cf.shape[1]):
        C += cf[0, j, 0] * ck + cf[0, j, 1] * sk
        K += cf[1, j, 0] * ck + cf[1, j, 1] * sk
        F += cf[2, j, 0] * ck + cf[2, j, 1] * sk
        t = ck * c1 - sk * s1
        sk = sk * c1 + ck * s1
        ck = t
    return C, K, F


@njit(nogil=True)
def _coef_at(cf, theta):
    return _coef(cf, math.cos(theta), math.sin(theta))


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
def _series1(a0, a1, b1, c, s):
    """a0 + a1 cos θ + b1 sin θ, accumulated term by term (as :func:`_series_acc`)."""
    return _fma(b1, s, _fma(a1, c, a0))


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
    return (_fma(h6, _fma(2.0, b3, _fma(2.0, b2, b)) + b4, a),
            _fma(h6, _fma(2.0, kb3, _fma(2.0, kb2, kb1)) + kb4, b))


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


# ----------------------------------------------------------------------------- accurate mode
@njit(inline="always")
def _region(u, D):
    if D == 0.0:
        return 1
    if u > D:
        return 1
    if u < -D:
        return -1
    return 0


@njit(inline="always")
def _flock(u, D, r):
    """Dead zone locked to contact region r (its smooth extension beyond the region)."""
    if r == 0:
        return 0.0
    return u - r * D


@njit(nogil=True)
def _rk4_locked(cf, theta0, omega, u, v, s, D, r):
    """One RK4 step of length s from angle theta0 with the vector field locked to region r."""
    C0, K0, F0 = _coef_at(cf, theta0)
    C1, K1, F1 = _coef_at(cf, theta0 + 0.5 * omega * s)
    C2, K2, F2 = _coef_at(cf, theta0 + omega * s)
    hh = 0.5 * s
    h6 = s / 6.0
    k1 = F0 - C0 * v - K0 * _flock(u, D, r)
    u2 = u + hh * v
    v2 = v + hh * k1
    k2 = F1 - C1 * v2 - K1 * _flock(u2, D, r)
    u3 = u + hh * v2
    v3 = v + hh * k2
    k3 = F1 - C1 * v3 - K1 * _flock(u3, D, r)
    u4 = u + s * v3
    v4 = v + s * k3
    k4 = F2 - C2 * v4 - K2 * _flock(u4, D, r)
    return u + h6 * (v + 2.0 * v2 + 2.0 * v3 + v4), v + h6 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


@njit(nogil=True)
def _tangent_locked(cf, theta0, omega, s, r, Y):
    """Propagate the tangent matrix Y over a sub-step of length s locked to region r."""
    C0, K0, F0 = _coef_at(cf, theta0)
    C1, K1, F1 = _coef_at(cf, theta0 + 0.5 * omega * s)
    C2, K2, F2 = _coef_at(cf, theta0 + omega * s)
    g = 1.0 if r != 0 else 0.0
    hh = 0.5 * s
    h6 = s / 6.0
    for col in range(2):
        a = Y[0, col]
        b = Y[1, col]
        kb1 = -C0 * b - g * K0 * a
        a2 = a + hh * b
        b2 = b + hh * kb1
        kb2 = -C1 * b2 - g * K1 * a2
        a3 = a + hh * b2
        b3 = b + hh * kb2
        kb3 = -C1 * b3 - g * K1 * a3
        a4 = a + s * b3
        b4 = b + s * kb3
        kb4 = -C2 * b4 - g * K2 * a4
        Y[0, col] = a + h6 * (b + 2.0 * b2 + 2.0 * b3 + b4)
        Y[1, col] = b + h6 * (kb1 + 2.0 * kb2 + 2.0 * kb3 + kb4)


@njit(inline="always")
def _outside(u, D, r):
    """True when u has left contact region r."""
    if D == 0.0:
        return False
    if r == 1:
        return u < D
    if r == -1:
        return u > -D
    return u > D or u < -D


@njit(inline="always")
def _hermite(u0, v0, u1, v1, H, x):
    x2 = x * x
    x3 = x2 * x
    return (
        (2.0 * x3 - 3.0 * x2 + 1.0) * u0
        + (x3 - 2.0 * x2 + x) * H * v0
        + (-2.0 * x3 + 3.0 * x2) * u1
        + (x3 - x2) * H * v1
    )


@njit(nogil=True)
def _step_accurate(cf, theta0, omega, h, u, v, D, r, Y, tangent):
    """One regular step of length h in accurate mode; returns (u, v, region)."""
    t_done = 0.0
    for _ in range(MAX_SPLITS):
        H = h - t_done
        if H <= 0.0:
            break
        th = theta0 + omega * t_done
        un, vn = _rk4_locked(cf, th, omega, u, v, H, D, r)
        # earliest exit from region r along the dense (Hermite) output of this sub-step
        x_in = 0.0
        x_out = -1.0
        for i in range(1, HERMITE_SAMPLES + 1):
            x = i / HERMITE_SAMPLES
            ux = un if i == HERMITE_SAMPLES else _hermite(u, v, un, vn, H, x)
            if _outside(ux, D, r):
                x_out = x
                break
            x_in = x
        if x_out < 0.0:
            if tangent:
                _tangent_locked(cf, th, omega, H, r, Y)
            return un, vn, r
        # which boundary: the one on the side where the path went
        ux = un if x_out == 1.0 else _hermite(u, v, un, vn, H, x_out)
        b = D if ux > 0.0 else -D
        if r == 1:
            b = D
        elif r == -1:
            b = -D
        # bisection on the Hermite cubic, then Newton on the true sub-step length
        lo = x_in
        hi = x_out
        for _k in range(40):
            mid = 0.5 * (lo + hi)
            if _outside(_hermite(u, v, un, vn, H, mid), D, r):
                hi = mid
            else:
                lo = mid
        s = 0.5 * (lo + hi) * H
        for _k in range(NEWTON_ITERS):
            us, vs = _rk4_locked(cf, th, omega, u, v, s, D, r)
            g = us - b
            if abs(g) <= CROSSING_TOL * (1.0 + abs(b)) or vs == 0.0:
                break
            s_new = s - g / vs
            if s_new <= 0.0 or s_new > H:
                break
            s = s_new
        us, vs = _rk4_locked(cf, th, omega, u, v, s, D, r)
        if tangent:
            _tangent_locked(cf, th, omega, s, r, Y)
        u = b
        v = vs
        t_done += s
        # the region entered: from the boundary, the side the velocity points to
        if r == 0:
            r = 1 if b > 0.0 else -1
        else:
            r = 0
    # remaining length after the split budget: finish in the current region
    H = h - t_done
    if H > 0.0:
        th = theta0 + omega * t_done
        un, vn = _rk4_locked(cf, th, omega, u, v, H, D, r)
        if tangent:
            _tangent_locked(cf, th, omega, H, r, Y)
        u = un
        v = vn
    return u, v, r


@njit(inline="always")
def _gram_schmidt(Y):
    """Modified Gram–Schmidt on the columns of Y in place; returns (log r11, log r22)."""
    a1, b1, a2, b2, l1, l2 = _gs(Y[0, 0], Y[1, 0], Y[0, 1], Y[1, 1])
    Y[0, 0] = a1
    Y[1, 0] = b1
    Y[0, 1] = a2
    Y[1, 1] = b2
    return l1, l2


@njit(nogil=True)
def _diverged(p, poincare, end_state, status):
    status[p] = ST_DIVERGED
    for j in range(poincare.shape[1]):
        poincare[p, j, 0] = np.nan
        poincare[p, j, 1] = np.nan
    end_state[p, 0] = np.nan
    end_state[p, 1] = np.nan


@njit(nogil=True)
def _point_accurate(p, cf, D, omega, N, u, v, n_transient, n_record, tangent,
                    poincare, end_state, stats, tan_log, tan_out, status, hist):
    """One point in accurate mode (steps split at the contact-boundary crossings)."""
    T = 2.0 * math.pi / omega
    h = T / N
    Y = np.eye(2)
    n_hist = hist.shape[1]
    hist_periods = (n_hist - 1) // N if n_hist > 0 else 0
    hist_first = n_transient + n_record - hist_periods
    hi = 0
    st = stats[p]
    st[:] = 0.0
    st[S_UMIN] = np.inf
    st[S_UMAX] = -np.inf
    st[S_VMIN] = np.inf
    st[S_VMAX] = -np.inf
    r = _region(u, D)
    n_total = n_transient + n_record
    for per in range(n_total):
        rec = per >= n_transient
        tan_on = tangent != TAN_NONE and rec
        if n_hist > 0 and per == hist_first:
            hist[p, 0, 0] = u
            hist[p, 0, 1] = v
            hi = 1
        for k in range(N):
            u, v, r = _step_accurate(cf, k * h * omega, omega, h, u, v, D, r, Y, tan_on)
            if rec:
                st[S_UMIN] = min(st[S_UMIN], u)
                st[S_UMAX] = max(st[S_UMAX], u)
                st[S_VMIN] = min(st[S_VMIN], v)
                st[S_VMAX] = max(st[S_VMAX], v)
                st[S_USUM] += u
                st[S_USQ] += u * u
                st[S_N] += 1.0
                if D == 0.0 or u > D:
                    st[S_NDRIVE] += 1.0
                elif u < -D:
                    st[S_NBACK] += 1.0
                else:
                    st[S_NSEP] += 1.0
            if hi > 0:
                hist[p, hi, 0] = u
                hist[p, hi, 1] = v
                hi += 1
        if not (abs(u) < DIVERGENCE_BOUND and abs(v) < DIVERGENCE_BOUND):
            _diverged(p, poincare, end_state, status)
            return
        if rec:
            j = per - n_transient
            if poincare.shape[1] > 0:
                poincare[p, j, 0] = u
                poincare[p, j, 1] = v
            if tangent == TAN_LYAPUNOV:
                l1, l2 = _gram_schmidt(Y)
                tan_log[p, j, 0] = l1
                tan_log[p, j, 1] = l2
    end_state[p, 0] = u
    end_state[p, 1] = v
    if tangent != TAN_NONE:
        tan_out[p, :, :] = Y
    status[p] = ST_OK


# ----------------------------------------------------------------------------- scalar default mode
@njit(nogil=True)
def _point_scalar(p, cf, D, omega, N, u, v, n_transient, n_record, tangent,
                  poincare, end_state, stats, tan_log, tan_out, status, hist):
    """One point in the default mode, state and statistics in registers.

    The arithmetic is that of the lane kernels (same operations, same order), so a point gives
    the same bits on either path.
    """
    T = 2.0 * math.pi / omega
    h = T / N
    hh = 0.5 * h
    h6 = h / 6.0
    cm1, sa = _half_step_rotation(N)
    H1 = cf.shape[1]
    fast = H1 <= 2
    ca0 = cf[0, 0, 0]
    ka0 = cf[1, 0, 0]
    fa0 = cf[2, 0, 0]
    ca1 = cb1 = ka1 = kb1 = fa1 = fb1 = 0.0
    if H1 > 1:
        ca1 = cf[0, 1, 0]
        cb1 = cf[0, 1, 1]
        ka1 = cf[1, 1, 0]
        kb1 = cf[1, 1, 1]
        fa1 = cf[2, 1, 0]
        fb1 = cf[2, 1, 1]
    tdrv, tbck, dtan = _thresholds(D)
    y00 = 1.0
    y10 = 0.0
    y01 = 0.0
    y11 = 1.0
    umin = np.inf
    umax = -np.inf
    vmin = np.inf
    vmax = -np.inf
    usum = 0.0
    usq = 0.0
    ndrv = 0.0
    nbck = 0.0
    n_hist = hist.shape[1]
    hist_periods = (n_hist - 1) // N if n_hist > 0 else 0
    hist_first = n_transient + n_record - hist_periods
    hi = 0
    n_total = n_transient + n_record
    for per in range(n_total):
        rec = per >= n_transient
        tan_on = tangent != TAN_NONE and rec
        if n_hist > 0 and per == hist_first:
            hist[p, 0, 0] = u
            hist[p, 0, 1] = v
            hi = 1
        c = 1.0
        s = 0.0
        for k in range(N):
            c1, s1 = _rot_small(c, s, cm1, sa)
            c2, s2 = _rot_small(c1, s1, cm1, sa)
            if fast:
                C0 = _series1(ca0, ca1, cb1, c, s)
                K0 = _series1(ka0, ka1, kb1, c, s)
                F0 = _series1(fa0, fa1, fb1, c, s)
                C1 = _series1(ca0, ca1, cb1, c1, s1)
                K1 = _series1(ka0, ka1, kb1, c1, s1)
                F1 = _series1(fa0, fa1, fb1, c1, s1)
                C2 = _series1(ca0, ca1, cb1, c2, s2)
                K2 = _series1(ka0, ka1, kb1, c2, s2)
                F2 = _series1(fa0, fa1, fb1, c2, s2)
            else:
                C0, K0, F0 = _coef_seq(cf, c, s)
                C1, K1, F1 = _coef_seq(cf, c1, s1)
                C2, K2, F2 = _coef_seq(cf, c2, s2)
            un, vn, u2, u3, u4 = _rk4(u, v, h, hh, h6, C0, K0, F0, C1, K1, F1, C2, K2, F2, D)
            if tan_on:
                g1 = _slope(K0, u, dtan)
                g2 = _slope(K1, u2, dtan)
                g3 = _slope(K1, u3, dtan)
                g4 = _slope(K2, u4, dtan)
                y00, y10 = _rk4_tan(y00, y10, h, hh, h6, C0, C1, C2, g1, g2, g3, g4)
                y01, y11 = _rk4_tan(y01, y11, h, hh, h6, C0, C1, C2, g1, g2, g3, g4)
            u = un
            v = vn
            c = c2
            s = s2
            if rec:
                umin = min(umin, u)
                umax = max(umax, u)
                vmin = min(vmin, v)
                vmax = max(vmax, v)
                usum = usum + u
                usq = _fma(u, u, usq)
                ndrv = ndrv + (1.0 if u > tdrv else 0.0)
                nbck = nbck + (1.0 if u < tbck else 0.0)
            if hi > 0:
                hist[p, hi, 0] = u
                hist[p, hi, 1] = v
                hi += 1
        if not (abs(u) < DIVERGENCE_BOUND and abs(v) < DIVERGENCE_BOUND):
            _diverged(p, poincare, end_state, status)
            nrec = N * (per + 1 - n_transient) if rec else 0
            _write_stats(stats, p, nrec, umin, umax, vmin, vmax, usum, usq, ndrv, nbck)
            return
        if rec:
            j = per - n_transient
            if poincare.shape[1] > 0:
                poincare[p, j, 0] = u
                poincare[p, j, 1] = v
            if tangent == TAN_LYAPUNOV:
                y00, y10, y01, y11, l1, l2 = _gs(y00, y10, y01, y11)
                tan_log[p, j, 0] = l1
                tan_log[p, j, 1] = l2
    end_state[p, 0] = u
    end_state[p, 1] = v
    _write_stats(stats, p, N * n_record, umin, umax, vmin, vmax, usum, usq, ndrv, nbck)
    if tangent != TAN_NONE:
        tan_out[p, 0, 0] = y00
        tan_out[p, 1, 0] = y10
        tan_out[p, 0, 1] = y01
        tan_out[p, 1, 1] = y11
    status[p] = ST_OK


@njit(nogil=True)
def _write_stats(stats, p, n, umin, umax, vmin, vmax, usum, usq, ndrv, nbck):
    stats[p, S_UMIN] = umin
    stats[p, S_UMAX] = umax
    stats[p, S_VMIN] = vmin
    stats[p, S_VMAX] = vmax
    stats[p, S_USUM] = usum
    stats[p, S_USQ] = usq
    stats[p, S_NDRIVE] = ndrv
    stats[p, S_NBACK] = nbck
    stats[p, S_NSEP] = n - ndrv - nbck
    stats[p, S_N] = n


@njit(nogil=True, cache=True)
def _scalar_worker(order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent,
                   poincare, end_state, stats, tan_log, tan_out, status, hist):
    """Integrate points of the queue ``order`` one at a time (histories, small batches)."""
    while True:
        i = _fetch_add(counter, 1)
        if i >= order.shape[0]:
            break
        p = order[i]
        _point_scalar(p, coef[p], D[p], omega[p], nsteps[p], state0[p, 0], state0[p, 1],
                      n_transient, n_record, tangent,
                      poincare, end_state, stats, tan_log, tan_out, status, hist)


@njit(nogil=True, cache=True)
def _accurate_worker(order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent,
                     poincare, end_state, stats, tan_log, tan_out, status, hist):
    """Integrate points of the queue ``order`` one at a time in accurate mode."""
    while True:
        i = _fetch_add(counter, 1)
        if i >= order.shape[0]:
            break
        p = order[i]
        _point_accurate(p, coef[p], D[p], omega[p], nsteps[p], state0[p, 0], state0[p, 1],
                        n_transient, n_record, tangent,
                        poincare, end_state, stats, tan_log, tan_out, status, hist)


# ----------------------------------------------------------------------------- lane chunk kernels
def _make_chunk(kind, mode):
    """Build the chunk kernel advancing all lanes by m steps for one (kind, mode)."""
    L = LANES
    general = kind == KIND_GEN
    with_sin = kind != KIND_COS
    with_stats = mode != MODE_PLAIN
    with_tan = mode == MODE_TAN

    @njit(nogil=True)
    def chunk(S, CF, m, H1, ng):
        for _it in range(m):
            if general:
                # cos/sin at the three angles, then the series term by term (lanes innermost)
                for g in range(ng):
                    for k in range(GROUP):
                        l = g * GROUP + k
                        c0 = S[F_C * L + l]
                        s0 = S[F_S * L + l]
                        c1, s1 = _rot_small(c0, s0, S[F_CM1 * L + l], S[F_SA * L + l])
                        c2, s2 = _rot_small(c1, s1, S[F_CM1 * L + l], S[F_SA * L + l])
                        S[F_R1C * L + l] = c1
                        S[F_R1S * L + l] = s1
                        S[F_R2C * L + l] = c2
                        S[F_R2S * L + l] = s2
                        S[F_P0C * L + l] = c0
                        S[F_P0S * L + l] = s0
                        S[F_P1C * L + l] = c1
                        S[F_P1S * L + l] = s1
                        S[F_P2C * L + l] = c2
                        S[F_P2S * L + l] = s2
                        S[F_XC0 * L + l] = CF[0 * L + l]
                        S[F_XK0 * L + l] = CF[(2 * H1) * L + l]
                        S[F_XF0 * L + l] = CF[(4 * H1) * L + l]
                        S[F_XC1 * L + l] = CF[0 * L + l]
                        S[F_XK1 * L + l] = CF[(2 * H1) * L + l]
                        S[F_XF1 * L + l] = CF[(4 * H1) * L + l]
                        S[F_XC2 * L + l] = CF[0 * L + l]
                        S[F_XK2 * L + l] = CF[(2 * H1) * L + l]
                        S[F_XF2 * L + l] = CF[(4 * H1) * L + l]
                for j in range(1, H1):
                    oc = (2 * j) * L
                    ok = (2 * (H1 + j)) * L
                    of = (2 * (2 * H1 + j)) * L
                    for g in range(ng):
                        for k in range(GROUP):
                            l = g * GROUP + k
                            ac = CF[oc + l]
                            bc = CF[oc + L + l]
                            ak = CF[ok + l]
                            bk = CF[ok + L + l]
                            af = CF[of + l]
                            bf = CF[of + L + l]
                            # angle 0
                            ck = S[F_P0C * L + l]
                            sk = S[F_P0S * L + l]
                            S[F_XC0 * L + l] = _series_acc(S[F_XC0 * L + l], ac, bc, ck, sk)
                            S[F_XK0 * L + l] = _series_acc(S[F_XK0 * L + l], ak, bk, ck, sk)
                            S[F_XF0 * L + l] = _series_acc(S[F_XF0 * L + l], af, bf, ck, sk)
                            ck, sk = _rot(ck, sk, S[F_C * L + l], S[F_S * L + l])
                            S[F_P0C * L + l] = ck
                            S[F_P0S * L + l] = sk
                            # angle 1 (midpoint)
                            ck = S[F_P1C * L + l]
                            sk = S[F_P1S * L + l]
                            S[F_XC1 * L + l] = _series_acc(S[F_XC1 * L + l], ac, bc, ck, sk)
                            S[F_XK1 * L + l] = _series_acc(S[F_XK1 * L + l], ak, bk, ck, sk)
                            S[F_XF1 * L + l] = _series_acc(S[F_XF1 * L + l], af, bf, ck, sk)
                            ck, sk = _rot(ck, sk, S[F_R1C * L + l], S[F_R1S * L + l])
                            S[F_P1C * L + l] = ck
                            S[F_P1S * L + l] = sk
                            # angle 2 (step end)
                            ck = S[F_P2C * L + l]
                            sk = S[F_P2S * L + l]
                            S[F_XC2 * L + l] = _series_acc(S[F_XC2 * L + l], ac, bc, ck, sk)
                            S[F_XK2 * L + l] = _series_acc(S[F_XK2 * L + l], ak, bk, ck, sk)
                            S[F_XF2 * L + l] = _series_acc(S[F_XF2 * L + l], af, bf, ck, sk)
                            ck, sk = _rot(ck, sk, S[F_R2C * L + l], S[F_R2S * L + l])
                            S[F_P2C * L + l] = ck
                            S[F_P2S * L + l] = sk
            for g in range(ng):
                for k in range(GROUP):
                    l = g * GROUP + k
                    if general:
                        C0 = S[F_XC0 * L + l]
                        K0 = S[F_XK0 * L + l]
                        F0 = S[F_XF0 * L + l]
                        C1 = S[F_XC1 * L + l]
                        K1 = S[F_XK1 * L + l]
                        F1 = S[F_XF1 * L + l]
                        C2 = S[F_XC2 * L + l]
                        K2 = S[F_XK2 * L + l]
                        F2 = S[F_XF2 * L + l]
                        c2 = S[F_R2C * L + l]
                        s2 = S[F_R2S * L + l]
                    else:
                        cm1 = S[F_CM1 * L + l]
                        sa = S[F_SA * L + l]
                        c0 = S[F_C * L + l]
                        s0 = S[F_S * L + l]
                        c1, s1 = _rot_small(c0, s0, cm1, sa)
                        c2, s2 = _rot_small(c1, s1, cm1, sa)
                        a0 = S[F_CA0 * L + l]
                        a1 = S[F_CA1 * L + l]
                        k0 = S[F_KA0 * L + l]
                        k1 = S[F_KA1 * L + l]
                        f0 = S[F_FA0 * L + l]
                        f1 = S[F_FA1 * L + l]
                        if with_sin:
                            b1 = S[F_CB1 * L + l]
                            kb = S[F_KB1 * L + l]
                            fb = S[F_FB1 * L + l]
                            C0 = _series1(a0, a1, b1, c0, s0)
                            K0 = _series1(k0, k1, kb, c0, s0)
                            F0 = _series1(f0, f1, fb, c0, s0)
                            C1 = _series1(a0, a1, b1, c1, s1)
                            K1 = _series1(k0, k1, kb, c1, s1)
                            F1 = _series1(f0, f1, fb, c1, s1)
                            C2 = _series1(a0, a1, b1, c2, s2)
                            K2 = _series1(k0, k1, kb, c2, s2)
                            F2 = _series1(f0, f1, fb, c2, s2)
                        else:
                            # the sine coefficients are exactly zero: fma(0, s, x) == x
                            C0 = _fma(a1, c0, a0)
                            K0 = _fma(k1, c0, k0)
                            F0 = _fma(f1, c0, f0)
                            C1 = _fma(a1, c1, a0)
                            K1 = _fma(k1, c1, k0)
                            F1 = _fma(f1, c1, f0)
                            C2 = _fma(a1, c2, a0)
                            K2 = _fma(k1, c2, k0)
                            F2 = _fma(f1, c2, f0)
                    h = S[F_H * L + l]
                    hh = S[F_HH * L + l]
                    h6 = S[F_H6 * L + l]
                    D = S[F_D * L + l]
                    u = S[F_U * L + l]
                    v = S[F_V * L + l]
                    un, vn, u2, u3, u4 = _rk4(u, v, h, hh, h6, C0, K0, F0, C1, K1, F1, C2, K2, F2, D)
                    if with_tan:
                        dtan = S[F_DTAN * L + l]
                        g1 = _slope(K0, u, dtan)
                        g2 = _slope(K1, u2, dtan)
                        g3 = _slope(K1, u3, dtan)
                        g4 = _slope(K2, u4, dtan)
                        y00, y10 = _rk4_tan(S[F_Y00 * L + l], S[F_Y10 * L + l], h, hh, h6,
                                            C0, C1, C2, g1, g2, g3, g4)
                        y01, y11 = _rk4_tan(S[F_Y01 * L + l], S[F_Y11 * L + l], h, hh, h6,
                                            C0, C1, C2, g1, g2, g3, g4)
                        S[F_Y00 * L + l] = y00
                        S[F_Y10 * L + l] = y10
                        S[F_Y01 * L + l] = y01
                        S[F_Y11 * L + l] = y11
                    if with_stats:
                        S[F_UMIN * L + l] = min(S[F_UMIN * L + l], un)
                        S[F_UMAX * L + l] = max(S[F_UMAX * L + l], un)
                        S[F_VMIN * L + l] = min(S[F_VMIN * L + l], vn)
                        S[F_VMAX * L + l] = max(S[F_VMAX * L + l], vn)
                        S[F_USUM * L + l] = S[F_USUM * L + l] + un
                        S[F_USQ * L + l] = _fma(un, un, S[F_USQ * L + l])
                        S[F_NDRV * L + l] = S[F_NDRV * L + l] + (1.0 if un > S[F_DRV * L + l] else 0.0)
                        S[F_NBCK * L + l] = S[F_NBCK * L + l] + (1.0 if un < S[F_BCK * L + l] else 0.0)
                    S[F_U * L + l] = un
                    S[F_V * L + l] = vn
                    S[F_C * L + l] = c2
                    S[F_S * L + l] = s2

    return chunk


_chunk_c0 = _make_chunk(KIND_COS, MODE_PLAIN)
_chunk_c1 = _make_chunk(KIND_COS, MODE_STATS)
_chunk_c2 = _make_chunk(KIND_COS, MODE_TAN)
_chunk_s0 = _make_chunk(KIND_SIN, MODE_PLAIN)
_chunk_s1 = _make_chunk(KIND_SIN, MODE_STATS)
_chunk_s2 = _make_chunk(KIND_SIN, MODE_TAN)
_chunk_g0 = _make_chunk(KIND_GEN, MODE_PLAIN)
_chunk_g1 = _make_chunk(KIND_GEN, MODE_STATS)
_chunk_g2 = _make_chunk(KIND_GEN, MODE_TAN)


def _chunk(token, mode, S, CF, m, H1, ng):
    """Run the chunk kernel of the kind selected by ``token``'s type and of ``mode``."""


@overload(_chunk, jit_options={"nogil": True})
def _chunk_impl(token, mode, S, CF, m, H1, ng):
    kernels = {types.int8: (_chunk_c0, _chunk_c1, _chunk_c2),
               types.int16: (_chunk_s0, _chunk_s1, _chunk_s2),
               types.int32: (_chunk_g0, _chunk_g1, _chunk_g2)}[token.dtype]
    k_plain, k_stats, k_tan = kernels

    def impl(token, mode, S, CF, m, H1, ng):
        if mode == MODE_PLAIN:
            k_plain(S, CF, m, H1, ng)
        elif mode == MODE_STATS:
            k_stats(S, CF, m, H1, ng)
        else:
            k_tan(S, CF, m, H1, ng)

    return impl


def _is_general(token):
    """True for the token of the general (any number of harmonics) kind."""


@overload(_is_general)
def _is_general_impl(token):
    general = token.dtype == types.int32
    return lambda token: general


# ----------------------------------------------------------------------------- lane scheduler
#: Byte alignment of the lane arrays (a cache line: no SIMD load or store straddles two lines).
ALIGN_BYTES = 64


@njit(nogil=True)
def _aligned_zeros(n):
    """A zeroed float64 array of length n whose data start on an ALIGN_BYTES boundary."""
    pad = ALIGN_BYTES // 8
    raw = np.zeros(n + pad)
    off = ((ALIGN_BYTES - raw.ctypes.data % ALIGN_BYTES) % ALIGN_BYTES) // 8
    return raw[off:off + n]


@njit(nogil=True)
def _lane_reset_stats(S, l):
    L = LANES
    S[F_UMIN * L + l] = np.inf
    S[F_UMAX * L + l] = -np.inf
    S[F_VMIN * L + l] = np.inf
    S[F_VMAX * L + l] = -np.inf
    S[F_USUM * L + l] = 0.0
    S[F_USQ * L + l] = 0.0
    S[F_NDRV * L + l] = 0.0
    S[F_NBCK * L + l] = 0.0


@njit(nogil=True)
def _lane_reset_tangent(S, l):
    L = LANES
    S[F_Y00 * L + l] = 1.0
    S[F_Y10 * L + l] = 0.0
    S[F_Y01 * L + l] = 0.0
    S[F_Y11 * L + l] = 1.0


@njit(nogil=True)
def _lane_idle(S, CF, l):
    """An idle lane: all zeros, no rotation: it computes zeros and never ends a period."""
    L = LANES
    for f in range(NFIELDS):
        S[f * L + l] = 0.0
    S[F_C * L + l] = 1.0
    for i in range(CF.shape[0] // L):
        CF[i * L + l] = 0.0
    _lane_reset_tangent(S, l)


@njit(nogil=True)
def _lane_move(S, CF, src, dst):
    """Copy every field of lane src to lane dst."""
    L = LANES
    for f in range(NFIELDS):
        S[f * L + dst] = S[f * L + src]
    for i in range(CF.shape[0] // L):
        CF[i * L + dst] = CF[i * L + src]


@njit(nogil=True)
def _lane_load(S, CF, l, cf, D, omega, N, u, v):
    L = LANES
    T = 2.0 * math.pi / omega
    h = T / N
    cm1, sa = _half_step_rotation(N)
    S[F_U * L + l] = u
    S[F_V * L + l] = v
    S[F_C * L + l] = 1.0
    S[F_S * L + l] = 0.0
    S[F_CM1 * L + l] = cm1
    S[F_SA * L + l] = sa
    S[F_H * L + l] = h
    S[F_HH * L + l] = 0.5 * h
    S[F_H6 * L + l] = h / 6.0
    H1 = cf.shape[1]
    S[F_CA0 * L + l] = cf[0, 0, 0]
    S[F_KA0 * L + l] = cf[1, 0, 0]
    S[F_FA0 * L + l] = cf[2, 0, 0]
    if H1 > 1:
        S[F_CA1 * L + l] = cf[0, 1, 0]
        S[F_CB1 * L + l] = cf[0, 1, 1]
        S[F_KA1 * L + l] = cf[1, 1, 0]
        S[F_KB1 * L + l] = cf[1, 1, 1]
        S[F_FA1 * L + l] = cf[2, 1, 0]
        S[F_FB1 * L + l] = cf[2, 1, 1]
    else:
        S[F_CA1 * L + l] = 0.0
        S[F_CB1 * L + l] = 0.0
        S[F_KA1 * L + l] = 0.0
        S[F_KB1 * L + l] = 0.0
        S[F_FA1 * L + l] = 0.0
        S[F_FB1 * L + l] = 0.0
    if CF.shape[0] > 0:
        for i in range(3):
            for j in range(H1):
                for q in range(2):
                    CF[((i * H1 + j) * 2 + q) * L + l] = cf[i, j, q]
    t1, t2, t3 = _thresholds(D)
    S[F_D * L + l] = D
    S[F_DRV * L + l] = t1
    S[F_BCK * L + l] = t2
    S[F_DTAN * L + l] = t3
    _lane_reset_stats(S, l)
    _lane_reset_tangent(S, l)


@njit(nogil=True)
def _lane_stats_out(S, l, stats, p, n):
    L = LANES
    _write_stats(stats, p, n, S[F_UMIN * L + l], S[F_UMAX * L + l], S[F_VMIN * L + l],
                 S[F_VMAX * L + l], S[F_USUM * L + l], S[F_USQ * L + l],
                 S[F_NDRV * L + l], S[F_NBCK * L + l])


@njit(nogil=True, cache=True)
def _lanes_worker(token, order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent,
                  poincare, end_state, stats, tan_log, tan_out, status):
    """Integrate points of the queue ``order`` (default mode) in lock-step lanes, refilling each
    finished lane with the next point of the queue (shared through ``counter`` with the other
    workers of the batch).

    ``token`` (an empty array from ``_KIND_TOKENS``) selects the chunk kind by its type.
    """
    general = _is_general(token)
    L = LANES
    P = order.shape[0]
    H1 = coef.shape[2]
    n_total = n_transient + n_record
    S = _aligned_zeros(NFIELDS * L)
    CF = _aligned_zeros(3 * H1 * 2 * L if general else 0)
    pid = np.full(L, -1, dtype=np.int64)
    kstep = np.zeros(L, dtype=np.int64)
    nst = np.full(L, _BIG, dtype=np.int64)
    per = np.zeros(L, dtype=np.int64)
    exhausted = False
    active = 0
    for l in range(L):
        _lane_idle(S, CF, l)
    while True:
        # fill idle lanes from the queue
        for l in range(L):
            while pid[l] < 0 and not exhausted:
                i = _fetch_add(counter, 1)
                if i >= P:
                    exhausted = True
                    break
                p = order[i]
                if n_total == 0:
                    end_state[p, 0] = state0[p, 0]
                    end_state[p, 1] = state0[p, 1]
                    _write_stats(stats, p, 0, np.inf, -np.inf, np.inf, -np.inf, 0.0, 0.0, 0.0, 0.0)
                    if tangent != TAN_NONE:
                        tan_out[p, 0, 0] = 1.0
                        tan_out[p, 1, 0] = 0.0
                        tan_out[p, 0, 1] = 0.0
                        tan_out[p, 1, 1] = 1.0
                    status[p] = ST_OK
                    continue
                _lane_load(S, CF, l, coef[p], D[p], omega[p], nsteps[p], state0[p, 0], state0[p, 1])
                pid[l] = p
                kstep[l] = 0
                nst[l] = nsteps[p]
                per[l] = 0
                active += 1
        if active == 0:
            break
        ng = L // GROUP
        if exhausted:
            # queue empty: pack the remaining lanes into the first groups, run only those
            dst = 0
            for l in range(L):
                if pid[l] >= 0:
                    if l != dst:
                        _lane_move(S, CF, l, dst)
                        pid[dst] = pid[l]
                        kstep[dst] = kstep[l]
                        nst[dst] = nst[l]
                        per[dst] = per[l]
                        pid[l] = -1
                        kstep[l] = 0
                        nst[l] = _BIG
                        _lane_idle(S, CF, l)
                    dst += 1
            ng = (active + GROUP - 1) // GROUP
        m = nst[0] - kstep[0]  # (not the literal _BIG: keeps the chunk kernels' m an int64)
        rec = False
        for l in range(L):
            if pid[l] >= 0:
                m = min(m, nst[l] - kstep[l])
                if per[l] >= n_transient:
                    rec = True
        mode = MODE_PLAIN
        if rec:
            mode = MODE_TAN if tangent != TAN_NONE else MODE_STATS
        _chunk(token, mode, S, CF, m, H1, ng)
        # period ends
        for l in range(L):
            p = pid[l]
            if p < 0:
                continue
            kstep[l] += m
            if kstep[l] < nst[l]:
                continue
            kstep[l] = 0
            S[F_C * L + l] = 1.0  # exact re-seed of the rotation at the period start
            S[F_S * L + l] = 0.0
            per[l] += 1
            done = per[l]
            u = S[F_U * L + l]
            v = S[F_V * L + l]
            N = nst[l]
            if not (abs(u) < DIVERGENCE_BOUND and abs(v) < DIVERGENCE_BOUND):
                _diverged(p, poincare, end_state, status)
                if done > n_transient:
                    _lane_stats_out(S, l, stats, p, N * (done - n_transient))
                else:
                    _write_stats(stats, p, 0, np.inf, -np.inf, np.inf, -np.inf, 0.0, 0.0, 0.0, 0.0)
                pid[l] = -1
                nst[l] = _BIG
                _lane_idle(S, CF, l)
                active -= 1
                continue
            if done > n_transient:
                j = done - 1 - n_transient
                if poincare.shape[1] > 0:
                    poincare[p, j, 0] = u
                    poincare[p, j, 1] = v
                if tangent == TAN_LYAPUNOV:
                    a1, b1, a2, b2, l1, l2 = _gs(S[F_Y00 * L + l], S[F_Y10 * L + l],
                                                 S[F_Y01 * L + l], S[F_Y11 * L + l])
                    S[F_Y00 * L + l] = a1
                    S[F_Y10 * L + l] = b1
                    S[F_Y01 * L + l] = a2
                    S[F_Y11 * L + l] = b2
                    tan_log[p, j, 0] = l1
                    tan_log[p, j, 1] = l2
            else:
                # a transient period ended: discard what the chunks accumulated for this lane
                _lane_reset_stats(S, l)
                _lane_reset_tangent(S, l)
            if done == n_total:
                end_state[p, 0] = u
                end_state[p, 1] = v
                _lane_stats_out(S, l, stats, p, N * n_record)
                if tangent != TAN_NONE:
                    tan_out[p, 0, 0] = S[F_Y00 * L + l]
                    tan_out[p, 1, 0] = S[F_Y10 * L + l]
                    tan_out[p, 0, 1] = S[F_Y01 * L + l]
                    tan_out[p, 1, 1] = S[F_Y11 * L + l]
                status[p] = ST_OK
                pid[l] = -1
                nst[l] = _BIG
                _lane_idle(S, CF, l)
                active -= 1




def _lanes_kind(coef: np.ndarray, order: np.ndarray) -> int:
    """The chunk kind a worker needs: general for more than one harmonic, else with or without
    sine terms (the kinds give the same bits on the points they share, so this choice only
    decides speed and what is compiled)."""
    if coef.shape[2] > 2:
        return KIND_GEN
    if coef.shape[2] == 2 and np.any(coef[order, :, 1, 1] != 0.0):
        return KIND_SIN
    return KIND_COS


#: Type tokens selecting the chunk kind at compile time: the lanes worker is compiled (and cached)
#: separately per kind, and only for the kinds a program uses.
_KIND_TOKENS = {KIND_COS: np.empty(0, np.int8), KIND_SIN: np.empty(0, np.int16), KIND_GEN: np.empty(0, np.int32)}


# ----------------------------------------------------------------------------- entry point
_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()


def _executor() -> ThreadPoolExecutor:
    """The kernel's thread pool, created once (its threads start on demand, up to numba's
    thread limit, which bounds every thread setting) and never resized, so concurrent callers can
    share it."""
    global _pool
    with _pool_lock:
        if _pool is None:
            import numba

            _pool = ThreadPoolExecutor(max_workers=max(1, int(numba.config.NUMBA_NUM_THREADS)),
                                       thread_name_prefix="geardyn-kernel")
        return _pool


def _forget_pool() -> None:
    """In a forked child the parent's pool threads do not exist: start a new pool when needed."""
    global _pool, _pool_lock
    _pool = None
    _pool_lock = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def n_threads() -> int:
    """Threads the kernel uses: numba's thread setting (``geardyn.integrate.set_threads``)."""
    import numba

    return max(1, int(numba.get_num_threads()))


def _queue_order(nsteps: np.ndarray) -> np.ndarray:
    """The batch's queue: points by decreasing cost (steps per period), so that the last points
    taken, which the lanes and threads finish unevenly, are the cheapest."""
    return np.argsort(-np.asarray(nsteps, dtype=np.int64), kind="stable").astype(np.int64)


def run_batch(coef, D, omega, nsteps, state0, n_transient, n_record, tangent, accurate,
              poincare, end_state, stats, tan_log, tan_out, status, hist):
    """Advance a batch of P parameter points; results are written into the output arrays.

    Parameters
    ----------
    coef : float64[P, 3, H+1, 2]
        Fourier coefficients of C(θ) = 2ξ(θ), K(θ) and F(θ) per point (``GearModel.coefficients``).
    D : float64[P]
        Half backlash per point (non-dimensional).
    omega : float64[P]
        Mesh frequency per point; the period is T = 2π/ω.
    nsteps : int64[P]
        RK4 steps per period per point; the step is h = T/nsteps.
    state0 : float64[P, 2]
        Initial (u, u') at θ = 0.
    n_transient, n_record : int
        Periods discarded, then periods recorded.
    tangent : int
        ``TAN_NONE``; ``TAN_LYAPUNOV`` (tangent matrix from the identity at the record start,
        Gram–Schmidt each recorded period, logs of the diagonal into ``tan_log``); or
        ``TAN_MONODROMY`` (the raw product over the recorded periods into ``tan_out``).
    accurate : bool
        Split steps at contact-boundary crossings.
    poincare : float64[P, n_record or 0, 2]
        Out: state at the end of each recorded period (NaN after divergence).
    end_state : float64[P, 2]
        Out: final state.
    stats : float64[P, NSTAT]
        Out: streaming statistics over the recorded periods (see the ``S_*`` indices).
    tan_log : float64[P, n_record or 0, 2]
        Out (Lyapunov mode): log r11, log r22 of each recorded period.
    tan_out : float64[P, 2, 2]
        Out: final tangent matrix (the monodromy in ``TAN_MONODROMY`` mode).
    status : int64[P]
        Out: ``ST_OK`` or ``ST_DIVERGED``.
    hist : float64[P, K, 2]
        Out: if K > 0, the state at every step of the last (K - 1)/nsteps periods (all points of a
        batch with a history must share nsteps).

    Notes
    -----
    ``n_threads()`` workers take the points from a queue ordered by decreasing cost; with at
    least ``LANE_MIN_POINTS`` points per worker they run them in lock-step lanes (default mode, no
    history), otherwise one at a time.  Each point's results are the same bits whichever way and
    wherever it is run.
    """
    P = coef.shape[0]
    if P == 0:
        return
    n_transient = int(n_transient)
    n_record = int(n_record)
    tangent = int(tangent)
    accurate = bool(accurate)
    scalar_only = accurate or hist.shape[1] > 0
    total = int(np.sum(nsteps)) * (n_transient + n_record)
    nw = min(n_threads(), P) if total >= THREAD_MIN_STEPS else 1
    order = _queue_order(nsteps)
    counter = np.zeros(1, dtype=np.int64)
    lanes = not scalar_only and P >= LANE_MIN_POINTS * nw
    token = _KIND_TOKENS[_lanes_kind(coef, order)] if lanes else None

    def work():
        if accurate:
            _accurate_worker(order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent,
                             poincare, end_state, stats, tan_log, tan_out, status, hist)
        elif lanes:
            _lanes_worker(token, order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent,
                          poincare, end_state, stats, tan_log, tan_out, status)
        else:
            _scalar_worker(order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent,
                           poincare, end_state, stats, tan_log, tan_out, status, hist)

    if nw == 1:
        work()
        return
    pool = _executor()
    for f in [pool.submit(work) for _ in range(nw)]:
        f.result()
