"""Integration of the non-dimensional model: batches, trajectories, period maps.

This is the only module that talks to the numba kernel (:mod:`geardyn._kernel`).  Every analysis
(simulation, sweeps, Lyapunov spectra, shooting) goes through :func:`integrate_batch`,
:func:`trajectory` or :func:`period_map`.

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

from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterator, Sequence

import numpy as np

from . import _kernel as K
from .model import GearModel, IntegrationOptions, ModelError, pack_models, steps_per_period

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
    "STATE_DIM",
    "ST_OK",
    "ST_DIVERGED",
    "DIVERGENCE_BOUND",
]

ST_OK = K.ST_OK
ST_DIVERGED = K.ST_DIVERGED
DIVERGENCE_BOUND = K.DIVERGENCE_BOUND
#: Dimension of the state the kernel integrates: (u, u') of the 1-DOF model.
STATE_DIM = 2


def state_dim(model: GearModel) -> int:
    """Dimension of the state of ``model`` as the kernel integrates it (the length of ``state0``).

    Parameters
    ----------
    model : GearModel
        The system.

    Returns
    -------
    int
        ``model.state_dim`` (:data:`STATE_DIM` = 2, (u, u'), for the 1-DOF model).
    """
    return int(model.state_dim)


def natural_steps(model: GearModel, dtau: float) -> int:
    """The RK4 steps per forcing period the kernel takes for ``model`` when none are given.

    Parameters
    ----------
    model : GearModel
        The model.
    dtau : float
        Target step Δτ.

    Returns
    -------
    int
        N = ceil(T/Δτ), so that h = T/N <= Δτ (:func:`geardyn.model.steps_per_period`).
    """
    return int(steps_per_period(model.omega, dtau))


def _thread_count(n: int) -> int:
    import numba

    try:
        whole = not isinstance(n, bool) and float(n).is_integer()
    except (TypeError, ValueError, OverflowError):
        whole = False
    if not whole:
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


@dataclass
class _Batch:
    """The fields and totals of a batch result, the same for :class:`BatchResult` and
    :class:`geardyn.integrate_ndof.SystemBatchResult` (the shapes along the state axis differ)."""

    models: list
    options: IntegrationOptions
    poincare: np.ndarray
    end_state: np.ndarray
    status: np.ndarray
    stats: np.ndarray
    nsteps: np.ndarray
    lyapunov_log: np.ndarray | None = None
    tangent: np.ndarray | None = None

    @property
    def ok(self) -> np.ndarray:
        """Whether each point finished without diverging (P,)."""
        return self.status == ST_OK

    @property
    def amplitude(self) -> np.ndarray:
        """Half peak-to-peak displacement (u_max − u_min)/2 over the recorded periods."""
        return 0.5 * (self.u_max - self.u_min)

    @property
    def total_steps(self) -> int:
        """RK4 steps the batch took, transient included."""
        o = self.options
        return int(np.sum(self.nsteps) * (o.transient + o.periods))


def _statistic(k: int, doc: str) -> property:
    """The read-only property of the streaming statistic ``stats[:, k]``, NaN where diverged."""
    return property(lambda self: self._masked(self.stats[:, k]), doc=doc)


@dataclass
class BatchResult(_Batch):
    """Results for P parameter points integrated together (all non-dimensional).

    Attributes
    ----------
    models : list of GearModel
        The points, in batch order.
    options : IntegrationOptions
        The options they were integrated with.
    poincare : ndarray (P, n, d)
        The state at θ ≡ 0 mod 2π at the end of each recorded period; NaN where diverged.
    end_state : ndarray (P, d)
        Final state (the start state for a continuation sweep).
    status : ndarray (P,)
        ``ST_OK`` or ``ST_DIVERGED``.
    stats : ndarray (P, NSTAT)
        Streaming statistics over the recorded periods, sampled at every step.
    lyapunov_log : ndarray (P, n, 2) or None
        Per recorded period, the logs of the Gram–Schmidt diagonal (Lyapunov mode).
    tangent : ndarray (P, 2, 2) or None
        Final tangent matrix: the monodromy over the recorded periods in monodromy mode.
    nsteps : ndarray (P,)
        RK4 steps per forcing period.
    """

    def _masked(self, x: np.ndarray) -> np.ndarray:
        return np.where(self.ok, x, np.nan)

    def _per_sample(self, x: np.ndarray) -> np.ndarray:
        """x / number of samples; NaN where no sample was taken (diverged before recording)."""
        n = self.stats[:, K.S_N]
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, x / np.where(n > 0, n, 1.0), np.nan)

    u_min = _statistic(K.S_UMIN, "Smallest u over the recorded periods (P,); NaN where diverged.")
    u_max = _statistic(K.S_UMAX, "Largest u over the recorded periods (P,); NaN where diverged.")
    v_min = _statistic(K.S_VMIN, "Smallest u' over the recorded periods (P,); NaN where diverged.")
    v_max = _statistic(K.S_VMAX, "Largest u' over the recorded periods (P,); NaN where diverged.")

    @property
    def mean(self) -> np.ndarray:
        return self._masked(self._per_sample(self.stats[:, K.S_USUM]))

    @property
    def rms(self) -> np.ndarray:
        """RMS of the fluctuation u − mean(u) over the recorded periods."""
        m = self._per_sample(self.stats[:, K.S_USUM])
        var = np.maximum(self._per_sample(self.stats[:, K.S_USQ]) - m * m, 0.0)
        return self._masked(np.sqrt(var))

    @property
    def contact_fractions(self) -> np.ndarray:
        """(P, 3) time fractions in drive-side contact, separation and back-side contact."""
        f = np.stack([self._per_sample(self.stats[:, k]) for k in (K.S_NDRIVE, K.S_NSEP, K.S_NBACK)], axis=1)
        return np.where(self.ok[:, None], f, np.nan)


def _state_array(state0: Sequence[float] | np.ndarray | None, P: int, d: int = STATE_DIM,
                 coords: str = "(u0, v0)") -> np.ndarray:
    """The (P, d) initial states of a batch from one state (d,) or one per point (P, d), checked;
    ``coords`` names the state's coordinates in the messages."""
    if state0 is None:
        return np.zeros((P, d))
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
    if arr.dtype.kind not in "iuf" or arr.dtype == bool or not np.all(np.isfinite(arr)) \
            or not np.all(arr == np.round(arr)) or np.any(arr < 1):
        raise ModelError(f"steps: RK4 steps per period must be integers >= 1, got {steps!r}")
    return np.ascontiguousarray(arr, dtype=np.int64)


def _prepare(models: Sequence[GearModel], options: IntegrationOptions,
             steps: int | Sequence[int] | np.ndarray | None = None):
    models = list(models)
    coef, D, omega = pack_models(models)
    if steps is None:
        for m in models:
            options.check_for(m.omega)
        nsteps = steps_per_period(omega, options.dtau)
    else:
        nsteps = _steps_array(steps, len(models))
    return models, coef, D, omega, nsteps


def _run(coef, D, omega, nsteps, state0, n_transient, n_record, tangent, accurate,
         record_poincare=True, hist_len=0, lyapunov=False, threads=None, adaptive=False, tangent0=None):
    P = coef.shape[0]
    d = STATE_DIM  # the kernel's buffers: it integrates the 1-DOF mesh, state (u, u')
    poincare = np.zeros((P, n_record if record_poincare else 0, d))
    end_state = np.zeros((P, d))
    stats = np.zeros((P, K.NSTAT))
    tan_log = np.zeros((P, n_record if lyapunov else 0, d))
    tan_out = np.zeros((P, d, d))
    if tangent0 is not None:  # K.TAN_CONTINUE: the kernel starts the tangent basis from these
        tan_out[:] = tangent0
    status = np.zeros(P, dtype=np.int64)
    hist = np.zeros((P, hist_len, d))
    # one point runs on one worker whatever the setting: leave numba's state alone then
    with using_threads(threads if P > 1 else None):
        if adaptive:
            from .analysis.classify import MAX_PERIOD

            K.run_batch(coef, D, omega, nsteps, state0, int(n_transient), int(n_record), int(tangent),
                        bool(accurate), poincare, end_state, stats, tan_log, tan_out, status, hist,
                        IntegrationOptions.ADAPTIVE_TOL, MAX_PERIOD)
        else:
            K.run_batch(coef, D, omega, nsteps, state0, int(n_transient), int(n_record), int(tangent),
                        bool(accurate), poincare, end_state, stats, tan_log, tan_out, status, hist)
    return poincare, end_state, stats, tan_log, tan_out, status, hist


def integrate_batch(
    models: Sequence[GearModel],
    state0: Sequence[float] | np.ndarray | None = None,
    options: IntegrationOptions = IntegrationOptions(),
    *,
    lyapunov: bool = False,
    record_poincare: bool = True,
    steps: int | Sequence[int] | np.ndarray | None = None,
    threads: int | None = None,
    tangent0: np.ndarray | None = None,
) -> BatchResult:
    """Integrate P parameter points through ``options.transient + options.periods`` periods.

    Parameters
    ----------
    models : sequence of GearModel
        One model per parameter point (their harmonic counts may differ).
    state0 : (2,) or (P, 2), optional
        Initial (u, u') at θ = 0 (non-dimensional); zeros by default.
    options : IntegrationOptions
        Step, transient, recorded periods, accurate mode.
    lyapunov : bool
        Propagate the tangent matrix over the recorded periods with Gram–Schmidt every period and
        return the per-period logs (``lyapunov_log``) for :mod:`geardyn.analysis.lyapunov`.
    record_poincare : bool
        Keep the Poincaré points (False saves memory in large sweeps).
    steps : int or (P,) ints, optional
        RK4 steps per forcing period N, the step being h = T/N; by default N = ceil(T/Δτ) from
        ``options.dtau`` (which is then not used).
    threads : int, optional
        Threads the kernel may use for this batch (default: numba's current setting, which is
        left as it was).
    tangent0 : (P, 2, 2) array, optional
        With ``lyapunov``: the tangent basis to start the recorded periods from (the ``tangent`` a
        previous run ended with), instead of the identity, so that a run continued in blocks of
        periods gives the same numbers as one run.

    Returns
    -------
    BatchResult
        Section points, end states, statuses and statistics per point.

    Raises
    ------
    ModelError
        For an empty grid, a step not below a forcing period, a bad initial state, ``steps`` or
        ``threads``.
    """
    models, coef, D, omega, nsteps = _prepare(models, options, steps)
    s0 = _state_array(state0, len(models), state_dim(models[0]))
    tangent = K.TAN_LYAPUNOV if lyapunov else K.TAN_NONE
    if tangent0 is not None:
        if not lyapunov:
            raise ModelError("tangent0: a starting tangent basis needs lyapunov=True")
        tangent0 = np.asarray(tangent0, dtype=float).reshape(len(models), 2, 2)
        tangent = K.TAN_CONTINUE
    pc, end, stats, tl, tout, status, _ = _run(coef, D, omega, nsteps, s0, options.transient, options.periods,
                                               tangent, options.accurate, record_poincare, 0, lyapunov,
                                               threads, options.adaptive, tangent0)
    return BatchResult(models, options, pc, end, status, stats, nsteps,
                       lyapunov_log=tl if lyapunov else None, tangent=tout if lyapunov else None)


@dataclass
class Trajectory:
    """A single trajectory: the time history of its last periods plus its batch summary.

    ``tau`` is non-dimensional time measured from the start of the history window (which
    starts at a period boundary, θ ≡ 0), ``u`` and ``v`` = u' are non-dimensional.

    Attributes
    ----------
    model : GearModel
        The point.
    options : IntegrationOptions
        The options it was integrated with.
    tau, u, v : ndarray
        The time history of the last ``history_periods`` periods (every step).
    summary : BatchResult
        The batch result of the run (Poincaré points, statistics, status).
    history_periods : int
        Periods of history kept.
    """

    model: GearModel
    options: IntegrationOptions
    tau: np.ndarray
    u: np.ndarray
    v: np.ndarray
    summary: BatchResult
    history_periods: int = field(default=0)

    @property
    def poincare(self) -> np.ndarray:
        return self.summary.poincare[0]


def trajectory(
    model: GearModel,
    state0: Sequence[float] = (0.0, 0.0),
    options: IntegrationOptions = IntegrationOptions(),
    *,
    history_periods: int = 32,
    steps: int | None = None,
    threads: int | None = None,
) -> Trajectory:
    """Integrate one point and keep the state at every step of its last ``history_periods`` periods.

    Parameters
    ----------
    model : GearModel
        The model.
    state0 : (2,)
        Initial (u, u') at θ = 0.
    options : IntegrationOptions
        Step, transient, recorded periods, accurate mode.
    history_periods : int
        Periods kept at every step (at most ``options.periods``).
    steps : int, optional
        RK4 steps per forcing period (default ceil(T/Δτ)).
    threads : int, optional
        Threads for this call (numba's setting is left as it was).

    Returns
    -------
    Trajectory
        The history and the batch summary.

    Raises
    ------
    ModelError
        For a step not below the forcing period, a bad initial state or ``steps``.
    """
    models, coef, D, omega, nsteps = _prepare([model], options, steps)
    hp = int(min(max(history_periods, 1), options.periods))
    N = int(nsteps[0])
    s0 = _state_array(state0, 1, state_dim(model))
    pc, end, stats, _, _, status, hist = _run(coef, D, omega, nsteps, s0, options.transient, options.periods,
                                              K.TAN_NONE, options.accurate, True, hp * N + 1, False, threads)
    summary = BatchResult(models, options, pc, end, status, stats, nsteps)
    h = model.period / N
    tau = np.arange(hp * N + 1) * h
    u, v = hist[0, :, 0].copy(), hist[0, :, 1].copy()
    if status[0] != ST_OK:
        u[:] = np.nan
        v[:] = np.nan
    return Trajectory(model, options, tau, u, v, summary, hp)


def period_map(
    model: GearModel,
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
    model : GearModel
        The model.
    state : (2,)
        (u, u') at θ = 0.
    n : int
        Forcing periods of the map P^n.
    dtau : float
        Target step Δτ; N = ceil(T/Δτ) steps per period unless ``steps`` is given.
    accurate : bool
        Split steps at the contact boundaries.
    steps : int, optional
        RK4 steps per forcing period N (the step is h = T/N; ``dtau`` is then not used).
    threads : int, optional
        Threads for this call (numba's setting is left as it was).

    Returns
    -------
    points : ndarray (n, 2)
        The state after each of the n periods (the last is P^n(state)).
    monodromy : ndarray (2, 2)
        The derivative of P^n at ``state`` (tangent propagation of the same kernel: the exact
        Jacobian of the discrete map in the default mode).
    stats : ndarray (NSTAT,)
        The streaming statistics over the n periods.
    ok : bool
        False if the trajectory diverged.

    Raises
    ------
    ModelError
        For a step not below the forcing period, a bad state or ``steps``.
    """
    opts = IntegrationOptions(dtau=dtau, transient=0, periods=int(n), accurate=accurate)
    models, coef, D, omega, nsteps = _prepare([model], opts, steps)
    s0 = _state_array(state, 1, state_dim(model))
    pc, end, stats, _, tout, status, _ = _run(coef, D, omega, nsteps, s0, 0, int(n), K.TAN_MONODROMY, accurate,
                                              threads=threads)
    return pc[0], tout[0], stats[0], bool(status[0] == ST_OK)
