"""Event location on a branch: the Illinois (modified regula falsi) secant on a chord.

Both continuation methods (shooting, :mod:`geardyn.analysis.periodic.arclength`, and harmonic
balance, :mod:`geardyn.analysis.hb.continuation`) locate a zero of a test function between two
branch points a and b in the same way: along the chord s ∈ [0, 1] from a to b, a secant step whose
trial point is corrected onto the branch; when the same end is kept twice its function value is
halved (the Illinois modification), so the bracket shrinks from both sides.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["illinois_on_chord"]


def illinois_on_chord(
    f_a: float,
    f_b: float,
    trial: Callable[[float, float, float], tuple[float, Any, float] | None],
    best: Any,
    tol: float,
    max_iter: int,
    *,
    length: float = 1.0,
) -> tuple[Any, bool]:
    """A zero of a test function along the chord [a, b], by the Illinois secant method.

    Parameters
    ----------
    f_a, f_b : float
        The test function at the chord's ends (of opposite signs).
    trial : callable
        ``trial(s, lo, hi)`` corrects the point at chord parameter ``s`` (inside the bracket
        ``[lo, hi]``) onto the branch and returns ``(s_used, point, f)`` — ``s_used`` the chord
        parameter actually used (a fallback may move it) and ``f`` the test function there — or
        ``None`` when no point can be had (the search stops, unlocated).
    best : object
        The point returned if the search ends before any trial (the end nearer the zero).
    tol : float
        Stop when the bracket, times ``length``, is at most ``tol``.
    max_iter : int
        Largest number of trials.
    length : float
        Length of the chord (1 for a tolerance relative to it).

    Returns
    -------
    point : object
        The last trial point (or ``best``).
    located : bool
        Whether the bracket shrank below ``tol`` (within 10³ × ``tol`` after ``max_iter`` trials)
        or the test function vanished.

    References
    ----------
    M. Dowell and P. Jarratt, "A modified regula falsi method for computing the root of an
    equation", *BIT* 11 (1971) 168–174.
    """
    lo, hi, flo, fhi = 0.0, 1.0, f_a, f_b
    side = 0
    for _ in range(max_iter):
        if (hi - lo) * length <= tol:
            return best, True
        s = (lo * fhi - hi * flo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
        if not (lo < s < hi):
            s = 0.5 * (lo + hi)
        got = trial(s, lo, hi)
        if got is None:
            return best, False
        s, pt, f = got
        best = pt
        if f == 0.0:
            return pt, True
        if (f > 0) == (flo > 0):
            lo, flo = s, f
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = s, f
            if side == 1:
                flo *= 0.5
            side = 1
    return best, (hi - lo) * length <= 1e3 * tol
