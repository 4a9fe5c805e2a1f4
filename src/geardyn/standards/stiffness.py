r"""Stiffness harmonics κ_r from the contact ratios: the time-varying mesh stiffness over a mesh cycle.

Derivation
----------
Let τ be the mesh phase in mesh cycles (θ = 2π τ is geardyn's mesh angle; one base pitch of roll
per cycle) and let every tooth pair in contact contribute the same stiffness per unit length of its
contact line.

*Spur teeth (ε_β = 0).*  A tooth pair enters contact at τ = j (j = 0, ±1, …) and leaves it
ε_α cycles later, so the number of pairs in contact is the comb of boxes

    n(τ) = Σ_j H(τ − j) − H(τ − j − ε_α)      (H the unit step),

i.e. the comb of period 1 convolved with a box of width ε_α.  For 1 < ε_α < 2 this is the familiar
alternation of double contact (during ε_α − 1 of each cycle) and single contact (during 2 − ε_α).
Its mean is ε_α and its Fourier coefficients are, with ``sinc x = sin(πx)/(πx)``,

    n̂_r = ε_α sinc(r ε_α) e^{−iπ r ε_α}.

*Spiral and helical teeth (ε_β > 0).*  The contact line of a pair sweeps obliquely across the zone
of action: the pair enters at one end of the face and takes ε_β further mesh cycles to be in contact
across the whole face.  The stiffness, proportional to the total length of the contact lines, is
therefore the moving-window average of the spur pattern over ε_β cycles,

    L(τ) = (1/ε_β) ∫_{τ−ε_β}^{τ} n(s) ds,

a second convolution with a box, now of width ε_β.  It leaves the mean unchanged and multiplies
harmonic r by ``sinc(r ε_β) e^{−iπ r ε_β}``.

*Normalisation.*  Dividing by the mean and writing the real series in geardyn's convention
``k(θ)/k0 = 1 + Σ_r κ_r cos(rθ + φ_r)``:

    S_r = sinc(r ε_α) · sinc(r ε_β),   κ_r = 2 |S_r|,
    φ_r = −π r (ε_α + ε_β)  (+ π where S_r < 0),  wrapped to (−π, π],

with θ = 0 where a tooth pair enters contact at the first end of the face.  The mean k0 is the one
of the standard (``c_γ · b``, ISO 6336-1 / ISO 10300-1): only the *shape* of the variation comes from
this model, so its amplitude is consistent with the ISO mean stiffness by construction.

Consequences: κ_r vanishes when r ε_α or r ε_β is a whole number (the contact length is then
constant); for ε_β → 0 the spur result ``κ_r = 2|sinc(r ε_α)|`` is recovered; and
``Σ κ_r`` is bounded by the peak-to-peak ratio of the rectangular (or trapezoidal) pattern.

Limits of the model: every contact line carries the same stiffness per unit length (no reduction
near tip and root, no load sharing by tooth bending across pairs), the zone of action is a
parallelogram (the bevel and hypoid zone is taken as that of the virtual cylindrical gear), and
there is no profile or lead modification.  Real teeth with tip relief or crowning have smaller
higher harmonics than this rectangular model.

References
----------
ISO 6336-1:2006 and ISO 10300-1:2014 (contact ratios ε_α, ε_β and mean mesh stiffness c_γ).
The single/double-contact alternation and its smoothing by the overlap of helical teeth are the
standard description of parametric mesh excitation in gear dynamics textbooks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["StiffnessHarmonics", "mesh_stiffness_harmonics", "mesh_stiffness_waveform"]


def _sinc(x: float) -> float:
    return 1.0 if x == 0.0 else math.sin(math.pi * x) / (math.pi * x)


def _check(eps_alpha: float, eps_beta: float) -> tuple[float, float]:
    ea, eb = float(eps_alpha), float(eps_beta)
    if not (math.isfinite(ea) and ea > 0.0):
        raise ModelError(f"eps_alpha: must be a finite contact ratio > 0, got {eps_alpha!r}")
    if not (math.isfinite(eb) and eb >= 0.0):
        raise ModelError(f"eps_beta: must be a finite face contact ratio >= 0, got {eps_beta!r}")
    return ea, eb


@dataclass(frozen=True)
class StiffnessHarmonics:
    """Fourier harmonics of the mesh stiffness implied by the contact ratios.

    ``k(θ)/k0 = 1 + Σ_r kappa[r-1] cos(rθ + phi[r-1])`` (geardyn's ``kappa``/``phi_k`` convention).

    Attributes
    ----------
    eps_alpha, eps_beta : float
        The transverse and face contact ratios used.
    kappa : tuple of float
        Amplitudes κ_1 … κ_R relative to the mean stiffness (≥ 0).
    phi : tuple of float
        Phases φ_1 … φ_R (rad, in (−π, π]).
    """

    eps_alpha: float
    eps_beta: float
    kappa: tuple[float, ...]
    phi: tuple[float, ...]

    def to_dict(self) -> dict[str, object]:
        """Plain dict for JSON: contact ratios, ``kappa`` and ``phi_k`` (rad) as lists."""
        return {
            "eps_alpha": self.eps_alpha,
            "eps_beta": self.eps_beta,
            "kappa": list(self.kappa),
            "phi_k": list(self.phi),
        }


def mesh_stiffness_harmonics(eps_alpha: float, eps_beta: float = 0.0, n_harmonics: int = 3) -> StiffnessHarmonics:
    """Stiffness harmonics κ_r and phases φ_r from the transverse and face contact ratios.

    Parameters
    ----------
    eps_alpha : float
        Transverse contact ratio ε_α (> 0); for bevel gears ε_vα of the virtual cylindrical gear.
    eps_beta : float, optional
        Face contact ratio ε_β (≥ 0, default 0: spur teeth); for bevel gears ε_vβ.
    n_harmonics : int, optional
        Number of harmonics R (≥ 1, default 3).

    Returns
    -------
    StiffnessHarmonics
        ``κ_r = 2 |sinc(r ε_α) sinc(r ε_β)|`` and ``φ_r`` as derived in the module docstring.

    Raises
    ------
    ModelError
        For contact ratios out of range or ``n_harmonics < 1``.
    """
    ea, eb = _check(eps_alpha, eps_beta)
    if int(n_harmonics) != n_harmonics or n_harmonics < 1:
        raise ModelError(f"n_harmonics: must be a whole number >= 1, got {n_harmonics!r}")
    kappa, phi = [], []
    for r in range(1, int(n_harmonics) + 1):
        s = _sinc(r * ea) * _sinc(r * eb)
        ph = -math.pi * r * (ea + eb) + (math.pi if s < 0.0 else 0.0)
        ph = math.pi - ((math.pi - ph) % (2.0 * math.pi))  # wrap to (-pi, pi]
        kappa.append(2.0 * abs(s))
        phi.append(ph if abs(s) > 0.0 else 0.0)
    return StiffnessHarmonics(eps_alpha=ea, eps_beta=eb, kappa=tuple(kappa), phi=tuple(phi))


def _cumulative_contact(t: np.ndarray, ea: float, j: np.ndarray) -> np.ndarray:
    """Σ_j clip(t − j, 0, ε_α): the integral of n up to t, less a constant (pairs j in ``j``)."""
    return np.clip(t[..., None] - j, 0.0, ea).sum(axis=-1)


def mesh_stiffness_waveform(eps_alpha: float, eps_beta: float, theta: np.ndarray) -> np.ndarray:
    """The normalised mesh stiffness k(θ)/k0 of the model, evaluated exactly (no Fourier truncation).

    Parameters
    ----------
    eps_alpha, eps_beta : float
        Transverse and face contact ratios (ε_α > 0, ε_β ≥ 0).
    theta : array_like
        Mesh angle θ (rad; 2π per mesh cycle).

    Returns
    -------
    numpy.ndarray
        ``L(θ/2π) / ε_α``: the number of pairs in contact (ε_β = 0) or the window-averaged contact
        length (ε_β > 0), divided by its mean.  Its mean over a cycle is 1.
    """
    ea, eb = _check(eps_alpha, eps_beta)
    tau = np.asarray(theta, dtype=float) / (2.0 * math.pi)
    if eb == 0.0:
        # pairs that entered at tau - m (m = 0, 1, ...) and have not left: m + frac(tau) < eps_alpha
        return np.ceil(ea - (tau - np.floor(tau))) / ea
    lo = math.floor(float(np.min(tau)) - eb - ea) - 1 if tau.size else 0
    hi = math.ceil(float(np.max(tau))) + 1 if tau.size else 0
    j = np.arange(lo, hi + 1, dtype=float)
    big = _cumulative_contact(tau, ea, j) - _cumulative_contact(tau - eb, ea, j)
    return big / (eb * ea)
