"""One RK4 stage of the default mode on a block of ``LANE_BLOCK`` rows as explicit SIMD vectors.

The plain step keeps the state in a padded layout: q and q' in arrays of ``NP`` values (n rounded
up to a multiple of ``LANE_BLOCK``, the padding zero, and ``margin`` zero values on either side), the matrices
by the diagonals of each block of L = ``LANE_BLOCK`` rows, copied once per point: ``AT[k, r] = A[i0 + r,
i0 + r + o]`` for the block's offsets o = ``cj[k]`` (ascending), ``BT`` alike, ``WT[e, i]`` the rows M̃⁻¹V[m]
(meshes, then clearances).  Row i of the acceleration is accumulated diagonal by diagonal,

    acc_i = g_i;  acc_i -= AT[k, i] q_{i+o} + BT[k, i] q'_{i+o}  (o = cj[k] ascending);  acc_i -= WT[e, i] s_e,

which meets every row's columns j = i + o in ascending order: operation by operation and in the same order, the
row-by-row sum of :func:`geardyn._kernel_ndof.core.field` with zero terms added (a product with a zero factor
changes no finite sum), so the results are bit-identical; the rows of a block are the lanes of one vector, the
columns ``q[i0 + o : i0 + o + L]`` one (unaligned) load (IEEE multiplications, additions and subtractions only: no
contraction, no reassociation).  A chain's block has 3 diagonals where it has 9 columns.  numba runs no SLP
vectorizer and fully unrolls short fixed loops before its loop vectorizer sees them, so the vectors are written
here as LLVM IR (:func:`numba.extending.intrinsic`).

:func:`stage_block` finishes a stage: it stores the acceleration ``k`` and the next stage's state
``qn = q0 + c q'_s``, ``vn = v0 + c k``; :func:`final_block` finishes the step:
``q0 += h6 (((v0 + 2 v2) + 2 v3) + v4)``, ``v0 += h6 (((k1 + 2 k2) + 2 k3) + k4)``.

:func:`forces_group` computes the forces of L meshes or clearances at once, one per lane (their terms gathered from
q and q'), in the arithmetic of :func:`geardyn._kernel_ndof.core.field`: each lane's sums run over its terms
in the same order, the padding terms (value 0) after them; :func:`values_group` their δ and δ' (the statistics'
samples) in that of :func:`geardyn._kernel_ndof.core.element_values`.
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
    """The vector of LANE_BLOCK copies of the scalar x (a float64 or an integer)."""
    vty = ir.VectorType(x.type, LANE_BLOCK)
    u = builder.insert_element(ir.Constant(vty, ir.Undefined), x, ir.Constant(ir.IntType(32), 0))
    mask = ir.Constant(ir.VectorType(ir.IntType(32), LANE_BLOCK), [0] * LANE_BLOCK)
    return builder.shuffle_vector(u, ir.Constant(vty, ir.Undefined), mask)


def _accel(context, builder, tys, vals, i0):
    """The block's acceleration vector: g − Σ_k (AT[k] q[i0 + o : i0 + o + L] + BT[k] v[…]) − Σ_k WT[k] s_e over
    the block's diagonals o = cj[k] (k = lo … hi−1) and elements e = ej[k] (k = elo … ehi−1), ascending."""
    (tA, tB, tcj, _tlo, _thi, tg, tW, tej, _telo, _tehi, ts, tq, tv) = tys
    (AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v) = vals
    zero = ir.Constant(lo.type, 0)
    one = ir.Constant(lo.type, 1)
    acc = cgutils.alloca_once(builder, _vty())
    builder.store(_vload(context, builder, tg, gP, [i0]), acc)
    with cgutils.for_range_slice(builder, lo, hi, one, intp=lo.type) as (k, _c):
        j = builder.add(i0, builder.load(_ptr(context, builder, tcj, cj, [k])))  # diagonal o: columns i0 + o + r
        qj = _vload(context, builder, tq, q, [j])
        vj = _vload(context, builder, tv, v, [j])
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


def _block(sig, accel, nacc, finish):
    """The (signature, codegen) of a block's intrinsic: the acceleration ``accel`` from its first ``nacc`` arguments
    (:func:`_accel`, or the dense one), then ``finish`` (:func:`_finish_stage` or :func:`_finish_final`); the block's
    first row i0 is the last argument."""

    def codegen(context, builder, signature, args):
        t = signature.args
        finish(context, builder, t, args, nacc - 7, accel(context, builder, t[:nacc], args[:nacc], args[-1]))
        return context.get_dummy_value()

    return sig, codegen


def _finish_stage(context, builder, t, args, b, acc):
    """Store a stage's acceleration ``acc`` into k, and qn = q0 + c q', vn = v0 + c k (the arguments (q', q0, v0,
    c, k, qn, vn, i0) at 6 + b … 13 + b: b = 0 for the dense stage, the sparse one's extra arguments before)."""
    i0v = args[-1]
    cv = _splat(builder, args[9 + b])

    def ld(a):
        return _vload(context, builder, t[a + b], args[a + b], [i0v])

    def st(a, value):
        _vstore(context, builder, t[a + b], args[a + b], [i0v], value)

    st(10, acc)
    qs = ld(6)
    st(11, builder.fadd(ld(7), builder.fmul(cv, qs)))
    st(12, builder.fadd(ld(8), builder.fmul(cv, acc)))


def _finish_final(context, builder, t, args, b, k4):
    """The RK4 update of (q0, v0) from the last stage's acceleration ``k4`` (the arguments (q4, v4, q0, v0, h6, k1,
    k2, k3, v2, v3, i0) at 5 + b … 15 + b, as :func:`_finish_stage`)."""
    i0v = args[-1]

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


@intrinsic
def stage_block(typingctx, AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, c, k, qn, vn, i0):
    """Rows i0 … i0+LANE_BLOCK−1 of one stage at (q, v): k = acceleration, qn = q0 + c v, vn = v0 + c k."""
    sig = types.void(AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, c, k, qn, vn, i0)
    return _block(sig, _accel, NACC, _finish_stage)  # the arguments after NACC: the dense version's after 7


@intrinsic
def final_block(typingctx, AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, h6, k1, k2, k3, v2, v3, i0):
    """Rows i0 … of the last stage at (q, v) = (q4, v4), then the RK4 update of (q0, v0) in place."""
    sig = types.void(AT, BT, cj, lo, hi, gP, WT, ej, elo, ehi, s, q, v, q0, v0, h6, k1, k2, k3, v2, v3, i0)
    return _block(sig, _accel, NACC, _finish_final)


def _gather(builder, base, idx):
    """The vector base[idx] (base a pointer to float64, idx a vector of LANE_BLOCK int64)."""
    i64 = ir.IntType(64)
    iv = ir.VectorType(i64, LANE_BLOCK)
    addr = builder.add(
        _splat(builder, builder.ptrtoint(base, i64)), builder.shl(idx, ir.Constant(iv, [3] * LANE_BLOCK))
    )
    pty = ir.VectorType(base.type, LANE_BLOCK)
    mty = ir.VectorType(ir.IntType(1), LANE_BLOCK)
    fnty = ir.FunctionType(_vty(), [pty, ir.IntType(32), mty, _vty()])
    fn = cgutils.get_or_insert_function(builder.module, fnty, f"llvm.masked.gather.v{LANE_BLOCK}f64.v{LANE_BLOCK}p0")
    return builder.call(
        fn,
        [
            builder.inttoptr(addr, pty),
            ir.Constant(ir.IntType(32), 8),
            ir.Constant(mty, [1] * LANE_BLOCK),
            ir.Constant(_vty(), ir.Undefined),
        ],
    )


def _group_sums(context, builder, tys, vals, d0, v0):
    """(d0 + Σ_t EV[G, t] q[EI[G, t]], v0 + Σ_t EV[G, t] v[EI[G, t]]) of group G, lane by lane, t ascending."""
    tEI, tEV, tq, tv, tg = tys
    EIv, EVv, qv, vv, gv = vals
    T = cgutils.unpack_tuple(builder, context.make_array(tEI)(context, builder, value=EIv).shape)[1]
    zero = ir.Constant(T.type, 0)
    one = ir.Constant(T.type, 1)
    qb = _ptr(context, builder, tq, qv, [zero])
    vb = _ptr(context, builder, tv, vv, [zero])
    dacc = cgutils.alloca_once(builder, _vty())
    vacc = cgutils.alloca_once(builder, _vty())
    builder.store(d0, dacc)
    builder.store(v0, vacc)
    iv = ir.VectorType(ir.IntType(64), LANE_BLOCK)
    with cgutils.for_range_slice(builder, zero, T, one, intp=T.type) as (t, _c):
        idx = builder.load(builder.bitcast(_ptr(context, builder, tEI, EIv, [gv, t, zero]), iv.as_pointer()), align=8)
        ev = _vload(context, builder, tEV, EVv, [gv, t, zero])
        builder.store(builder.fadd(builder.load(dacc), builder.fmul(ev, _gather(builder, qb, idx))), dacc)
        builder.store(builder.fadd(builder.load(vacc), builder.fmul(ev, _gather(builder, vb, idx))), vacc)
    return builder.load(dacc), builder.load(vacc)


def _group_head(context, builder, tTB, TBv, rv, gv):
    """(first lane's index g0 = G·L of group G = ``gv``, and ``tb(c)``: the vector TB[r, c, g0 : g0 + L])."""
    g0 = builder.mul(gv, ir.Constant(gv.type, LANE_BLOCK))

    def tb(c):
        return _vload(context, builder, tTB, TBv, [rv, ir.Constant(rv.type, c), g0])

    return g0, tb


def _group_forces(context, builder, tys, vals):
    """(first lane's index, δ, D, s) of an element group: the force of :func:`forces_group`."""
    tEI, tEV, tq, tv, tTB, _tr, tD, _tom, tg = tys
    EIv, EVv, qv, vv, TBv, rv, Dv, om, gv = vals
    g0, tb = _group_head(context, builder, tTB, TBv, rv, gv)
    z = ir.Constant(_vty(), [0.0] * LANE_BLOCK)
    d, dv = _group_sums(context, builder, (tEI, tEV, tq, tv, tg), (EIv, EVv, qv, vv, gv), z, z)
    d = builder.fsub(d, tb(2))
    dv = builder.fsub(dv, builder.fmul(_splat(builder, om), tb(3)))
    D = _vload(context, builder, tD, Dv, [g0])
    nD = builder.fneg(D)
    c1 = builder.select(builder.fcmp_ordered(">", nD, d), nD, d)  # max(δ, −D) as numba's max
    c2 = builder.select(builder.fcmp_ordered("<", D, c1), D, c1)  # min(…, D) as numba's min
    f = builder.fadd(builder.fmul(tb(0), dv), builder.fmul(tb(1), builder.fsub(d, c2)))
    return g0, d, D, f, tb


@intrinsic
def forces_group(typingctx, EI, EV, q, v, TB, r, Dp, omega, s, g):
    """The forces s[G·L … G·L + L−1] of element group G = ``g`` at (q̃, q̃') = (q, v): lane l sums
    EV[G, t, l] q[EI[G, t, l]] (and q') over its terms t ascending, subtracts E_m (``TB[r, 2]``) and ω E_m'
    (``TB[r, 3]``; clearances: 0), and takes C δ' + K f(δ; D) with C, K = ``TB[r, 0:2]``, D = ``Dp``."""
    sig = types.void(EI, EV, q, v, TB, r, Dp, omega, s, g)

    def codegen(context, builder, signature, args):
        t = signature.args
        g0, _d, _D, f, _tb = _group_forces(context, builder, t[:8] + t[9:], args[:8] + args[9:])
        _vstore(context, builder, t[8], args[8], [g0], f)
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def forces_slopes_group(typingctx, EI, EV, q, v, TB, r, Dp, omega, s, gk, gc, g):
    """:func:`forces_group` and the slopes of :func:`geardyn._kernel_ndof.core.slopes` (default mode):
    gk = K · (1 if D = 0 or |δ| > D else 0), gc = C, into gk[G·L …], gc[G·L …]."""
    sig = types.void(EI, EV, q, v, TB, r, Dp, omega, s, gk, gc, g)

    def codegen(context, builder, signature, args):
        t = signature.args
        g0, d, D, f, tb = _group_forces(context, builder, t[:8] + t[11:], args[:8] + args[11:])
        _vstore(context, builder, t[8], args[8], [g0], f)
        zero = ir.Constant(_vty(), [0.0] * LANE_BLOCK)
        contact = builder.or_(
            builder.fcmp_ordered("==", D, zero),
            builder.or_(builder.fcmp_ordered(">", d, D), builder.fcmp_ordered(">", builder.fneg(d), D)),
        )  # D == 0 or |δ| > D
        sl = builder.select(contact, ir.Constant(_vty(), [1.0] * LANE_BLOCK), zero)
        _vstore(context, builder, t[9], args[9], [g0], builder.fmul(tb(1), sl))
        _vstore(context, builder, t[10], args[10], [g0], tb(0))
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def values_group(typingctx, EI, EV, q, v, TB, r, out, g):
    """δ, δ' of element group G = ``g`` into out[0, G·L …], out[1, G·L …] in the arithmetic of
    :func:`geardyn._kernel_ndof.core.element_values`: lane l starts from −E_m (``TB[r, 4]``; clearances +0) and
    −ω E_m' (``TB[r, 5]``) and adds EV[G, t, l] q[EI[G, t, l]] (and q') over its terms t ascending."""
    sig = types.void(EI, EV, q, v, TB, r, out, g)

    def codegen(context, builder, signature, args):
        tEI, tEV, tq, tv, tTB, _tr, to, tg = signature.args
        EIv, EVv, qv, vv, TBv, rv, ov, gv = args
        g0, tb = _group_head(context, builder, tTB, TBv, rv, gv)
        d, dv = _group_sums(context, builder, (tEI, tEV, tq, tv, tg), (EIv, EVv, qv, vv, gv), tb(4), tb(5))
        _vstore(context, builder, to, ov, [ir.Constant(g0.type, 0), g0], d)
        _vstore(context, builder, to, ov, [ir.Constant(g0.type, 1), g0], dv)
        return context.get_dummy_value()

    return sig, codegen
