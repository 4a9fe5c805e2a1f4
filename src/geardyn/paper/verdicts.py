"""How the studies read the paper's words and turn computed motions into verdicts.

The verdict rule for a claimed motion over a parameter range: the fraction of grid points in the
range whose motion matches the claim is ≥ :data:`MATCH_REPRODUCED` → reproduced;
≥ :data:`MATCH_PARTLY` → partly reproduced; else not reproduced.  :func:`motion_rule` maps the
paper's words for motions onto geardyn's classification, once for every study.
"""

from __future__ import annotations

import re
from typing import Callable, Mapping, Sequence

import numpy as np
import xarray as xr

from ..analysis.classify import MOTION_CHAOTIC, MOTION_PERIODIC, MOTION_QUASIPERIODIC

__all__ = [
    "MATCH_PARTLY",
    "MATCH_REPRODUCED",
    "combine",
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

#: Fraction of matching grid points for "reproduced" / "partly reproduced".
MATCH_REPRODUCED = 0.8
MATCH_PARTLY = 0.3

#: A predicate on (motion, period, loops) of one grid point.
MotionTest = Callable[[int, int, int], bool]


def verdict_of(fraction: float) -> str:
    """The verdict for the fraction of grid points that match a claim.

    Parameters
    ----------
    fraction : float
        Matching fraction in [0, 1] (NaN: no grid point in the range).

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


def combine(both_ok: bool, either_ok: bool) -> str:
    """The verdict of a claim with two parts: both hold → reproduced, one → partly, none → not.

    Parameters
    ----------
    both_ok, either_ok : bool
        Whether all parts hold, and whether at least one does.

    Returns
    -------
    str
    """
    return "reproduced" if both_ok else ("partly reproduced" if either_ok else "not reproduced")


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


def is_chaotic(motion: int, period: int, loops: int) -> bool:
    """The paper's "chaotic": geardyn classifies the point as chaotic (largest exponent positive)."""
    return motion == MOTION_CHAOTIC


def is_regular(motion: int, period: int, loops: int) -> bool:
    """The paper's unqualified "quasi-periodic" (Table 2, ξ1 rows): regular, not chaotic motion."""
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
