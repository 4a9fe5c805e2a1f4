"""The N-DOF integrator kernel: numba functions on the arrays of :meth:`geardyn.systems.SystemModel.pack`.

Only :mod:`geardyn.backend` (its ``MESH`` backend, behind :mod:`geardyn.integrate`) imports this package.  :func:`run_batch` advances a batch of
parameter points of one system structure through ``n_transient + n_record`` forcing periods with
classic fixed-step RK4 (h = T_f/N, T_f the forcing period, so the stroboscopic samples are exact)
and serves every analysis: Poincaré points of the full state, streaming statistics per element
(each mesh's deflection δ_m = V[m]·q̃ − E_m(θ), then each clearance's), time histories, Lyapunov
spectra (all 2n tangent vectors, Gram–Schmidt each recorded period) and monodromy matrices.
The accurate mode splits every step at each element's contact boundary (δ = ±D) inside it.

The default mode's plain step (no tangents) keeps the state in a padded layout with the
matrices transposed once per point and advances blocks of rows as SIMD vectors, column by column:
the same operations in the same order as the row-by-row :func:`.core.field`, so bit-identical.

Layout: :mod:`.core` (vector field, Jacobian, statistics), :mod:`.step` (RK4 step, split steps,
the plain step), :mod:`.simd` (one stage of the plain step on a block of rows, as LLVM vectors),
:mod:`.worker` (one point at a time from a shared queue; ``nogil``, ``cache=True``).  Threads: the
1-DOF kernel's pool (:func:`geardyn._kernel._executor`), as many workers as numba's thread setting.
numba keys a cache entry on the worker's source file only, so this package calls
:func:`geardyn._cache_guard.refresh` first: a change to any of its sources recompiles the workers.
"""

from __future__ import annotations

from .._cache_guard import fast_loads as _fast_loads
from .._cache_guard import refresh as _refresh_cache

_refresh_cache(__file__)  # before the cached workers are imported (see geardyn._cache_guard)

import numpy as np

from .._kernel import _executor, n_threads
from .core import (
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
)
from .step import CROSSING_TOL, HERMITE_SAMPLES, MAX_SPLITS
from .worker import ndof_worker

_fast_loads(ndof_worker)  # read from numba's cache without setting up its compiler (see geardyn._cache_guard)

__all__ = [
    "run_batch",
    "n_threads",
    "S_UMIN",
    "S_UMAX",
    "S_USUM",
    "S_USQ",
    "S_VMIN",
    "S_VMAX",
    "S_NDRIVE",
    "S_NSEP",
    "S_NBACK",
    "S_N",
    "NSTAT",
    "TAN_NONE",
    "TAN_LYAPUNOV",
    "TAN_MONODROMY",
    "ST_OK",
    "ST_DIVERGED",
    "DIVERGENCE_BOUND",
    "MAX_SPLITS",
    "HERMITE_SAMPLES",
    "CROSSING_TOL",
    "THREAD_MIN_WORK",
]

#: Batches with less work than this (RK4 steps × DOFs²) run on the calling thread only.
THREAD_MIN_WORK = 2_000_000


def derived(arrays):
    """(A, B, W, g, Wc) = (M̃⁻¹K̃_b, M̃⁻¹C̃_b, rows M̃⁻¹V[m], M̃⁻¹F̃, rows M̃⁻¹Vc[c]) of packed arrays."""
    Mi = arrays.Mi
    c = np.ascontiguousarray
    A = c(Mi @ arrays.Kb)
    B = c(Mi @ arrays.Cb)
    W = c(np.einsum("pij,pmj->pmi", Mi, arrays.V))
    g = c(np.einsum("pij,pj->pi", Mi, arrays.F))
    Wc = c(np.einsum("pij,pmj->pmi", Mi, arrays.Vc)) if arrays.Vc.shape[1] else c(np.zeros_like(arrays.Vc))
    return A, B, W, g, Wc


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
    tan_log : float64[P, n_record or 0, 2n]
        Out (Lyapunov mode).
    tan_out : float64[P, 2n, 2n]
        Out: final tangent matrix.
    status : int64[P]
        Out: ``ST_OK`` or ``ST_DIVERGED``.
    hist : float64[P, K, 2n]
        Out: if K > 0 the state at every step of the last (K − 1)/N periods.
    """
    P = arrays.Mi.shape[0]
    if P == 0:
        return
    A, B, W, g, Wc = derived(arrays)
    order = np.argsort(-np.asarray(nsteps, dtype=np.int64), kind="stable").astype(np.int64)
    counter = np.zeros(1, dtype=np.int64)
    n = arrays.Mi.shape[1]
    work = float(np.sum(nsteps)) * (int(n_transient) + int(n_record)) * n * n
    nw = min(n_threads(), P) if work >= THREAD_MIN_WORK else 1
    a = arrays

    def job():
        ndof_worker(
            order,
            counter,
            A,
            B,
            W,
            a.V,
            a.coef,
            a.D,
            a.ratio,
            g,
            Wc,
            a.Vc,
            a.kc,
            a.cc,
            a.Dc,
            a.omega,
            np.ascontiguousarray(tperiod, dtype=np.float64),
            np.ascontiguousarray(nsteps, dtype=np.int64),
            np.ascontiguousarray(state0, dtype=np.float64),
            int(n_transient),
            int(n_record),
            int(tangent),
            bool(accurate),
            poincare,
            end_state,
            stats,
            tan_log,
            tan_out,
            status,
            hist,
        )

    if nw == 1:
        job()
        return
    pool = _executor()
    for f in [pool.submit(job) for _ in range(nw)]:
        f.result()
