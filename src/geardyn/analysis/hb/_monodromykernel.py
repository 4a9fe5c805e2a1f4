"""Compiled integration of one response period with the variational equation (see :mod:`.monodromy`).

:func:`monodromy_kernel` advances the state x = (q, q') of

    q'' = G(φ) − A q − B q' − Σ_e W[e] (C_e(φ) δ_e' + K_e(φ) f(δ_e; D_e)),   δ_e = V[e]·q − E_e(φ),

and the columns Y of a fundamental matrix of its variational equation (the stiffness K_e χ_e, χ_e = 1 in contact)
from φ = 0 to 2π (d/dτ = ν d/dφ) with the classic RK4.  Each step runs with every element locked to the contact region
(drive contact, gap, back contact) it is in at the step's start, so the vector field is smooth on the step; a step at
whose end an element is in another region is shortened to end on the boundary (the step length found by an Illinois
iteration on the locked step), so RK4 keeps its fourth order through the contact switches.  All series are centred
complex coefficients in φ.  Each RK4 stage's rates of the columns go straight into the stages' sum and the next
stage's columns (:func:`_tangent_step`); 8 or more columns are padded with zero columns to whole SIMD vectors; the
series at a step's end are the next step's start.

A rolling bearing (``bq``: the N-DOF kernel's parameter rows, :data:`geardyn._kernel_ndof.core.BQ_Z` …, its cage
radians per radian of φ in ``BQ_RHO``; ``bx``: its x row, the y row next) is smooth: its two rows carry no series of
their own (C = K = 0, D = 0: no switch), and its joint force and 2×2 stiffness are the N-DOF kernel's own
(:func:`~geardyn._kernel_ndof.core.bearing_force`, :func:`~geardyn._kernel_ndof.core.bearing_slopes`), the
stiffness at each RK4 stage's state (``stages``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..._cache_guard import install as _install_cache
from ..._kernel_ndof.core import BQ_CX, BQ_CY, BQ_RHO, bearing_force, bearing_slopes

__all__ = ["monodromy_kernel"]

SWITCH_MAX_ITER = 60
#: The columns are padded to a multiple of this (the widest SIMD vector of doubles).
LANES = 8
#: More contact switches than this in one period: the integration is abandoned (chattering on a boundary).
MAX_SWITCHES = 100_000


_install_cache()  # the cache follows this directory's sources (see geardyn._cache_guard)


@njit(cache=True)
def _series(Z, i, L, trig):
    """The real trigonometric polynomial of centred coefficients Z[i, 0 … 2L] at the φ of ``trig`` (cos kφ, sin kφ)."""
    v = Z[i, L].real
    for k in range(1, L + 1):
        c = Z[i, L + k]
        v += 2.0 * (c.real * trig[0, k] - c.imag * trig[1, k])
    return v


@njit(cache=True)
def _region(d, D):
    if D == 0.0:
        return 1
    return 1 if d > D else (-1 if d < -D else 0)


@njit(cache=True)
def _deflection(x, e, V, vp, vi, cf):
    """δ_e of the state x, E_e from the series at its φ (``cf``, :func:`_coefficients`)."""
    d = 0.0
    for q in range(vp[e], vp[e + 1]):
        d += V[e, vi[q]] * x[vi[q]]
    return d - cf[3, e]


@njit(cache=True)
def _coefficients(phi, series, out, trig):
    """The series at φ: out[0, :nd] = G, out[1, :ne] = C, out[2] = K, out[3] = E, out[4] = dE/dφ, out[5, b] the
    cage angle of bearing b (``series``: the kernel's; ``trig``: room for cos kφ and sin kφ up to the longest one)."""
    Cz, Lc, Kz, Lk, Ez, dEz, Le, Gz, Lg, bq = series
    for k in range(1, trig.shape[1]):
        trig[0, k] = math.cos(k * phi)
        trig[1, k] = math.sin(k * phi)
    for b in range(bq.shape[0]):
        out[5, b] = bq[b, BQ_RHO] * phi
    for r in range(Gz.shape[0]):
        out[0, r] = _series(Gz, r, Lg[r], trig)
    for e in range(Cz.shape[0]):
        out[1, e] = _series(Cz, e, Lc[e], trig)
        out[2, e] = _series(Kz, e, Lk[e], trig)
        out[3, e] = _series(Ez, e, Le[e], trig)
        out[4, e] = _series(dEz, e, Le[e], trig)


@njit(cache=True)
def _bearing_rows(x, V, vp, vi, e, off):
    """(δ_x, δ_y) of the bearing whose x row is e, from x[off:] (off = nd: their rates)."""
    dx, dy = 0.0, 0.0
    for q in range(vp[e], vp[e + 1]):
        dx += V[e, vi[q]] * x[off + vi[q]]
    for q in range(vp[e + 1], vp[e + 2]):
        dy += V[e + 1, vi[q]] * x[off + vi[q]]
    return dx, dy


@njit(cache=True)
def _state_rhs(x, out, system, cf, reg):
    A, B, W, V, sp, D, inv_nu, nu, bq, bx = system
    nd, ne, (rp, ri, vp, vi, wp, wi) = A.shape[0], W.shape[0], sp
    for r in range(nd):
        out[r] = x[nd + r] * inv_nu
        acc = cf[0, r]
        for q in range(rp[r], rp[r + 1]):
            s = ri[q]
            acc -= A[r, s] * x[s] + B[r, s] * x[nd + s]
        out[nd + r] = acc
    for e in range(ne):
        d = -cf[3, e]
        dv = -nu * cf[4, e]
        for q in range(vp[e], vp[e + 1]):
            s = vi[q]
            d += V[e, s] * x[s]
            dv += V[e, s] * x[nd + s]
        f = 0.0
        if reg[e] != 0:
            f = d - reg[e] * D[e] if D[e] > 0.0 else d
        force = cf[1, e] * dv + cf[2, e] * f
        for q in range(wp[e], wp[e + 1]):
            r = wi[q]
            out[nd + r] -= W[e, r] * force
    for b in range(bq.shape[0]):
        e = bx[b]
        dx, dy = _bearing_rows(x, V, vp, vi, e, 0)
        vx, vy = _bearing_rows(x, V, vp, vi, e, nd)
        sx, sy = bearing_force(dx, dy, vx, vy, cf[5, b], bq, b)
        for r in range(nd):
            out[nd + r] -= W[e, r] * sx + W[e + 1, r] * sy
    for r in range(nd):
        out[nd + r] *= inv_nu


@njit(cache=True)
def _tangent_rhs(Y, out, system, cf, reg, vy, xs):
    """ν times the rate of the columns' velocity rows into out[:nd] (their position rows' rate is the velocity
    rows over ν), summed over the nonzeros only (``sp``: the union pattern of A and B, the patterns of V and W)."""
    A, B, W, V, sp, _D, _inv_nu, _nu, bq, bx = system
    nd, m, ne, (rp, ri, vp, vi, wp, wi) = A.shape[0], Y.shape[1], W.shape[0], sp
    acc, b = vy[1], vy[2]
    for r in range(nd):
        o = out[r]
        o[:] = 0.0
        for q in range(rp[r], rp[r + 1]):
            s = ri[q]
            ar, br = A[r, s], B[r, s]
            ys, yv = Y[s], Y[nd + s]
            for j in range(m):
                o[j] -= ar * ys[j] + br * yv[j]
    for e in range(ne):
        c = cf[1, e]
        k = cf[2, e] if reg[e] != 0 else 0.0
        acc[:] = 0.0
        b[:] = 0.0
        for q in range(vp[e], vp[e + 1]):
            s = vi[q]
            v = V[e, s]
            ys, yv = Y[s], Y[nd + s]
            for j in range(m):
                acc[j] += v * ys[j]
                b[j] += v * yv[j]
        for j in range(m):
            acc[j] = k * acc[j] + c * b[j]
        for q in range(wp[e], wp[e + 1]):
            r = wi[q]
            w = W[e, r]
            o = out[r]
            for j in range(m):
                o[j] -= w * acc[j]
    for b in range(bq.shape[0]):  # the bearing's 2×2 stiffness at the stage's state xs, its dampers cx, cy
        e = bx[b]
        dx, dy = _bearing_rows(xs, V, vp, vi, e, 0)
        kxx, kxy, kyy = bearing_slopes(dx, dy, cf[5, b], bq, b)
        vy[3:] = 0.0
        for k in range(2):
            for q in range(vp[e + k], vp[e + k + 1]):
                s = vi[q]
                v = V[e + k, s]
                for j in range(m):
                    vy[3 + k, j] += v * Y[s, j]
                    vy[5 + k, j] += v * Y[nd + s, j]
        for r in range(nd):
            wx, wy = W[e, r], W[e + 1, r]
            if wx != 0.0 or wy != 0.0:
                for j in range(m):
                    fx = kxx * vy[3, j] + kxy * vy[4, j] + bq[b, BQ_CX] * vy[5, j]
                    fy = kxy * vy[3, j] + kyy * vy[4, j] + bq[b, BQ_CY] * vy[6, j]
                    out[r, j] -= wx * fx + wy * fy


@njit(cache=True)
def _state_step(h, x, out, sv, system, c0, c1, c2, reg, stages):
    """One locked RK4 step of the state from ``x`` into ``out`` (sv[:5]: room); c0, c1, c2: the series at the step's
    start, middle and end; the stages' states into ``stages`` (for the bearings' stiffness of the tangent step)."""
    n2, (k1, k2, k3, k4, tmp) = x.shape[0], (sv[0], sv[1], sv[2], sv[3], sv[4])
    stages[0] = x
    _state_rhs(x, k1, system, c0, reg)
    for r in range(n2):
        tmp[r] = x[r] + 0.5 * h * k1[r]
    stages[1] = tmp
    _state_rhs(tmp, k2, system, c1, reg)
    for r in range(n2):
        tmp[r] = x[r] + 0.5 * h * k2[r]
    stages[2] = tmp
    _state_rhs(tmp, k3, system, c1, reg)
    for r in range(n2):
        tmp[r] = x[r] + h * k3[r]
    stages[3] = tmp
    _state_rhs(tmp, k4, system, c2, reg)
    for r in range(n2):
        out[r] = x[r] + h / 6.0 * (k1[r] + 2.0 * k2[r] + 2.0 * k3[r] + k4[r])


@njit(cache=True)
def _tangent_step(h, Yp, system, c0, c1, c2, reg, vy, stages):
    """One locked RK4 step of the fundamental matrix Yp[0] in place (a bearing's stiffness at the state's ``stages``):
    the stages' sum accumulated in ``Yn`` as each stage's rate is known, the next stage's columns in ``Ys``."""
    (Y, Yn, Ys, F), inv_nu = (Yp[0], Yp[1], Yp[2], Yp[3]), system[6]
    n2, m = Y.shape
    nd = n2 // 2
    _tangent_rhs(Y, F, system, c0, reg, vy, stages[0])
    for r in range(nd):
        yq, yv, nq, nv, sq, sv, f = Y[r], Y[nd + r], Yn[r], Yn[nd + r], Ys[r], Ys[nd + r], F[r]
        for j in range(m):
            kq, kv = yv[j] * inv_nu, f[j] * inv_nu
            nq[j] = yq[j] + h / 6.0 * kq
            nv[j] = yv[j] + h / 6.0 * kv
            sq[j] = yq[j] + 0.5 * h * kq
            sv[j] = yv[j] + 0.5 * h * kv
    for stage in range(1, 3):
        _tangent_rhs(Ys, F, system, c1, reg, vy, stages[stage])
        a = 0.5 * h if stage == 1 else h
        for r in range(nd):
            yq, yv, nq, nv, sq, sv, f = Y[r], Y[nd + r], Yn[r], Yn[nd + r], Ys[r], Ys[nd + r], F[r]
            for j in range(m):
                kq, kv = sv[j] * inv_nu, f[j] * inv_nu
                nq[j] += h / 3.0 * kq
                nv[j] += h / 3.0 * kv
                sq[j] = yq[j] + a * kq
                sv[j] = yv[j] + a * kv
    _tangent_rhs(Ys, F, system, c2, reg, vy, stages[3])
    for r in range(nd):
        yq, yv, nq, nv, sv, f = Y[r], Y[nd + r], Yn[r], Yn[nd + r], Ys[nd + r], F[r]
        for j in range(m):
            yq[j] = nq[j] + h / 6.0 * (sv[j] * inv_nu)
            yv[j] = nv[j] + h / 6.0 * (f[j] * inv_nu)


@njit(cache=True)
def monodromy_kernel(x, Y, A, B, W, V, sp, Cz, Lc, Kz, Lk, Ez, dEz, Le, Gz, Lg, D, hmax, nu, tol, bq, bx, stride):
    """Advance the state ``x`` (2n) and the columns ``Y`` (2n, m) in place over φ ∈ [0, 2π], the columns a step per
    ``stride`` of the state's, ending early at a contact switch (``stride`` > 1 without rolling bearings only);
    returns (steps, switches) taken, or (−1, switches) if the state stopped being finite."""
    n2, m, ne, inv_nu = x.shape[0], Y.shape[1], W.shape[0], 1.0 / nu
    mp = m if m < LANES else -(-m // LANES) * LANES  # the columns padded with zeros to whole vectors (no remainder)
    Yp = np.zeros((4, n2, mp))  # the columns, the stages' sum and two stages' columns
    Yp[0, :, :m] = Y
    sv, cv, vy = np.empty((7, n2)), np.empty((6, 6, max(A.shape[0], ne))), np.empty((7, mp))
    stages = np.empty((4, n2))
    xe, xt = sv[5], sv[6]  # (sv[:5]: the state step's room)
    series, system = (Cz, Lc, Kz, Lk, Ez, dEz, Le, Gz, Lg, bq), (A, B, W, V, sp, D, inv_nu, nu, bq, bx)
    c0, c1, c2, t1, t2, tc = cv[0], cv[1], cv[2], cv[3], cv[4], cv[5]  # tc: the columns' step start
    trig = np.empty((2, 1 + max(Cz.shape[1], Kz.shape[1], Ez.shape[1], Gz.shape[1]) // 2))
    reg = np.empty(ne, dtype=np.int64)
    _coefficients(0.0, series, c0, trig)
    for e in range(ne):
        reg[e] = _region(_deflection(x, e, V, sp[2], sp[3], c0), D[e])
    tc[:] = c0
    end, phi, steps, switches, start_known, tphi, pending = 2.0 * math.pi, 0.0, 0, 0, False, 0.0, 0
    while phi < end:
        h = min(hmax, end - phi)
        if end - (phi + h) < 1e-12 * end:
            h = end - phi
        if not start_known:  # (else the last step's end)
            _coefficients(phi, series, c0, trig)
        _coefficients(phi + 0.5 * h, series, c1, trig)
        _coefficients(phi + h, series, c2, trig)
        _state_step(h, x, xe, sv, system, c0, c1, c2, reg, stages)
        for r in range(n2):
            if not math.isfinite(xe[r]):
                return -1, switches
        # the earliest element whose region changed: the step is cut at its boundary
        first, hs, level_first = -1, h, 0.0
        for e in range(ne):
            if D[e] == 0.0:
                continue
            d1 = _deflection(xe, e, V, sp[2], sp[3], c2)
            if _region(d1, D[e]) == reg[e]:
                continue
            d0 = _deflection(x, e, V, sp[2], sp[3], c0)
            level = reg[e] * D[e] if reg[e] != 0 else (D[e] if d1 > D[e] else -D[e])
            a, fa, b, fb = 0.0, d0 - level, h, d1 - level
            side, c = 0, (b if (fa > 0.0) != (fb > 0.0) else 0.0)  # (no bracket: on or past its boundary already)
            for _it in range(SWITCH_MAX_ITER if c > 0.0 else 0):
                c = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
                if not (a < c < b):
                    c = 0.5 * (a + b)
                _coefficients(phi + 0.5 * c, series, t1, trig)
                _coefficients(phi + c, series, t2, trig)
                _state_step(c, x, xt, sv, system, c0, t1, t2, reg, stages)
                fc = _deflection(xt, e, V, sp[2], sp[3], t2) - level
                if fc == 0.0 or b - a <= tol * (1.0 + phi):
                    break
                if (fc > 0.0) == (fa > 0.0):
                    a, fa = c, fc
                    if side == -1:
                        fb *= 0.5
                    side = -1
                else:
                    b, fb = c, fc
                    if side == 1:
                        fa *= 0.5
                    side = 1
            if c < hs:
                first, hs, level_first = e, c, level
        if first < 0 or hs > 1e-13 * end:  # (else on the boundary already: only the region changes)
            if first >= 0:
                _coefficients(phi + 0.5 * hs, series, c1, trig)
                _coefficients(phi + hs, series, c2, trig)
                _state_step(hs, x, xe, sv, system, c0, c1, c2, reg, stages)
            if stride == 1:
                _tangent_step(hs, Yp, system, c0, c1, c2, reg, vy, stages)
            for r in range(n2):
                x[r] = xe[r]
            phi += hs  # (h when no element changed region)
            steps += 1
            pending += 1
            c0, c2 = c2, c0
        start_known = first < 0 or hs > 1e-13 * end
        if stride > 1 and pending > 0 and (pending == stride or first >= 0 or phi >= end):
            # the columns' step over the state's last steps, before any region changes (c0: the series at φ)
            hc = phi - tphi
            _coefficients(tphi + 0.5 * hc, series, t1, trig)
            _tangent_step(hc, Yp, system, tc, t1, c0, reg, vy, stages)
            tc[:] = c0
            tphi, pending = phi, 0
        if first >= 0:
            # the element crossed its boundary: into the gap from a contact, or into the contact at that level
            reg[first] = 0 if reg[first] != 0 else (1 if level_first > 0.0 else -1)
            switches += 1
            if switches > MAX_SWITCHES:
                return -1, switches
    Y[:] = Yp[0, :, :m]
    return steps, switches
