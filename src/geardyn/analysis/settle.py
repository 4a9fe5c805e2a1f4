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
    "CYCLES_SUFFIX",
    "DECAY_EFOLDS",
    "FLOOR_PERIODS",
    "Settling",
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
        for i, m in enumerate(model.meshes):
            vv = np.outer(model.V[i], model.V[i])
            K += m.k * vv
            C += 2.0 * m.xi0 * vv
        for i, (k, c) in enumerate(zip(model.kc, model.cc)):
            vv = np.outer(model.Vc[i], model.Vc[i])
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
