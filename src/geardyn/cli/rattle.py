"""The ``rattle`` command: impacts of an unloaded gear pair driven by torque orders, and the rattle map."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError
from .app import console
from .options import MODEL, OUTPUT, RPM_RANGE, SYSTEM, Inputs, command, finish, option

RUN_PANEL = "Integration"
#: Defaults of a rattle run: the free flight is lightly damped and the forcing period long, so a short transient
#: in forcing periods and a coarser step than the pair's (the contact oscillation still has ~300 steps).
RATTLE_RUN = [
    option("dtau", float, 0.02, help="Target RK4 step Δτ; the step is T/ceil(T/Δτ).", panel=RUN_PANEL),
    option("transient", int, 30, help="Forcing periods discarded before recording.", panel=RUN_PANEL),
    option("periods", int, 10, help="Forcing periods (cycles) recorded.", panel=RUN_PANEL),
    option(
        "accurate",
        bool,
        True,
        "--accurate/--no-accurate",
        help="Split steps at the contact crossings u = ±D (default on: the impacts are the result).",
        panel=RUN_PANEL,
    ),
]
MAP_PANEL = "Rattle map"
MAP_OPTIONS = [
    option(
        "map_points",
        int,
        0,
        panel=MAP_PANEL,
        help="Speeds of the rattle map (0: no map): from --rpm-start to --rpm-stop, or --start to --stop in ω "
        "(default 0.5 to 2 times the model's ω).",
    ),
    option("start", float | None, panel=MAP_PANEL, help="First mesh frequency ω of the map."),
    option("stop", float | None, panel=MAP_PANEL, help="Last mesh frequency ω of the map."),
    option("scale_max", float, 2.0, panel=MAP_PANEL, help="Largest scale of the torque orders' amplitudes on the map."),
    option(
        "scale_points",
        int,
        4,
        panel=MAP_PANEL,
        help="Amplitude scales of the map: scale_max/n, 2 scale_max/n, … scale_max.",
    ),
]


def _scales(inp: Inputs, model: Any) -> Any:
    """The physical scales: a system's, or the configured pair's (none without --config / --system)."""
    if inp.system is not None:
        return model.scaling
    if inp.config is None:
        return None
    sc = inp.scales()
    return None if getattr(sc, "nondimensional", False) else sc


@command("rattle", MAP_OPTIONS, MODEL, SYSTEM, RATTLE_RUN, RPM_RANGE, OUTPUT)
def rattle(inp: Inputs) -> None:
    """Gear rattle of an unloaded (loose) gear pair driven by torque orders (--torque-order, [model] torque_orders,
    or orders on a load of a --system file of two gears): impacts per cycle on the drive and back flanks, impact
    velocities, and the rattle index (impact kinetic-energy loss per cycle); with --map-points a rattle map over
    speed × torque-order amplitude."""
    from .. import validate
    from ..analysis.rattle import pair_of_system, rattle_map
    from ..analysis.rattle import rattle as run_rattle
    from ..units import sweep_range

    system = inp.model()
    model = pair_of_system(system)
    if not model.torque_orders:
        raise ModelError(
            "torque_orders: rattle needs a torque order (--torque-order ORDER:AMPLITUDE, [model] torque_orders, "
            "or orders on a load of the system file)"
        )
    scales = _scales(inp, system)
    opts = inp.options(model.forcing_omega)
    res = run_rattle(model, opts, (0.0, 0.0), scales=scales)
    summary = res.to_json()
    paths = inp.write(res.to_dataset(), "rattle")
    n = validate.integer("map_points", inp.map_points, 0, 1000)
    start, stop = inp.start, inp.stop
    if n:
        ns = validate.integer("scale_points", inp.scale_points, 1, 1000)
        smax = validate.positive("scale_max", inp.scale_max)
        if inp.rpm_start is not None or inp.rpm_stop is not None:
            if scales is None:
                raise ModelError("rpm_start: a speed range in rpm needs --config of a gear pair or --system")
            if start is not None or stop is not None:
                raise ModelError("start: give the map's speeds in rpm (--rpm-start/--rpm-stop) or in ω, not both")
            if inp.system is None:  # the configured pair's scales
                lo, hi = sweep_range(scales, inp.rpm_start, inp.rpm_stop, None, None, param="omega")
            else:
                if inp.rpm_start is None or inp.rpm_stop is None:
                    raise ModelError("rpm_stop: give both --rpm-start and --rpm-stop")
                lo, hi = (scales.omega_from_rpm(float(r)) for r in (inp.rpm_start, inp.rpm_stop))
        else:
            lo = 0.5 * model.omega if start is None else validate.number("start", start)
            hi = 2.0 * model.omega if stop is None else validate.number("stop", stop)
        if not 0 < lo < hi:
            raise ModelError(f"start: the map's speeds must satisfy 0 < start < stop, got {lo:g} and {hi:g}")
        omegas = np.linspace(lo, hi, n)
        amps = smax * np.arange(1, ns + 1) / ns
        opts_map = inp.options(omegas=omegas / model.period_multiple())
        with inp.progress("rattle map", "points") as bar:
            ds = rattle_map(model, omegas, amps, opts_map, scales=scales, progress=bar)
        summary["map"] = {
            "omega": omegas.tolist(),
            "amplitude_scale": amps.tolist(),
            "rattle_index": [
                [None if not np.isfinite(x) else float(x) for x in row] for row in ds["rattle_index"].values
            ],
        }
        if "rpm" in ds.coords:
            summary["map"]["rpm"] = ds["rpm"].values.tolist()
        paths += inp.write(ds, "rattle_map")
    finish(summary, paths, inp, _show)


def _show(s: dict[str, Any]) -> None:
    from . import render

    render.plain(
        f"ω = {s['omega']:.6g}"
        + (f" ({s['rpm']:.6g} rpm)" if s.get("rpm") is not None else "")
        + f", cycle = {s['cycle_mesh_periods']} mesh periods, {s['cycles']} cycles recorded: {s.get('regime')}"
    )
    if s.get("status") != "ok":
        render.plain(f"status: {s.get('status')}")
        return
    t = render.table("Rattle", "flank", "impacts / cycle", "impact velocity mean", "max", "m/s max")
    for name in ("drive", "back"):
        f = s["flanks"][name]
        speeds = [f.get(f"impact_velocity_{k}") for k in ("mean", "max", "max_m_s")]
        t.add_row(name, f"{f['impacts_per_cycle']:g}", *("—" if v is None else f"{v:.4g}" for v in speeds))
    console.print(t)
    ri = f"rattle index (impact kinetic-energy loss per cycle): {s['rattle_index']:.4g} (k b_c²)"
    if s.get("rattle_index_J") is not None:
        ri += f" = {s['rattle_index_J']:.4g} J"
    render.plain(ri)
