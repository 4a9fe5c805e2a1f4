"""Fourier coefficients, time samples and the dead zone's exact projection for harmonic balance (``docs/hb.md``).

A coordinate's response over the response period is a truncated Fourier series in the slow angle φ::

    u(φ) = a_0 + Σ_{k=1..H} a_k cos(kφ) + b_k sin(kφ)     (real coefficients ``[a_0, a_1 … a_H, b_1 … b_H]``)

with the complex coefficients c_0 = a_0, c_{±k} = (a_k ∓ i b_k)/2 used internally (:class:`HarmonicBasis`).

The dead zone f(u; D) is where a time grid is needed (:func:`dead_zone_terms`): u is sampled at N equispaced angles
(:func:`time_samples`), a change of contact state between two samples brackets a switch, located to machine
precision by a safeguarded Newton iteration on u(φ) = ±D; on each contact interval K(θ)(u ∓ D) is a trigonometric
polynomial whose Fourier coefficients over the interval are integrated in closed form.  The Galerkin projection is
therefore exact for the truncated u (no aliasing, no quadrature error at the kink), the residual is C¹ and its
Jacobian is the multiplication operator of K(θ)·χ(φ), χ the indicator of contact — the operator of Hill's matrix.
N: the smallest power of two with N >= 8(2H + 1) and N >= 64; a switch pair closer than 2π/N is missed only at a
graze of depth O(N⁻²), which contributes O(N⁻³) (``docs/hb.md``).

References
----------
T. M. Cameron and J. H. Griffin, "An alternating frequency/time domain method for calculating the
steady-state response of nonlinear dynamic systems", J. Appl. Mech. 56 (1989) 149–154.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ._aftkernel import dead_zone_kernel, extrema_kernel, to_complex, to_real

__all__ = ["HarmonicBasis", "DeadZoneTerms", "time_samples", "dead_zone_terms", "sampled_terms", "signal_extrema"]

#: Samples per retained Fourier coefficient (N >= OVERSAMPLE·(2H + 1)) and the smallest N.
OVERSAMPLE = 8
MIN_SAMPLES = 64
#: Newton iterations (safeguarded by the bracket) when locating a switch u(φ) = ±D or an extremum.
ROOT_MAX_ITER = 60
ROOT_TOL = 1e-13


def time_samples(H: int, span: int = 0) -> int:
    """Number N of equispaced samples per response period bracketing the contact switches.

    Parameters
    ----------
    H, span : int
        Harmonics retained and a bound of the harmonics (in φ) of the series that multiply the response
        (:attr:`~geardyn.analysis.hb.form.HBForm.span`).

    Returns
    -------
    int
        The smallest power of two with N >= 8(2H + 1), N > 2(H + span) and N >= 64.
    """
    need = max(OVERSAMPLE * (2 * H + 1), 2 * (H + span) + 1, MIN_SAMPLES)
    return 1 << int(math.ceil(math.log2(need)))


@dataclass
class HarmonicBasis:
    """Real ↔ complex coefficient maps, samples and operators for H harmonics of period 2π in φ.

    Parameters
    ----------
    H : int
        Harmonics retained (the unknown has 2H + 1 real components).
    N : int
        Time samples per period in φ (default :func:`time_samples`).
    """

    H: int
    N: int = 0

    def __post_init__(self) -> None:
        H = int(self.H)
        if H < 1:
            raise ValueError(f"harmonics: must be >= 1, got {self.H!r}")
        self.H, self.N = H, self.N or time_samples(H)
        if self.N < 2 * H + 2:
            raise ValueError(f"samples: need N > 2H + 1 = {2 * H + 1}, got {self.N}")
        self.k = np.arange(-H, H + 1)
        self.phi = 2.0 * np.pi * np.arange(self.N) / self.N
        self.W = np.array([self.to_complex(e) for e in np.eye(2 * H + 1)]).T  # c = W a
        arg = np.multiply.outer(self.phi, np.arange(1, H + 1))
        self.cos_table = np.ascontiguousarray(np.cos(arg))  # cos(kφ_j), k = 1 … H
        self.sin_table = np.ascontiguousarray(np.sin(arg))

    def to_complex(self, a: np.ndarray) -> np.ndarray:
        """Complex coefficients c_k, k = −H … H, of the real coefficient vector ``a``."""
        return to_complex(np.asarray(a, dtype=float), self.H)

    def to_real(self, c: np.ndarray) -> np.ndarray:
        """Real coefficient vector of the complex coefficients ``c`` (imaginary residue dropped)."""
        return to_real(np.asarray(c, dtype=complex), self.H)

    def evaluate(self, a: np.ndarray, phi: np.ndarray, derivative: int = 0) -> np.ndarray:
        """u or its φ-derivative of order 0, 1 or 2 at arbitrary angles ``phi``."""
        a, H = np.asarray(a, dtype=float), self.H
        kk = np.arange(1, H + 1)
        arg = np.multiply.outer(np.asarray(phi, dtype=float), kk)
        c, s = np.cos(arg), np.sin(arg)
        A, B = a[1 : H + 1], a[H + 1 :]
        if derivative == 0:
            return a[0] + c @ A + s @ B
        if derivative == 1:
            return -s @ (kk * A) + c @ (kk * B)
        return -c @ (kk**2 * A) - s @ (kk**2 * B)


def toeplitz(coef: np.ndarray, H: int) -> np.ndarray:
    """Multiplication operator on c_k (|k| <= H) of a function with complex coefficients ``coef``
    (odd length 2L + 1, centred); entry (k, l) = coef_{k−l}, zero where |k − l| > L."""
    L = (len(coef) - 1) // 2
    ok, idx = _toeplitz_index(L, H)
    out = np.zeros((2 * H + 1, 2 * H + 1), dtype=complex)
    out[ok] = coef[idx]
    return out


@functools.lru_cache(maxsize=64)
def _toeplitz_index(L: int, H: int) -> tuple[np.ndarray, np.ndarray]:
    """Mask of the entries (k, l) with |k − l| <= L and the coefficient index k − l + L of each."""
    k = np.arange(-H, H + 1)
    d = k[:, None] - k[None, :]
    ok = np.abs(d) <= L
    return ok, d[ok] + L


class DeadZoneTerms(NamedTuple):
    """The dead-zone term K(θ) f(u; D) projected on the harmonics, and its derivative.

    Attributes
    ----------
    G : complex array (2H + 1,)
        Coefficients c_k (k = −H … H) of K f(u).
    S : complex array (4H + 1,)
        Coefficients (index m + 2H, m = −2H … 2H) of K(θ)·χ(φ), χ = 1 in contact (|u| > D); the
        Jacobian of G is ``toeplitz(S, H)`` and it is the stiffness of the linearised equation.
    switches : ndarray
        Angles φ of the contact switches found in [0, 2π).
    """

    G: np.ndarray
    S: np.ndarray
    switches: np.ndarray


def dead_zone_terms(basis: HarmonicBasis, a: np.ndarray, K: np.ndarray, D: float) -> DeadZoneTerms:
    """Exact Galerkin projection of K(θ) f(u; D) with the contact switches located on the time grid.

    Parameters
    ----------
    basis : HarmonicBasis
    a : ndarray (2H + 1,)
        Real coefficients of u.
    K : complex ndarray
        Centred coefficients of the stiffness in φ.
    D : float
        Half gap (>= 0).
    """
    a, K, cos_t = np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(K, dtype=complex), basis.cos_table
    return DeadZoneTerms(*dead_zone_kernel(a, K, float(D), cos_t, basis.sin_table, basis.H, ROOT_MAX_ITER, ROOT_TOL))


def sampled_terms(basis: HarmonicBasis, ds: list, rule, K: float, periods: int) -> tuple[np.ndarray, np.ndarray]:
    """AFT of a law of several rows evaluated on the time grid (a rolling bearing's, C¹: no switch to locate).

    The rows' deflections are sampled at the N angles φ_j, the law (``rule.force``, ``rule.stiffness``: the System's
    own, :class:`~geardyn.system.RollingBearingLaw`) evaluated there at the base angle θ_j = periods·φ_j, and the
    samples of K f_i and K ∂f_i/∂δ_j transformed: G_i (2H + 1 coefficients) and S_ij (4H + 1, ``toeplitz(S_ij, H)``
    the exact derivative of the sampled G_i in δ_j, since 2H < N/2), returned as arrays G (rows, 2H + 1) and
    S (rows, rows, 4H + 1).

    Parameters
    ----------
    basis : HarmonicBasis
    ds : list of ndarray (2H + 1,)
        Real coefficients of each row's deflection.
    rule : Law
        The law, ``force(δ, θ)`` (N, rows) and ``stiffness(δ, θ)`` (N, rows, rows) at deflections δ (N, rows).
    K : float
        Its load–deflection constant.
    periods : int
        Base periods per response period.
    """
    H, N = basis.H, basis.N
    X = np.stack([a[0] + basis.cos_table @ a[1 : H + 1] + basis.sin_table @ a[H + 1 :] for a in ds], axis=-1)
    theta = periods * basis.phi
    G = np.fft.fft(K * rule.force(X, theta), axis=0)[np.arange(-H, H + 1) % N] / N
    S = np.fft.fft(K * rule.stiffness(X, theta), axis=0)[np.arange(-2 * H, 2 * H + 1) % N] / N
    return G.T, S.transpose(1, 2, 0)


def signal_extrema(basis: HarmonicBasis, a: np.ndarray) -> tuple[float, float, float, float]:
    """(u_min, u_max, φ_min, φ_max) of u over the period, refined by Newton on u_φ = 0.

    Parameters
    ----------
    basis : HarmonicBasis
    a : ndarray
        Real coefficients of u.
    """
    r = extrema_kernel(np.ascontiguousarray(a, dtype=float), basis.H, basis.cos_table, basis.sin_table, ROOT_MAX_ITER)
    return tuple(map(float, r))
