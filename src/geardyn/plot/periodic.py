"""Figures of periodic-orbit results: an orbit with its multipliers, a continuation diagram over the
brute-force up/down sweep, and the stability-boundary comparison.  Datasets in, figures out; no
numerics here."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..io import attached
from .common import (
    bifurcation_marker,
    branch_lines,
    contact_lines,
    json_attr,
    label,
    model_of,
    plot_function,
    rpm_axis,
    set_title,
    symbol,
)

__all__ = [
    "BIFURCATION_STYLE",
    "PERIOD_COLOURS",
    "SWEEP_CONTEXT",
    "continuation_figure",
    "orbit_figure",
    "stability_figure",
]

#: Colours of branches by period (period-1, 2, 4, 8, others).
PERIOD_COLOURS = {1: "C0", 2: "C1", 4: "C2", 8: "C4"}
#: Marker style of each bifurcation type.
BIFURCATION_STYLE = {
    "fold": dict(marker="o", color="C3", label="fold"),
    "period-doubling": dict(marker="s", color="C2", label="period doubling"),
    "neimark-sacker": dict(marker="D", color="C4", label="Neimark–Sacker"),
    "grazing": dict(marker="^", color="0.35", label="grazing"),
    "branch-point": dict(marker="*", color="C5", label="branch point"),
}
#: Brute-force Poincaré points drawn per sweep point (the last ones).
SWEEP_SECTION_SHOWN = 16
#: Name under which a continuation Dataset carries the brute-force sweep drawn beneath its branches
#: (see :func:`geardyn.io.attach`).
SWEEP_CONTEXT = "sweep"


# ------------------------------------------------------------------------------------- orbit
@plot_function(
    "orbit",
    (14, 4.2),
    n=3,
    tight=True,
    subplots={"nrows": 1, "ncols": 3, "gridspec_kw": {"width_ratios": [1.2, 1.6, 1.0]}},
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of three Axes, optional
                   One Axes: the phase portrait only; three: phase portrait, time history, multipliers;
                   omitted: a new figure.""",
)
def orbit_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """Phase portrait with the section points, time history over the orbit, and the Floquet
    multipliers against the unit circle."""
    m = model_of(ds)
    D = float(m["D"])
    summary = json_attr(ds, "summary")
    axes = ax
    ax = axes[0]
    if D > 0:
        ax.axvspan(-D, D, color="0.92", label="separation |u| ≤ D")
    if ds["u"].size:
        ax.plot(ds["u"].values, ds["v"].values, lw=0.9, color="C0", label="orbit")
    ax.plot(ds["poincare_u"].values, ds["poincare_v"].values, "o", color="C3", ms=5, label="section points")
    ax.set_xlabel(label(ds["u"]))
    ax.set_ylabel(label(ds["v"], "du/dτ"))
    ax.legend(fontsize=8)
    ax.set_title("Phase portrait")
    if axes[1] is not None:
        _orbit_history(axes[1], ds, m, D, summary)
    else:
        set_title(ax, "Phase portrait", ds, fontsize=9)
    if axes[2] is not None:
        _multipliers(axes[2], ds, summary)


def _orbit_history(ax, ds: xr.Dataset, m: dict, D: float, summary: dict) -> None:
    if D > 0:
        ax.axhspan(-D, D, color="0.92")
    if ds["u"].size:
        ax.plot(ds["tau"].values, ds["u"].values, lw=1.0, color="C0")
        T = 2 * np.pi / float(m["omega"])
        for k in range(ds.sizes["section"] + 1):
            ax.axvline(k * T, color="C3", lw=0.5, alpha=0.6)
    ax.set_xlabel(label(ds["tau"], "τ"))
    ax.set_ylabel(label(ds["u"]))
    per = summary.get("period")
    set_title(ax, f"Period-{per if per else '?'} orbit ({summary.get('impact', '')})", ds, fontsize=10)


def _multipliers(ax, ds: xr.Dataset, summary: dict) -> None:
    th = np.linspace(0, 2 * np.pi, 256)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8)
    ax.axhline(0, color="0.8", lw=0.6)
    ax.axvline(0, color="0.8", lw=0.6)
    re, im = ds["multiplier_re"].values, ds["multiplier_im"].values
    ax.plot(re, im, "x", color="C3", ms=9, mew=2)
    ax.set_aspect("equal")
    r = max(1.1, float(np.nanmax(np.hypot(re, im))) * 1.1 if np.any(np.isfinite(re)) else 1.1)
    ax.set_xlim(-r, r)
    ax.set_ylim(-r, r)
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    stable = summary.get("stable")
    ax.set_title("Floquet multipliers (" + ("stable" if stable else "unstable") + ")")


# ------------------------------------------------------------------------------ continuation
def _draw_branches(ax, ds: xr.Dataset, param: str, what: str) -> None:
    """Branches of a continuation Dataset, stable solid and unstable dashed (runs overlap by one point)."""
    x_all = ds[param].values
    seen_labels = set()
    for b in np.unique(ds["branch"].values):
        sel = np.nonzero(ds["branch"].values == b)[0]
        n = int(ds["period"].values[sel[0]])
        x = x_all[sel]
        stable = ds["stable"].values[sel].astype(bool)
        ys = (
            [ds["amplitude"].values[sel]]
            if what == "amplitude"
            else [ds["poincare_u"].values[sel, k] for k in range(n)]
        )
        branch_lines(
            ax, x, ys, stable, f"period-{n} ", seen_labels, (1.6, 1.1), color=PERIOD_COLOURS.get(n, "C5"), zorder=3
        )


def _draw_sweep(ax, sweep: xr.Dataset, param: str, what: str) -> None:
    styles = {"up": dict(marker=".", color="0.45", ms=4), "down": dict(marker="x", color="0.7", ms=3.5)}
    x = sweep[param].values
    for lab in sweep["sweep"].values:
        st = styles.get(str(lab), dict(marker=".", color="0.5", ms=3))
        s = sweep.sel(sweep=lab)
        xs, ys = x, s["amplitude"].values
        if what != "amplitude":
            ys = s["poincare_u"].values[:, -SWEEP_SECTION_SHOWN:]
            xs = np.repeat(x[:, None], ys.shape[1], axis=1).ravel()
        ax.plot(xs, ys.ravel(), ls="none", label=f"simulation, sweep {lab}", zorder=2, **st)


def _draw_bifurcations(ax, ds: xr.Dataset, param: str, what: str) -> None:
    seen: set[str] = set()
    for i in range(ds.sizes.get("bifurcation", 0)):
        typ = str(ds["bifurcation_type"].values[i])
        st = BIFURCATION_STYLE.get(typ, dict(marker="P", color="k", label=typ))
        bifurcation_marker(
            ax,
            float(ds[f"bifurcation_{param}"].values[i]),
            float(ds["bifurcation_amplitude" if what == "amplitude" else "bifurcation_u"].values[i]),
            st["marker"],
            st["color"],
            st["label"],
            seen,
        )


@plot_function(
    "continuation",
    (10, 8.5),
    n=2,
    subplots={"sharex": True},
    tight=True,
    params="""
               sweep : xarray.Dataset, optional
                   The brute-force sweep (dims ``sweep`` and the parameter, variables ``amplitude`` and
                   ``poincare_u``, as written by ``geardyn bifurcation --mode continue --sweep both``);
                   default the one attached to ``ds`` under :data:`SWEEP_CONTEXT`, if any.""",
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of two Axes, optional
                   One Axes: the amplitude panel only; two: amplitude and section points; omitted: a new figure.""",
)
def continuation_figure(ds: xr.Dataset, sweep: xr.Dataset | None = None, ax: Any = None) -> None:
    """The branches of a continuation (stable solid, unstable dashed, coloured by period) with their
    bifurcations, over the brute-force up/down sweep of the same parameter.  Top: amplitude;
    bottom: section points u, with the contact boundaries u = ±D."""
    if sweep is None:
        sweep = attached(ds, SWEEP_CONTEXT)
    param = ds.attrs["param"]
    axes = ax
    for ax, what in zip(axes, ("amplitude", "section")):
        if ax is None:
            continue
        if sweep is not None:
            _draw_sweep(ax, sweep, param, what)
        _draw_branches(ax, ds, param, what)
        _draw_bifurcations(ax, ds, param, what)
        ax.grid(alpha=0.3)
    if axes[1] is not None:
        x = ds[param].values if sweep is None else np.concatenate([ds[param].values, sweep[param].values])
        contact_lines(axes[1], ds, param, x)
        axes[1].set_ylabel(label(ds["poincare_u"]))
    axes[0].set_ylabel(label(ds["amplitude"]))
    [a for a in axes if a is not None][-1].set_xlabel(label(ds[param]))
    axes[0].legend(fontsize=7, ncol=2, loc="best")
    over = " over the brute-force up/down sweep" if sweep is not None else ""
    set_title(axes[0], f"Continuation in {symbol(param)}: periodic orbits{over}", ds, exclude=[param])
    rpm_axis(axes[0], ds, param)


# ---------------------------------------------------------------------------- stability boundary
def _strip(ax, x: np.ndarray, height: float, **style: Any) -> None:
    """Markers at ``x`` on a strip at ``height`` (a fraction of the axes) over the ω axis, where a boundary has a
    gap."""
    ax.plot(
        x, np.full(x.size, height), ls="none", clip_on=False, transform=ax.get_xaxis_transform(), gid="gap", **style
    )


def _stability_gaps(ax, om: np.ndarray, kinds: np.ndarray, crit: np.ndarray, xi0_low: Any) -> None:
    """Mark the ω where the full model has no boundary marker, on a strip above the ω axis: stable down to the
    end of the ξ0 scan (no boundary above it), or not decided (the start orbit not found or unstable, the
    scan stopped early); each kind named in the legend."""
    low = f"{float(xi0_low):g}" if xi0_low is not None else "the end of the scan"
    stable = (kinds == "stable") & ~np.isfinite(crit)
    undecided = ~np.isfinite(crit) & ~stable
    why = sorted({str(k) for k in kinds[undecided] if str(k)}) or ["not computed"]
    for sel, style in (
        (
            stable,
            dict(
                marker="v",
                color="0.45",
                mfc="none",
                label=f"gap: full model stays stable down to ξ0 = {low} (no boundary above it)",
            ),
        ),
        (undecided, dict(marker="x", color="k", label="gap: stability not decided (" + "; ".join(why) + ")")),
    ):
        if sel.any():
            _strip(ax, om[sel], 0.03, **style)


@plot_function("stability_comparison", (8, 5.5), tight=True)
def stability_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """Floquet stability boundaries ξ0_c(ω), with the paper's condition ξ0 = ½√(1 − κ1²) when the
    Dataset holds it (a ``stability_comparison`` result from
    :func:`geardyn.analysis.periodic.compare_stability_condition`, or a ``stability_boundary`` or
    ``mathieu_boundary`` one); the legend sits below the axes, clear of the data."""
    om = ds["omega"].values
    linear = (
        "xi0_critical_linear"
        if "xi0_critical_linear" in ds
        else ("xi0_critical" if ds.attrs.get("geardyn_kind") == "mathieu_boundary" else None)
    )
    if linear is not None:
        ax.plot(
            om,
            ds[linear].values,
            "-",
            color="C0",
            label="linear contact model (D = 0, unforced): Mathieu–Hill boundary",
        )
    if "bifurcation_type" in ds:
        crit = ds["xi0_critical"].values
        kinds = ds["bifurcation_type"].values.astype(str)
        for typ in sorted(set(kinds)):
            if typ not in BIFURCATION_STYLE:
                continue
            sel = kinds == typ
            st = BIFURCATION_STYLE[typ]
            ax.plot(
                om[sel],
                crit[sel],
                ls="none",
                marker=st["marker"],
                color=st["color"],
                mfc="white",
                label=f"full model, period-1 response loses stability by {st['label']}",
            )
        _stability_gaps(ax, om, kinds, crit, ds.attrs.get("xi0_low"))
    if linear is not None and np.any(np.isnan(ds[linear].values)):
        _strip(
            ax,
            om[np.isnan(ds[linear].values)],
            0.97,
            marker="^",
            color="C0",
            mfc="none",
            label="gap in the linear boundary: still unstable at the top of its search, no boundary found",
        )
    paper = ds["xi0_paper"].values if "xi0_paper" in ds else ds.attrs.get("xi0_paper")
    if paper is not None:
        paper = float(paper)
        ax.axhline(paper, color="C3", ls="--", label=f"paper's condition ½√(1 − κ1²) = {paper:.4f}")
    ax.set_xlabel("mesh frequency ω")
    ax.set_ylabel("critical mean damping ratio ξ0")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), frameon=False)
    set_title(
        ax, "Stability boundaries from Floquet multipliers vs the paper's condition", ds, exclude=["omega", "xi0"]
    )
