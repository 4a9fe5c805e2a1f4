"""Backends: the kernel contract, written once.

A backend integrates a packed batch of systems of one kind.  It is the only code that calls a kernel:
:data:`PAIR` serves :class:`~geardyn.model.GearModel` (:mod:`geardyn._kernel`, the 1-DOF mesh in SIMD
lanes), :data:`MESH` serves :class:`~geardyn.systems.SystemModel` (:mod:`geardyn._kernel_ndof`, mesh-vector
systems).  Both return the same :class:`RawRun`; :mod:`geardyn.integrate` (the door every analysis uses)
turns it into one batch result.  A new kind of system is a new backend, not a new integrator module.

The contract
------------
``pack(models)``
    The kernel arrays of a batch (the models' own ``pack``; the pair's :func:`geardyn.pairpack.pack_models`).
``points(base, names, points)``
    The :class:`~geardyn.system.Batch` of a grid's parameter points: a :class:`~geardyn.system.ModelList` of
    their systems, or the pair's :class:`~geardyn.pairpack.PointModels` packed straight from the array.
    :func:`geardyn.system.as_batch` makes a list of systems a batch; every analysis hands batches to
    :mod:`geardyn.integrate` and asks them (sampling periods, steps per period N = ceil(T_f/Δτ), gaps, reference
    section) what it needs.
``run(models, packed, nsteps, state0, transient, record, mode, accurate, ...)``
    Integrate ``transient`` sampling periods, then record ``record``; ``mode`` is one of :data:`MODES`:
    ``"none"``, ``"lyapunov"`` (Gram–Schmidt logs per recorded period), ``"monodromy"`` (the raw tangent
    product over the recorded periods), ``"continue"`` (Lyapunov from a given tangent basis; pair only).
    ``tangents=k`` in Lyapunov mode asks for the k leading exponents only (``tan_log`` and ``tangent`` then have k
    columns; a backend may give more, the pair always gives its two).  A mesh-vector system's leading exponents
    are those of its motion modulo its rigid-body modes (``rigid_basis``: a free rotation's tangent grows linearly,
    a finite-time exponent ln(t)/t > 0 that would read as chaos), which the full spectrum keeps.
    The kernels' arithmetic is theirs: a backend only allocates the outputs and calls ``run_batch``.
    ``watch(poincare)``, when given, receives the Poincaré output before the kernel runs, filled with NaN
    until each recorded period writes its row (every kernel writes every row of a point, or NaN in all of
    them when it diverges, so the fill changes no result), so that another thread can follow a long run
    (:func:`geardyn.integrate.integrate_batch` with ``progress``).
Statistics
    ``RawRun.stats`` holds per point and element :data:`NSTAT` numbers over the recorded samples: the
    deflection's extremes, sum and sum of squares and the rate's extremes (``S_UMIN`` … ``S_VMAX``, the same
    for every law), then the element law's counters from :data:`S_LAW` (:attr:`geardyn.system.Law.counters`,
    at most :data:`geardyn.system.LAW_COUNTERS`: for the dead zone drive, separation and back contact),
    then the sample count ``S_N``.  Nothing here names a law's counters: a law names them itself.
``laws``
    The codes of the element laws the kernel implements; a kernel that gains a law's branch adds its code.
``restarts_exactly(accurate)``
    Whether the state at a period's end is all the kernel carries from one period to the next when no
    period is recorded: then ``k`` transient periods followed by a run from their end state equal one run,
    bit for bit, and :func:`geardyn.integrate.integrate_batch` with ``progress`` runs a long transient in
    such pieces to report it.
"""

from __future__ import annotations

import abc
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _kernel as _K1
from ._kernel import (  # the statistics' indices, statuses and bound: the same in both kernels
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
)
from .errors import ModelError
from .labels import MAX_PERIOD
from .pairpack import PointModels
from .system import Batch, ModelList, build_models

__all__ = [
    "RawRun",
    "Backend",
    "PairBackend",
    "MeshBackend",
    "PAIR",
    "MESH",
    "MODES",
    "run_followed",
    "tangent_work",
    "S_UMIN",
    "S_UMAX",
    "S_USUM",
    "S_USQ",
    "S_VMIN",
    "S_VMAX",
    "S_LAW",
    "S_N",
    "NSTAT",
    "ST_OK",
    "ST_DIVERGED",
    "DIVERGENCE_BOUND",
]

#: The first of an element law's counters in a run's statistics (the dead zone's drive, separation, back).
S_LAW = S_NDRIVE

#: Integration modes of :meth:`Backend.run`.
MODES = ("none", "lyapunov", "monodromy", "continue")
#: Their codes in the kernels (the same in both; the mesh-vector kernel has no "continue").
_TAN = dict(zip(MODES, (_K1.TAN_NONE, _K1.TAN_LYAPUNOV, _K1.TAN_MONODROMY, _K1.TAN_CONTINUE)))
#: Seconds one piece of a transient run in pieces by :func:`run_followed` aims at (its periods follow the speed seen).
PIECE_SECONDS = 0.25
#: RK4 steps (summed over the points) of the first such piece.
FIRST_PIECE_STEPS = 200_000


@dataclass
class RawRun:
    """The raw arrays of one kernel run of P points (state dimension d, E elements).

    Attributes
    ----------
    poincare : ndarray (P, record or 0, d)
    end_state : ndarray (P, d)
    stats : ndarray (P, E, NSTAT)
        Streaming statistics of every element's deflection over the recorded periods: the deflection's and its
        rate's (``S_UMIN`` … ``S_VMAX``), the element law's counters from :data:`S_LAW`, the sample count ``S_N``.
    tan_log : ndarray (P, record or 0, d)
    tangent : ndarray (P, d, d)
    status : ndarray (P,) int64
    hist : ndarray (P, K, d)
        The state at every step of the last (K − 1)/N periods (K = ``hist_len``).
    """

    poincare: np.ndarray
    end_state: np.ndarray
    stats: np.ndarray
    tan_log: np.ndarray
    tangent: np.ndarray
    status: np.ndarray
    hist: np.ndarray


def leading_basis(d: int, k: int) -> np.ndarray:
    """A fixed orthonormal (d, k) basis in general position: the start of k leading tangent vectors (seeded, so
    that a run is reproducible; no column lies in a coordinate subspace a decoupled part of a system could keep)."""
    q, _r = np.linalg.qr(np.random.default_rng(20261205).standard_normal((d, k)))
    return np.ascontiguousarray(q)


class Backend(abc.ABC):
    """The kernel contract (see the module docstring); subclasses call one kernel."""

    #: The backend's name.
    name = ""
    #: The codes of the element laws its kernel implements (:attr:`geardyn.system.Law.code`; the dead zone is 0):
    #: :mod:`geardyn.integrate` refuses a batch with an element of another law before anything runs.
    laws: frozenset[int] = frozenset({0})
    #: The state's coordinates, as messages name them.
    coords = "x"

    @staticmethod
    def pack(models: Sequence[Any]) -> Any:
        """The kernel arrays of a batch of systems of one kind."""
        models = list(models)
        return type(models[0]).pack(models)

    def points(self, base: Any, names: Sequence[str], points: np.ndarray) -> Batch:
        """The :class:`~geardyn.system.Batch` of parameter points (``base`` with ``names[j]`` = ``points[i, j]``).

        Raises
        ------
        ModelError
            For a point the model refuses.
        """
        return ModelList(build_models(base, names, points))

    def initial_states(self, models: Sequence[Any]) -> np.ndarray:
        """The (P, d) default initial states: each system's ``initial_state()``."""
        return np.stack([m.initial_state() for m in models])

    def restarts_exactly(self, accurate: bool) -> bool:
        """Whether a transient run from a period's end state continues it bit for bit (see the module docstring)."""
        return False

    def tangent_count(self, mode: str, d: int, tangents: int | None) -> int:
        """The tangent vectors a run in ``mode`` propagates (``tangents`` asked for in Lyapunov mode, else None):
        all d here (the pair always takes both); a backend that runs the leading ones only says so."""
        return d

    def run(
        self,
        models: Sequence[Any],
        packed: Any,
        nsteps: np.ndarray,
        state0: np.ndarray,
        transient: int,
        record: int,
        mode: str,
        accurate: bool,
        *,
        record_poincare: bool = True,
        hist_len: int = 0,
        adaptive_tol: float = 0.0,
        tangent0: np.ndarray | None = None,
        watch: Callable[[np.ndarray], None] | None = None,
        tangents: int | None = None,
    ) -> RawRun:
        """Run the batch in ``mode`` and return its raw arrays: allocated here, the same for every kernel, and
        filled by the backend's own kernel (:meth:`kernel`)."""
        P, d = len(models), int(models[0].state_dim)
        lyapunov = mode in ("lyapunov", "continue")
        k = self.tangent_count(mode, d, tangents if lyapunov else None)
        raw = RawRun(
            np.zeros((P, record if record_poincare else 0, d)),
            np.zeros((P, d)),
            np.zeros((P, len(models[0].elements), NSTAT)),
            np.zeros((P, record if lyapunov else 0, k)),
            np.zeros((P, d, k)),
            np.zeros(P, dtype=np.int64),
            np.zeros((P, hist_len, d)),
        )
        if tangent0 is not None:  # mode "continue": the kernel starts the tangent basis from these
            raw.tangent[:] = tangent0
        if watch is not None:  # every recorded row is written by the kernel (NaN after a divergence)
            raw.poincare.fill(np.nan)
            watch(raw.poincare)
        head = (nsteps, state0, int(transient), int(record), int(_TAN[mode]), bool(accurate))
        self.kernel(models, packed, head, raw, adaptive_tol)
        return raw

    @abc.abstractmethod
    def kernel(self, models: Any, packed: Any, head: tuple, raw: RawRun, adaptive_tol: float) -> None:
        """Fill ``raw`` by the backend's kernel: its ``run_batch`` with the batch's arrays, ``head`` (steps per
        period, start states, transient and recorded periods, tangent mode, accurate mode) and ``raw``'s outputs."""


class PairBackend(Backend):
    """The 1-DOF pair's kernel (:mod:`geardyn._kernel`): packed ``(coef, D, omega)``, state (u, u'), one element."""

    name = "pair"
    coords = "(u0, v0)"

    def points(self, base: Any, names: Sequence[str], points: np.ndarray) -> Batch:
        """The pair's points packed straight from the array (:class:`~geardyn.pairpack.PointModels`)."""
        return PointModels(base, names, points)

    def initial_states(self, models: Sequence[Any]) -> np.ndarray:
        return np.zeros((len(models), 2))  # every pair's initial_state() is (0, 0)

    def restarts_exactly(self, accurate: bool) -> bool:
        """The default mode carries (u, u') only (the rotation is re-seeded at every period's start, tangents and
        statistics start with the record); the accurate mode also carries the contact region its last sub-step was
        locked to, which a restart would take again from u (they differ where a period ends on u = ±D or after a
        step used up its splits)."""
        return not accurate

    def kernel(self, models, packed, head, raw, adaptive_tol) -> None:
        coef, D, omega = packed[:3]
        table = packed[3] if len(packed) > 3 else None  # models evaluated as tables (accurate mode)
        adaptive = (float(adaptive_tol), MAX_PERIOD) if adaptive_tol > 0.0 else ()  # cycles up to MAX_PERIOD
        _K1.run_batch(coef, D, omega, *head, *_outputs(raw, raw.stats[:, 0]), *adaptive, table=table)


class MeshBackend(Backend):
    """The mesh-vector kernel (:mod:`geardyn._kernel_ndof`): packed :class:`~geardyn.systems.SystemArrays`,
    state (q̃, q̃'), the meshes then the clearances.  The adaptive transient is not available
    (``adaptive_tol`` is ignored: every point runs its full transient)."""

    name = "mesh"
    coords = "(q̃, q̃')"
    #: The dead zone and the rolling-element bearing (:class:`geardyn.system.RollingBearingLaw`).
    laws: frozenset[int] = frozenset({0, 1})

    def restarts_exactly(self, accurate: bool) -> bool:
        """Both modes carry the state only: the default mode's coefficient table is the same every period and the
        accurate mode takes every element's contact branch again from the state at each (sub-)step's start."""
        return True

    def tangent_count(self, mode: str, d: int, tangents: int | None) -> int:
        """The leading ``tangents`` only, when asked (a continued tangent basis is refused)."""
        if mode == "continue":
            raise ModelError("tangent0: continuing a tangent basis is not available for mesh-vector systems")
        return d if tangents is None else max(1, min(int(tangents), d))

    def kernel(self, models, packed, head, raw, adaptive_tol) -> None:
        from . import _kernel_ndof as K  # imported by the first mesh-vector run: a pair never needs it

        P, d, k = raw.tangent.shape
        basis = rigid = None
        if k < d:  # leading exponents: a fixed generic orthonormal start, modulo the rigid-body motions
            R = np.asarray(models[0].rigid_basis(), dtype=float)
            n, r = d // 2, R.shape[1]
            rigid = np.zeros((d, 2 * r))
            rigid[:n, :r] = R
            rigid[n:, r:] = R
            b0 = leading_basis(d, k)
            b0 = np.linalg.qr(b0 - rigid @ (rigid.T @ b0))[0]
            basis = np.broadcast_to(b0, (P, d, k))
        tper = np.array([m.sampling_period for m in models], dtype=float)
        K.run_batch(packed, tper, *head, *_outputs(raw, raw.stats), tangent0=basis, rigid=rigid)


def _outputs(raw: RawRun, stats: np.ndarray) -> tuple[np.ndarray, ...]:
    """The output arrays of a kernel's ``run_batch``, in its order, with ``stats`` as that kernel takes them."""
    return raw.poincare, raw.end_state, stats, raw.tan_log, raw.tangent, raw.status, raw.hist


def tangent_work(models: Sequence[Any], tangents: int | None = None) -> float:
    """The work of a mesh-vector run with ``tangents`` tangent vectors (default all 2n: the full spectrum) over that
    of a plain run of the same periods, counted in multiply-adds per RK4 step from the kernel's sparse patterns
    (an estimate of the cost, printed before a full spectrum; the classification's two leading vectors run beside
    the plain step instead, :func:`geardyn._kernel_ndof.core.tan_free`).

    Parameters
    ----------
    models : sequence of SystemModel
        The run's systems; the first one's sparse patterns are counted (a batch shares its structure).
    tangents : int, optional
        Tangent vectors integrated beside the state, clipped to 1 … 2n (None: all 2n).

    Returns
    -------
    float
        The ratio of the two counts (the tangent run's over the plain run's).
    """
    from . import _kernel_ndof as K

    arrays = type(models[0]).pack(list(models)[:1])
    sp, jt, blk = K.sparse_arrays(arrays)
    n = int(sp[10].shape[1])
    d = 2 * n
    k = MESH.tangent_count("lyapunov", d, tangents)
    ne, nab, nw = int(sp[5].shape[0]), int(sp[1].shape[0]), int(sp[8].shape[0])
    ng, nct = int(jt[1].shape[0]), int(jt[5].shape[0])
    plain = 4 * (K.plain_cost(blk) + 2 * ne) + ne
    state = 4 * (2 * nab + 2 * ne + nw + n)
    jac = 4 * (ne + 2 * nct + 2 * ng) if k == d else 4 * ne
    cols = 4 * k * ((2 * ng + 2 * n) if k == d else (2 * nab + 2 * ne + nw + n)) + 4 * d * k
    return float((state if k == d else plain) + jac + cols) / float(plain)


#: The backend of :class:`~geardyn.model.GearModel`.
PAIR = PairBackend()
#: The backend of :class:`~geardyn.systems.SystemModel`.
MESH = MeshBackend()


# ------------------------------------------------------------------------------ a run followed as it goes
def run_followed(
    call: Callable[..., RawRun],
    nsteps: np.ndarray,
    state0: np.ndarray,
    transient: int,
    record: int,
    progress: Callable[[int, int], None],
    *,
    pieces: bool,
    rows: bool,
    poll: float,
) -> RawRun:
    """One run of a batch reporting ``progress(done, total)`` in sampling periods per point as it goes.

    Parameters
    ----------
    call : callable
        ``call(start, periods, watch=None)``: the run from the states ``start`` through ``periods`` transient
        periods and the record, handing its Poincaré output to ``watch`` (:meth:`Backend.run`);
        ``call(start, periods, piece=True)``: ``periods`` transient periods only.
    nsteps : ndarray (P,)
        RK4 steps per sampling period (sizes the first piece).
    state0 : ndarray (P, d)
        The start states.
    transient, record : int
        Transient and recorded periods.
    progress : callable
        ``progress(done, total)``, ``total`` = transient + record; ``done`` never decreases and ends at ``total``.
    pieces : bool
        Run all but the last transient period in pieces of whole periods, each from the end state of the one
        before and reported, which only a backend whose :meth:`~Backend.restarts_exactly` may (and no adaptive
        transient): the state at a period's end is then all a run carries, so the results are the one run's,
        bit for bit.  A point that diverges in a piece ends it with a NaN state; every later run of it diverges
        in its first period, which lies in its transient (the last transient period is left to the recording
        run), so it ends as the one run ends a point diverged in its transient.  Without pieces the transient
        counts once recording begins.
    rows : bool
        Whether the recorded periods write Poincaré rows to follow (else they count at the end).
    poll : float
        Seconds between two counts of the recorded rows (the kernel runs in a thread; it holds no GIL).

    Returns
    -------
    RawRun
        That of ``call(state0, transient)``, bit for bit.
    """
    total = transient + record
    state, done = state0, 0
    progress(0, total)
    if pieces:
        state = np.array(state0, dtype=float)
        size = max(1, -(-FIRST_PIECE_STEPS // max(int(np.sum(nsteps)), 1)))
        while transient - 1 - done > 0:
            n = min(size, transient - 1 - done)
            t0 = time.monotonic()
            state = np.ascontiguousarray(call(state, n, piece=True).end_state)
            dt = time.monotonic() - t0
            done += n
            progress(done, total)
            size = int(min(max(1.0, n * PIECE_SECONDS / dt if dt > 0 else 8.0 * n), 8.0 * n))
    rest = transient - done
    if record == 0 or not rows:
        raw = call(state, rest)
        progress(total, total)
        return raw
    import numba

    seen: list[np.ndarray] = []
    out: dict[str, Any] = {}
    threads = numba.get_num_threads()  # numba's setting is per thread: the kernel's thread takes the caller's

    def work() -> None:
        try:
            numba.set_num_threads(threads)
            out["raw"] = call(state, rest, seen.append)
        except BaseException as e:  # raised again in the caller's thread
            out["error"] = e

    worker = threading.Thread(target=work, name="geardyn-kernel", daemon=True)
    worker.start()
    shown = done
    while worker.is_alive():
        worker.join(poll)
        if seen:
            pc = seen[0]
            rows = int(np.count_nonzero(np.isfinite(pc[:, :, 0]))) // max(pc.shape[0], 1)  # per point, on average
            if rows and transient + rows > shown:
                shown = transient + rows
                progress(shown, total)
    if "error" in out:
        raise out["error"]
    if shown < total:
        progress(total, total)
    return out["raw"]
