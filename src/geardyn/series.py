"""Fourier series of the mesh coefficients at many angles, written once.

A model's coefficients are ``c[i, j, (a, b)]``: series i is ``x_i(θ) = Σ_j a_ij cos jθ + b_ij sin jθ`` (the pair's
C(θ) = 2ξ(θ), K(θ), F(θ) from :meth:`geardyn.model.GearModel.coefficients`; a system mesh's, with θ scaled by its
ratio).  :func:`series_values` evaluates chosen series and, if asked, their derivatives d/dθ at the angles of a
history, in blocks of samples so that the work stays in cache whatever the history's length (a one-revolution
excitation has hundreds of harmonics and a record hundreds of thousands of samples: the full table of cos jθ would
take gigabytes).  Each harmonic's cos and sin are computed once and the terms are summed in order of j, so a
value does not depend on the block it falls in.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["series_values", "BLOCK"]

#: Samples evaluated together (a block's cos and sin rows stay in the core's cache).
BLOCK = 4096


def series_values(
    c: np.ndarray, theta: np.ndarray | float, rows: Sequence[int], *, ratio: float = 1.0, derivative: bool = False
) -> tuple[np.ndarray, ...]:
    """Series ``rows`` of the coefficients ``c`` at angles ``ratio·θ``, then (if ``derivative``) their d/dθ.

    Parameters
    ----------
    c : ndarray (S, J, 2)
        Coefficients: ``c[i, j] = (a_ij, b_ij)``.
    theta : ndarray or float
        Angles θ (any shape).
    rows : sequence of int
        Which series i to evaluate.
    ratio : float
        Harmonic j is at the angle ``(j·ratio)·θ`` (a system mesh's speed ratio to the forcing angle).
    derivative : bool
        Also return ``dx_i/dθ = Σ_j (j·ratio)(b_ij cos − a_ij sin)``.

    Returns
    -------
    tuple of ndarray
        ``x_i(θ)`` for each i of ``rows`` (the shape of ``theta``), then, with ``derivative``, each ``dx_i/dθ``.
    """
    c = np.asarray(c, dtype=float)
    th = np.asarray(theta, dtype=float)
    flat = th.reshape(-1)
    rows = list(rows)
    val = np.empty((len(rows), flat.size))
    der = np.empty((len(rows), flat.size)) if derivative else None
    for a in range(0, flat.size, BLOCK):
        t = flat[a : a + BLOCK]
        x = [np.full_like(t, c[i, 0, 0]) for i in rows]
        dx = [np.zeros_like(t) for _ in rows] if derivative else []
        for j in range(1, c.shape[1]):
            jr = j * ratio
            ph = jr * t
            cs, sn = np.cos(ph), np.sin(ph)
            for k, i in enumerate(rows):
                x[k] = x[k] + c[i, j, 0] * cs + c[i, j, 1] * sn
                if derivative:
                    dx[k] = dx[k] + jr * (c[i, j, 1] * cs - c[i, j, 0] * sn)
        val[:, a : a + BLOCK] = x
        if derivative:
            der[:, a : a + BLOCK] = dx
    out = [v.reshape(th.shape) for v in val]
    if derivative:
        out += [d.reshape(th.shape) for d in der]
    return tuple(out)
