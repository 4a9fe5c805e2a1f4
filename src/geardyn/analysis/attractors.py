"""Attractors: when two steady responses are the same attractor, and labelling points by attractor.

One test serves the frequency response (do the up and down sweeps end on the same attractor at
a grid point? :func:`geardyn.analysis.response.same_attractor`) and the basins of attraction
(which attractor does each initial state reach? :func:`identify_attractors`):

- two **periodic** attractors are the same when each point of one Poincaré cycle lies within
  ``tol`` (relative to max(1, the first cycle's largest |coordinate|)) of a point of the other, in
  both directions — the cycle's phase does not matter (:func:`same_cycle`).  The detected periods
  need not agree: a period-1 orbit whose last points still scatter by more than the period test's
  1e-6 (a transient not yet decayed, typically at the point just after a jump) is detected with a
  longer period, yet all its points lie on the one point of the settled cycle;
- two **non-periodic** attractors (quasi-periodic, chaotic, unresolved) are the same when their
  amplitude signatures (amplitude and mean; the basins also compare the extremes and require the
  same motion class) agree to an absolute tolerance (:func:`same_signature`);
- a periodic and a non-periodic attractor differ.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..integrate import ST_OK
from .classify import MAX_PERIOD, MOTION_PERIODIC

__all__ = [
    "CLOUD_POINTS",
    "CYCLE_TOL",
    "NONPERIODIC_TOL",
    "Attractor",
    "identify_attractors",
    "same_attractor",
    "same_cycle",
    "same_signature",
]

#: Cycle points closer than this (relative to max(1, largest |coordinate|)) are the same point.
CYCLE_TOL = 1.0e-3
#: Non-periodic attractors are the same when their amplitude signatures agree to this fraction of
#: an amplitude scale (the response's amplitude range; the largest amplitude of a basin map).
NONPERIODIC_TOL = 0.05
#: Non-periodic attractors of a basin map are drawn with this many of their Poincaré points.
CLOUD_POINTS = MAX_PERIOD


def same_cycle(a: np.ndarray, b: np.ndarray, tol: float = CYCLE_TOL) -> bool:
    """Whether two Poincaré cycles are the same set of points, in any phase.

    Parameters
    ----------
    a, b : ndarray (n, 2), (m, 2)
        The cycles' points.
    tol : float
        Distance (max norm) within which two points are the same, relative to max(1, the largest
        |coordinate| of ``a``).

    Returns
    -------
    bool
        True when each point of ``a`` is within the distance of a point of ``b`` and vice versa.
    """
    scale = max(1.0, float(np.max(np.abs(a))))
    d = np.max(np.abs(a[:, None, :] - b[None, :, :]), axis=2)
    return bool(np.all(d.min(axis=1) <= tol * scale) and np.all(d.min(axis=0) <= tol * scale))


def same_signature(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Whether two amplitude signatures agree entry by entry to the absolute tolerance ``tol``.

    Parameters
    ----------
    a, b : ndarray
        Signatures (e.g. amplitude, mean, u_min, u_max); NaN never agrees.
    tol : float
        Absolute tolerance.

    Returns
    -------
    bool
    """
    return bool(np.all(np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) <= tol))


@dataclass
class Attractor:
    """One attractor as seen from a steady response.

    Parameters
    ----------
    period : int
        Period n of a periodic attractor, 0 for a non-periodic one.
    motion : int
        Motion code (:data:`geardyn.analysis.classify.MOTION_LABELS`).
    points : ndarray (k, 2)
        The Poincaré cycle of a periodic attractor, a sample of the section otherwise.
    signature : ndarray
        The amplitude measures compared for a non-periodic attractor.
    """

    period: int
    motion: int
    points: np.ndarray
    signature: np.ndarray

    @property
    def periodic(self) -> bool:
        """Whether the attractor is periodic."""
        return self.period > 0


def attractor_of(
    period: int, motion: int, section: np.ndarray, signature: np.ndarray, cloud: int = CLOUD_POINTS
) -> Attractor:
    """The :class:`Attractor` of one point from its period, motion code and Poincaré section.

    Parameters
    ----------
    period, motion : int
        Its period (:func:`~geardyn.analysis.classify.detect_period`) and motion code.
    section : ndarray (m, 2)
        Its recorded Poincaré points.
    signature : ndarray
        Its amplitude signature.
    cloud : int
        Points of the section kept for a non-periodic attractor.

    Returns
    -------
    Attractor
    """
    n = int(period)
    if int(motion) == MOTION_PERIODIC and n > 0:
        return Attractor(n, int(motion), section[-n:], signature)
    return Attractor(0, int(motion), section[-cloud:], signature)


def same_attractor(
    a: Attractor, b: Attractor, *, signature_tol: float, tol: float = CYCLE_TOL, match_motion: bool = True
) -> bool:
    """Whether ``a`` and ``b`` are the same attractor (see the module docstring).

    Parameters
    ----------
    a, b : Attractor
        The two attractors (``a`` sets the scale of the cycle comparison).
    signature_tol : float
        Absolute tolerance of the signature comparison of non-periodic attractors.
    tol : float
        Relative tolerance of the cycle comparison (:func:`same_cycle`).
    match_motion : bool
        Non-periodic attractors must also have the same motion class.

    Returns
    -------
    bool
    """
    if a.periodic != b.periodic:
        return False
    if a.periodic:  # the same set of section points whatever period the detector saw (module docstring)
        return same_cycle(a.points, b.points, tol)
    if match_motion and a.motion != b.motion:
        return False
    return same_signature(a.signature, b.signature, signature_tol)


def identify_attractors(
    rows: dict[str, np.ndarray], *, tol: float = CYCLE_TOL, nonperiodic_tol: float = NONPERIODIC_TOL
) -> tuple[np.ndarray, list[dict[str, Any]]]:
    """Label each point by its attractor.

    Non-periodic attractors are compared by amplitude, mean and extremes, to ``nonperiodic_tol``
    of the largest amplitude, and must have the same motion class.

    Parameters
    ----------
    rows : dict of arrays
        Per-point ``period``, ``motion``, ``status``, ``amplitude``, ``mean``, ``u_min``,
        ``u_max`` and ``poincare`` (P, m, 2).
    tol : float
        Relative tolerance of the cycle comparison.
    nonperiodic_tol : float
        Fraction of the largest amplitude within which non-periodic signatures agree.

    Returns
    -------
    labels : ndarray (P,)
        Attractor index per point (0 = largest basin), −1 where diverged.
    attractors : list of dict
        Per attractor: ``period`` (0 if not periodic), ``motion`` code, ``points`` (the cycle,
        sorted, or a sample of the section), ``amplitude``, ``mean``, ``count`` (points in its basin).
    """
    P = rows["period"].shape[0]
    raw = np.full(P, -1, dtype=np.int64)
    atts: list[Attractor] = []
    counts: list[int] = []
    amps = rows["amplitude"][np.isfinite(rows["amplitude"])]
    amp_scale = max(float(np.max(amps)) if amps.size else 0.0, 1e-12)
    sig_tol = nonperiodic_tol * amp_scale
    for i in range(P):
        if rows["status"][i] != ST_OK:
            continue
        sig = np.array([rows["amplitude"][i], rows["mean"][i], rows["u_min"][i], rows["u_max"][i]])
        new = attractor_of(rows["period"][i], rows["motion"][i], rows["poincare"][i], sig)
        found = next((a for a, att in enumerate(atts) if same_attractor(new, att, signature_tol=sig_tol, tol=tol)), -1)
        if found < 0:
            pts = new.points
            if new.periodic:
                pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]
            atts.append(Attractor(new.period, new.motion, pts.copy(), sig))
            counts.append(0)
            found = len(atts) - 1
        raw[i] = found
        counts[found] += 1
    # number by basin size (ties: periodic first, then by period and first cycle point)
    key = sorted(
        range(len(atts)),
        key=lambda a: (-counts[a], atts[a].period == 0, atts[a].period, float(atts[a].points[0, 0])),
    )
    renumber = {old: k for k, old in enumerate(key)}
    labels = np.array([renumber[r] if r >= 0 else -1 for r in raw], dtype=np.int64)
    info = [
        {
            "period": a.period,
            "motion": a.motion,
            "points": a.points,
            "amplitude": float(a.signature[0]),
            "mean": float(a.signature[1]),
            "count": n,
        }
        for a, n in zip(atts, counts)
    ]
    return labels, [info[old] for old in key]
