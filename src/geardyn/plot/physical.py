"""Figures in physical units (µm, N, Hz, ms, rpm) from results that carry physical variables.

Drawn when a result has been through :func:`geardyn.analysis.physical.add_physical` (the CLI does
this for every result of a configured gear pair).  Axis labels come from the variables' ``units``
and ``long_name`` attributes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize

from .common import OUTSIDE_RIGHT, json_attr, json_list, label, log_stems, of_mesh, plot_function, set_title, symbol
from .response import draw_response
from .simulate import TIME_PERIODS_SHOWN, last_periods

__all__ = [
    "RPM_CURVE_VARIABLES",
    "TIME_PERIODS_SHOWN",
    "response_rpm",
    "rpm_curve",
    "rpm_curve_variable",
    "spectrum_hz",
    "time_history",
]

#: Variables drawn against pinion speed, in order of preference, for results with an ``rpm`` coordinate.
RPM_CURVE_VARIABLES = ("amplitude_um", "rms_um", "u_max_um", "poincare_u_um")
#: Most curves of :func:`rpm_curve` named in a legend; more are coloured by a colour bar of their parameter.
LEGEND_CURVES = 4
#: Most curves :func:`rpm_curve` draws: of more rows, this many evenly spaced ones are drawn (the first
#: and the last among them; the title says so), since hundreds of overlapping marked lines show no more.
MAX_CURVES = 32


def _pair_title(ax: Axes, text: str, ds: xr.Dataset, *args: Any, **kwargs: Any) -> Any:
    """:func:`~geardyn.plot.common.set_title` with the gear pair whose scales the physical values were drawn with
    (a result rescaled with ``geardyn plot --physical --config`` names the pair it was rescaled to)."""
    name = json_attr(ds, "physical_scales").get("title")
    return set_title(ax, f"{text} — {name}" if name else text, ds, *args, **kwargs)


@plot_function(
    "simulate",
    (8, 6.5),
    n=2,
    subplots={"sharex": True},
    ax_doc="""
               ax : matplotlib.axes.Axes or sequence of two Axes, optional
                   One Axes: the DTE only; two: DTE and mesh force; omitted: a new figure.""",
)
def time_history(ds: xr.Dataset, ax: Axes = None) -> None:
    """Dynamic transmission error (µm) and dynamic mesh force (kN) against time (ms), last periods
    (a ``simulate`` result with physical variables ``time_s``, ``dte_um``, ``mesh_force_N``)."""
    a1, a2 = ax
    keep, _ = last_periods(ds)
    t_ms = ds["time_s"].values[keep] * 1e3
    dte = ds["dte_um"]
    summ = json_attr(ds, "physical_summary")
    b = summ.get("backlash_um")
    if b:
        a1.axhspan(-b, b, color="0.9", label="separation\n(inside the backlash)")
    a1.plot(t_ms, dte.values[keep], lw=1.0, color="C0")
    a1.set_ylabel(label(dte))
    a1.legend(**OUTSIDE_RIGHT)
    if a2 is not None:
        F = ds["mesh_force_N"]
        a2.plot(t_ms, F.values[keep] * 1e-3, lw=1.0, color="C1")
        if summ.get("static_force_N") is not None:
            a2.axhline(summ["static_force_N"] * 1e-3, color="k", ls="--", lw=0.8, label="static mesh\nforce F_p")
            a2.legend(**OUTSIDE_RIGHT)
        a2.set_ylabel(f"{F.attrs.get('long_name', 'mesh force')} [kN]")
    (a2 or a1).set_xlabel("time [ms]")
    title = f"{summ.get('rpm', float('nan')):.6g} rpm"
    if summ.get("dynamic_factor") is not None:
        title += f", dynamic factor {summ['dynamic_factor']:.3g}"
    _pair_title(a1, title, ds)


@plot_function("simulate", (7, 4))
def spectrum_hz(ds: xr.Dataset, ax: Axes = None) -> None:
    """Amplitude spectrum of the DTE (µm) against frequency (Hz), with mesh orders on the top axis
    (a ``simulate`` result with ``frequency_Hz`` and ``spectrum_um``)."""
    f = ds["frequency_Hz"].values
    log_stems(ax, f, ds["spectrum_um"].values)
    ax.set_xlabel(label(ds["frequency_Hz"]))
    ax.set_ylabel(f"{of_mesh('DTE amplitude', ds)} [{ds['spectrum_um'].attrs.get('units', 'µm')}]")
    order = ds["order"].values
    if order.size > 1 and order[1] > 0:
        hz_per_order = f[1] / order[1]
        sec = ax.secondary_xaxis("top", functions=(lambda x: x / hz_per_order, lambda o: o * hz_per_order))
        sec.set_xlabel("order of the mesh frequency")
    _pair_title(ax, ds["spectrum_um"].attrs.get("long_name", "Amplitude spectrum of the DTE"), ds)


def rpm_curve_variable(ds: xr.Dataset) -> str | None:
    """The variable :func:`rpm_curve` draws for ``ds`` (first of :data:`RPM_CURVE_VARIABLES` present on the
    ``rpm`` dimension), or ``None`` when the result has no such curve (no ``rpm`` coordinate, a
    ``simulate`` or a ``response`` result, which has :func:`response_rpm`).

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result with physical coordinates.

    Returns
    -------
    str or None
    """
    if (
        ds.attrs.get("geardyn_kind") == "simulate"
        or "rpm" not in ds.coords
        or ds["rpm"].ndim != 1
        or _has_response_rpm(ds)
    ):
        return None
    for name in RPM_CURVE_VARIABLES:
        if name in ds.data_vars and ds["rpm"].dims[0] in ds[name].dims and ds[name].ndim <= 3:
            return name
    return None


def _has_response_rpm(ds: xr.Dataset) -> bool:
    return (
        ds.attrs.get("geardyn_kind") == "response"
        and "rpm" in ds.coords
        and "sweep" in ds.dims
        and "amplitude_um" in ds.data_vars
    )


@plot_function(
    "any",
    (7.5, 4.5),
    params="""
               name : str, optional
                   The variable drawn; default :func:`rpm_curve_variable`.""",
)
def rpm_curve(ds: xr.Dataset, name: str | None = None, ax: Axes = None) -> None:
    """A result variable (µm) against pinion speed (rpm), one line per value of its other dimensions: named
    in a legend up to :data:`LEGEND_CURVES` lines, else coloured by the value of a colour bar (a result with
    an ``rpm`` coordinate); of more than :data:`MAX_CURVES` rows, evenly spaced ones."""
    name = name or rpm_curve_variable(ds)
    da = ds[name]
    rpm = ds["rpm"]
    dim = rpm.dims[0]
    others = [d for d in da.dims if d != dim]
    ax.set_xlabel(label(rpm))
    ax.set_ylabel(label(da))
    what = da.attrs.get("long_name", name)
    title = f"{what[:1].upper()}{what[1:]} against pinion speed"
    if not others:
        _pair_title(ax, title, ds, exclude=[dim, "omega"])
        ax.plot(rpm.values, da.values, ".-", ms=4, lw=0.8)
        return
    flat = da.stack(_line=others).transpose(dim, "_line")
    count = flat.sizes["_line"]
    drawn = np.unique(np.linspace(0, count - 1, min(count, MAX_CURVES)).round().astype(int))
    if drawn.size < count:
        rows = f"{symbol(others[0])} values" if len(others) == 1 else "curves"
        title += f" ({drawn.size} of {count} {rows}, evenly spaced)"
    _pair_title(ax, title, ds, exclude=[dim, "omega", *others])
    x, lines = rpm.values, flat.values  # read once (a lazily opened file is read again at every access)
    values = [np.atleast_1d(v) for v in flat["_line"].values]
    colour_by = (
        len(others) == 1 and count > LEGEND_CURVES and np.issubdtype(np.asarray(flat[others[0]]).dtype, np.number)
    )
    if colour_by:
        z = np.asarray(flat[others[0]].values, dtype=float)
        mappable = ScalarMappable(Normalize(np.nanmin(z), np.nanmax(z)), "viridis")
    for i in drawn:
        lab = _curve_label(others, values[i])
        colour = mappable.to_rgba(z[i]) if colour_by else f"C{i % 10}"
        ax.plot(
            x, lines[:, i], ".-", ms=4, lw=0.8, color=colour, label=(lab or None) if count <= LEGEND_CURVES else None
        )
    if colour_by:
        ax.figure.colorbar(mappable, ax=ax, label=label(ds[others[0]]))
    elif count <= LEGEND_CURVES and ax.get_legend_handles_labels()[1]:
        ax.legend(fontsize=8, loc="best")


def _curve_label(dims: list[str], values: Any) -> str:
    """A curve's legend entry from the values of its other dimensions: ``ξ0 = 0.1``, ``sweep up``; a fixed sweep
    (one curve, no direction) is no name at all."""
    parts = []
    for k, v in zip(dims, values, strict=False):
        if k == "sweep":
            if str(v) != "fixed":
                parts.append(f"sweep {v}")
        elif isinstance(v, (int, float, np.number)):
            parts.append(f"{symbol(k)} = {v:.4g}")
        else:
            parts.append(f"{k} = {v}")
    return ", ".join(parts)


@plot_function("response", (8.5, 4.8))
def response_rpm(ds: xr.Dataset, ax: Axes = None) -> None:
    """Frequency response against pinion speed: up and down sweeps in µm, jumps (arrows, labelled in rpm)
    and hysteresis intervals (shaded), with ω on the top axis (a ``response`` result with physical variables)."""
    measure = str(ds.attrs.get("measure", "amplitude"))
    name = f"{measure}_um" if f"{measure}_um" in ds.data_vars else "amplitude_um"
    da = ds[name]
    w = ds["omega"].values
    rpm = ds["rpm"].values
    hy = json_list(ds, "hysteresis_rpm")
    jumps = [
        (j["rpm"], j["amplitude_from_um"], j["amplitude_to_um"], j["sweep"], f"{j['rpm']:.0f} rpm")
        for j in json_list(ds, "jumps_physical")
    ]
    scale = float(rpm[-1] / w[-1])
    co = [[a * scale, b * scale] for a, b in json_list(ds, "coexistence")]
    draw_response(ax, rpm, da, hy, jumps, min_width=1e-3 * float(np.ptp(rpm)), coexistence=co)
    ax.set_xlabel(label(ds["rpm"]))
    ax.set_ylabel(label(da))
    sec = ax.secondary_xaxis("top", functions=(lambda r: r / scale, lambda x: x * scale))
    sec.set_xlabel(of_mesh("ω = ω_e/ω_n", ds))
    sc = json_attr(ds, "physical_scales")
    k0 = sc.get("k0_N_per_m")
    k0_text = f" (k0 = {k0 * 1e-6:.4g} N/µm{', assumed' if 'k0' in sc.get('assumed', []) else ''})" if k0 else ""
    _pair_title(
        ax,
        "Frequency response against pinion speed"
        + k0_text
        + ("; grey: hysteresis" if hy else "")
        + ("; hatched: coexisting attractors" if co else ""),
        ds,
        exclude=["omega"],
        fontsize=10,
    )
