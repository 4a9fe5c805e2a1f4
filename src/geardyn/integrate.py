"""Integration of the non-dimensional model: batches, trajectories, period maps.

This is the only module that talks to the numba kernel (:mod:`geardyn._kernel`).  Every analysis
(simulation, sweeps, Lyapunov spectra, shooting) goes through :func:`integrate_batch`,
:func:`trajectory` or :func:`period_map`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

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
    "ST_OK",
    "ST_DIVERGED",
    "DIVERGENCE_BOUND",
]

ST_OK = K.ST_OK
ST_DIVERGED = K.ST_DIVERGED
DIVERGENCE_BOUND = K.DIVERGENCE_BOUND


def set_threads(n: int | None) -> None:
    """Set the number of threads the kernel uses (None: leave numba's default, all cores)."""
    if n is None:
        return
    import numba

    if n < 1:
        raise ModelError(f"threads: must be >= 1, got {n}")
    numba.set_num_threads(min(int(n), numba.config.NUMBA_NUM_THREADS))


@dataclass
class BatchResult:
    """Results for P parameter points integrated together (all non-dimensional).

    Attributes
    ----------
    poincare : ndarray (P, n, 2)
        (u, u') at θ ≡ 0 mod 2π at the end of each recorded period; NaN where diverged.
    end_state : ndarray (P, 2)
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

    models: list[GearModel]
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
        return self.status == ST_OK

    def _masked(self, x: np.ndarray) -> np.ndarray:
        return np.where(self.ok, x, np.nan)

    def _per_sample(self, x: np.ndarray) -> np.ndarray:
        """x / number of samples; NaN where no sample was taken (diverged before recording)."""
        n = self.stats[:, K.S_N]
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, x / np.where(n > 0, n, 1.0), np.nan)

    @property
    def u_min(self) -> np.ndarray:
        return self._masked(self.stats[:, K.S_UMIN])

    @property
    def u_max(self) -> np.ndarray:
        return self._masked(self.stats[:, K.S_UMAX])

    @property
    def v_min(self) -> np.ndarray:
        return self._masked(self.stats[:, K.S_VMIN])

    @property
    def v_max(self) -> np.ndarray:
        return self._masked(self.stats[:, K.S_VMAX])

    @property
    def amplitude(self) -> np.ndarray:
        """Half peak-to-peak displacement (u_max − u_min)/2 over the recorded periods."""
        return 0.5 * (self.u_max - self.u_min)

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

    @property
    def total_steps(self) -> int:
        o = self.options
        return int(np.sum(self.nsteps) * (o.transient + o.periods))


def _state_array(state0: Sequence[float] | np.ndarray | None, P: int) -> np.ndarray:
    if state0 is None:
        return np.zeros((P, 2))
    s = np.asarray(state0, dtype=float)
    if s.shape == (2,):
        s = np.broadcast_to(s, (P, 2))
    if s.shape != (P, 2):
        raise ModelError(f"initial state: expected shape (2,) or ({P}, 2), got {s.shape}")
    if not np.all(np.isfinite(s)):
        raise ModelError("initial state (u0, v0): must be finite")
    return np.ascontiguousarray(s, dtype=float)


def _prepare(models: Sequence[GearModel], options: IntegrationOptions):
    models = list(models)
    coef, D, omega = pack_models(models)
    for m in models:
        options.check_for(m.omega)
    nsteps = steps_per_period(omega, options.dtau)
    return models, coef, D, omega, nsteps


def _run(coef, D, omega, nsteps, state0, n_transient, n_record, tangent, accurate,
         record_poincare=True, hist_len=0, lyapunov=False):
    P = coef.shape[0]
    poincare = np.zeros((P, n_record if record_poincare else 0, 2))
    end_state = np.zeros((P, 2))
    stats = np.zeros((P, K.NSTAT))
    tan_log = np.zeros((P, n_record if lyapunov else 0, 2))
    tan_out = np.zeros((P, 2, 2))
    status = np.zeros(P, dtype=np.int64)
    hist = np.zeros((P, hist_len, 2))
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
    """
    models, coef, D, omega, nsteps = _prepare(models, options)
    s0 = _state_array(state0, len(models))
    tangent = K.TAN_LYAPUNOV if lyapunov else K.TAN_NONE
    pc, end, stats, tl, tout, status, _ = _run(coef, D, omega, nsteps, s0, options.transient, options.periods,
                                               tangent, options.accurate, record_poincare, 0, lyapunov)
    return BatchResult(models, options, pc, end, status, stats, nsteps,
                       lyapunov_log=tl if lyapunov else None, tangent=tout if lyapunov else None)


@dataclass
class Trajectory:
    """A single trajectory: the time history of its last periods plus its batch summary.

    ``tau`` is non-dimensional time measured from the start of the history window (which
    starts at a period boundary, θ ≡ 0), ``u`` and ``v`` = u' are non-dimensional.
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
) -> Trajectory:
    """Integrate one point and keep the state at every step of its last ``history_periods`` periods."""
    models, coef, D, omega, nsteps = _prepare([model], options)
    hp = int(min(max(history_periods, 1), options.periods))
    N = int(nsteps[0])
    s0 = _state_array(state0, 1)
    pc, end, stats, _, _, status, hist = _run(coef, D, omega, nsteps, s0, options.transient, options.periods,
                                              K.TAN_NONE, options.accurate, True, hp * N + 1)
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
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """The n-period stroboscopic map and its Jacobian.

    Returns ``(points, monodromy, stats, ok)``: ``points`` (n, 2) the state after each of the n
    periods (the last is P^n(state)), ``monodromy`` (2, 2) the derivative of P^n at ``state``
    (tangent propagation of the same kernel: the exact Jacobian of the discrete map in the
    default mode), ``stats`` the streaming statistics over the n periods, ``ok`` False if the
    trajectory diverged.
    """
    opts = IntegrationOptions(dtau=dtau, transient=0, periods=int(n), accurate=accurate)
    models, coef, D, omega, nsteps = _prepare([model], opts)
    s0 = _state_array(state, 1)
    pc, end, stats, _, tout, status, _ = _run(coef, D, omega, nsteps, s0, 0, int(n), K.TAN_MONODROMY, accurate)
    return pc[0], tout[0], stats[0], bool(status[0] == ST_OK)

