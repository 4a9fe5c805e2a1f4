"""Classification of a steady response: period of the Poincaré sequence and impact state.

Names follow DESIGN §1.3.  Contact states: drive-side contact u > D, separation |u| <= D,
back-side contact u < −D.  Impact state of a steady response: *no impact* (always in drive-side
contact), *single-sided impact* (separation occurs, the back side is never touched),
*double-sided impact* (back-side contact occurs).
"""

from __future__ import annotations

import numpy as np

#: Largest period n (in forcing periods) that :func:`detect_period` reports.
MAX_PERIOD = 32
#: Poincaré points i and i+n count as equal when they differ by less than this, relative to
#: max(1, the largest |point| in the window).
PERIOD_TOL = 1.0e-6
#: Fraction of the recorded Poincaré points (the latest ones) examined for periodicity.
PERIOD_WINDOW = 0.5

IMPACT_NONE, IMPACT_SINGLE, IMPACT_DOUBLE, IMPACT_UNKNOWN = 0, 1, 2, -1
IMPACT_LABELS = {
    IMPACT_NONE: "no impact",
    IMPACT_SINGLE: "single-sided impact",
    IMPACT_DOUBLE: "double-sided impact",
    IMPACT_UNKNOWN: "unknown",
}


def detect_period(points: np.ndarray, max_period: int = MAX_PERIOD, tol: float = PERIOD_TOL) -> int:
    """Smallest n <= ``max_period`` with P_{i+n} = P_i over the latest recorded Poincaré points.

    Parameters
    ----------
    points : ndarray (m, 2)
        Successive Poincaré points (non-dimensional u, u').
    Returns
    -------
    int
        The period n, 0 if the sequence is not periodic with n <= ``max_period`` (or too short to
        tell), -1 if it holds non-finite values (diverged).
    """
    pts = np.asarray(points, dtype=float)
    m = pts.shape[0]
    if m == 0 or not np.all(np.isfinite(pts)):
        return -1
    window = max(int(np.ceil(PERIOD_WINDOW * m)), 2)
    scale = max(1.0, float(np.max(np.abs(pts[-window:]))))
    for n in range(1, max_period + 1):
        w = min(window, m - n)
        if w < max(2, n):  # need every point of the cycle compared at least once
            break
        a = pts[m - w:]
        b = pts[m - w - n: m - n]
        if float(np.max(np.abs(a - b))) <= tol * scale:
            return n
    return 0


def impact_state(u_min: float, D: float) -> int:
    """Impact state code from the smallest displacement of a steady response."""
    if not np.isfinite(u_min):
        return IMPACT_UNKNOWN
    if D == 0.0 or u_min > D:
        return IMPACT_NONE
    if u_min >= -D:
        return IMPACT_SINGLE
    return IMPACT_DOUBLE


def period_label(period: int) -> str:
    """'period-n', 'not periodic' or 'diverged' from :func:`detect_period`'s code."""
    if period > 0:
        return f"period-{period}"
    if period == 0:
        return "not periodic"
    return "diverged"
