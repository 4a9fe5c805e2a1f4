"""The integrator kernel: numba functions on plain arrays.

Only :mod:`geardyn.integrate` imports this package.  One entry point, :func:`run_batch`,
advances a batch of parameter points (each with its own coefficients, backlash and step count)
through ``n_transient + n_record`` forcing periods with classic fixed-step RK4, and serves
every analysis: Poincaré sections, streaming amplitude statistics, time histories, Lyapunov
spectra (tangent vectors with Gram–Schmidt each period) and monodromy matrices.

How the default mode is made fast
---------------------------------
* **Lock-step lanes.**  A worker keeps ``LANES`` parameter points in a structure of arrays (one
  flat float64 array, each field ``LANES`` consecutive values) and advances all lanes together in
  chunks of ``m`` steps, ``m`` being the distance to the nearest period end among the active
  lanes.  The RK4 step runs across points in SIMD vectors: explicit LLVM vectors of the machine's
  register width for the first-harmonic kinds (:mod:`.simd`: 512-bit where the CPU has AVX-512,
  else 256-bit; ``GEARDYN_SIMD_WIDTH`` forces 512, 256 or 0), loops over the lanes that LLVM
  vectorises (256-bit) for the general kind and with ``GEARDYN_SIMD_WIDTH=0``; every width gives
  the same bits.  At a period end the lane's Poincaré point, divergence check and Gram–Schmidt are
  done in scalar code; a finished lane is refilled from the worker's queue of points.
* **Coefficients without trigonometric calls.**  cos θ, sin θ at the step start, midpoint and end
  come from a rotation recurrence by the half-step angle π/N (in increment form, see
  ``_rot_small``: error ~1e-15 over a period), re-seeded exactly (cos 0 = 1, sin 0 = 0) at every
  period start.  The Fourier series are summed by the same recurrence.
* **Branch-free dead zone** ``f(u) = u - clamp(u, -D, D)`` and contact indicators as selects.
* **Specialised chunk kernels** (built once from one template): first harmonic only with or
  without sine terms, or any number of harmonics; without statistics (every lane still in its
  transient), with statistics, with statistics and tangent propagation.  All variants perform
  the same floating-point operations in the same order on the terms they share, and a zero
  coefficient contributes exactly nothing, so a point gets bit-identical results whichever
  variant, lane, batch or thread runs it.  The lanes worker is compiled (and cached) per kind,
  selected by the type of a token argument, so a program compiles only the kinds it uses.
* **Packing the tail.**  Once a worker's queue is empty, the lanes still running are moved into
  the first groups of ``GROUP`` lanes and the chunks run over those groups only, so the last
  points of a batch do not pay for idle lanes.
* **Scalar path** for batches with fewer than ``LANE_MIN_POINTS`` points per worker (e.g. a
  single long trajectory or a shooting iteration): the same arithmetic, state and statistics in registers.
* **Threads balanced dynamically.**  :func:`run_batch` queues the points by decreasing cost
  (steps per period) and runs T workers on T Python threads over ``nogil`` compiled functions;
  each worker takes the next point of the shared queue (an atomic counter) whenever one of its
  lanes is free, so a faster or less loaded core takes more points.  T is numba's thread setting
  (``geardyn.integrate.set_threads``).  No result depends on T or on which worker ran a point.
* Fused multiply-adds are written explicitly (``_fma``) and no fast-math flag is used: the
  compiler neither contracts nor reassociates on its own, so the scalar and the vectorised code
  round identically, and results differ from a plain RK4 loop only by rounding.

The accurate mode locks the vector field to one contact region per sub-step and splits each step
at the crossings u = ±D (dense Hermite output, then Newton on the sub-step length), which keeps
RK4 fourth order through contact changes; it runs one point at a time (scalar).

Layout
------
The package is split by execution path; imports flow one way, from this door down to
:mod:`.core`:

``__init__`` (this module)
    The public door: :func:`run_batch`, :func:`n_threads`, the kernel's thread pool, the
    dispatch thresholds (``LANE_MIN_POINTS``, ``THREAD_MIN_STEPS``) and the constants the
    callers read, re-exported from the modules below.
:mod:`.lanes`
    The lock-step lanes (default mode, enough points per worker): the chunk kernels built from
    one template, the lane state layout, the choice of SIMD width and the lanes worker.
:mod:`.simd`
    The explicit-SIMD chunk kernels of the first-harmonic kinds (LLVM vector IR), used by
    :mod:`.lanes`.
:mod:`.scalar`
    The default mode one point at a time (histories, small batches) and its worker.
:mod:`.accurate`
    The accurate mode: locked sub-steps, event location on the Hermite output, its worker.
:mod:`.core`
    What every path shares: the output layout and status constants, the intrinsics
    (``_fetch_add``, ``_fma``), the dead zone, rotations and coefficient series, the RK4 steps
    of the state and of tangent vectors, Gram–Schmidt and the result writers.

Each worker (``_lanes_worker``, ``_scalar_worker``, ``_accurate_worker``) is compiled with
``cache=True`` and stays a top-level function of its module.  numba keys a cache entry on the
source file of the cached function only, not on the files it calls into, so this package calls
:func:`geardyn._cache_guard.refresh` first: when any of its sources changed, the cached workers are
removed and compiled again.
"""

from __future__ import annotations

from .._cache_guard import fast_loads as _fast_loads
from .._cache_guard import refresh as _refresh_cache

_refresh_cache(__file__)  # before the cached workers are imported (see geardyn._cache_guard)

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .core import (
    DIVERGENCE_BOUND,
    NSTAT,
    S_N,
    S_NDRIVE,
    S_UMAX,
    S_UMIN,
    S_USQ,
    S_USUM,
    S_VMAX,
    S_VMIN,
    ST_DIVERGED,
    ST_OK,
    TAN_CONTINUE,
    TAN_LYAPUNOV,
    TAN_MONODROMY,
    TAN_NONE,
)
from .scalar import _scalar_worker

_fast_loads(_scalar_worker)  # read from numba's cache without setting up its compiler (see fast_loads)

#: Names of the lanes module, imported on first use: a run imports the worker it runs (``simulate`` one point at
#: a time: the scalar worker only, not the lanes' chunk kernels).
_LAZY = ("KIND_COS", "KIND_GEN", "KIND_SIN", "LANES", "simd_width")


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from . import lanes

    return getattr(lanes, name)


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
    "S_N",
    "NSTAT",
    "TAN_NONE",
    "TAN_LYAPUNOV",
    "TAN_MONODROMY",
    "TAN_CONTINUE",
    "ST_OK",
    "ST_DIVERGED",
    "DIVERGENCE_BOUND",
    "LANES",
    "THREAD_MIN_STEPS",
    "KIND_COS",
    "KIND_SIN",
    "KIND_GEN",
    "simd_width",
]


#: Batches with fewer points per worker than this are integrated one point at a time (scalar path).
LANE_MIN_POINTS = 3
#: Batches with fewer RK4 steps than this run on the calling thread only.
THREAD_MIN_STEPS = 200_000


# ----------------------------------------------------------------------------- entry point
_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()


def _executor() -> ThreadPoolExecutor:
    """The kernel's thread pool, created once (its threads start on demand, up to numba's
    thread limit, which bounds every thread setting) and never resized, so concurrent callers can
    share it."""
    global _pool
    with _pool_lock:
        if _pool is None:
            import numba

            _pool = ThreadPoolExecutor(
                max_workers=max(1, int(numba.config.NUMBA_NUM_THREADS)), thread_name_prefix="geardyn-kernel"
            )
        return _pool


def _forget_pool() -> None:
    """In a forked child the parent's pool threads do not exist: start a new pool when needed."""
    global _pool, _pool_lock
    _pool = None
    _pool_lock = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def n_threads() -> int:
    """Threads the kernel uses: numba's thread setting (``geardyn.integrate.set_threads``)."""
    import numba

    return max(1, int(numba.get_num_threads()))


def _queue_order(nsteps: np.ndarray) -> np.ndarray:
    """The batch's queue: points by decreasing cost (steps per period), so that the last points
    taken, which the lanes and threads finish unevenly, are the cheapest."""
    return np.argsort(-np.asarray(nsteps, dtype=np.int64), kind="stable").astype(np.int64)


def run_batch(
    coef,
    D,
    omega,
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
    adapt_tol=0.0,
    max_period=0,
    table=None,
):
    """Advance a batch of P parameter points; results are written into the output arrays.

    Parameters
    ----------
    coef : float64[P, 3, H+1, 2]
        Fourier coefficients of C(θ) = 2ξ(θ), K(θ) and F(θ) per point (``GearModel.coefficients``).
    D : float64[P]
        Half backlash per point (non-dimensional).
    omega : float64[P]
        Mesh frequency per point; the period is T = 2π/ω.
    nsteps : int64[P]
        RK4 steps per period per point; the step is h = T/nsteps.
    state0 : float64[P, 2]
        Initial (u, u') at θ = 0.
    n_transient, n_record : int
        Periods discarded, then periods recorded.
    tangent : int
        ``TAN_NONE``; ``TAN_LYAPUNOV`` (tangent matrix from the identity at the record start,
        Gram–Schmidt each recorded period, logs of the diagonal into ``tan_log``); or
        ``TAN_MONODROMY`` (the raw product over the recorded periods into ``tan_out``).
    accurate : bool
        Split steps at contact-boundary crossings.
    poincare : float64[P, n_record or 0, 2]
        Out: state at the end of each recorded period (NaN after divergence).
    end_state : float64[P, 2]
        Out: final state.
    stats : float64[P, NSTAT]
        Out: streaming statistics over the recorded periods (see the ``S_*`` indices).
    tan_log : float64[P, n_record or 0, 2]
        Out (Lyapunov mode): log r11, log r22 of each recorded period.
    tan_out : float64[P, 2, 2]
        Out: final tangent matrix (the monodromy in ``TAN_MONODROMY`` mode).
    status : int64[P]
        Out: ``ST_OK`` or ``ST_DIVERGED``.
    hist : float64[P, K, 2]
        Out: if K > 0, the state at every step of the last (K - 1)/nsteps periods (all points of a
        batch with a history must share nsteps).
    adapt_tol : float
        > 0: adaptive transient (default mode, no history): ``n_transient`` becomes a maximum, each
        point stops its transient once its Poincaré sequence has converged onto a period-n cycle
        (n <= ``max_period``) to within ``adapt_tol`` (``core._adapt_check``), at a period count
        congruent to ``n_transient`` mod n; without tangents it then records one cycle, repeated
        over the ``n_record`` periods (``core._adapt_finish``).  0 (default): the fixed transient.
    max_period : int
        Longest cycle the adaptive transient looks for.
    table : (float64[P, M, 7], int64[P]), optional
        Accurate mode only: per point the rows of its stiffness and STE table
        (:func:`geardyn.meshtable.kernel_table`) and their count m (0: the point's series); the sub-steps
        end at the table's nodes.

    Notes
    -----
    ``n_threads()`` workers take the points from a queue ordered by decreasing cost; with at
    least ``LANE_MIN_POINTS`` points per worker they run them in lock-step lanes (default mode, no
    history, at least one period), otherwise one at a time.  Each point's results are the same bits whichever way and
    wherever it is run.
    """
    P = coef.shape[0]
    if P == 0:
        return
    if table is not None and not accurate:
        raise ValueError("a table is evaluated as given in the accurate mode only")
    if table is None:
        tab, ntab = np.zeros((P, 1, 7)), np.zeros(P, dtype=np.int64)
    else:
        tab, ntab = np.ascontiguousarray(table[0], dtype=float), np.ascontiguousarray(table[1], dtype=np.int64)
    n_transient = int(n_transient)
    n_record = int(n_record)
    tangent = int(tangent)
    accurate = bool(accurate)
    scalar_only = accurate or hist.shape[1] > 0
    adapt_tol = float(adapt_tol) if not scalar_only and n_record > 0 else 0.0
    max_period = int(max_period) if adapt_tol > 0.0 else 0
    total = int(np.sum(nsteps)) * (n_transient + n_record)
    nw = min(n_threads(), P) if total >= THREAD_MIN_STEPS else 1
    order = _queue_order(nsteps)
    counter = np.zeros(1, dtype=np.int64)
    # (no periods: each point's results are its start state, written one at a time)
    lanes = not scalar_only and tangent != TAN_CONTINUE and n_transient + n_record > 0 and P >= LANE_MIN_POINTS * nw
    # the workers' shared arguments, between each worker's own leading and trailing ones
    mid = (order, counter, coef, D, omega, nsteps, state0, n_transient, n_record, tangent)
    mid += (poincare, end_state, stats, tan_log, tan_out, status)
    if accurate:
        from .accurate import _accurate_worker as worker

        args = (*mid, hist, tab, ntab)
    elif lanes:
        from .lanes import _kind_token, _lanes_kind
        from .lanes import _lanes_worker as worker

        args = (_kind_token(_lanes_kind(coef, order)), *mid, adapt_tol, max_period)
    else:
        worker, args = _scalar_worker, (*mid, hist, adapt_tol, max_period)
    _fast_loads(worker)
    _run_workers(lambda: worker(*args), nw)


def _run_workers(work, nw: int) -> None:
    """Run ``work`` on the calling thread (``nw`` 1) or on ``nw`` threads of the kernel's pool, each a worker
    taking points from the batch's shared queue; errors are raised here."""
    if nw == 1:
        work()
        return
    pool = _executor()
    for f in [pool.submit(work) for _ in range(nw)]:
        f.result()
