"""One RK4 step of the state (and of the tangent columns), and the accurate mode's split steps.

A step uses the coefficients at its start, midpoint and end (``cf0, cf1, cf2``, each (meshes, 4));
the tangent columns are advanced with the Jacobian at each stage's state (so that in the default
mode they are the exact derivative of the discrete map).  The accurate mode locks every element
to the branch of its dead zone at the sub-step start, takes the step, and where an element's
contact boundary (δ = ±D, E_m(θ) included for meshes) is crossed inside it, finds the crossing
length by a safeguarded secant (Illinois) iteration on the locked step and splits the step there;
the vector field is continuous, so the split keeps RK4 fourth order and no saltation is needed.
A rolling bearing (:mod:`.core`'s second law) is treated as smooth: its force K Σ max(δ_j, 0)^n is C¹ at each
element's contact for n > 1, so it is never locked and never splits a step (the worker gives its rows a gap of 0
here, which :func:`_regions` and :func:`_gfun` take as always in contact and never crossing; its force ignores the
mode).  Its order at a contact is then that of the law's smoothness (n = 3/2: RK4 converges as usual in the
tests; n = 10/9: about order 2.7).
:func:`rk4_plain` is the default mode's step without tangents on the padded layout of
:mod:`geardyn._kernel_ndof.simd` (:func:`pad_point` prepares a point's matrices).

Torque orders: every step takes ``ld = (gb, go, ct)``, the constant load row gb = M̃⁻¹F̃, the orders' rows go
(orders, n) and a table ct of cos(r_o θ + φ_o) at the stage times; :func:`load_at` writes
g(θ) = gb + Σ_o ct[r, o] go[o] into the load the stage reads (g of ``sp``, or the padded gP of the plain step)
before the stages at a new time.  Without orders it writes nothing: g keeps its value, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .core import (
    _bearing_forces,
    _bearing_slots,
    coef_at,
    element_values,
    field,
    jac_values,
    slopes,
    tan_field,
    tan_free,
)
from .simd import LANE_BLOCK, final_block, forces_group, forces_slopes_group, stage_block, values_group

#: Largest number of sub-steps one step is split into (accurate mode).
MAX_SPLITS = 64
#: Hermite samples inside a sub-step checked for a double crossing (grazing).
HERMITE_SAMPLES = 4
#: Iterations of the crossing search.
ROOT_ITERS = 60
#: Crossings are located to this fraction of the step.
CROSSING_TOL = 1e-13


@njit(nogil=True, inline="always")
def load_at(dst, ld, r):
    """dst[0:n] = gb + Σ_o ct[r, o] go[o] of ``ld = (gb, go, ct)``: the load at the time of row r of ct; without
    orders nothing is written (``ld`` None: the caller compiles without the refill)."""
    if ld is None:
        return
    gb, go, ct = ld
    O = go.shape[0]
    if O == 0:
        return
    for i in range(gb.shape[0]):
        acc = gb[i]
        for o in range(O):
            acc += ct[r, o] * go[o, i]
        dst[i] = acc


@njit(nogil=True)
def order_cosines(ro, po, theta, ct, r):
    """ct[r, o] = cos(ro[o] θ + po[o]) of every order."""
    for o in range(ro.shape[0]):
        ct[r, o] = math.cos(ro[o] * theta + po[o])


@njit(nogil=True)
def rk4(x, h, cf0, cf1, cf2, sp, el, omega, mode, tangent, Y, wk, wt, gk, gc, jw, ld, r):
    """Advance x (and the columns Y when ``tangent``) by one RK4 step of length h, in place.

    wk : (6, 2n) workspace (k1..k4, stage state, start state); wt : (5, 2n, k) tangent workspace;
    gk, gc : (elements,) workspace (the element slopes); ``jw = (jt, Gq, Gv)`` the Jacobian's pattern and its
    values (workspace);
    ``ld`` the loads (module docstring), rows r, r + 1, r + 2 of its table at the start, midpoint and end.
    """
    jt, Gq, Gv = jw
    d = x.shape[0]
    hh = 0.5 * h
    h6 = h / 6.0
    k1 = wk[0]
    k2 = wk[1]
    k3 = wk[2]
    k4 = wk[3]
    xs = wk[4]
    g = sp[10]
    load_at(g, ld, r)
    field(x, cf0, sp, el, omega, mode, k1)
    if tangent:
        slopes(x, cf0, sp, el, mode, gk, gc)
        jac_values(sp, jt, gk, gc, Gq, Gv)
        tan_field(Y, jt, Gq, Gv, wt[0])
    for i in range(d):
        xs[i] = x[i] + hh * k1[i]
    load_at(g, ld, r + 1)
    field(xs, cf1, sp, el, omega, mode, k2)
    if tangent:
        slopes(xs, cf1, sp, el, mode, gk, gc)
        jac_values(sp, jt, gk, gc, Gq, Gv)
        Ys = wt[4]
        for i in range(d):
            for c in range(Y.shape[1]):
                Ys[i, c] = Y[i, c] + hh * wt[0][i, c]
        tan_field(Ys, jt, Gq, Gv, wt[1])
    for i in range(d):
        xs[i] = x[i] + hh * k2[i]
    field(xs, cf1, sp, el, omega, mode, k3)
    if tangent:
        slopes(xs, cf1, sp, el, mode, gk, gc)
        jac_values(sp, jt, gk, gc, Gq, Gv)
        Ys = wt[4]
        for i in range(d):
            for c in range(Y.shape[1]):
                Ys[i, c] = Y[i, c] + hh * wt[1][i, c]
        tan_field(Ys, jt, Gq, Gv, wt[2])
    for i in range(d):
        xs[i] = x[i] + h * k3[i]
    load_at(g, ld, r + 2)
    field(xs, cf2, sp, el, omega, mode, k4)
    if tangent:
        slopes(xs, cf2, sp, el, mode, gk, gc)
        jac_values(sp, jt, gk, gc, Gq, Gv)
        Ys = wt[4]
        for i in range(d):
            for c in range(Y.shape[1]):
                Ys[i, c] = Y[i, c] + h * wt[2][i, c]
        tan_field(Ys, jt, Gq, Gv, wt[3])
        for i in range(d):
            for c in range(Y.shape[1]):
                Y[i, c] += h6 * (wt[0][i, c] + 2.0 * wt[1][i, c] + 2.0 * wt[2][i, c] + wt[3][i, c])
    for i in range(d):
        x[i] += h6 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


# ----------------------------------------------------------------------------- accurate mode
@njit(nogil=True)
def _regions(ev, gaps, mode):
    """Branch of every element from its (δ, δ'); on a boundary the side δ' moves into."""
    for e in range(ev.shape[0]):
        d = ev[e, 0]
        D = gaps[e]
        if D == 0.0:
            mode[e] = 1
        elif d > D or (d == D and ev[e, 1] > 0.0):
            mode[e] = 1
        elif d < -D or (d == -D and ev[e, 1] < 0.0):
            mode[e] = -1
        else:
            mode[e] = 0


@njit(nogil=True)
def _gfun(d, D, m):
    """Distance inside the locked branch m (negative once δ has left it)."""
    if D == 0.0:
        return 1.0
    if m == 1:
        return d - D
    if m == -1:
        return -D - d
    return min(D - d, d + D)


@njit(nogil=True)
def _copy(dst, src):
    """dst = src, element by element (arrays of one shape, any layout)."""
    for i, v in np.ndenumerate(src):
        dst[i] = v


@njit(nogil=True)
def _locked(x0, t, s, coef, ratio, omega, sp, el, mode, xo, cfa, wk, wt, gk, gc, jt, tangent, Y, lds):
    """xo = locked RK4 step of length s from x0 at time t (Y advanced when ``tangent``); ``lds = (ld, ro, po)``
    the loads (their table ct the rows of this step's three times)."""
    for i in range(x0.shape[0]):
        xo[i] = x0[i]
    coef_at(coef, ratio, omega * t, cfa[0])
    coef_at(coef, ratio, omega * (t + 0.5 * s), cfa[1])
    coef_at(coef, ratio, omega * (t + s), cfa[2])
    ld, ro, po = lds
    ct = ld[2]
    order_cosines(ro, po, omega * t, ct, 0)
    order_cosines(ro, po, omega * (t + 0.5 * s), ct, 1)
    order_cosines(ro, po, omega * (t + s), ct, 2)
    rk4(xo, s, cfa[0], cfa[1], cfa[2], sp, el, omega, mode, tangent, Y, wk, wt, gk, gc, jt, ld, 0)


@njit(nogil=True)
def _worst(x, t, coef, ratio, omega, sp, el, gaps, mode, cfa, ev, g0):
    """Smallest locked-branch distance at state x, time t, over the elements off their boundary at the sub-step's
    start (``g0[e] > 0``: their distance there), and its element."""
    coef_at(coef, ratio, omega * t, cfa[3])
    element_values(x, x, sp[10].shape[0], cfa[3], sp, el, omega, ev)
    best = np.inf
    who = -1
    for e in range(ev.shape[0]):
        if g0[e] <= 0.0:
            continue
        gv = _gfun(ev[e, 0], gaps[e], mode[e])
        if gv < best:
            best = gv
            who = e
    return best, who


@njit(nogil=True)
def accurate_step(
    x,
    t,
    h,
    coef,
    ratio,
    omega,
    sp,
    el,
    gaps,
    mode,
    xo,
    cfa,
    wk,
    wt,
    gk,
    gc,
    jt,
    tangent,
    Y,
    Ysave,
    ev,
    g0,
    lds,
):
    """Advance x (and Y) by one step of length h split at every contact-boundary crossing.

    ``jt`` is (the Jacobian's pattern, its values Gq, Gv) of :func:`rk4`; ``lds`` the loads of :func:`_locked`;
    ``g0`` (elements,) workspace: each element's locked-branch distance at the sub-step's start.

    An element found exactly on its boundary at a sub-step's start (the previous split put it there, or it sits
    there to rounding) is locked to the branch it moves into and takes no part in that sub-step's search: its
    distance, zero at the start, would otherwise make s = 0 a root of the smallest distance, and the search, its
    secant degenerate there, could end on a split of rounding length that advances nothing; repeated up to
    MAX_SPLITS times, the step was then finished unsplit, past the crossing of another element inside it."""
    d = x.shape[0]
    rem = h
    tt = t
    for _split in range(MAX_SPLITS):
        coef_at(coef, ratio, omega * tt, cfa[3])
        element_values(x, x, sp[10].shape[0], cfa[3], sp, el, omega, ev)
        _regions(ev, gaps, mode)
        for e in range(ev.shape[0]):
            g0[e] = _gfun(ev[e, 0], gaps[e], mode[e])
        if tangent:
            for i in range(d):
                for c in range(Y.shape[1]):
                    Ysave[i, c] = Y[i, c]
        _locked(
            x,
            tt,
            rem,
            coef,
            ratio,
            omega,
            sp,
            el,
            mode,
            xo,
            cfa,
            wk,
            wt,
            gk,
            gc,
            jt,
            tangent,
            Y,
            lds,
        )
        gend, _w = _worst(xo, tt + rem, coef, ratio, omega, sp, el, gaps, mode, cfa, ev, g0)
        hi = rem
        ghi = gend
        if gend >= 0.0:
            # a crossing out and back inside the sub-step: check a few locked sub-lengths
            for k in range(1, HERMITE_SAMPLES + 1):
                sk = rem * k / (HERMITE_SAMPLES + 1)
                _locked(
                    x,
                    tt,
                    sk,
                    coef,
                    ratio,
                    omega,
                    sp,
                    el,
                    mode,
                    wk[5],
                    cfa,
                    wk,
                    wt,
                    gk,
                    gc,
                    jt,
                    False,
                    Y,
                    lds,
                )
                gsk, _w = _worst(wk[5], tt + sk, coef, ratio, omega, sp, el, gaps, mode, cfa, ev, g0)
                if gsk < 0.0:
                    hi = sk
                    ghi = gsk
                    break
        if ghi >= 0.0:
            for i in range(d):
                x[i] = xo[i]
            return
        # bracket [lo, hi] with g(lo) >= 0 > g(hi): Illinois
        lo = 0.0
        glo, _w = _worst(x, tt, coef, ratio, omega, sp, el, gaps, mode, cfa, ev, g0)
        if glo < 0.0:
            glo = 0.0
        side = 0
        for _it in range(ROOT_ITERS):
            if hi - lo <= CROSSING_TOL * h:
                break
            s = hi - ghi * (hi - lo) / (ghi - glo) if ghi != glo else 0.5 * (lo + hi)
            if not (s > lo and s < hi):
                s = 0.5 * (lo + hi)
            _locked(
                x,
                tt,
                s,
                coef,
                ratio,
                omega,
                sp,
                el,
                mode,
                wk[5],
                cfa,
                wk,
                wt,
                gk,
                gc,
                jt,
                False,
                Y,
                lds,
            )
            gs, _w = _worst(wk[5], tt + s, coef, ratio, omega, sp, el, gaps, mode, cfa, ev, g0)
            if gs == 0.0:
                lo = s
                hi = s
                break
            if gs > 0.0:
                lo = s
                glo = gs
                if side == 1:
                    ghi *= 0.5
                side = 1
            else:
                hi = s
                ghi = gs
                if side == -1:
                    glo *= 0.5
                side = -1
        s = hi
        if tangent:
            for i in range(d):
                for c in range(Y.shape[1]):
                    Y[i, c] = Ysave[i, c]
        _locked(
            x,
            tt,
            s,
            coef,
            ratio,
            omega,
            sp,
            el,
            mode,
            xo,
            cfa,
            wk,
            wt,
            gk,
            gc,
            jt,
            tangent,
            Y,
            lds,
        )
        for i in range(d):
            x[i] = xo[i]
        tt += s
        rem -= s
        if rem <= 0.0:
            return
    # split limit reached: finish the step unsplit
    coef_at(coef, ratio, omega * tt, cfa[3])
    element_values(x, x, sp[10].shape[0], cfa[3], sp, el, omega, ev)
    _regions(ev, gaps, mode)
    _locked(x, tt, rem, coef, ratio, omega, sp, el, mode, xo, cfa, wk, wt, gk, gc, jt, tangent, Y, lds)
    for i in range(d):
        x[i] = xo[i]


# ----------------------------------------------------------------------------- plain step (padded layout)
#: Rows of the plain step's workspace X (XROWS, NP): the state (q̃, q̃'), stage accelerations, stage states.
XQ, XV, XK1, XK2, XK3, XQ2, XV2, XQ3, XV3, XQ4, XV4 = range(11)
XROWS = 11


#: Byte alignment of the padded arrays: a block (LANE_BLOCK float64) is one cache line, and no SIMD
#: load or store straddles two lines.
ALIGN_BYTES = 64


@njit(nogil=True)
def aligned_zeros(rows, cols):
    """A zeroed float64 (rows, cols) array whose data start on an ALIGN_BYTES boundary."""
    raw = np.zeros(rows * cols + ALIGN_BYTES // 8)
    off = ((ALIGN_BYTES - raw.ctypes.data % ALIGN_BYTES) % ALIGN_BYTES) // 8
    return raw[off : off + rows * cols].reshape((rows, cols))


@njit(nogil=True)
def pad_point(p, bcp, bcj, ATs, BTs, bep, bej, WTs, gPs, AT, BT, WT, gP):
    """Copy point p's block-sparse matrices into the aligned buffers AT, BT (diagonals, LANE_BLOCK), WT, gP; the
    tuple of the plain step's block arrays."""
    _copy(AT[: bcj.shape[0]], ATs[p])
    _copy(BT[: bcj.shape[0]], BTs[p])
    _copy(WT[: bej.shape[0]], WTs[p])
    _copy(gP, gPs[p])
    return (bcp, bcj, AT, BT, bep, bej, WT, gP)


@njit(nogil=True, inline="always")
def state_rows(X, m, NP):
    """The plain step's rows (q, v, k1, k2, k3, q2, v2, q3, v3, q4, v4): X[r, m : m + NP], X (XROWS, NP + 2m)
    zero outside them (the ``margin`` m of the blocks' diagonals, :func:`geardyn._kernel_ndof.sparse_arrays`)."""
    e = m + NP
    return (
        X[XQ, m:e],
        X[XV, m:e],
        X[XK1, m:e],
        X[XK2, m:e],
        X[XK3, m:e],
        X[XQ2, m:e],
        X[XV2, m:e],
        X[XQ3, m:e],
        X[XV3, m:e],
        X[XQ4, m:e],
        X[XV4, m:e],
    )


@njit(nogil=True)
def element_table(tab, M, kc, cc, D, Dc, omega, TB, Dp):
    """The element groups' coefficients (:func:`.simd.forces_group`, :func:`.simd.values_group`): TB[i, 0:4, e] =
    tab[i, e, 0:4] of the meshes (C, K, E, E'), (cc, kc, 0, 0) of the clearances; TB[i, 4, e] = −E, TB[i, 5, e] =
    −ω E' of the meshes, +0 of the clearances (:func:`.core.element_values`' starting values); after them zero;
    Dp their half backlashes and gaps."""
    C = Dc.shape[0]
    TB[:, :, :] = 0.0
    Dp[:] = 0.0
    _copy(Dp[:M], D)
    _copy(Dp[M : M + C], Dc)
    for i in range(TB.shape[0]):
        for e in range(M):
            for c in range(4):
                TB[i, c, e] = tab[i, e, c]
            TB[i, 4, e] = -tab[i, e, 2]
            TB[i, 5, e] = -omega * tab[i, e, 3]
        for c in range(C):
            TB[i, 0, M + c] = cc[c]
            TB[i, 1, M + c] = kc[c]


@njit(nogil=True, inline="always")
def values_vec(q, v, r, ef, sp, el, ev, evs):
    """:func:`.core.element_values` (the same numbers) at (q̃, q̃') = (q[0:n], v[0:n]), table row r: the meshes and
    clearances L at a time (:func:`.simd.values_group`, through ``evs`` (2, groups·L)), then the rolling bearings'
    rows one by one."""
    EI, EV, TB, Dp = ef
    for G in range(EI.shape[0]):
        values_group(EI, EV, q, v, TB, r, evs, G)
    ep, ej, Ev = sp[4], sp[5], sp[6]
    e1 = el[0] + el[4].shape[0]
    for e in range(e1):
        ev[e, 0] = evs[0, e]
        ev[e, 1] = evs[1, e]
    for e in range(e1, ep.shape[0] - 1):
        d = 0.0
        dv = 0.0
        for k in range(ep[e], ep[e + 1]):
            j = ej[k]
            d += Ev[k] * q[j]
            dv += Ev[k] * v[j]
        ev[e, 0] = d
        ev[e, 1] = dv


@njit(nogil=True, inline="always")
def forces_vec(q, v, tab, r, ef, sp, el, omega, s, bear):
    """The element forces s[e] of :func:`.core.field` (default mode; the same numbers) at (q̃, q̃') = (q[0:n],
    v[0:n]), coefficients from row r of the table: the meshes and clearances L at a time
    (:func:`.simd.forces_group`; ``ef = (EI, EV, TB, Dp)``); then the rolling bearings' unless ``bear`` is None.
    A system without bearings is given None, so that its step compiles without the bearings' code: even untaken,
    that code made the plain step 3.5 times slower on a 48-DOF chain."""
    EI, EV, TB, Dp = ef
    for G in range(EI.shape[0]):
        forces_group(EI, EV, q, v, TB, r, Dp, omega, s, G)
    if bear is not None:
        _bearing_forces(sp, el, tab[r], q, v, s)


@njit(nogil=True, inline="always")
def _stages(blk, s, q, v, q0, v0, c, k, qn, vn):
    bcp, bcj, AT, BT, bep, bej, WT, gP = blk
    for b in range(bcp.shape[0] - 1):
        stage_block(
            AT,
            BT,
            bcj,
            bcp[b],
            bcp[b + 1],
            gP,
            WT,
            bej,
            bep[b],
            bep[b + 1],
            s,
            q,
            v,
            q0,
            v0,
            c,
            k,
            qn,
            vn,
            b * LANE_BLOCK,
        )


@njit(nogil=True, inline="always")
def _final(blk, s, q4, v4, q, v, h6, k1, k2, k3, v2, v3):
    """The last stage of every block at (q4, v4) and the RK4 update of (q, v) (:func:`.simd.final_block`)."""
    bcp, bcj, AT, BT, bep, bej, WT, gP = blk
    for b in range(bcp.shape[0] - 1):
        final_block(
            AT,
            BT,
            bcj,
            bcp[b],
            bcp[b + 1],
            gP,
            WT,
            bej,
            bep[b],
            bep[b + 1],
            s,
            q4,
            v4,
            q,
            v,
            h6,
            k1,
            k2,
            k3,
            v2,
            v3,
            b * LANE_BLOCK,
        )


@njit(nogil=True, inline="always")
def rk4_plain(R, s, h, tab, j, blk, sp, el, omega, ld, bear, ef):
    """One default-mode RK4 step without tangents (the hot loop) on the padded state R[0], R[1].

    R : the rows of :func:`state_rows` (NP values each, NP a multiple of LANE_BLOCK, the padding zero);
    s : (elements,) workspace; ``blk`` the point's block-sparse arrays (:func:`pad_point`), ``ef`` its element
    groups (:func:`forces_vec`).  Coefficients (and the loads ``ld``, into blk's gP) from the table rows 2j..2j+2;
    the arithmetic is :func:`rk4` with :func:`field`'s, operation by operation (see
    :mod:`geardyn._kernel_ndof.simd`), vectorised over blocks of rows and groups of elements.
    """
    hh = 0.5 * h
    h6 = h / 6.0
    q, v, k1, k2, k3, q2, v2, q3, v3, q4, v4 = R
    gP = blk[7]
    load_at(gP, ld, 2 * j)
    forces_vec(q, v, tab, 2 * j, ef, sp, el, omega, s, bear)
    _stages(blk, s, q, v, q, v, hh, k1, q2, v2)
    load_at(gP, ld, 2 * j + 1)
    forces_vec(q2, v2, tab, 2 * j + 1, ef, sp, el, omega, s, bear)
    _stages(blk, s, q2, v2, q, v, hh, k2, q3, v3)
    forces_vec(q3, v3, tab, 2 * j + 1, ef, sp, el, omega, s, bear)
    _stages(blk, s, q3, v3, q, v, h, k3, q4, v4)
    load_at(gP, ld, 2 * j + 2)
    forces_vec(q4, v4, tab, 2 * j + 2, ef, sp, el, omega, s, bear)
    _final(blk, s, q4, v4, q, v, h6, k1, k2, k3, v2, v3)


@njit(nogil=True, inline="always")
def _tan_stage(Y, Ys, c, Kp, sp, gk, gc, Kout):
    """Ys = Y + c Kp (c = 0: Y itself), then Kout = J Ys."""
    if c == 0.0:
        tan_free(Y, sp, gk, gc, Kout)
        return
    for i in range(Y.shape[0]):
        for k in range(Y.shape[1]):
            Ys[i, k] = Y[i, k] + c * Kp[i, k]
    tan_free(Ys, sp, gk, gc, Kout)


@njit(nogil=True, inline="always")
def forces_slopes_vec(q, v, tab, r, ef, sw, sp, el, omega, s, gk, gc, bear):
    """:func:`forces_vec` and the element slopes gk, gc of :func:`.core.slopes` (default mode; the same numbers) at
    the same state, the meshes and clearances L at a time
    (:func:`.simd.forces_slopes_group`, their slopes through ``sw = (gkv, gcv)``, (groups·L,) each); then the
    rolling bearings' forces and slopes unless ``bear`` is None."""
    EI, EV, TB, Dp = ef
    gkv, gcv = sw
    for G in range(EI.shape[0]):
        forces_slopes_group(EI, EV, q, v, TB, r, Dp, omega, s, gkv, gcv, G)
    for e in range(el[0] + el[4].shape[0]):
        gk[e] = gkv[e]
        gc[e] = gcv[e]
    if bear is not None:
        _bearing_forces(sp, el, tab[r], q, v, s)
        _bearing_slots(sp, el, tab[r], q, 0, gk, gc)


@njit(nogil=True)
def rk4_plain_tan(R, s, h, tab, j, blk, sp, el, omega, Y, wt, gk, gc, ld, bear, ef, sw):
    """:func:`rk4_plain` (the state, bit for bit) with a few tangent columns Y (2n, k) advanced by RK4 alongside,
    the Jacobian-vector products formed from the sparse rows (:func:`.core.tan_free`) at each stage's state; the
    element forces and slopes by groups (:func:`forces_slopes_vec`)."""
    hh = 0.5 * h
    h6 = h / 6.0
    q, v, k1, k2, k3, q2, v2, q3, v3, q4, v4 = R
    gP = blk[7]
    load_at(gP, ld, 2 * j)
    forces_slopes_vec(q, v, tab, 2 * j, ef, sw, sp, el, omega, s, gk, gc, bear)
    _tan_stage(Y, wt[4], 0.0, wt[0], sp, gk, gc, wt[0])
    _stages(blk, s, q, v, q, v, hh, k1, q2, v2)
    load_at(gP, ld, 2 * j + 1)
    forces_slopes_vec(q2, v2, tab, 2 * j + 1, ef, sw, sp, el, omega, s, gk, gc, bear)
    _tan_stage(Y, wt[4], hh, wt[0], sp, gk, gc, wt[1])
    _stages(blk, s, q2, v2, q, v, hh, k2, q3, v3)
    forces_slopes_vec(q3, v3, tab, 2 * j + 1, ef, sw, sp, el, omega, s, gk, gc, bear)
    _tan_stage(Y, wt[4], hh, wt[1], sp, gk, gc, wt[2])
    _stages(blk, s, q3, v3, q, v, h, k3, q4, v4)
    load_at(gP, ld, 2 * j + 2)
    forces_slopes_vec(q4, v4, tab, 2 * j + 2, ef, sw, sp, el, omega, s, gk, gc, bear)
    _tan_stage(Y, wt[4], h, wt[2], sp, gk, gc, wt[3])
    _final(blk, s, q4, v4, q, v, h6, k1, k2, k3, v2, v3)
    for i in range(Y.shape[0]):
        for k in range(Y.shape[1]):
            Y[i, k] += h6 * (wt[0][i, k] + 2.0 * wt[1][i, k] + 2.0 * wt[2][i, k] + wt[3][i, k])
