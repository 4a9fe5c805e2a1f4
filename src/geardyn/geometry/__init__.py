"""Spiral bevel gear pair geometry and the dimensional → non-dimensional conversion.

:class:`SpiralBevelGearPair` holds the physical description of a spiral bevel pair in SI units
(metres, radians, kilograms, newtons, seconds).  From it follow

* the pitch cone angles ``tan δ1 = sin Σ / (z2/z1 + cos Σ)``, ``δ2 = Σ − δ1``;
* the mesh-point position vectors ``r_l``, the rotation axes ``j_l`` and the common flank normal
  ``n`` at the mesh point, in a frame with its origin at the intersection of the axes
  (:meth:`SpiralBevelGearPair.mesh_vectors`);
* the directional radii ``R_l = n · (j_l × r_l)`` computed from those vectors;
* the equivalent mass ``m_e = I1 I2 / (I2 R1² + I1 R2²)`` and the static mesh force
  ``F_p = (I2 R1 T1 + I1 R2 T2) / (I2 R1² + I1 R2²)``;
* the mean mesh stiffness ``k0`` (given, or face width × c_γ) and ``ω_n = √(k0/m_e)``;
* a non-dimensional :class:`~geardyn.model.GearModel` at an operating point
  (:meth:`SpiralBevelGearPair.gear_model`) and the scales that convert back to physical units
  (:class:`PhysicalScales`, :meth:`SpiralBevelGearPair.scales`).

The derivation and every assumption are in ``docs/model.md``.

Modules
-------
``inputs``
    Defaults and their sources, input validation, :class:`Assumption`, :class:`ResolvedInputs`.
``vectors``
    :class:`MeshVectors` and :func:`mesh_vectors` (the directional radii come from them).
``harmonics``
    :class:`MeshHarmonics`.
``bevel``
    :class:`SpiralBevelGearPair`.
``scales``
    :class:`PhysicalScales`, every conversion between physical and non-dimensional values.
``summary``
    :func:`geometry_summary` and :func:`summary_rows`.

Coordinate frame
----------------
Origin at the intersection of the shaft axes (the common cone apex).  The pinion axis ``a1`` is
``+y``; the gear axis ``a2 = (sin Σ, cos Σ, 0)`` lies in the x–y plane (``+x`` for Σ = 90°), both
pointing from the apex towards the back of the gear.  The pitch cones touch along the generatrix
``g = (sin δ1, cos δ1, 0)``; the mesh point lies on it.  ``+z`` is normal to the plane of the axes.
The rotation axes ``j_l = ±a_l`` are oriented so that positive ``θ_l`` is the running direction
(both pitch points move the same way at the mesh), so that ``u_n = R1 θ1 − R2 θ2 − e_n`` is the
compression of the mesh.  ``n`` is the common normal of the loaded flanks at the mesh point,
pointing from the pinion flank into the gear flank (the direction of the force on the gear);
``n1 = n2 = n``.
"""

from __future__ import annotations

from . import bevel, harmonics, inputs, scales, summary, vectors
from .bevel import *  # noqa: F403  (each module's __all__ is the list of what it makes public)
from .harmonics import *  # noqa: F403
from .inputs import *  # noqa: F403
from .scales import *  # noqa: F403
from .summary import *  # noqa: F403
from .vectors import *  # noqa: F403

__all__ = sorted(
    {*bevel.__all__, *harmonics.__all__, *inputs.__all__, *scales.__all__, *summary.__all__, *vectors.__all__}
)
