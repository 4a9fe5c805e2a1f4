"""Explicit SIMD chunk kernels of the lanes path (first-harmonic kinds), written as LLVM vector IR.

A chunk kernel advances the lanes in use of the lane state ``S`` (layout of
:mod:`geardyn._kernel.lanes`) by ``m`` RK4 steps.  Each step runs the lanes as vectors of
``V = width / 64`` doubles (8 with 512-bit registers, 4 with 256-bit ones), one vector after the
other: the vector's fields are loaded from ``S``, its step computed, and its state, statistics and
tangent columns stored back, as the C reference and the compiler-vectorised template do.  The
vectors of a step run in a loop rather than unrolled: unrolled, LLVM hoists every vector's
constant fields out of the step loop and spills them, which is slower than loading them where they
are used.

Every lane performs the operations of the scalar template (:func:`geardyn._kernel.lanes._make_chunk`
and the functions of :mod:`geardyn._kernel.core`) in the same order: the same ``llvm.fma`` calls,
IEEE multiplications, additions and subtractions without fast-math flags, negation as
``-0.0 - x``, ``min``/``max`` as numba's compare-and-select (``max(a, b) = b > a ? b : a``,
``min(a, b) = b < a ? b : a``), ``abs`` as ``llvm.fabs``.  The results are therefore the same bits
as the compiler-vectorised loops and the scalar path (``tests/test_simd.py``).

Width
-----
numba does not vectorise the template's lanes beyond its groups of four (``GROUP``): 256-bit
``ymm`` registers.  Here the vector type fixes the width, and function attributes the registers
LLVM may use: ``"min-legal-vector-width"`` and ``"prefer-vector-width"`` = 512 allow ``zmm``
registers, 256 forbids them (the AVX2 code, also on an AVX-512 machine).  The kernels are marked
``noinline`` so that these attributes are not merged into their caller's.  Which width runs is
decided at run time (:func:`geardyn._kernel.lanes.simd_width`): the machine's native width, or
``GEARDYN_SIMD_WIDTH`` = ``512``, ``256`` or ``0`` (``0``: no explicit vectors, the
compiler-vectorised loops of the template, as before these kernels).  The general kind (more than
one harmonic) always runs the template.
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit
from numba.core import cgutils, types
from numba.extending import intrinsic

from .._cache_guard import own_name

# The lane-state field indices are those of :mod:`geardyn._kernel.lanes`, passed in by the caller
# (``fields``) so that the imports go one way (lanes imports this module).

_DBL = ir.DoubleType()


def _vector_chunk(kind_sin, mode, V, width, L, fields):
    """Build the intrinsic ``vchunk(S, m, nb)`` advancing lanes 0 … nb·V − 1 of ``S`` by ``m``
    steps, as ``nb`` vectors of V lanes per step.

    kind_sin : bool — first harmonic with sine terms (else cosine terms only).
    mode : 0 plain, 1 statistics, 2 statistics and tangents.
    V : lanes per vector; width : 256 or 512 (the register width the code may use);
    L : lanes of the state layout (field f of lane l at S[f * L + l]); fields : dict name → index.
    """
    with_stats = mode >= 1
    with_tan = mode == 2
    F = fields
    vty = ir.VectorType(_DBL, V)

    def codegen(context, builder, signature, args):
        S_ty = signature.args[0]
        S, m, nb = args
        fn = builder.function
        fn.attributes.add("noinline")
        # string attributes (llvmlite only validates the keyword attributes)
        set.add(fn.attributes, f'"min-legal-vector-width"="{width}"')
        set.add(fn.attributes, f'"prefer-vector-width"="{width}"')
        module = builder.module
        fma_fn = cgutils.get_or_insert_function(module, ir.FunctionType(vty, [vty, vty, vty]), f"llvm.fma.v{V}f64")
        fabs_fn = cgutils.get_or_insert_function(module, ir.FunctionType(vty, [vty]), f"llvm.fabs.v{V}f64")
        data = context.make_array(S_ty)(context, builder, value=S).data
        i64 = ir.IntType(64)

        def ptr(f, l0):
            off = builder.add(ir.Constant(i64, F[f] * L), l0)
            return builder.bitcast(builder.gep(data, [off]), vty.as_pointer())

        def const(x):
            return ir.Constant(vty, [x] * V)

        NEGZ = const(-0.0)
        ZERO = const(0.0)
        ONE = const(1.0)
        TWO = const(2.0)

        def fma(a, b, c):
            return builder.call(fma_fn, [a, b, c])

        def neg(a):
            return builder.fsub(NEGZ, a)

        def vmax(a, b):  # numba's max(a, b): b if b > a else a
            return builder.select(builder.fcmp_ordered(">", b, a), b, a)

        def vmin(a, b):  # numba's min(a, b): b if b < a else a
            return builder.select(builder.fcmp_ordered("<", b, a), b, a)

        def fz(u, D):  # core._fz
            c = vmin(vmax(u, neg(D)), D)
            return builder.fsub(u, c)

        def acc(u, v, C, K, Fo, D):  # core._acc
            return fma(neg(K), fz(u, D), fma(neg(C), v, Fo))

        def rot_small(c, s, cm1, sa):  # core._rot_small
            cn = builder.fadd(c, fma(cm1, c, neg(builder.fmul(s, sa))))
            sn = builder.fadd(s, fma(cm1, s, builder.fmul(c, sa)))
            return cn, sn

        def series(a0, a1, b1, c, s):  # core._series1, or fma(a1, c, a0) without sine terms
            x = fma(a1, c, a0)
            return fma(b1, s, x) if kind_sin else x

        def slope(K, u, dtan):  # core._slope
            return builder.select(builder.fcmp_ordered(">", builder.call(fabs_fn, [u]), dtan), K, ZERO)

        def rk4_tan(a, b, h, hh, h6, C0, C1, C2, g1, g2, g3, g4):  # core._rk4_tan
            kb1 = fma(neg(g1), a, neg(builder.fmul(C0, b)))
            a2 = fma(hh, b, a)
            b2 = fma(hh, kb1, b)
            kb2 = fma(neg(g2), a2, neg(builder.fmul(C1, b2)))
            a3 = fma(hh, b2, a)
            b3 = fma(hh, kb2, b)
            kb3 = fma(neg(g3), a3, neg(builder.fmul(C1, b3)))
            a4 = fma(h, b3, a)
            b4 = fma(h, kb3, b)
            kb4 = fma(neg(g4), a4, neg(builder.fmul(C2, b4)))
            an = fma(h6, builder.fadd(fma(TWO, b3, fma(TWO, b2, b)), b4), a)
            bn = fma(h6, builder.fadd(fma(TWO, kb3, fma(TWO, kb2, kb1)), kb4), b)
            return an, bn

        def step(l0):
            """One RK4 step of the block at lane l0: fields loaded from S, results stored to S."""

            def ld(f):
                return builder.load(ptr(f, l0), align=8)

            def st(f, x):
                builder.store(x, ptr(f, l0), align=8)

            cm1 = ld("CM1")
            sa = ld("SA")
            c0, s0 = ld("C"), ld("S")
            c1, s1 = rot_small(c0, s0, cm1, sa)
            c2, s2 = rot_small(c1, s1, cm1, sa)
            ca0, ca1, ka0, ka1, fa0, fa1 = (ld(f) for f in ("CA0", "CA1", "KA0", "KA1", "FA0", "FA1"))
            if kind_sin:
                cb1, kb1_, fb1 = ld("CB1"), ld("KB1"), ld("FB1")
            else:
                cb1 = kb1_ = fb1 = None
            C0 = series(ca0, ca1, cb1, c0, s0)
            K0 = series(ka0, ka1, kb1_, c0, s0)
            F0 = series(fa0, fa1, fb1, c0, s0)
            C1 = series(ca0, ca1, cb1, c1, s1)
            K1 = series(ka0, ka1, kb1_, c1, s1)
            F1 = series(fa0, fa1, fb1, c1, s1)
            C2 = series(ca0, ca1, cb1, c2, s2)
            K2 = series(ka0, ka1, kb1_, c2, s2)
            F2 = series(fa0, fa1, fb1, c2, s2)
            h = ld("H")
            hh = ld("HH")
            h6 = ld("H6")
            D = ld("D")
            u, v = ld("U"), ld("V")
            # core._rk4
            k1 = acc(u, v, C0, K0, F0, D)
            u2 = fma(hh, v, u)
            v2 = fma(hh, k1, v)
            k2 = acc(u2, v2, C1, K1, F1, D)
            u3 = fma(hh, v2, u)
            v3 = fma(hh, k2, v)
            k3 = acc(u3, v3, C1, K1, F1, D)
            u4 = fma(h, v3, u)
            v4 = fma(h, k3, v)
            k4 = acc(u4, v4, C2, K2, F2, D)
            un = fma(h6, builder.fadd(fma(TWO, v3, fma(TWO, v2, v)), v4), u)
            vn = fma(h6, builder.fadd(fma(TWO, k3, fma(TWO, k2, k1)), k4), v)
            if with_tan:
                dtan = ld("DTAN")
                g1 = slope(K0, u, dtan)
                g2 = slope(K1, u2, dtan)
                g3 = slope(K1, u3, dtan)
                g4 = slope(K2, u4, dtan)
                y00, y10 = rk4_tan(ld("Y00"), ld("Y10"), h, hh, h6, C0, C1, C2, g1, g2, g3, g4)
                y01, y11 = rk4_tan(ld("Y01"), ld("Y11"), h, hh, h6, C0, C1, C2, g1, g2, g3, g4)
                st("Y00", y00)
                st("Y10", y10)
                st("Y01", y01)
                st("Y11", y11)
            if with_stats:
                st("UMIN", vmin(ld("UMIN"), un))
                st("UMAX", vmax(ld("UMAX"), un))
                st("VMIN", vmin(ld("VMIN"), vn))
                st("VMAX", vmax(ld("VMAX"), vn))
                st("USUM", builder.fadd(ld("USUM"), un))
                st("USQ", fma(un, un, ld("USQ")))
                drive = builder.select(builder.fcmp_ordered(">", un, ld("DRV")), ONE, ZERO)
                back = builder.select(builder.fcmp_ordered("<", un, ld("BCK")), ONE, ZERO)
                st("NDRV", builder.fadd(ld("NDRV"), drive))
                st("NBCK", builder.fadd(ld("NBCK"), back))
            st("U", un)
            st("V", vn)
            st("C", c2)
            st("S", s2)

        # m steps; in each, the vectors one after the other (a loop, not unrolled: the loads of a
        # vector stay in the loop as memory operands instead of being hoisted and spilled)
        with cgutils.for_range(builder, m):
            with cgutils.for_range(builder, nb) as loop:
                step(builder.mul(loop.index, ir.Constant(i64, V)))
        return context.get_dummy_value()

    @intrinsic
    def vchunk(typingctx, S, m, nb):
        if not (isinstance(S, types.Array) and S.dtype == types.float64 and S.ndim == 1):
            return None
        return types.void(S, types.int64, types.int64), codegen

    return vchunk


#: The vector kernels built, by (kind_sin, mode, width): ``block(S, m, nb)``, whose machine code
#: can be inspected (``inspect_asm``) for the registers used.
BLOCKS: dict = {}


def make_vector_chunks(kind_sin, mode, width, L, fields):
    """The chunk kernel ``chunk(S, CF, m, H1, ng)`` of one first-harmonic kind and mode at one
    register width, with the signature of the template kernels (``ng`` groups of 4 lanes in use):
    vectors of ``width / 64`` lanes, as many per step as cover the lanes in use."""
    V = width // 64
    assert L % V == 0
    k = _vector_chunk(kind_sin, mode, V, width, L, fields)

    tags = ("sin" if kind_sin else "cos", "mode", mode, "width", width)

    @njit(nogil=True)
    @own_name(*tags)  # closures of one name collide once cached (see own_name)
    def block(S, m, nb):
        k(S, m, nb)

    BLOCKS[(bool(kind_sin), mode, width)] = block

    @njit(nogil=True)
    @own_name(*tags)
    def chunk(S, CF, m, H1, ng):
        if m > 0:
            block(S, m, (ng * 4 + V - 1) // V)

    return chunk
