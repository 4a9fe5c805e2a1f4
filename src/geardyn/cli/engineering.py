"""Commands for the engineer's front end: ``te`` (measured transmission error) and ``runup`` (speed ramps)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..errors import ModelError
from .app import console
from .options import JSON_ONLY, OUTPUT, SYSTEM, Inputs, command, finish, model_group, option
from .render import plain, table

TE_OPTIONS = [
    option("teeth", str, ..., help="Teeth of pinion and gear, z1,z2 (e.g. 14,39)."),
    option("harmonics", int, 3, help="Mesh harmonics fitted (orders l z1, l = 1 … L)."),
    option(
        "shaft_orders",
        int,
        2,
        help="Shaft orders j fitted for each shaft, alone and as sidebands l z1 ± j (pinion), l z1 ± j z1/z2 (gear).",
    ),
    option(
        "x_unit",
        str | None,
        help="Unit of the first column when the header does not state it: deg, rad, rev (angle) or s, ms, us (time).",
    ),
    option(
        "te_unit",
        str | None,
        help="Unit of the TE column when the header does not state it: um, mm, nm, m.",
    ),
    option("te_rpm", float | None, None, "--rpm", help="Pinion speed (rpm) of a time record."),
    option("te_out", Path | None, None, "--out", help="Write the [mesh] section (TOML) to this file."),
    *JSON_ONLY,
]


def _teeth(text: str) -> tuple[int, int]:
    from ..te import MAX_TEETH

    try:
        parts = text.replace(";", ",").split(",")
        if len(parts) != 2 or any(len(t.strip()) > 12 for t in parts):
            raise ValueError
        z1, z2 = (int(t) for t in parts)
    except ValueError:
        raise ModelError(f"teeth: expected z1,z2 (two whole numbers, e.g. 14,39), got {text[:40]!r}") from None
    if not (1 <= z1 <= MAX_TEETH and 1 <= z2 <= MAX_TEETH):
        raise ModelError(f"teeth: numbers of teeth must be from 1 to {MAX_TEETH}, got {text!r}")
    return z1, z2


@command("te", TE_OPTIONS)
def te(
    inp: Inputs,
    file: Annotated[
        Path, typer.Argument(help="Measured TE record: two columns (angle or time, TE), header with units optional.")
    ],
) -> None:
    """Measured transmission error: mesh-order harmonics with phases, shaft-order sidebands, hunting period, and a
    [mesh] section (mesh orders only) the other commands accept."""
    from ..te import analyse_te, mesh_section, read_te

    z1, z2 = _teeth(inp.teeth)
    if inp.te_out is not None:
        from .output import check_out

        check_out(inp.te_out, file_suffixes=(inp.te_out.suffix.lower() or ".toml",))
    sig = read_te(file, x_unit=inp.x_unit, te_unit=inp.te_unit, rpm=inp.te_rpm)
    res = analyse_te(sig, z1, z2, harmonics=inp.harmonics, shaft_orders=inp.shaft_orders)
    section = mesh_section(res)
    summary = {**res.to_json(), "abscissa": sig.abscissa, "mesh_section": section}
    if inp.te_out is not None:
        from ..atomic import atomic_write_bytes

        atomic_write_bytes(inp.te_out, section.encode("utf-8"))
    finish(summary, [str(inp.te_out)] * (inp.te_out is not None), inp, _show_te)


def _show_te(s: dict[str, Any]) -> None:
    t = table(
        f"Mesh harmonics of {s['source']} (z1 = {s['z1']}, z2 = {s['z2']})",
        "l",
        "pinion order",
        "amplitude (µm)",
        "phase (deg)",
        justify="right",
    )
    for r in s["mesh_harmonics"]:
        t.add_row(str(r["mesh_harmonic"]), f"{r['order']:.6g}", f"{r['amplitude_um']:.5g}", f"{r['phase_deg']:.4g}")
    console.print(t)
    side = sorted(s["sidebands"], key=lambda r: -r["amplitude_um"])[:8]
    t = table("Largest shaft orders and sidebands", "kind", "shaft", "pinion order", "amplitude (µm)", "phase (deg)")
    for r in side:
        t.add_row(
            r["kind"], r.get("shaft", ""), f"{r['order']:.6g}", f"{r['amplitude_um']:.5g}", f"{r['phase_deg']:.4g}"
        )
    console.print(t)
    lines = [
        f"hunting period: {s['hunting_period_mesh_cycles']} mesh cycles ({s['hunting_period_pinion_revolutions']:.6g} "
        f"pinion revolutions); the record covers {s['record_pinion_revolutions']:.4g} pinion revolutions",
        f"sidebands: {100 * s['sideband_share']:.3g} % of the fitted orders' RMS; the forcing is "
        + (
            "periodic over one mesh cycle to that share"
            if s["periodic_over_mesh_cycle"]
            else "NOT periodic over one mesh cycle (the model keeps the mesh orders only)"
        ),
        f"residual: {100 * s['residual_share']:.3g} % of the signal's RMS",
        *[f"left out: {x}" for x in s["left_out"]],
    ]
    plain(*lines)
    console.print(s["mesh_section"], markup=False, highlight=False, soft_wrap=True)


def attach_iso_kv(cfg: Any, model: Any, ds: Any, summary: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    """Add the ISO K_v-B curve (JSON ``iso_kv``, Dataset attribute ``iso_kv``) to a frequency response over ω.

    Only when the configured pair (``cfg``, a loaded configuration; None for a tooth pair's own run) has the ISO
    inputs K_v needs (``f_pt`` among its ``[gear_pair]`` keys); the response is returned unchanged otherwise.
    """
    import json

    from ..geometry.iso import iso_kv_block

    if cfg is None or cfg.pair is None or "f_pt" not in cfg.iso_inputs or "rpm" not in ds.coords:
        return ds, summary
    sc = cfg.scales
    u_max = {str(s): ds["u_max"].sel(sweep=s).values for s in ds["sweep"].values}
    block = iso_kv_block(
        cfg.pair,
        cfg.iso_inputs,
        torque=float(sc.torque_from_fp(model.fp)),
        rpm=ds["rpm"].values,
        u_max=u_max,
        D=model.D,
        fp=model.fp,
        model_resonance_rpm=float(sc.rpm_from_omega(1.0)),
    )
    ds = ds.copy()
    ds.attrs["iso_kv"] = json.dumps(block)
    return ds, {**summary, "iso_kv": block}


RUNUP_OPTIONS = [
    option(
        "ru_rpm_start",
        float | None,
        None,
        "--rpm-start",
        help="Pinion speed at the start of the ramp (rpm; with --system the reference mesh's pinion).",
    ),
    option(
        "ru_rpm_stop",
        float | None,
        None,
        "--rpm-stop",
        help="Pinion speed at the end of the ramp (rpm; below --rpm-start for a run-down).",
    ),
    option("duration", float | None, help="Duration of the ramp (s)."),
    option("omega_start", float | None, help="Start of the ramp as ω (instead of --rpm-start)."),
    option("omega_stop", float | None, help="End of the ramp as ω (instead of --rpm-stop)."),
    option("param", str | None, help="The ramped parameter: omega only (with --start/--stop)."),
    option("start", float | None, help="Start of the ramp as ω (as --omega-start)."),
    option("stop", float | None, help="End of the ramp as ω (as --omega-stop)."),
    option(
        "tau_duration",
        float | None,
        help="Duration of the ramp in τ (instead of --duration).",
    ),
    option(
        "cycles_per_block",
        int | None,
        help="Mesh cycles per constant-speed block (default: about 400 blocks); with an --excitation of P mesh cycles "
        "(or a system whose forcing period is P reference mesh cycles) a multiple of P (blocks of whole forcing "
        "periods).",
    ),
    option("orders", int, 3, help="Mesh orders tracked."),
    option("qs_num", int, 21, "--num", help="Speeds of the quasi-static (steady) response beside the ramp (0: none)."),
    option("dtau", float, 0.05, help="Target RK4 step Δτ; the step is T/ceil(T/Δτ) in every block."),
    option("accurate", bool, False, "--accurate", help="Split steps at the contact crossings u = ±D."),
    option(
        "settle",
        int,
        200,
        help="Mesh periods at the start speed before the ramp (from --u0, --v0 = 0; "
        "whole forcing periods with an --excitation of several cycles).",
    ),
]


def _ramp(inp: Inputs) -> tuple[float, float, float, Any]:
    """ω at the start and at the end of the ramp, its duration in τ and the scales, checked (the RK4 steps of the
    ramp within the bound)."""
    from .ranges import given_range

    scales = inp.scales()
    _, omega_start, omega_stop = given_range(inp, "omega")
    given_rpm = inp.ru_rpm_start is not None or inp.ru_rpm_stop is not None
    given_w = omega_start is not None or omega_stop is not None
    if given_rpm == given_w:
        raise ModelError("rpm_start: give the ramp either as --rpm-start/--rpm-stop or as --omega-start/--omega-stop")
    if given_rpm:
        from ..units import omega_range

        if inp.ru_rpm_start is None or inp.ru_rpm_stop is None:
            raise ModelError("rpm_start: give both --rpm-start and --rpm-stop")
        w0, w1 = omega_range(scales, inp.ru_rpm_start, inp.ru_rpm_stop)
    else:
        if omega_start is None or omega_stop is None:
            raise ModelError("omega_start: give both --omega-start and --omega-stop (or --start and --stop)")
        w0, w1 = omega_start, omega_stop
    if (inp.duration is None) == (inp.tau_duration is None):
        raise ModelError("duration: give the ramp's duration as --duration (s) or --tau-duration (τ), one of them")
    if inp.duration is not None:
        if getattr(scales, "nondimensional", False):
            raise ModelError("duration: the configuration has no [gear_pair]; give --tau-duration")
        if not inp.duration > 0:
            raise ModelError(f"duration: must be > 0 s, got {inp.duration:g}")
        T = float(scales.tau_from_s(inp.duration))
    else:
        T = float(inp.tau_duration)
    # refused before computing: a step or a ramp whose RK4 steps cannot be counted or exceed the bound
    import math

    from .. import validate

    dt = validate.options(inp.dtau, 0, 1, inp.accurate, [w0, w1]).dtau
    if not (math.isfinite(T) and T > 0):
        raise ModelError(f"tau_duration: must be a finite number > 0, got {T!r}")
    from .output import TRAJECTORY_STEP_SECONDS, _human_time, time_budget

    steps, budget = T / dt, time_budget()
    if not (steps <= validate.MAX_TOTAL_STEPS and steps * TRAJECTORY_STEP_SECONDS <= budget):
        raise ModelError(
            f"dtau: a ramp of τ = {T:.6g} with Δτ = {dt:g} is {steps:.3g} RK4 steps, about "
            f"{_human_time(steps * TRAJECTORY_STEP_SECONDS)} of computing; the budget is "
            f"{_human_time(budget)} (GEARDYN_TIME_BUDGET seconds): a shorter ramp or a larger dtau"
        )
    return float(w0), float(w1), T, scales


@command("runup", RUNUP_OPTIONS, model_group(omega=False), OUTPUT, SYSTEM)
def runup_cmd(inp: Inputs) -> None:
    """Run-up / run-down through a linear speed ramp: order-tracked DTE, amplitude and dynamic factor against
    speed, beside the quasi-static (steady) response swept up and down; with --system those of the reference
    mesh of any system file."""
    import json

    import numpy as np

    from .. import validate
    from ..analysis.runup import runup, steady_response

    model = inp.model()
    w0, w1, T, sc = _ramp(inp)
    nq = validate.integer("num", inp.qs_num, 0, 2001)
    orders = validate.integer("orders", inp.orders, 1, 50)
    with inp.progress("runup", "blocks") as bar:
        res = runup(
            model,
            w0,
            w1,
            T,
            cycles_per_block=inp.cycles_per_block,
            orders=orders,
            dtau=inp.dtau,
            accurate=inp.accurate,
            settle=validate.integer("settle", inp.settle, 0, validate.MAX_PERIODS),
            progress=bar,
        )
    ds = res.to_dataset()
    summary = res.to_json()
    um = float(sc.b_c_m) * 1e6
    from ..io import annotate

    ds = ds.assign_coords(
        rpm=("block", sc.rpm_from_omega(ds["omega"].values)), time_s=("block", sc.s_from_tau(ds["tau"].values))
    )
    for v in ("order_amplitude", "amplitude"):
        ds[f"{v}_um"] = (ds[v].dims, ds[v].values * um)
    annotate(ds)
    rate = float(sc.rpm_from_omega(res.ramp_rate) * sc.omega_n_rad_s)
    ds.attrs["ramp_rate_rpm_per_s"] = rate
    ds.attrs["physical_scales"] = sc.to_json()
    summary.update(
        {
            "rpm": [float(x) for x in ds["rpm"].values],
            "ramp_rate_rpm_per_s": rate,
            "duration_s": float(sc.s_from_tau(T)),
            "amplitude_um": [None if not np.isfinite(x) else float(x) for x in ds["amplitude_um"].values],
            "pair": sc.statement(),
            # the pair's model whole; a system's file and reference mesh (its matrices are in the Dataset)
            "model": json.loads(model.to_attrs())
            if model.backend.name == "pair"
            else {"system": str(inp.values["system"]), "reference_mesh": sc.reference, "dofs": model.n},
        }
    )
    if nq >= 2:
        lo, hi = sorted((w0, w1))
        with inp.progress("runup: quasi-static sweep up and down", "points") as bar:
            qs = steady_response(
                model, np.linspace(lo, hi, nq), orders=orders, dtau=inp.dtau, accurate=inp.accurate, progress=bar
            )
        x_rpm = [float(v) for v in sc.rpm_from_omega(np.array(qs["x"]))]
        plot_qs = {"x": x_rpm}
        for lab in ("up", "down"):
            qs[lab]["amplitude_um"] = [None if v is None else v * um for v in qs[lab]["amplitude"]]
            plot_qs[lab] = {"amplitude": qs[lab]["amplitude_um"], "dynamic_factor": qs[lab]["dynamic_factor"]}
        summary["quasi_static"] = {**qs, "rpm": x_rpm}
        ds.attrs["quasi_static"] = json.dumps(plot_qs)
    finish(summary, inp.write(ds, "runup"), inp, _show_runup)


def _show_runup(s: dict[str, Any]) -> None:
    what = "run-up" if s["omega_stop"] > s["omega_start"] else "run-down"
    plain(
        f"{what}: {s['rpm'][0]:.6g} → {s['rpm'][-1]:.6g} rpm in {s['duration_s']:.4g} s "
        f"({s['ramp_rate_rpm_per_s']:.4g} rpm/s), {s['blocks']} blocks of {s['cycles_per_block']} mesh cycles"
        + ("; DIVERGED" if s["diverged"] else "")
    )
    t = table(
        "Order-tracked DTE (every tenth block)",
        "rpm",
        "ω",
        "mesh order 1 (µm)",
        "half p-p (µm)",
        "dynamic factor",
        justify="right",
    )
    um = [None if a is None or b is None else b / a for a, b in zip(s["amplitude"], s["amplitude_um"])]
    scale = next((x for x in um if x), 1.0)
    for i in range(0, s["blocks"], max(1, s["blocks"] // 10)):
        a1 = s["order_amplitude"][0][i]
        cells = (None if a1 is None else a1 * scale, s["amplitude_um"][i], s["dynamic_factor"][i])
        t.add_row(f"{s['rpm'][i]:.6g}", f"{s['omega'][i]:.5g}", *("n/a" if v is None else f"{v:.4g}" for v in cells))
    console.print(t)
    plain(f"gear pair: {s['pair']}")
