"""The transient from the physics: the decay time of the least damped mode of the linearised system.

``--transient auto`` (:func:`settle_periods`) discards, before recording, the forcing periods in which the
slowest free vibration of the system linearised at its mean stiffness and damping has decayed by e^-K
(:data:`DECAY_EFOLDS` = 12, a factor 6.1e-6), in place of a fixed count.

The linearisation: the state matrix A = [[0, I], [−M̃⁻¹K̄, −M̃⁻¹C̄]] with K̄, C̄ the mean stiffness and damping:
the connections (bearings, shafts, couplings), every mesh at its mean stiffness k and damping 2ξ0 in contact,
every clearance in contact.  Its eigenvalues λ give the decay rates σ = −Re λ of the free vibrations; the
eigenvalues at 0 (the free drift of a rigid-body mode, which never decays and is not a transient of the
response) are left out.  The least damped mode's rate σ_min sets the time t = K/σ_min (τ units).  For the gear
pair (u'' + 2ξ0 u' + u in its own scaling, ω_n = 1) σ_min = ξ0 (ζ ω_n) when ξ0 < 1; a deflection then decays as
e^(−ξ0 τ) exactly.  The count is ceil(t / T_f) forcing periods T_f = p·2π/ω at the highest ω of the run
(the count grows with ω), at least :data:`FLOOR_PERIODS` and at most :data:`CAP_PERIODS`.

Where it is sound: the decay of a *linear* transient.  A nonlinear response (contact loss, impacts, a
rattling clearance) can settle onto its attractor more slowly than the linearised modes decay, or not at all
(chaos); the classification then keeps its own adaptive passes after the transient (``response --settle``,
``geardyn.analysis.classify``), which integrate further periods for points not yet periodic.  A mode without
damping (σ_min = 0 with a non-zero λ) gives no decay time: ``auto`` is refused for it.  The rate is that of the
model's parameters as given: a sweep of a damping parameter gets the count of the run's base model.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ModelError
from ..system import require_periodic

__all__ = [
    "CAP_PERIODS",
    "CLASSIFY_CYCLES",
    "CLASSIFY_SECTION",
    "CYCLES_SUFFIX",
    "DECAY_EFOLDS",
    "FLOOR_PERIODS",
    "LongRun",
    "RECORD_FLOOR",
    "Settling",
    "classify_budget",
    "long_run",
    "cycles_to_periods",
    "decay_rate",
    "decay_rates",
    "settle_periods",
    "transient_cycles",
    "unsettled_note",
]

#: e-folds of decay of the least damped mode before recording (e^-12 = 6.1e-6).
DECAY_EFOLDS = 12.0
#: Fewest forcing periods of an automatic transient.
FLOOR_PERIODS = 4
#: Most forcing periods of an automatic transient (a longer decay is capped, and the cap is said).
CAP_PERIODS = 20_000
#: Eigenvalues of A with |λ| below this times max(1, max |λ|) are a rigid-body drift, not a transient.
RIGID_RTOL = 1e-9


@dataclass(frozen=True)
class Settling:
    """An automatic transient.

    Attributes
    ----------
    periods : int
        Forcing periods to discard.
    rate : float
        σ_min, the decay rate of the least damped mode per unit τ.
    time : float
        K/σ_min, the decay time in τ units.
    forcing_period : float
        The forcing period T_f (τ units) the count is for (at the highest ω).
    capped, floored : bool
        Whether the count was raised to :data:`FLOOR_PERIODS` or cut to :data:`CAP_PERIODS`.
    """

    periods: int
    rate: float
    time: float
    forcing_period: float
    capped: bool = False
    floored: bool = False

    def note(self) -> str:
        """One line for stderr."""
        s = (
            f"transient auto: {self.periods} forcing periods (the least damped mode decays as e^(-{self.rate:.4g} τ): "
            f"e^-{DECAY_EFOLDS:g} after τ = {self.time:.4g}, forcing period {self.forcing_period:.4g})"
        )
        if self.capped:
            s += f"; capped at {CAP_PERIODS}: the slowest mode has not decayed by e^-{DECAY_EFOLDS:g}"
        return s


def _mean_matrices(model: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M̃⁻¹, K̄, C̄ of the model linearised at its mean stiffness and damping (contact everywhere)."""
    if hasattr(model, "Mi"):  # a mesh-vector system
        Mi = np.asarray(model.Mi, dtype=float)
        K = np.array(model.Kb, dtype=float)
        C = np.array(model.Cb, dtype=float)
        meshes = [(v, m.k, 2.0 * m.xi0) for v, m in zip(model.V, model.meshes)]
        for v, k, c in meshes + list(zip(model.Vc, model.kc, model.cc)):
            vv = np.outer(v, v)
            K += k * vv
            C += c * vv
        return Mi, K, C
    xi0 = getattr(model, "xi0", None)
    if xi0 is None:
        raise ModelError(f"transient: auto needs a gear pair or a mesh-vector system, not {type(model).__name__}")
    return np.eye(1), np.eye(1), np.array([[2.0 * float(xi0)]])


def decay_rate(model: Any) -> float:
    """σ_min: the smallest decay rate −Re λ of the model's linearised free vibrations (rigid drift left out).

    Parameters
    ----------
    model : GearModel or SystemModel

    Returns
    -------
    float
        Per unit τ; for the gear pair ξ0 when ξ0 < 1, ξ0 − √(ξ0² − 1) when overdamped.

    Raises
    ------
    ModelError
        When a mode is undamped (no decay time) or grows.
    """
    Mi, K, C = _mean_matrices(model)
    n = Mi.shape[0]
    # Coordinates y = Qᵀx with Q = [R, N], R the null space of K̄ (rigid-body directions): the positions a along
    # R enter no force, so they are left out of the state (their r eigenvalues are exactly 0, a drift).
    w, Q = np.linalg.eigh(0.5 * (K + K.T))
    rigid = np.abs(w) <= RIGID_RTOL * max(1.0, float(np.max(np.abs(w))))
    Q = np.concatenate([Q[:, rigid], Q[:, ~rigid]], axis=1)
    r = int(np.sum(rigid))
    G = Q.T @ Mi @ K @ Q
    H = Q.T @ Mi @ C @ Q
    m = n - r
    A = np.zeros((m + n, m + n))  # state (b, y'): b the elastic coordinates, y' all velocities
    A[:m, m + r :] = np.eye(m)
    A[m:, :m] = -G[:, r:]
    A[m:, m:] = -H
    lam = np.linalg.eigvals(A)
    tol = RIGID_RTOL * max(1.0, float(np.max(np.abs(lam))))
    lam = lam[np.abs(lam) > tol]  # an undamped rigid velocity (a free constant speed) is no transient either
    if lam.size == 0:
        raise ModelError("transient: auto needs a mode that decays; the linearised system has none")
    sigma = float(np.min(-lam.real))
    if not sigma > tol:
        raise ModelError(
            f"transient: auto needs every mode damped; the least damped has decay rate {max(sigma, 0.0):.3g} "
            "(give --transient as a number of forcing periods)"
        )
    return sigma


def decay_rates(models: Any, which: Iterable[int]) -> np.ndarray:
    """σ_min (:func:`decay_rate`) of the points ``which`` of a batch, NaN at every other point and where a mode
    is undamped or grows (no decay rate: such a model does not hide a torus, see
    :func:`geardyn.analysis.classify.decay_hides_torus`).

    Parameters
    ----------
    models : Batch
        The points.
    which : iterable of int
        The points to compute.

    Returns
    -------
    ndarray (P,)

    Examples
    --------
    >>> from geardyn import GearModel
    >>> from geardyn.system import ModelList
    >>> np.round(decay_rates(ModelList([GearModel(xi0=0.05), GearModel(xi0=0.1)]), [1]), 12).tolist()
    [nan, 0.1]
    """
    out = np.full(len(models), np.nan)
    for i in which:
        try:
            out[int(i)] = decay_rate(models[int(i)])
        except ModelError:
            pass
    return out


def settle_periods(
    model: Any,
    omegas: Iterable[float] | None = None,
    *,
    decay: float = DECAY_EFOLDS,
    floor: int = FLOOR_PERIODS,
    cap: int = CAP_PERIODS,
) -> Settling:
    """The forcing periods in which the least damped linearised mode decays by e^-``decay``.

    Parameters
    ----------
    model : GearModel or SystemModel
        The run's model (its forcing period at its own ω scales as 1/ω).
    omegas : iterable of float, optional
        The frequencies of the run; the count is that of the highest (default: the model's ω).
    decay : float
        e-folds K of decay.
    floor, cap : int
        Fewest and most periods.

    Returns
    -------
    Settling

    Examples
    --------
    >>> from geardyn import GearModel
    >>> s = settle_periods(GearModel(omega=0.8, xi0=0.05))
    >>> round(s.rate, 12), s.periods  # 12/0.05 = 240 τ over T = 2π/0.8 = 7.854: 30.6 periods
    (0.05, 31)
    """
    sigma = decay_rate(model)
    w0 = float(model.omega)
    ws = [w0] if omegas is None else [float(w) for w in np.atleast_1d(np.asarray(list(omegas) or [w0], dtype=float))]
    T = float(model.sampling_period) * w0 / max(ws)
    t = float(decay) / sigma
    raw = math.ceil(t / T - 1e-9)
    n = min(max(raw, int(floor)), int(cap))
    return Settling(n, sigma, t, T, capped=raw > cap, floored=raw < floor)


def unsettled_note(model: Any, transient: int) -> str | None:
    """One line when ``transient`` forcing periods leave the least damped linearised mode undecayed (less than
    e^-:data:`DECAY_EFOLDS`): its decay, how far the transient takes it and the count ``auto`` would take; None
    when the transient suffices or no mode has a decay time.

    Parameters
    ----------
    model : System
        The run's model.
    transient : int
        Forcing periods discarded before recording.

    Returns
    -------
    str or None

    Examples
    --------
    >>> from geardyn import GearModel
    >>> print(unsettled_note(GearModel(omega=0.8, xi0=0.001), 300))  # doctest: +NORMALIZE_WHITESPACE
    transient: 300 forcing periods decay the least damped mode (e^(-0.001 τ)) to e^-2.36 only; e^-12 needs 1528
    (--transient auto)
    >>> unsettled_note(GearModel(omega=0.8), 300) is None
    True
    """
    try:
        sigma = decay_rate(model)
    except ModelError:
        return None
    T = float(model.sampling_period)
    folds = sigma * T * int(transient)
    if folds >= DECAY_EFOLDS:
        return None
    need = math.ceil(DECAY_EFOLDS / (sigma * T) - 1e-9)
    return (
        f"transient: {int(transient)} forcing periods decay the least damped mode (e^(-{sigma:.3g} τ)) to "
        f"e^-{folds:.3g} only; e^-{DECAY_EFOLDS:g} needs {need} (--transient auto)"
    )


#: The suffix of ``--transient`` meaning reference mesh cycles (``--transient 3000cycles``).
CYCLES_SUFFIX = "cycles"


def transient_cycles(text: str) -> int | None:
    """The count of reference mesh cycles of a ``--transient`` text ``Ncycles``; ``None`` for a text
    without a letter (a count of forcing periods) or ``auto``.

    Parameters
    ----------
    text : str
        The option's text (``"3000cycles"``, ``"300"``, ``"auto"``; case and surrounding spaces ignored).

    Returns
    -------
    int or None

    Raises
    ------
    ModelError
        For any other suffix, or a count that is not a whole number >= 0 (one line naming ``--transient``).
    """
    t = text.strip().lower()
    if t == "auto" or not any(c.isalpha() for c in t):
        return None
    head = t[: -len(CYCLES_SUFFIX)].strip() if t.endswith(CYCLES_SUFFIX) else None
    if head is None or not head.isdigit():
        raise ModelError(
            f"--transient: must be an integer (forcing periods, >= 0), Ncycles (reference mesh cycles, N >= 0, "
            f"e.g. 3000cycles) or auto, got {text!r}"
        )
    return int(head)


def cycles_to_periods(cycles: int, model: Any) -> int:
    """Forcing periods covering ``cycles`` reference mesh cycles: ceil(cycles / P), P =
    ``model.period_multiple()`` (1 for the pair with a one-period excitation).

    Parameters
    ----------
    cycles : int
        Reference mesh cycles (>= 0).
    model : System
        The run's system.

    Returns
    -------
    int

    Raises
    ------
    ModelError
        For a quasi-periodic system (no forcing period).
    """
    p = require_periodic(model, "--transient in mesh cycles")
    return -(-int(cycles) // int(p))


# ---------------------------------------------------------------- the defaults of a long forcing period
#: Fewest forcing periods recorded by default when a forcing period spans several reference mesh cycles: with 4
#: Poincaré points the period test (:func:`geardyn.analysis.classify.detect_period`, over the latest half) compares
#: every point of a period-1 or period-2 cycle with its repeat.
RECORD_FLOOR = 4
#: Forcing periods of one classification pass when a forcing period spans several mesh cycles: the fewest with which
#: the section tests of a non-periodic class run (the correlation dimension needs 16 points, the settling ratio 8).
CLASSIFY_SECTION = 16
#: The classification's extension of a record in reference mesh cycles: the pair's SETTLE_ROUNDS passes of
#: SETTLE_PERIODS periods (4 × 1000); a long forcing period takes as many passes as fit (at least one).
CLASSIFY_CYCLES = 4000


def classify_budget(model: Any) -> tuple[int, int]:
    """The classification's passes of a point not found periodic: forcing periods per pass and the most passes.

    A forcing period of one mesh cycle (the pair, P = 1, or a system without a forcing period) keeps
    :data:`~geardyn.analysis.classify.SETTLE_PERIODS` × :data:`~geardyn.analysis.classify.SETTLE_ROUNDS`.  A forcing
    period of P > 1 reference mesh cycles takes passes of max(:data:`CLASSIFY_SECTION`, ceil(SETTLE_PERIODS / P))
    forcing periods, as many as fit in :data:`CLASSIFY_CYCLES` mesh cycles, and at least one.

    Parameters
    ----------
    model : System

    Returns
    -------
    (periods, rounds) : tuple of int

    Examples
    --------
    >>> from geardyn import GearModel
    >>> classify_budget(GearModel())
    (1000, 4)
    >>> classify_budget(GearModel(cycles=64)), classify_budget(GearModel(cycles=1472))
    ((16, 3), (16, 1))
    """
    from .classify import SETTLE_PERIODS, SETTLE_ROUNDS

    p = int(model.period_multiple() or 1)
    if p <= 1:
        return SETTLE_PERIODS, SETTLE_ROUNDS
    n = max(CLASSIFY_SECTION, -(-SETTLE_PERIODS // p))
    return n, max(1, CLASSIFY_CYCLES // (n * p))


@dataclass(frozen=True)
class LongRun:
    """The counts of a run whose forcing period spans several reference mesh cycles (:func:`long_run`).

    Attributes
    ----------
    cycles : int
        P, reference mesh cycles per forcing period.
    steps : int
        RK4 steps per forcing period at the run's ω.
    transient, periods : int
        Forcing periods discarded and recorded.
    transient_why, periods_why : str
        Where each count comes from.
    classify_periods, classify_rounds : int
        The classification's budget (:func:`classify_budget`) for a point not found periodic.
    """

    cycles: int
    steps: int
    transient: int
    periods: int
    transient_why: str
    periods_why: str
    classify_periods: int
    classify_rounds: int

    def note(self, classify: bool = True, per_point: bool = False) -> str:
        """The lines said before the run (stderr).

        Parameters
        ----------
        classify : bool
            Add the classification's budget (``simulate``: :func:`classify_budget`).
        per_point : bool
            The estimate is per point (a sweep).
        """
        P, N = self.cycles, self.steps
        run = (self.transient + self.periods) * N
        extra = self.classify_periods * self.classify_rounds
        text = (
            f"transient: {self.transient} forcing periods ({self.transient * P:,} mesh cycles): {self.transient_why}\n"
            f"record: {self.periods} forcing periods ({self.periods * P:,} mesh cycles): {self.periods_why}\n"
            f"estimate: {run:,} RK4 steps{' per point' if per_point else ''} ({self.transient + self.periods} "
            f"forcing periods of {N:,})"
        )
        if classify:
            text += (
                f"; a response not found periodic is classified over at most {extra} more forcing periods "
                f"({extra * N:,} steps with a tangent vector; {self.classify_rounds} pass(es) of "
                f"{self.classify_periods}), and reported unresolved if that budget ends first"
            )
        return text


def long_run(
    model: Any,
    dtau: float,
    *,
    transient: int | None = None,
    periods: int | None = None,
    default_transient: int | None = None,
    default_periods: int | None = None,
    omegas: Iterable[float] | None = None,
) -> LongRun | None:
    """The default transient and record of a run whose forcing period spans P > 1 reference mesh cycles; None for
    P <= 1 or no forcing period (the fixed defaults stand, bit for bit).

    The fixed defaults count forcing periods (300 + 200 at P = 1: 500 mesh cycles); at P cycles per forcing period they
    would be P times as long.  When not given:

    - the **transient** is the physics' (:func:`settle_periods`, at least 1 forcing period, at most the fixed
      default): the forcing periods in which the least damped linearised mode decays by e^-:data:`DECAY_EFOLDS`.  A
      model with a mode that has no decay time falls back to the fixed count in mesh cycles, ceil(300 / P) forcing
      periods (the pair's 300 periods are 300 mesh cycles);
    - the **record** is the fixed default in mesh cycles, ceil(200 / P) forcing periods, at least
      :data:`RECORD_FLOOR`.

    Parameters
    ----------
    model : System
        The run's model (at its ω).
    dtau : float
        Target RK4 step.
    transient, periods : int, optional
        The counts given by the user (kept as given); None: the defaults above.
    default_transient, default_periods : int, optional
        The command's fixed defaults (:data:`~geardyn.model.DEFAULT_TRANSIENT`,
        :data:`~geardyn.model.DEFAULT_PERIODS` when not given).
    omegas : iterable of float, optional
        Every frequency of a sweep: the transient is that of the highest (:func:`settle_periods`).

    Returns
    -------
    LongRun or None

    Examples
    --------
    >>> from geardyn import GearModel
    >>> long_run(GearModel(omega=0.8), 0.01) is None
    True
    >>> r = long_run(GearModel(omega=0.8, cycles=64), 0.01)  # σ = ξ0 = 0.1: 120 τ, less than one forcing period
    >>> r.transient, r.periods, r.steps  # 4 recorded (the floor); ceil(64·2π/0.8 / 0.01) steps each
    (1, 4, 50266)
    """
    from ..integrate import natural_steps
    from ..model import DEFAULT_PERIODS, DEFAULT_TRANSIENT

    p = int(model.period_multiple() or 1)
    if p <= 1:
        return None
    dt = DEFAULT_TRANSIENT if default_transient is None else int(default_transient)
    dp = DEFAULT_PERIODS if default_periods is None else int(default_periods)
    if transient is not None:
        tr, why_t = int(transient), "as given"
    else:
        try:
            s = settle_periods(model, omegas, floor=1, cap=dt)
            tr = s.periods
            why_t = (
                f"the least damped mode decays as e^(-{s.rate:.4g} τ), by e^-{DECAY_EFOLDS:g} after τ = {s.time:.4g}; "
                f"one forcing period is τ = {s.forcing_period:.4g} (the fixed default, {dt} forcing periods, would be "
                f"{dt * p:,} mesh cycles; --transient N or Ncycles sets it)"
            )
            if s.capped:
                why_t += f"; capped at the fixed default {dt}: the mode has not decayed by e^-{DECAY_EFOLDS:g}"
        except ModelError as e:
            tr = max(1, -(-dt // p))
            cause = e.args[0].split(";")[0].removeprefix("transient: auto needs ")
            why_t = (
                f"no decay time ({cause}): the fixed default's {dt} mesh cycles, rounded up to whole forcing periods"
            )
    if periods is not None:
        pe, why_p = int(periods), "as given"
    else:
        pe = max(RECORD_FLOOR, -(-dp // p))
        why_p = (
            f"the default's {dp} mesh cycles, at least {RECORD_FLOOR} Poincaré points (one per forcing period) for the "
            "period test"
        )
    n_pass, rounds = classify_budget(model)
    return LongRun(p, natural_steps(model, dtau), tr, pe, why_t, why_p, n_pass, rounds)
