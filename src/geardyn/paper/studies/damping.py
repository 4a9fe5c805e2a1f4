"""The damping study: Table 2 and the text on ξ0 and ξ1 (bifurcation diagrams over each).

A claimed motion over a range of ξ0 or ξ1 is judged by the fraction of grid points in the range
whose motion matches (:mod:`geardyn.paper.verdicts`); where that fails at the stated ω, ω is
searched (on coarser grids) for where the claim does hold, and the verdict is then at most
"partly reproduced" (the rules of :mod:`geardyn.paper.verdicts`).  The ω search is shown as a heat
map, and the ξ0 diagram also over :attr:`Settings.xi0_zoom`, where its structure lies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import xarray as xr

from ...analysis.classify import MOTION_CHAOTIC
from ..claims import CLAIMS, Claim
from ...io import json_attr
from ..report import Finding, Section
from ..settings import Context, model_text
from ..table1 import TABLE1
from ..verdicts import (
    MATCH_REPRODUCED,
    MotionTest,
    count_text,
    elsewhere,
    match_fraction,
    motion_fields,
    motion_rule,
    motion_runs,
    of_claims,
    parts,
    range_of,
    runs_text,
    verdict_of,
)

__all__ = ["RangeTest", "judge_ranges", "study_xi0", "study_xi1"]

#: XI0-BIF: the chaos below this ξ0 ends at the first bifurcation point ...
LOW_CHAOS_BELOW = 0.3
#: ... and chaos from this ξ0 on is the return to chaos at the second.
HIGH_CHAOS_FROM = 0.5
#: XI0-BIF: largest distances (in ξ0) of the computed points from the paper's first and second point.
BIF_NEAR = (0.02, 0.1)

_WORDS = ("'quasi-n-periodic' = n groups of Poincaré points (a period-n orbit, or a quasi-periodic torus "
          "section of n loops); 'chaotic' = largest exponent significantly positive.")


@dataclass(frozen=True)
class RangeTest:
    """A claim of a motion over a parameter range (a row of Table 2), ready to test on a grid.

    Parameters
    ----------
    claim : Claim
        The claim; its numbers give ``param``, the range and the ``motion`` word.
    lo, hi : float
        The range (±inf for an end the paper leaves open).
    lo_open, hi_open : bool
        Whether the ends are excluded.
    pred : callable
        The motion test (:func:`geardyn.paper.verdicts.motion_rule`).
    what : str
        The test in words, for the report.
    """

    claim: Claim
    lo: float
    hi: float
    lo_open: bool
    hi_open: bool
    pred: MotionTest
    what: str

    @classmethod
    def of(cls, claim: Claim, **bounds: Any) -> "RangeTest":
        """The test of ``claim``; ``bounds`` (``hi=…, hi_open=…``) close an end the paper leaves open.

        Parameters
        ----------
        claim : Claim
        **bounds
            Overrides of ``lo``, ``hi``, ``lo_open``, ``hi_open``.

        Returns
        -------
        RangeTest
        """
        lo, hi, lo_open, hi_open = range_of({**claim.numbers, **bounds})
        return cls(claim, lo, hi, lo_open, hi_open, *motion_rule(claim.numbers["motion"]))

    @property
    def param(self) -> str:
        """The swept parameter of the claim."""
        return str(self.claim.numbers["param"])

    def fraction(self, ds: xr.Dataset) -> tuple[float, int]:
        """Matching fraction and number of grid points in the range (:func:`match_fraction`)."""
        return match_fraction(ds, self.param, self.lo, self.hi, self.pred, lo_open=self.lo_open,
                              hi_open=self.hi_open)


def judge_ranges(ctx: Context, ds: xr.Dataset, rows: Sequence[RangeTest], search_grid: Sequence[float],
                 evidence: list[str], search_name: str) -> tuple[list[Finding], dict[float, list[float]]]:
    """Judge range claims at the stated ω; where one fails, search ω for where it holds.

    Parameters
    ----------
    ctx : Context
    ds : xarray.Dataset
        The bifurcation diagram at the stated ω.
    rows : sequence of RangeTest
        The claims, all over the same parameter.
    search_grid : sequence of float
        The parameter grid of the ω search.
    evidence : list of str
        Evidence of every claim (the search data is added when there is a search).
    search_name : str
        Name of the saved search Dataset.

    Returns
    -------
    (list of Finding, dict)
        The judged claims, and the matching fractions of each claim by searched ω.
    """
    w0 = ctx.settings.omega_damping
    param = rows[0].param
    sym = SYMBOL[param]
    results = {r.claim.id: r.fraction(ds) for r in rows}
    search: dict[float, list[tuple[float, int]]] = {}
    if any(verdict_of(f) != "reproduced" for f, _ in results.values()):
        for w in ctx.settings.search_omegas:
            if abs(w - w0) < 1e-12:
                continue
            dsw = ctx.bifurcation(ctx.base.replace(omega=float(w)), param, search_grid)
            search[float(w)] = [r.fraction(dsw) for r in rows]
        if search:
            attrs = {"geardyn_kind": "search", "model": json_attr(ctx.base), "param": param,
                     "grid": list(map(float, search_grid))}
            ctx.save(search_name, xr.Dataset(
                {"match_fraction": (("omega", "claim"), np.array([[f for f, _ in search[w]] for w in sorted(search)]))},
                coords={"omega": sorted(search), "claim": [r.claim.id for r in rows]}, attrs=attrs),
                f"ω search of the claims over {sym} ({model_text(ctx.base, skip=('omega', param))})")
            evidence = evidence + [ctx.datasets[search_name], ctx.figure(search_name)]
    claims = []
    for i, r in enumerate(rows):
        f, npts = results[r.claim.id]
        v = verdict_of(f)
        text = f"at ω = {w0:g}: {r.what} at {count_text(_count(f, npts), npts, 'grid points of the range')}."
        if v != "reproduced" and search:
            ok_w = [w for w in sorted(search) if search[w][i][0] >= MATCH_REPRODUCED]
            best_w = max(sorted(search), key=lambda w: search[w][i][0])
            if ok_w:
                text += " Searching ω (coarser grid): it holds at " + "; ".join(
                    f"ω = {w:g} with {count_text(_count(*search[w][i]), search[w][i][1], 'grid points')}" for w in ok_w) + "."
            else:
                bf, bn = search[best_w][i]
                text += (f" Searching ω ∈ {{{', '.join(f'{w:g}' for w in sorted(search))}}} (coarser grid): at best "
                         f"{count_text(_count(bf, bn), bn, 'grid points')} at ω = {best_w:g}.")
            v = elsewhere(v, bool(ok_w))
        claims.append(r.claim.judge(text, v, evidence))
    return claims, {w: [f for f, _ in fs] for w, fs in search.items()}


def _count(fraction: float, n: int) -> int:
    """The number of matching points behind a matching fraction of ``n`` points."""
    return int(round(fraction * n)) if n else 0


#: The report's symbols for the swept damping parameters.
SYMBOL = {"xi0": "ξ0", "xi1": "ξ1", "D": "D", "omega": "ω"}


def _diagram(ctx: Context, param: str, grid: Sequence[float]) -> tuple[xr.Dataset, list[str]]:
    ds = ctx.bifurcation(ctx.base, param, grid, lyapunov=True)
    name = f"{param}_bifurcation"
    label = f"bifurcation diagram over {SYMBOL[param]} ({model_text(ctx.base, skip=(param,))})"
    return ds, [ctx.save(name, ds, label), ctx.figure(name)]


def study_xi0(ctx: Context) -> Section:
    """Table 2 rows 1–3 and the ξ0 bifurcation points of the text (XI0-BIF).

    Parameters
    ----------
    ctx : Context
        The run; ``xi0_grid`` and ``search_xi0`` are its grids.

    Returns
    -------
    Section
        T2-1, T2-2, T2-3 and XI0-BIF.
    """
    s = ctx.settings
    ctx.log("ξ0 bifurcation diagram")
    ds, ev = _diagram(ctx, "xi0", s.xi0_grid)
    first, second = CLAIMS["XI0-BIF"].numbers["points"]
    # Table 2 leaves ξ0 > 0.1 open above; the text ends that motion at the second bifurcation point
    rows = [RangeTest.of(CLAIMS["T2-1"]), RangeTest.of(CLAIMS["T2-2"]),
            RangeTest.of(CLAIMS["T2-3"], hi=second, hi_open=True)]
    claims, _ = judge_ranges(ctx, ds, rows, s.search_xi0, ev, "xi0_search")
    x = ds["xi0"].values
    m, _, _ = motion_fields(ds)
    chaotic = x[m == MOTION_CHAOTIC]
    low = chaotic < LOW_CHAOS_BELOW
    last_low_chaos = float(chaotic[low].max()) if np.any(low) else float("nan")
    high_chaos = chaotic[chaotic >= HIGH_CHAOS_FROM]
    text = (f"at ω = {s.omega_damping:g}: largest chaotic ξ0 below {LOW_CHAOS_BELOW:g} is {last_low_chaos:.3g}"
            if np.isfinite(last_low_chaos) else f"at ω = {s.omega_damping:g}: no chaos below ξ0 = {LOW_CHAOS_BELOW:g}")
    text += ("; chaos returns at ξ0 = " + ", ".join(f"{v:.3g}" for v in high_chaos)) if high_chaos.size else \
        f"; no chaos for ξ0 ≥ {HIGH_CHAOS_FROM:g} (the high-damping response is periodic)"
    first_ok = bool(np.isfinite(last_low_chaos) and abs(last_low_chaos - first) <= BIF_NEAR[0])
    second_ok = bool(np.any(np.abs(high_chaos - second) <= BIF_NEAR[1]))
    text += (f". Bifurcation points found: {count_text(first_ok + second_ok, 2, '')}; within ±{BIF_NEAR[0]:g} "
             f"of ξ0 = {first:g}: {_yes(first_ok)}, within ±{BIF_NEAR[1]:g} of ξ0 = {second:g}: {_yes(second_ok)}")
    text += f". Motion along ξ0: {runs_text(motion_runs(ds, 'xi0'))}."
    claims.append(CLAIMS["XI0-BIF"].judge(text, parts(first_ok, second_ok), ev))
    figures = [(ev[1], f"Bifurcation diagram over ξ0 with the largest Lyapunov exponent, "
                       f"{model_text(ctx.base, skip=('xi0',))}")]
    lo, hi = s.xi0_zoom
    x = ds["xi0"].values
    inside = (x >= lo - 1e-12) & (x <= hi + 1e-12)
    if 2 <= inside.sum() < x.size:
        zoom = ds.isel(xi0=np.flatnonzero(inside))
        ctx.save("xi0_bifurcation_zoom", zoom, f"bifurcation diagram over ξ0 ∈ [{lo:g}, {hi:g}] "
                                               f"({model_text(ctx.base, skip=('xi0',))})")
        figures.append((ctx.figure("xi0_bifurcation_zoom"),
                        f"The same diagram over ξ0 ∈ [{lo:g}, {hi:g}], where its structure lies (the paper's first "
                        f"bifurcation point ξ0 = {first:g} and the Table 2 rows), {model_text(ctx.base, skip=('xi0',))}"))
        for c in claims:
            c.evidence.append(ctx.figure("xi0_bifurcation_zoom"))
    figures += _search_figure(ctx, "xi0_search", "xi0")
    return Section(
        "Mean damping ξ0 (Table 2, rows 1–3)",
        [f"Bifurcation diagram over ξ0 at ω = {s.omega_damping:g} (the paper does not state ω; see Settings), every "
         f"point from u = u' = 0, {s.transient} transient and {s.periods} recorded periods, exponents on every point. "
         f"The grid is fine over ξ0 ∈ [{lo:g}, {hi:g}], where the motions change, and coarse above; the diagram is "
         f"shown whole and over that interval.",
         "Mapping of the paper's words: " + _WORDS],
        figures,
        claims,
    )


def _yes(ok: bool) -> str:
    return "yes" if ok else "no"


def _search_figure(ctx: Context, name: str, param: str) -> list[tuple[str, str]]:
    """The heat map of the ω search saved as ``name``, if the search ran."""
    if name not in ctx.datasets:
        return []
    return [(ctx.figure(name), f"ω search: fraction of the grid points over {SYMBOL[param]} (coarser grid) that match "
                               f"each claim, at each searched ω ({model_text(ctx.base, skip=('omega', param))})")]


def study_xi1(ctx: Context) -> Section:
    """Table 2 rows 4–5 and the text: ξ1 drives quasi-periodic motion into chaos (XI1-CHAOS).

    Parameters
    ----------
    ctx : Context
        Its settings hold the ξ1 grid and the coarser ξ1 grid of the ω search.

    Returns
    -------
    Section
        The judged T2-4 and T2-5, and XI1-CHAOS (the sequence of motions along ξ1).
    """
    s = ctx.settings
    ctx.log("ξ1 bifurcation diagram")
    ds, ev = _diagram(ctx, "xi1", s.xi1_grid)
    rows = [RangeTest.of(CLAIMS["T2-4"]), RangeTest.of(CLAIMS["T2-5"])]
    claims, _ = judge_ranges(ctx, ds, rows, s.search_xi1, ev, "xi1_search")
    ends = [c.verdict for c in claims]
    claims.append(CLAIMS["XI1-CHAOS"].judge(
        f"at ω = {s.omega_damping:g}, motion along ξ1: {runs_text(motion_runs(ds, 'xi1'))}. The sequence's ends are "
        f"Table 2 rows 4 and 5: regular at low ξ1 (T2-4) {ends[0]}, chaotic at high ξ1 (T2-5) {ends[1]}.",
        of_claims(ends), ev))
    return Section(
        "Harmonic damping ξ1 (Table 2, rows 4–5)",
        [f"Bifurcation diagram over ξ1 at ω = {s.omega_damping:g}, other values from Table 1. The paper's Table 2 "
         f"puts its default point (ξ0 = {TABLE1['xi0']:g}, ξ1 = {TABLE1['xi1']:g}) both in the quasi-4-periodic row "
         f"(ξ0 ≤ {CLAIMS['T2-2'].numbers['hi']:g}) and in the chaotic row (ξ1 ≥ {CLAIMS['T2-5'].numbers['lo']:g}): "
         "the two studies cannot share one ω unless the boundary case decides it."],
        [(ev[1], f"Bifurcation diagram over ξ1 with the largest Lyapunov exponent, {model_text(ctx.base, skip=('xi1',))}"),
         *_search_figure(ctx, "xi1_search", "xi1")],
        claims,
    )
