"""The system contract every analysis is written against.

A *system* is a frozen description of a periodically forced, piecewise-smooth ODE ``x' = F(θ, x)`` with
``θ = ω τ``, whose non-smooth elements are dead zones ``δ ↦ δ − clamp(δ, −D, D)`` of linear functions δ of
the state.  The analyses (integration, steady responses, Poincaré sections, Lyapunov spectra, the period map
and everything on it, sweeps) use only what this protocol gives, never the fields of one model, and reach
the kernels only through :mod:`geardyn.integrate`, which hands a batch to the system's :attr:`backend`.

Implementations: :class:`~geardyn.model.GearModel` (the 1-DOF mesh, state (u, u'), one element, no
rigid-body mode; backend :data:`geardyn.backend.PAIR`) and :class:`~geardyn.systems.SystemModel`
(mesh-vector systems, state (q̃, q̃'), meshes then clearances, rigid-body modes of free rotations;
backend :data:`geardyn.backend.MESH`).  ``tests/test_conformance.py`` holds every implementation to the
same checks.

Members
-------
state_dim : int
    Dimension of the first-order state ``x``.
omega : float
    Base forcing frequency ω; the stroboscopic section is θ ≡ 0 mod 2π.
period : float
    Base period 2π/ω.
sampling_period : float
    The stroboscopic sampling period T_f: the forcing period p·2π/ω (p = :meth:`period_multiple`, 1
    for the pair), or 2π/ω when the forcing is not periodic.
period_multiple()
    p, or None when the forcing is quasi-periodic (the periodic tools then refuse).
elements, reference
    The non-smooth elements (:class:`Element`: name, half gap, kind) and the index of the reference
    element, whose deflection is the 1-DOF model's u.
element_series(x, tau)
    δ and δ' of every element for states x at times τ, shape (..., elements, 2).
rigid_basis()
    Orthonormal columns (coordinates, r) of the rigid-body modes (zero stiffness, damping and load);
    r = 0 for the pair.
initial_state(u0, v0)
    The state at θ = 0 with the reference element at (u0, v0) (and every other mesh at rest).
mean_trace()
    The mean over a forcing period of the trace of ∂F/∂x (the sum of the Lyapunov exponents).
report(res, point, tau, deltas, extrema)
    What the kind adds to an analysis summary beyond the reference element's keys (nothing for the pair;
    per-mesh DTE, forces and dynamic factors for a mesh-vector system).
get(name), with_param(name, value), parameters()
    Parameters by their canonical names.
contact_boundaries()
    The switching surfaces of the non-smooth elements (:class:`~geardyn.model.Boundary`).
pack(systems)
    The kernel arrays of a batch of systems of one kind.
backend
    The :class:`geardyn.backend.Backend` that integrates a packed batch.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = ["System", "Element", "state_names", "element_names"]


@dataclass(frozen=True)
class Element:
    """A non-smooth element of a system: a dead zone of half gap ``gap`` in the deflection δ.

    Attributes
    ----------
    name : str
        Its name (``mesh`` for the pair; the mesh or clearance name of a system).
    gap : float
        Half gap D (contact boundaries at δ = ±D, non-dimensional).
    kind : str
        ``"mesh"`` or ``"clearance"``.
    """

    name: str
    gap: float
    kind: str = "mesh"


@runtime_checkable
class System(Protocol):
    """What an analysis may ask of a model (see the module docstring).

    Examples
    --------
    >>> from geardyn import GearModel, System, load_system
    >>> pair = GearModel(omega=0.8)
    >>> isinstance(pair, System), pair.state_dim, [e.name for e in pair.elements]
    (True, 2, ['mesh'])
    >>> system = load_system("examples/systems/paper_torsional.toml")
    >>> isinstance(system, System), system.state_dim, system.rigid_basis().shape
    (True, 4, (2, 1))
    """

    state_dim: int

    @property
    def omega(self) -> float: ...

    @property
    def period(self) -> float: ...

    @property
    def sampling_period(self) -> float: ...

    def period_multiple(self) -> int | None: ...

    @property
    def elements(self) -> tuple[Element, ...]: ...

    @property
    def reference(self) -> int: ...

    def element_series(self, x: np.ndarray, tau: np.ndarray | float) -> np.ndarray: ...

    def rigid_basis(self) -> np.ndarray: ...

    def initial_state(self, u0: float = 0.0, v0: float = 0.0) -> np.ndarray: ...

    def mean_trace(self) -> float: ...

    def report(
        self, res: Any = None, point: int = 0, tau: Any = None, deltas: Any = None, extrema: Any = None
    ) -> dict[str, Any]: ...

    def get(self, name: str) -> float: ...

    def with_param(self, name: str, value: float) -> System: ...

    def parameters(self) -> dict[str, float]: ...

    def contact_boundaries(self) -> tuple[Any, ...]: ...

    @staticmethod
    def pack(systems: Iterable[Any]) -> Any: ...

    @property
    def backend(self) -> Any: ...


def state_names(model: Any, d: int) -> list[str]:
    """Names of the d state coordinates of a system (its DOF labels, then their rates), else their indices.

    Parameters
    ----------
    model : System
        The system (its ``labels``, if it has them).
    d : int
        The state dimension.

    Returns
    -------
    list of str

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> state_names(GearModel(), 2)
    ['0', '1']
    """
    labels = list(getattr(model, "labels", ()) or ())
    if 2 * len(labels) == d:
        return labels + [f"{lab}'" for lab in labels]
    return [str(i) for i in range(d)]


def element_names(model: Any, n: int) -> list[str]:
    """Names of the n non-smooth elements of a system (its :attr:`~geardyn.system.System.elements`), else indices.

    Parameters
    ----------
    model : System or None
        The system.
    n : int
        The number of elements expected.

    Returns
    -------
    list of str

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> element_names(GearModel(), 1)
    ['mesh']
    """
    els = [e.name for e in model.elements] if model is not None else []
    return els if len(els) == n else [str(i) for i in range(n)]
