"""Stability of a harmonic-balance solution by Hill's method (``docs/hb.md``, "Stability rule").

The variational equation about a period-n solution of n coordinates is y'' + 𝒞(τ) y' + 𝒦(τ) y = 0, periodic with
period T = 2π/ν.  Floquet's ansatz y = e^{λτ} Σ_{k=−H..H} y_k e^{ikντ} turns it into the quadratic eigenvalue
problem (λ² + λ K1 + K0) y = 0, in real coefficients K0 the HB Jacobian and K1 = 2Ω + T(𝒞) (Ω = diag(ikν), T(·)
the Toeplitz matrix of a Fourier series), solved through the companion matrix [[0, I], [−K0, −K1]].  At λ = 0 it
is the HB Jacobian, so a fold of the branch is exactly a zero exponent.  Along a rigid-body mode R the vectors
(R e^{ikφ}, 0), (0, R e^{ikφ}) span an invariant subspace (the copies of the double exponent 0); the pencil is
restricted to the complement of R, so the 2r multipliers 1 of the r rigid modes are left out.

Which eigenvalues are the Floquet exponents: every exponent appears with copies λ + imν whose eigenvectors are
shifted by m harmonics; only the central copies are accurate ("sorting by centrality", Lazarus & Thomas 2010;
Peletan et al. 2013).  The first 2(n − r) − 1 exponents are taken in order of the energy centroid
⟨|k|⟩ = Σ|k||y_k|²/Σ|y_k|² of their eigenvectors, skipping a *copy* of one taken (multiplier within
:data:`COPY_TOL`, shift m = round(Im Δλ/ν) ≠ 0, eigenvector the shifted one with overlap >= :data:`COPY_OVERLAP`: in
the flip case, μ real < 0, an exponent and its copy λ − iν are mirror images with equal centroids).  The last is,
among the :data:`PARTNER_CANDIDATES` next most central eigenvalues, the one whose multiplier is closest to
Liouville's partner exp(−∫ tr 𝒞 dτ)/Π μ of those taken.  Resolution is checked two ways, a failure giving
:attr:`~geardyn.status.Status.UNRESOLVED`: every chosen centroid <= :data:`CENTROID_FRACTION`·H, and Liouville's
formula Π μ = exp(−∫ tr 𝒞 dτ) to :data:`LIOUVILLE_TOL` (relative).

References
----------
.. [1] G. W. Hill, "On the part of the motion of the lunar perigee which is a function of the mean
   motions of the sun and moon", Acta Math. 8 (1886) 1–36.
.. [2] A. Lazarus, O. Thomas, "A harmonic-based method for computing the stability of periodic
   solutions of dynamical systems", C. R. Mécanique 338 (2010) 510–517.
.. [3] L. Peletan, S. Baguet, M. Torkhani, G. Jacquet-Richardet, "A comparison of stability
   computational methods for periodic solution of nonlinear problems with application to
   rotordynamics", Nonlinear Dyn. 72 (2013) 671–682.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ...status import Status
from ._aftkernel import real_operator_kernel
from .aft import HarmonicBasis, toeplitz

__all__ = ["HillResult", "hill_floquet", "system_hill_floquet", "LIOUVILLE_TOL", "CENTROID_FRACTION"]

#: Relative tolerance of Liouville's check |μ₁μ₂ / exp(−∫c dτ) − 1|.
LIOUVILLE_TOL = 1e-4
#: The chosen eigenvectors' energy centroid must be at most this fraction of H.
CENTROID_FRACTION = 0.25
#: The second exponent is sought among this many next most central eigenvalues.
PARTNER_CANDIDATES = 8
#: A candidate is a copy of an accepted exponent only if their multipliers agree to this (relative to max(1, |μ|)).
COPY_TOL = 1e-3
#: ... and its eigenvector overlaps the accepted one's, shifted by m harmonics, by at least this.
COPY_OVERLAP = 0.9


@dataclass(frozen=True)
class HillResult:
    """Floquet exponents and multipliers of a periodic orbit from Hill's method.

    Attributes
    ----------
    exponents : complex ndarray (2,)
        Selected Floquet exponents λ (per unit τ), largest Re first.
    multipliers : complex ndarray (2,)
        μ = exp(λ T_n), largest modulus first.
    centrality : ndarray (2,)
        Energy centroids ⟨|k|⟩ of the chosen eigenvectors.
    liouville_error : float
        |μ₁μ₂ / exp(−∫c dτ) − 1|.
    status : Status
        ``OK`` or ``UNRESOLVED`` (see the module notes); ``DIVERGED`` if the matrix was not finite.
    """

    exponents: np.ndarray
    multipliers: np.ndarray
    centrality: np.ndarray
    liouville_error: float
    status: Status

    @property
    def stable(self) -> bool:
        """All multipliers strictly inside the unit circle."""
        return bool(np.all(np.abs(self.multipliers) < 1.0))

    @property
    def max_modulus(self) -> float:
        return float(np.max(np.abs(self.multipliers)))


#: The result of a system without elastic modes (every coordinate rigid).
NO_MULTIPLIERS = HillResult(np.zeros(0, complex), np.zeros(0, complex), np.zeros(0), 0.0, Status.OK)


def hill_floquet(c_hat: np.ndarray, s_hat: np.ndarray, nu: float, H: int) -> HillResult:
    """Floquet exponents and multipliers of y'' + c(τ)y' + s(τ)y = 0 by Hill's method.

    Parameters
    ----------
    c_hat, s_hat : complex ndarray
        Centred Fourier coefficients (odd length 2L + 1, index m + L holding the coefficient of e^{imντ}) of the
        damping c(τ) and the stiffness s(τ).
    nu : float
        Fundamental frequency (the orbit's period is T_n = 2π/ν).
    H : int
        Harmonics retained in the Floquet eigenvector.

    Returns
    -------
    HillResult
        The two selected exponents (the rule of the module docstring, one elastic coordinate) and their checks.
    """
    H = int(H)
    c_hat, s_hat = np.asarray(c_hat, dtype=complex), np.asarray(s_hat, dtype=complex)
    ik = 1j * nu * np.arange(-H, H + 1)
    Tc = toeplitz(c_hat, H)
    K0 = real_operator_kernel(np.diag(ik * ik) + Tc * ik[None, :] + toeplitz(s_hat, H), H)
    K1 = real_operator_kernel(np.diag(2.0 * ik) + Tc, H)
    return system_hill_floquet(K0, K1, np.eye(1), nu, H, float(c_hat[(len(c_hat) - 1) // 2].real))


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
    M, ne = 2 * H + 1, P.shape[1]
    count = 2 * ne
    if ne == 0:
        return NO_MULTIPLIERS
    if not (np.all(np.isfinite(K0)) and np.all(np.isfinite(K1))):
        nan = np.full(count, complex(math.nan, math.nan))
        return HillResult(nan, nan, np.full(count, math.nan), math.nan, Status.DIVERGED)
    if ne < P.shape[0] or not np.array_equal(P, np.eye(ne)):
        K0, K1 = _restrict(K0, P, M), _restrict(K1, P, M)
    size = ne * M
    A = np.block([[np.zeros((size, size)), np.eye(size)], [-K0, -K1]])
    lam, Vr = np.linalg.eig(A)
    W = _to_complex(H)
    y = np.einsum("km,imc->ikc", W, Vr[:size].reshape(ne, M, -1))  # complex harmonics (DOF, k, vector)
    # the centroid from the real coefficients: |c_k|² + |c_−k|² = (|a_k|² + |b_k|²)/2, so that a conjugate pair
    # (conjugate eigenvectors) has exactly one centroid and keeps LAPACK's order
    w = (np.abs(Vr[:size]) ** 2).reshape(ne, M, -1).sum(axis=0)
    kk = np.concatenate([np.arange(H + 1), np.arange(1, H + 1)]).astype(float)
    half = np.where(np.arange(M) == 0, 1.0, 0.5)
    with np.errstate(invalid="ignore", divide="ignore"):
        cent = ((half * kk) @ w) / (half @ w)
    cent = np.where(np.isfinite(cent), cent, np.inf)
    order = np.argsort(cent, kind="mergesort")
    T = 2.0 * math.pi / nu
    mu_all, ref, chosen, pos = np.exp(lam * T), math.exp(-trace * T), [], 0
    for pos, c in enumerate(order):  # noqa: B007 (pos is read after the loop)
        if len(chosen) == count - 1:
            break
        if not _is_copy(int(c), chosen, lam, mu_all, y, nu):
            chosen.append(int(c))
    # the last exponent: among the next PARTNER_CANDIDATES most central eigenvalues (copies of those accepted left
    # out; if all are copies, the next one that is not), the one closest to Liouville's partner exp(−∫ tr 𝒞 dτ) / Π μ
    # of those accepted
    after = [int(c) for c in order[pos:] if int(c) not in chosen]
    rest = [c for c in after[:PARTNER_CANDIDATES] if not _is_copy(c, chosen, lam, mu_all, y, nu)]
    if not rest:
        rest = [c for c in after if not _is_copy(c, chosen, lam, mu_all, y, nu)][:1] or after[:1]
    prod = complex(np.prod(mu_all[chosen]))  # (at least one taken: the first is never a copy)
    partner = ref / prod if prod != 0 else complex(math.inf)
    rest_a = np.array(rest)
    chosen.append(int(rest_a[int(np.argmin(np.abs(mu_all[rest_a] - partner)))]))
    idx = np.array(chosen)
    idx = idx[np.argsort(-np.abs(mu_all[idx]), kind="stable")]
    ex, mu, cc = lam[idx], mu_all[idx], cent[idx]
    liou = float(abs(np.prod(mu) / ref - 1.0))
    ok = bool(np.all(cc <= CENTROID_FRACTION * H) and liou <= LIOUVILLE_TOL)
    return HillResult(ex, mu, cc, liou, Status.OK if ok else Status.UNRESOLVED)
