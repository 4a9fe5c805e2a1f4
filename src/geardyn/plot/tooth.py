"""Figures of the mesh stiffness (``geardyn stiffness``) and of vibration signatures (``geardyn signature``)."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .common import OUTSIDE_RIGHT, json_attr, plot_function

#: Documentation of ``ax`` for a figure of several panels.
_PANELS = """
           ax : Axes or sequence of Axes, optional
               Where to draw (as many Axes as panels); a new figure if omitted."""

__all__ = [
    "compliance_figure",
    "fe_compliance_figure",
    "fe_crack_figure",
    "indicator_sweep",
    "order_spectrum",
    "signature_signals",
    "stiffness_figure",
]


@plot_function("stiffness", (11.0, 8.0), n=3, subplots={"sharex": True}, adjust={"right": 0.7}, ax_doc=_PANELS)
def stiffness_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """Mesh stiffness, STE and load shares over the mesh phase of a ``stiffness`` result (``geardyn stiffness``)."""
    s = json_attr(ds, "summary")
    ph = ds["phase"].values
    a0, a1, a2 = ax
    a0.plot(ph, ds["mesh_stiffness"], "k-", lw=1.2, label="k_m (loaded pairs)")
    if not np.allclose(ds["mesh_stiffness"], ds["mesh_stiffness_unmodified"]):
        a0.plot(ph, ds["mesh_stiffness_unmodified"], "C0--", lw=1.0, label="pairs in geometric contact")
    iso = s["iso6336"]
    bw = s["face_width_mm"]
    if iso["c_gamma_iso"] is not None:
        a0.axhline(
            iso["c_gamma_iso"] * bw,
            color="C3",
            lw=1.0,
            ls=":",
            label=f"ISO 6336-1 c_γ·b = {iso['c_gamma_iso'] * bw:.4g} N/µm",
        )
    a0.axhline(s["k_mean_N_per_um"], color="C2", lw=1.0, ls="-.", label=f"mean {s['k_mean_N_per_um']:.4g} N/µm")
    a0.set_ylabel("mesh stiffness [N/µm]")
    a0.legend(**OUTSIDE_RIGHT)  # beside the curve: no segment hidden
    faults = ", ".join(f"{f['kind']} g{f['gear']}t{f.get('tooth')}" for f in s["faults"]) or "healthy"
    a0.set_title(
        f"z = {s['z1']}/{s['z2']}, m_n = {s['m_n_mm']:g} mm, b = {bw:g} mm, ε_α = {s['eps_alpha']:.3f}, "
        f"F = {s['force_N']:.4g} N — {faults}",
        fontsize=9,
    )
    if a1 is not None:
        a1.plot(ph, ds["ste"], "k-", lw=1.2, label="loaded STE δ")
        if np.nanmax(np.abs(ds["ste_noload"].values)) > 0:
            a1.plot(ph, ds["ste_noload"], "C1--", lw=1.0, label="no-load TE (modifications, faults)")
        a1.set_ylabel("STE [µm]")
        a1.legend(**OUTSIDE_RIGHT)
    if a2 is not None:
        for j in range(ds.sizes["pair"]):
            a2.plot(ph, ds["load_share"].isel(pair=j), lw=1.0, label=f"pair m = ⌊θ⌋ − {j}")
        a2.set_ylabel("load share [1]")
        a2.legend(**OUTSIDE_RIGHT)
    (a2 or a0).set_xlabel("mesh phase θ [mesh cycles]")


@plot_function("stiffness", (7.5, 4.5))
def compliance_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """A healthy pair's compliances by term (per unit face width) along the path of contact."""
    x = ds["path"].values
    terms = {"hertz": "C0", "bending": "C1", "shear": "C2", "axial": "C4", "fillet": "C3"}
    for k, c in terms.items():
        ax.plot(x, ds[f"compliance_{k}"], color=c, lw=1.2, label=k)
    total = sum(ds[f"compliance_{k}"].values for k in terms)
    ax.plot(x, total, "k-", lw=1.8, label="total (1/single-pair stiffness per width)")
    ax.set_xlabel("contact position from A [base pitches]")
    ax.set_ylabel("compliance per unit width [mm·µm/N]")
    ax.set_title("one tooth pair: potential-energy terms (pinion + wheel)", fontsize=10)
    ax.legend(fontsize=8)


def _runs(ds: xr.Dataset) -> list[tuple[str, dict]]:
    s = json_attr(ds, "summary")["runs"]
    return [(str(r), s[i]) for i, r in enumerate(ds["run"].values)]


@plot_function(
    "signature",
    lambda ds: (9.0, 3.2 * ds.sizes["run"] + 0.8),
    n=lambda ds: ds.sizes["run"],
    subplots={"sharex": True},
    ax_doc=_PANELS,
)
def order_spectrum(ds: xr.Dataset, ax: Any = None) -> None:
    """Order spectrum of each run (one panel per run) with the mesh orders and their pinion and wheel shaft-order
    sidebands labelled."""
    runs = _runs(ds)
    order = ds["order"].values
    for a, (name, s) in zip(ax, runs):
        if a is None:
            continue
        amp = ds["order_amplitude"].sel(run=name).values
        a.semilogy(order, np.maximum(amp, 1e-12), "k-", lw=0.7)
        z1, z2 = s["z1"], s["z2"]
        top = float(np.nanmax(amp))
        for k in range(1, int(order.max() // z1) + 1):
            m = k * z1
            a.axvline(m, color="C3", lw=0.8, alpha=0.6)
            a.text(m, top * 1.5, f"{k}× mesh", color="C3", fontsize=7, ha="center")
            # the pinion's shaft-order sidebands ±1, ±2 and the wheel's ±z1/z2
            for o, mk, c in [(m + s * j, "v", "C0") for j in (1, 2) for s in (-1, 1)] + [
                (m + s * z1 / z2, "^", "C2") for s in (-1, 1)
            ]:
                i = int(np.argmin(np.abs(order - o)))
                a.plot(order[i], max(amp[i], 1e-12), mk, color=c, ms=4)
            if k == 1:  # one label per side, under the axis top, clear of the mesh label and of each other
                a.text(m - 1.5, top * 0.35, "−1 −2", color="C0", fontsize=7, ha="right")
                a.text(m + 1.5, top * 0.35, "+1 +2", color="C0", fontsize=7, ha="left")
        ind = s["indicators"]["pinion"]
        a.set_title(
            f"{name}: order spectrum (▼ pinion shaft-order sidebands ±1, ±2; ▲ wheel ±{z1}/{z2}); "
            f"FM4 {ind['fm4']:.3g}, kurtosis {ind['kurtosis']:.3g}",
            fontsize=9,
        )
        a.set_ylabel("amplitude [m/s²]")
        a.set_ylim(top * 1e-5, top * 5)
    [a for a in ax if a is not None][-1].set_xlabel(f"pinion order (mesh order k = k·{runs[0][1]['z1']})")


@plot_function("signature", (9.0, 10.5), n=4, adjust={"hspace": 0.4}, ax_doc=_PANELS)
def signature_signals(ds: xr.Dataset, ax: Any = None) -> None:
    """Record with tachometer (of the sensor, for a system), pinion TSA, residual and difference signals of each
    run."""
    a0, a1, a2, a3 = ax
    t, ang = ds["time"].values * 1e3, ds["angle_pinion"].values
    for i, (name, s) in enumerate(_runs(ds)):
        c = f"C{i}"
        a0.plot(t, ds["accel"].sel(run=name), color=c, lw=0.6, label=name)
        if i == 0:
            tach = ds["tach"].sel(run=name).values
            scale = float(np.nanmax(np.abs(ds["accel"].values))) / 5.0
            a0.plot(t, tach * scale, color="0.5", lw=0.8, label="tachometer (scaled)")
        ind = s["indicators"]["pinion"]
        if a1 is None:
            continue
        text = f"{name}: FM4 {ind['fm4']:.3g}, NA4 {ind['na4']:.3g}, M6A {ind['m6a']:.3g}"
        for a, var, lab in ((a1, "tsa_pinion", name), (a2, "residual", name), (a3, "difference", text)):
            a.plot(ang, ds[var].sel(run=name), color=c, lw=0.9, label=lab)
    a0.set_xlabel("time [ms]")
    r0 = json_attr(ds, "summary")["runs"][0]
    a0.set_ylabel(f"accel. of {r0['sensor']} [m/s²]" if "sensor" in r0 else "relative accel. along LoA [m/s²]")
    a0.set_title(  # a system's record is that of a sensor (its runs name it)
        f"acceleration of the sensor {r0['sensor']} (mesh {r0['mesh']!r}), sampled with a once-per-revolution "
        "tachometer on its pinion"
        if "sensor" in r0
        else "relative acceleration of the two gears along the line of action (no bearing sensor), sampled with a "
        "once-per-revolution tachometer",
        fontsize=9,
    )
    for a, what in ((a1, "TSA (pinion)"), (a2, "residual"), (a3, "difference")):
        if a is not None:
            a.set_ylabel(f"{what} [m/s²]")
            a.legend(fontsize=7, loc="upper right")
    a0.legend(fontsize=7, loc="upper right")
    if a3 is not None:
        a3.set_xlabel("pinion angle [deg]")


@plot_function(
    "signature_sweep",
    (9.0, 10.0),
    n=8,
    subplots={"nrows": 4, "ncols": 2, "sharex": True},
    ax_doc=_PANELS,
)
def indicator_sweep(ds: xr.Dataset, ax: Any = None) -> None:
    """Condition indicators of pinion and wheel against the fault size."""
    names = "kurtosis fm4 na4 m6a fm0 energy_ratio sideband_level crest_factor".split()
    x = ds["size"].values
    for a, n in zip(ax, names):
        if a is None:
            continue
        for sh, mk in (("pinion", "o-"), ("wheel", "s--")):
            a.plot(x, ds[n].sel(shaft=sh), mk, ms=4, label=sh)
        a.set_ylabel(n)
        a.legend(fontsize=7)
    for a in [a for a in ax if a is not None][-2:]:
        a.set_xlabel(ds["size"].attrs.get("long_name", "fault size"))


@plot_function(
    "tooth_fe",
    lambda ds: (10.0, 2.9 * ((ds.sizes["tooth"] + 1) // 2) + 0.6),
    n=lambda ds: ds.sizes["tooth"],
    subplots=lambda ds: {"nrows": (ds.sizes["tooth"] + 1) // 2, "ncols": 2},
    adjust={"hspace": 0.5},
    ax_doc="""
               ax : Axes or sequence of Axes, optional
                   Where to draw (one Axes per tooth); a new figure if omitted.""",
)
def fe_compliance_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """Tooth compliance along the contact path, geardyn against finite elements, with the FE mesh levels (a
    result of ``benchmarks/tooth_fe.py``)."""
    for a, t in zip(ax, ds["tooth"].values):
        if a is None:
            continue
        r = ds["radius"].sel(tooth=t).values
        a.plot(r, ds["compliance_geardyn"].sel(tooth=t), "k-o", ms=3, lw=1.2, label="geardyn")
        for lv in ds["level"].values:
            a.plot(r, ds["compliance_fe_level"].sel(tooth=t, level=lv), "--", lw=0.9, label=f"FE level {lv:g}")
        a.set_title(str(t), fontsize=8)
        a.set_ylabel("compliance [1e-12 m²/N]", fontsize=8)
        a.set_xlabel("contact radius [mm]", fontsize=8)
        a.legend(fontsize=6)


@plot_function("tooth_fe", (7.5, 4.5))
def fe_crack_figure(ds: xr.Dataset, ax: Any = None) -> None:
    """Compliance of the cracked pinion tooth over the healthy one along its contact, geardyn against FE."""
    x = ds["point"].values + 1
    for i, c in enumerate(ds["crack"].values):
        ax.plot(x, ds["crack_ratio_geardyn"].sel(crack=c), "-o", color=f"C{i}", ms=3, label=f"{c} geardyn")
        ax.plot(x, ds["crack_ratio_fe"].sel(crack=c), "--s", color=f"C{i}", ms=3, label=f"{c} FE")
    ax.set_xlabel("load point along the pinion's contact (1: start of contact, 7: tip)")
    ax.set_ylabel("compliance, cracked / healthy")
    ax.set_title("root crack at the fillet's 30° point: potential energy against finite elements", fontsize=9)
    ax.legend(fontsize=6, ncol=2)
