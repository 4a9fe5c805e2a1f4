"""How the studies read the paper's words and turn computed results into verdicts.

The verdict rules are stated once, here (:data:`VERDICT_RULES`, which the report quotes), and
every study applies them through the functions of this module:

- a claim of a motion over a parameter interval: the fraction of the interval's *length* where it
  holds (:func:`length_fraction`, :func:`match_fraction`), reproduced from :data:`MATCH_REPRODUCED`;
- a claim with several parts: every part required (:func:`parts`, :func:`of_claims`);
- fluctuation trends measured as fluctuation (:func:`section_spread`, :func:`fluctuation_trend`);
- jumps by direction and location, the opposite jump failing (:func:`jump_type_at`, :func:`jump_holds`);
- single-number claims: the formula fit (:data:`FORMULA_R2_REPRODUCED`) and the stability
  condition (:data:`STABILITY_REL`).

The verdict kinds are :data:`VERDICTS`; the readings tried for each claim come from
:mod:`geardyn.paper.readings`.

:func:`motion_rule` maps the paper's words for motions onto geardyn's classification, once for
every study.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from itertools import groupby

import numpy as np
import xarray as xr

from .._docfill import parameters
from ..analysis.classify import MOTION_CHAOTIC, MOTION_PERIODIC, MOTION_QUASIPERIODIC
from .report import VERDICTS

__all__ = [
    "FORMULA_R2_PARTLY",
    "FORMULA_R2_REPRODUCED",
    "distinct_text",
    "MATCH_PARTLY",
    "MATCH_REPRODUCED",
    "STABILITY_REL",
    "VERDICTS",
    "VERDICT_RULES",
    "count_text",
    "of_claims",
    "parts",
    "describe_motion",
    "is_chaotic",
    "is_regular",
    "match_fraction",
    "motion_fields",
    "motion_rule",
    "motion_runs",
    "quasi_n",
    "range_of",
    "runs_text",
    "verdict_of",
    "FLUCT_MIN",
    "fluctuation_trend",
    "jump_holds",
    "jump_type_at",
    "length_fraction",
    "section_spread",
    "strictly_monotone",
    "yes_no",
]

#: Fraction of a claim's parameter interval (by length) where it must hold to hold.
MATCH_REPRODUCED = 0.8
#: Kept for callers of the former three-verdict scale: a fraction below this never counts as holding in part.
MATCH_PARTLY = 0.3
#: The amplitude formula holds when its least-squares fit reaches this R² …
FORMULA_R2_REPRODUCED = 0.9
#: … (and, for the record, fits worse than this explain less than half of the variance).
FORMULA_R2_PARTLY = 0.5
#: The stability condition holds when a computed critical ξ0 lies within this relative distance of it.
STABILITY_REL = 0.1
#: Fluctuation (spread of the Poincaré points, in units of b_c) below this counts as none.
FLUCT_MIN = 1e-3

#: The verdict rules as the report states them (once, in its Settings section).
VERDICT_RULES: tuple[str, ...] = (
    "Four kinds of verdict. Reproduced: the claim holds under the paper's stated values and geardyn's declared "
    "defaults (phases 0, D = b/(2 mm), ω = 1 where the paper states none). Reproduced under a named reading: it "
    "fails there but holds under another reading of what the paper leaves open (the stiffness and damping phases, "
    "the backlash reading, the ω of a study), named with what it changes, and confirmed by a full computation at "
    "that reading. Contradicted: no reading tried reproduces it (where a structural fact, F1 or F2 below, decides "
    "it, the fact is checked numerically). Not testable: the paper lacks what a test needs.",
    f"Ranges are judged by length. A claim of a motion over a parameter interval holds when the grid points "
    f"showing it cover at least {100 * MATCH_REPRODUCED:.0f} % of the interval's length (each point stands for the "
    "interval between the midpoints to its neighbours), so an uneven grid cannot decide it.",
    "Every part is required. A claim that says two things (a motion and the sign or vanishing of λ1; a jump and "
    "its size trend; a motion at low and at high ξ1) holds only when all its parts hold.",
    f"Fluctuation is measured as fluctuation: the spread of the Poincaré points (RMS distance from their "
    f"centroid, zero for period-1 motion) averaged over the ω after the first jump. A trend of fluctuation holds "
    f"only where some exists (largest mean spread ≥ {FLUCT_MIN:g}) and the trend is strict.",
    "Jumps are tested by direction and location: the jump nearest the claimed ω (either sweep, within the stated "
    "tolerance) must have the claimed direction, and a jump of the opposite direction at least as close makes the "
    "claim fail; 'no jump' holds only when no jump lies within the tolerance.",
    f"Single numbers. The amplitude formula holds when its least-squares fit reaches R² ≥ "
    f"{FORMULA_R2_REPRODUCED:g}; the stability condition when a critical ξ0 from Floquet multipliers lies within "
    f"{100 * STABILITY_REL:.0f} % of it.",
)

#: A predicate on (motion, period, loops) of one grid point.
MotionTest = Callable[[int, int, int], bool]


def verdict_of(fraction: float) -> str:
    """The verdict at the default reading for the fraction (by length) of a claim's interval where it holds.

    Parameters
    ----------
    fraction : float
        Matching fraction in [0, 1] (NaN: no case, the claim does not hold).

    Returns
    -------
    str
        ``"reproduced"`` from :data:`MATCH_REPRODUCED` on, else ``"contradicted"`` (a reading may
        still reproduce it: :mod:`geardyn.paper.studies.readings`).
    """
    return "reproduced" if fraction >= MATCH_REPRODUCED else "contradicted"


def parts(*holds: bool) -> str:
    """The verdict of a claim that says several things: reproduced only when every part holds.

    Parameters
    ----------
    *holds : bool
        Whether each part holds (at least one).

    Returns
    -------
    str
    """
    return "reproduced" if holds and all(map(bool, holds)) else "contradicted"


def of_claims(verdicts: Sequence[str]) -> str:
    """The verdict of a claim made of other claims: reproduced when all are, contradicted otherwise.

    Parameters
    ----------
    verdicts : sequence of str
        The verdicts of the claims it is made of.

    Returns
    -------
    str
    """
    return parts(*(v == "reproduced" for v in verdicts))


def length_fraction(
    x: Sequence[float], ok: Sequence[bool], lo: float, hi: float, *, lo_open: bool = False, hi_open: bool = False
) -> tuple[float, float]:
    """Fraction of the length of [lo, hi] (within the grid's reach) where a claim holds.

    Each grid point stands for the interval between the midpoints to its neighbours (the first and
    last points for half a step beyond them), cut to [lo, hi]; the fraction is the length of the
    intervals of the points where the claim holds over the length of all of them.  Grid spacing
    therefore cannot decide it: ten points crowded into a small matching corner weigh what that
    corner is long.  Open ends only exclude a point lying exactly on them.

    Parameters
    ----------
    x : sequence of float
        The grid (any order, distinct values).
    ok : sequence of bool
        Whether the claim holds at each point.
    lo, hi : float
        The claimed interval (±inf for an open-ended claim: cut to the grid).
    lo_open, hi_open : bool
        Exclude points exactly on an end.

    Returns
    -------
    (float, float)
        The fraction (NaN when the interval meets no grid cell) and the length judged.
    """
    x = np.asarray(x, dtype=float)
    ok = np.asarray(ok, dtype=bool)
    order = np.argsort(x)
    x, ok = x[order], ok[order]
    if x.size == 0:
        return float("nan"), 0.0
    if x.size == 1:
        inside = (x[0] > lo if lo_open else x[0] >= lo) and (x[0] < hi if hi_open else x[0] <= hi)
        return (float(ok[0]) if inside else float("nan")), 0.0
    mid = 0.5 * (x[1:] + x[:-1])
    left = np.concatenate([[x[0] - (x[1] - x[0]) / 2], mid])
    right = np.concatenate([mid, [x[-1] + (x[-1] - x[-2]) / 2]])
    length = np.clip(np.minimum(right, hi) - np.maximum(left, lo), 0.0, None)
    if lo_open:
        length[x == lo] = 0.0
    if hi_open:
        length[x == hi] = 0.0
    total = float(length.sum())
    if total <= 0:
        return float("nan"), 0.0
    return float(length[ok].sum()) / total, total


def section_spread(points: np.ndarray) -> float:
    """The spread of a set of Poincaré points: RMS distance from their centroid (0 for period-1).

    Parameters
    ----------
    points : ndarray (m, 2)
        Section points (u, u') of one steady response; non-finite rows are ignored.

    Returns
    -------
    float
        NaN when no point is finite.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    p = p[np.all(np.isfinite(p), axis=1)]
    if p.shape[0] == 0:
        return float("nan")
    return float(np.sqrt(np.mean(np.sum((p - p.mean(axis=0)) ** 2, axis=1))))


def fluctuation_trend(values: Sequence[float], decreasing: bool) -> tuple[bool, str]:
    """Whether fluctuation measures follow a claimed trend, with the reason when they do not.

    The trend must be strict along the given order, and some fluctuation must exist (largest value
    ≥ :data:`FLUCT_MIN`): a trend of nothing cannot hold.

    Parameters
    ----------
    values : sequence of float
        The fluctuation measure at each setting, in the order of the varied parameter.
    decreasing : bool
        The claimed trend.

    Returns
    -------
    (bool, str)
    """
    v = np.asarray(values, dtype=float)
    if v.size < 2 or not np.all(np.isfinite(v)):
        return False, "not measured at every setting"
    if float(v.max()) < FLUCT_MIN:
        return False, f"no fluctuation at these settings (largest {float(v.max()):.1e} < {FLUCT_MIN:g})"
    ok = strictly_monotone(v, decreasing)
    return ok, ("strictly " if ok else "not strictly ") + ("decreasing" if decreasing else "increasing")


def strictly_monotone(values: Sequence[float], decreasing: bool) -> bool:
    """Whether at least two values, all finite, strictly decrease (``decreasing``) or strictly increase.

    Parameters
    ----------
    values : sequence of float
    decreasing : bool

    Returns
    -------
    bool
    """
    v = np.asarray(values, dtype=float)
    d = np.diff(v)
    return bool(v.size >= 2 and np.all(np.isfinite(v)) and np.all(d < 0 if decreasing else d > 0))


def yes_no(ok: bool) -> str:
    """``"yes"`` or ``"no"``, as the report's tables and texts answer.

    Parameters
    ----------
    ok : bool

    Returns
    -------
    str
    """
    return "yes" if ok else "no"


def distinct_text(values: Sequence[float], decimals: int = 3) -> list[str]:
    """The values with at least ``decimals`` decimals, and as many more as it takes for unequal neighbours to
    print unequal (a trend judged on the values is seen in their text: 0.0085, 0.0091, 0.0094, not 0.008,
    0.009, 0.009).

    Parameters
    ----------
    values : sequence of float
    decimals : int
        The fewest decimals.

    Returns
    -------
    list of str
    """
    v = [float(x) for x in values]
    for d in range(decimals, 17):
        t = [f"{x:.{d}f}" for x in v]
        if all(t[i] != t[i + 1] or v[i] == v[i + 1] for i in range(len(v) - 1)):
            return t
    return [repr(x) for x in v]


def jump_type_at(jumps: Sequence[Mapping[str, object]], omega: float, tol: float) -> str:
    """The type of jump a response shows at ``omega``: the direction of the nearest jump within ``tol``.

    Parameters
    ----------
    jumps : sequence of mapping
        Jumps with ``omega`` and ``direction`` (``"up"``/``"down"``), from either sweep.
    omega : float
        The claimed location.
    tol : float
        Largest distance in ω.

    Returns
    -------
    str
        ``"upward"`` or ``"downward"``; ``"none"`` when no jump lies within ``tol``; ``"both"``
        when jumps of both directions are equally near (neither direction is then shown).
    """
    near = [
        (d, str(j["direction"]))
        for j in jumps
        if (d := abs(float(j["omega"]) - omega)) <= tol + 1e-12  # type: ignore[arg-type]
    ]
    if not near:
        return "none"
    dmin = min(d for d, _ in near)
    dirs = {k for d, k in near if d <= dmin + 1e-12}
    if len(dirs) > 1:
        return "both"
    return dirs.pop() + "ward"


def jump_holds(jumps: Sequence[Mapping[str, object]], omega: float, claimed: str, tol: float) -> bool:
    """Whether a response shows the claimed jump type (``upward``, ``downward``, ``none``) at ``omega``.

    The opposite jump fails: see :func:`jump_type_at`.

    Parameters
    ----------
    jumps : sequence of mapping
    omega : float
    claimed : str
        ``"upward"``, ``"downward"`` or ``"none"`` (``"up"``/``"down"`` accepted).
    tol : float

    Returns
    -------
    bool
    """
    want = {"up": "upward", "down": "downward"}.get(claimed, claimed)
    return jump_type_at(jumps, omega, tol) == want


def count_text(k: int, n: int, what: str) -> str:
    """``"2 of 3 grid points (67 %)"``: the k and N of the counted-claims rule, as the report gives them.

    Parameters
    ----------
    k, n : int
        Cases holding and cases checked.
    what : str
        The cases, plural (``"grid points"``); empty for ``"2 of 3 (67 %)"``.

    Returns
    -------
    str
    """
    return f"{k} of {n}" + (f" {what}" if what else "") + (f" ({100 * k / n:.0f} %)" if n else "")


def describe_motion(motion: int, period: int, loops: int) -> str:
    """A grid point's motion in the report's words (``"period-2"``, ``"quasi-periodic (4 loops)"``…).

    Parameters
    ----------
    motion, period, loops : int
        The classification of the point (:mod:`geardyn.analysis.classify`).

    Returns
    -------
    str
    """
    return {
        MOTION_PERIODIC: f"period-{period}",
        MOTION_QUASIPERIODIC: f"quasi-periodic ({loops} loop{'s' if loops != 1 else ''})",
        MOTION_CHAOTIC: "chaotic",
    }.get(motion, "diverged" if motion < 0 else "unresolved")


def quasi_n(n: int) -> MotionTest:
    """The paper's "quasi-n-periodic": a period-n orbit.

    By F1 (the period map contracts every area by exp(−4πξ0/ω) < 1) no invariant closed curve, and
    so no quasi-periodic attractor of n loops, exists for ξ0 > 0: the words can only mean period-n.

    Parameters
    ----------
    n : int
        Number of groups.

    Returns
    -------
    callable
        ``match(motion, period, loops) -> bool``.
    """

    def match(motion: int, period: int, loops: int) -> bool:
        return motion == MOTION_PERIODIC and period == n

    return match


#: The parameters of a motion test: the signature is that of every test, not all use them all.
_motion_test = parameters(
    "motion : int\n    Motion code of the point (``MOTION_*`` of :mod:`geardyn.analysis.classify`).",
    "period : int\n    Detected period (not used by this test; the signature is that of every motion test).",
    "loops : int\n    Loops of a quasi-periodic orbit (not used by this test).",
)


@_motion_test
def is_chaotic(motion: int, period: int, loops: int) -> bool:
    """The paper's "chaotic": geardyn classifies the point as chaotic (largest exponent positive).

    Returns
    -------
    bool
    """
    return motion == MOTION_CHAOTIC


@_motion_test
def is_regular(motion: int, period: int, loops: int) -> bool:
    """The paper's unqualified "quasi-periodic" (Table 2, ξ1 rows): regular, not chaotic motion.

    Returns
    -------
    bool
    """
    return motion in (MOTION_PERIODIC, MOTION_QUASIPERIODIC)


_QUASI_N = re.compile(r"quasi-(\d+)-periodic")


def motion_rule(word: str) -> tuple[MotionTest, str]:
    """How a paper's word for a motion is tested, and how the report names the test.

    Parameters
    ----------
    word : str
        ``"chaotic"``, ``"quasi-n-periodic"`` (n an integer) or ``"quasi-periodic"``.

    Returns
    -------
    (callable, str)
        The predicate on (motion, period, loops) and its description.

    Raises
    ------
    ValueError
        For any other word.
    """
    if word == "chaotic":
        return is_chaotic, "chaotic"
    if word == "quasi-periodic":
        return is_regular, "regular (periodic or quasi-periodic)"
    m = _QUASI_N.fullmatch(word)
    if m is None:
        raise ValueError(f"unknown motion word {word!r}: expected 'chaotic', 'quasi-periodic' or 'quasi-n-periodic'")
    n = int(m.group(1))
    return quasi_n(n), f"quasi-{n}-periodic (read as period-{n}, by F1)"


def range_of(numbers: Mapping[str, object]) -> tuple[float, float, bool, bool]:
    """A claim's parameter range (lo, hi, lo_open, hi_open); a missing end is unbounded.

    Parameters
    ----------
    numbers : mapping
        A claim's numbers (:attr:`geardyn.paper.claims.Claim.numbers`).

    Returns
    -------
    tuple
    """
    return (
        float(numbers.get("lo", -np.inf)),
        float(numbers.get("hi", np.inf)),  # type: ignore[arg-type]
        bool(numbers.get("lo_open", False)),
        bool(numbers.get("hi_open", False)),
    )


def motion_fields(ds: xr.Dataset, sweep: str | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Motion, period and loops of a bifurcation Dataset (its first sweep unless named), as ints.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``bifurcation`` or ``response`` result.
    sweep : str, optional
        The sweep to read; default the first.

    Returns
    -------
    tuple of numpy.ndarray
    """
    s = ds.isel(sweep=0) if sweep is None else ds.sel(sweep=sweep)
    return s["motion"].values.astype(int), s["period"].values.astype(int), s["loops"].values.astype(int)


def match_fraction(
    ds: xr.Dataset, param: str, lo: float, hi: float, pred: MotionTest, *, lo_open: bool = False, hi_open: bool = False
) -> tuple[float, int]:
    """Fraction, by length (:func:`length_fraction`), of [lo, hi] where the motion satisfies ``pred``.

    Parameters
    ----------
    ds : xarray.Dataset
        A bifurcation diagram.
    param : str
        Its parameter (the grid's coordinate).
    lo, hi : float
        The range.
    pred : callable
        The claimed motion (:func:`motion_rule`).
    lo_open, hi_open : bool
        Exclude grid points exactly on the ends.

    Returns
    -------
    (float, int)
        The fraction (NaN if no grid cell meets the range) and the number of grid points in the range.
    """
    x = ds[param].values
    m, n, l = motion_fields(ds)
    ok = np.vectorize(pred, otypes=[bool])(m, n, l)
    frac, _ = length_fraction(x, ok, lo, hi, lo_open=lo_open, hi_open=hi_open)
    sel = ((x > lo) if lo_open else (x >= lo - 1e-12)) & ((x < hi) if hi_open else (x <= hi + 1e-12))
    return frac, int(sel.sum())


def motion_runs(ds: xr.Dataset, param: str) -> list[tuple[float, float, str]]:
    """Consecutive grid runs with the same motion description: (from, to, description).

    Parameters
    ----------
    ds : xarray.Dataset
        A bifurcation result over ``param``.
    param : str
        The swept parameter.

    Returns
    -------
    list of (float, float, str)
    """
    pts = [
        (float(v), describe_motion(int(a), int(b), int(c))) for v, a, b, c in zip(ds[param].values, *motion_fields(ds))
    ]
    return [(g[0][0], g[-1][0], d) for d, run in groupby(pts, key=lambda p: p[1]) for g in [list(run)]]


def runs_text(runs: Sequence[tuple[float, float, str]], fmt: str = "{:.3g}") -> str:
    """The runs of :func:`motion_runs` as one line: ``"0.02–0.05: chaotic; 0.06: period-4"``.

    Parameters
    ----------
    runs : sequence of (float, float, str)
    fmt : str
        Format of the parameter values.

    Returns
    -------
    str
    """
    return "; ".join(f"{fmt.format(a)}{'' if a == b else '–' + fmt.format(b)}: {d}" for a, b, d in runs)
