"""Sweep commands: ``bifurcation``, ``response``, ``map``, ``basins`` (on the sweep engine: workers, Dask, resume)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ModelError
from . import render
from .options import (
    ENGINE,
    MODEL,
    OUTPUT,
    RPM_RANGE,
    STATE,
    SYSTEM,
    SYSTEM_PANEL,
    Inputs,
    choice,
    command,
    finish,
    integration,
    model_group,
    option,
    param_option,
    sweep_range,
)
from .ranges import OMEGA_RANGE, given_range

MODE = option(
    "mode",
    str,
    "fixed",
    help="fixed: every point from (u0, v0); continue: each point from the previous end state.",
)
LYAPUNOV = option(
    "lyap",
    bool,
    False,
    "--lyapunov",
    help="Largest Lyapunov exponent for every point (otherwise only for non-periodic points, to classify them).",
)
SETTLE = option(
    "settle",
    int | None,
    help="Further forcing periods (with exponents) for points not periodic after the transient, before "
    "classification, a pass of up to 4 (0: none). Default 1000; for a forcing period of P > 1 mesh cycles "
    "max(16, ceil(1000/P)).",
)
CHUNK = option(
    "chunk_size",
    int | None,
    help="Points per chunk of a fixed-initial-state sweep (default: chunks of about 1 s of work each).",
)


def _engine(inp: Inputs, stem: str, model: Any, settle: int | None, chunk_size: int | None = None) -> dict[str, Any]:
    """The sweep's keywords: ``settle_periods`` of ``--settle`` (as given, else the classification's pass of the
    model's forcing period, :func:`~geardyn.analysis.settle.classify_budget`: 1000 forcing periods of one mesh cycle,
    max(16, ⌈1000/P⌉) of P > 1 mesh cycles), the engine's (:meth:`Inputs.engine`) and ``chunk_points`` if given."""
    from .. import validate
    from ..analysis.settle import classify_budget

    n = classify_budget(model)[0] if settle is None else validate.integer("settle", settle, 0, validate.MAX_PERIODS)
    kw = {"settle_periods": n, **inp.engine(stem)}
    if chunk_size is not None:
        kw["chunk_points"] = validate.chunk_points(chunk_size)
    return kw


BIFURCATION_OPTIONS = [
    param_option("Swept parameter"),
    option("start", float | None, help="First parameter value."),
    option("stop", float | None, help="Last parameter value."),
    option("num", int, 101, help="Number of parameter values."),
    MODE,
    option("sweep", str, "up", help="Continuation direction: up (increasing), down (decreasing) or both."),
    LYAPUNOV,
    SETTLE,
    CHUNK,
]


@command(
    "bifurcation",
    BIFURCATION_OPTIONS,
    OMEGA_RANGE,
    RPM_RANGE,
    MODEL,
    STATE,
    integration(adaptive=True),
    ENGINE,
    OUTPUT,
    SYSTEM,
)
def bifurcation(inp: Inputs) -> None:
    """Bifurcation diagram over any parameter: Poincaré points, period, motion class, impact state and amplitudes
    per point (and the largest Lyapunov exponent with --lyapunov); fixed initial state or continuation, up/down/both."""
    from .. import validate
    from ..analysis.bifurcation import MODES, SWEEPS, bifurcation_json
    from ..analysis.bifurcation import bifurcation as run_bifurcation
    from ..analysis.physical import add_physical, physical_json

    model = inp.model()
    scales = inp.scales()
    name, start, stop = inp.param_range(*given_range(inp))
    name, values = validate.axis(name, start, stop, inp.num)
    mode, sweep = inp.mode, inp.sweep
    runs = 2 if sweep == "both" else 1
    # the budgets first: building a grid of 10^8 models alone takes minutes
    inp.options(omegas=values if name == "omega" else [model.omega], points=values.size * runs)
    models = validate.grid(model, [(name, values)])
    opts = inp.options(omegas=[m.omega for m in models], points=len(models) * runs)
    if inp.lyap:
        validate.exponents_computable(model, [m.omega for m in models])
    choice("mode", mode, MODES)
    choice("sweep", sweep, SWEEPS)
    if mode == "fixed" and sweep != "up":
        raise ModelError(
            f"sweep: --sweep {sweep} applies to --mode continue; in fixed mode every point starts from "
            "(u0, v0), so the direction changes nothing"
        )
    engine = _engine(inp, "bifurcation", model, inp.settle, inp.chunk_size)
    ds = run_bifurcation(
        model,
        name,
        values,
        mode=mode,
        sweep=sweep,
        state0=inp.state0(),
        options=opts,
        lyapunov=inp.lyap,
        **engine,
    )
    ds = add_physical(ds, scales)
    summary = inp.system_summary(model, physical_json(bifurcation_json(ds), model, scales, param=name), ds)
    finish(summary, inp.write(ds, "bifurcation", engine), inp, render.intervals)


RESPONSE_RANGE = [
    option("omega_start", float | None, help="Lowest ω of the sweeps."),
    option("omega_stop", float | None, help="Highest ω of the sweeps."),
    option("param", str | None, help="The swept parameter: omega only (with --start/--stop)."),
    option("start", float | None, help="Lowest ω of the sweeps (as --omega-start)."),
    option("stop", float | None, help="Highest ω of the sweeps (as --omega-stop)."),
    *RPM_RANGE,
]
RESPONSE_OPTIONS = [
    option("num", int, 71, help="Number of ω values (the jumps are located to within one step)."),
    option(
        "measure",
        str,
        "amplitude",
        help="Amplitude measure: amplitude (half peak-to-peak), rms, u_max, u_min or mean.",
    ),
    LYAPUNOV,
    SETTLE,
    option(
        "method",
        str,
        "sweep",
        help="sweep: brute-force sweeps by simulation; hb: read off one harmonic-balance branch (H = 16; for an "
        "--excitation of P mesh cycles at least 16·P harmonics of ω/P) with Floquet stability, jumps at the exact "
        "folds (integration and engine options unused).",
    ),
]


@command(
    "response",
    RESPONSE_OPTIONS,
    RESPONSE_RANGE,
    model_group(omega=False),
    STATE,
    integration(adaptive=True),
    ENGINE,
    OUTPUT,
    SYSTEM,
)
def response(inp: Inputs) -> None:
    """Amplitude-frequency response swept up and down with state continuation: jumps (ω, direction, size, sweep)
    and hysteresis intervals where the sweeps end on different attractors (or, with --method hb, from one
    harmonic-balance branch: jumps at its folds)."""
    from .. import validate
    from ..analysis.physical import add_physical, physical_json
    from ..analysis.response import MEASURES, frequency_response, response_json

    model = inp.model()
    scales = inp.scales()
    _, w0, w1 = given_range(inp, "omega")
    omega_start, omega_stop = sweep_range(inp, w0, w1)
    if omega_start is None or omega_stop is None:
        raise ModelError("omega_start: give the range as --omega-start/--omega-stop or as --rpm-start/--rpm-stop")
    _, values = validate.axis("omega", omega_start, omega_stop, inp.num)
    measure, method = inp.measure, inp.method
    opts = inp.options(omegas=values, points=2 * values.size)
    validate.grid(model, [("omega", values)])
    if inp.lyap:
        validate.exponents_computable(model, values)
    choice("measure", measure, MEASURES)
    engine = _engine(inp, "response", model, inp.settle)
    if choice("method", method, ("sweep", "hb")) == "hb":
        from ..analysis.hb import hb_response

        ds = hb_response(
            model,
            float(values[0]),
            float(values[-1]),
            values.size,
            measure=measure,
            progress=not inp.json_out,
            **({"state0": inp.state0()} if inp.system is not None else {}),
        )
        if not np.isfinite(np.asarray(ds[measure].values, dtype=float)).any():  # no point resolved: nothing to show
            from .app import EXIT_FAILURE, fail

            raise fail(
                f"harmonic balance resolved no point of the response from ω = {values[0]:.6g} to "
                f"{values[-1]:.6g}; nothing written",
                EXIT_FAILURE,
            )
    else:
        ds = frequency_response(
            model,
            float(values[0]),
            float(values[-1]),
            values.size,
            options=opts,
            state0=inp.state0(),
            measure=measure,
            lyapunov=inp.lyap,
            **engine,
        )
    ds = add_physical(ds, scales)
    summary = physical_json(response_json(ds), model, scales, param="omega")
    if inp.system is None:
        from .engineering import attach_iso_kv  # the ISO K_v-B curve beside the response, when the pair has its inputs

        ds, summary = attach_iso_kv(inp.pair().loaded, model, ds, summary)
    elif method == "sweep":
        summary = inp.system_summary(model, summary, ds)
    finish(summary, inp.write(ds, "response", engine), inp, render.response)


MAP_AXES = [
    option(
        "x",
        str,
        ...,
        help="Parameter along the horizontal axis (e.g. omega), or rpm / torque for a range "
        "in pinion speed (rpm) / pinion torque (N·m) of the configured pair.",
    ),
    option("y", str, ..., help="Parameter along the vertical axis (e.g. xi0 or D), or rpm / torque."),
    option("x_start", float | None, help="First x value (for x = omega also as --rpm-start)."),
    option("x_stop", float | None, help="Last x value (for x = omega also as --rpm-stop)."),
    option("y_start", float | None, help="First y value (for y = omega also as --rpm-start)."),
    option("y_stop", float | None, help="Last y value (for y = omega also as --rpm-stop)."),
    *RPM_RANGE,
    option("x_num", int, 41, help="Number of x values."),
    option("y_num", int, 21, help="Number of y values."),
]


@command(
    "map", [MODE, LYAPUNOV, SETTLE, CHUNK], MAP_AXES, MODEL, STATE, integration(adaptive=True), ENGINE, OUTPUT, SYSTEM
)
def parameter_map(inp: Inputs) -> None:
    """2-D parameter map (e.g. ω × ξ0, ω × D) of motion class, impact state, amplitude and largest exponent."""
    from .. import validate
    from ..analysis.bifurcation import MODES
    from ..analysis.maps import map_json
    from ..analysis.maps import parameter_map as run_map
    from ..analysis.physical import add_physical, physical_json
    from ..grid import param_name as canonical_param

    model = inp.model()
    scales = inp.scales()
    # an axis in physical units: pinion speed (rpm) for ω, pinion torque (N·m, balanced) for f_p
    physical = {"rpm": ("omega", scales.omega_from_rpm), "torque": ("fp", scales.fp_from_torque)}

    def in_model_units(name: str, a: float | None, b: float | None) -> tuple[str, float | None, float | None]:
        if name not in physical or a is None or b is None:
            return name, a, b
        param, convert = physical[name]
        return (
            param,
            float(convert(validate.number(f"{name} start", a))),
            float(convert(validate.number(f"{name} stop", b))),
        )

    x, x_start, x_stop = in_model_units(inp.x, inp.x_start, inp.x_stop)
    y, y_start, y_stop = in_model_units(inp.y, inp.y_start, inp.y_stop)
    if inp.rpm_start is not None or inp.rpm_stop is not None:
        if canonical_param(y) == "omega":
            y_start, y_stop = sweep_range(inp, y_start, y_stop, "omega")
        else:
            x_start, x_stop = sweep_range(inp, x_start, x_stop, canonical_param(x))
    for nm, val in (("x_start", x_start), ("x_stop", x_stop), ("y_start", y_start), ("y_stop", y_stop)):
        if val is None:
            raise ModelError(
                f"{nm}: required (for an omega axis a pinion-speed range --rpm-start/--rpm-stop also works)"
            )
    xn, xv = validate.axis(x, x_start, x_stop, inp.x_num)
    yn, yv = validate.axis(y, y_start, y_stop, inp.y_num)
    inp.not_swept(xn, yn)
    axis_omegas = xv if xn == "omega" else yv if yn == "omega" else [model.omega]
    opts = inp.options(omegas=axis_omegas, points=xv.size * yv.size)
    if inp.lyap:
        validate.exponents_computable(model, axis_omegas)
    validate.grid(model, [(yn, yv), (xn, xv)], opts)
    choice("mode", inp.mode, MODES)
    engine = _engine(inp, "map", model, inp.settle, inp.chunk_size)
    ds = run_map(
        model,
        xn,
        xv,
        yn,
        yv,
        mode=inp.mode,
        state0=inp.state0(),
        options=opts,
        lyapunov=inp.lyap,
        **engine,
    )
    ds = add_physical(ds, scales, lazy=True)
    summary = inp.system_summary(
        model, physical_json(map_json(ds), model, scales) if inp.json_out else _map_counts(ds), ds
    )
    finish(summary, inp.write(ds, "map", engine, release=True), inp, render.parameter_map)


def _map_counts(ds: Any) -> dict[str, Any]:
    """What the table of a map shows (its axes and the points of each motion class), without the per-point
    grids of the ``--json`` summary (10⁶ entries each for a 1000 × 1000 map)."""
    from ..analysis.classify import MOTION_LABELS

    xn, yn = str(ds.attrs["x"]), str(ds.attrs["y"])
    motion = ds["motion"].values.ravel()
    present = [c for c in sorted(MOTION_LABELS) if np.any(motion == c)]
    return {
        "x": xn,
        "y": yn,
        "x_values": ds[xn].values.tolist(),
        "y_values": ds[yn].values.tolist(),
        "motion_counts": {MOTION_LABELS[c]: int(np.count_nonzero(motion == c)) for c in present},
    }


BASIN_RUN = integration(
    periods=64,
    periods_help="Forcing periods recorded per initial state (>= 2 × the largest period detected).",
    adaptive=True,
)


BASIN_GRID = [
    option("u_min", float, -3.0, help="Smallest initial displacement u0."),
    option("u_max", float, 3.0, help="Largest initial displacement u0."),
    option("v_min", float, -3.0, help="Smallest initial velocity v0."),
    option("v_max", float, 3.0, help="Largest initial velocity v0."),
    option("nu", int, 41, help="Grid points along u0."),
    option("nv", int, 41, help="Grid points along v0."),
    SETTLE,
    option("chunk_size", int, 64, help="Initial states per chunk."),
    option(
        "coords",
        str | None,
        panel=SYSTEM_PANEL,
        help="With --system: two state coordinates, DOF labels or 'label'' for a rate (e.g. x_p,x_p'): the axes of the "
        "basins' slice (--u-min/--u-max, --v-min/--v-max; default the reference mesh's δ, δ').",
    ),
]


@command("basins", BASIN_GRID, MODEL, BASIN_RUN, ENGINE, OUTPUT, SYSTEM)
def basins(inp: Inputs) -> None:
    """Basins of attraction: a grid of initial states (u0, v0) at θ = 0, each labelled by the attractor it reaches
    (attractors identified by their Poincaré cycles)."""
    from .. import validate
    from ..analysis.basins import basins as run_basins
    from ..analysis.basins import basins_json
    from ..analysis.physical import add_physical, physical_json

    model = inp.model()
    scales = inp.scales()
    lo_u, hi_u = validate.number("u-min", inp.u_min), validate.number("u-max", inp.u_max)
    lo_v, hi_v = validate.number("v-min", inp.v_min), validate.number("v-max", inp.v_max)
    n_u, n_v = validate.integer("nu", inp.nu, 1, 100_000), validate.integer("nv", inp.nv, 1, 100_000)
    opts = inp.options(model.omega, points=n_u * n_v)
    engine = _engine(inp, "basins", model, inp.settle, inp.chunk_size)
    c = None
    if inp.system is not None:  # a slice of two state coordinates (default the reference mesh's δ, δ')
        from .system_input import coordinates

        c = coordinates(model, inp.coords, 2)
    elif inp.coords is not None:
        raise ModelError(
            "coords: --coords picks the state coordinates of a --system's slice; the pair's basins are over (u0, v0)"
        )
    ds = run_basins(
        model,
        (lo_u, hi_u),
        (lo_v, hi_v),
        n_u,
        n_v,
        coordinates=None if c is None else (c[0], c[1]),
        options=opts,
        **engine,
    )
    ds = add_physical(ds, scales)
    summary = inp.system_summary(model, physical_json(basins_json(ds), model, scales), ds)
    finish(summary, inp.write(ds, "basins", engine), inp, render.basins, n_u, n_v)
