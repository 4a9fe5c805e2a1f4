"""Stability: the paper's condition ξ0 = ½√(1 − κ1²) against Floquet analysis, and the periodic
orbits behind the first jump (continuation, folds against the hysteresis of the sweeps)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from ...analysis.bifurcation import bifurcation, sweep_values
from ...analysis.periodic import compare_stability_condition, continuation
from ...io import attach, attached
from ...model import GearModel, IntegrationOptions
from ...plot.periodic import SWEEP_CONTEXT
from ..claims import CLAIMS
from ..report import Section
from ..settings import Context, model_text
from ..table1 import TABLE1
from ..verdicts import STABILITY_REL, parts
from .jumps import JumpData, hysteresis_of

__all__ = ["STABILITY_REL", "gaps_text", "jump_continuation", "study_orbits", "study_stability"]


def study_stability(ctx: Context) -> Section:
    """The stability condition ξ0 = ½√(1 − κ1²) (STABILITY) against Floquet analysis over ω.

    Parameters
    ----------
    ctx : Context
        Uses ``stability_omegas``.

    Returns
    -------
    Section
        One claim: STABILITY.
    """
    s = ctx.settings
    ctx.log("stability condition against Floquet analysis")
    ds = compare_stability_condition(ctx.base, s.stability_omegas)
    rel = ctx.save(
        "stability_condition",
        ds,
        f"Floquet stability boundaries over ω ({model_text(ctx.base, skip=('omega', 'xi0'))})",
    )
    paper = float(ds.attrs["xi0_paper"])
    mxv, mlv = (
        float(v) if v not in (None, "null") else float("nan")
        for v in (ds.attrs.get("max_xi0_critical"), ds.attrs.get("max_xi0_critical_linear"))
    )
    close = any(np.isfinite(m) and abs(m - paper) <= STABILITY_REL * paper for m in (mxv, mlv))
    ev = [rel, ctx.figure("stability_condition")]
    c = CLAIMS["STABILITY"].judge(
        f"the paper's condition gives ξ0 = {paper:.4f} for κ1 = {TABLE1['kappa1']}; Floquet analysis over ω ∈ "
        f"[{min(s.stability_omegas):g}, {max(s.stability_omegas):g}] gives critical ξ0 up to {mxv:.4f} "
        f"(at ω = {ds.attrs.get('max_xi0_critical_at_omega')}) for the period-1 response of the full model and up to "
        f"{mlv:.4f} (at ω = {ds.attrs.get('max_xi0_critical_linear_at_omega')}) for the linear contact model.",
        parts(close),
        ev,
    )
    return Section(
        "The stability condition ξ0 = ½√(1 − κ1²)",
        [
            "The critical mean damping above which the period-1 response (full model) and the zero solution of the "
            "linear contact model (D = 0, unforced) are stable, from Floquet multipliers, against the paper's closed "
            "form."
        ],
        [
            (
                ev[1],
                f"Floquet stability boundaries in ξ0 against the paper's condition, ω ∈ [{min(s.stability_omegas):g}, "
                f"{max(s.stability_omegas):g}], "
                f"{model_text(ctx.base, skip=('omega', 'xi0'), only=('xi1', 'D', 'fp', 'kappa1'))}. " + gaps_text(ds),
            )
        ],
        [c],
    )


def _omegas(om: np.ndarray) -> str:
    return ", ".join(f"{w:g}" for w in om)


def gaps_text(ds: xr.Dataset) -> str:
    """What the gaps of the stability figure are, for its caption: the ω where the full model's period-1
    response has no boundary marker (stable down to the end of the ξ0 scan, or not decided, and why) and
    where the linear boundary is missing.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``stability_comparison`` result (:func:`geardyn.analysis.periodic.compare_stability_condition`).

    Returns
    -------
    str
    """
    om = ds["omega"].values
    kinds = ds["bifurcation_type"].values.astype(str)
    crit = ds["xi0_critical"].values
    low = ds.attrs.get("xi0_low", "the end of the scan")
    stable = (kinds == "stable") & ~np.isfinite(crit)
    undecided = ~np.isfinite(crit) & ~stable
    out = [
        f"Markers: the ξ0 below which the period-1 response of the full model (started stable at ξ0 = "
        f"{ds.attrs.get('xi0_high', 'the top of the scan')} and continued down in ξ0) loses stability; the line: "
        "the linear contact model's boundary (0 outside its instability tongues)."
    ]
    if not stable.any() and not undecided.any():
        out.append("Every ω of the grid has a boundary of the full model (no gaps).")
    if stable.any():
        out.append(
            f"Gaps (▽ on the ω axis) at ω = {_omegas(om[stable])}: the period-1 response stays stable down to "
            f"ξ0 = {low}, the end of the scan, so it has no stability boundary above it: stable for every damping "
            "the scan covers, not a missing computation."
        )
    if undecided.any():
        why = "; ".join(sorted({k for k in kinds[undecided] if k})) or "not computed"
        out.append(f"Gaps (× on the ω axis) at ω = {_omegas(om[undecided])}: stability could not be decided ({why}).")
    lin = ds["xi0_critical_linear"].values
    if np.any(np.isnan(lin)):
        out.append(
            f"The linear boundary is missing (△ at the top) at ω = {_omegas(om[np.isnan(lin)])}: still unstable at "
            "the top of its search."
        )
    return " ".join(out)


def jump_continuation(
    model: GearModel, lo: float, hi: float, *, sweep_num: int = 0, sweep_options: IntegrationOptions | None = None
) -> xr.Dataset:
    """Period-1 branch through the first jump by pseudo-arclength continuation, with the brute-force
    up/down sweep over the same interval attached for its figure (run on a worker).

    Parameters
    ----------
    model : GearModel
        The model of the first response of the ξ0 set.
    lo, hi : float
        The ω interval.
    sweep_num : int, optional
        Points of the up/down sweep (each point continuing from the previous end state), as
        ``geardyn continuation`` draws under its branches; 0: no sweep.
    sweep_options : IntegrationOptions, optional
        Transient and recorded periods of the sweep.

    Returns
    -------
    xarray.Dataset
        A ``continuation`` result; with a sweep, the sweep is attached under
        :data:`geardyn.plot.periodic.SWEEP_CONTEXT` (:func:`geardyn.io.attach`).
    """
    ds = continuation(model, "omega", lo, hi, switch=False).to_dataset()
    if sweep_num > 0:
        sweep = bifurcation(
            model,
            "omega",
            sweep_values(lo, hi, sweep_num),
            mode="continue",
            sweep="both",
            options=sweep_options or IntegrationOptions(),
        )
        ds = attach(ds, SWEEP_CONTEXT, sweep)
    return ds


def study_orbits(ctx: Context, branch: xr.Dataset, jd: JumpData) -> Section:
    """The periodic orbits behind the first jump: folds against the hysteresis of the sweeps.

    Parameters
    ----------
    ctx : Context
    branch : xarray.Dataset
        The continuation (:func:`jump_continuation`).
    jd : JumpData
        The frequency responses of the jump study.

    Returns
    -------
    Section
    """
    s = ctx.settings
    key = s.xi0_set[0]
    ctx.save(
        "jump_continuation",
        branch,
        f"continuation of the period-1 orbit over ω ∈ [{s.continuation_omega[0]:g}, "
        f"{s.continuation_omega[1]:g}] ({model_text(ctx.model_at(key), skip=('omega',))})",
    )
    bifs = (
        [(str(t), float(w)) for t, w in zip(branch["bifurcation_type"].values, branch["bifurcation_omega"].values)]
        if "bifurcation" in branch.dims
        else []
    )
    folds = sorted(w for t, w in bifs if t == "fold")
    first = [
        h
        for h in hysteresis_of(jd.responses[key])
        if h[1] >= s.continuation_omega[0] and h[0] <= s.continuation_omega[1]
    ]
    events = (
        (", ".join(f"{t} at ω = {w:.4f}" for t, w in bifs) + ".")
        if bifs
        else "no fold, period doubling or other event on this interval."
    )
    sweep = attached(branch, SWEEP_CONTEXT)
    over = (
        (
            f", drawn over the brute-force up/down sweep of the same interval ({sweep['omega'].size} points, each "
            f"continuing from the previous end state, {s.response_transient} transient and "
            f"{s.continuation_sweep_periods} recorded periods)"
        )
        if sweep is not None
        else ""
    )
    text = [
        f"Pseudo-arclength continuation of the period-1 orbit (shooting, Floquet multipliers, accurate mode) over "
        f"ω ∈ [{s.continuation_omega[0]:g}, {s.continuation_omega[1]:g}] for ξ0 = {key[0]:g}, ξ1 = {key[1]:g}, "
        f"D = {key[2]:g}{over}. Events: " + events
    ]
    if len(folds) >= 2 and first:
        a, b = first[0]
        text.append(
            f"The folds at ω = {folds[0]:.4f} and {folds[-1]:.4f} bound the unstable middle branch; the up/down "
            f"sweeps disagree over [{a:.3f}, {b:.3f}], inside the fold interval within one grid step: the jumps are "
            "the ends of the stable branches at the folds."
        )
    text.append(
        "No Neimark–Sacker (torus) point can occur in this model for ξ0 > 0: the product of the two Floquet "
        "multipliers is det M = exp(−2ξ0 nT) < 1, so a complex pair always lies inside the unit circle. The "
        "paper's 'Hopf bifurcation' cannot be a torus bifurcation of a periodic orbit here; the transitions it "
        "describes are period doublings, folds and the crises that end chaotic bands."
    )
    return Section(
        "Periodic orbits behind the first jump",
        text,
        [
            (
                ctx.figure("jump_continuation"),
                "Continuation over ω at "
                + model_text(ctx.model_at(key), skip=("omega",))
                + ": stable (solid) and unstable (dashed) period-1 branch with its bifurcations"
                + (", over the brute-force up/down sweep" if sweep is not None else ""),
            )
        ],
        [],
    )
