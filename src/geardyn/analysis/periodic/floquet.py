"""Floquet analysis of a period-n orbit from its monodromy matrix."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Floquet", "floquet", "INSTABILITY_TYPES", "REAL_MULTIPLIER_TOL"]

#: A multiplier with |Im μ| below this (relative to |μ|) counts as real.
REAL_MULTIPLIER_TOL = 1.0e-9

#: Instability types of a periodic orbit (see :class:`Floquet`).
INSTABILITY_TYPES = {
    "none": "stable: all multipliers inside the unit circle",
    "saddle": "one real multiplier > 1 (the kind of instability a fold creates)",
    "flip-saddle": "one real multiplier < −1 (the kind a period doubling creates)",
    "unstable-focus": "a complex pair outside the unit circle (the kind a Neimark–Sacker bifurcation creates)",
    "repeller": "both real multipliers outside the unit circle",
}


@dataclass(frozen=True)
class Floquet:
    """Floquet analysis of a period-n orbit from its monodromy matrix (non-dimensional).

    Attributes
    ----------
    multipliers : ndarray of complex (d,)
        Eigenvalues μ of the monodromy matrix, largest modulus first.
    exponents : ndarray (d,)
        Floquet (Lyapunov) exponents ln|μ|/(nT) per unit τ; for a stable orbit the first equals the
        largest Lyapunov exponent.
    stable : bool
        All |μ| < 1 (asymptotically stable).
    instability : str
        One of :data:`INSTABILITY_TYPES`: ``none``, ``saddle`` (a real μ > 1), ``flip-saddle``
        (a real μ < −1), ``unstable-focus`` (a complex pair with |μ| > 1), ``repeller``.
    determinant, trace : float
        det M and tr M; for the 1-DOF model det M = exp(−2 ξ0 n T).

    References
    ----------
    Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
    (multipliers of a fixed point of a map and the codimension-one crossings).
    """

    multipliers: np.ndarray
    exponents: np.ndarray
    stable: bool
    instability: str
    determinant: float
    trace: float

    @property
    def max_modulus(self) -> float:
        """The largest |μ|."""
        return float(np.max(np.abs(self.multipliers)))

    @property
    def crossing(self) -> str | None:
        """The bifurcation through which this kind of instability arises (None if stable)."""
        return {
            "saddle": "fold",
            "flip-saddle": "period-doubling",
            "unstable-focus": "neimark-sacker",
            "repeller": None,
            "none": None,
        }[self.instability]

    def pairs(self) -> list[list[float]]:
        """Multipliers as [[re, im], ...] (the JSON form)."""
        return pairs(self.multipliers)


def largest_first(mu: np.ndarray) -> np.ndarray:
    """The multipliers ``mu`` by decreasing modulus (equal moduli in their order)."""
    return mu[np.argsort(-np.abs(mu), kind="stable")]


def pairs(mu: np.ndarray) -> list[list[float]]:
    """Complex multipliers as JSON pairs [re, im]."""
    return [[float(m.real), float(m.imag)] for m in mu]


def floquet(monodromy: np.ndarray, n: int, period: float) -> Floquet:
    """Floquet multipliers, exponents, stability and instability type of a period-n orbit.

    Parameters
    ----------
    monodromy : (d, d) array
        Jacobian of P^n at a point of the orbit (:meth:`PeriodMap.jacobian
        <geardyn.analysis.periodic.PeriodMap.jacobian>`).
    n : int
        Number of forcing periods of the orbit.
    period : float
        Forcing period T = 2π/ω (non-dimensional time).

    Returns
    -------
    Floquet
        All NaN (and ``repeller``) when the matrix is not finite.

    References
    ----------
    Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
    (multipliers of periodic orbits and fixed points of maps).
    """
    M = np.asarray(monodromy, dtype=float)
    if not np.all(np.isfinite(M)):
        d = M.shape[0] if M.ndim == 2 else 2
        nan = np.array([complex(math.nan, 0.0)] * d)
        return Floquet(nan, np.full(d, math.nan), False, "repeller", math.nan, math.nan)
    mu = largest_first(np.linalg.eigvals(M).astype(complex))
    mod = np.abs(mu)
    with np.errstate(divide="ignore"):
        expo = np.log(mod) / (n * period)
    out = mod > 1.0
    stable = bool(not np.any(out))
    is_real = np.abs(mu.imag) <= REAL_MULTIPLIER_TOL * np.maximum(mod, 1e-300)
    if stable:
        kind = "none"
    elif not np.all(is_real):
        kind = "unstable-focus"
    elif np.all(out):
        kind = "repeller"
    else:
        kind = "saddle" if mu[0].real > 0 else "flip-saddle"
    return Floquet(mu, expo, stable, kind, float(np.linalg.det(M)), float(np.trace(M)))
