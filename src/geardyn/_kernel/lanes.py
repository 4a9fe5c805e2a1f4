"""The lock-step lanes path: ``LANES`` points per worker advanced together, SIMD across points.

The lane state is a structure of arrays (one aligned float64 array ``S``, field ``f`` of lane
``l`` at ``S[f * LANES + l]``; the general kind keeps all Fourier coefficients in a second array
``CF``).  :func:`_make_chunk` builds, from one template, the chunk kernels advancing all lanes by
``m`` steps: per kind (first harmonic with cosine terms only, with sine terms, any number of
harmonics) and per mode (no statistics, statistics, statistics and tangents); for the
first-harmonic kinds :mod:`.simd` builds the same kernels as explicit vectors of 512 or 256 bits,
and the width that runs (:func:`simd_width`) is chosen at import from the CPU or from
``GEARDYN_SIMD_WIDTH``.  The lanes worker is compiled per kind and width, selected by the type of
its token argument (dtype: kind; number of dimensions: width).  The :func:`_lanes_worker`
schedules the lanes: it refills a finished lane from the batch's shared queue, runs the chunk up
to the nearest period end, does the period-end work of each lane in scalar code, and packs the
remaining lanes into the first groups once the queue is empty.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numba import njit
from numba.core import types
from numba.extending import overload

from .._cache_guard import own_name
from .core import (
    DIVERGENCE_BOUND,
    NSNAP,
    ST_OK,
    TAN_LYAPUNOV,
    TAN_NONE,
    _adapt_check,
    _adapt_finish,
    _adapt_reset,
    _diverged,
    _fetch_add,
    _fma,
    _gs,
    _half_step_rotation,
    _rk4,
    _rk4_tan,
    _rot,
    _rot_small,
    _series_acc,
    _slope,
    _thresholds,
    _write_stats,
)
from .simd import make_vector_chunks

#: Parameter points advanced in lock-step by one worker, in groups of GROUP lanes (one SIMD
#: vector of doubles); when the queue is empty the remaining lanes are packed into the first groups.
GROUP = 4
LANES = 16

# Lane state: field f of lane l is S[f * LANES + l].
(
    F_U,
    F_V,
    F_C,
    F_S,
    F_CM1,
    F_SA,
    F_H,
    F_HH,
    F_H6,
    F_CA0,
    F_CA1,
    F_CB1,
    F_KA0,
    F_KA1,
    F_KB1,
    F_FA0,
    F_FA1,
    F_FB1,
    F_D,
    F_DRV,
    F_BCK,
    F_DTAN,
    F_UMIN,
    F_UMAX,
    F_VMIN,
    F_VMAX,
    F_USUM,
    F_USQ,
    F_NDRV,
    F_NBCK,
    F_Y00,
    F_Y10,
    F_Y01,
    F_Y11,
    # scratch of the general (any number of harmonics) chunk
    F_XC0,
    F_XK0,
    F_XF0,
    F_XC1,
    F_XK1,
    F_XF1,
    F_XC2,
    F_XK2,
    F_XF2,
    F_P0C,
    F_P0S,
    F_P1C,
    F_P1S,
    F_P2C,
    F_P2S,
    F_R1C,
    F_R1S,
    F_R2C,
    F_R2S,
    NFIELDS,
) = range(54)

#: Chunk kinds: first harmonic with cosine terms only, first harmonic with sine terms, general.
KIND_COS, KIND_SIN, KIND_GEN = 0, 1, 2
#: Chunk modes: no statistics, statistics, statistics and tangent propagation.
MODE_PLAIN, MODE_STATS, MODE_TAN = 0, 1, 2

#: Steps-per-period of an idle lane: never the nearest period end.
_BIG = 1 << 62


# ----------------------------------------------------------------------------- lane chunk kernels
@njit(inline="always")
def _series_lane(S, l, c, s, with_sin):
    """C, K, F of lane l (first harmonic) at the angle (c, s): ``core._series1``, the sine terms left out
    without them (fma(0, s, x) == x)."""
    L = LANES
    C = _fma(S[F_CA1 * L + l], c, S[F_CA0 * L + l])
    K = _fma(S[F_KA1 * L + l], c, S[F_KA0 * L + l])
    F = _fma(S[F_FA1 * L + l], c, S[F_FA0 * L + l])
    if with_sin:
        C = _fma(S[F_CB1 * L + l], s, C)
        K = _fma(S[F_KB1 * L + l], s, K)
        F = _fma(S[F_FB1 * L + l], s, F)
    return C, K, F


@njit(inline="always")
def _angle_start(S, CF, l, H1, x, p, c, s):
    """The general chunk's start at one angle (c, s) of lane l: the series (fields x, x + 1, x + 2: C, K, F) at
    their constant terms, the harmonic's angle (fields p, p + 1: cos jθ, sin jθ) at j = 1."""
    L = LANES
    S[p * L + l] = c
    S[(p + 1) * L + l] = s
    S[x * L + l] = CF[l]
    S[(x + 1) * L + l] = CF[(2 * H1) * L + l]
    S[(x + 2) * L + l] = CF[(4 * H1) * L + l]


@njit(inline="always")
def _angle_term(S, l, cfj, x, p, r):
    """Add the terms of harmonic j (``cfj``: its cosine and sine coefficients of C, K and F) at one angle of lane l
    (fields as in :func:`_angle_start`), then rotate the harmonic's angle by the angle (fields r, r + 1)."""
    L = LANES
    ac, bc, ak, bk, af, bf = cfj
    ck = S[p * L + l]
    sk = S[(p + 1) * L + l]
    S[x * L + l] = _series_acc(S[x * L + l], ac, bc, ck, sk)
    S[(x + 1) * L + l] = _series_acc(S[(x + 1) * L + l], ak, bk, ck, sk)
    S[(x + 2) * L + l] = _series_acc(S[(x + 2) * L + l], af, bf, ck, sk)
    ck, sk = _rot(ck, sk, S[r * L + l], S[(r + 1) * L + l])
    S[p * L + l] = ck
    S[(p + 1) * L + l] = sk


def _make_chunk(kind, mode):
    """Build the chunk kernel advancing all lanes by m steps for one (kind, mode)."""
    L = LANES
    general = kind == KIND_GEN
    with_sin = kind != KIND_COS
    with_stats = mode != MODE_PLAIN
    with_tan = mode == MODE_TAN

    @njit(nogil=True)
    @own_name("kind", kind, "mode", mode)  # closures of one name collide once cached (see own_name)
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
                        _angle_start(S, CF, l, H1, F_XC0, F_P0C, c0, s0)
                        _angle_start(S, CF, l, H1, F_XC1, F_P1C, c1, s1)
                        _angle_start(S, CF, l, H1, F_XC2, F_P2C, c2, s2)
                for j in range(1, H1):
                    oc = (2 * j) * L
                    ok = (2 * (H1 + j)) * L
                    of = (2 * (2 * H1 + j)) * L
                    for g in range(ng):
                        for k in range(GROUP):
                            l = g * GROUP + k
                            cfj = (CF[oc + l], CF[oc + L + l], CF[ok + l], CF[ok + L + l], CF[of + l], CF[of + L + l])
                            _angle_term(S, l, cfj, F_XC0, F_P0C, F_C)  # angle 0 (step start)
                            _angle_term(S, l, cfj, F_XC1, F_P1C, F_R1C)  # angle 1 (midpoint)
                            _angle_term(S, l, cfj, F_XC2, F_P2C, F_R2C)  # angle 2 (step end)
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
                        C0, K0, F0 = _series_lane(S, l, c0, s0, with_sin)
                        C1, K1, F1 = _series_lane(S, l, c1, s1, with_sin)
                        C2, K2, F2 = _series_lane(S, l, c2, s2, with_sin)
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
                        y00, y10 = _rk4_tan(S[F_Y00 * L + l], S[F_Y10 * L + l], h, hh, h6, C0, C1, C2, g1, g2, g3, g4)
                        y01, y11 = _rk4_tan(S[F_Y01 * L + l], S[F_Y11 * L + l], h, hh, h6, C0, C1, C2, g1, g2, g3, g4)
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


_FIELDS = {name[2:]: value for name, value in globals().items() if name.startswith("F_") and name != "F_"}
_MODES = (MODE_PLAIN, MODE_STATS, MODE_TAN)
#: Chunk kernels per register width (0: the template's compiler-vectorised loops) and kind, each a tuple over
#: ``_MODES``: at 256 and 512 bits the explicit-SIMD chunk kernels (:mod:`.simd`) of the first-harmonic kinds;
#: the general kind always runs the template.
_KERNELS = {0: {kind: tuple(_make_chunk(kind, mode) for mode in _MODES) for kind in (KIND_COS, KIND_SIN, KIND_GEN)}}
for _w in (256, 512):
    _KERNELS[_w] = {
        kind: tuple(make_vector_chunks(kind == KIND_SIN, mode, _w, LANES, _FIELDS) for mode in _MODES)
        for kind in (KIND_COS, KIND_SIN)
    }
    _KERNELS[_w][KIND_GEN] = _KERNELS[0][KIND_GEN]

#: Widths a lanes worker can be compiled for, by the number of dimensions of its token.
_WIDTH_OF_NDIM = {1: 0, 2: 256, 3: 512}
_NDIM_OF_WIDTH = {w: n for n, w in _WIDTH_OF_NDIM.items()}
_KIND_OF_DTYPE = {types.int8: KIND_COS, types.int16: KIND_SIN, types.int32: KIND_GEN}


def _chunk(token, mode, S, CF, m, H1, ng):
    """Run the chunk kernel of the kind and width selected by ``token``'s type, and of ``mode``."""


@overload(_chunk, jit_options={"nogil": True})
def _chunk_impl(token, mode, S, CF, m, H1, ng):
    k_plain, k_stats, k_tan = _KERNELS[_WIDTH_OF_NDIM[token.ndim]][_KIND_OF_DTYPE[token.dtype]]

    @own_name(token.dtype, token.ndim)  # one implementation per token type (see own_name)
    def impl(token, mode, S, CF, m, H1, ng):
        if mode == MODE_PLAIN:
            k_plain(S, CF, m, H1, ng)
        elif mode == MODE_STATS:
            k_stats(S, CF, m, H1, ng)
        else:
            k_tan(S, CF, m, H1, ng)

    return impl


# ----------------------------------------------------------------------------- lane scheduler
#: Byte alignment of the lane arrays (a cache line: no SIMD load or store straddles two lines).
ALIGN_BYTES = 64


@njit(nogil=True)
def _aligned_zeros(n):
    """A zeroed float64 array of length n whose data start on an ALIGN_BYTES boundary."""
    pad = ALIGN_BYTES // 8
    raw = np.zeros(n + pad)
    off = ((ALIGN_BYTES - raw.ctypes.data % ALIGN_BYTES) % ALIGN_BYTES) // 8
    return raw[off : off + n]


@njit(nogil=True)
def _lane_reset_stats(S, l):
    for i in range(NSNAP):  # the fields UMIN … NBCK: u min, u max, u' min, u' max, Σu, Σu², the counts
        S[(F_UMIN + i) * LANES + l] = (np.inf if i % 2 == 0 else -np.inf) if i < 4 else 0.0


@njit(nogil=True)
def _lane_reset_tangent(S, l):
    for i in range(4):  # the identity: Y00, Y10, Y01, Y11
        S[(F_Y00 + i) * LANES + l] = 1.0 if i % 3 == 0 else 0.0


@njit(nogil=True)
def _lane_idle(S, CF, ls, l):
    """An idle lane: no point (``ls``: the worker's lane integers), all zeros, no rotation: it computes zeros and
    never ends a period (``_BIG`` steps per period)."""
    L = LANES
    ls[:, l] = 0
    ls[0, l] = -1
    ls[2, l] = _BIG
    S[l::L] = 0.0
    CF[l::L] = 0.0
    S[F_C * L + l] = 1.0
    _lane_reset_tangent(S, l)


@njit(nogil=True)
def _lane_load(S, CF, l, cf, D, omega, N, u, v):
    L = LANES
    h = 2.0 * math.pi / omega / N
    cm1, sa = _half_step_rotation(N)
    for f, x in enumerate((u, v, 1.0, 0.0, cm1, sa, h, 0.5 * h, h / 6.0)):  # the fields U … H6
        S[(F_U + f) * L + l] = x
    H1 = cf.shape[1]
    for i in range(3):  # the fields A0, A1, B1 of C, K and F
        S[(F_CA0 + 3 * i) * L + l] = cf[i, 0, 0]
        S[(F_CA1 + 3 * i) * L + l] = cf[i, 1, 0] if H1 > 1 else 0.0
        S[(F_CB1 + 3 * i) * L + l] = cf[i, 1, 1] if H1 > 1 else 0.0
    if CF.shape[0] > 0:  # all coefficients: (i, j, q) at CF[((i * H1 + j) * 2 + q) * L + l]
        CF[l::L] = cf.ravel()
    for f, x in enumerate((D,) + _thresholds(D)):  # the fields D, DRV, BCK, DTAN
        S[(F_D + f) * L + l] = x
    _lane_reset_stats(S, l)
    _lane_reset_tangent(S, l)


@njit(nogil=True, cache=True)
def _lanes_worker(
    token,
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
    adapt_tol,
    max_period,
):
    """Integrate points of the queue ``order`` (default mode) in lock-step lanes, refilling each
    finished lane with the next point of the queue (shared through ``counter`` with the other
    workers of the batch).

    ``token`` (an empty array from ``_kind_token``) selects the chunk kind by its type.  With
    ``adapt_tol`` > 0 the transient is adaptive (``core._adapt_check``, periods up to
    ``max_period``): each lane has its own transient length ``tend`` and recorded length ``rlen``,
    and a converged lane is freed (and refilled) as soon as it has recorded its cycle.
    """
    L = LANES
    P = order.shape[0]
    H1 = coef.shape[2]
    S = _aligned_zeros(NFIELDS * L)
    CF = _aligned_zeros(3 * H1 * 2 * L if H1 > 2 else 0)  # the general kind's coefficients (see _lanes_kind)
    # per lane: its point (-1: idle), step in the period, steps per period, periods done, transient and
    # recorded periods, cycle found (rows of one array, so that a lane moves as one column)
    ls = np.zeros((7, L), dtype=np.int64)
    pid, kstep, nst, per, tend, rlen, cyc = ls[0], ls[1], ls[2], ls[3], ls[4], ls[5], ls[6]
    adaptive = adapt_tol > 0.0 and max_period > 0
    mp = max_period if adaptive else 0
    ring = np.zeros((L, 2 * mp + 1, 2))
    streak = np.zeros((L, mp + 1), dtype=np.int64)
    cbuf = np.zeros((L, max(mp, 1), 2))
    snap = np.zeros((L, NSNAP))
    exhausted = False
    active = 0
    for l in range(L):
        _lane_idle(S, CF, ls, l)
    while True:
        # fill idle lanes from the queue
        for l in range(L):
            while pid[l] < 0 and not exhausted:
                i = _fetch_add(counter, 1)
                if i >= P:
                    exhausted = True
                    break
                p = order[i]
                _lane_load(S, CF, l, coef[p], D[p], omega[p], nsteps[p], state0[p, 0], state0[p, 1])
                pid[l] = p  # (step, periods done and cycle: 0 since the lane went idle)
                nst[l] = nsteps[p]
                tend[l] = n_transient
                rlen[l] = n_record
                if adaptive:
                    _adapt_reset(ring, streak, l, state0[p, 0], state0[p, 1])
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
                        S[dst::L] = S[l::L]  # every field of the lane
                        CF[dst::L] = CF[l::L]
                        ls[:, dst] = ls[:, l]
                        if adaptive:
                            ring[dst] = ring[l]
                            streak[dst] = streak[l]
                            cbuf[dst] = cbuf[l]
                            snap[dst] = snap[l]
                        _lane_idle(S, CF, ls, l)
                    dst += 1
            ng = (active + GROUP - 1) // GROUP
        m = nst[0] - kstep[0]  # (not the literal _BIG: keeps the chunk kernels' m an int64)
        rec = False
        for l in range(L):
            if pid[l] >= 0:
                m = min(m, nst[l] - kstep[l])
                if per[l] >= tend[l]:
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
                if done <= tend[l]:  # (diverged in its transient: no statistics)
                    _lane_reset_stats(S, l)
                _write_stats(stats, p, N * max(done - tend[l], 0), S[F_UMIN * L + l :: L])
                _lane_idle(S, CF, ls, l)
                active -= 1
                continue
            if adaptive and cyc[l] == 0 and done < tend[l]:
                nc = _adapt_check(ring, streak, l, done, u, v, adapt_tol)
                if nc > 0:
                    # stop at a period count congruent to n_transient mod nc: the record then starts
                    # at the same phase of the cycle as the fixed-transient run's
                    cyc[l] = nc
                    tend[l] = min(tend[l], done + (n_transient - done) % nc)
                    if tangent == TAN_NONE and nc < n_record:
                        rlen[l] = nc
            te = tend[l]
            if done > te:
                j = done - 1 - te
                if poincare.shape[1] > 0:
                    poincare[p, j, 0] = u
                    poincare[p, j, 1] = v
                if rlen[l] < n_record:
                    cbuf[l, j, 0] = u
                    cbuf[l, j, 1] = v
                    if j + 1 == n_record % rlen[l]:
                        snap[l] = S[F_UMIN * L + l :: L][:NSNAP]  # the fields UMIN … NBCK, in order
                if tangent == TAN_LYAPUNOV:
                    y = (S[F_Y00 * L + l], S[F_Y10 * L + l], S[F_Y01 * L + l], S[F_Y11 * L + l])
                    (
                        S[F_Y00 * L + l],
                        S[F_Y10 * L + l],
                        S[F_Y01 * L + l],
                        S[F_Y11 * L + l],
                        tan_log[p, j, 0],
                        tan_log[p, j, 1],
                    ) = _gs(*y)
            else:
                # a transient period ended: discard what the chunks accumulated for this lane
                _lane_reset_stats(S, l)
                _lane_reset_tangent(S, l)
            if done == te + rlen[l]:
                end_state[p, 0] = u
                end_state[p, 1] = v
                _write_stats(stats, p, N * n_record, S[F_UMIN * L + l :: L])
                if rlen[l] < n_record:
                    _adapt_finish(p, l, rlen[l], n_record, N, cbuf, snap, poincare, end_state, stats)
                if tangent != TAN_NONE:
                    for i in range(4):  # Y00, Y10, Y01, Y11
                        tan_out[p, i % 2, i // 2] = S[(F_Y00 + i) * L + l]
                status[p] = ST_OK
                _lane_idle(S, CF, ls, l)
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


_KIND_DTYPES = {KIND_COS: np.int8, KIND_SIN: np.int16, KIND_GEN: np.int32}
#: Type tokens selecting the chunk kind (dtype) and register width (number of dimensions) at compile
#: time: the lanes worker is compiled (and cached) separately per kind and width, and only for those
#: a program uses.
_TOKENS = {
    (kind, width): np.empty((0,) * _NDIM_OF_WIDTH[width], dt)
    for kind, dt in _KIND_DTYPES.items()
    for width in _NDIM_OF_WIDTH
}


def native_simd_width() -> int:
    """512 where the CPU numba compiles for has AVX-512 (F, DQ and VL: the host as LLVM sees it, or
    ``NUMBA_CPU_FEATURES`` when set), else 256."""
    import numba
    from llvmlite import binding as llvm

    want = ("avx512f", "avx512dq", "avx512vl")
    if numba.config.CPU_FEATURES:
        given = set(numba.config.CPU_FEATURES.replace(" ", "").split(","))
        return 512 if all(f"+{f}" in given for f in want) else 256
    try:
        feats = llvm.get_host_cpu_features()
    except RuntimeError:
        return 256
    return 512 if all(feats.get(f, False) for f in want) else 256


#: Environment variable forcing the register width of the lanes: ``512``, ``256`` or ``0`` (no
#: explicit vectors: the compiler-vectorised loops).  Unset: :func:`native_simd_width`.
SIMD_ENV = "GEARDYN_SIMD_WIDTH"


def _width_from_env() -> int:
    v = os.environ.get(SIMD_ENV, "").strip()
    if not v:
        return native_simd_width()
    if v not in ("0", "256", "512"):
        raise ValueError(f"{SIMD_ENV}={v!r}: expected 512, 256 or 0")
    return int(v)


_simd_width = _width_from_env()


def simd_width() -> int:
    """Register width of the lanes' explicit vectors in this process (0: compiler-vectorised loops)."""
    return _simd_width


def _set_simd_width(width: int) -> int:
    """Set the register width of the lanes (512, 256 or 0); returns the previous one.  Every width
    gives the same bits; this only selects the code that runs (and is compiled)."""
    global _simd_width
    if width not in _NDIM_OF_WIDTH:
        raise ValueError(f"SIMD width {width!r}: expected 512, 256 or 0")
    old, _simd_width = _simd_width, int(width)
    return old


def _kind_token(kind: int) -> np.ndarray:
    """The type token of the lanes worker for ``kind`` at the current width."""
    return _TOKENS[(kind, _simd_width)]
