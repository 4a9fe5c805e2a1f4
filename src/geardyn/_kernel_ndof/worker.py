"""The N-DOF worker: one parameter point at a time from a shared queue (nogil, compiled once, cached).

A batch of one block of rows (n <= LANE_BLOCK, ``dense``) takes the plain step on dense matrices
(:mod:`geardyn._kernel_ndof.dense`), any other the sparse one; both give the same numbers.

Per point: the derived matrices are given by the caller; in the default mode the coefficients of
one forcing period are tabulated at the 2N + 1 half-step angles (the forcing is periodic in that
period, so the table serves every period: no trigonometric call in the step loop); the accurate
mode evaluates them where its split sub-steps need them; so are the torque orders' cosines (the load g(θ) of every
stage, :func:`geardyn._kernel_ndof.step.load_at`).  Periods without tangents in the default
mode run the plain step (:func:`geardyn._kernel_ndof.step.rk4_plain`) on the padded state (with a margin of
zeros either side for the blocks' diagonals), copied from and back to the state at the period's start and end; its
element forces and statistics take the period's coefficients transposed into element groups
(:func:`geardyn._kernel_ndof.step.element_table`).  A thread keeps the tables of the last point it tabulated and
uses them again for a point whose table inputs are the same bit for bit (:func:`_same_table`: the points of a basin
grid, or other initial states of one model), so they are the numbers a new tabulation would give.  The stroboscopic
samples are exact: h = T_f/N with T_f the forcing period.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._kernel.core import _fetch_add
from .core import (
    LOCK_FREE,
    NSTAT,
    ST_DIVERGED,
    ST_OK,
    TAN_LYAPUNOV,
    TAN_NONE,
    accumulate,
    coef_at,
    diverged_state,
    element_values,
    gram_schmidt,
)
from .dense import element_values_dense, pad_dense, rk4_plain_dense
from .simd import LANE_BLOCK
from .step import (
    XQ,
    XROWS,
    XV,
    _copy,
    accurate_step,
    aligned_zeros,
    element_table,
    order_cosines,
    pad_point,
    rk4,
    rk4_plain,
    rk4_plain_tan,
    state_rows,
    values_vec,
)


@njit(nogil=True)
def _store_hist(hist, p, s, q, v, vo):
    """History sample s (if s >= 0) of point p: (q̃, q̃') = (q[0:n], v[vo:vo+n])."""
    if s >= 0:
        n = hist.shape[2] // 2
        for i in range(n):
            hist[p, s, i] = q[i]
            hist[p, s, n + i] = v[vo + i]


@njit(nogil=True, inline="always")
def _same(x, y):
    """x and y are the same number bit for bit (a zero's sign counted; a NaN never the same)."""
    return x == y and math.copysign(1.0, x) == math.copysign(1.0, y)


@njit(nogil=True)
def _same_rows(a, p, q):
    """Rows p and q of ``a`` hold the same numbers bit for bit (a zero's sign counted; a NaN never the same)."""
    for x, y in zip(a[p].flat, a[q].flat):
        if not _same(x, y):
            return False
    return True


@njit(nogil=True)
def _same_table(p, q, coef, ratio, omega, tperiod, nsteps, ro, po, kc, cc, D, Dc):
    """Points p and q have the same inputs of the default mode's tables (module docstring): the coefficient rows,
    the ratios, ω, the step h = T_f/N, the orders' rates and phases, the clearances' kc, cc and the gaps D, Dc;
    the tables of q then serve p as they are (the same numbers as tabulating them again)."""
    if nsteps[p] != nsteps[q] or not (_same(omega[p], omega[q]) and _same(tperiod[p], tperiod[q])):
        return False
    if not (_same_rows(ratio, p, q) and _same_rows(ro, p, q) and _same_rows(po, p, q)):
        return False
    if not (_same_rows(kc, p, q) and _same_rows(cc, p, q) and _same_rows(D, p, q) and _same_rows(Dc, p, q)):
        return False
    return _same_rows(coef, p, q)


@njit(nogil=True)
def _quotient(Y, R):
    """Y −= R (Rᵀ Y): the tangent columns modulo the invariant rigid-body subspace (orthonormal columns R, (d, r);
    r = 0: nothing), so that the leading exponents are the elastic ones, not the secular drift of a free rotation."""
    for c in range(Y.shape[1]):
        for b in range(R.shape[1]):
            r = 0.0
            for i in range(Y.shape[0]):
                r += R[i, b] * Y[i, c]
            for i in range(Y.shape[0]):
                Y[i, c] -= r * R[i, b]


@njit(nogil=True)
def _period_sparse(R, pc, blk, sp, el, ld, bear, ef, evs, T):
    """N plain steps on the padded state R (:func:`.step.state_rows`), ``pc = (sf, h, tab, N, om, rec, st, ev,
    gaps, hist, p, b0)`` (statistics when ``rec``, ``evs`` their workspace; history samples b0 + j); the loads
    ``ld``; the element groups ``ef``; a few tangent columns ``T`` (:func:`.step.rk4_plain_tan`; None: none)."""
    sf, h, tab, N, om, rec, st, ev, gaps, hist, p, b0 = pc
    q = R[0]
    v = R[1]
    for j in range(N):
        if T is None:
            rk4_plain(R, sf, h, tab, j, blk, sp, el, om, ld, bear, ef)
        else:
            Y, wt, gk, gc, sw = T
            rk4_plain_tan(R, sf, h, tab, j, blk, sp, el, om, Y, wt, gk, gc, ld, bear, ef, sw)
        if rec:
            if T is None:
                values_vec(q, v, 2 * j + 2, ef, sp, el, ev, evs)
            else:
                element_values(q, v, 0, tab[2 * j + 2], sp, el, om, ev)
            accumulate(st, ev, gaps)
        if hist.shape[1] > 0:
            _store_hist(hist, p, b0 + j, q, v, 0)


@njit(nogil=True)
def _period_dense(X, pc, dm, ld):
    """:func:`_period_sparse` on dense matrices ``dm`` (:func:`.dense.rk4_plain_dense`)."""
    sf, h, tab, N, om, rec, st, ev, gaps, hist, p, b0 = pc
    q = X[XQ]
    v = X[XV]
    for j in range(N):
        rk4_plain_dense(X, sf, h, tab, j, dm, om, ld)
        if rec:
            element_values_dense(q, v, 0, tab[2 * j + 2], dm[4], dm[6], om, ev)
            accumulate(st, ev, gaps)
        if hist.shape[1] > 0:
            _store_hist(hist, p, b0 + j, q, v, 0)


@njit(nogil=True, cache=True)
def ndof_worker(
    order,
    counter,
    abp,
    abj,
    Av,
    Bv,
    ep,
    ej,
    Ev,
    wp,
    wi,
    Wv,
    g,
    gp,
    gj,
    Ag,
    Bg,
    cp,
    ce,
    cw,
    cv,
    bcp,
    bcj,
    ATs,
    BTs,
    bep,
    bej,
    WTs,
    gPs,
    EI,
    EVs,
    margin,
    dense,
    Ad,
    Bd,
    Wd,
    Wcd,
    Vd,
    Vcd,
    coef,
    D,
    ratio,
    kc,
    cc,
    Dc,
    omega,
    bq,
    go,
    ro,
    po,
    tperiod,
    nsteps,
    state0,
    n_transient,
    n_record,
    tangent,
    ntan,
    tangent0,
    rigid,
    accurate,
    poincare,
    end_state,
    stats,
    tan_log,
    tan_out,
    status,
    hist,
):
    P = order.shape[0]
    d = state0.shape[1]
    n = d // 2
    M = D.shape[1]
    C = Dc.shape[1]
    NB = bq.shape[1]
    E = M + C + 2 * NB  # element rows: meshes, clearances, then two per rolling bearing
    ktan = ntan if tangent != TAN_NONE else 0
    x = np.empty(d)
    xo = np.empty(d)
    wk = np.empty((6, d))
    wt = np.empty((5, d, max(ktan, 1)))
    Y = np.zeros((d, max(ktan, 1)))
    Ysave = np.zeros((d, max(ktan, 1)))
    Gq = np.empty(max(gj.shape[0], 1))
    Gv = np.empty(max(gj.shape[0], 1))
    gk = np.empty(max(E + 2 * NB, 1))  # a slope per element row, then two cross slots per bearing (.core)
    gc = np.empty(max(E + 2 * NB, 1))
    ev = np.empty((E, 2))
    g0 = np.empty(E)  # the accurate step's distances at a sub-step's start
    cfa = np.empty((4, M + NB, 4))
    mode = np.full(E, LOCK_FREE, dtype=np.int64)
    logs = np.empty(max(ktan, 1))
    st = np.zeros((E, NSTAT))
    hl = hist.shape[1]
    NP = gPs.shape[1]
    X = aligned_zeros(XROWS, NP)
    AT = aligned_zeros(max(bcj.shape[0], 1), LANE_BLOCK)
    BT = aligned_zeros(max(bcj.shape[0], 1), LANE_BLOCK)
    WT = aligned_zeros(max(bej.shape[0], 1), LANE_BLOCK)
    gP = aligned_zeros(1, NP)[0]
    Xs = aligned_zeros(XROWS, NP + 2 * margin)  # the sparse step's rows, a margin of zeros either side
    R = state_rows(Xs, margin, NP)
    EP = EI.shape[0] * LANE_BLOCK
    Dp = aligned_zeros(1, max(EP, 1))[0]
    sf = aligned_zeros(1, max(E, EP, 1))[0]
    evs = aligned_zeros(2, max(EP, 1))  # the statistics' samples of the element groups
    gks = aligned_zeros(2, max(EP, 1))  # their slopes (the tangent step)
    sw = (gks[0], gks[1])
    nd = n if dense else 0
    ATd = aligned_zeros(max(nd, 1), NP)
    BTd = aligned_zeros(max(nd, 1), NP)
    WTd = aligned_zeros(max(E if dense else 0, 1), NP)
    O = go.shape[1]
    gw = np.empty(n)  # the load g(θ) the full step's stages read (sp's g)
    ocs = np.empty((3, O))  # the accurate mode's cos(r_o θ + φ_o) at a step's three times
    tab = np.empty((0, M + NB, 4))
    TB = np.empty((0, 6, EP))
    otab = ocs
    last = -1  # the point whose inputs the tables tab, otab, TB, Dp hold (-1: none yet)
    while True:
        k = _fetch_add(counter, 1)
        if k >= P:
            break
        p = order[k]
        N = nsteps[p]
        Tf = tperiod[p]
        h = Tf / N
        om = omega[p]
        _copy(gw, g[p])
        sp = (abp, abj, Av[p], Bv[p], ep, ej, Ev[p], wp, wi, Wv[p], gw)
        el = (M, D[p], kc[p], cc[p], Dc[p], bq[p])
        jt = (gp, gj, Ag[p], Bg[p], cp, ce, cw, cv)
        jw = (jt, Gq, Gv)
        blk = pad_point(p, bcp, bcj, ATs, BTs, bep, bej, WTs, gPs, AT, BT, WT, gP)
        if dense:
            pad_dense(Ad[p], Bd[p], g[p], Wd[p], Wcd[p], ATd, BTd, gP, WTd)
        gaps = np.zeros(E)
        _copy(gaps[:M], D[p])
        _copy(gaps[M : M + C], Dc[p])
        # the accurate mode splits no step at a bearing (its force is C¹ at contact): a gap 0 never switches
        agaps = gaps.copy()
        for b in range(NB):
            gaps[M + C + 2 * b : M + C + 2 * b + 2] = bq[p, b, 3]
        if accurate:
            tab = np.empty((0, M + NB, 4))
            TB = np.empty((0, 6, EP))
            otab = ocs
        elif last < 0 or not _same_table(p, last, coef, ratio, omega, tperiod, nsteps, ro, po, kc, cc, D, Dc):
            tab = np.empty((2 * N + 1, M + NB, 4))
            otab = np.empty((2 * N + 1, O))
            for i in range(2 * N + 1):
                coef_at(coef[p], ratio[p], om * (0.5 * h * i), tab[i])
                order_cosines(ro[p], po[p], om * (0.5 * h * i), otab, i)
            TB = np.empty((2 * N + 1, 6, EP))
            element_table(tab, M, kc[p], cc[p], D[p], Dc[p], om, TB, Dp)
            last = p
        ef = (EI, EVs[p], TB, Dp)
        ld = (g[p], go[p], otab)  # the loads at the table's times (module docstring of .step)
        lds = ((g[p], go[p], ocs), ro[p], po[p])  # the accurate mode's
        _copy(x, state0[p])
        st[:, :] = 0.0
        _copy(Y[:, :ktan], tangent0[p])
        bad = False
        total = n_transient + n_record
        hstart = total * N - (hl - 1)
        if hl > 0:
            hist[p, 0] = 0.0
            if hstart == 0:
                hist[p, 0] = x
        for per in range(total):
            rec = per >= n_transient
            tan_on = rec and ktan > 0
            if not accurate and (not tan_on or ktan < d):
                # the plain step on the padded state (padding zero); a few tangent columns alongside
                pc = (sf, h, tab, N, om, rec, st, ev, gaps, hist, p, per * N + 1 - hstart)
                dn = dense and not tan_on
                Z = X if dn else Xs
                z0 = 0 if dn else margin
                Z[:, :] = 0.0
                for i in range(n):
                    Z[XQ, z0 + i] = x[i]
                    Z[XV, z0 + i] = x[n + i]
                if dn:
                    dm = (ATd, BTd, gP, WTd, Vd[p], D[p], Vcd[p], kc[p], cc[p], Dc[p])
                    if O > 0:
                        _period_dense(X, pc, dm, ld)
                    else:  # no orders: the step compiled without the load's refill
                        _period_dense(X, pc, dm, None)
                else:
                    # bearings: the step compiled with their code; without, given None, compiled without it (.core)
                    T = (Y, wt, gk, gc, sw)
                    if tan_on and NB > 0:
                        _period_sparse(R, pc, blk, sp, el, ld, bq, ef, evs, T)
                    elif tan_on:
                        _period_sparse(R, pc, blk, sp, el, ld, None, ef, evs, T)
                    elif NB > 0:
                        _period_sparse(R, pc, blk, sp, el, ld, bq, ef, evs, None)
                    else:
                        _period_sparse(R, pc, blk, sp, el, ld, None, ef, evs, None)
                for i in range(n):
                    x[i] = Z[XQ, z0 + i]
                    x[n + i] = Z[XV, z0 + i]
            else:
                for j in range(N):
                    if accurate:
                        accurate_step(
                            x,
                            j * h,
                            h,
                            coef[p],
                            ratio[p],
                            om,
                            sp,
                            el,
                            agaps,
                            mode,
                            xo,
                            cfa,
                            wk,
                            wt,
                            gk,
                            gc,
                            jw,
                            tan_on,
                            Y,
                            Ysave,
                            ev,
                            g0,
                            lds,
                        )
                    else:
                        rk4(
                            x,
                            h,
                            tab[2 * j],
                            tab[2 * j + 1],
                            tab[2 * j + 2],
                            sp,
                            el,
                            om,
                            mode,
                            tan_on,
                            Y,
                            wk,
                            wt,
                            gk,
                            gc,
                            jw,
                            ld,
                            2 * j,
                        )
                    if rec:
                        if accurate:
                            coef_at(coef[p], ratio[p], om * ((j + 1) * h), cfa[3])
                            element_values(x, x, n, cfa[3], sp, el, om, ev)
                        else:
                            element_values(x, x, n, tab[2 * j + 2], sp, el, om, ev)
                        accumulate(st, ev, gaps)
                    if hl > 0:
                        _store_hist(hist, p, per * N + j + 1 - hstart, x, x, n)
            if diverged_state(x):
                bad = True
                break
            if rec:
                r = per - n_transient
                if poincare.shape[1] > 0:
                    _copy(poincare[p, r], x)
                if tangent == TAN_LYAPUNOV:
                    _quotient(Y, rigid)
                    gram_schmidt(Y, logs)
                    _copy(tan_log[p, r], logs[:ktan])
        _copy(stats[p], st)
        if bad:
            status[p] = ST_DIVERGED
            poincare[p] = np.nan
            end_state[p] = np.nan
        else:
            status[p] = ST_OK
            _copy(end_state[p], x)
        if tangent != TAN_NONE:
            _copy(tan_out[p], Y[:, :ktan])
