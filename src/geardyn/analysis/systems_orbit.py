"""Names kept for the imports of :mod:`geardyn.analysis.hb.system`; shooting and Floquet multipliers of every
System are :func:`geardyn.analysis.periodic.shoot`."""

from __future__ import annotations

from .periodic.orbit import elastic_multipliers, require_periodic

__all__ = ["require_periodic", "elastic_multipliers"]
