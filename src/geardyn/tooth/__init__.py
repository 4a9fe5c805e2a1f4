"""Tooth-pair stiffness from the gear geometry by the potential-energy method, tooth faults, the
static transmission error, and the mesh excitation they imply (``docs/excitation.md``).

:mod:`.geometry` (involute-and-fillet tooth, the pair's line of action), :mod:`.energy` (Hertzian,
bending, shear, axial and fillet-foundation compliances), :mod:`.faults` (cracks, spalls, wear, broken
teeth, profile modifications), :mod:`.mesh` (load sharing and STE over a mesh cycle or the hunting
period), :mod:`.excitation` (the tables as the model's Fourier inputs), :mod:`.table` (excitation files),
:mod:`.result` (Dataset).
"""

from .excitation import Excitation, excitation_model, fourier_series, pair_model, series_table
from .faults import Broken, Crack, Modifications, Spall, Wear, fault_from_dict
from .geometry import PairGeometry, pair_geometry
from .mesh import MeshStiffness, mesh_stiffness, share_load
from .table import apply_excitation, read_table, table_of, write_table

__all__ = [
    "Broken",
    "Crack",
    "Excitation",
    "MeshStiffness",
    "Modifications",
    "PairGeometry",
    "Spall",
    "Wear",
    "excitation_model",
    "fault_from_dict",
    "fourier_series",
    "mesh_stiffness",
    "pair_geometry",
    "pair_model",
    "apply_excitation",
    "read_table",
    "series_table",
    "share_load",
    "table_of",
    "write_table",
]
