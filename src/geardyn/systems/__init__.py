"""Multi-DOF gear systems: bodies, bearings, couplings and meshes; their non-dimensional form and modes.

* :mod:`~geardyn.systems.description` — the physical description (SI): :class:`Body`,
  :class:`Connection`, :class:`Clearance`, :class:`Mesh`, :class:`Load`, :class:`SystemDescription`.
* :mod:`~geardyn.systems.files` — system files in TOML with units (:func:`load_description`,
  :func:`load_system`).
* :mod:`~geardyn.systems.assemble` — :func:`assemble` → :class:`SystemModel`, the frozen
  non-dimensional system (the :class:`geardyn.system.System` protocol) and its kernel arrays
  (the contract is in that module's docstring).
* :mod:`~geardyn.systems.modes` — natural frequencies, mode shapes, modal strain-energy fractions and
  Campbell diagrams (:func:`modal_analysis`, :func:`campbell`, :func:`modes_report`).
"""

from .assemble import MeshND, SystemArrays, SystemModel, assemble
from .description import DOFS, Body, Clearance, Connection, Load, Mesh, SystemDescription
from .files import load_description, load_system
from .modes import ModalResult, campbell, modal_analysis, modes_report
from .vectors import bevel_mesh_vector, cylindrical_mesh_vector

__all__ = sorted(
    [
        "DOFS",
        "Body",
        "Clearance",
        "Connection",
        "Load",
        "Mesh",
        "SystemDescription",
        "MeshND",
        "SystemArrays",
        "SystemModel",
        "assemble",
        "load_description",
        "load_system",
        "ModalResult",
        "campbell",
        "modal_analysis",
        "modes_report",
        "bevel_mesh_vector",
        "cylindrical_mesh_vector",
    ]
)
