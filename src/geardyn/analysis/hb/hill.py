"""Stability of a harmonic-balance solution by Hill's method.

The variational equation of u'' + C(θ) u' + K(θ) f(u; D) = F(θ) about a period-n solution is the
Hill equation y'' + c(τ) y' + s(τ) y = 0 with c = C(θ) and s = K(θ) f'(u(τ)), both periodic with
period T_n = 2π/ν, ν = ω/n.  Floquet's ansatz y = e^{λτ} Σ_{k=−H..H} y_k e^{ikντ} turns it into the
quadratic eigenvalue problem

    [λ² I + λ (2Ω + T_c) + (Ω² + T_c Ω + T_s)] y = 0,        Ω = diag(ikν),

with T_c, T_s the Toeplitz (multiplication) matrices of the Fourier coefficients of c and s; it is
solved as the linear eigenvalue problem of the 2(2H + 1) companion ("Hill") matrix.  At λ = 0 the
matrix polynomial is the complex form of the harmonic-balance Jacobian, so a fold of the branch is
exactly a zero exponent.

Which eigenvalues are the Floquet exponents
-------------------------------------------
The exact problem has every exponent λ repeated as λ + imν (m ∈ ℤ), each copy with its eigenvector
shifted by m harmonics; truncation keeps 2(2H + 1) eigenvalues of which only the copies whose
eigenvectors sit in the middle of the retained band are accurate.  The rule used here ("sorting by
centrality", cf. Lazarus & Thomas 2010; Peletan et al. 2013): for each eigenvector take the
y-part and its energy centroid ⟨|k|⟩ = Σ|k||y_k|² / Σ|y_k|².  The first exponent λ₁ is the most
central eigenvalue.  The second is not simply the next most central one: in the flip case
(μ real < 0, Im λ = ν/2) λ₁ and its copy λ₁ − iν are mirror images, equally central, and the next
most central eigenvalue may be that copy.  So λ₂ is, among the :data:`PARTNER_CANDIDATES` next
most central eigenvalues, the one whose multiplier exp(λT_n) is closest to Liouville's partner
exp(−∫c dτ)/μ₁ (for a complex pair this is the conjugate, for a real pair the other real
multiplier).  The multipliers μ = exp(λ T_n) do not depend on which copy is chosen.

Resolution is checked two ways and a failure gives :attr:`~geardyn.status.Status.UNRESOLVED`:
the centroids of the chosen eigenvectors must lie in the inner quarter of the band (≤ H/4), and
Liouville's formula μ₁μ₂ = exp(−∫c dτ) must hold to :data:`LIOUVILLE_TOL` (relative).

Systems (:func:`system_hill_floquet`)
-------------------------------------
For n coordinates the variational equation y'' + 𝒞(τ) y' + 𝒦(τ) y = 0 gives the pencil λ² + λ K1 + K0 in real
coefficients (K0 the HB Jacobian, K1 = 2Ω + T(𝒞)), solved through its companion matrix.  Along a rigid-body mode R
the vectors (R e^{ikφ}, 0), (0, R e^{ikφ}) span an invariant subspace whose eigenvalues are the copies of the double
exponent 0; the pencil is restricted to the complement of R (K → (Pᵀ⊗I) K (P⊗I)), so the 2r multipliers 1 of the r
rigid modes are left out, as in shooting.  The first 2(n − r) − 1 exponents are taken in order of centrality,
skipping a *copy* of one taken (multiplier within :data:`COPY_TOL`, shift m = round(Im Δλ/ν) ≠ 0, eigenvector the
shifted one with overlap >= :data:`COPY_OVERLAP`); the last is the candidate closest to Liouville's partner
exp(−∫ tr 𝒞 dτ)/Π μ.  For one elastic coordinate this is the rule above.

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
from scipy.linalg.lapack import dgeev

from ...status import Status
from ._hillkernel import hill_real_matrix, hill_select
from .aft import HarmonicBasis, toeplitz

__all__ = ["HillResult", "hill_matrix", "hill_floquet", "system_hill_floquet", "LIOUVILLE_TOL", "CENTROID_FRACTION"]

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


def hill_matrix(c_hat: np.ndarray, s_hat: np.ndarray, nu: float, H: int) -> np.ndarray:
    """The companion (Hill) matrix of y'' + c(τ)y' + s(τ)y = 0 truncated to harmonics |k| <= H.

    Parameters
    ----------
    c_hat, s_hat : complex ndarray
        Centred Fourier coefficients (odd length 2L + 1, index m + L holds the coefficient of
        e^{imντ}) of the damping c(τ) and the stiffness s(τ).
    nu : float
        Fundamental frequency ν of the periodic coefficients (period 2π/ν).
    H : int
        Harmonics retained.

    Returns
    -------
    complex ndarray (2(2H + 1), 2(2H + 1))
        A with eigenvalues λ (approximate Floquet exponents and their copies) and eigenvectors (y, λy).
    """
    M = 2 * H + 1
    Om = np.diag(1j * nu * np.arange(-H, H + 1))
    Tc = toeplitz(np.asarray(c_hat, dtype=complex), H)
    Ts = toeplitz(np.asarray(s_hat, dtype=complex), H)
    K0 = Om @ Om + Tc @ Om + Ts
    K1 = 2.0 * Om + Tc
    A = np.zeros((2 * M, 2 * M), dtype=complex)
    A[:M, M:] = np.eye(M)
    A[M:, :M] = -K0
    A[M:, M:] = -K1
    return A


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


def _nan_result(status: Status) -> HillResult:
    nan = np.full(2, complex(math.nan, math.nan))
    return HillResult(nan, nan, np.full(2, math.nan), math.nan, status)


def hill_floquet(c_hat: np.ndarray, s_hat: np.ndarray, nu: float, H: int) -> HillResult:
    """Floquet exponents and multipliers of y'' + c(τ)y' + s(τ)y = 0 by Hill's method.

    Parameters
    ----------
    c_hat, s_hat : complex ndarray
        Centred Fourier coefficients of c and s in e^{imντ} (see :func:`hill_matrix`).
    nu : float
        Fundamental frequency (the orbit's period is T_n = 2π/ν).
    H : int
        Harmonics retained in the Floquet eigenvector.

    Returns
    -------
    HillResult
        The two selected exponents (sorting by centrality, one per multiplier) and their checks.

    References
    ----------
    .. [1] A. Lazarus, O. Thomas, C. R. Mécanique 338 (2010) 510–517.
    .. [2] A. H. Nayfeh and D. T. Mook, *Nonlinear Oscillations*, Wiley, 1979 (Floquet theory and
       Hill's determinant).
    """
    c_hat = np.ascontiguousarray(c_hat, dtype=complex)
    s_hat = np.ascontiguousarray(s_hat, dtype=complex)
    # c and s are real, so A maps the coefficients of real signals to those of real signals: in the
    # real coefficients [a_0, a_k, b_k] it is a real matrix with the same eigenvalues (real LAPACK,
    # about three times cheaper than complex); the energy centroids of the eigenvectors are the same
    # in either coefficients.
    Ar, finite = hill_real_matrix(c_hat, s_hat, float(nu), int(H))
    if not finite:
        return _nan_result(Status.DIVERGED)
    wr, wi, _vl, vr, info = dgeev(Ar, compute_vl=0, overwrite_a=1)
    if info != 0:
        return _nan_result(Status.UNRESOLVED)
    Tn = 2.0 * math.pi / nu
    L = (len(c_hat) - 1) // 2
    ref = math.exp(-float(np.real(c_hat[L])) * Tn)  # Liouville: μ₁μ₂ = exp(−∫c dτ)
    ex, mu, cc, liou = hill_select(wr, wi, vr, Tn, ref, int(H), PARTNER_CANDIDATES)
    ok = cc[0] <= CENTROID_FRACTION * H and cc[1] <= CENTROID_FRACTION * H and liou <= LIOUVILLE_TOL
    return HillResult(ex, mu, cc, float(liou), Status.OK if ok else Status.UNRESOLVED)


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


def _nan_results(count: int, status: Status) -> HillResult:
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
        return _nan_results(count, Status.DIVERGED)
    if ne < P.shape[0] or not np.array_equal(P, np.eye(ne)):
        K0, K1 = _restrict(K0, P, M), _restrict(K1, P, M)
    size = ne * M
    A = np.zeros((2 * size, 2 * size))
    A[:size, size:] = np.eye(size)
    A[size:, :size] = -K0
    A[size:, size:] = -K1
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
    for pos, c in enumerate(order):  # noqa: B007 (pos is read after the loop)
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
