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

        def series(c, s, a0, a1, b1=None):  # core._series1, or fma(a1, c, a0) without sine terms
            x = fma(a1, c, a0)
            return fma(b1, s, x) if kind_sin else x

        def slope(K, u, dtan):  # core._slope
            return builder.select(builder.fcmp_ordered(">", builder.call(fabs_fn, [u]), dtan), K, ZERO)

        def rk4(x, y, h, hh, h6, rate):  # core._rk4 (rate: core._acc) and core._rk4_tan; rate(j, ...) at stage j
            k1 = rate(0, x, y)
            x2 = fma(hh, y, x)
            y2 = fma(hh, k1, y)
            k2 = rate(1, x2, y2)
            x3 = fma(hh, y2, x)
            y3 = fma(hh, k2, y)
            k3 = rate(2, x3, y3)
            x4 = fma(h, y3, x)
            y4 = fma(h, k3, y)
            k4 = rate(3, x4, y4)
            xn = fma(h6, builder.fadd(fma(TWO, y3, fma(TWO, y2, y)), y4), x)
            yn = fma(h6, builder.fadd(fma(TWO, k3, fma(TWO, k2, k1)), k4), y)
            return xn, yn, (x, x2, x3, x4)

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
            cf = [[ld(f + t) for t in ("A0", "A1", "B1")[: 3 if kind_sin else 2]] for f in "CKF"]
            # (C, K, F) at the stages j = 0 … 3: the step's start, the midpoint twice, the end
            ckf = [[series(c, s, *x) for x in cf] for c, s in ((c0, s0), (c1, s1), (c2, s2))]
            ckf.insert(1, ckf[1])
            h = ld("H")
            hh = ld("HH")
            h6 = ld("H6")
            D = ld("D")
            un, vn, us = rk4(ld("U"), ld("V"), h, hh, h6, lambda j, u, v: acc(u, v, *ckf[j], D))
            if with_tan:
                dtan = ld("DTAN")
                g = [slope(ckf[j][1], us[j], dtan) for j in range(4)]

                def rate(j, a, b):  # core._rk4_tan's stage rate
                    return fma(neg(g[j]), a, neg(builder.fmul(ckf[j][0], b)))

                for col in ("0", "1"):
                    yp, yv, _ = rk4(ld("Y0" + col), ld("Y1" + col), h, hh, h6, rate)
                    st("Y0" + col, yp)
                    st("Y1" + col, yv)
            if with_stats:
                for f, op, x in (("UMIN", vmin, un), ("UMAX", vmax, un), ("VMIN", vmin, vn), ("VMAX", vmax, vn)):
                    st(f, op(ld(f), x))
                st("USUM", builder.fadd(ld("USUM"), un))
                st("USQ", fma(un, un, ld("USQ")))
                for f, op, t in (("NDRV", ">", "DRV"), ("NBCK", "<", "BCK")):  # drive u > DRV, back u < BCK
                    st(f, builder.fadd(ld(f), builder.select(builder.fcmp_ordered(op, un, ld(t)), ONE, ZERO)))
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
