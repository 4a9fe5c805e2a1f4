"""Figures that only the results of multi-DOF systems have.

A system's result is of the command's one kind (``simulate``, ``bifurcation``, ...) with the pair's layout
along the reference element plus per-element variables, so its main figures are the pair's; this module adds
what only systems have — every element's deflection, all 2n Lyapunov exponents, all Floquet multipliers, the
amplitude of each mesh along a sweep — each drawn when the Dataset holds it, and keeps the figures of the
``system_*`` kinds that earlier versions wrote (their files stay readable: ``geardyn plot`` redraws them);
:mod:`.registry` enters them in the figure registry.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes

from .common import label, of_mesh, plot_function, rpm_axis, symbol, system_info

__all__ = [
    "element_deflections",
    "reference_phase",
    "lyapunov_spectrum",
    "multipliers",
    "mesh_amplitudes",
    "continuation_branches",
]


def _finish(ax: Axes, ds: xr.Dataset, text: str, xlabel: str, ylabel: str, legend: dict | None = None) -> None:
    """Axis labels, the legend (with these options, if any) and the title ``text`` over the system's title."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if legend is not None:
        ax.legend(**legend)
    sub = system_info(ds).get("title") or ""
    ax.set_title(f"{text}\n{sub}" if sub else text, fontsize=9)


@plot_function("system_simulate", (8, 3.6))
def element_deflections(ds: xr.Dataset, ax: Axes = None) -> None:
    """Deflection δ of every element (meshes, then clearances) over the recorded history."""
    tau = ds["tau"].values
    for e in ds["element"].values:
        ax.plot(tau, ds["delta"].sel(element=e).values, lw=0.8, label=str(e))
    _finish(
        ax,
        ds,
        "Element deflections",
        label(ds["tau"], "τ"),
        "deflection δ of each element (over b_c)",
        legend=dict(fontsize=7, loc="upper right"),
    )


@plot_function("system_simulate", (5.5, 4.5))
def reference_phase(ds: xr.Dataset, ax: Axes = None) -> None:
    """Phase portrait of the reference mesh (δ, δ') with its Poincaré points."""
    ax.plot(ds["u"].values, ds["v"].values, lw=0.6, color="C0")
    _finish(ax, ds, of_mesh("Phase portrait of the reference mesh", ds), of_mesh("δ", ds), of_mesh("dδ/dτ", ds))


@plot_function("system_lyapunov", (6, 3.8))
def lyapunov_spectrum(ds: xr.Dataset, ax: Axes = None) -> None:
    """All 2n Lyapunov exponents with their block-statistics uncertainty."""
    k = ds["exponent"].values
    lam = ds["exponents"].values
    err = np.nan_to_num(ds["uncertainty"].values)
    ax.bar(k, lam, yerr=err, color=["C3" if v > 0 else "C0" for v in lam])
    ax.axhline(0.0, color="k", lw=0.6)
    _finish(ax, ds, "Lyapunov spectrum", "exponent index", "λ [1/τ]")


@plot_function("system_orbit", (5, 5))
def multipliers(ds: xr.Dataset, ax: Axes = None) -> None:
    """All Floquet multipliers in the complex plane with the unit circle (elastic ones filled)."""
    t = np.linspace(0.0, 2 * np.pi, 361)
    ax.plot(np.cos(t), np.sin(t), color="0.5", lw=0.8)
    ax.plot(ds["multiplier_re"].values, ds["multiplier_im"].values, "o", mfc="none", color="k", label="all")
    if "elastic_re" in ds:
        ax.plot(ds["elastic_re"].values, ds["elastic_im"].values, ".", color="C3", label="elastic")
    ax.set_aspect("equal")
    _finish(ax, ds, "Floquet multipliers", "Re μ", "Im μ", legend=dict(fontsize=8))


@plot_function("system_bifurcation", (7, 4))
def mesh_amplitudes(ds: xr.Dataset, ax: Axes = None) -> None:
    """Amplitude (half peak-to-peak δ) of every mesh along the sweep, per direction."""
    param = str(ds.attrs.get("param", "omega"))
    x = ds[param].values
    if "mesh_amplitude" in ds:  # a system_* file of an earlier version
        names, amp = ds["mesh"].values, ds["mesh_amplitude"]
    else:
        kinds = {e["name"]: e["kind"] for e in system_info(ds).get("elements", [])}
        names = [str(n) for n in ds["element"].values if kinds.get(str(n), "mesh") == "mesh"]
        amp = 0.5 * (ds["element_u_max"] - ds["element_u_min"]).sel(element=names)
    for e, name in enumerate(names):
        for s, style in zip([str(v) for v in ds["sweep"].values], ("-", "--")):
            ax.plot(x, amp.sel(sweep=s).values[:, e], style, color=f"C{e}", lw=1.0, label=f"mesh {name} ({s})")
    _finish(
        ax,
        ds,
        "Mesh amplitudes",
        label(ds[param], symbol(param)) if param in ds else symbol(param),
        "amplitude of δ of each mesh (half peak-to-peak, over b_c)",
        legend=dict(fontsize=7),
    )
    rpm_axis(ax, ds, param)


@plot_function("system_continuation", (7, 4.5))
def continuation_branches(ds: xr.Dataset, ax: Axes = None) -> None:
    """Branches of periodic orbits (reference mesh amplitude; solid stable, dotted unstable) and bifurcations."""
    param = str(ds.attrs.get("param", "omega"))
    x, a, st, br = (ds[k].values for k in ("value", "amplitude", "stable", "branch"))
    for b in np.unique(br):
        sel = br == b
        xs, ys, ss = x[sel], a[sel], st[sel].astype(bool)
        ax.plot(xs, np.where(ss, ys, np.nan), "-", color=f"C{int(b)}", lw=1.4, label=f"branch {int(b)} stable")
        ax.plot(xs, np.where(ss, np.nan, ys), ":", color=f"C{int(b)}", lw=1.2)
    if ds.sizes.get("bifurcation", 0):
        marks = {"fold": "s", "period-doubling": "D", "neimark-sacker": "*", "grazing": "v"}
        for t in np.unique(ds["bifurcation_type"].values):
            sel = ds["bifurcation_type"].values == t
            ax.plot(
                ds["bifurcation_value"].values[sel],
                ds["bifurcation_amplitude"].values[sel],
                marks.get(str(t), "o"),
                color="k",
                ms=5,
                mfc="none",
                label=str(t),
            )
    _finish(
        ax,
        ds,
        "Continuation of periodic orbits",
        symbol(param),
        of_mesh("amplitude of δ (the reference mesh)", ds),
        legend=dict(fontsize=7),
    )
