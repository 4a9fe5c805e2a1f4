"""Whether harmonic balance can decide stability on a model: its damping.

By Liouville's formula the Floquet multipliers of a period T multiply to exp(T·mean trace of the Jacobian), the
mean trace being −Σ damping (:meth:`~geardyn.system.System.mean_trace`; −2ξ0 for the 1-DOF pair).  Without
damping their product is 1: a multiplier outside the unit circle, or all of them on it.  No solution is then
asymptotically stable, the stability test |μ| < 1 only reads rounding, and every pair grazing the circle is
reported as a Neimark–Sacker point: a branch of an undamped system (the planetary example, undamped and unforced)
costs hours and says nothing.  :func:`require_damping` refuses such a model in one line.

A system can also be damped as a whole and still have elastic modes of its mean linear system that no damper
moves (C̄φ = 0 for a mode φ of K̄φ = λM̃φ: then e^{i√λ τ}φ solves the damped linear system too, and conversely an
undamped solution dissipates nothing, so C̄φ = 0).  Their multipliers stay on the unit circle;
:func:`undamped_modes` names them for a warning.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...errors import ModelError

__all__ = ["require_damping", "undamped_modes"]

#: Relative size below which a damping or an eigenvalue gap counts as zero.
RTOL = 1e-9


def _undamped(model: Any) -> bool:
    return float(model.mean_trace()) == 0.0


def require_damping(
    model: Any, param: str | None = None, start: float | None = None, stop: float | None = None
) -> None:
    """Refuse a model without damping (at both ends of the parameter range, when one is given).

    Parameters
    ----------
    model : System
    param : str, optional
        The continued parameter; with ``start`` and ``stop`` the model is refused only when it has no damping at
        either end (a damping continued through zero is allowed).
    start, stop : float, optional

    Raises
    ------
    ModelError
        One line: the model has no damping, so no stability can be decided.
    """
    ends = [model] if param is None else [model.with_param(param, v) for v in (start, stop)]
    if not all(_undamped(m) for m in ends):
        return
    if hasattr(model, "meshes"):
        what = (
            "the system has no damping (every mesh's xi0 and every connection's damping are 0)",
            "give the meshes xi0 > 0 or damping to the connections",
        )
    else:
        what = ("the model has no damping (xi0 = 0)", "give --xi0 > 0")
    raise ModelError(
        f"{what[0]}: every Floquet multiplier then lies on or outside the unit circle (Liouville), "
        f"so harmonic balance can decide no stability and would report every pair grazing the circle "
        f"as a bifurcation; {what[1]}"
    )


def undamped_modes(model: Any) -> list[float]:
    """Natural frequencies (Hz) of the elastic modes of a system's mean linear system that no damping acts on.

    Parameters
    ----------
    model : System
        (A 1-DOF model has one mode, damped unless ξ0 = 0: see :func:`require_damping`.)

    Returns
    -------
    list of float
        One frequency per undamped mode (a degenerate frequency once per mode), ascending; empty when every
        elastic mode is damped or the model is not a system.
    """
    if not hasattr(model, "meshes"):
        return []
    from scipy.linalg import eigh

    Mt = np.linalg.inv(np.asarray(model.Mi))
    Mt = 0.5 * (Mt + Mt.T)
    K = np.array(model.Kb, dtype=float)
    C = np.array(model.Cb, dtype=float)
    for i, m in enumerate(model.meshes):
        K += m.k * np.outer(model.V[i], model.V[i])
        C += 2.0 * m.xi0 * np.outer(model.V[i], model.V[i])
    for i, (k, c) in enumerate(zip(model.kc, model.cc)):
        K += k * np.outer(model.Vc[i], model.Vc[i])
        C += c * np.outer(model.Vc[i], model.Vc[i])
    lam, phi = eigh(K, Mt)
    scale = max(float(np.max(np.abs(lam))), 1e-300)
    ctol = RTOL * max(float(np.max(np.abs(C))), 1e-300)
    out: list[float] = []
    i = 0
    while i < lam.size:
        j = i + 1
        while j < lam.size and lam[j] - lam[i] <= RTOL * scale:
            j += 1
        if lam[i] > RTOL * scale:  # elastic (the rigid-body modes are left out of the stability test)
            E = phi[:, i:j]
            E = np.linalg.qr(E)[0]
            d = np.linalg.eigvalsh(E.T @ C @ E)
            f = math.sqrt(lam[i]) * model.scaling.omega_n_rad_s / (2.0 * math.pi)
            out.extend([f] * int(np.count_nonzero(d <= ctol)))
        i = j
    return out
