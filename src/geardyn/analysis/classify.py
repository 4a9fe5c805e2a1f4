"""Classification of a steady response: period, impact state and motion class.

Names follow DESIGN §1.3.  Contact states: drive-side contact u > D, separation |u| <= D,
back-side contact u < −D.  Impact state of a steady response: *no impact* (always in drive-side
contact), *single-sided impact* (separation occurs, the back side is never touched),
*double-sided impact* (back-side contact occurs).

Motion classes (:func:`classify_motion`, thresholds below, explained in ``docs/analysis.md``):

- **period-n**: the Poincaré sequence repeats after n <= :data:`MAX_PERIOD` periods to within
  :data:`PERIOD_TOL` (:func:`detect_period`);
- **quasi-periodic**: not periodic, and the largest Lyapunov exponent is zero within its
  uncertainty: |λ1| <= :data:`LLE_SIGMAS`·σ + :data:`LLE_FLOOR`; the Poincaré points then lie on
  closed curves, whose number :func:`count_loops` reports (the "n" of the paper's
  "quasi-n-periodic").  Never for a model whose structure forbids it
  (:func:`quasi_periodic_allowed`: the pair with ξ0 > 0, whose period map contracts every area), nor
  where the least damped mode of the linearised system decays more slowly than that band resolves
  (0 < σ_min <= LLE_SIGMAS·σ + LLE_FLOOR, :func:`decay_hides_torus`): its exponent −σ_min is then zero within
  the band too, so a neutral λ1 cannot tell a torus from that mode's transient;
- **chaotic**: not periodic and λ1 > :data:`LLE_SIGMAS`·σ + :data:`LLE_FLOOR`;
- **diverged**: the trajectory left |u|, |u'| < DIVERGENCE_BOUND or became non-finite;
- **unresolved**: not periodic within the limits although λ1 is significantly negative (a stable
  orbit of period > :data:`MAX_PERIOD`, or one still settling); or λ1 zero within its uncertainty
  but the section is not a set of closed curves (e.g. the accumulation point of a
  period-doubling cascade); or no exponent available.

This module only classifies what has been integrated; it never integrates.  A non-periodic
point is integrated for :data:`SETTLE_PERIODS` further periods with the tangent equations
before it is classified (:func:`geardyn.analysis.steady.classify_batch`): slowly settling orbits
near a bifurcation then show their period, and λ1 gets a small uncertainty; while the sequence is
still contracting onto a cycle (:func:`settling_ratio` <= :data:`SETTLING_RATIO`), up to :data:`SETTLE_ROUNDS`
such passes run.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..labels import (  # noqa: F401  (the vocabulary, re-exported for the classification's callers)
    IMPACT_DOUBLE,
    IMPACT_LABELS,
    IMPACT_NONE,
    IMPACT_SINGLE,
    IMPACT_UNKNOWN,
    MAX_PERIOD,
    MOTION_CHAOTIC,
    MOTION_DIVERGED,
    MOTION_LABELS,
    MOTION_PERIODIC,
    MOTION_QUASIPERIODIC,
    MOTION_UNRESOLVED,
    impact_state,
    motion_label,
    period_label,
)

#: Poincaré points i and i+n count as equal when they differ by less than this, relative to
#: max(1, the largest |point| in the window).
PERIOD_TOL = 1.0e-6
#: Fraction of the recorded Poincaré points (the latest ones) examined for periodicity.
PERIOD_WINDOW = 0.5
#: A period n found over the window is refused while the sequence still converges onto a cycle of a
#: proper divisor m of n: the median of |P_{i+m} − P_i| over the window's second half at most this
#: fraction of its median over the first half (see :func:`converging_to_divisor`).  A slowly converging
#: period-2 orbit whose multiplier is near −1 repeats after 4 periods to within the tolerance long before it
#: repeats after 2; its differences over 2 periods still shrink.  A true period-n cycle has stationary
#: differences over its divisors (a ratio of 1 to within the tolerance).
CONVERGING_RATIO = 0.8


def _lag_distances(points: np.ndarray, n: int) -> np.ndarray:
    """max over the coordinates of |P_{i+n} − P_i| for every i of a sequence (or a batch of them, (..., m, d))."""
    return np.max(np.abs(points[..., n:, :] - points[..., :-n, :]), axis=-1)


def converging_to_divisor(points: np.ndarray, n: int, window: int) -> bool:
    """True when the last ``window`` points of a sequence found periodic with period ``n`` are still
    converging onto a cycle of a proper divisor of ``n`` (:data:`CONVERGING_RATIO`).

    Parameters
    ----------
    points : ndarray (m, d)
        The Poincaré sequence.
    n : int
        The period found.
    window : int
        How many of the latest points the period was found over.
    """
    pts = np.asarray(points, dtype=float)
    m_pts = pts.shape[0]
    for m in range(1, int(n)):
        if int(n) % m:
            continue  # the proper divisors of n only
        w = min(window, m_pts - m)
        half = w // 2
        if half < max(2, m):
            continue
        d = _lag_distances(pts[m_pts - w - m :], m)
        early, late = float(np.median(d[:half])), float(np.median(d[-half:]))
        if early > 0.0 and late <= CONVERGING_RATIO * early:
            return True
    return False


def detect_period(points: np.ndarray, max_period: int = MAX_PERIOD, tol: float = PERIOD_TOL) -> int:
    """Smallest n <= ``max_period`` with P_{i+n} = P_i over the latest recorded Poincaré points.

    A period n is not reported while the points still converge onto a cycle of a proper divisor of n
    (:func:`converging_to_divisor`): the sequence is then not yet periodic (0), and a sweep settles it further.

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
    return int(detect_periods(np.asarray(points, dtype=float)[None], max_period, tol)[0])


def detect_periods(points: np.ndarray, max_period: int = MAX_PERIOD, tol: float = PERIOD_TOL) -> np.ndarray:
    """:func:`detect_period` of every point of a batch at once (the same codes, bit for bit).

    Parameters
    ----------
    points : ndarray (P, m, d)
        The Poincaré points of each of P points.
    max_period : int
        Largest period reported.
    tol : float
        Relative tolerance (see :data:`PERIOD_TOL`).

    Returns
    -------
    ndarray of int64 (P,)
        n > 0 periodic, 0 not periodic (or too short to tell), -1 non-finite (diverged).
    """
    pts = np.asarray(points, dtype=float)
    P, m = int(pts.shape[0]), int(pts.shape[1])
    out = np.zeros(P, dtype=np.int64)
    if P == 0:
        return out
    if m == 0:
        out[:] = -1
        return out
    flat = pts.reshape(P, -1)
    finite = np.all(np.isfinite(flat), axis=1)
    out[~finite] = -1
    window = max(int(np.ceil(PERIOD_WINDOW * m)), 2)
    scale = np.maximum(1.0, np.max(np.abs(pts[:, -window:]).reshape(P, -1), axis=1))
    todo = np.flatnonzero(finite)
    for n in range(1, max_period + 1):
        w = min(window, m - n)
        if w < max(2, n) or todo.size == 0:  # need every point of the cycle compared at least once
            break
        d = np.max(_lag_distances(pts[todo, m - w - n :], n), axis=1)
        hit = d <= tol * scale[todo]
        found = todo[hit]
        if n > 1 and found.size:  # still converging onto a cycle of a divisor of n: not yet periodic
            found = np.array([i for i in found if not converging_to_divisor(pts[i], n, window)], dtype=np.int64)
        out[found] = n
        todo = todo[~hit]
    return out


def impact_states(u_min: np.ndarray, D: np.ndarray) -> np.ndarray:
    """:func:`impact_state` element-wise (the same codes).

    Parameters
    ----------
    u_min : ndarray
        Smallest displacement of each steady response (NaN: unknown).
    D : ndarray or float
        Half backlash of each point.

    Returns
    -------
    ndarray of int64
        ``IMPACT_*`` codes.
    """
    u = np.asarray(u_min, dtype=float)
    d = np.broadcast_to(np.asarray(D, dtype=float), u.shape)
    with np.errstate(invalid="ignore"):
        code = np.where(u >= -d, IMPACT_SINGLE, IMPACT_DOUBLE)
        code = np.where((d == 0.0) | (u > d), IMPACT_NONE, code)
    return np.where(np.isfinite(u), code, IMPACT_UNKNOWN).astype(np.int64)


# ---------------------------------------------------------------------------- motion classes
#: An exponent counts as different from zero when it exceeds LLE_SIGMAS standard errors …
LLE_SIGMAS = 3.0
#: … plus this absolute floor (per unit τ), which absorbs the O(h⁴) integration error and round-off
#: when the block standard error is tiny (e.g. 1e-15 on an exactly rotating tangent basis).  It is
#: 0.05 % of the total contraction rate 2ξ0 = 0.2 of the paper's defaults.
LLE_FLOOR = 1.0e-4
#: Further periods integrated (with the tangent equations) for a point whose Poincaré sequence is
#: not periodic after the transient, before it is classified.
SETTLE_PERIODS = 1000
#: Poincaré points closer than this fraction of the point set's extent belong to the same loop
#: (single-linkage), see :func:`count_loops`.
LOOP_GAP = 0.05
#: At most this many settling passes of SETTLE_PERIODS each; another pass runs only while the
#: Poincaré sequence is still contracting onto a cycle (see :data:`SETTLING_RATIO`).
SETTLE_ROUNDS = 4
#: The sequence is still settling when its distance to the best cycle shrank by this factor or
#: more between the first and the last quarter of a pass.
SETTLING_RATIO = 0.5
#: Quasi-periodic sections are stationary: the distance to the best cycle (see :func:`settling_ratio`)
#: must not shrink below this fraction between the first and the last quarter of the sequence.
#: A sequence creeping onto a cycle at a bifurcation point (critical slowing down) fails this.
STATIONARY_RATIO = 0.8
#: Quasi-periodic sections are closed curves: their correlation dimension (:func:`curve_dimension`)
#: must lie in this interval (a smooth curve gives 1; a period-doubling cascade's Cantor-like set
#: at its accumulation point about 0.4–0.5; a strange attractor's section above 1).
CURVE_DIM_RANGE = (0.8, 1.5)
#: Radii of the correlation-dimension estimate, in units of the median nearest-neighbour distance.
CURVE_DIM_RADII = (4.0, 32.0)


def quasi_periodic_allowed(model: Any) -> bool:
    """Whether the structure of a System admits a quasi-periodic attractor at all.

    The period map of a system with a two-dimensional state and no rigid-body mode is a homeomorphism of
    the plane whose Jacobian determinant is exp(mean_trace · T) over a period T (Liouville).  With a
    negative mean trace (the pair: −2ξ0, so det = exp(−4πξ0/ω) < 1 for ξ0 > 0) it contracts every area by
    that factor; an invariant closed curve (or a cycle of n of them, invariant under the n-th iterate)
    would bound a region mapped onto itself, of unchanged area.  So such a system has no quasi-periodic
    attractor, and :func:`classify_motion` never labels one of its points quasi-periodic.

    Parameters
    ----------
    model : System
        The point.

    Returns
    -------
    bool
        False for a planar state, no rigid-body mode and a negative mean trace; True otherwise.
    """
    return not (_planar(model) and float(model.mean_trace()) < 0.0)


def _planar(model: Any) -> bool:
    """A two-dimensional state without rigid-body modes: a period map of the plane."""
    return int(model.state_dim) == 2 and np.asarray(model.rigid_basis()).shape[-1] == 0


def quasi_periodic_allowed_batch(batch: Any) -> np.ndarray:
    """:func:`quasi_periodic_allowed` of every point of a :class:`~geardyn.system.Batch` (P,), its mean traces
    read from the batch (a grid of the pair builds no model per point)."""
    if not _planar(batch[0]):
        return np.ones(len(batch), dtype=bool)
    return ~(np.asarray(batch.mean_traces()) < 0.0)


def classify_motion(
    period: Any,
    lle: Any,
    lle_err: Any,
    ok: Any = True,
    curve_dim: Any = np.nan,
    settle_ratio: Any = np.nan,
    quasi_allowed: Any = True,
    decay: Any = np.nan,
) -> np.ndarray:
    """Motion codes from the period, the largest exponent and its uncertainty (element-wise).

    Parameters
    ----------
    period : int or array
        Result of :func:`detect_period` (n > 0 periodic, 0 not periodic, −1 diverged).
    lle, lle_err : float or array
        Largest Lyapunov exponent λ1 per unit τ and its standard error σ (NaN: not computed).
    ok : bool or array
        False where the trajectory diverged.
    curve_dim : float or array
        Correlation dimension of the Poincaré section (:func:`curve_dimension`); NaN skips the
        closed-curve test.
    settle_ratio : float or array
        :func:`settling_ratio` of the Poincaré sequence; NaN skips the stationarity test.
    quasi_allowed : bool or array
        False where the model's structure forbids a quasi-periodic attractor
        (:func:`quasi_periodic_allowed`): such a point is never labelled quasi-periodic, it is unresolved
        (a slowly converging orbit, or one of period above the limit) until settled further.
    decay : float or array
        σ_min, the decay rate per unit τ of the least damped mode of the model linearised in contact
        (:func:`geardyn.analysis.settle.decay_rate`; NaN: not known or a mode undamped).  A point with
        0 < σ_min <= LLE_SIGMAS·σ + LLE_FLOOR is never quasi-periodic (:func:`decay_hides_torus`).

    Returns
    -------
    ndarray of int
        ``MOTION_*`` codes: periodic when n > 0; else chaotic when λ1 > LLE_SIGMAS·σ + LLE_FLOOR,
        quasi-periodic when |λ1| <= LLE_SIGMAS·σ + LLE_FLOOR, the section is a stationary set of
        closed curves and the model admits a quasi-periodic attractor, unresolved otherwise (λ1
        significantly negative; zero but the section not stationary closed curves, or the structure
        forbids it; or not available).
    """
    n = np.asarray(period, dtype=np.int64)
    lam = np.asarray(lle, dtype=float)
    err = np.asarray(lle_err, dtype=float)
    good = np.asarray(ok, dtype=bool) & (n >= 0)
    band = LLE_SIGMAS * np.where(np.isfinite(err), err, 0.0) + LLE_FLOOR
    with np.errstate(invalid="ignore"):
        code = np.where(
            lam > band, MOTION_CHAOTIC, np.where(np.abs(lam) <= band, MOTION_QUASIPERIODIC, MOTION_UNRESOLVED)
        )
    dim = np.asarray(curve_dim, dtype=float)
    lo, hi = CURVE_DIM_RANGE
    ratio = np.asarray(settle_ratio, dtype=float)
    off_curve = (np.isfinite(dim) & ((dim < lo) | (dim > hi))) | (np.isfinite(ratio) & (ratio < STATIONARY_RATIO))
    forbidden = ~np.asarray(quasi_allowed, dtype=bool) | decay_hides_torus(decay, band)
    code = np.where((code == MOTION_QUASIPERIODIC) & (off_curve | forbidden), MOTION_UNRESOLVED, code)
    code = np.where(np.isfinite(lam), code, MOTION_UNRESOLVED)
    code = np.where(n > 0, MOTION_PERIODIC, code)
    code = np.where(good, code, MOTION_DIVERGED)
    return code.astype(np.int64)


def decay_hides_torus(decay: Any, band: Any) -> np.ndarray:
    """Where the least damped linearised mode decays too slowly for a neutral exponent to mean a torus.

    A stable orbit of a lightly damped system has a Floquet exponent near −σ_min (the mode that the
    nonlinear elements barely touch keeps its linear decay); when 0 < σ_min <= the band within which λ1
    counts as zero, a λ1 in that band is as well that mode's slow transient as a neutral direction, so
    the point is unresolved, not quasi-periodic.  An undamped mode (σ_min = 0, or NaN: unknown) does
    not forbid it.

    Parameters
    ----------
    decay : float or array
        σ_min per unit τ (NaN: unknown).
    band : float or array
        LLE_SIGMAS·σ + LLE_FLOOR of each point.

    Returns
    -------
    ndarray of bool

    Examples
    --------
    >>> decay_hides_torus([3e-7, 0.05, np.nan], 1e-4).tolist()
    [True, False, False]
    """
    s = np.asarray(decay, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.asarray((s > 0.0) & (s <= np.asarray(band, dtype=float)))


def count_loops(points: np.ndarray, gap: float = LOOP_GAP) -> int:
    """Number of separate groups (closed curves or cycle points) in a Poincaré point set.

    Points are joined when closer than ``gap`` times the larger side of the set's bounding box;
    the count is the number of connected groups.  For a quasi-periodic response it is the number
    of closed curves of the section (a torus born from a period-n orbit shows n curves); for a
    period-n orbit it is n (when its points are farther apart than the gap).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=float)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if pts.shape[0] == 0:
        return 0
    extent = float(np.max(np.ptp(pts, axis=0)))
    if extent == 0.0:
        return 1
    pairs = cKDTree(pts).query_pairs(gap * extent, output_type="ndarray")
    m = pts.shape[0]
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    return int(connected_components(g, directed=False)[0])


def curve_dimension(points: np.ndarray, radii: tuple[float, float] = CURVE_DIM_RADII) -> float:
    """Correlation dimension of a Poincaré point set at the scale of its sampling.

    The slope of log C(r) against log r between r1 = radii[0]·δ and r2 = radii[1]·δ (capped at a
    quarter of the set's extent), where C(r) counts point pairs closer than r and δ is the median
    nearest-neighbour distance.  About 1 for points filling closed curves (quasi-periodic), 0 for
    a cycle of repeated points, between 1 and 2 for a strange attractor's section, below 1 for
    Cantor-like sets.  NaN with fewer than 16 finite points.
    """
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=float)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if pts.shape[0] < 16:
        return float("nan")
    tree = cKDTree(pts)
    d, _ = tree.query(pts, k=2)
    delta = float(np.median(d[:, 1]))
    extent = float(np.max(np.ptp(pts, axis=0)))
    if delta <= 0.0 or extent <= 0.0:
        return 0.0
    r1 = radii[0] * delta
    r2 = min(radii[1] * delta, 0.25 * extent)
    if r2 <= r1:
        return float("nan")
    c = tree.count_neighbors(tree, np.array([r1, r2])) - pts.shape[0]
    if c[0] <= 0:
        return float("nan")
    return float(np.log(c[1] / c[0]) / np.log(r2 / r1))


def settling_ratio(points: np.ndarray, max_period: int = MAX_PERIOD) -> float:
    """How much a Poincaré sequence closed in on a cycle of period <= ``max_period`` during the record.

    For each n the distances |P_{i+n} − P_i| are taken; for the n with the smallest median over
    the last quarter of the sequence, the ratio of that median to the median over the first
    quarter is returned: about 1 for a stationary sequence (quasi-periodic, chaotic or converged),
    well below 1 while it still contracts onto a cycle.  NaN for fewer than 8 finite points or an
    exactly repeating sequence.
    """
    return float(settling_ratios(np.asarray(points, dtype=float)[None], max_period)[0])


def settling_ratios(points: np.ndarray, max_period: int = MAX_PERIOD) -> np.ndarray:
    """:func:`settling_ratio` of every sequence of a batch of equal length at once (the same bits).

    Parameters
    ----------
    points : ndarray (B, m, d)
        B Poincaré sequences of m points.
    max_period : int
        Longest cycle considered.

    Returns
    -------
    ndarray (B,)
        The ratios (NaN where :func:`settling_ratio` gives NaN).
    """
    pts = np.asarray(points, dtype=float)
    B, m = int(pts.shape[0]), int(pts.shape[1])
    out = np.full(B, np.nan)
    if B == 0 or m < 8:
        return out
    good = np.all(np.isfinite(pts.reshape(B, -1)), axis=1)
    q = m // 4
    best_late = np.full(B, np.inf)
    best_early = np.full(B, np.nan)
    for n in range(1, min(max_period, m - 2 * q) + 1):
        d = _lag_distances(pts, n)
        late = np.median(d[:, -q:], axis=1)
        better = late < best_late
        best_late = np.where(better, late, best_late)
        best_early = np.where(better, np.median(d[:, :q], axis=1), best_early)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = best_late / best_early
    return np.where(good & (best_early > 0.0), ratio, np.nan)


def classify_points(
    period: np.ndarray,
    lle: np.ndarray,
    lle_err: np.ndarray,
    ok: np.ndarray,
    sections: Sequence[np.ndarray],
    quasi_allowed: Any = True,
    decay: Any = np.nan,
) -> dict[str, np.ndarray]:
    """Motion class, section dimension, settling ratio and loop count of a batch of points.

    Pure classification: the points are integrated (and settled) before, by
    :func:`geardyn.analysis.steady.classify_batch`.

    Parameters
    ----------
    period : ndarray of int (P,)
        :func:`detect_period` of each point.
    lle, lle_err : ndarray (P,)
        Largest Lyapunov exponent and its standard error (NaN where not computed).
    ok : ndarray of bool (P,)
        False where the trajectory diverged.
    sections : sequence of ndarray (m, 2)
        The Poincaré section of each point (for a settled point, that of its last settling pass).
    quasi_allowed : bool or ndarray of bool (P,)
        :func:`quasi_periodic_allowed` of each point's model.
    decay : float or ndarray (P,)
        σ_min of each point's model (:func:`classify_motion`; NaN: unknown).

    Returns
    -------
    dict of ndarray
        ``motion`` (codes of :func:`classify_motion`), ``curve_dim`` (:func:`curve_dimension` of
        non-periodic points, else NaN), ``settle_ratio`` (:func:`settling_ratio` of non-periodic
        points, else NaN) and ``loops`` (:func:`count_loops` of quasi-periodic points, else 0).
    """
    period = np.asarray(period)
    ok = np.asarray(ok, dtype=bool)
    P = period.shape[0]
    curve_dim = np.full(P, np.nan)
    ratio = np.full(P, np.nan)
    todo = np.flatnonzero(ok & (period == 0))
    by_length: dict[tuple[int, ...], list[int]] = {}
    for i in todo:
        sec = np.asarray(sections[i])
        by_length.setdefault(sec.shape, []).append(int(i))
        if sec.shape[0] >= 16:  # fewer points: NaN (see curve_dimension)
            curve_dim[i] = curve_dimension(sec)
    for idx in by_length.values():  # the settling ratio of sequences of one length at once
        ratio[idx] = settling_ratios(np.stack([np.asarray(sections[i]) for i in idx]))
    motion = classify_motion(period, lle, lle_err, ok, curve_dim, ratio, quasi_allowed, decay)
    loops = np.zeros(P, dtype=np.int64)
    for i in np.flatnonzero(motion == MOTION_QUASIPERIODIC):
        loops[i] = count_loops(sections[i])
    return {"motion": motion, "curve_dim": curve_dim, "settle_ratio": ratio, "loops": loops}
