"""The scalar default-mode path: one point at a time, state and statistics in registers.

Used for batches with few points per worker (a single long trajectory, a shooting iteration)
and for every batch that records a time history.  The arithmetic is that of the lane kernels
(:mod:`.lanes`): the same operations in the same order, so a point gives the same bits on
either path.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .core import (
    DIVERGENCE_BOUND,
    NSNAP,
    ST_OK,
    TAN_CONTINUE,
    TAN_LYAPUNOV,
    TAN_NONE,
    _adapt_check,
    _adapt_finish,
    _adapt_reset,
    _coef_seq,
    _diverged,
    _fetch_add,
    _fma,
    _gs,
    _half_step_rotation,
    _rk4,
    _rk4_tan,
    _rot_small,
    _series1,
    _slope,
    _thresholds,
    _write_stats,
)


@njit(inline="always")
def _first_harmonic(cf, i):
    """(a0, a1, b1) of series i (0 when there is no first harmonic)."""
    H1 = cf.shape[1]
    return cf[i, 0, 0], cf[i, 1, 0] if H1 > 1 else 0.0, cf[i, 1, 1] if H1 > 1 else 0.0


@njit(inline="always")
def _series3(cf1, c, s):
    """C, K, F at the angle (c, s) from their first-harmonic coefficients ``cf1`` (:func:`_first_harmonic`)."""
    return _series1(cf1[0], c, s), _series1(cf1[1], c, s), _series1(cf1[2], c, s)


@njit(nogil=True)
def _point_scalar(
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
    adapt_tol,
    ring,
    streak,
    cbuf,
    snap,
):
    """One point in the default mode, state and statistics in registers.

    The arithmetic is that of the lane kernels (same operations, same order), so a point gives
    the same bits on either path.  With ``adapt_tol`` > 0 the transient is adaptive, as in the
    lanes worker (``ring``, ``streak``, ``cbuf``, ``snap``: its slot-0 work arrays).
    """
    T = 2.0 * math.pi / omega
    h = T / N
    hh = 0.5 * h
    h6 = h / 6.0
    cm1, sa = _half_step_rotation(N)
    fast = cf.shape[1] <= 2
    cf1 = (_first_harmonic(cf, 0), _first_harmonic(cf, 1), _first_harmonic(cf, 2))
    tdrv, tbck, dtan = _thresholds(D)
    y00, y10, y01, y11 = 1.0, 0.0, 0.0, 1.0
    if tangent == TAN_CONTINUE:  # the orthonormal basis a previous block ended with
        y00, y10, y01, y11 = tan_out[p, 0, 0], tan_out[p, 1, 0], tan_out[p, 0, 1], tan_out[p, 1, 1]
        tangent = TAN_LYAPUNOV
    umin = np.inf
    umax = -np.inf
    vmin = np.inf
    vmax = -np.inf
    usum = 0.0
    usq = 0.0
    ndrv = 0.0
    nbck = 0.0
    hist_first = n_transient + n_record - (hist.shape[1] - 1) // N  # (after the last period without a history)
    hi = 0
    adaptive = adapt_tol > 0.0 and streak.shape[1] > 1
    tend = n_transient
    rlen = n_record
    cyc = 0
    if adaptive:
        _adapt_reset(ring, streak, 0, u, v)
    per = -1
    while per + 1 < tend + rlen:
        per += 1
        rec = per >= tend
        tan_on = tangent != TAN_NONE and rec
        if per == hist_first:
            hist[p, 0, 0] = u
            hist[p, 0, 1] = v
            hi = 1
        c = 1.0
        s = 0.0
        for _k in range(N):
            c1, s1 = _rot_small(c, s, cm1, sa)
            c2, s2 = _rot_small(c1, s1, cm1, sa)
            if fast:
                C0, K0, F0 = _series3(cf1, c, s)
                C1, K1, F1 = _series3(cf1, c1, s1)
                C2, K2, F2 = _series3(cf1, c2, s2)
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
            nrec = N * (per + 1 - tend) if rec else 0
            _write_stats(stats, p, nrec, (umin, umax, vmin, vmax, usum, usq, ndrv, nbck))
            return
        if adaptive and cyc == 0 and per + 1 < tend:
            nc = _adapt_check(ring, streak, 0, per + 1, u, v, adapt_tol)
            if nc > 0:
                cyc = nc
                tend = min(tend, per + 1 + (n_transient - per - 1) % nc)
                if tangent == TAN_NONE and nc < n_record:
                    rlen = nc
        if rec:
            j = per - tend
            if poincare.shape[1] > 0:
                poincare[p, j, 0] = u
                poincare[p, j, 1] = v
            if rlen < n_record:
                cbuf[0, j, 0] = u
                cbuf[0, j, 1] = v
                if j + 1 == n_record % rlen:
                    snap[0] = np.array([umin, umax, vmin, vmax, usum, usq, ndrv, nbck])
            if tangent == TAN_LYAPUNOV:
                y00, y10, y01, y11, tan_log[p, j, 0], tan_log[p, j, 1] = _gs(y00, y10, y01, y11)
    end_state[p, 0] = u
    end_state[p, 1] = v
    _write_stats(stats, p, N * n_record, (umin, umax, vmin, vmax, usum, usq, ndrv, nbck))
    if rlen < n_record:
        _adapt_finish(p, 0, rlen, n_record, N, cbuf, snap, poincare, end_state, stats)
    if tangent != TAN_NONE:
        tan_out[p, 0, 0] = y00
        tan_out[p, 1, 0] = y10
        tan_out[p, 0, 1] = y01
        tan_out[p, 1, 1] = y11
    status[p] = ST_OK


@njit(nogil=True, cache=True)
def _scalar_worker(
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
    adapt_tol,
    max_period,
):
    """Integrate points of the queue ``order`` one at a time (histories, small batches); adaptive
    transient with ``adapt_tol`` > 0 (periods up to ``max_period``)."""
    mp = max_period if adapt_tol > 0.0 else 0
    ring = np.zeros((1, 2 * mp + 1, 2))
    streak = np.zeros((1, mp + 1), dtype=np.int64)
    cbuf = np.zeros((1, max(mp, 1), 2))
    snap = np.zeros((1, NSNAP))
    while True:
        i = _fetch_add(counter, 1)
        if i >= order.shape[0]:
            break
        p = order[i]
        _point_scalar(
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
            adapt_tol,
            ring,
            streak,
            cbuf,
            snap,
        )
