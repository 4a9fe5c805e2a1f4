"""One RK4 stage of the default mode on a block of ``LANE_BLOCK`` rows as explicit SIMD vectors.

The plain step keeps the state in a padded layout: q and q' in arrays of ``NP`` values (n rounded
up to a multiple of ``LANE_BLOCK``, the padding zero), the matrices transposed and padded once per
point, ``AT[j, i] = A[i, j]``, ``BT[j, i] = B[i, j]``, ``WT[e, i]`` the rows M̃⁻¹V[m] (meshes, then
clearances).  Row i of the acceleration is accumulated column by column,

    acc_i = g_i;  acc_i -= AT[j, i] q_j + BT[j, i] q'_j  (j = 0 … n−1);  acc_i -= WT[e, i] s_e  (e = 0 …),

which is, operation by operation and in the same order, the row-by-row sum of
:func:`geardyn._kernel_ndof.core.field`, so the results are bit-identical; the rows of a block are
the lanes of one vector (IEEE multiplications, additions and subtractions only: no contraction, no
reassociation).  numba runs no SLP vectorizer and fully unrolls short fixed loops before its loop
vectorizer sees them, so the vectors are written here as LLVM IR (:func:`numba.extending.intrinsic`).

:func:`stage_block` finishes a stage: it stores the acceleration ``k`` and the next stage's state
``qn = q0 + c q'_s``, ``vn = v0 + c k``; :func:`final_block` finishes the step:
``q0 += h6 (((v0 + 2 v2) + 2 v3) + v4)``, ``v0 += h6 (((k1 + 2 k2) + 2 k3) + k4)``.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

#: Rows per SIMD block (one 512-bit vector of float64; narrower hardware splits it).
LANE_BLOCK = 8


def _vty():
    return ir.VectorType(ir.DoubleType(), LANE_BLOCK)


def _ptr(context, builder, aty, aval, inds):
    """Pointer to element ``inds`` of the array value ``aval`` of numba type ``aty``."""
    arr = context.make_array(aty)(context, builder, value=aval)
    shape = cgutils.unpack_tuple(builder, arr.shape)
    strides = cgutils.unpack_tuple(builder, arr.strides)
    return cgutils.get_item_pointer2(context, builder, arr.data, shape, strides, aty.layout, inds)


def _rows(context, builder, aty, aval):
    arr = context.make_array(aty)(context, builder, value=aval)
    return cgutils.unpack_tuple(builder, arr.shape)[0]


def _vload(context, builder, aty, aval, inds):
    p = _ptr(context, builder, aty, aval, inds)
    return builder.load(builder.bitcast(p, _vty().as_pointer()), align=8)


def _vstore(context, builder, aty, aval, inds, value):
    p = _ptr(context, builder, aty, aval, inds)
    builder.store(value, builder.bitcast(p, _vty().as_pointer()), align=8)


def _splat(builder, x):
    vty = _vty()
    u = builder.insert_element(ir.Constant(vty, ir.Undefined), x, ir.Constant(ir.IntType(32), 0))
    mask = ir.Constant(ir.VectorType(ir.IntType(32), LANE_BLOCK), [0] * LANE_BLOCK)
    return builder.shuffle_vector(u, ir.Constant(vty, ir.Undefined), mask)


def _accel(context, builder, tys, vals, i0):
    """The block's acceleration vector: g − Σ_k (AT[k] q_j + BT[k] v_j) − Σ_k WT[k] s_e over the block's columns
    j = cj[k] (k = lo … hi−1) and elements e = ej[k] (k = elo … ehi−1), ascending."""
    (tA, tB, tcj, _tlo, _thi, tg, tW, tej, _telo, _tehi, ts, tq, tv) = tys
    (AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v) = vals
    zero = ir.Constant(lo.type, 0)
    one = ir.Constant(lo.type, 1)
    acc = cgutils.alloca_once(builder, _vty())
    builder.store(_vload(context, builder, tg, gP, [i0]), acc)
    with cgutils.for_range_slice(builder, lo, hi, one, intp=lo.type) as (k, _c):
        j = builder.load(_ptr(context, builder, tcj, cj, [k]))
        qj = _splat(builder, builder.load(_ptr(context, builder, tq, q, [j])))
        vj = _splat(builder, builder.load(_ptr(context, builder, tv, v, [j])))
        t = builder.fadd(
            builder.fmul(_vload(context, builder, tA, AT, [k, zero]), qj),
            builder.fmul(_vload(context, builder, tB, BT, [k, zero]), vj),
        )
        builder.store(builder.fsub(builder.load(acc), t), acc)
    with cgutils.for_range_slice(builder, elo, ehi, one, intp=lo.type) as (k, _c):
        e = builder.load(_ptr(context, builder, tej, ej, [k]))
        se = _splat(builder, builder.load(_ptr(context, builder, ts, s, [e])))
        builder.store(
            builder.fsub(builder.load(acc), builder.fmul(_vload(context, builder, tW, WT, [k, zero]), se)), acc
        )
    return builder.load(acc)


#: Arguments of the acceleration (:func:`_accel`) at the head of both intrinsics.
NACC = 13


@intrinsic
def stage_block(typingctx, AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, c, k, qn, vn, i0):
    """Rows i0 … i0+LANE_BLOCK−1 of one stage at (q, v): k = acceleration, qn = q0 + c v, vn = v0 + c k."""
    sig = types.void(AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, c, k, qn, vn, i0)

    def codegen(context, builder, signature, args):
        t = signature.args
        b = NACC - 7  # the arguments below are those of the dense version, shifted by b
        i0v = args[13 + b]
        acc = _accel(context, builder, t[:NACC], args[:NACC], i0v)
        cv = _splat(builder, args[9 + b])
        _vstore(context, builder, t[10 + b], args[10 + b], [i0v], acc)
        qs = _vload(context, builder, t[6 + b], args[6 + b], [i0v])
        _vstore(
            context,
            builder,
            t[11 + b],
            args[11 + b],
            [i0v],
            builder.fadd(_vload(context, builder, t[7 + b], args[7 + b], [i0v]), builder.fmul(cv, qs)),
        )
        _vstore(
            context,
            builder,
            t[12 + b],
            args[12 + b],
            [i0v],
            builder.fadd(_vload(context, builder, t[8 + b], args[8 + b], [i0v]), builder.fmul(cv, acc)),
        )
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def final_block(typingctx, AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, h6, k1, k2, k3, v2, v3, i0):
    """Rows i0 … of the last stage at (q, v) = (q4, v4), then the RK4 update of (q0, v0) in place."""
    sig = types.void(AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, h6, k1, k2, k3, v2, v3, i0)

    def codegen(context, builder, signature, args):
        t = signature.args
        b = NACC - 7
        i0v = args[15 + b]
        k4 = _accel(context, builder, t[:NACC], args[:NACC], i0v)

        def ld(a):
            return _vload(context, builder, t[a + b], args[a + b], [i0v])

        hv = _splat(builder, args[9 + b])
        two = ir.Constant(_vty(), [2.0] * LANE_BLOCK)

        def comb(a1, a2, a3, a4):
            s12 = builder.fadd(a1, builder.fmul(two, a2))
            return builder.fadd(builder.fadd(s12, builder.fmul(two, a3)), a4)

        v0v = ld(8)
        qnew = builder.fadd(ld(7), builder.fmul(hv, comb(v0v, ld(13), ld(14), ld(6))))
        vnew = builder.fadd(v0v, builder.fmul(hv, comb(ld(10), ld(11), ld(12), k4)))
        _vstore(context, builder, t[7 + b], args[7 + b], [i0v], qnew)
        _vstore(context, builder, t[8 + b], args[8 + b], [i0v], vnew)
        return context.get_dummy_value()

    return sig, codegen
