"""Hill stability of a harmonic-balance solution of a multi-DOF system (2n-dimensional first-order system).

The variational equation about a periodic solution is y'' + 𝒞(τ) y' + 𝒦(τ) y = 0 (n DOFs) with
𝒞 = B + Σ_e W[e] V[e]ᵀ C_e(θ) and 𝒦 = A + Σ_e W[e] V[e]ᵀ K_e(θ) χ_e(φ).  Floquet's ansatz
y = e^{λτ} Σ_k y_k e^{ikντ} gives the quadratic eigenvalue problem (λ² + λ K1 + K0) y = 0 with
K0 the harmonic-balance Jacobian and K1 = 2Ω + T(𝒞), both real in real coefficients
(:meth:`~geardyn.analysis.hb.system.HBSystemEquations.hill_operators`); it is solved through the
companion matrix [[0, I], [−K0, −K1]], as for one DOF (:mod:`.hill`).

Rigid-body modes
----------------
Along a rigid-body mode R (V[e]·R = 0, C̃_b R = K̃_b R = 0) the pencil reduces to (λ + ikν)² for every
harmonic k: the vectors (R e^{ikφ}, 0) and (0, R e^{ikφ}) span an invariant subspace of the companion
matrix whose eigenvalues are the copies of the double exponent 0 (multiplier 1, position and
velocity of the rigid motion).  The matrix is restricted to the quotient by that subspace — with P an
orthonormal basis of the complement of R, K0 → (Pᵀ⊗I) K0 (P⊗I) and likewise K1 — whose 2(n − r)(2H + 1)
eigenvalues are those of the elastic motion only.  The r rigid modes' 2r multipliers (exactly 1) are
therefore excluded from the output and from the stability test, as in shooting
(:func:`~geardyn.analysis.periodic.orbit.elastic_multipliers`).

Which eigenvalues are the Floquet exponents (the rule of :mod:`.hill`, generalised)
--------------------------------------------------------------------------------
Every exponent appears with copies λ + imν whose eigenvectors are shifted by m harmonics; the accurate
copies are the most central.  For each eigenvector the energy centroid ⟨|k|⟩ = Σ|k||y_k|²/Σ|y_k|²
(summed over the DOFs) is taken.  The first 2(n − r) − 1 exponents are accepted in order of increasing
centroid, skipping a *copy* of an exponent already accepted: an eigenvalue whose multiplier exp(λT)
is within :data:`COPY_TOL` of that exponent's, at a shift m = round(Im Δλ/ν) ≠ 0, and whose eigenvector
is that exponent's shifted by m harmonics (normalised overlap >= :data:`COPY_OVERLAP`) — in the flip
case (μ real < 0) an exponent and its copy λ − iν are mirror images with equal centroids.  The last
exponent is chosen as :mod:`.hill` chooses its second: among the PARTNER_CANDIDATES next most central
eigenvalues, the one whose multiplier is closest to Liouville's partner exp(−∫ tr 𝒞 dτ)/Π μ of those
accepted; copies of the accepted ones are left out of that window, and when it holds nothing else (a
system has many copies as central as a flip exponent) the next eigenvalue that is not a copy is taken.
For one elastic DOF this is the rule of :mod:`.hill` (it differs only where that would take a copy of
λ₁, i.e. μ₂ = μ₁ to within Hill's truncation error).
Resolution is checked as in :mod:`.hill`: every chosen centroid <= CENTROID_FRACTION·H and Liouville's
formula Π μ = exp(−∫ tr 𝒞 dτ) to LIOUVILLE_TOL; otherwise ``Status.UNRESOLVED``.

References
----------
A. Lazarus, O. Thomas, "A harmonic-based method for computing the stability of periodic solutions of
dynamical systems", C. R. Mécanique 338 (2010) 510–517; L. Peletan et al., Nonlinear Dyn. 72 (2013)
671–682 (sorting by centrality); G. W. Hill, Acta Math. 8 (1886) 1–36.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ...status import Status
from ._blas import single_thread_blas
from .aft import HarmonicBasis
from .hill import CENTROID_FRACTION, LIOUVILLE_TOL, PARTNER_CANDIDATES, HillResult

__all__ = ["system_hill_floquet", "COPY_TOL", "COPY_OVERLAP"]

#: A candidate is a copy of an accepted exponent only if their multipliers agree to this (relative to max(1, |μ|)).
COPY_TOL = 1e-3
#: ... and its eigenvector overlaps the accepted one's, shifted by m harmonics, by at least this.
COPY_OVERLAP = 0.9


@functools.lru_cache(maxsize=16)
def _to_complex(H: int) -> np.ndarray:
    """W with c = W a: real coefficients [a_0, a_k, b_k] to the complex c_k, k = −H … H."""
    return HarmonicBasis(H, 2 * H + 2).W


def _restrict(K: np.ndarray, P: np.ndarray, M: int) -> np.ndarray:
    """(Pᵀ⊗I_M) K (P⊗I_M) for K with n×n blocks of size M."""
    n, ne = P.shape
    K4 = K.reshape(n, M, n, M)
    return np.einsum("ia,iujv,jb->aubv", P, K4, P, optimize=True).reshape(ne * M, ne * M)


def _overlap(ya: np.ndarray, yc: np.ndarray, m: int) -> float:
    """|⟨shift_m(y_a), y_c⟩| / (‖y_a‖ ‖y_c‖), shift_m(y)[k] = y[k + m] (blocks (DOF, harmonic))."""
    M = ya.shape[1]
    sh = np.zeros_like(ya)
    if m >= 0:
        sh[:, : M - m] = ya[:, m:]
    else:
        sh[:, -m:] = ya[:, : M + m]
    den = np.linalg.norm(ya) * np.linalg.norm(yc)
    return float(abs(np.vdot(sh, yc)) / den) if den > 0 else 0.0


def _is_copy(c: int, chosen: list[int], lam: np.ndarray, mu: np.ndarray, y: np.ndarray, nu: float) -> bool:
    """Whether eigenvalue c is a copy λ_a + imν (m ≠ 0) of an accepted exponent a (see the module docstring)."""
    for a in chosen:
        m = int(round(float((lam[c] - lam[a]).imag) / nu))
        if (
            m != 0
            and abs(mu[c] - mu[a]) <= COPY_TOL * max(1.0, abs(mu[a]))
            and _overlap(y[:, :, a], y[:, :, c], m) >= COPY_OVERLAP
        ):
            return True
    return False


def _nan_result(count: int, status: Status) -> HillResult:
    nan = np.full(count, complex(math.nan, math.nan))
    return HillResult(nan, nan, np.full(count, math.nan), math.nan, status)


def system_hill_floquet(K0: np.ndarray, K1: np.ndarray, P: np.ndarray, nu: float, H: int, trace: float) -> HillResult:
    """Elastic Floquet exponents and multipliers of y'' + 𝒞(τ)y' + 𝒦(τ)y = 0 by Hill's method.

    Parameters
    ----------
    K0, K1 : ndarray (n(2H + 1), n(2H + 1))
        The pencil's real matrices (DOF-major blocks of real coefficients).
    P : ndarray (n, n − r)
        Orthonormal basis of the complement of the rigid-body modes (the identity when there are none).
    nu : float
        Fundamental frequency (period T = 2π/ν).
    H : int
        Harmonics retained.
    trace : float
        Mean over the period of tr 𝒞(τ) (Liouville's check).

    Returns
    -------
    HillResult
        2(n − r) exponents and multipliers (largest modulus first), their centroids, Liouville's error and
        the status.
    """
    M = 2 * H + 1
    ne = P.shape[1]
    count = 2 * ne
    if ne == 0:
        e = np.zeros(0, dtype=complex)
        return HillResult(e, e, np.zeros(0), 0.0, Status.OK)
    if not (np.all(np.isfinite(K0)) and np.all(np.isfinite(K1))):
        return _nan_result(count, Status.DIVERGED)
    if ne < P.shape[0] or not np.array_equal(P, np.eye(ne)):
        K0, K1 = _restrict(K0, P, M), _restrict(K1, P, M)
    size = ne * M
    A = np.zeros((2 * size, 2 * size))
    A[:size, size:] = np.eye(size)
    A[size:, :size] = -K0
    A[size:, size:] = -K1
    with single_thread_blas():
        lam, Vr = np.linalg.eig(A)
    W = _to_complex(H)
    y = np.einsum("km,imc->ikc", W, Vr[:size].reshape(ne, M, -1))  # complex harmonics (DOF, k, vector)
    # the centroid from the real coefficients, as hill.py does: |c_k|² + |c_−k|² = (|a_k|² + |b_k|²)/2, so that a
    # conjugate pair (conjugate eigenvectors) has exactly one centroid and keeps LAPACK's order
    w = (np.abs(Vr[:size]) ** 2).reshape(ne, M, -1).sum(axis=0)
    kk = np.concatenate([np.arange(H + 1), np.arange(1, H + 1)]).astype(float)
    half = np.full(M, 0.5)
    half[0] = 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        cent = ((half * kk) @ w) / (half @ w)
    cent = np.where(np.isfinite(cent), cent, np.inf)
    order = np.argsort(cent, kind="mergesort")
    T = 2.0 * math.pi / nu
    mu_all = np.exp(lam * T)
    ref = math.exp(-trace * T)
    chosen: list[int] = []
    pos = 0
    for pos, c in enumerate(order):
        if len(chosen) == count - 1:
            break
        if not _is_copy(int(c), chosen, lam, mu_all, y, nu):
            chosen.append(int(c))
    # the last exponent as hill.py's second: among the next PARTNER_CANDIDATES most central eigenvalues (copies
    # of those accepted left out; if all are copies, the next one that is not), the one closest to Liouville's
    # partner exp(−∫ tr 𝒞 dτ) / Π μ of those accepted — for one DOF the rule of hill.py
    after = [int(c) for c in order[pos:] if int(c) not in chosen]
    rest = [c for c in after[:PARTNER_CANDIDATES] if not _is_copy(c, chosen, lam, mu_all, y, nu)]
    if not rest:
        rest = [c for c in after if not _is_copy(c, chosen, lam, mu_all, y, nu)][:1] or after[:1]
    prod = complex(np.prod(mu_all[chosen])) if chosen else 1.0
    partner = ref / prod if prod != 0 else complex(math.inf)
    rest_a = np.array(rest)
    chosen.append(int(rest_a[int(np.argmin(np.abs(mu_all[rest_a] - partner)))]))
    idx = np.array(chosen)
    ex, mu, cc = lam[idx], mu_all[idx], cent[idx]
    srt = np.argsort(-np.abs(mu), kind="stable")
    ex, mu, cc = ex[srt], mu[srt], cc[srt]
    liou = float(abs(np.prod(mu) / ref - 1.0))
    ok = bool(np.all(cc <= CENTROID_FRACTION * H) and liou <= LIOUVILLE_TOL)
    return HillResult(ex, mu, cc, liou, Status.OK if ok else Status.UNRESOLVED)
