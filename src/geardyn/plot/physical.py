"""Figures in physical units (µm, N, Hz, ms, rpm) from results that carry physical variables.

Drawn when a result has been through :func:`geardyn.analysis.physical.add_physical` (the CLI does
this for every result of a configured gear pair).  Axis labels come from the variables' ``units``
and ``long_name`` attributes.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from .common import PlotArtists, label, one_axes, panels, result, snapshot

__all__ = ["RPM_CURVE_VARIABLES", "TIME_PERIODS_SHOWN", "response_rpm", "rpm_curve", "rpm_curve_variable",
           "spectrum_hz", "time_history"]

#: Periods of the time history drawn.
TIME_PERIODS_SHOWN = 8
#: Variables drawn against pinion speed, in order of preference, for results with an ``rpm`` coordinate.
RPM_CURVE_VARIABLES = ("amplitude_um", "rms_um", "u_max_um", "poincare_u_um")


def _model(ds: xr.Dataset) -> dict:
    return json.loads(ds.attrs["model"])


def time_history(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Dynamic transmission error (µm) and dynamic mesh force (kN) against time (ms), last periods.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result with physical variables (``time_s``, ``dte_um``, ``mesh_force_N``).
    ax : matplotlib.axes.Axes or sequence of two Axes, optional
        One Axes: the DTE only; two: DTE and mesh force; omitted: a new figure.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, (a1, a2), _ = panels(ax, 2, (8, 5.5), sharex=True)
    before = snapshot([a1, a2])
    m = _model(ds)
    T = 2 * np.pi / float(m["omega"])
    tau = ds["tau"].values
    keep = tau >= tau[-1] - TIME_PERIODS_SHOWN * T - 1e-12
    t_ms = ds["time_s"].values[keep] * 1e3
    dte = ds["dte_um"]
    summ = json.loads(ds.attrs.get("physical_summary", "{}"))
    b = summ.get("backlash_um")
    if b:
        a1.axhspan(-b, b, color="0.9", label="separation (inside the backlash)")
    a1.plot(t_ms, dte.values[keep], lw=1.0, color="C0")
    a1.set_ylabel(label(dte))
    a1.legend(loc="upper right", fontsize=8)
    if a2 is not None:
        F = ds["mesh_force_N"]
        a2.plot(t_ms, F.values[keep] * 1e-3, lw=1.0, color="C1")
        if summ.get("static_force_N") is not None:
            a2.axhline(summ["static_force_N"] * 1e-3, color="k", ls="--", lw=0.8, label="static mesh force F_p")
            a2.legend(loc="upper right", fontsize=8)
        a2.set_ylabel(f"{F.attrs.get('long_name', 'mesh force')} [kN]")
    (a2 if a2 is not None else a1).set_xlabel("time [ms]")
    title = f"{summ.get('rpm', float('nan')):.6g} rpm"
    if summ.get("dynamic_factor") is not None:
        title += f", dynamic factor {summ['dynamic_factor']:.3g}"
    a1.set_title(title)
    return result(fig, [a1, a2], before)


def spectrum_hz(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Amplitude spectrum of the DTE (µm) against frequency (Hz), with mesh orders on the top axis.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result with ``frequency_Hz`` and ``spectrum_um``.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (7, 3.2))
    before = snapshot([ax])
    f = ds["frequency_Hz"].values
    amp = ds["spectrum_um"].values
    ax.vlines(f[1:], 1e-12, np.maximum(amp[1:], 1e-12), color="C0", lw=1.0)
    ax.set_yscale("log")
    top = max(float(np.max(amp[1:])) if amp.size > 1 else 1.0, 1e-12)
    ax.set_ylim(max(top * 1e-6, 1e-12), top * 2)
    ax.set_xlabel(label(ds["frequency_Hz"]))
    ax.set_ylabel(label(ds["spectrum_um"]))
    order = ds["order"].values
    if order.size > 1 and order[1] > 0:
        hz_per_order = f[1] / order[1]
        sec = ax.secondary_xaxis("top", functions=(lambda x: x / hz_per_order, lambda o: o * hz_per_order))
        sec.set_xlabel("order of the mesh frequency")
    return result(fig, [ax], before)


def rpm_curve_variable(ds: xr.Dataset) -> str | None:
    """The variable :func:`rpm_curve` draws for ``ds`` (first of :data:`RPM_CURVE_VARIABLES` present on the
    ``rpm`` dimension), or ``None`` when the result has no such curve (no ``rpm`` coordinate, a
    ``simulate`` or a ``response`` result, which has :func:`response_rpm`)."""
    kind = ds.attrs.get("geardyn_kind")
    if kind == "simulate" or "rpm" not in ds.coords or ds["rpm"].ndim != 1 or _has_response_rpm(ds):
        return None
    for name in RPM_CURVE_VARIABLES:
        if name in ds.data_vars and ds["rpm"].dims[0] in ds[name].dims and ds[name].ndim <= 3:
            return name
    return None


def _has_response_rpm(ds: xr.Dataset) -> bool:
    return (ds.attrs.get("geardyn_kind") == "response" and "rpm" in ds.coords and "sweep" in ds.dims
            and "amplitude_um" in ds.data_vars)


def rpm_curve(ds: xr.Dataset, name: str | None = None, ax: Any = None) -> PlotArtists:
    """A result variable (µm) against pinion speed (rpm), one line per extra dimension.

    Parameters
    ----------
    ds : xarray.Dataset
        A result with an ``rpm`` coordinate.
    name : str, optional
        The variable drawn; default :func:`rpm_curve_variable`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (7.5, 4))
    before = snapshot([ax])
    name = name or rpm_curve_variable(ds)
    da = ds[name]
    rpm = ds["rpm"]
    dim = rpm.dims[0]
    others = [d for d in da.dims if d != dim]
    if not others:
        ax.plot(rpm.values, da.values, ".-", ms=3, lw=0.8)
    else:
        flat = da.stack(_line=others).transpose(dim, "_line")
        for i in range(flat.sizes["_line"]):
            lab = ", ".join(f"{k}={v}" for k, v in zip(others, np.atleast_1d(flat["_line"].values[i])))
            style = ".-" if flat.sizes["_line"] <= 4 else ","
            ax.plot(rpm.values, flat.values[:, i], style, ms=3, lw=0.8, label=lab if flat.sizes["_line"] <= 4 else None)
        if flat.sizes["_line"] <= 4:
            ax.legend(fontsize=8)
    ax.set_xlabel(label(rpm))
    ax.set_ylabel(label(da))
    return result(fig, [ax], before)


def response_rpm(ds: xr.Dataset, ax: Any = None) -> PlotArtists:
    """Frequency response against pinion speed: up and down sweeps in µm, jumps (arrows, labelled in rpm)
    and hysteresis intervals (shaded), with ω on the top axis.

    Parameters
    ----------
    ds : xarray.Dataset
        A ``response`` result with physical variables.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure if omitted.

    Returns
    -------
    PlotArtists
        The figure, its Axes and the artists drawn.
    """
    fig, ax, _ = one_axes(ax, (8.5, 4.8))
    before = snapshot([ax])
    measure = str(ds.attrs.get("measure", "amplitude"))
    name = f"{measure}_um" if f"{measure}_um" in ds.data_vars else "amplitude_um"
    da = ds[name]
    w = ds["omega"].values
    rpm = ds["rpm"].values
    span = 1e-3 * float(np.ptp(rpm))
    for a, b in json.loads(ds.attrs.get("hysteresis_rpm", "[]")):
        ax.axvspan(a, max(b, a + span), color="0.88", lw=0, zorder=0)
    styles = {"up": ("^", "C0"), "down": ("v", "C3")}
    for sw in [str(v) for v in ds["sweep"].values]:
        mk, c = styles.get(sw, ("o", "k"))
        ax.plot(rpm, da.sel(sweep=sw).values, "-", marker=mk, ms=3.5, lw=0.8, color=c, label=f"sweep {sw}")
    for j in json.loads(ds.attrs.get("jumps_physical", "[]")):
        c = styles.get(j["sweep"], ("o", "k"))[1]
        a0, a1 = j["amplitude_from_um"], j["amplitude_to_um"]
        ax.annotate("", xy=(j["rpm"], a1), xytext=(j["rpm"], a0), arrowprops=dict(arrowstyle="->", color=c, lw=1.5))
        ax.text(j["rpm"], 0.5 * (a0 + a1), f" {j['rpm']:.0f} rpm", color=c, fontsize=7, va="center")
    scale = float(rpm[-1] / w[-1])
    ax.set_xlabel(label(ds["rpm"]))
    ax.set_ylabel(label(da))
    sec = ax.secondary_xaxis("top", functions=(lambda r: r / scale, lambda x: x * scale))
    sec.set_xlabel("ω = ω_e/ω_n")
    sc = json.loads(ds.attrs.get("physical_scales", "{}"))
    k0 = sc.get("k0_N_per_m")
    hy = json.loads(ds.attrs.get("hysteresis_rpm", "[]"))
    k0_text = f" (k0 = {k0 * 1e-6:.4g} N/µm{', assumed' if 'k0' in sc.get('assumed', []) else ''})" if k0 else ""
    ax.set_title("Frequency response against pinion speed" + k0_text + ("; grey: hysteresis" if hy else ""),
                 fontsize=10)
    ax.legend(fontsize=8)
    return result(fig, [ax], before)
