"""The damping study: Table 2 and the text on ξ0 and ξ1 (bifurcation diagrams over each).

A claimed motion over a range of ξ0 or ξ1 is judged at the default reading (ω = 1, phases 0) by
the fraction of the range's length where the motion matches (:mod:`geardyn.paper.verdicts`), on
diagrams whose doubtful labels are re-examined (:func:`geardyn.analysis.confirm.confirm_sweep`,
F1).  The other readings are tried by :mod:`geardyn.paper.studies.readings`.  The ξ0 diagram is
also shown over :attr:`Settings.xi0_zoom`, where its structure lies.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from ...analysis.confirm import confirm_sweep
from ..claims import CLAIMS
from ..report import Finding, Section
from ..settings import SYMBOLS, Context, model_text
from ..table1 import TABLE1
from ..verdicts import (
    MATCH_REPRODUCED,
    count_text,
    motion_fields,
    motion_rule,
    motion_runs,
    of_claims,
    parts,
    runs_text,
    verdict_of,
    yes_no,
)
from .readings import BIF_NEAR, HIGH_CHAOS_FROM, LOW_CHAOS_BELOW, bif_points, range_match

__all__ = ["judge_ranges", "study_xi0", "study_xi1"]

_WORDS = (
    "'quasi-n-periodic' = a period-n orbit (by F1 no quasi-periodic torus exists for ξ0 > 0); 'chaotic' = "
    "largest exponent significantly positive; labels of closed curves, λ1 ≈ 0 or period-2n are re-examined by a "
    "longer exponent run or shooting."
)


def judge_ranges(ctx: Context, ds: xr.Dataset, cids: Sequence[str], evidence: list[str]) -> list[Finding]:
    """Judge range claims at the default reading by the fraction of each interval's length where they hold.

    The other readings (ω, phases) are tried by the readings study (:mod:`geardyn.paper.studies.readings`).

    Parameters
    ----------
    ctx : Context
    ds : xarray.Dataset
        The bifurcation diagram at the default ω (labels re-examined by :func:`geardyn.analysis.confirm.confirm_sweep`).
    cids : sequence of str
        The claims (rows of Table 2), all over the same parameter; their intervals are
        :func:`geardyn.paper.studies.readings.claim_range`.
    evidence : list of str
        Evidence of every claim.

    Returns
    -------
    list of Finding
    """
    w0 = ctx.settings.omega_damping
    claims = []
    for cid in cids:
        f, npts = range_match(ds, cid)
        what = motion_rule(CLAIMS[cid].numbers["motion"])[1]
        text = (
            f"at ω = {w0:g}: {what} over {100 * f:.0f} % of the interval's length ({npts} grid points in it; "
            f"holds from {100 * MATCH_REPRODUCED:.0f} %)."
            if np.isfinite(f)
            else f"at ω = {w0:g}: no grid point in the interval."
        )
        claims.append(CLAIMS[cid].judge(text, verdict_of(f), evidence))
    return claims


def _diagram(ctx: Context, param: str, grid: Sequence[float]) -> tuple[xr.Dataset, list[str]]:
    ds = confirm_sweep(
        ctx.bifurcation(ctx.base, param, grid, lyapunov=True),
        ctx.base,
        param,
        long_periods=ctx.settings.confirm_periods,
    )
    name = f"{param}_bifurcation"
    label = f"bifurcation diagram over {SYMBOLS[param]} ({model_text(ctx.base, skip=(param,))})"
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
    # Table 2 leaves ξ0 > 0.1 open above; the text ends that motion at the second bifurcation point (claim_range)
    claims = judge_ranges(ctx, ds, ["T2-1", "T2-2", "T2-3"], ev)
    last_low_chaos, high_chaos, first_ok, second_ok = bif_points(ds["xi0"].values, motion_fields(ds)[0])
    text = (
        f"at ω = {s.omega_damping:g}: largest chaotic ξ0 below {LOW_CHAOS_BELOW:g} is {last_low_chaos:.3g}"
        if np.isfinite(last_low_chaos)
        else f"at ω = {s.omega_damping:g}: no chaos below ξ0 = {LOW_CHAOS_BELOW:g}"
    )
    text += (
        ("; chaos returns at ξ0 = " + ", ".join(f"{v:.3g}" for v in high_chaos))
        if high_chaos.size
        else f"; no chaos for ξ0 ≥ {HIGH_CHAOS_FROM:g} (the high-damping response is periodic)"
    )
    text += (
        f". Bifurcation points found: {count_text(first_ok + second_ok, 2, '')}; within ±{BIF_NEAR[0]:g} "
        f"of ξ0 = {first:g}: {yes_no(first_ok)}, within ±{BIF_NEAR[1]:g} of ξ0 = {second:g}: {yes_no(second_ok)}"
    )
    text += f". Motion along ξ0: {runs_text(motion_runs(ds, 'xi0'))}."
    claims.append(CLAIMS["XI0-BIF"].judge(text, parts(first_ok, second_ok), ev))
    figures = [
        (
            ev[1],
            f"Bifurcation diagram over ξ0 with the largest Lyapunov exponent, {model_text(ctx.base, skip=('xi0',))}",
        )
    ]
    lo, hi = s.xi0_zoom
    x = ds["xi0"].values
    inside = (x >= lo - 1e-12) & (x <= hi + 1e-12)
    if 2 <= inside.sum() < x.size:
        zoom = ds.isel(xi0=np.flatnonzero(inside))
        ctx.save(
            "xi0_bifurcation_zoom",
            zoom,
            f"bifurcation diagram over ξ0 ∈ [{lo:g}, {hi:g}] ({model_text(ctx.base, skip=('xi0',))})",
        )
        figures.append(
            (
                ctx.figure("xi0_bifurcation_zoom"),
                f"The same diagram over ξ0 ∈ [{lo:g}, {hi:g}], where its structure lies (the paper's first "
                f"bifurcation point ξ0 = {first:g} and the Table 2 rows), {model_text(ctx.base, skip=('xi0',))}",
            )
        )
        for c in claims:
            c.evidence.append(ctx.figure("xi0_bifurcation_zoom"))
    return Section(
        "Mean damping ξ0 (Table 2, rows 1–3)",
        [
            f"Bifurcation diagram over ξ0 at ω = {s.omega_damping:g} (the paper does not state ω; see Settings), every "
            f"point from u = u' = 0, {s.transient} transient and {s.periods} recorded periods, exponents on every "
            f"point. The grid is fine over ξ0 ∈ [{lo:g}, {hi:g}], where the motions change, and coarse above; the "
            f"diagram is shown whole and over that interval.",
            "Mapping of the paper's words: " + _WORDS,
        ],
        figures,
        claims,
    )


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
    claims = judge_ranges(ctx, ds, ["T2-4", "T2-5"], ev)
    ends = [c.verdict for c in claims]
    claims.append(
        CLAIMS["XI1-CHAOS"].judge(
            f"at ω = {s.omega_damping:g}, motion along ξ1: {runs_text(motion_runs(ds, 'xi1'))}. The sequence's ends "
            f"are Table 2 rows 4 and 5: regular at low ξ1 (T2-4) {ends[0]}, chaotic at high ξ1 (T2-5) {ends[1]}.",
            of_claims(ends),
            ev,
        )
    )
    return Section(
        "Harmonic damping ξ1 (Table 2, rows 4–5)",
        [
            f"Bifurcation diagram over ξ1 at ω = {s.omega_damping:g}, other values from Table 1. The paper's Table 2 "
            f"puts its default point (ξ0 = {TABLE1['xi0']:g}, ξ1 = {TABLE1['xi1']:g}) both in the quasi-4-periodic row "
            f"(ξ0 ≤ {CLAIMS['T2-2'].numbers['hi']:g}) and in the chaotic row (ξ1 ≥ {CLAIMS['T2-5'].numbers['lo']:g}): "
            "the two studies cannot share one ω unless the boundary case decides it."
        ],
        [
            (
                ev[1],
                "Bifurcation diagram over ξ1 with the largest Lyapunov exponent, "
                f"{model_text(ctx.base, skip=('xi1',))}",
            ),
        ],
        claims,
    )
