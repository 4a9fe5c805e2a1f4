"""What a result of a system cannot show, said in its output: a system with no excitation."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["excitation_note"]


def excitation_note(system: Any, state0: tuple[float, float] = (0.0, 0.0)) -> str | None:
    """A note when the system has no excitation and starts from rest, so its response is identically zero.

    With no mean load (``F``), no transmission error (every mesh's ``eps``) and the initial state at rest,
    q = 0 solves the equations of motion (stiffness and damping variations multiply the deflections, which
    stay 0): such a file (the planetary example, Lin & Parker's free-vibration system) is for the modes.

    Parameters
    ----------
    system : SystemModel
        The system.
    state0 : (float, float)
        The initial state given on the command line (``--u0``, ``--v0``).

    Returns
    -------
    str or None
        The note, or ``None`` when something excites the system.
    """
    if any(float(x) != 0.0 for x in state0) or np.any(np.asarray(system.F) != 0.0):
        return None
    if any(any(float(e) != 0.0 for e in m.eps) for m in system.meshes):
        return None
    return (
        "the system has no excitation (no load, no transmission error) and starts from rest: its response is "
        "zero; it is meant for the linear modes (geardyn modes), or give loads or STE in its file"
    )
