"""The system contract every analysis is written against.

A *system* is a frozen description of a periodically forced, piecewise-smooth ODE ``x' = F(θ, x)`` with
``θ = ω τ``, whose non-smooth elements are linear functions δ = V x of the state acted on by an element
*law* (:class:`Law`; the dead zone ``δ ↦ δ − clamp(δ, −D, D)`` of half gap D is the default).  The analyses
(integration, steady responses, Poincaré sections, Lyapunov spectra, the period map and everything on it,
sweeps) use only what this protocol gives, never the fields of one model, and reach the kernels only through
:mod:`geardyn.integrate`, which hands a :class:`Batch` to the system's :attr:`backend`.

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
    The non-smooth elements (:class:`Element`: name, gap, kind, law) and the index of the reference
    element, whose deflection is the 1-DOF model's u.
element_series(x, tau)
    δ and δ' of every element for states x at times τ, shape (..., elements, 2).
rigid_basis()
    Orthonormal columns (coordinates, r) of the rigid-body modes (zero stiffness, damping and load);
    r = 0 for the pair.
initial_state(u0, v0)
    The state at θ = 0 with the reference element at (u0, v0) (and every other mesh at rest).
element_forces(tau, deltas)
    The forces (K, meshes) the meshes transmit at times τ given every element's (δ, δ') (:meth:`element_series`),
    in the units of the reference mesh's k b_c; column :attr:`reference` is the reference mesh's.
static_force()
    The static force of the reference element (non-dimensional): the pair's mean load f_p, a system's reference
    mesh force at its static equilibrium; the reference of dynamic factors and of :meth:`Scales.operating_point
    <geardyn.geometry.scales.Scales.operating_point>`.
mean_trace()
    The mean over a forcing period of the trace of ∂F/∂x (the sum of the Lyapunov exponents; negative:
    the period map contracts every volume).
report(res, point, tau, deltas, extrema)
    What the kind adds to an analysis summary beyond the reference element's keys (nothing for the pair;
    per-mesh DTE, forces and dynamic factors for a mesh-vector system).
get(name), with_param(name, value), parameters()
    Parameters by their canonical names.
contact_boundaries()
    The switching surfaces of the non-smooth elements (:class:`~geardyn.model.Boundary`).
to_attrs(), from_attrs(attrs)
    The system as JSON text for a result's attributes, and back: ``from_attrs(to_attrs())`` is the same
    system (:func:`geardyn.io.model_from_attrs` picks the class by :attr:`backend`'s name).
pack(systems)
    The kernel arrays of a batch of systems of one kind.
backend
    The :class:`geardyn.backend.Backend` that integrates a batch: it packs it, supplies the
    :class:`Batch` of a list of systems or of a grid's parameter points (:meth:`Backend.points`), and
    runs its kernel.

Element laws
------------
An element's law (:class:`Law`) maps its deflection δ to the force it transmits.  A law is a small frozen
value: an integer :attr:`~Law.code` (the branch a kernel takes; kernels receive it in their packed arrays)
and its parameters (:meth:`~Law.params`), and it provides, in plain NumPy for references and tools:

``force(delta)``, ``stiffness(delta)``
    The restoring function f(δ) (unit stiffness; the element's own stiffness multiplies it) and df/dδ.
``surfaces()``
    The deflections where the law switches branch (event surfaces of the accurate mode and of grazing in
    continuation): (−D, D) for the dead zone.
``counters``, ``counter(delta)``
    The names of the law's per-sample counters in a run's statistics (at most :data:`LAW_COUNTERS`) and the
    counter one sample of δ counts in: for the dead zone ``drive`` (δ > D), ``separation``, ``back``
    (δ < −D).  A kernel's statistics hold, per element, the deflection's extremes, sums and the rate's
    extremes (law independent), then the law's counters, then the sample count
    (:data:`geardyn.backend.S_LAW`); :meth:`geardyn.integrate.BatchResult.law_fractions` turns the counters
    into time fractions named by the law.

A new law is a subclass with a new ``code``, one kernel branch per backend, and nothing in the analyses.
The second law is the rolling-element bearing (:class:`RollingBearingLaw`, code 1): it acts on two element rows
of a system (a body's x and y translation relative to ground or another body), whose forces it gives jointly,
K·Σ_j max(δ_j, 0)^n (cos ψ_j, sin ψ_j) with δ_j = δ_x cos ψ_j + δ_y sin ψ_j − c over its rolling elements at
the cage angles ψ_j (θ) — a smooth law (C¹ at contact for n > 1: no switching surface).  A backend declares
the codes its kernel takes (:attr:`geardyn.backend.Backend.laws`).
"""

from __future__ import annotations

import abc
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from .errors import ModelError

__all__ = [
    "System",
    "Element",
    "Law",
    "DeadZone",
    "RollingBearingLaw",
    "LAW_COUNTERS",
    "Batch",
    "ModelList",
    "as_batch",
    "build_models",
    "state_names",
    "element_names",
    "require_periodic",
]

#: The most counters a law keeps in a run's statistics (the slots the kernels reserve per element).
LAW_COUNTERS = 3


class Law(abc.ABC):
    """The law of a non-smooth element: the force it transmits as a function of its deflection δ.

    See the module docstring.  Subclasses are frozen dataclasses with a class-level :attr:`code`,
    :attr:`name` and :attr:`counters`.
    """

    #: The kernel branch of the law (an integer in the packed arrays).
    code: ClassVar[int]
    #: The law's name, as results and messages give it.
    name: ClassVar[str]
    #: Names of its per-sample counters in a run's statistics (at most :data:`LAW_COUNTERS`).
    counters: ClassVar[tuple[str, ...]]

    @abc.abstractmethod
    def params(self) -> tuple[float, ...]:
        """The law's parameters, in the order its kernel branch reads them."""

    @abc.abstractmethod
    def force(self, delta: np.ndarray | float) -> np.ndarray:
        """The restoring function f(δ) (unit stiffness)."""

    @abc.abstractmethod
    def stiffness(self, delta: np.ndarray | float) -> np.ndarray:
        """df/dδ (away from the switching surfaces)."""

    @abc.abstractmethod
    def surfaces(self) -> tuple[float, ...]:
        """The deflections where the law switches branch."""

    @abc.abstractmethod
    def counter(self, delta: np.ndarray | float) -> np.ndarray:
        """The index into :attr:`counters` a sample of δ counts in."""


def _side(delta: np.ndarray | float, clearance: float) -> np.ndarray:
    """The counter of a sample of δ against a symmetric clearance c: 0 for δ > c, 2 for δ < −c, else 1."""
    d = np.asarray(delta, dtype=float)
    return np.where(d > clearance, 0, np.where(d < -clearance, 2, 1))


@dataclass(frozen=True)
class DeadZone(Law):
    """The dead zone (backlash, clearance) of half gap D: f(δ) = δ − clamp(δ, −D, D).

    Attributes
    ----------
    gap : float
        The half gap D (in the system's displacement unit), ≥ 0: the force is zero for |δ| ≤ D.

    Examples
    --------
    >>> law = DeadZone(1.0)
    >>> law.force([-2.0, 0.5, 3.0]).tolist()
    [-1.0, 0.0, 2.0]
    >>> law.counters, law.counter([2.0, 0.0, -2.0]).tolist()
    (('drive', 'separation', 'back'), [0, 1, 2])
    """

    gap: float

    code: ClassVar[int] = 0
    name: ClassVar[str] = "dead_zone"
    counters: ClassVar[tuple[str, ...]] = ("drive", "separation", "back")

    def params(self) -> tuple[float, ...]:
        return (float(self.gap),)

    def force(self, delta: np.ndarray | float) -> np.ndarray:
        d = np.asarray(delta, dtype=float)
        return d - np.clip(d, -self.gap, self.gap)

    def stiffness(self, delta: np.ndarray | float) -> np.ndarray:
        return (np.abs(np.asarray(delta, dtype=float)) > self.gap).astype(float)

    def surfaces(self) -> tuple[float, ...]:
        return (-float(self.gap), float(self.gap))

    def counter(self, delta: np.ndarray | float) -> np.ndarray:
        return _side(delta, self.gap)


@dataclass(frozen=True)
class RollingBearingLaw(Law):
    """The rolling-element bearing: Z elements of exponent n and radial clearance c, on two element rows (x, y).

    The force (unit load–deflection constant: the bearing's K multiplies it) on the two rows at (δ_x, δ_y) and
    cage angle ψ is ``Σ_j max(δ_j, 0)^n (cos ψ_j, sin ψ_j)``, ``δ_j = δ_x cos ψ_j + δ_y sin ψ_j − c``,
    ``ψ_j = ψ + phase + 2πj/Z`` (:func:`geardyn.systems.bearings.bearing_forces`, the shaft's restoring force);
    the cage turns at ``ratio/Z`` radians per radian of the base angle θ, so the stiffness varies at the
    ball-pass frequency ``ratio·ω``.  The law is C¹ at contact (n > 1): it has no switching surface, and the
    accurate mode splits no step at it.  Its counters classify each row's deflection against the clearance
    (``plus``: δ > c, ``free``: |δ| <= c, ``minus``: δ < −c), as the kernels' statistics count it.

    Attributes
    ----------
    elements : int
        Z, the number of rolling elements.
    exponent : float
        n (3/2 ball, 10/9 roller).
    clearance : float
        The radial clearance c (the system's displacement unit).
    ratio : float
        The ball-pass frequency over the base frequency (Z times the cage's speed over it).
    phase : float
        The cage angle at θ = 0 (rad).

    Examples
    --------
    >>> law = RollingBearingLaw(elements=4, exponent=1.5, clearance=0.5, ratio=1.0)
    >>> [round(v, 12) for v in law.force([2.5, 0.0]).tolist()]
    [2.828427124746, 0.0]
    >>> law.counters, law.counter([1.0, 0.0, -1.0]).tolist()
    (('plus', 'free', 'minus'), [0, 1, 2])
    """

    elements: int
    exponent: float
    clearance: float
    ratio: float
    phase: float = 0.0

    code: ClassVar[int] = 1
    name: ClassVar[str] = "rolling_bearing"
    counters: ClassVar[tuple[str, ...]] = ("plus", "free", "minus")

    def params(self) -> tuple[float, ...]:
        return (float(self.elements), float(self.exponent), float(self.clearance), float(self.ratio), self.phase)

    def cage_angle(self, theta: np.ndarray | float) -> np.ndarray:
        """The cage angle ψ at base angles θ (rad)."""
        return self.ratio / self.elements * np.asarray(theta, dtype=float) + self.phase

    def _bearing_args(self, delta: np.ndarray | float, theta: np.ndarray | float) -> tuple:
        """The arguments of :mod:`geardyn.systems.bearings`' functions at δ = (δ_x, δ_y) (..., 2) and θ (unit K)."""
        d = np.asarray(delta, dtype=float)
        return d[..., 0], d[..., 1], self.cage_angle(theta), self.elements, 1.0, self.exponent, self.clearance

    def force(self, delta: np.ndarray | float, theta: np.ndarray | float = 0.0) -> np.ndarray:
        """The rows' forces (..., 2) at deflections δ = (δ_x, δ_y) (..., 2) and base angle θ (unit K)."""
        from .systems.bearings import bearing_forces

        return -np.stack(bearing_forces(*self._bearing_args(delta, theta)), axis=-1)

    def stiffness(self, delta: np.ndarray | float, theta: np.ndarray | float = 0.0) -> np.ndarray:
        """The tangent stiffness (..., 2, 2) at δ = (δ_x, δ_y) (..., 2) and θ (unit K)."""
        from .systems.bearings import bearing_stiffness

        return bearing_stiffness(*self._bearing_args(delta, theta))

    def surfaces(self) -> tuple[float, ...]:
        return ()

    def counter(self, delta: np.ndarray | float) -> np.ndarray:
        return _side(delta, self.clearance)


@dataclass(frozen=True)
class Element:
    """A non-smooth element of a system: its deflection δ acted on by a :class:`Law`.

    Attributes
    ----------
    name : str
        Its name (``mesh`` for the pair; the mesh or clearance name of a system).
    gap : float
        Half gap D: the deflection where contact begins (non-dimensional); the impact states of the
        analyses compare the deflection's extremes with it.
    kind : str
        ``"mesh"``, ``"clearance"`` or ``"bearing"`` (one of a rolling bearing's two rows, x then y).
    law : Law
        The element's law; default the dead zone of half gap ``gap``.

    Examples
    --------
    >>> Element("mesh", 1.0).law
    DeadZone(gap=1.0)
    """

    name: str
    gap: float
    kind: str = "mesh"
    law: Law | None = None

    def __post_init__(self) -> None:
        if self.law is None:
            object.__setattr__(self, "law", DeadZone(float(self.gap)))


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

    def element_forces(self, tau: np.ndarray, deltas: np.ndarray) -> np.ndarray: ...

    def static_force(self) -> float: ...

    def report(
        self, res: Any = None, point: int = 0, tau: Any = None, deltas: Any = None, extrema: Any = None
    ) -> dict[str, Any]: ...

    def get(self, name: str) -> float: ...

    def with_param(self, name: str, value: float) -> System: ...

    def parameters(self) -> dict[str, float]: ...

    def contact_boundaries(self) -> tuple[Any, ...]: ...

    def to_attrs(self) -> str: ...

    @staticmethod
    def pack(systems: Iterable[Any]) -> Any: ...

    @property
    def backend(self) -> Any: ...


def build_models(base: Any, names: Sequence[str], points: np.ndarray) -> list[Any]:
    """The systems of parameter points: ``base`` with ``names[j]`` set to ``points[i, j]`` in that order.

    Parameters
    ----------
    base : System
        The system every point starts from.
    names : sequence of str
        Parameter names, one per column of ``points``.
    points : ndarray (P, len(names))
        The parameter values of each point.

    Returns
    -------
    list of System

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> [m.omega for m in build_models(GearModel(), ["omega"], [[0.5], [0.75]])]
    [0.5, 0.75]
    """
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    out = []
    for row in pts:
        m = base
        for p, v in zip(names, row):
            m = m.with_param(p, float(v))
        out.append(m)
    return out


class Batch(Sequence):
    """The points of one kind of system integrated together, as the system's backend supplies them.

    A sequence of systems (an integer index gives one system, a slice or an index array the
    :class:`Batch` of those points) that also answers what the analyses ask of a whole batch, so that
    none of them asks which kind it holds: its kernel arrays (:meth:`packed`), sampling periods, the gaps
    of its elements, the reference element's section and the steps per period.  Two implementations:
    :class:`ModelList` (any list of systems) and the pair's points packed straight from a grid
    (:class:`geardyn.pairpack.PointModels`); a backend supplies them (:meth:`geardyn.backend.Backend.points`,
    :func:`as_batch`).
    """

    @property
    @abc.abstractmethod
    def backend(self) -> Any:
        """The backend that integrates the batch."""

    @property
    @abc.abstractmethod
    def state_dim(self) -> int:
        """The state dimension d of its points."""

    @abc.abstractmethod
    def packed(self) -> Any:
        """The kernel arrays of the batch (bit for bit ``backend.pack`` of its systems)."""

    @abc.abstractmethod
    def sampling_periods(self) -> np.ndarray:
        """The sampling period T_f of every point (P,)."""

    def natural_steps(self, dtau: float) -> np.ndarray:
        """RK4 steps per sampling period N = ceil(T_f/Δτ) of every point (int64, (P,))."""
        return np.ceil(self.sampling_periods() / dtau).astype(np.int64)

    @abc.abstractmethod
    def check_step(self, options: Any) -> None:
        """Refuse a step Δτ that is not smaller than a point's sampling period (:class:`~geardyn.errors.ModelError`)."""

    @abc.abstractmethod
    def element_gaps(self) -> np.ndarray:
        """The gap of every element of every point (P, elements)."""

    @property
    def reference(self) -> int:
        """The index of the reference element (the same for every point of a batch)."""
        return int(self[0].reference)

    def reference_gaps(self) -> np.ndarray:
        """The reference element's gap of every point (P,)."""
        return self.element_gaps()[:, self.reference]

    def mean_traces(self) -> np.ndarray:
        """The mean trace of the Jacobian of every point (P,): the sum of its Lyapunov exponents."""
        return np.array([float(m.mean_trace()) for m in self])

    def reference_section(self, poincare: np.ndarray) -> np.ndarray:
        """The reference element's (δ, δ') at Poincaré points (P, n, d) of the batch: (P, n, 2)."""
        out = np.empty(poincare.shape[:2] + (2,))
        for i, m in enumerate(self):
            out[i] = m.element_series(poincare[i], 0.0)[:, m.reference, :]
        return out


class ModelList(Batch):
    """A :class:`Batch` of systems given one by one (any kind; all of one kind and structure).

    Parameters
    ----------
    models : iterable of System
        The points.

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> b = ModelList([GearModel(omega=0.5), GearModel(omega=1.0)])
    >>> len(b), b.reference_gaps().tolist()
    (2, [1.0, 1.0])
    """

    def __init__(self, models: Iterable[Any]) -> None:
        self.models = list(models)
        self._packed: Any = None

    def __len__(self) -> int:
        return len(self.models)

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, (int, np.integer)):
            return self.models[int(i)]
        return ModelList([self.models[int(k)] for k in np.arange(len(self.models))[i]])

    def __repr__(self) -> str:
        return f"ModelList({len(self)} systems)"

    @property
    def backend(self) -> Any:
        return self.models[0].backend

    @property
    def state_dim(self) -> int:
        return int(self.models[0].state_dim)

    def packed(self) -> Any:
        if self._packed is None:
            self._packed = self.backend.pack(self.models)
        return self._packed

    def sampling_periods(self) -> np.ndarray:
        return np.array([m.sampling_period for m in self.models], dtype=float)

    def check_step(self, options: Any) -> None:
        for m in self.models:
            T = m.sampling_period
            options.check_for(m.omega if T == m.period else 2.0 * math.pi / T)

    def element_gaps(self) -> np.ndarray:
        return np.array([[e.gap for e in m.elements] for m in self.models], dtype=float).reshape(len(self), -1)


def as_batch(models: Iterable[Any]) -> Batch:
    """``models`` as a :class:`Batch`: itself if it is one, else a :class:`ModelList` of its systems.

    Parameters
    ----------
    models : Batch or iterable of System
        A batch (returned as it is) or the systems to batch, in order.

    Returns
    -------
    Batch

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> as_batch([GearModel()])
    ModelList(1 systems)
    """
    return models if isinstance(models, Batch) else ModelList(models)


def state_names(model: Any, d: int) -> list[str]:
    """Names of the d state coordinates of a system (its ``state_labels``, else its DOF labels then their rates),
    else their indices.

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
    ['u', "u'"]
    """
    names = list(getattr(model, "state_labels", ()) or ())
    if len(names) == d:
        return names
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


def require_periodic(model: Any, what: str = "the periodic tools") -> int:
    """The forcing-period multiple p of a system, refusing a quasi-periodic forcing.

    Parameters
    ----------
    model : System
    what : str
        The tools named in the error message.

    Returns
    -------
    int
        p = ``model.period_multiple()``: the forcing repeats after p base periods (1 for the pair).

    Raises
    ------
    ModelError
        If the forcing frequencies are incommensurate (no common period).
    """
    p = model.period_multiple()
    if p is None:
        raise ModelError(
            f"system: {what} need a periodic forcing, but the mesh-frequency ratios are "
            f"incommensurate; use simulate or lyapunov"
        )
    return p
