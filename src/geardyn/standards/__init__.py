"""Gear rating standards as geardyn uses them: mesh data from the geometry of the gear pair.

* :mod:`~geardyn.standards.iso10300` — bevel and hypoid pairs (ISO 10300-1 virtual cylindrical
  gears, contact ratios, mesh stiffness, resonance speed, K_v by Method B);
* :mod:`~geardyn.standards.iso6336` — cylindrical pairs (ISO 6336-1) and the relations both share;
* :mod:`~geardyn.standards.stiffness` — stiffness harmonics κ_r implied by the contact ratios.
"""

from ._common import AssumedInput
from .iso6336 import CylindricalMesh, cylindrical_mesh, dynamic_factor_method_b, method_b_coefficients
from .iso10300 import BevelMesh, bevel_mesh
from .stiffness import StiffnessHarmonics, mesh_stiffness_harmonics, mesh_stiffness_waveform

__all__ = [
    "AssumedInput",
    "BevelMesh",
    "CylindricalMesh",
    "StiffnessHarmonics",
    "bevel_mesh",
    "cylindrical_mesh",
    "dynamic_factor_method_b",
    "mesh_stiffness_harmonics",
    "mesh_stiffness_waveform",
    "method_b_coefficients",
]
