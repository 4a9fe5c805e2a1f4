"""Lyapunov spectrum of the stroboscopic flow by the Benettin method.

The kernel propagates a 2×2 tangent matrix with the trajectory (the variational equations with
the piecewise-constant Jacobian ``[[0, 1], [-K(θ) f'(u), -C(θ)]]``, DESIGN §2) and
re-orthonormalises it by Gram–Schmidt (QR) at the end of every recorded forcing period, writing
``log r11`` and ``log r22`` of that period (``BatchResult.lyapunov_log``).  The exponents are the
time averages of these logs per unit non-dimensional time τ:

    λ_i = Σ_j log r_ii(j) / (m T),   T = 2π/ω,

over the m periods kept after a short alignment transient.  Their uncertainty is the standard
error from block statistics: the kept periods are cut into ``blocks`` consecutive blocks, each
block gives its own estimate, and the uncertainty is the standard deviation of the block
estimates divided by √blocks.  Correlations shorter than a block are thereby accounted for.

Checks (``tests/test_lyapunov.py``): λ1 + λ2 = −2ξ0 (Liouville: the mean trace of the Jacobian),
λ1 = ln|μ_max|/(nT) for a stable period-n orbit with Floquet multipliers μ, and the damped Mathieu
instability tongue near ω = 2.

All exponents are non-dimensional rates per unit τ = ω_n t; multiply by ω_n for 1/s.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._lazy import lazy_module
from ..integrate import ST_OK, BatchResult, integrate_batch, start_state
from ..io import annotate, json_number, result_attrs
from ..model import GearModel, IntegrationOptions, ModelError

xr = lazy_module("xarray")

__all__ = [
    "DEFAULT_BLOCKS",
    "ALIGN_FRACTION",
    "LYAPUNOV_PERIODS",
    "LyapunovResult",
    "spectrum_from_log",
    "lyapunov_spectrum",
    "lyapunov_batch",
]

#: Number of blocks for the block-statistics uncertainty (the standard error uses blocks − 1
#: degrees of freedom; 20 blocks make the error estimate itself good to about ±16 %).
DEFAULT_BLOCKS = 20
#: Fraction of the recorded periods discarded at the start while the tangent basis aligns with
#: the dominant directions (at least one period is always discarded).
ALIGN_FRACTION = 0.05
#: Default number of recorded periods for a stand-alone Lyapunov computation (``geardyn lyapunov``).
LYAPUNOV_PERIODS = 2000


def spectrum_from_log(
    log: np.ndarray,
    period: float | np.ndarray,
    *,
    blocks: int = DEFAULT_BLOCKS,
    align_fraction: float = ALIGN_FRACTION,
) -> tuple[np.ndarray, np.ndarray]:
    """Exponents and their block-statistics uncertainty from per-period Gram–Schmidt logs.

    Parameters
    ----------
    log : ndarray (m, 2) or (P, m, 2)
        ``log r11``, ``log r22`` of each recorded period (``BatchResult.lyapunov_log``).
    period : float or ndarray (P,)
        Forcing period T = 2π/ω in τ (non-dimensional).
    blocks : int
        Number of blocks for the uncertainty (>= 2); reduced when fewer periods are available.
    align_fraction : float
        Fraction of the periods discarded at the start (tangent-basis alignment).

    Returns
    -------
    exponents, uncertainty : ndarray (2,) or (P, 2)
        λ1 >= λ2 per unit τ and their one-standard-error uncertainties (NaN where the logs are not
        finite or fewer than two blocks are available).
    """
    a = np.asarray(log, dtype=float)
    single = a.ndim == 2
    if single:
        a = a[None]
    if a.ndim != 3:
        raise ModelError(f"lyapunov log: expected shape (m, d) or (P, m, d), got {np.shape(log)}")
    P, m, d = a.shape
    T = np.broadcast_to(np.asarray(period, dtype=float), (P,))
    skip = min(max(1, int(np.ceil(align_fraction * m))), max(m - 2, 0))
    kept = a[:, skip:, :]
    mk = kept.shape[1]
    if mk == 0:
        nan = np.full((P, d), np.nan)
        return (nan[0], nan[0]) if single else (nan, nan.copy())
    lam = kept.mean(axis=1) / T[:, None]
    B = int(min(max(blocks, 2), mk))
    if B >= 2:
        L = mk // B
        blk = kept[:, mk - B * L :, :].reshape(P, B, L, d).mean(axis=2) / T[:, None, None]
        err = blk.std(axis=1, ddof=1) / np.sqrt(B)
    else:
        err = np.full((P, d), np.nan)
    # Gram–Schmidt orders the exponents on average; sort them so that λ1 >= λ2 >= … exactly
    # (a stable sort: equal exponents keep their order).
    order = np.argsort(-lam, axis=1, kind="stable")
    lam = np.take_along_axis(lam, order, axis=1)
    err = np.take_along_axis(err, order, axis=1)
    bad = ~np.all(np.isfinite(kept), axis=(1, 2))
    lam[bad] = err[bad] = np.nan
    if single:
        return lam[0], err[0]
    return lam, err


def lyapunov_batch(
    models: Sequence[GearModel],
    state0: Sequence[float] | np.ndarray | None = None,
    options: IntegrationOptions = IntegrationOptions(periods=LYAPUNOV_PERIODS),
    *,
    blocks: int = DEFAULT_BLOCKS,
) -> dict[str, np.ndarray]:
    """Lyapunov spectra of many parameter points in one kernel batch (Benettin's method).

    Parameters
    ----------
    models : sequence of GearModel
        The points.
    state0 : ndarray (d,) or (P, d), optional
        Initial state(s) at θ = 0 (default the origin).
    options : IntegrationOptions
        Transient and recorded periods (default :data:`LYAPUNOV_PERIODS` recorded).
    blocks : int
        Blocks of the uncertainty; default :data:`DEFAULT_BLOCKS`.

    Returns
    -------
    dict
        ``exponents`` (P, d), ``uncertainty`` (P, d), ``status`` (P,) and the
        :class:`~geardyn.integrate.BatchResult` under ``result`` (NaN exponents where diverged).

    Raises
    ------
    ModelError
        As :func:`geardyn.integrate.integrate_batch`.

    References
    ----------
    G. Benettin, L. Galgani, A. Giorgilli and J.-M. Strelcyn, "Lyapunov characteristic exponents
    for smooth dynamical systems and for Hamiltonian systems; a method for computing all of them",
    *Meccanica* 15 (1980) 9–20 and 21–30.
    """
    return _spectra(integrate_batch(models, state0, options, lyapunov=True), blocks)


def _spectra(res: BatchResult, blocks: int) -> dict[str, Any]:
    """The dict of :func:`lyapunov_batch` from a Lyapunov-mode batch result."""
    T = res.models.sampling_periods()
    lam, err = spectrum_from_log(res.lyapunov_log, T, blocks=blocks)
    bad = res.status != ST_OK
    lam[bad] = err[bad] = np.nan
    return {"exponents": lam, "uncertainty": err, "status": res.status.copy(), "result": res}


@dataclass
class LyapunovResult:
    """Lyapunov spectrum of one point (non-dimensional rates per unit τ); see :func:`lyapunov_spectrum`.

    Parameters
    ----------
    model : GearModel
        The point.
    options : IntegrationOptions
        The integration options used.
    state0 : tuple of float
        The initial state.
    exponents, uncertainty : ndarray (d,)
        λ1 >= λ2 >= … per unit τ and their standard errors.
    log : ndarray (m, d)
        The per-period Gram–Schmidt logs.
    status : int
        :class:`~geardyn.status.Status` code of the run.
    blocks : int
        Blocks of the uncertainty.
    motion : dict
        ``motion`` and ``period`` labels when classified (else empty).
    extra : dict
        What the system adds to the summary (``System.report``: per-mesh entries; empty for the pair).
    """

    model: Any
    options: IntegrationOptions
    state0: tuple[float, ...]
    exponents: np.ndarray
    uncertainty: np.ndarray
    log: np.ndarray
    status: int
    blocks: int
    motion: dict[str, Any] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == ST_OK

    @property
    def expected_sum(self) -> float:
        """The sum the exponents must have: the mean trace of the Jacobian (−2ξ0 for the pair)."""
        return self.model.mean_trace()

    def to_json(self) -> dict[str, Any]:
        """The ``lyapunov --json`` summary (DESIGN §5 keys ``exponents`` and ``uncertainty``)."""

        return {
            "omega": self.model.omega,
            "exponents": [json_number(x) for x in self.exponents],
            "uncertainty": [json_number(x) for x in self.uncertainty],
            "sum": json_number(self.exponents.sum()),
            "expected_sum": self.expected_sum,
            "periods": int(self.log.shape[0]),
            "blocks": self.blocks,
            "motion": self.motion.get("motion"),
            "period": self.motion.get("period"),
            "status": "ok" if self.ok else "diverged",
            **self.extra,
        }

    def to_dataset(self) -> xr.Dataset:
        """Per-period logs and running estimates, with the final exponents as attributes."""
        m = self.log.shape[0]
        # the running (cumulative) estimates after each period, per unit τ
        run = np.cumsum(self.log, axis=0) / (np.arange(1, m + 1)[:, None] * self.model.sampling_period)
        ds = xr.Dataset(
            {
                "log_r": (("section", "exponent"), self.log),
                "running": (("section", "exponent"), run),
                "exponents": ("exponent", self.exponents),
                "uncertainty": ("exponent", self.uncertainty),
            },
            coords={"section": np.arange(m), "exponent": np.arange(1, len(self.exponents) + 1)},
            attrs=result_attrs("lyapunov", self.model, self.options, state0=list(self.state0), summary=self.to_json()),
        )
        return annotate(ds)


def lyapunov_spectrum(
    model: Any,
    options: IntegrationOptions = IntegrationOptions(periods=LYAPUNOV_PERIODS),
    state0: Sequence[float] | None = None,
    *,
    blocks: int = DEFAULT_BLOCKS,
    classify: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> LyapunovResult:
    """The Lyapunov spectrum (all d exponents) of one point of any System, with its uncertainty.

    Parameters
    ----------
    model : System
        Non-dimensional model.
    options : IntegrationOptions
        ``transient`` periods are discarded (the trajectory settles on its attractor), then the
        tangent matrix is propagated over ``periods`` periods (more periods, smaller uncertainty:
        it falls roughly as 1/√periods on a chaotic attractor).
    state0 : (u0, v0) of the reference element, or a full state, optional
        Initial state at θ = 0 (:func:`geardyn.integrate.start_state`; default ``model.initial_state()``).
    blocks : int
        Blocks of the block-statistics uncertainty.
    classify : bool
        Also classify the motion from the same run (period, exponent, and for non-periodic points
        the closed-curve tests of :func:`~geardyn.analysis.classify.classify_motion`; no settling
        passes: give a long enough transient).
    progress : callable, optional
        Called as ``progress(done, total)`` in forcing periods, ``total`` = transient + recorded
        periods, as by :func:`~geardyn.integrate.integrate_batch` (the transient in pieces where the kernel
        continues a run exactly, the recorded periods in one run followed as it goes).  The results are those
        of a call without it, bit for bit.

    Returns
    -------
    LyapunovResult
        Exponents, uncertainties, the per-period logs and, with ``classify``, the motion; a bad
        model, state or option raises :class:`ModelError` (:func:`geardyn.integrate.integrate_batch`).

    References
    ----------
    Benettin et al. (1980), as for :func:`lyapunov_batch`: tangent vectors re-orthonormalised by
    Gram–Schmidt once per forcing period.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, lyapunov_spectrum
    >>> ly = lyapunov_spectrum(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=100))
    >>> ly.motion["motion"], ly.expected_sum  # the exponents sum to the mean trace, -2 ξ0
    ('period-2', -0.2)
    >>> abs(float(ly.exponents.sum()) - ly.expected_sum) < 1e-9
    True
    """
    from ..validate import exponents_computable

    exponents_computable(model, [model.omega])  # below double precision within a period: refused
    state0 = start_state(model, state0)
    out = _spectra(integrate_batch([model], state0, options, lyapunov=True, progress=progress), blocks)
    res = out["result"]
    motion: dict[str, Any] = {}
    if classify:
        from ..system import ModelList
        from .classify import classify_points, detect_period, motion_label, quasi_periodic_allowed
        from .settle import decay_rates

        ok = res.status[0] == ST_OK
        n = detect_period(res.poincare[0]) if ok else -1
        lam, err = out["exponents"][:1, 0], out["uncertainty"][:1, 0]
        decay = decay_rates(ModelList([model]), [0] if n == 0 else [])
        code = classify_points(
            np.array([n]), lam, err, np.array([ok]), res.poincare, quasi_periodic_allowed(model), decay
        )
        motion = {"motion": motion_label(int(code["motion"][0]), n), "period": n if n > 0 else None}
    return LyapunovResult(
        model,
        options,
        tuple(float(x) for x in state0),
        out["exponents"][0],
        out["uncertainty"][0],
        res.lyapunov_log[0],
        int(res.status[0]),
        blocks,
        motion,
        model.report(res, 0),
    )
