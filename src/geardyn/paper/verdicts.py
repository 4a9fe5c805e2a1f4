"""How the studies read the paper's words and turn computed results into verdicts.

The verdict rules are stated once, here (:data:`VERDICT_RULES`, which the report quotes), and
every study applies them through the functions of this module:

- a claim checked on N cases (grid points of a range, responses, values, or the parts of a claim
  with several parts) with k of them holding: :func:`verdict_of` (k/N ≥ :data:`MATCH_REPRODUCED`
  → reproduced; ≥ :data:`MATCH_PARTLY` → partly reproduced; else not reproduced; 0 of N is
  therefore never "partly");
- a claim that fails at the study's chosen setting but holds at a searched one (another ω, the
  other reading of the paper's b): :func:`elsewhere` (at most partly reproduced);
- a claim made of other claims: :func:`of_claims`;
- single-number claims: the formula fit (:data:`FORMULA_R2_REPRODUCED`, :data:`FORMULA_R2_PARTLY`)
  and the stability condition (:data:`STABILITY_REL`).

:func:`motion_rule` maps the paper's words for motions onto geardyn's classification, once for
every study.
"""

from __future__ import annotations

import re
from typing import Callable, Mapping, Sequence

import numpy as np
import xarray as xr

from .._docfill import parameters
from ..analysis.classify import MOTION_CHAOTIC, MOTION_PERIODIC, MOTION_QUASIPERIODIC
from .report import VERDICTS

__all__ = [
    "FORMULA_R2_PARTLY",
    "FORMULA_R2_REPRODUCED",
    "MATCH_PARTLY",
    "MATCH_REPRODUCED",
    "STABILITY_REL",
    "VERDICTS",
    "VERDICT_RULES",
    "combine",
    "count_text",
    "elsewhere",
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
]

#: Fraction of matching cases for "reproduced" / "partly reproduced" (MATCH_PARTLY > 0: 0 of N is "not").
MATCH_REPRODUCED = 0.8
MATCH_PARTLY = 0.3
#: The amplitude formula: coefficient of determination R² of the fit for "reproduced" / "partly reproduced".
FORMULA_R2_REPRODUCED = 0.9
FORMULA_R2_PARTLY = 0.5
#: The stability condition is reproduced when a computed critical ξ0 lies within this relative distance of it.
STABILITY_REL = 0.1

#: The verdict rules as the report states them (once, in its Settings section).
VERDICT_RULES: tuple[str, ...] = (
    f"Counted claims. A claim is checked on N cases: the grid points of a parameter range, the responses or "
    f"values it speaks of, or the parts of a claim that says several things. With k of the N holding, it is "
    f"reproduced if k/N ≥ {100 * MATCH_REPRODUCED:.0f} %, partly reproduced if k/N ≥ {100 * MATCH_PARTLY:.0f} %, "
    f"and not reproduced otherwise; 0 of N is never partly reproduced. The report gives k and N.",
    "Elsewhere only. A claim that is not reproduced at the setting its study chose (the ω of the damping and "
    "backlash studies, the reading D = b/2 of the paper's b in mm) but holds in full at a searched ω or under the "
    "reading D = b is partly reproduced, and the report names where it holds. A claim is never upgraded further.",
    "Claims made of other claims (the sequence of motions along ξ1, whose ends are Table 2 rows 4 and 5) are "
    "reproduced when all of those are, not reproduced when none of them holds even partly, and partly reproduced "
    "otherwise.",
    f"Single numbers. The amplitude formula is reproduced when its least-squares fit reaches R² ≥ "
    f"{FORMULA_R2_REPRODUCED:g}, partly reproduced for R² ≥ {FORMULA_R2_PARTLY:g}; the stability condition is "
    f"reproduced when a critical ξ0 from Floquet multipliers lies within {100 * STABILITY_REL:.0f} % of it.",
)

#: A predicate on (motion, period, loops) of one grid point.
MotionTest = Callable[[int, int, int], bool]


def verdict_of(fraction: float) -> str:
    """The verdict for the fraction k/N of the cases of a claim that hold (the counted-claims rule).

    Parameters
    ----------
    fraction : float
        Matching fraction in [0, 1] (NaN: no case, not reproduced).

    Returns
    -------
    str
        ``"reproduced"``, ``"partly reproduced"`` or ``"not reproduced"``.
    """
    if fraction >= MATCH_REPRODUCED:
        return "reproduced"
    if fraction >= MATCH_PARTLY:
        return "partly reproduced"
    return "not reproduced"


def parts(*holds: bool) -> str:
    """The verdict of a claim that says several things, by how many of them hold (the counted-claims rule).

    Parameters
    ----------
    *holds : bool
        Whether each part holds (at least one).

    Returns
    -------
    str
    """
    return verdict_of(sum(map(bool, holds)) / len(holds))


def combine(both_ok: bool, either_ok: bool) -> str:
    """The verdict of a claim with two parts: both hold → reproduced, one → partly, none → not.

    The counted-claims rule with N = 2 (:func:`parts`).

    Parameters
    ----------
    both_ok, either_ok : bool
        Whether all parts hold, and whether at least one does.

    Returns
    -------
    str
    """
    return "reproduced" if both_ok else ("partly reproduced" if either_ok else "not reproduced")


def elsewhere(verdict: str, holds_elsewhere: bool) -> str:
    """The elsewhere-only rule: a claim not reproduced at its study's setting that holds in full at a
    searched one is partly reproduced; any other verdict stands.

    Parameters
    ----------
    verdict : str
        The verdict at the study's setting.
    holds_elsewhere : bool
        Whether the claim holds in full at a searched ω or under the other reading of b.

    Returns
    -------
    str
    """
    return "partly reproduced" if verdict == "not reproduced" and holds_elsewhere else verdict


def of_claims(verdicts: Sequence[str]) -> str:
    """The verdict of a claim made of other claims: all reproduced → reproduced, none holding even
    partly → not reproduced, else partly reproduced.

    Parameters
    ----------
    verdicts : sequence of str
        The verdicts of the claims it is made of.

    Returns
    -------
    str
    """
    return combine(all(v == "reproduced" for v in verdicts), any(v != "not reproduced" for v in verdicts))


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
    if motion == MOTION_PERIODIC:
        return f"period-{period}"
    if motion == MOTION_QUASIPERIODIC:
        return f"quasi-periodic ({loops} loop{'s' if loops != 1 else ''})"
    if motion == MOTION_CHAOTIC:
        return "chaotic"
    if motion < 0:
        return "diverged"
    return "unresolved"


def quasi_n(n: int) -> MotionTest:
    """The paper's "quasi-n-periodic": n groups of Poincaré points.

    A period-n orbit, or a quasi-periodic response whose section is n closed loops (a torus born
    from a period-n orbit).

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
        return (motion == MOTION_PERIODIC and period == n) or (motion == MOTION_QUASIPERIODIC and loops == n)

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
    return quasi_n(n), f"quasi-{n}-periodic (period-{n} or {n} loops)"


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
    return (float(numbers.get("lo", -np.inf)), float(numbers.get("hi", np.inf)),  # type: ignore[arg-type]
            bool(numbers.get("lo_open", False)), bool(numbers.get("hi_open", False)))


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


def match_fraction(ds: xr.Dataset, param: str, lo: float, hi: float, pred: MotionTest,
                   *, lo_open: bool = False, hi_open: bool = False) -> tuple[float, int]:
    """Fraction of grid points with lo ≤ p ≤ hi (ends open on request) whose motion satisfies ``pred``.

    Parameters
    ----------
    ds : xarray.Dataset
        A bifurcation diagram.
    param : str
        Its parameter (the grid's coordinate).
    lo, hi : float
        The range (closed within 1e-12 unless open).
    pred : callable
        The claimed motion (:func:`motion_rule`).
    lo_open, hi_open : bool
        Exclude the ends.

    Returns
    -------
    (float, int)
        The fraction (NaN if no grid point is in the range) and the number of points in the range.
    """
    x = ds[param].values
    m, n, l = motion_fields(ds)
    sel = ((x > lo) if lo_open else (x >= lo - 1e-12)) & ((x < hi) if hi_open else (x <= hi + 1e-12))
    idx = np.flatnonzero(sel)
    if idx.size == 0:
        return float("nan"), 0
    ok = sum(pred(int(m[i]), int(n[i]), int(l[i])) for i in idx)
    return ok / idx.size, int(idx.size)


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
    x = ds[param].values
    m, n, l = motion_fields(ds)
    runs: list[tuple[float, float, str]] = []
    for i in range(x.size):
        d = describe_motion(int(m[i]), int(n[i]), int(l[i]))
        if runs and runs[-1][2] == d:
            runs[-1] = (runs[-1][0], float(x[i]), d)
        else:
            runs.append((float(x[i]), float(x[i]), d))
    return runs


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
    parts = []
    for a, b, d in runs:
        rng = fmt.format(a) if a == b else f"{fmt.format(a)}–{fmt.format(b)}"
        parts.append(f"{rng}: {d}")
    return "; ".join(parts)
