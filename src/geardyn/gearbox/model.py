"""The gearbox as a :class:`~geardyn.systems.description.SystemDescription`.

Each shaft node is a body with the six DOFs ``x, y, z, rx, ry, theta`` (:data:`~geardyn.gearbox.shaft.NODE_DOFS`);
its own mass matrix (diagonal) holds the diagonal of the shaft's consistent mass matrix at the node plus the
gear mounted there (mass on x, y, z, diametral inertia on rx, ry, polar inertia on θ).  The shaft's
stiffness (and its Rayleigh damping β K) is one linear connection over all its nodes, named after the shaft,
so that the modal strain energy is reported per shaft, per bearing and per mesh.  The off-diagonal part of
the consistent mass matrix couples the nodes of a shaft; :meth:`GearboxDescription.mass_matrix` adds it to
the block-diagonal matrix of the bodies.  With ``[gearbox] gyroscopic = true`` the shafts' gyroscopic matrices
(:meth:`GearboxDescription.gyroscopic_matrix`, each shaft at its own exact speed) enter the damping of the
equations of motion at a running speed (:func:`geardyn.systems.assemble.assemble`) and the modes of a
Campbell diagram (:func:`geardyn.systems.modes.campbell`).  Everything downstream — assembly, scaling, kernels, every
analysis — sees an ordinary mesh-vector system.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from ..errors import ModelError
from ..systems.description import Body, SystemDescription
from .shaft import NODE_DOFS, Material, Section

__all__ = ["NodeBody", "ShaftModel", "GearboxDescription"]


@dataclass(frozen=True)
class NodeBody(Body):
    """A shaft node: a body with the DOFs ``x, y, z, rx, ry, theta`` and a diagonal mass matrix.

    Attributes
    ----------
    name : str
        Unique name of the node's body.
    dofs : tuple[str, ...]
        Must be ``NODE_DOFS`` (``x, y, z, rx, ry, theta``).
    mass : float | None
        Unused by a node (its ``mass_matrix`` holds the masses); as in :class:`~geardyn.systems.description.Body`.
    inertia : float | None
        Unused by a node; as in :class:`~geardyn.systems.description.Body`.
    mass_matrix : tuple[tuple[float, ...], ...]
        The 6 × 6 mass matrix over ``dofs`` (SI: kg on translations, kg·m² on rotations), finite with a positive
        diagonal; required.
    """

    def __post_init__(self) -> None:
        if tuple(self.dofs) != NODE_DOFS or self.mass_matrix is None:
            raise ModelError(f"shaft node {self.name!r}: needs the DOFs {NODE_DOFS} and a mass matrix")
        mm = np.array(self.mass_matrix, dtype=float)
        if mm.shape != (6, 6) or not np.all(np.isfinite(mm)) or np.any(np.diag(mm) <= 0):
            raise ModelError(f"shaft node {self.name!r}: mass matrix must be 6x6, finite, with a positive diagonal")
        object.__setattr__(self, "dofs", NODE_DOFS)
        object.__setattr__(self, "mass_matrix", tuple(map(tuple, mm.tolist())))


@dataclass(frozen=True, eq=False)
class ShaftModel:
    """One discretised shaft.

    Attributes
    ----------
    name : str
        Name of the shaft.
    positions : tuple[float, ...]
        Node positions along the shaft (m).
    nodes : tuple[str, ...]
        The body name of each node.
    sections : tuple[Section, ...]
        Section of each element.
    material : Material
        The shaft's material.
    M, K, G : ndarray
        Consistent mass, stiffness and gyroscopic matrices over the nodes' DOFs (SI; G per unit spin speed
        in rad/s about +z: the shaft's elements and the polar inertia of its gears).
    speed : Fraction
        Speed relative to the reference shaft (exact); default 1.
    sense : int
        Running sense: +1 counterclockwise about +z (default), −1 clockwise.
    features : tuple[tuple[str, ...], ...]
        What sits at each node (gear, bearing and coupling names).
    radii : tuple[float, ...]
        Radius of each node (m): the reference radius of its gear, else the shaft's outer radius there.
    """

    name: str
    #: Node positions along the shaft (m) and the body name of each node.
    positions: tuple[float, ...]
    nodes: tuple[str, ...]
    #: Section of each element.
    sections: tuple[Section, ...]
    material: Material
    #: Consistent mass, stiffness and gyroscopic matrices over the nodes' DOFs (SI).
    M: np.ndarray = field(repr=False)
    K: np.ndarray = field(repr=False)
    G: np.ndarray = field(repr=False)
    #: Speed relative to the reference shaft (exact) and running sense (+1 counterclockwise about +z).
    speed: Fraction = Fraction(1)
    sense: int = 1
    #: What sits at each node (gear, bearing and coupling names).
    features: tuple[tuple[str, ...], ...] = ()
    #: Radius of each node (m): the reference radius of its gear, else the shaft's outer radius there.
    radii: tuple[float, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "speed_ratio": str(self.speed),
            "sense": "counterclockwise" if self.sense > 0 else "clockwise",
            "elements": len(self.sections),
            "nodes": [
                {"name": n, "position_m": p, "radius_m": r, "features": list(f)}
                for n, p, r, f in zip(self.nodes, self.positions, self.radii, self.features)
            ],
        }


@dataclass(frozen=True)
class GearboxDescription(SystemDescription):
    """A :class:`SystemDescription` whose bodies are shaft nodes (and any rigid bodies, a motor, a load).

    Parameters
    ----------
    bodies, connections, clearances, meshes, loads, rolling_bearings : tuples of the element classes
        The elements, as in :class:`~geardyn.systems.description.SystemDescription`.
    reference, characteristic_length, rpm, omega, equivalent_mass, title, source, assumptions
        As in :class:`~geardyn.systems.description.SystemDescription`.
    shafts : tuple[ShaftModel, ...]
        The discretised shafts (their consistent mass matrices' off-diagonal parts enter :meth:`mass_matrix`).
    kinematics : dict[str, Any]
        Exact kinematics: shaft speeds, mesh ratios (as strings of fractions) and the forcing period.
    element_kinds : dict[str, str]
        The kind of each named element: ``"shaft"``, ``"bearing"``, ``"coupling"`` or ``"mesh"``.
    gyroscopic : bool
        Whether the shafts' gyroscopic terms enter (``[gearbox] gyroscopic``); default False.
    """

    shafts: tuple[ShaftModel, ...] = field(default=(), compare=False)
    #: Exact kinematics: shaft speeds, mesh ratios (as strings of fractions) and the forcing period.
    kinematics: dict[str, Any] = field(default_factory=dict, compare=False)
    #: The kind of each named element: ``"shaft"``, ``"bearing"``, ``"coupling"`` or ``"mesh"``.
    element_kinds: dict[str, str] = field(default_factory=dict, compare=False)
    #: Whether the shafts' gyroscopic terms enter (``[gearbox] gyroscopic``).
    gyroscopic: bool = field(default=False, compare=False)

    def _over_shafts(self, M: np.ndarray, part) -> np.ndarray:
        """``M`` plus ``part(s)`` of every shaft s scattered onto its nodes' DOFs."""
        idx = self.index()
        for s in self.shafts:
            ii = [idx[(n, d)] for n in s.nodes for d in NODE_DOFS]
            M[np.ix_(ii, ii)] += part(s)
        return M

    def mass_matrix(self) -> np.ndarray:
        """M (SI): the bodies' blocks plus the off-diagonal part of each shaft's consistent mass matrix."""
        return self._over_shafts(super().mass_matrix(), lambda s: s.M - np.diag(np.diag(s.M)))

    def gyroscopic_matrix(self) -> np.ndarray | None:
        """Σ_s σ_s n_s G_s (SI) over the system's DOFs, or None when the gyroscopic terms are off.

        Shaft s turns at n_s times the reference shaft's speed (exact, from the teeth) in the sense σ_s = ±1
        about +z, so at the reference shaft's speed Ω (rad/s, in its running sense) the equations of motion are
        ``M q'' + (C + Ω G) q' + K q = f`` with this G (skew-symmetric).
        """
        if not self.gyroscopic:
            return None
        return self._over_shafts(np.zeros((self.n, self.n)), lambda s: (s.sense * float(s.speed)) * s.G)

    def gearbox_summary(self) -> dict[str, Any]:
        """The shafts (nodes, positions, speeds) and the exact kinematics, for reports."""
        return {"shafts": [s.to_dict() for s in self.shafts], "kinematics": dict(self.kinematics)}
