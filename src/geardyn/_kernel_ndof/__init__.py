"""The N-DOF integrator kernel: numba functions on the arrays of :meth:`geardyn.systems.SystemModel.pack`.

Only :mod:`geardyn.backend` (its ``MESH`` backend, behind :mod:`geardyn.integrate`) imports this package, and the
harmonic-balance monodromy kernel its rolling bearing's force and stiffness (:func:`.core.bearing_force`,
:func:`.core.bearing_slopes`).
:func:`run_batch` advances a batch of parameter points of one system structure through
``n_transient + n_record`` forcing periods with classic fixed-step RK4 (h = T_f/N, T_f the forcing period, so the
stroboscopic samples are exact) and serves every analysis: Poincaré points of the full state, streaming statistics
per element (each mesh's deflection δ_m = V[m]·q̃ − E_m(θ), then each clearance's, then each rolling bearing's x
and y rows: :mod:`.core`), time histories, Lyapunov
spectra (all 2n tangent vectors, or the k leading ones, Gram–Schmidt each recorded period) and monodromy matrices.
The accurate mode splits every step at each dead zone's contact boundary (δ = ±D) inside it (a rolling bearing is
smooth: no split, :mod:`.step`).  A batch with rolling bearings takes the sparse plain step (not the dense one).
Torque orders make the load time-varying: g = M̃⁻¹F̃ becomes g + Σ_o M̃⁻¹F̃_o cos(r_o θ + φ_o), refilled before
each RK4 stage (:func:`.step.load_at`); a system without orders keeps g as it is, bit for bit.

Sparse: the cost of a step follows the nonzeros, not n².  :func:`sparse_arrays` keeps A, B, the element vectors
and their force rows by their nonzeros (the union of the batch's patterns; :mod:`.core` lists the layout), and
forms the Jacobian only on its pattern.  Every sum keeps the dense order without its zero terms, so the numbers are
those of the dense kernel, bit for bit.  The k < 2n leading tangent vectors of a classification take their
Jacobian-vector products straight from the sparse rows (:func:`.core.tan_free`) beside the plain step.

The default mode's plain step (no tangents) keeps the state in a padded layout and advances blocks of
``LANE_BLOCK`` rows as SIMD vectors over the diagonals a block touches only (:mod:`.simd`), diagonal by diagonal:
each row meets its columns in the order of the row-by-row :func:`.core.field`, so bit-identical.  The element
forces (and the statistics' deflections) of the meshes and clearances are computed ``LANE_BLOCK`` elements at a
time, their terms gathered (:func:`.simd.forces_group`), each element's sums in their scalar order.  A system of
one block (n <= LANE_BLOCK) takes the dense step of :mod:`.dense`, for which index lists cost more than they
save.

Layout: :mod:`.core` (vector field, Jacobian, statistics), :mod:`.step` (RK4 step, split steps,
the plain step), :mod:`.simd` (one stage of the plain step on a block of rows, as LLVM vectors), :mod:`.dense`,
:mod:`.worker` (one point at a time from a shared queue; ``nogil``, ``cache=True``).  Threads: the
1-DOF kernel's pool (:func:`geardyn._kernel._run_workers`), as many workers as numba's thread setting.
numba keys a cache entry on the worker's source file only, so this package calls
:func:`geardyn._cache_guard.refresh` first: a change to any of its sources recompiles the workers.
"""

from __future__ import annotations

from .._cache_guard import fast_loads as _fast_loads
from .._cache_guard import refresh as _refresh_cache

_refresh_cache(__file__)  # before the cached workers are imported (see geardyn._cache_guard)

import numpy as np

from .._kernel import _queue_order, _run_workers, n_threads
from .core import BQ_RHO, NSTAT, TAN_LYAPUNOV, TAN_MONODROMY, TAN_NONE
from .simd import LANE_BLOCK
from .worker import ndof_worker

_fast_loads(ndof_worker)  # read from numba's cache without setting up its compiler (see geardyn._cache_guard)

__all__ = ["run_batch", "n_threads", "NSTAT", "TAN_NONE", "TAN_LYAPUNOV", "TAN_MONODROMY", "THREAD_MIN_WORK"]

#: Batches with less work than this (RK4 steps × the plain step's multiply-adds) run on the calling thread only.
THREAD_MIN_WORK = 2_000_000


def derived(arrays):
    """(A, B, W, g, Wc) = (M̃⁻¹K̃_b, M̃⁻¹C̃_b, rows M̃⁻¹V[m], M̃⁻¹F̃, rows M̃⁻¹Vc[c]) of packed arrays."""
    Mi = arrays.Mi
    c = np.ascontiguousarray
    A = c(Mi @ arrays.Kb)
    B = c(Mi @ arrays.Cb)
    g = c(np.einsum("pij,pj->pi", Mi, arrays.F))
    return A, B, _times_rows(Mi, arrays.V), g, _times_rows(Mi, arrays.Vc)


def _times_rows(Mi, V):
    """The rows M̃⁻¹V[m] of a (P, rows, n) stack of row vectors."""
    return np.ascontiguousarray(np.einsum("pij,pmj->pmi", Mi, V))


def order_loads(arrays):
    """(go, ro, po): the torque orders' load rows M̃⁻¹F̃_o (P, orders, n), their frequencies over ω and phases
    (P, orders): g(θ) = g + Σ_o go[o] cos(ro[o] θ + po[o])."""
    c = np.ascontiguousarray
    return _times_rows(arrays.Mi, arrays.Fo), c(arrays.ro, dtype=np.float64), c(arrays.po, dtype=np.float64)


def _rows(mask):
    """Compressed rows of a boolean (R, C) pattern: (row pointers (R+1,), column indices ascending, the row of each
    entry)."""
    ptr = np.zeros(mask.shape[0] + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(mask.sum(axis=1))
    rows, cols = np.nonzero(mask)
    return ptr, np.ascontiguousarray(cols.astype(np.int64)), rows


def sparse_arrays(arrays):
    """The kernel's sparse arrays of a packed batch (the patterns: the union over its points).

    Returns
    -------
    sp : tuple
        ``(abp, abj, Av, Bv, ep, ej, Ev, wp, wi, Wv, g)`` (values with a leading point axis; see
        :mod:`geardyn._kernel_ndof.core`).
    jt : tuple
        ``(gp, gj, Ag, Bg, cp, ce, cw, cv)``: the Jacobian's pattern (:func:`.core.jac_values`).
    blk : tuple
        ``(bcp, bcj, ATs, BTs, bep, bej, WTs, gPs, EI, EVs, margin)``: the plain step's blocks of ``LANE_BLOCK``
        rows; block b's diagonals ``bcj[bcp[b]:bcp[b+1]]`` (the offsets o = j − i, ascending, of its rows' entries
        of A or B) with the values ``ATs[p, k, r] = A[p, b·L + r, b·L + r + o]`` (zero outside the matrix;
        ``BTs`` alike), its elements ``bej[bep[b]:bep[b+1]]`` (those whose force reaches a row of the block) with
        ``WTs[p, k, r]`` the force row's entries, ``gPs`` g padded to a multiple of ``LANE_BLOCK`` (the padding
        zero); the meshes' and clearances' vectors L elements at a time (``EI[G, t, l]`` the column of term t of
        element G·L + l, ``EVs[p, G, t, l]`` its value; padding: column 0, value 0); ``margin`` the zero columns
        the padded state needs on either side (the largest offset, rounded up to ``LANE_BLOCK``).
    """
    A, B, W, g, Wc = derived(arrays)
    P, n = g.shape
    E_V = np.concatenate([arrays.V, arrays.Vc], axis=1)  # (P, E, n)
    E_W = np.concatenate([W, Wc], axis=1)
    NB = arrays.bq.shape[1]
    if NB:  # rolling bearings: two element rows each (x, y), after the meshes and clearances
        E_V = np.concatenate([E_V, arrays.Vb], axis=1)
        E_W = np.concatenate([E_W, _times_rows(arrays.Mi, arrays.Vb)], axis=1)
    NE = E_V.shape[1]
    ab = np.any(A != 0.0, axis=0) | np.any(B != 0.0, axis=0)
    abp, abj, rows_ab = _rows(ab)
    ev = np.any(E_V != 0.0, axis=0)
    ep, ej, rows_e = _rows(ev)
    ew = np.any(E_W != 0.0, axis=0)
    wp, wi, rows_w = _rows(ew)
    c = np.ascontiguousarray
    # the Jacobian's pattern: A and B, and W[e, i] V[e, j] of every element
    gmask = ab.copy()
    for e in range(ev.shape[0]):
        gmask |= np.outer(ew[e], ev[e])
    e0 = NE - 2 * NB
    cross = []  # (slot, force row, deflection row) of every bearing's cross terms W_x V_y, W_y V_x
    for b in range(NB):
        ex = e0 + 2 * b
        cross += [(NE + 2 * b, ex, ex + 1), (NE + 2 * b + 1, ex + 1, ex)]
    for _, ew_, ev_ in cross:
        gmask |= np.outer(ew[ew_], ev[ev_])
    gp, gj, rows_g = _rows(gmask)
    gidx = np.full((n, n), -1, dtype=np.int64)
    gidx[rows_g, gj] = np.arange(gj.shape[0])
    parts = []  # (entry, element or cross slot, index in Wv, index in Ev) of every product W[e, i] V[e, j]
    for slot, ew_, ev_ in [(e, e, e) for e in range(ev.shape[0])] + cross:
        kw = np.arange(wp[ew_], wp[ew_ + 1])
        kv = np.arange(ep[ev_], ep[ev_ + 1])
        KW, KV = np.meshgrid(kw, kv, indexing="ij")
        KW, KV = KW.ravel(), KV.ravel()
        parts.append(np.stack([gidx[wi[KW], ej[KV]], np.full(KW.shape, slot), KW, KV]))
    allp = np.concatenate(parts, axis=1) if parts else np.zeros((4, 0), dtype=np.int64)
    allp = allp[:, np.lexsort((allp[1], allp[0]))]
    cp = np.zeros(gj.shape[0] + 1, dtype=np.int64)
    cp[1:] = np.cumsum(np.bincount(allp[0], minlength=gj.shape[0]))
    jt = (gp, gj, c(A[:, rows_g, gj]), c(B[:, rows_g, gj]), cp, *c(allp[1:], dtype=np.int64))
    sp = (
        abp,
        abj,
        c(A[:, rows_ab, abj]),
        c(B[:, rows_ab, abj]),
        ep,
        ej,
        c(E_V[:, rows_e, ej]),
        wp,
        wi,
        c(E_W[:, rows_w, wi]),
        c(g),
    )
    L = LANE_BLOCK
    nb = -(-n // L)
    NP = nb * L
    pad = np.zeros((NP, n), dtype=bool)
    pad[:n] = ab
    # the blocks' diagonals: block b's offsets o = j − i of its nonzeros (i a row of the block), ascending, so that
    # every row meets its columns in ascending order; ATs[p, k, r] = A[p, b·L + r, b·L + r + o] (zero outside)
    bo = []
    for b in range(nb):
        r_, j_ = np.nonzero(pad[b * L : (b + 1) * L])
        bo.append(np.unique(j_ - (b * L + r_)))
    bcp = np.zeros(nb + 1, dtype=np.int64)
    bcp[1:] = np.cumsum([len(o) for o in bo])
    bcj = np.ascontiguousarray(np.concatenate(bo).astype(np.int64)) if nb else np.zeros(0, dtype=np.int64)
    bl = np.repeat(np.arange(nb), np.diff(bcp))
    ri = bl[:, None] * L + np.arange(L)[None, :]  # (terms, L) row of each lane
    ci = ri + bcj[:, None]  # its column
    inside = (ri < n) & (ci >= 0) & (ci < n)
    rr, cc_ = np.where(inside, ri, 0), np.where(inside, ci, 0)
    ATs, BTs = (c(np.where(inside[None], X[:, rr, cc_], 0.0)) for X in (A, B))
    margin = int(L * -(-int(np.max(np.abs(bcj), initial=0)) // L))
    Wp = np.zeros((P, ew.shape[0], NP))
    Wp[:, :, :n] = E_W
    wpad = np.zeros((ew.shape[0], NP), dtype=bool)
    wpad[:, :n] = ew
    emask = wpad.reshape(ew.shape[0], nb, L).any(axis=2).T  # (blocks, elements)
    bep, bej, be = _rows(emask)
    ri_e = be[:, None] * L + np.arange(L)[None, :]
    WTs = c(Wp[:, bej[:, None], ri_e])
    gPs = np.zeros((P, NP))
    gPs[:, :n] = g
    # the element forces of the meshes and clearances, L at a time (lane l of group G: element G·L + l): term t
    # of each, EI[G, t, l] its column, EVs[p, G, t, l] its value (padding: column 0, value 0, after the terms)
    e1 = NE - 2 * NB
    EG = -(-e1 // L)
    T = int(np.max(np.diff(ep[: e1 + 1]), initial=0))
    EI = np.zeros((EG, T, L), dtype=np.int64)
    EVs = np.zeros((P, EG, T, L))
    for e in range(e1):
        k = np.arange(ep[e], ep[e + 1])
        EI[e // L, : k.size, e % L] = ej[k]
        EVs[:, e // L, : k.size, e % L] = E_V[:, e, ej[k]]
    return sp, jt, (bcp, bcj, ATs, BTs, bep, bej, WTs, gPs, EI, EVs, margin)


def plain_cost(blk):
    """Multiply-adds of one evaluation of the plain step's accelerations (all blocks' diagonals and elements, all
    lanes)."""
    return LANE_BLOCK * (int(blk[1].shape[0]) + int(blk[5].shape[0]))


def run_batch(
    arrays,
    tperiod,
    nsteps,
    state0,
    n_transient,
    n_record,
    tangent,
    accurate,
    poincare,
    end_state,
    stats,
    tan_log,
    tan_out,
    status,
    hist,
    tangent0=None,
    rigid=None,
):
    """Advance a batch of P points of one system structure; results are written into the outputs.

    Parameters
    ----------
    arrays : geardyn.systems.SystemArrays
        Packed arrays (leading axis P), :meth:`SystemModel.pack`.
    tperiod : float64[P]
        Forcing period T_f per point (the sampling period).
    nsteps : int64[P]
        RK4 steps per forcing period; h = T_f/N.
    state0 : float64[P, 2n]
        Initial (q̃, q̃') at θ = 0.
    n_transient, n_record : int
        Forcing periods discarded, then recorded.
    tangent : int
        ``TAN_NONE``, ``TAN_LYAPUNOV`` (logs of the Gram–Schmidt diagonal into ``tan_log``) or
        ``TAN_MONODROMY`` (the raw tangent product over the recorded periods into ``tan_out``).
    accurate : bool
        Split steps at the contact boundaries.
    poincare : float64[P, n_record or 0, 2n]
        Out: state at the end of each recorded period.
    end_state : float64[P, 2n]
        Out: final state.
    stats : float64[P, elements, NSTAT]
        Out: statistics of every element's δ over the recorded periods.
    tan_log : float64[P, n_record or 0, k]
        Out (Lyapunov mode).
    tan_out : float64[P, 2n, k]
        Out: final tangent columns (k of them: the columns of ``tan_out``).
    status : int64[P]
        Out: ``ST_OK`` or ``ST_DIVERGED``.
    hist : float64[P, K, 2n]
        Out: if K > 0 the state at every step of the last (K − 1)/N periods.
    tangent0 : float64[P, 2n, k], optional
        The initial tangent columns (default the first k columns of the identity).
    rigid : float64[2n, r], optional
        Orthonormal columns spanning an invariant subspace (the rigid-body modes' positions and velocities) removed
        from the tangent columns before each Gram–Schmidt (Lyapunov mode): the exponents are then those of the
        dynamics modulo it.
    """
    P = arrays.Mi.shape[0]
    if P == 0:
        return
    sp, jt, blk = sparse_arrays(arrays)
    d = 2 * arrays.Mi.shape[1]
    k = int(tan_out.shape[2]) if tangent != TAN_NONE else 0
    if tangent0 is None:
        tangent0 = np.zeros((P, d, k))
        tangent0[:, np.arange(k), np.arange(k)] = 1.0
    tangent0 = np.ascontiguousarray(tangent0, dtype=np.float64)
    rigid = np.zeros((d, 0)) if rigid is None else np.ascontiguousarray(rigid, dtype=np.float64)
    order = _queue_order(nsteps)
    counter = np.zeros(1, dtype=np.int64)
    work = float(np.sum(nsteps)) * (int(n_transient) + int(n_record)) * plain_cost(blk)
    nw = min(n_threads(), P) if work >= THREAD_MIN_WORK else 1
    a = arrays
    loads = order_loads(arrays)
    NB = arrays.bq.shape[1]
    # one block of rows: the dense plain step (see .worker); rolling bearings take the sparse one
    dense = blk[7].shape[1] == LANE_BLOCK and NB == 0
    ratio = np.ascontiguousarray(np.concatenate([a.ratio, a.bq[:, :, BQ_RHO]], axis=1)) if NB else a.ratio
    z = np.zeros((P, 0, 0))
    A, B, W, _g, Wc = derived(arrays) if dense else (z,) * 5
    Vd, Vcd = (a.V, a.Vc) if dense else (z, z)

    def job():
        ndof_worker(
            order,
            counter,
            *sp,
            *jt,
            *blk,
            dense,
            A,
            B,
            W,
            Wc,
            np.ascontiguousarray(Vd),
            np.ascontiguousarray(Vcd),
            a.coef,
            a.D,
            ratio,
            a.kc,
            a.cc,
            a.Dc,
            a.omega,
            np.ascontiguousarray(a.bq, dtype=np.float64),
            *loads,
            np.ascontiguousarray(tperiod, dtype=np.float64),
            np.ascontiguousarray(nsteps, dtype=np.int64),
            np.ascontiguousarray(state0, dtype=np.float64),
            int(n_transient),
            int(n_record),
            int(tangent),
            k,
            tangent0,
            rigid,
            bool(accurate),
            poincare,
            end_state,
            stats,
            tan_log,
            tan_out,
            status,
            hist,
        )

    _run_workers(job, nw)
