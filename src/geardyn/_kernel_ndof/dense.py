"""The plain step on dense matrices: the kernel's step for systems of one block of rows (n <= LANE_BLOCK), where
the sparse form saves no multiplications and its index lists would cost more than they save.

The same arithmetic as the sparse step, operation by operation (the sparse sums are these without their zero
terms): the transposed, padded matrices ``AT[j, i] = A[i, j]``, ``BT``, ``WT[e, i]`` (meshes, then clearances),
every column of a block (see :mod:`geardyn._kernel_ndof.simd`), and the element sums over every DOF.
"""

from __future__ import annotations

from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .core import _fz
from .simd import LANE_BLOCK, _block, _finish_final, _finish_stage, _ptr, _rows, _splat, _vload, _vty
from .step import load_at, state_rows


def _accel_dense(context, builder, tys, vals, i0):
    """The block's acceleration vector: g − Σ_j (AT[j] q_j + BT[j] v_j) − Σ_e WT[e] s_e."""
    (tA, tB, tg, tW, ts, tq, tv), (AT, BT, gP, WT, s, q, v) = tys, vals
    acc = cgutils.alloca_once(builder, _vty())
    builder.store(_vload(context, builder, tg, gP, [i0]), acc)
    with cgutils.for_range(builder, _rows(context, builder, tA, AT)) as loop:
        j = loop.index
        qj = _splat(builder, builder.load(_ptr(context, builder, tq, q, [j])))
        vj = _splat(builder, builder.load(_ptr(context, builder, tv, v, [j])))
        t = builder.fadd(
            builder.fmul(_vload(context, builder, tA, AT, [j, i0]), qj),
            builder.fmul(_vload(context, builder, tB, BT, [j, i0]), vj),
        )
        builder.store(builder.fsub(builder.load(acc), t), acc)
    with cgutils.for_range(builder, _rows(context, builder, tW, WT)) as loop:
        e = loop.index
        se = _splat(builder, builder.load(_ptr(context, builder, ts, s, [e])))
        builder.store(builder.fsub(builder.load(acc), builder.fmul(_vload(context, builder, tW, WT, [e, i0]), se)), acc)
    return builder.load(acc)


@intrinsic
def dense_stage_block(typingctx, AT, BT, gP, WT, s, q, v, q0, v0, c, k, qn, vn, i0):
    """Rows i0 … i0+LANE_BLOCK−1 of one stage at (q, v): k = acceleration, qn = q0 + c v, vn = v0 + c k."""
    return _block(types.void(AT, BT, gP, WT, s, q, v, q0, v0, c, k, qn, vn, i0), _accel_dense, 7, _finish_stage)


@intrinsic
def dense_final_block(typingctx, AT, BT, gP, WT, s, q, v, q0, v0, h6, k1, k2, k3, v2, v3, i0):
    """Rows i0 … of the last stage at (q, v) = (q4, v4), then the RK4 update of (q0, v0) in place."""
    sig = types.void(AT, BT, gP, WT, s, q, v, q0, v0, h6, k1, k2, k3, v2, v3, i0)
    return _block(sig, _accel_dense, 7, _finish_final)


@njit(nogil=True, inline="always")
def _dots(V, m, q, v, vo, d, dv):
    """(d + Σ_j V[m, j] q[j], dv + Σ_j V[m, j] v[vo + j]), the terms added one by one in order."""
    for j in range(V.shape[1]):
        d += V[m, j] * q[j]
        dv += V[m, j] * v[vo + j]
    return d, dv


@njit(nogil=True, inline="always")
def forces_dense(q, v, tab, r, V, D, Vc, kc, cc, Dc, omega, s):
    """Element forces s[e] of :func:`field` (default mode) at (q̃, q̃') = (q[0:n], v[0:n]), coefficients
    from row r of a table (T, meshes, 4); meshes, then clearances, in :func:`field`'s arithmetic."""
    M = V.shape[0]
    for m in range(M):
        d, dv = _dots(V, m, q, v, 0, 0.0, 0.0)
        d -= tab[r, m, 2]
        dv -= omega * tab[r, m, 3]
        s[m] = tab[r, m, 0] * dv + tab[r, m, 1] * _fz(d, D[m])
    for c in range(Vc.shape[0]):
        d, dv = _dots(Vc, c, q, v, 0, 0.0, 0.0)
        s[M + c] = cc[c] * dv + kc[c] * _fz(d, Dc[c])


@njit(nogil=True, inline="always")
def element_values_dense(q, v, vo, cf, V, Vc, omega, out):
    """δ, δ' of every element (meshes then clearances) into out[e, 0:2]; q̃ = q[0:n], q̃' = v[vo:vo+n]."""
    M = V.shape[0]
    for m in range(M):
        out[m, 0], out[m, 1] = _dots(V, m, q, v, vo, -cf[m, 2], -omega * cf[m, 3])
    for c in range(Vc.shape[0]):
        out[M + c, 0], out[M + c, 1] = _dots(Vc, c, q, v, vo, 0.0, 0.0)


@njit(nogil=True)
def pad_dense(A, B, g, W, Wc, AT, BT, gP, WT):
    """The plain step's padded transposed matrices of one point (AT, BT (n, NP), gP (NP,), WT (E, NP))."""
    n = A.shape[0]
    M = W.shape[0]
    AT[:, :] = 0.0
    BT[:, :] = 0.0
    gP[:] = 0.0
    WT[:, :] = 0.0
    gP[:n] = g
    AT[:n, :n] = A.T
    BT[:n, :n] = B.T
    WT[:M, :n] = W
    WT[M : M + Wc.shape[0], :n] = Wc


@njit(nogil=True, inline="always")
def rk4_plain_dense(X, s, h, tab, j, dm, omega, ld):
    """One default-mode RK4 step without tangents (the hot loop) on the padded state X[XQ], X[XV].

    X : (XROWS, NP) workspace, NP a multiple of LANE_BLOCK, its padding zero; s : (elements,) workspace;
    ``dm = (AT, BT, gP, WT, V, D, Vc, kc, cc, Dc)`` the point's padded matrices (:func:`pad_dense`) and elements.
    Coefficients (and the loads ``ld`` into gP, :func:`geardyn._kernel_ndof.step.load_at`; None without torque
    orders: the step then compiles without the refill) from the table rows 2j..2j+2; the arithmetic is
    :func:`rk4` with :func:`field`'s, operation by operation (see :mod:`geardyn._kernel_ndof.simd`), vectorised
    over blocks of rows.
    """
    AT, BT, gP, WT, V, D, Vc, kc, cc, Dc = dm
    hh = 0.5 * h
    h6 = h / 6.0
    q, v, k1, k2, k3, q2, v2, q3, v3, q4, v4 = state_rows(X, 0, X.shape[1])
    load_at(gP, ld, 2 * j)
    forces_dense(q, v, tab, 2 * j, V, D, Vc, kc, cc, Dc, omega, s)
    for b in range(0, X.shape[1], LANE_BLOCK):
        dense_stage_block(AT, BT, gP, WT, s, q, v, q, v, hh, k1, q2, v2, b)
    load_at(gP, ld, 2 * j + 1)
    forces_dense(q2, v2, tab, 2 * j + 1, V, D, Vc, kc, cc, Dc, omega, s)
    for b in range(0, X.shape[1], LANE_BLOCK):
        dense_stage_block(AT, BT, gP, WT, s, q2, v2, q, v, hh, k2, q3, v3, b)
    forces_dense(q3, v3, tab, 2 * j + 1, V, D, Vc, kc, cc, Dc, omega, s)
    for b in range(0, X.shape[1], LANE_BLOCK):
        dense_stage_block(AT, BT, gP, WT, s, q3, v3, q, v, h, k3, q4, v4, b)
    load_at(gP, ld, 2 * j + 2)
    forces_dense(q4, v4, tab, 2 * j + 2, V, D, Vc, kc, cc, Dc, omega, s)
    for b in range(0, X.shape[1], LANE_BLOCK):
        dense_final_block(AT, BT, gP, WT, s, q4, v4, q, v, h6, k1, k2, k3, v2, v3, b)
