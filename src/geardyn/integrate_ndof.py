"""Former door of the mesh-vector systems, kept only for the imports of :mod:`geardyn.analysis.hb.system`.

Every system now goes through :mod:`geardyn.integrate` (:func:`~geardyn.integrate.integrate_batch`,
:func:`~geardyn.integrate.trajectory`, :func:`~geardyn.integrate.period_map`), which hands it to its backend.
"""

from __future__ import annotations

from .integrate import trajectory

__all__ = ["trajectory"]
