"""Whether harmonic balance can decide the stability of a system's solutions: its damping and its free modes.

By Liouville's formula the Floquet multipliers of a period T multiply to exp(T·mean trace of the Jacobian), the mean
trace being −Σ damping.  Without damping (a *conservative* system, :func:`require_decidable`) they lie on the unit
circle or in pairs μ, 1/μ off it: |μ| < 1 reads rounding, and |μ_i μ_j| − 1 of a pair on the circle is zero up to
rounding, so no Neimark–Sacker test can be made.  What works on the circle are det(I − M) (a multiplier through +1:
the fold) and det(I + M) (through −1: the period doubling, as at the boundaries of a Mathieu tongue); a point is then
*neutrally* stable when every |μ| <= 1 + :data:`~geardyn.analysis.hb.continuation.NEUTRAL_TOL`.  Harmonic balance
cannot decide at all only where a coordinate moves freely and the gauge of :mod:`.equations` cannot fix it: a
direction of zero mean stiffness that is not a free rigid-body mode (a damping or a load acts along it) leaves the
harmonic-0 equations singular — with a load the motion drifts and has no periodic solution, without one every shift
along it is another solution.  A damped system can still have elastic modes that no damper moves (C̄φ = 0);
:func:`undamped_modes` names them for a warning.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.linalg import eigh

from ...errors import ModelError
from .form import mean

__all__ = ["require_decidable", "undamped_modes"]

#: Relative size below which a damping or an eigenvalue counts as zero.
RTOL = 1e-9


def _modes(form: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eigenvalues λ and modes φ of K̄φ = λM̃φ of a form's mean linear system (every element in contact at its mean
    stiffness), and its mean damping C̄."""
    Mt = np.linalg.inv(form.Mi)
    K, C = Mt @ form.A, Mt @ form.B
    for e in form.elements:
        vv = np.outer(e.V, e.V)
        K, C = K + mean(e.K) * vv, C + mean(e.C) * vv
    lam, phi = eigh(0.5 * (K + K.T), 0.5 * (Mt + Mt.T))
    return lam, phi, 0.5 * (C + C.T)


def require_decidable(
    model: Any, param: str | None = None, start: float | None = None, stop: float | None = None
) -> bool:
    """Whether the system is conservative (no damping at either end of the range), refusing one whose stability
    harmonic balance cannot decide.

    Parameters
    ----------
    model : System
    param : str, optional
        The continued parameter; with ``start`` and ``stop`` the system counts as conservative only when it has
        no damping at either end (a damping continued through zero keeps the damped tests).
    start, stop : float, optional

    Returns
    -------
    bool
        True for a conservative system.

    Raises
    ------
    ModelError
        One line naming the free direction, when the mean stiffness has a zero direction that is not a free
        rigid-body mode.
    """
    ends = [model] if param is None else [model.with_param(param, v) for v in (start, stop)]
    form = model.hb_form()
    lam, phi, _C = _modes(form)
    zero = np.abs(lam) <= RTOL * max(1.0, float(np.max(np.abs(lam))))
    if int(np.count_nonzero(zero)) > form.rigid.shape[1]:
        v = phi[:, np.argmax(zero)]
        v /= np.linalg.norm(v)
        Mt = np.linalg.inv(form.Mi)
        load = float(np.real(Mt @ form.G0[:, (form.G0.shape[1] - 1) // 2]) @ v)
        damp = float(np.linalg.norm(Mt @ form.B @ v))
        why = f"a load along it (F·φ = {load:.3g})" if abs(load) > 0 else f"a damping along it (|C̃φ| = {damp:.3g})"
        raise ModelError(
            f"system: the coordinate {form.labels[int(np.argmax(np.abs(v)))]} moves freely (zero mean stiffness) "
            f"but with {why}, so it is not a rigid-body mode the gauge can fix: its mean drifts or is undetermined "
            f"and harmonic balance has no isolated periodic solution; support it (a bearing stiffness) or balance "
            f"its load"
        )
    return all(float(m.mean_trace()) == 0.0 for m in ends)


def undamped_modes(model: Any) -> list[float]:
    """Natural frequencies (Hz; non-dimensional ω for a model without physical scales) of the elastic modes of a
    system's mean linear system that no damping acts on.

    Parameters
    ----------
    model : System

    Returns
    -------
    list of float
        One frequency per undamped mode (a degenerate frequency once per mode), ascending; empty when every
        elastic mode is damped.
    """
    form = model.hb_form()
    lam, phi, C = _modes(form)
    scale = max(float(np.max(np.abs(lam))), 1e-300)
    ctol = RTOL * max(float(np.max(np.abs(C))), 1e-300)
    hz = form.hz if math.isfinite(form.hz) else 1.0
    out, i = [], 0
    while i < lam.size:
        j = i + 1
        while j < lam.size and lam[j] - lam[i] <= RTOL * scale:
            j += 1
        if lam[i] > RTOL * scale:  # elastic (the rigid-body modes are left out of the stability test)
            E = np.linalg.qr(phi[:, i:j])[0]
            d = np.linalg.eigvalsh(E.T @ C @ E)
            out.extend([math.sqrt(lam[i]) * hz] * int(np.count_nonzero(d <= ctol)))
        i = j
    return out
