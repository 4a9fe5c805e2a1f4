"""The rolling-element bearing: a nonlinear element law between a shaft's (x, y) and the housing.

A radial ball or roller bearing of ``Z`` rolling elements on the pitch diameter d_m, element diameter d_b, contact
angle α, radial internal clearance c (half the diametral clearance P_d of Harris) and Hertzian load–deflection
constant K with exponent n (3/2 for point contact, a ball; 10/9 for line contact, a roller).  With the outer ring
fixed and the inner ring on the shaft turning at Ω, the cage turns at

    ω_cage = Ω (1 − d_b cos α / d_m) / 2,

element j sits at φ_j(t) = ω_cage t + φ_0 + 2πj/Z, and with the shaft centre displaced by (x, y) its compression is

    δ_j = x cos φ_j + y sin φ_j − c.

The bearing pushes the shaft back with

    F = −K Σ_j max(δ_j, 0)^n (cos φ_j, sin φ_j)

(Sopanen & Mikkola 2003; Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., ch. 7): a stiffness that varies
as the elements pass the load line, at the ball-pass frequency Z ω_cage, and a dead band of width c.

Non-dimensional form (with the system's scales: lengths b_c, forces k_ref b_c, time τ = ω_n t): x = b_c x̃ and
F̃ = F/(k_ref b_c), so ``K̃ = K b_c^(n−1)/k_ref`` and ``c̃ = c/b_c``; the cage angle advances by ``ρ_cage`` radians
per radian of the base phase θ (``ρ_cage = ω_cage/ω_e``, ω_e the reference mesh frequency).

The functions here are plain NumPy (one bearing, any number of samples) and are what the kernel's bearing law
evaluates; the load distribution in tests is computed independently from Harris's integrals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = [
    "BALL_EXPONENT",
    "ROLLER_EXPONENT",
    "RollingBearing",
    "bearing_forces",
    "bearing_stiffness",
    "ball_bearing_forces",
    "loaded_elements",
]

#: Hertzian exponent of a point contact (ball) and of a line contact (roller).
BALL_EXPONENT = 1.5
ROLLER_EXPONENT = 10.0 / 9.0


@dataclass(frozen=True)
class RollingBearing:
    """A radial rolling-element bearing (SI units; see the module docstring).

    Attributes
    ----------
    kind : str
        ``"ball"`` or ``"roller"`` (sets the default exponent).
    elements : int
        Number Z of rolling elements (>= 3).
    pitch_diameter : float
        d_m (m).
    element_diameter : float
        d_b, the ball or roller diameter (m); < d_m.
    contact_angle : float
        α (rad), in [0, π/2).
    clearance : float
        Radial internal clearance c (m, >= 0): the shaft moves c in any direction before an element is loaded.
    stiffness : float
        Hertzian load–deflection constant K (N/m^n), > 0.
    exponent : float, optional
        n (default 3/2 for a ball, 10/9 for a roller); >= 1.
    """

    kind: str
    elements: int
    pitch_diameter: float
    element_diameter: float
    contact_angle: float
    clearance: float
    stiffness: float
    exponent: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("ball", "roller"):
            raise ModelError(f"bearing type: 'ball' or 'roller', got {self.kind!r}")
        if int(self.elements) != self.elements or self.elements < 3:
            raise ModelError(f"bearing elements: an integer >= 3, got {self.elements!r}")
        object.__setattr__(self, "elements", int(self.elements))
        for key in ("pitch_diameter", "element_diameter", "stiffness"):
            v = float(getattr(self, key))
            if not (math.isfinite(v) and v > 0):
                raise ModelError(f"bearing {key}: must be > 0, got {v!r}")
            object.__setattr__(self, key, v)
        if not self.element_diameter < self.pitch_diameter:
            raise ModelError(
                f"bearing element_diameter: must be < pitch_diameter {self.pitch_diameter!r}, "
                f"got {self.element_diameter!r}"
            )
        a = float(self.contact_angle)
        if not (math.isfinite(a) and 0.0 <= a < math.pi / 2):
            raise ModelError(f"bearing contact_angle: must be in [0, 90) deg, got {math.degrees(a)!r} deg")
        object.__setattr__(self, "contact_angle", a)
        c = float(self.clearance)
        if not (math.isfinite(c) and c >= 0):
            raise ModelError(f"bearing clearance: must be >= 0, got {c!r}")
        object.__setattr__(self, "clearance", c)
        n = float(
            (BALL_EXPONENT if self.kind == "ball" else ROLLER_EXPONENT) if self.exponent is None else self.exponent
        )
        if not (math.isfinite(n) and 1.0 <= n <= 3.0):
            raise ModelError(f"bearing exponent: must be in [1, 3], got {n!r}")
        object.__setattr__(self, "exponent", n)

    @property
    def cage_ratio(self) -> float:
        """ω_cage/Ω = (1 − d_b cos α / d_m)/2 (outer ring fixed)."""
        return 0.5 * (1.0 - self.element_diameter * math.cos(self.contact_angle) / self.pitch_diameter)

    @property
    def ball_pass_ratio(self) -> float:
        """The varying-compliance frequency over the shaft frequency: Z ω_cage/Ω (the outer-race ball pass)."""
        return self.elements * self.cage_ratio

    def nondimensional(self, b_c: float, k_ref: float) -> tuple[float, float]:
        """(K̃, c̃) = (K b_c^(n−1)/k_ref, c/b_c) in a system's scales."""
        n = float(self.exponent)  # type: ignore[arg-type]
        return self.stiffness * b_c ** (n - 1.0) / k_ref, self.clearance / b_c


def _compression(x, y, cage_angle, Z: int, c: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """δ_j = x cos φ_j + y sin φ_j − c of every element (last axis), with cos φ_j and sin φ_j."""
    phi = np.asarray(cage_angle, dtype=float)[..., None] + 2.0 * np.pi * np.arange(Z) / Z
    cs, sn = np.cos(phi), np.sin(phi)
    return np.asarray(x, dtype=float)[..., None] * cs + np.asarray(y, dtype=float)[..., None] * sn - c, cs, sn


def bearing_forces(x, y, cage_angle, Z: int, K: float, n: float, c: float) -> tuple[np.ndarray, np.ndarray]:
    """The bearing's force on the shaft, (F_x, F_y) = −K Σ_j max(δ_j, 0)^n (cos φ_j, sin φ_j).

    Parameters
    ----------
    x, y : float or array
        Shaft centre relative to the housing (any consistent length unit: SI, or non-dimensional with K̃, c̃).
    cage_angle : float or array
        The cage's angle φ_0 (element 0 at φ_0, element j at φ_0 + 2πj/Z); broadcast with x, y.
    Z, K, n, c
        Elements, load–deflection constant, exponent, radial clearance.
    """
    d, cs, sn = _compression(x, y, cage_angle, Z, c)
    q = K * np.maximum(d, 0.0) ** n
    return -np.sum(q * cs, axis=-1), -np.sum(q * sn, axis=-1)


def bearing_stiffness(x, y, cage_angle, Z: int, K: float, n: float, c: float) -> np.ndarray:
    """−∂F/∂(x, y): the bearing's tangent stiffness matrix (…, 2, 2), K n Σ_j δ_j^(n−1) (cos, sin)ᵀ(cos, sin).

    Parameters
    ----------
    x, y : float or array
        Shaft centre relative to the housing (any consistent length unit: SI, or non-dimensional with K̃, c̃).
    cage_angle : float or array
        The cage's angle φ_0 (rad; element j at φ_0 + 2πj/Z); broadcast with x, y.
    Z : int
        Number of rolling elements.
    K : float
        Load–deflection constant (N/m^n in SI, or K̃).
    n : float
        Load–deflection exponent (3/2 ball, 10/9 roller).
    c : float
        Radial clearance (same length unit as x, y).
    """
    d, cs, sn = _compression(x, y, cage_angle, Z, c)
    w = np.where(d > 0.0, K * n * np.maximum(d, 0.0) ** (n - 1.0), 0.0)
    out = np.empty(d.shape[:-1] + (2, 2))
    out[..., 0, 0] = np.sum(w * cs * cs, axis=-1)
    out[..., 0, 1] = out[..., 1, 0] = np.sum(w * cs * sn, axis=-1)
    out[..., 1, 1] = np.sum(w * sn * sn, axis=-1)
    return out


def loaded_elements(x, y, cage_angle, Z: int, c: float) -> np.ndarray:
    """How many elements carry load (δ_j > 0).

    Parameters
    ----------
    x, y : float or array
        Shaft centre relative to the housing (any consistent length unit).
    cage_angle : float or array
        The cage's angle φ_0 (rad; element j at φ_0 + 2πj/Z); broadcast with x, y.
    Z : int
        Number of rolling elements.
    c : float
        Radial clearance (same length unit as x, y).
    """
    return np.sum(_compression(x, y, cage_angle, Z, c)[0] > 0.0, axis=-1)


def ball_bearing_forces(
    bearing: RollingBearing, x, y, t, shaft_speed: float, phase: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """The force on the shaft (N) at time t (s) of a bearing whose inner ring turns at ``shaft_speed`` (rad/s).

    The cage angle is ω_cage t + ``phase`` with ω_cage = ``shaft_speed`` × :attr:`RollingBearing.cage_ratio`; x, y
    in m.  For roller bearings too (the name follows the common case).

    Parameters
    ----------
    bearing : RollingBearing
        The bearing (elements, stiffness, exponent, clearance and cage ratio, SI).
    x, y : float or array
        Shaft centre relative to the housing (m).
    t : float or array
        Time (s); broadcast with x, y.
    shaft_speed : float
        Speed of the inner ring, i.e. the shaft (rad/s).
    phase : float
        Cage angle at t = 0 (rad); default 0.

    Returns
    -------
    F_x, F_y : ndarray
        The force on the shaft (N).
    """
    cage = bearing.cage_ratio * shaft_speed * np.asarray(t, dtype=float) + phase
    return bearing_forces(x, y, cage, bearing.elements, bearing.stiffness, float(bearing.exponent), bearing.clearance)  # type: ignore[arg-type]
