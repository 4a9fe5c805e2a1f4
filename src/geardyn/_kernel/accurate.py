"""The accurate mode: steps split at the contact-boundary crossings, one point at a time.

Each sub-step is an RK4 step with the vector field locked to one contact region (its smooth
extension beyond the region), so RK4 keeps its fourth order through contact changes.  The
earliest exit from the region is found on the dense (cubic Hermite) output of the sub-step, by
bisection on the cubic, then refined by Newton on the true sub-step length; the step goes on from
the boundary in the region the velocity points to.  The coefficients are evaluated with plain
trigonometric calls at every (sub-)step start, midpoint and end.

A point whose stiffness and STE are a table evaluated as given (:mod:`geardyn.meshtable`) also ends a
sub-step at every node of the table (the node times θ_j/ω are known in advance): within a sub-step the
stiffness is the node's segment, linear in θ, so RK4 keeps its order through the jumps; at a node the
STE's kink changes u' by −ω(σ_j − σ_{j−1}) and its jump changes u by −(e_j⁺ − e_j⁻).  A node within
``NODE_TOL``·h of a step's end is taken at that end (the last step of a period: every node left).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .core import (
    DIVERGENCE_BOUND,
    S_N,
    S_NBACK,
    S_NDRIVE,
    S_NSEP,
    S_UMAX,
    S_UMIN,
    S_USQ,
    S_USUM,
    S_VMAX,
    S_VMIN,
    ST_OK,
    TAN_CONTINUE,
    TAN_LYAPUNOV,
    TAN_NONE,
    _diverged,
    _fetch_add,
    _gs,
)

#: Accurate mode: at most this many splits of one step, and Hermite samples per step searched.
MAX_SPLITS = 8
HERMITE_SAMPLES = 8
#: Accurate mode: Newton iterations on the sub-step length, and the tolerance on |u - boundary|.
NEWTON_ITERS = 6
CROSSING_TOL = 1.0e-14
#: Table evaluation: a node this close (relative to the step h) to the end of a step is taken at that end.
NODE_TOL = 1.0e-10


# ----------------------------------------------------------------------------- coefficients
@njit(nogil=True)
def _coef_at(cf, theta, xb, kb, ks):
    """C, K, F at θ (accurate mode: cos θ, sin θ and their multiples by rotation), K plus the table segment
    kb + ks (θ − xb) (all three 0 for a series model)."""
    c1 = math.cos(theta)
    s1 = math.sin(theta)
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
    return C, K + (kb + ks * (theta - xb)), F


# ----------------------------------------------------------------------------- locked steps
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
def _rk4_locked(cf, theta0, omega, u, v, s, D, r, xb, kb, ks):
    """One RK4 step of length s from angle theta0 with the vector field locked to region r."""
    C0, K0, F0 = _coef_at(cf, theta0, xb, kb, ks)
    C1, K1, F1 = _coef_at(cf, theta0 + 0.5 * omega * s, xb, kb, ks)
    C2, K2, F2 = _coef_at(cf, theta0 + omega * s, xb, kb, ks)
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
def _tangent_locked(cf, theta0, omega, s, r, Y, xb, kb, ks):
    """Propagate the tangent matrix Y over a sub-step of length s locked to region r."""
    C0, K0, F0 = _coef_at(cf, theta0, xb, kb, ks)
    C1, K1, F1 = _coef_at(cf, theta0 + 0.5 * omega * s, xb, kb, ks)
    C2, K2, F2 = _coef_at(cf, theta0 + omega * s, xb, kb, ks)
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


# ----------------------------------------------------------------------------- event location
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
def _step_accurate(cf, theta0, omega, h, u, v, D, r, Y, tangent, xb, kb, ks):
    """One regular step of length h in accurate mode; returns (u, v, region).

    ``xb, kb, ks``: the table segment K += kb + ks (θ − xb) the step lies in (0, 0, 0 for a series model)."""
    t_done = 0.0
    for split in range(MAX_SPLITS + 1):
        H = h - t_done
        if H <= 0.0:
            break
        th = theta0 + omega * t_done
        un, vn = _rk4_locked(cf, th, omega, u, v, H, D, r, xb, kb, ks)
        # earliest exit from region r along the dense (Hermite) output of this sub-step (after the split budget:
        # none, the step finishes in the current region)
        x_in = 0.0
        x_out = -1.0
        for i in range(1, HERMITE_SAMPLES + 1 if split < MAX_SPLITS else 1):
            x = i / HERMITE_SAMPLES
            ux = un if i == HERMITE_SAMPLES else _hermite(u, v, un, vn, H, x)
            if _outside(ux, D, r):
                x_out = x
                break
            x_in = x
        if x_out < 0.0:
            if tangent:
                _tangent_locked(cf, th, omega, H, r, Y, xb, kb, ks)
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
            us, vs = _rk4_locked(cf, th, omega, u, v, s, D, r, xb, kb, ks)
            g = us - b
            if abs(g) <= CROSSING_TOL * (1.0 + abs(b)) or vs == 0.0:
                break
            s_new = s - g / vs
            if s_new <= 0.0 or s_new > H:
                break
            s = s_new
        us, vs = _rk4_locked(cf, th, omega, u, v, s, D, r, xb, kb, ks)
        if tangent:
            _tangent_locked(cf, th, omega, s, r, Y, xb, kb, ks)
        u = b
        v = vs
        t_done += s
        # the region entered: from the boundary, the side the velocity points to
        if r == 0:
            r = 1 if b > 0.0 else -1
        else:
            r = 0
    return u, v, r


# ----------------------------------------------------------------------------- a table evaluated as given
@njit(nogil=True)
def _step_table(cf, tab, m, t, te, last, omega, u, v, D, r, Y, tangent, jn, seg, eps):
    """The regular step [t, te] of a point evaluated as a table; returns (u, v, region, jn, seg).

    ``jn``: the next node of the period (m: none left); ``seg``: the segment the motion is in (m − 1 and
    ``jn`` = 0: the wrap segment from the last node, one period back).  Sub-steps end at the nodes; the
    ``last`` step of a period takes the nodes left within ``eps`` of its end there.
    """
    while True:
        # the nodes due (at the period's end: all that are left): the STE's kink and jump
        while jn < m and (tab[jn, 0] / omega <= t + eps or (last and t == te)):
            du = tab[jn, 4] - tab[jn, 3]
            v -= omega * (tab[jn, 6] - tab[seg, 6])
            if du != 0.0:
                u -= du
                r = _region(u, D)
            seg = jn
            jn += 1
        if t == te:
            return u, v, r, jn, seg
        ts = te
        if jn < m and tab[jn, 0] / omega < te - eps:
            ts = tab[jn, 0] / omega
        xb = tab[seg, 0] - (2.0 * math.pi if jn == 0 else 0.0)
        u, v, r = _step_accurate(cf, omega * t, omega, ts - t, u, v, D, r, Y, tangent, xb, tab[seg, 2], tab[seg, 5])
        t = ts


# ----------------------------------------------------------------------------- one point, the worker
@njit(nogil=True)
def _point_accurate(
    p,
    cf,
    D,
    omega,
    N,
    u,
    v,
    n_transient,
    n_record,
    tangent,
    poincare,
    end_state,
    stats,
    tan_log,
    tan_out,
    status,
    hist,
    tab,
    m,
):
    """One point in accurate mode (steps split at the contact-boundary crossings, and at the nodes of
    its table when m > 0; its state at a period end is that before the node at θ ≡ 0)."""
    T = 2.0 * math.pi / omega
    h = T / N
    eps = NODE_TOL * h
    Y = np.eye(2)
    if tangent == TAN_CONTINUE:  # the orthonormal basis a previous block ended with
        Y[:, :] = tan_out[p]
        tangent = TAN_LYAPUNOV
    hist_first = n_transient + n_record - (hist.shape[1] - 1) // N  # (after the last period without a history)
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
        if per == hist_first:
            hist[p, 0, 0] = u
            hist[p, 0, 1] = v
            hi = 1
        jn = 0
        seg = m - 1
        for k in range(N):
            if m == 0:
                u, v, r = _step_accurate(cf, k * h * omega, omega, h, u, v, D, r, Y, tan_on, 0.0, 0.0, 0.0)
            else:
                u, v, r, jn, seg = _step_table(
                    cf,
                    tab,
                    m,
                    k * h,
                    T if k == N - 1 else (k + 1) * h,
                    k == N - 1,
                    omega,
                    u,
                    v,
                    D,
                    r,
                    Y,
                    tan_on,
                    jn,
                    seg,
                    eps,
                )
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
                # modified Gram–Schmidt on the columns of Y in place, the logs of r11, r22 logged
                Y[0, 0], Y[1, 0], Y[0, 1], Y[1, 1], tan_log[p, j, 0], tan_log[p, j, 1] = _gs(
                    Y[0, 0], Y[1, 0], Y[0, 1], Y[1, 1]
                )
    end_state[p, 0] = u
    end_state[p, 1] = v
    if tangent != TAN_NONE:
        tan_out[p, :, :] = Y
    status[p] = ST_OK


@njit(nogil=True, cache=True)
def _accurate_worker(
    order,
    counter,
    coef,
    D,
    omega,
    nsteps,
    state0,
    n_transient,
    n_record,
    tangent,
    poincare,
    end_state,
    stats,
    tan_log,
    tan_out,
    status,
    hist,
    tab,
    ntab,
):
    """Integrate points of the queue ``order`` one at a time in accurate mode (tables: ``tab``, ``ntab``)."""
    while True:
        i = _fetch_add(counter, 1)
        if i >= order.shape[0]:
            break
        p = order[i]
        _point_accurate(
            p,
            coef[p],
            D[p],
            omega[p],
            nsteps[p],
            state0[p, 0],
            state0[p, 1],
            n_transient,
            n_record,
            tangent,
            poincare,
            end_state,
            stats,
            tan_log,
            tan_out,
            status,
            hist,
            tab[p],
            ntab[p],
        )
