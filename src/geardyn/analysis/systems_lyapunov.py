"""The full Lyapunov spectrum of a multi-DOF system (Benettin, all 2n exponents).

The N-DOF kernel propagates 2n tangent vectors with the trajectory and re-orthonormalises them by
Gram–Schmidt every recorded forcing period; the exponents are the time averages of the logs
(the method of :func:`geardyn.analysis.lyapunov.spectrum_from_log`, for 2n columns: the same
alignment transient and block-statistics uncertainties).  Their sum equals the mean trace of the Jacobian,
``−mean trace(M̃⁻¹C̃(t))`` (:func:`expected_sum`), the check of :mod:`tests.test_ndof`.

References
----------
G. Benettin, L. Galgani, A. Giorgilli, J.-M. Strelcyn, "Lyapunov characteristic exponents for smooth
dynamical systems and for Hamiltonian systems; a method for computing all of them", Meccanica 15
(1980) 9–30.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .._docfill import OPTIONS, POINT, fill
from ..integrate_ndof import forcing_period, integrate_batch
from ..model import IntegrationOptions
from .classify import detect_period, period_label
from .lyapunov import ALIGN_FRACTION, DEFAULT_BLOCKS, LYAPUNOV_PERIODS
from .systems_steady import mesh_entries, system_state0

__all__ = ["SystemLyapunovResult", "system_lyapunov", "expected_sum"]


def spectrum_from_log_n(log: np.ndarray, period: float, *, blocks: int = DEFAULT_BLOCKS,
                        align_fraction: float = ALIGN_FRACTION) -> tuple[np.ndarray, np.ndarray]:
    """Exponents (descending) and block-statistics uncertainties from (m, d) Gram–Schmidt logs.

    Parameters
    ----------
    log : ndarray (m, d)
        Logs of the Gram–Schmidt stretch factors, one row per forcing period.
    period : float
        Forcing period T_f (τ).
    blocks : int
        Blocks of the uncertainty estimate (default :data:`~geardyn.analysis.lyapunov.DEFAULT_BLOCKS`).
    align_fraction : float
        Leading fraction of the rows discarded while the tangent vectors align (default
        :data:`~geardyn.analysis.lyapunov.ALIGN_FRACTION`).

    Returns
    -------
    exponents, uncertainty : ndarray (d,)
    """
    a = np.asarray(log, dtype=float)
    m, d = a.shape
    skip = min(max(1, int(np.ceil(align_fraction * m))), max(m - 2, 0))
    kept = a[skip:]
    mk = kept.shape[0]
    if mk == 0 or not np.all(np.isfinite(kept)):
        return np.full(d, np.nan), np.full(d, np.nan)
    lam = kept.mean(axis=0) / period
    B = int(min(max(blocks, 2), mk))
    err = np.full(d, np.nan)
    if B >= 2:
        L = mk // B
        blk = kept[mk - B * L:].reshape(B, L, d).mean(axis=1) / period
        err = blk.std(axis=0, ddof=1) / np.sqrt(B)
    order = np.argsort(-lam, kind="stable")
    return lam[order], err[order]


@fill(POINT)
def expected_sum(model: Any) -> float:
    """The sum the Lyapunov spectrum must have: −mean over a forcing period of trace(M̃⁻¹C̃(θ)).

    C̃ = C̃_b + Σ C_m(θ) V_m V_mᵀ + Σ cc Vc Vcᵀ; the mesh-damping harmonics average to zero, so only
    their mean 2ξ0 enters.  For the paper's 1-DOF pair this is −2ξ0.

    Parameters
    ----------
    {{model}}

    Returns
    -------
    float
        −mean trace of the Jacobian (per unit τ), the value λ1 + … + λ2n converges to.
    """
    Mi = np.asarray(model.Mi)
    tr = float(np.trace(Mi @ model.Cb))
    for i, m in enumerate(model.meshes):
        tr += 2.0 * m.xi0 * float(model.V[i] @ Mi @ model.V[i])  # harmonics average to 0
    for i, c in enumerate(model.cc):
        tr += c * float(model.Vc[i] @ Mi @ model.Vc[i])
    return -tr


@dataclass
@fill(POINT, OPTIONS)
class SystemLyapunovResult:
    """All 2n exponents (per unit τ) of one system point; see :func:`system_lyapunov`.

    Attributes
    ----------
    {{model, options}}
    exponents : ndarray (2n,)
        Exponents in descending order (NaN if the integration diverged).
    uncertainty : ndarray (2n,)
        Block-statistics standard errors of the exponents.
    log : ndarray (periods, 2n)
        Logs of the Gram–Schmidt stretch factors, one row per recorded forcing period.
    status : int
        Kernel status of the point (:class:`~geardyn.status.Status` value).
    blocks : int
        Blocks of the uncertainty estimate.
    summary : dict
        ``motion``, ``period``, ``status`` and ``meshes`` (per-mesh entries) of the ``--json`` output.

    References
    ----------
    G. Benettin, L. Galgani, A. Giorgilli, J.-M. Strelcyn, "Lyapunov characteristic exponents for
    smooth dynamical systems and for Hamiltonian systems; a method for computing all of them",
    Meccanica 15 (1980) 9–30.
    """

    model: Any
    options: IntegrationOptions
    exponents: np.ndarray
    uncertainty: np.ndarray
    log: np.ndarray
    status: int
    blocks: int
    summary: dict[str, Any]

    def to_json(self) -> dict[str, Any]:
        """Keys of ``lyapunov --json`` plus ``meshes`` (every exponent in ``exponents``)."""
        f = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731
        return {
            "omega": self.model.omega,
            "exponents": [f(x) for x in self.exponents],
            "uncertainty": [f(x) for x in self.uncertainty],
            "sum": f(np.sum(self.exponents)),
            "expected_sum": expected_sum(self.model),
            "periods": int(self.log.shape[0]),
            "blocks": self.blocks,
            **self.summary,
        }


@fill(POINT)
def system_lyapunov(model: Any, options: IntegrationOptions = IntegrationOptions(periods=LYAPUNOV_PERIODS),
                    state0: Sequence[float] | None = None, *, blocks: int = DEFAULT_BLOCKS) -> SystemLyapunovResult:
    """The full Lyapunov spectrum of a system point.

    The kernel propagates 2n tangent vectors with the trajectory and re-orthonormalises them by
    Gram–Schmidt every forcing period (Benettin's method); the exponents are the time averages of the
    logs after an alignment transient (:func:`spectrum_from_log_n`).

    Parameters
    ----------
    {{model}}
    options : IntegrationOptions
        ``transient`` periods discarded, then ``periods`` averaged (default ``periods``
        :data:`~geardyn.analysis.lyapunov.LYAPUNOV_PERIODS`).
    state0 : (u0, v0) or (2n,), optional
        Initial state: (u0, v0) of the reference mesh or a full state; default the model's
        default initial state.
    blocks : int
        Blocks of the uncertainty estimate (default :data:`~geardyn.analysis.lyapunov.DEFAULT_BLOCKS`).

    Returns
    -------
    SystemLyapunovResult

    References
    ----------
    G. Benettin, L. Galgani, A. Giorgilli, J.-M. Strelcyn, Meccanica 15 (1980) 9–30.
    """
    s0 = system_state0(model, state0)
    res = integrate_batch([model], s0, options, lyapunov=True)
    lam, err = spectrum_from_log_n(res.lyapunov_log[0], forcing_period(model), blocks=blocks)
    ok = bool(res.ok[0])
    if not ok:
        lam[:] = np.nan
        err[:] = np.nan
    n = detect_period(res.poincare[0]) if ok else -1
    summary = {"motion": period_label(n) if ok else "diverged", "period": n if n > 0 else None,
               "status": "ok" if ok else "diverged", "meshes": mesh_entries(model, res, 0)}
    return SystemLyapunovResult(model, options, lam, err, res.lyapunov_log[0], int(res.status[0]), blocks,
                                summary)
