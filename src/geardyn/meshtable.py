"""A mesh excitation evaluated as given: a piecewise-linear table of the mesh phase, with jumps.

A :class:`~geardyn.model.GearModel` with ``evaluation = "table"`` carries ``table = (phase, k, e)``:
node phases in mesh cycles, non-decreasing over [0, P) (P = the model's ``cycles``), the relative
stiffness k/k0 and the STE e/b_c at each node.  Between two nodes the functions are linear; a phase
given twice is a jump (the first row its left value, the second its right value); after the last
node the functions run linearly back to the first node's values one period later.  In the kernel's
forcing phase θ = 2π·phase/P (docs/excitation.md, section 3)::

    K(θ) = k_j⁺ + s_j (θ − θ_j),   e(θ) = e_j⁺ + σ_j (θ − θ_j)   on θ_j ≤ θ < θ_{j+1}

The equation carries the STE through its second derivative (F = f_p − e''(τ)), so a piecewise-linear
e acts at the nodes only: crossing θ_j changes u' by −(ω/P)(σ_j − σ_{j−1}) and a jump of e changes u
by −(e_j⁺ − e_j⁻) (the dynamic transmission error u + e is continuous).

This module validates the nodes and builds the kernel's arrays; it imports NumPy only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .errors import ModelError

__all__ = ["EVALUATIONS", "TABLE_COLUMNS", "check_table", "kernel_table", "node_values", "segments", "table_values"]

#: How a model's mesh stiffness and STE are evaluated: its Fourier series, or its table as given.
EVALUATIONS = ("series", "table")
#: Columns of a row of :func:`kernel_table`: θ_j, k_j⁻, k_j⁺, e_j⁻, e_j⁺, s_j, σ_j.
TABLE_COLUMNS = 7


def _floats(name: str, values: Any) -> tuple[float, ...]:
    a = np.asarray(values, dtype=float).ravel()
    if not np.all(np.isfinite(a)):
        raise ModelError(f"table: {name} must be finite numbers")
    return tuple(float(x) for x in a)


def check_table(table: Sequence[Any], cycles: int) -> tuple[tuple[float, ...], ...]:
    """The validated ``(phase, k, e)`` of a model's table (``e`` may be empty: no STE).

    Parameters
    ----------
    table : (phase, k, e)
        Node phases (mesh cycles), relative stiffness k/k0 and STE e/b_c per node.
    cycles : int
        P: the phases lie in [0, P).

    Returns
    -------
    tuple of three tuples of float

    Raises
    ------
    ModelError
        For unequal lengths, fewer than two distinct phases, phases decreasing, outside [0, P) or given
        more than twice, or a stiffness <= 0.
    """
    try:
        phase, k, e = table
    except (TypeError, ValueError):
        raise ModelError("table: expected (phase, k, e): node phases in mesh cycles, k/k0 and e/b_c") from None
    phase, k, e = _floats("phase", phase), _floats("k", k), _floats("e", e)
    n = len(phase)
    if len(k) != n or len(e) not in (0, n):
        raise ModelError(f"table: {n} phases, {len(k)} stiffness and {len(e)} STE values; give one of each per node")
    p = np.asarray(phase)
    d = np.diff(p)
    if n < 2 or np.any(d < 0) or p[0] < 0 or p[-1] >= cycles:
        raise ModelError(f"table: the node phases must be non-decreasing in [0, {cycles}) mesh cycles (at least 2)")
    if np.any((d[:-1] == 0) & (d[1:] == 0)) or np.unique(p).size < 2:
        raise ModelError(
            "table: a phase is given at most twice (a jump: left value, then right value), and at "
            "least two phases are distinct"
        )
    if min(k) <= 0:
        raise ModelError("table: the stiffness must be > 0 at every node")
    return phase, k, e


def node_values(phase: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distinct node phases and each one's left and right value (equal where there is no jump).

    Parameters
    ----------
    phase : ndarray (n,)
        Non-decreasing phases in [0, period), each at most twice.
    values : ndarray (n,)
        The value at each row.

    Returns
    -------
    (x, left, right) : ndarray (m,)
    """
    phase = np.asarray(phase, dtype=float)
    values = np.asarray(values, dtype=float)
    first = np.r_[True, np.diff(phase) > 0]
    last = np.r_[np.diff(phase) > 0, True]
    return phase[first], values[first], values[last]


def segments(x: np.ndarray, left: np.ndarray, right: np.ndarray, period: float) -> np.ndarray:
    """The slope of each segment x_j → x_{j+1} (the last one wraps to x_0 + period).

    Parameters
    ----------
    x : ndarray (m,)
        Distinct node positions, increasing within one period.
    left, right : ndarray (m,)
        Each node's left and right value (:func:`node_values`).
    period : float
        The period of the position.

    Returns
    -------
    ndarray (m,)
        (left_{j+1} − right_j)/(x_{j+1} − x_j).
    """
    x1 = np.r_[x[1:], x[0] + period]
    l1 = np.r_[left[1:], left[0]]
    return (l1 - right) / (x1 - x)


def kernel_table(table: Sequence[Any], cycles: int) -> np.ndarray:
    """The accurate kernel's rows of a table: one per distinct phase, then the first again one period on.

    Parameters
    ----------
    table : (phase, k, e)
        As :func:`check_table` returns it.
    cycles : int
        P, the mesh cycles of the forcing period.

    Returns
    -------
    ndarray (m + 1, TABLE_COLUMNS)
        The breakpoints only (a node where neither k nor e jumps or changes slope is dropped, the
        first node kept), so a sub-step ends only where the right-hand side is not smooth.  Row j:
        θ_j = 2π·phase_j/P, k_j⁻, k_j⁺, e_j⁻, e_j⁺ and the slopes s_j, σ_j (per radian of θ) of the
        segment from θ_j; row m repeats row 0 with θ_0 + 2π.
    """
    phase, k, e = (np.asarray(c, dtype=float) for c in table)
    if e.size == 0:
        e = np.zeros_like(k)
    theta = math.tau * phase / cycles
    x, kl, kr = node_values(theta, k)
    _, el, er = node_values(theta, e)
    keep = np.arange(x.size) == 0  # the breakpoints: a jump or a kink of k or e (and the first node)
    for lv, rv in ((kl, kr), (el, er)):
        tol = 1e-13 * max(float(np.max(np.abs(rv))), float(np.max(np.abs(lv))), 1e-300)
        sl = segments(x, lv, rv, math.tau)
        kink = np.abs(sl - np.roll(sl, 1)) > 1e-12 * (np.abs(sl) + np.abs(np.roll(sl, 1))) + tol
        keep |= (np.abs(rv - lv) > tol) | kink
    x, kl, kr, el, er = (v[keep] for v in (x, kl, kr, el, er))
    rows = np.column_stack([x, kl, kr, el, er, segments(x, kl, kr, math.tau), segments(x, el, er, math.tau)])
    wrap = rows[:1].copy()
    wrap[0, 0] += math.tau
    return np.ascontiguousarray(np.vstack([rows, wrap]))


def table_values(table: Sequence[Any], cycles: int, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """K(θ) = k/k0 and e(θ) = e/b_c of a table at the forcing phases θ (right-continuous at a jump).

    Parameters
    ----------
    table : (phase, k, e)
        As :func:`check_table` returns it.
    cycles : int
        P, the mesh cycles of the forcing period.
    theta : ndarray
        Forcing phases θ = (ω/P) τ (any real values; the table is periodic in 2π).

    Returns
    -------
    (K, e) : ndarray
    """
    rows = kernel_table(table, cycles)
    x = np.mod(np.asarray(theta, dtype=float), math.tau)
    j = np.searchsorted(rows[:-1, 0], x, side="right") - 1  # −1: before the first node, the wrap segment
    base = np.where(j < 0, rows[-2, 0] - math.tau, rows[j, 0])
    r = rows[:-1][j]  # j = −1: the last node
    return r[..., 2] + r[..., 5] * (x - base), r[..., 4] + r[..., 6] * (x - base)
