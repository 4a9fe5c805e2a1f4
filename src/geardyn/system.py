"""The system concept every analysis works on.

A *system* is a frozen description of a periodically forced, piecewise-smooth ODE ``x' = F(θ, x)`` with
``θ = ω τ``: the analyses (integration, Poincaré sections, Lyapunov spectra, the period map and everything
on it) use only what this protocol gives, never the fields of one model.  :class:`~geardyn.model.GearModel`
(the 1-DOF mesh, state (u, u')) is its first implementation.

Members
-------
state_dim : int
    Dimension of the first-order state ``x``.
period : float
    Forcing period ``T = 2π/ω`` in non-dimensional time.
omega : float
    Forcing (mesh) frequency ω; the stroboscopic section is θ ≡ 0 mod 2π.
get(name), with_param(name, value), parameters()
    Parameters by their canonical names (:func:`geardyn.params.canonical_param`).
contact_boundaries()
    The switching surfaces of the non-smooth elements (:class:`~geardyn.model.Boundary`).
pack(systems)
    The kernel arrays of a batch of systems of one kind.
"""

from __future__ import annotations

from typing import Any, Iterable, Protocol, runtime_checkable

__all__ = ["System"]


@runtime_checkable
class System(Protocol):
    """What an analysis may ask of a model (see the module docstring)."""

    state_dim: int

    @property
    def omega(self) -> float: ...

    @property
    def period(self) -> float: ...

    def get(self, name: str) -> float: ...

    def with_param(self, name: str, value: float) -> "System": ...

    def parameters(self) -> dict[str, float]: ...

    def contact_boundaries(self) -> tuple[Any, ...]: ...

    @staticmethod
    def pack(systems: Iterable[Any]) -> tuple[Any, ...]: ...
