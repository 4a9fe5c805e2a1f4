"""Arithmetic of the N-DOF kernel: coefficients, the vector field, RK4 of the state and of tangents.

The system (non-dimensional, see :mod:`geardyn.systems.assemble`) in first-order form, state
``x = (q, q')`` of length 2n::

    q'' = g − A q − B q' − Σ_m W[m] s_m − Σ_c Wc[c] s_c,
    s_m = C_m(θ) δ_m' + K_m(θ) f(δ_m; D_m),     δ_m = V[m]·q − E_m(θ),  δ_m' = V[m]·q' − ω E_m'(θ),
    s_c = cc_c δ_c' + kc_c f(δ_c; Dc_c),          δ_c = Vc[c]·q,

with ``A = M̃⁻¹K̃_b``, ``B = M̃⁻¹C̃_b``, ``W[m] = M̃⁻¹V[m]``, ``Wc[c] = M̃⁻¹Vc[c]``, ``g = M̃⁻¹F̃`` formed once
per batch by the caller.  ``mode`` arrays select, per element, the dead zone (``LOCK_FREE``) or
one branch of it locked (``-1, 0, +1``: back contact, separation, drive contact) for the
accurate mode's sub-steps.

Sparse storage (:func:`geardyn._kernel_ndof.sparse_arrays`): the matrices are kept by their nonzeros only, in
two tuples per point,

``sp = (abp, abj, Av, Bv, ep, ej, Ev, wp, wi, Wv, g)``
    rows of A and B in compressed-row form over the union of their patterns (row i: columns
    ``abj[abp[i]:abp[i+1]]`` ascending, values ``Av``, ``Bv``); the element vectors V[m] then Vc[c] as rows
    ``ej[ep[e]:ep[e+1]]`` (values ``Ev``); the element forces' rows W[m] then Wc[c] (``wi[wp[e]:wp[e+1]]``,
    values ``Wv``); g dense;
``el = (M, D, kc, cc, Dc, bq)``
    the meshes' count and half backlashes, the clearances' stiffness, damping and half gaps, and the rolling
    bearings' parameters ``bq`` (bearings, 8) (:data:`BQ_Z` … :data:`BQ_PHASE`).

Rolling-element bearings (the second element law, :class:`geardyn.system.RollingBearingLaw`): bearing b is the two
element rows ``ex = M + C + 2b`` (its x vector V_x and force row W_x) and ``ey = ex + 1`` (y), after the meshes and
the C clearances.  Their forces are computed jointly from (δ_x, δ_y),

    s_x = cx δ_x' + K Σ_j max(δ_j, 0)^n cos ψ_j,   s_y = cy δ_y' + K Σ_j max(δ_j, 0)^n sin ψ_j,
    δ_j = δ_x cos ψ_j + δ_y sin ψ_j − c,   ψ_j = ψ(θ) + φ0 + 2πj/Z,

with the cage angle ψ(θ) = ρ θ (ρ the cage's radians per radian of the base angle) in row M + b of the
coefficients (:func:`coef_at`, which fills rows M … of ``out`` from ``ratio[M + b]`` = ρ_b).  The Jacobian adds the
2×2 cross terms: the slopes ``gk`` hold one slot per element row, then two per bearing (``E + 2b``: ∂s_x/∂δ_y,
``E + 2b + 1``: ∂s_y/∂δ_x, E the element rows), so ``gk`` and ``gc`` have E + 2B entries (:func:`tan_free` reads B
from that length).  Without bearings every loop below is the one it was, term by term.

Every sum runs over the same terms in the same order as the dense sums it replaces, the zero terms left out
(adding a product with a zero factor changes no finite value), so the state's arithmetic is the dense one's,
bit for bit; so is the tangent's, whose Jacobian is formed on its sparse pattern (:func:`jac_values`).
"""

from __future__ import annotations

import math

from numba import njit

# The layout of the per-element statistics (sampled at every step end of the recorded periods), the tangent modes,
# the statuses and the divergence bound are the 1-DOF kernel's, as is its dead zone.
from .._kernel.core import (  # noqa: F401
    DIVERGENCE_BOUND,
    NSTAT,
    S_N,
    S_NBACK,
    S_NDRIVE,
    S_NSEP,
    S_UMAX,
    S_UMIN,
    S_USQ,
    S_USUM,
    S_VMAX,
    S_VMIN,
    ST_DIVERGED,
    ST_OK,
    TAN_LYAPUNOV,
    TAN_MONODROMY,
    TAN_NONE,
    _fz,
)

#: Mode value of an element whose dead zone is evaluated as it is (default mode).
LOCK_FREE = 2
#: Columns of a bearing's parameter row ``bq[b]``: elements Z, load–deflection constant K̃, exponent n, radial
#: clearance c̃, dampings cx̃, cỹ, cage radians per base radian ρ, cage phase φ0 (rad).
BQ_Z, BQ_K, BQ_N, BQ_C, BQ_CX, BQ_CY, BQ_RHO, BQ_PHASE = range(8)


@njit(inline="always")
def _flock(u, D, mode):
    """Dead zone, or its branch ``mode`` (−1: u + D, 0: 0, +1: u − D)."""
    if mode == LOCK_FREE:
        return _fz(u, D)
    if mode == 1:
        return u - D
    if mode == -1:
        return u + D
    return 0.0


@njit(inline="always")
def _slope(u, D, mode):
    """f'(u) for the branch in use (1 in contact, 0 in separation; D = 0: always 1)."""
    if mode == LOCK_FREE:
        return 1.0 if (D == 0.0 or abs(u) > D) else 0.0
    return 0.0 if mode == 0 else 1.0


@njit(nogil=True)
def coef_at(coef, ratio, theta, out):
    """C_m, K_m, E_m, E_m' (= dE_m/dθ) of every mesh at the base angle θ into out[m, 0:4]; then, for rows
    M + b of ``out`` (bearings), the cage angle ``ratio[M + b] θ`` into out[M + b, 0]."""
    M = coef.shape[0]
    H = coef.shape[2] - 1
    for m in range(M):
        ph = ratio[m] * theta
        c0 = coef[m, 0, 0, 0]
        k0 = coef[m, 1, 0, 0]
        e0 = coef[m, 2, 0, 0]
        ed = 0.0
        for j in range(1, H + 1):
            cj = math.cos(j * ph)
            sj = math.sin(j * ph)
            c0 += coef[m, 0, j, 0] * cj + coef[m, 0, j, 1] * sj
            k0 += coef[m, 1, j, 0] * cj + coef[m, 1, j, 1] * sj
            e0 += coef[m, 2, j, 0] * cj + coef[m, 2, j, 1] * sj
            ed += j * ratio[m] * (coef[m, 2, j, 1] * cj - coef[m, 2, j, 0] * sj)
        out[m, 0] = c0
        out[m, 1] = k0
        out[m, 2] = e0
        out[m, 3] = ed
    for b in range(M, out.shape[0]):  # rolling bearings: the cage angle ρ_b θ
        out[b, 0] = ratio[b] * theta


@njit(nogil=True, inline="always")
def _element_force(e, d, dv, cf, el, mode):
    """The force s_e of element e (a mesh or a clearance) at its (δ, δ') (meshes: δ without E_m)."""
    M, D, kc, cc, Dc = el[0], el[1], el[2], el[3], el[4]
    if e < M:
        d -= cf[e, 2]
        return cf[e, 0] * dv + cf[e, 1] * _flock(d, D[e], mode[e])
    c = e - M
    return cc[c] * dv + kc[c] * _flock(d, Dc[c], mode[e])


@njit(nogil=True, inline="always")
def _row(ep, ej, Ev, x, vo, e):
    """(V[e]·q̃, V[e]·q̃') of element row e; q̃ = x[0:n], q̃' = x[vo:vo+n]."""
    d = 0.0
    dv = 0.0
    for k in range(ep[e], ep[e + 1]):
        j = ej[k]
        d += Ev[k] * x[j]
        dv += Ev[k] * x[vo + j]
    return d, dv


@njit(nogil=True, inline="always")
def bearing_force(dx, dy, vx, vy, psi, bq, b):
    """(s_x, s_y) of bearing b at (δ_x, δ_y), rates (vx, vy), cage angle ψ (see the module docstring)."""
    Z = int(bq[b, BQ_Z])
    K = bq[b, BQ_K]
    n = bq[b, BQ_N]
    c = bq[b, BQ_C]
    a0 = psi + bq[b, BQ_PHASE]
    step = 2.0 * math.pi / Z
    fx = 0.0
    fy = 0.0
    for j in range(Z):
        a = a0 + step * j
        ca = math.cos(a)
        sa = math.sin(a)
        d = dx * ca + dy * sa - c
        if d > 0.0:
            f = K * d**n
            fx += f * ca
            fy += f * sa
    return bq[b, BQ_CX] * vx + fx, bq[b, BQ_CY] * vy + fy


@njit(nogil=True, inline="always")
def bearing_slopes(dx, dy, psi, bq, b):
    """(k_xx, k_xy, k_yy) = ∂(s_x, s_y)/∂(δ_x, δ_y) of bearing b (the damping's slopes are cx, cy)."""
    Z = int(bq[b, BQ_Z])
    K = bq[b, BQ_K]
    n = bq[b, BQ_N]
    c = bq[b, BQ_C]
    a0 = psi + bq[b, BQ_PHASE]
    step = 2.0 * math.pi / Z
    kxx = 0.0
    kxy = 0.0
    kyy = 0.0
    for j in range(Z):
        a = a0 + step * j
        ca = math.cos(a)
        sa = math.sin(a)
        d = dx * ca + dy * sa - c
        if d > 0.0:
            w = K * n * d ** (n - 1.0)
            kxx += w * ca * ca
            kxy += w * ca * sa
            kyy += w * sa * sa
    return kxx, kxy, kyy


@njit(nogil=True, inline="always")
def _bearing_slots(sp, el, cf, q, vo, gk, gc):
    """The slopes of every bearing at (q̃, q̃') into gk, gc (its rows' and its two cross slots)."""
    ep, ej, Ev = sp[4], sp[5], sp[6]
    M = el[0]
    bq = el[5]
    E = ep.shape[0] - 1
    e0 = M + el[4].shape[0]
    for b in range(bq.shape[0]):
        ex = e0 + 2 * b
        dx, vx = _row(ep, ej, Ev, q, vo, ex)
        dy, vy = _row(ep, ej, Ev, q, vo, ex + 1)
        kxx, kxy, kyy = bearing_slopes(dx, dy, cf[M + b, 0], bq, b)
        gk[ex] = kxx
        gk[ex + 1] = kyy
        gk[E + 2 * b] = kxy
        gk[E + 2 * b + 1] = kxy
        gc[ex] = bq[b, BQ_CX]
        gc[ex + 1] = bq[b, BQ_CY]
        gc[E + 2 * b] = 0.0
        gc[E + 2 * b + 1] = 0.0


@njit(nogil=True, inline="always")
def _bearing_forces(sp, el, cf, q, v, s):
    """The forces s[ex], s[ey] of every bearing at (q̃, q̃') = (q[0:n], v[0:n])."""
    ep, ej, Ev = sp[4], sp[5], sp[6]
    M = el[0]
    bq = el[5]
    e0 = M + el[4].shape[0]
    for b in range(bq.shape[0]):
        ex = e0 + 2 * b
        dx = 0.0
        vx = 0.0
        for k in range(ep[ex], ep[ex + 1]):
            j = ej[k]
            dx += Ev[k] * q[j]
            vx += Ev[k] * v[j]
        dy = 0.0
        vy = 0.0
        for k in range(ep[ex + 1], ep[ex + 2]):
            j = ej[k]
            dy += Ev[k] * q[j]
            vy += Ev[k] * v[j]
        sx, sy = bearing_force(dx, dy, vx, vy, cf[M + b, 0], bq, b)
        s[ex] = sx
        s[ex + 1] = sy


@njit(nogil=True)
def field(x, cf, sp, el, omega, mode, out):
    """out = x' at coefficients cf (meshes, 4); ``mode`` per element (meshes then clearances)."""
    abp, abj, Av, Bv, ep, ej, Ev, wp, wi, Wv, g = sp
    M = el[0]
    n = g.shape[0]
    for i in range(n):
        out[i] = x[n + i]
    for i in range(n):
        acc = g[i]
        for k in range(abp[i], abp[i + 1]):
            j = abj[k]
            acc -= Av[k] * x[j] + Bv[k] * x[n + j]
        out[n + i] = acc
    bq = el[5]
    e0 = M + el[4].shape[0]
    for e in range(e0):
        d = 0.0
        dv = 0.0
        for k in range(ep[e], ep[e + 1]):
            j = ej[k]
            d += Ev[k] * x[j]
            dv += Ev[k] * x[n + j]
        if e < M:
            dv -= omega * cf[e, 3]
        s = _element_force(e, d, dv, cf, el, mode)
        for k in range(wp[e], wp[e + 1]):
            out[n + wi[k]] -= Wv[k] * s
    for b in range(bq.shape[0]):
        ex = e0 + 2 * b
        dx, vx = _row(ep, ej, Ev, x, n, ex)
        dy, vy = _row(ep, ej, Ev, x, n, ex + 1)
        sx, sy = bearing_force(dx, dy, vx, vy, cf[M + b, 0], bq, b)
        for k in range(wp[ex], wp[ex + 1]):
            out[n + wi[k]] -= Wv[k] * sx
        for k in range(wp[ex + 1], wp[ex + 2]):
            out[n + wi[k]] -= Wv[k] * sy


@njit(nogil=True)
def slopes(x, cf, sp, el, mode, gk, gc):
    """d s_e/dδ_e and d s_e/dδ_e' of every element at x into gk, gc (bearings: also their cross slots)."""
    abp, abj, Av, Bv, ep, ej, Ev, wp, wi, Wv, g = sp
    M, D, kc, cc, Dc = el[0], el[1], el[2], el[3], el[4]
    e0 = M + Dc.shape[0]
    for e in range(e0):
        d = -cf[e, 2] if e < M else 0.0
        for k in range(ep[e], ep[e + 1]):
            d += Ev[k] * x[ej[k]]
        if e < M:
            gk[e] = cf[e, 1] * _slope(d, D[e], mode[e])
            gc[e] = cf[e, 0]
        else:
            c = e - M
            gk[e] = kc[c] * _slope(d, Dc[c], mode[e])
            gc[e] = cc[c]
    _bearing_slots(sp, el, cf, x, g.shape[0], gk, gc)


@njit(nogil=True)
def jac_values(sp, jt, gk, gc, Gq, Gv):
    """The Jacobian's lower blocks on their sparse pattern: q''-part = −Gq dq − Gv dq'.

    ``jt = (gp, gj, Ag, Bg, cp, ce, cw, cv)``: entry k of the pattern (row i, column ``gj[k]``) starts from
    A[i, j] (``Ag[k]``), B[i, j], and adds ``gk[e] W[e, i] V[e, j]`` for its elements e = ``ce[l]`` ascending
    (l = cp[k] … cp[k+1]−1; ``cw``, ``cv`` the indices of W[e, i] and V[e, j] in ``Wv``, ``Ev``): the dense
    Jacobian's sums, term by term, without its zero terms."""
    Ev, Wv = sp[6], sp[9]
    gp, gj, Ag, Bg, cp, ce, cw, cv = jt
    for k in range(gj.shape[0]):
        a = Ag[k]
        b = Bg[k]
        for m in range(cp[k], cp[k + 1]):
            e = ce[m]
            wv = Wv[cw[m]]
            vv = Ev[cv[m]]
            a += gk[e] * wv * vv
            b += gc[e] * wv * vv
        Gq[k] = a
        Gv[k] = b


@njit(nogil=True)
def tan_field(Y, jt, Gq, Gv, out):
    """out = J Y for the tangent columns Y (2n, k), the Jacobian's values Gq, Gv of :func:`jac_values`."""
    gp = jt[0]
    gj = jt[1]
    n = gp.shape[0] - 1
    for c in range(Y.shape[1]):
        for i in range(n):
            out[i, c] = Y[n + i, c]
        for i in range(n):
            acc = 0.0
            for k in range(gp[i], gp[i + 1]):
                j = gj[k]
                acc += Gq[k] * Y[j, c] + Gv[k] * Y[n + j, c]
            out[n + i, c] = -acc


@njit(nogil=True, inline="always")
def tan_free(Y, sp, gk, gc, out):
    """out = J Y for a few tangent columns Y (2n, k) without forming J: the rows of A and B, then every element's
    W[e] (gk[e] V[e]·y + gc[e] V[e]·y') (the leading exponents' products; their sums run in another order than
    :func:`tan_field`'s)."""
    abp, abj, Av, Bv, ep, ej, Ev, wp, wi, Wv, g = sp
    n = g.shape[0]
    E = ep.shape[0] - 1
    B2 = gk.shape[0] - E  # two cross slots per bearing
    e0 = E - B2
    for c in range(Y.shape[1]):
        for i in range(n):
            out[i, c] = Y[n + i, c]
        for i in range(n):
            acc = 0.0
            for k in range(abp[i], abp[i + 1]):
                j = abj[k]
                acc += Av[k] * Y[j, c] + Bv[k] * Y[n + j, c]
            out[n + i, c] = -acc
        for e in range(e0):
            pq = 0.0
            pv = 0.0
            for k in range(ep[e], ep[e + 1]):
                j = ej[k]
                pq += Ev[k] * Y[j, c]
                pv += Ev[k] * Y[n + j, c]
            t = gk[e] * pq + gc[e] * pv
            for k in range(wp[e], wp[e + 1]):
                out[n + wi[k], c] -= Wv[k] * t
        for b in range(B2 // 2):
            ex = e0 + 2 * b
            qx = 0.0
            vx = 0.0
            for k in range(ep[ex], ep[ex + 1]):
                j = ej[k]
                qx += Ev[k] * Y[j, c]
                vx += Ev[k] * Y[n + j, c]
            qy = 0.0
            vy = 0.0
            for k in range(ep[ex + 1], ep[ex + 2]):
                j = ej[k]
                qy += Ev[k] * Y[j, c]
                vy += Ev[k] * Y[n + j, c]
            tx = gk[ex] * qx + gk[E + 2 * b] * qy + gc[ex] * vx
            ty = gk[ex + 1] * qy + gk[E + 2 * b + 1] * qx + gc[ex + 1] * vy
            for k in range(wp[ex], wp[ex + 1]):
                out[n + wi[k], c] -= Wv[k] * tx
            for k in range(wp[ex + 1], wp[ex + 2]):
                out[n + wi[k], c] -= Wv[k] * ty


@njit(nogil=True)
def gram_schmidt(Y, logs):
    """Modified Gram–Schmidt on the columns of Y in place; logs[k] = log r_kk."""
    d, k = Y.shape
    for c in range(k):
        for b in range(c):
            r = 0.0
            for i in range(d):
                r += Y[i, b] * Y[i, c]
            for i in range(d):
                Y[i, c] -= r * Y[i, b]
        r = 0.0
        for i in range(d):
            r += Y[i, c] * Y[i, c]
        r = math.sqrt(r)
        logs[c] = math.log(r)
        for i in range(d):
            Y[i, c] /= r


@njit(nogil=True)
def diverged_state(x):
    for i in range(x.shape[0]):
        if not (abs(x[i]) <= DIVERGENCE_BOUND):
            return True
    return False


@njit(nogil=True, inline="always")
def element_values(q, v, vo, cf, sp, el, omega, out):
    """δ, δ' of every element (meshes then clearances) into out[e, 0:2]; q̃ = q[0:n], q̃' = v[vo:vo+n]."""
    ep, ej, Ev = sp[4], sp[5], sp[6]
    M = el[0]
    for e in range(ep.shape[0] - 1):
        if e < M:
            d = -cf[e, 2]
            dv = -omega * cf[e, 3]
        else:
            d = 0.0
            dv = 0.0
        for k in range(ep[e], ep[e + 1]):
            j = ej[k]
            d += Ev[k] * q[j]
            dv += Ev[k] * v[vo + j]
        out[e, 0] = d
        out[e, 1] = dv


@njit(nogil=True, inline="always")
def accumulate(st, ev, gaps):
    """Add one sample of every element's (δ, δ') to its statistics row st[e]."""
    for e in range(ev.shape[0]):
        d = ev[e, 0]
        dv = ev[e, 1]
        if st[e, S_N] == 0.0:
            st[e, S_UMIN] = d
            st[e, S_UMAX] = d
            st[e, S_VMIN] = dv
            st[e, S_VMAX] = dv
        else:
            st[e, S_UMIN] = min(st[e, S_UMIN], d)
            st[e, S_UMAX] = max(st[e, S_UMAX], d)
            st[e, S_VMIN] = min(st[e, S_VMIN], dv)
            st[e, S_VMAX] = max(st[e, S_VMAX], dv)
        st[e, S_USUM] += d
        st[e, S_USQ] += d * d
        D = gaps[e]
        if D == 0.0:
            st[e, S_NDRIVE] += 1.0
        elif d > D:
            st[e, S_NDRIVE] += 1.0
        elif d < -D:
            st[e, S_NBACK] += 1.0
        else:
            st[e, S_NSEP] += 1.0
        st[e, S_N] += 1.0
