"""The bottom vocabulary of results: motion and impact codes with their labels, and the longest period.

Every layer names results with these (the kernel door's adaptive transient, the Dataset registry of
:mod:`geardyn.io`, the classification of :mod:`geardyn.analysis.classify`), so they live below all of
them and import nothing.  Statuses are :class:`geardyn.status.Status`.
"""

from __future__ import annotations

import math

__all__ = [
    "MAX_PERIOD",
    "IMPACT_NONE",
    "IMPACT_SINGLE",
    "IMPACT_DOUBLE",
    "IMPACT_UNKNOWN",
    "IMPACT_LABELS",
    "MOTION_DIVERGED",
    "MOTION_UNRESOLVED",
    "MOTION_PERIODIC",
    "MOTION_QUASIPERIODIC",
    "MOTION_CHAOTIC",
    "MOTION_LABELS",
    "impact_state",
    "period_label",
    "motion_label",
]

#: Largest period n (in forcing periods) that period detection reports (and the adaptive transient seeks).
MAX_PERIOD = 32

#: Impact states of a steady response (variable ``impact``): never separating, separating without
#: touching the back side, touching the back side, not known (diverged).
IMPACT_NONE, IMPACT_SINGLE, IMPACT_DOUBLE, IMPACT_UNKNOWN = 0, 1, 2, -1
IMPACT_LABELS = {
    IMPACT_NONE: "no impact",
    IMPACT_SINGLE: "single-sided impact",
    IMPACT_DOUBLE: "double-sided impact",
    IMPACT_UNKNOWN: "unknown",
}

#: Motion codes stored in Datasets (variable ``motion``).
MOTION_DIVERGED, MOTION_UNRESOLVED, MOTION_PERIODIC, MOTION_QUASIPERIODIC, MOTION_CHAOTIC = -1, 0, 1, 2, 3
MOTION_LABELS = {
    MOTION_DIVERGED: "diverged",
    MOTION_UNRESOLVED: "unresolved",
    MOTION_PERIODIC: "periodic",
    MOTION_QUASIPERIODIC: "quasi-periodic",
    MOTION_CHAOTIC: "chaotic",
}


def impact_state(u_min: float, D: float) -> int:
    """Impact state code from the smallest deflection of a steady response.

    Parameters
    ----------
    u_min : float
        Smallest deflection u (NaN: unknown).
    D : float
        Half gap of the element.

    Returns
    -------
    int
        An ``IMPACT_*`` code.
    """
    if not math.isfinite(u_min):
        return IMPACT_UNKNOWN
    if D == 0.0 or u_min > D:
        return IMPACT_NONE
    if u_min >= -D:
        return IMPACT_SINGLE
    return IMPACT_DOUBLE


def period_label(period: int) -> str:
    """'period-n', 'not periodic' or 'diverged' from a period-detection code.

    Parameters
    ----------
    period : int
        n > 0 (period n), 0 (not periodic) or −1 (diverged).

    Returns
    -------
    str
    """
    if period > 0:
        return f"period-{period}"
    if period == 0:
        return "not periodic"
    return "diverged"


def motion_label(code: int, period: int | None = None) -> str:
    """'period-n', 'quasi-periodic', 'chaotic', 'diverged' or 'unresolved'.

    Parameters
    ----------
    code : int
        A ``MOTION_*`` code.
    period : int, optional
        The period of a periodic point (its label is then ``period-n``).

    Returns
    -------
    str
    """
    code = int(code)
    if code == MOTION_PERIODIC and period is not None and int(period) > 0:
        return f"period-{int(period)}"
    return MOTION_LABELS.get(code, "unresolved")
