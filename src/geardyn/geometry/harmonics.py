"""Fourier harmonics of the mesh damping, stiffness and static transmission error of a gear pair."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..model import ModelError
from .inputs import _finite

__all__ = ["MeshHarmonics"]


@dataclass(frozen=True)
class MeshHarmonics:
    """Fourier harmonics of the mesh damping, stiffness and static transmission error.

    Each series is given either non-dimensionally or dimensionally, not both.  Harmonic ``k``
    (1-based) of each series is element ``k − 1``; phases default to 0 and are in radians.

    Parameters
    ----------
    xi : sequence of float
        Damping harmonics ξ_k = c_k/(2 m_e ω_n) (non-dimensional).
    c : sequence of float
        Damping harmonics c_k (N·s/m).
    phi_c : sequence of float
        Phases φ_ck (rad).
    kappa : sequence of float
        Stiffness harmonics κ_r = k_r/k0 (non-dimensional).
    k : sequence of float
        Stiffness harmonics k_r (N/m).
    phi_k : sequence of float
        Phases φ_kr (rad).
    eps : sequence of float
        STE harmonics ε_l = e_l/b_c (non-dimensional).
    e : sequence of float
        STE harmonics e_l (m).
    phi_e : sequence of float
        Phases φ_el (rad).

    Examples
    --------
    >>> from geardyn import MeshHarmonics
    >>> h = MeshHarmonics(xi=(0.05,), kappa=(0.2,), eps=(0.5,))
    >>> nd = h.nondimensional(1.0, 1.0, 1.0, 1.0)
    >>> nd["kappa"], nd["eps"]
    ((0.2,), (0.5,))
    """

    xi: tuple[float, ...] = ()
    c: tuple[float, ...] = ()
    phi_c: tuple[float, ...] = ()
    kappa: tuple[float, ...] = ()
    k: tuple[float, ...] = ()
    phi_k: tuple[float, ...] = ()
    eps: tuple[float, ...] = ()
    e: tuple[float, ...] = ()
    phi_e: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        for f in fields(self):
            vals = getattr(self, f.name)
            if vals is None:
                vals = ()
            if np.isscalar(vals):
                vals = (vals,)
            object.__setattr__(self, f.name, tuple(_finite(f"{f.name}{i + 1}", v) for i, v in enumerate(vals)))
        for nd, dim, unit in (("xi", "c", "N*s/m"), ("kappa", "k", "N/m"), ("eps", "e", "m")):
            if getattr(self, nd) and getattr(self, dim):
                raise ModelError(
                    f"{nd}/{dim}: give the harmonics either non-dimensionally ({nd}) or in {unit} ({dim}), not both"
                )

    def nondimensional(self, m_e: float, omega_n: float, k0: float, b_c: float) -> dict[str, tuple[float, ...]]:
        """Non-dimensional harmonics for :class:`~geardyn.model.GearModel`.

        Parameters
        ----------
        m_e : float
            Equivalent mass (kg).
        omega_n : float
            Natural frequency √(k0/m_e) (rad/s).
        k0 : float
            Mean mesh stiffness (N/m).
        b_c : float
            Characteristic length (m).

        Returns
        -------
        dict
            ``xi``, ``phi_c``, ``kappa``, ``phi_k``, ``eps``, ``phi_e``: the keyword arguments of
            :class:`~geardyn.model.GearModel` (ξ_k = c_k/(2 m_e ω_n), κ_r = k_r/k0, ε_l = e_l/b_c).
        """
        return {
            "xi": self.xi or tuple(c / (2.0 * m_e * omega_n) for c in self.c),
            "phi_c": self.phi_c,
            "kappa": self.kappa or tuple(k / k0 for k in self.k),
            "phi_k": self.phi_k,
            "eps": self.eps or tuple(e / b_c for e in self.e),
            "phi_e": self.phi_e,
        }
