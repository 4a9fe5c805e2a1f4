"""Integration of any system: batches, trajectories, period maps — the one door to the kernels.

Every analysis (simulation, sweeps, Lyapunov spectra, shooting, continuation) goes through
:func:`integrate_batch`, :func:`trajectory` or :func:`period_map`, for any
:class:`~geardyn.system.System`: the door packs the batch with the system's ``pack``, hands it to the
system's :attr:`~geardyn.system.System.backend` (:mod:`geardyn.backend`: the 1-DOF kernel for a
:class:`~geardyn.model.GearModel`, the mesh-vector kernel for a :class:`~geardyn.systems.SystemModel`)
and returns one :class:`BatchResult` with an element axis (length 1 for the pair; the meshes, then the
clearances for a system).  Sampling: the step is h = T_f/N with T_f the system's ``sampling_period`` (the
forcing period; 2π/ω for the pair) and N = ceil(T_f/Δτ) unless given.

Two integration settings are arguments of these functions rather than fields of
:class:`~geardyn.model.IntegrationOptions`:

``steps``
    RK4 steps per forcing period.  By default N = ceil(T/Δτ); an analysis that must hold N fixed
    while a parameter moves (the corrector of a continuation) passes it directly, and the step is
    then h = T/N exactly.
``threads``
    Threads the kernel may use for this call (None: numba's current setting).  The setting of the
    calling thread is restored when the call returns, so no analysis changes the thread count its
    caller sees (:func:`using_threads`).  Only :func:`set_threads` changes it for good.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .backend import (
    DIVERGENCE_BOUND,
    S_LAW,
    S_N,
    S_UMAX,
    S_UMIN,
    S_USQ,
    S_USUM,
    S_VMAX,
    S_VMIN,
    ST_DIVERGED,
    ST_OK,
    RawRun,
)
from .model import IntegrationOptions, ModelError, _whole_number
from .system import LAW_COUNTERS, Batch, as_batch

__all__ = [
    "BatchResult",
    "Trajectory",
    "integrate_batch",
    "trajectory",
    "period_map",
    "set_threads",
    "using_threads",
    "state_dim",
    "natural_steps",
    "forcing_period",
    "start_state",
    "ST_OK",
    "ST_DIVERGED",
    "DIVERGENCE_BOUND",
]


def state_dim(model: Any) -> int:
    """Dimension of the state of ``model`` as the kernel integrates it (the length of ``state0``).

    Parameters
    ----------
    model : System
        The system.

    Returns
    -------
    int
        ``model.state_dim`` (2, (u, u'), for the 1-DOF model; 2n for a system).
    """
    return int(model.state_dim)


def natural_steps(model: Any, dtau: float) -> int:
    """The RK4 steps per sampling period the kernel takes for ``model`` when none are given.

    Parameters
    ----------
    model : System
        The model.
    dtau : float
        Target step Δτ.

    Returns
    -------
    int
        N = ceil(T_f/Δτ), so that h = T_f/N <= Δτ (for the pair :func:`geardyn.pairpack.steps_per_period`).
    """
    return int(math.ceil(model.sampling_period / dtau))


def _thread_count(n: int) -> int:
    import numba

    if not _whole_number(n):
        raise ModelError(f"threads: must be an integer >= 1, got {n!r}")
    if n < 1:
        raise ModelError(f"threads: must be >= 1, got {n}")
    return min(int(n), numba.config.NUMBA_NUM_THREADS)


def set_threads(n: int | None) -> None:
    """Set the number of threads the kernel uses from now on (for a command or a worker process).

    Parameters
    ----------
    n : int or None
        Threads (at most numba's thread limit); None leaves numba's setting (default: all cores).

    Raises
    ------
    ModelError
        If ``n`` is not an integer >= 1.
    """
    if n is None:
        return
    import numba

    numba.set_num_threads(_thread_count(n))


@contextmanager
def using_threads(n: int | None) -> Iterator[None]:
    """Let the kernel use ``n`` threads inside the ``with`` block, then restore the previous setting.

    numba's thread setting belongs to the calling thread; it is restored even when the block
    raises, so a caller sees the same ``numba.get_num_threads()`` before and after.

    Parameters
    ----------
    n : int or None
        Threads for the block; None changes nothing.

    Raises
    ------
    ModelError
        As :func:`set_threads`.
    """
    if n is None:
        yield
        return
    import numba

    want = _thread_count(n)
    old = numba.get_num_threads()
    if want == old:
        yield
        return
    numba.set_num_threads(want)
    try:
        yield
    finally:
        numba.set_num_threads(old)


def forcing_period(model: Any) -> float:
    """The sampling period T_f of ``model``: its forcing period (p·2π/ω), or 2π/ω when not periodic.

    Parameters
    ----------
    model : System

    Returns
    -------
    float
        ``model.sampling_period``.
    """
    return float(model.sampling_period)


def start_state(model: Any, state0: Sequence[float] | np.ndarray | None = None) -> np.ndarray:
    """A full initial state from what a user gives.

    Parameters
    ----------
    model : System
    state0 : None, (u0, v0) or (d,)
        None: ``model.initial_state()``; two numbers: the reference element's (δ, δ') at θ = 0
        (``model.initial_state(u0, v0)``; for the pair the state itself); else the full state as given.

    Returns
    -------
    ndarray (d,)
    """
    if state0 is None:
        return model.initial_state()
    s = np.asarray(state0, dtype=float)
    if s.shape == (2,):
        return model.initial_state(float(s[0]), float(s[1]))
    return s


def _statistic(k: int, doc: str) -> property:
    """The read-only property of the reference element's streaming statistic ``k``, NaN where diverged."""
    return property(lambda self: self._el(k, self.reference), doc=doc)


@dataclass
class BatchResult:
    """Results for P points of one kind of system integrated together (all non-dimensional).

    Attributes
    ----------
    models : Batch
        The points, in batch order (:class:`~geardyn.system.Batch`: the one integrated, or the
        :class:`~geardyn.system.ModelList` of the systems given).
    options : IntegrationOptions
        The options they were integrated with.
    poincare : ndarray (P, periods, d)
        The state at θ ≡ 0 at the end of each recorded sampling period; NaN where diverged.
    end_state : ndarray (P, d)
        Final state (the start state for a continuation sweep).
    status : ndarray (P,)
        ``ST_OK`` or ``ST_DIVERGED``.
    stats : ndarray (P, elements, NSTAT)
        Streaming statistics of every element's deflection over the recorded periods, sampled at every
        step (one element, the mesh, for the pair), its law's counters among them (:mod:`geardyn.backend`).
    nsteps : ndarray (P,)
        RK4 steps per sampling period.
    lyapunov_log : ndarray (P, periods, d) or None
        Per recorded period, the logs of the Gram–Schmidt diagonal (Lyapunov mode).
    tangent : ndarray (P, d, d) or None
        Final tangent matrix: the monodromy over the recorded periods in monodromy mode.
    elements : tuple of str
        Names of the elements of ``stats``.
    laws : tuple of Law
        The law of each element (:class:`~geardyn.system.Law`; names its counters).
    reference : int
        Index of the reference element (whose deflection is the 1-DOF model's u): ``u_min``, ``u_max``,
        ``amplitude``, ``mean``, ``rms`` and ``contact_fractions`` are its.
    """

    models: Batch
    options: IntegrationOptions
    poincare: np.ndarray
    end_state: np.ndarray
    status: np.ndarray
    stats: np.ndarray
    nsteps: np.ndarray
    lyapunov_log: np.ndarray | None = None
    tangent: np.ndarray | None = None
    elements: tuple[str, ...] = ("mesh",)
    reference: int = 0
    laws: tuple[Any, ...] = ()

    @property
    def ok(self) -> np.ndarray:
        """Whether each point finished without diverging (P,)."""
        return self.status == ST_OK

    def _el(self, k: int, e: int | None) -> np.ndarray:
        x = self.stats[:, :, k]
        x = np.where(self.ok[:, None], x, np.nan)
        return x if e is None else x[:, e]

    def _per_sample(self, k: int, e: int | None) -> np.ndarray:
        """stats k / number of samples; NaN where no sample was taken (diverged before recording)."""
        n = self.stats[:, :, S_N]
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.where(n > 0, self.stats[:, :, k] / np.where(n > 0, n, 1.0), np.nan)
        r = np.where(self.ok[:, None], r, np.nan)
        return r if e is None else r[:, e]

    def element_u_min(self, e: int | None = None) -> np.ndarray:
        """Smallest δ (P,) of element e, or (P, elements) for e None; NaN where diverged."""
        return self._el(S_UMIN, e)

    def element_u_max(self, e: int | None = None) -> np.ndarray:
        """Largest δ (P,) of element e, or (P, elements) for e None; NaN where diverged."""
        return self._el(S_UMAX, e)

    def element_mean(self, e: int | None = None) -> np.ndarray:
        """Mean δ over the recorded periods."""
        return self._per_sample(S_USUM, e)

    def element_rms(self, e: int | None = None) -> np.ndarray:
        """RMS of the fluctuation δ − mean(δ) over the recorded periods."""
        m = self._per_sample(S_USUM, e)
        return np.sqrt(np.maximum(self._per_sample(S_USQ, e) - m * m, 0.0))

    def element_fractions(self, e: int | None = None) -> np.ndarray:
        """(P, LAW_COUNTERS) (or (P, elements, LAW_COUNTERS)) time fractions of the law's counters (the dead
        zone's: drive contact, separation, back contact); a law with fewer counters leaves the rest 0."""
        f = np.stack([self._per_sample(S_LAW + k, None) for k in range(LAW_COUNTERS)], axis=-1)
        return f if e is None else f[:, e]

    def law_fractions(self, e: int | None = None) -> dict[str, np.ndarray]:
        """The time fractions (P,) of the counters of element e's law (default the reference element), by the
        names the law gives them (:attr:`geardyn.system.Law.counters`; the dead zone's ``drive``,
        ``separation``, ``back``)."""
        e = self.reference if e is None else e
        f = self.element_fractions(e)
        return {name: f[:, k] for k, name in enumerate(self.laws[e].counters)}

    u_min = _statistic(S_UMIN, "Smallest u over the recorded periods (P,); NaN where diverged.")
    u_max = _statistic(S_UMAX, "Largest u over the recorded periods (P,); NaN where diverged.")
    v_min = _statistic(S_VMIN, "Smallest u' over the recorded periods (P,); NaN where diverged.")
    v_max = _statistic(S_VMAX, "Largest u' over the recorded periods (P,); NaN where diverged.")

    @property
    def amplitude(self) -> np.ndarray:
        """Half peak-to-peak displacement (u_max − u_min)/2 over the recorded periods."""
        return 0.5 * (self.u_max - self.u_min)

    @property
    def mean(self) -> np.ndarray:
        """Mean u over the recorded periods."""
        return self.element_mean(self.reference)

    @property
    def rms(self) -> np.ndarray:
        """RMS of the fluctuation u − mean(u) over the recorded periods."""
        return self.element_rms(self.reference)

    @property
    def contact_fractions(self) -> np.ndarray:
        """(P, LAW_COUNTERS) time fractions of the reference element's law counters (the dead zone's drive-side
        contact, separation and back-side contact)."""
        return self.element_fractions(self.reference)


def _state_array(state0: Sequence[float] | np.ndarray, P: int, d: int, coords: str) -> np.ndarray:
    """The (P, d) initial states of a batch from one state (d,) or one per point (P, d), checked;
    ``coords`` names the state's coordinates in the messages."""
    s = np.asarray(state0, dtype=float)
    if s.shape == (d,):
        s = np.broadcast_to(s, (P, d))
    if s.shape != (P, d):
        raise ModelError(f"initial state {coords}: expected shape ({d},) or ({P}, {d}), got {s.shape}")
    if not np.all(np.isfinite(s)):
        raise ModelError(f"initial state {coords}: must be finite")
    return np.ascontiguousarray(s, dtype=float)


def _steps_array(steps: int | Sequence[int] | np.ndarray, P: int) -> np.ndarray:
    """Validated steps per period for P points from an integer or a (P,) sequence."""
    arr = np.asarray(steps)
    if arr.ndim == 0:
        arr = np.full(P, arr)
    if arr.shape != (P,):
        raise ModelError(f"steps: expected an integer or {P} integers, got shape {arr.shape}")
    if (
        arr.dtype.kind not in "iuf"
        or not np.all(np.isfinite(arr))
        or not np.all(arr == np.round(arr))
        or np.any(arr < 1)
    ):
        raise ModelError(f"steps: RK4 steps per period must be integers >= 1, got {steps!r}")
    return np.ascontiguousarray(arr, dtype=np.int64)


def _prepare(
    models: Sequence[Any],
    options: IntegrationOptions,
    steps: int | Sequence[int] | np.ndarray | None,
    state0: Any,
) -> tuple:
    """The models as a :class:`~geardyn.system.Batch` (packed), their steps per sampling period and initial states
    (given ones checked, or each system's :meth:`initial_state`)."""
    models = as_batch(models)
    if not len(models):
        raise ModelError("empty parameter grid: no model to integrate")
    backend = models.backend
    for e in models[0].elements:  # the door refuses a law the kernel has no branch for
        if e.law.code not in backend.laws:
            raise ModelError(f"element {e.name!r}: law {e.law.name}: the {backend.name} kernel does not implement it")
    models.packed()  # a batch packs once (its arrays are kept)
    if steps is None:
        models.check_step(options)
        nsteps = models.natural_steps(options.dtau)
    else:
        nsteps = _steps_array(steps, len(models))
    if state0 is None:
        return models, nsteps, backend.initial_states(models)
    return models, nsteps, _state_array(state0, len(models), models.state_dim, backend.coords)


#: Seconds between two looks at a running kernel's output by :func:`integrate_batch` with ``progress``.
PROGRESS_POLL = 0.25


def _run(
    models: Batch,
    nsteps: np.ndarray,
    state0: np.ndarray,
    options: IntegrationOptions,
    mode: str,
    *,
    threads: int | None = None,
    adaptive: bool = False,
    progress: Callable[[int, int], None] | None = None,
    record_poincare: bool = True,
    **kw: Any,
) -> RawRun:
    """The batch's run by its backend through ``options.transient`` and ``options.periods`` periods in ``mode``
    (``adaptive``: the adaptive transient; ``kw``: ``hist_len``, ``tangent0``, ``tangents`` of :meth:`Backend.run
    <geardyn.backend.Backend.run>`), followed with ``progress``."""
    accurate = options.accurate
    if not accurate and getattr(models[0], "evaluation", "series") == "table":
        raise ModelError(
            'evaluation "table": the table is evaluated as given in the accurate mode only '
            "(--accurate, IntegrationOptions(accurate=True)); or evaluate its series"
        )
    backend, packed = models.backend, models.packed()

    def call(start: np.ndarray, periods: int, watch: Any = None, *, piece: bool = False) -> RawRun:
        """The batch from ``start`` through ``periods`` transient periods and the record (``piece``: the
        transient periods only)."""
        # one point runs on one worker whatever the setting: leave numba's state alone then
        with using_threads(threads if len(models) > 1 else None):
            if piece:
                return backend.run(models, packed, nsteps, start, periods, 0, "none", accurate, record_poincare=False)
            return backend.run(
                models,
                packed,
                nsteps,
                start,
                periods,
                options.periods,
                mode,
                accurate,
                record_poincare=record_poincare,
                adaptive_tol=IntegrationOptions.ADAPTIVE_TOL if adaptive else 0.0,
                watch=watch,
                **kw,
            )

    if progress is None:
        return call(state0, options.transient)
    from .backend import run_followed

    return run_followed(
        call,
        nsteps,
        state0,
        options.transient,
        options.periods,
        progress,
        pieces=not adaptive and backend.restarts_exactly(accurate),
        rows=record_poincare,
        poll=PROGRESS_POLL,
    )


def _result(
    models: Batch, options: IntegrationOptions, raw: RawRun, nsteps: np.ndarray, lyapunov: bool, monodromy: bool
) -> BatchResult:
    m = models[0]
    return BatchResult(
        models,
        options,
        raw.poincare,
        raw.end_state,
        raw.status,
        raw.stats,
        nsteps,
        lyapunov_log=raw.tan_log if lyapunov else None,
        tangent=raw.tangent if (lyapunov or monodromy) else None,
        elements=tuple(e.name for e in m.elements),
        reference=int(m.reference),
        laws=tuple(e.law for e in m.elements),
    )


def integrate_batch(
    models: Sequence[Any],
    state0: Sequence[float] | np.ndarray | None = None,
    options: IntegrationOptions = IntegrationOptions(),
    *,
    lyapunov: bool = False,
    record_poincare: bool = True,
    steps: int | Sequence[int] | np.ndarray | None = None,
    threads: int | None = None,
    monodromy: bool = False,
    tangent0: np.ndarray | None = None,
    progress: Callable[[int, int], None] | None = None,
    tangents: int | None = None,
) -> BatchResult:
    """Integrate P points of one kind of system through ``options.transient + options.periods`` periods.

    Parameters
    ----------
    models : Batch or sequence of System
        One model per point, all of one kind (GearModels may differ in their harmonic counts; systems
        must share their structure); a :class:`~geardyn.system.Batch` (e.g. a grid's points from
        :func:`geardyn.grid.point_models`) is integrated from its own kernel arrays.
    state0 : (d,) or (P, d), optional
        Initial state at θ = 0 (non-dimensional); by default each system's ``initial_state()`` (zeros
        for the pair).
    options : IntegrationOptions
        Step, transient, recorded periods, accurate mode (the adaptive transient: pair only).
    lyapunov : bool
        Propagate the tangent matrix over the recorded periods with Gram–Schmidt every period and
        return the per-period logs (``lyapunov_log``) for :mod:`geardyn.analysis.lyapunov`.
    record_poincare : bool
        Keep the Poincaré points (False saves memory in large sweeps).
    steps : int or (P,) ints, optional
        RK4 steps per sampling period N, the step being h = T_f/N; by default N = ceil(T_f/Δτ) from
        ``options.dtau`` (which is then not used).
    threads : int, optional
        Threads the kernel may use for this batch (default: numba's current setting, which is
        left as it was).
    monodromy : bool
        Propagate the raw tangent matrix over the recorded periods (``tangent``: the monodromy).
    tangent0 : (P, d, d) array, optional
        With ``lyapunov`` (pair only): the tangent basis to start the recorded periods from (the ``tangent``
        a previous run ended with), instead of the identity, so that a run continued in blocks of
        periods gives the same numbers as one run.
    progress : callable, optional
        Called as ``progress(done, total)`` in sampling periods (per point), ``total`` = transient + recorded
        periods, while the batch runs and at its end; the numbers are those of a call without it, bit for bit.
        The transient goes in pieces of whole periods, each reported, where the backend continues a run from a
        period's end state exactly (:meth:`~geardyn.backend.Backend.restarts_exactly`: every mode of a
        mesh-vector system, the pair's default mode; not the adaptive transient); otherwise it counts once
        recording begins.  The recorded periods run in one kernel call in a thread, the rows it has written
        counted every :data:`PROGRESS_POLL` s.
    tangents : int, optional
        With ``lyapunov``: propagate only this many tangent vectors (the leading exponents; a backend may
        propagate more: the pair always takes both), from a fixed generic orthonormal basis; default all d.

    Returns
    -------
    BatchResult
        Section points, end states, statuses and per-element statistics per point.

    Raises
    ------
    ModelError
        For an empty batch, a step not below a sampling period, a bad initial state, ``steps`` or
        ``threads``.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, integrate_batch
    >>> models = [GearModel(omega=0.6), GearModel(omega=0.8)]
    >>> res = integrate_batch(models, (0.0, 0.0), IntegrationOptions(transient=50, periods=4))
    >>> res.poincare.shape, res.ok.tolist()
    ((2, 4, 2), [True, True])
    """
    models, nsteps, s0 = _prepare(models, options, steps, state0)
    mode = "lyapunov" if lyapunov else ("monodromy" if monodromy else "none")
    if tangent0 is not None:
        if not lyapunov:
            raise ModelError("tangent0: a starting tangent basis needs lyapunov=True")
        d = models.state_dim
        tangent0 = np.asarray(tangent0, dtype=float).reshape(len(models), d, d)
        mode = "continue"
    raw = _run(
        models,
        nsteps,
        s0,
        options,
        mode,
        record_poincare=record_poincare,
        threads=threads,
        adaptive=options.adaptive,
        tangent0=tangent0,
        progress=progress,
        tangents=tangents if lyapunov else None,
    )
    return _result(models, options, raw, nsteps, lyapunov, monodromy)


@dataclass
class Trajectory:
    """A single trajectory: the state at every step of its last periods plus its batch summary.

    ``tau`` is non-dimensional time measured from the start of the history window (which
    starts at a period boundary, θ ≡ 0).

    Attributes
    ----------
    model : System
        The point.
    options : IntegrationOptions
        The options it was integrated with.
    tau : ndarray (K,)
        Times of the kept history (every step of the last ``history_periods`` periods).
    x : ndarray (K, d)
        The state at those times (NaN if the trajectory diverged).
    deltas : ndarray (K, elements, 2)
        δ and δ' of every element (``model.element_series``).
    summary : BatchResult
        The batch result of the run (Poincaré points, statistics, status).
    history_periods : int
        Periods of history kept.
    """

    model: Any
    options: IntegrationOptions
    tau: np.ndarray
    x: np.ndarray
    deltas: np.ndarray
    summary: BatchResult
    history_periods: int = field(default=0)

    @property
    def u(self) -> np.ndarray:
        """δ of the reference element (K,): the 1-DOF model's u."""
        return np.ascontiguousarray(self.deltas[:, self.summary.reference, 0])

    @property
    def v(self) -> np.ndarray:
        """δ' of the reference element (K,)."""
        return np.ascontiguousarray(self.deltas[:, self.summary.reference, 1])

    @property
    def poincare(self) -> np.ndarray:
        """Poincaré points (periods, d)."""
        return self.summary.poincare[0]


def trajectory(
    model: Any,
    state0: Sequence[float] | np.ndarray | None = None,
    options: IntegrationOptions = IntegrationOptions(),
    *,
    history_periods: int = 32,
    steps: int | None = None,
    threads: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    history_steps: int | None = None,
) -> Trajectory:
    """Integrate one point and keep the state at every step of its last ``history_periods`` periods.

    Parameters
    ----------
    model : System
        The model.
    state0 : (d,), optional
        Initial state at θ = 0 (default ``model.initial_state()``: (0, 0) for the pair).
    options : IntegrationOptions
        Step, transient, recorded periods, accurate mode.
    history_periods : int
        Periods kept at every step (at most ``options.periods``).
    steps : int, optional
        RK4 steps per sampling period (default ceil(T_f/Δτ)).
    threads : int, optional
        Threads for this call (numba's setting is left as it was).
    progress : callable, optional
        Called as ``progress(done, total)`` in sampling periods while the point runs, as by
        :func:`integrate_batch`; the numbers are those of a call without it, bit for bit.
    history_steps : int, optional
        Keep only the last ``history_steps`` steps (fewer than ``history_periods`` periods' worth; a mesh-vector
        system only): a long forcing period's history within a memory budget.

    Returns
    -------
    Trajectory
        The history and the batch summary.

    Raises
    ------
    ModelError
        For a step not below the sampling period, a bad initial state or ``steps``.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, trajectory
    >>> tr = trajectory(GearModel(omega=0.8), (0.0, 0.0), IntegrationOptions(transient=50, periods=4))
    >>> tr.poincare.shape  # the Poincaré points (u, u') of the 4 recorded periods
    (4, 2)
    """
    models, nsteps, s0 = _prepare([model], options, steps, state0)
    hp = int(min(max(history_periods, 1), options.periods))
    N = int(nsteps[0])
    K = hp * N + 1
    if history_steps is not None and 1 <= int(history_steps) < hp * N and int(model.state_dim) > 2:
        K = int(history_steps) + 1
    raw = _run(
        models,
        nsteps,
        s0,
        options,
        "none",
        hist_len=K,
        threads=threads,
        progress=progress,
    )
    summary = _result(models, options, raw, nsteps, False, False)
    tau = np.arange(K) * (model.sampling_period / N)
    x = raw.hist[0]
    if raw.status[0] != ST_OK:
        x = np.full_like(x, np.nan)
    return Trajectory(model, options, tau, x, model.element_series(x, tau), summary, hp)


def period_map(
    model: Any,
    state: Sequence[float],
    n: int = 1,
    *,
    dtau: float = IntegrationOptions().dtau,
    accurate: bool = False,
    steps: int | None = None,
    threads: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The n-period stroboscopic map and its Jacobian.

    Parameters
    ----------
    model : System
        The model.
    state : (d,)
        The state at θ = 0.
    n : int
        Sampling periods of the map P^n.
    dtau : float
        Target step Δτ; N = ceil(T_f/Δτ) steps per period unless ``steps`` is given.
    accurate : bool
        Split steps at the contact boundaries.
    steps : int, optional
        RK4 steps per sampling period N (the step is h = T_f/N; ``dtau`` is then not used).
    threads : int, optional
        Threads for this call (numba's setting is left as it was).

    Returns
    -------
    points : ndarray (n, d)
        The state after each of the n periods (the last is P^n(state)).
    monodromy : ndarray (d, d)
        The derivative of P^n at ``state`` (tangent propagation of the same kernel: the exact
        Jacobian of the discrete map in the default mode).
    stats : ndarray (elements, NSTAT)
        The streaming statistics of every element over the n periods.
    ok : bool
        False if the trajectory diverged.

    Raises
    ------
    ModelError
        For a step not below the sampling period, a bad state or ``steps``.

    Examples
    --------
    >>> from geardyn import GearModel, period_map
    >>> x, jac, stats, ok = period_map(GearModel(omega=0.8), (0.0, 0.0), 1)
    >>> x.shape, jac.shape, bool(ok)
    ((1, 2), (2, 2), True)
    """
    opts = IntegrationOptions(dtau=dtau, transient=0, periods=int(n), accurate=accurate)
    models, nsteps, s0 = _prepare([model], opts, steps, state)
    raw = _run(models, nsteps, s0, opts, "monodromy", threads=threads)
    return raw.poincare[0], raw.tangent[0], raw.stats[0], bool(raw.status[0] == ST_OK)
