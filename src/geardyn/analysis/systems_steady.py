"""Names kept for the imports of :mod:`geardyn.analysis.hb.system`; the steady response of every System is
:func:`geardyn.analysis.steady.simulate`, its per-mesh entries :func:`geardyn.systems.report.report`."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..integrate import start_state
from ..systems.elements import rigid_modes
from ..systems.report import static_mesh_forces

__all__ = ["rigid_modes", "static_mesh_forces", "system_state0"]


def system_state0(model: Any, state0: Sequence[float] | None) -> np.ndarray:
    """A full initial state, :func:`geardyn.integrate.start_state`.

    Parameters
    ----------
    model : System
    state0 : None, (u0, v0) or (d,)

    Returns
    -------
    ndarray (d,)
    """
    return start_state(model, state0)
