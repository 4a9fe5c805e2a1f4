"""Commands on one operating point: ``simulate``, ``lyapunov``, ``orbit``, ``continuation``."""

from __future__ import annotations

from typing import Any

import typer

from ..errors import ModelError
from . import render
from .options import (
    CONTINUATION_PARAM,
    CONTINUATION_STOP,
    MODEL,
    OUTPUT,
    RPM_RANGE,
    STATE,
    SYSTEM,
    Inputs,
    command,
    finish,
    integration,
    option,
)
from .ranges import OMEGA_RANGE, given_range

PERIOD = option("period", int, 1, help="Period n of the orbit in forcing periods (Newton solves P^n(x) = x).")
GUESS = option(
    "guess",
    str | None,
    help="Shooting guess 'u,v' at θ = 0 (with --system the full state, comma-separated; default: the state "
    "reached by simulating --transient periods from --u0, --v0).",
)
#: Points of the brute-force up/down sweep drawn under a continuation figure (:mod:`geardyn.analysis.context`).
CONTINUATION_SWEEP_NUM = 101


def parse_guess(text: str | None, d: int = 2) -> tuple[float, ...] | None:
    """'u,v' → (u, v) (a system's d state values); None when not given."""
    if text is None:
        return None
    try:
        vals = tuple(float(p) for p in text.split(","))
    except ValueError:
        vals = ()
    if len(vals) != d or not all(abs(v) < float("inf") for v in vals):
        what = "two finite numbers 'u,v'" if d == 2 else f"{d} finite numbers (q̃, q̃') separated by commas"
        raise ModelError(f"guess: expected {what}, got {text!r}")
    return vals


NO_CLASSIFY = option(
    "no_classify",
    bool,
    False,
    "--no-classify",
    help="Report a response that is not periodic as it is (motion 'not periodic'), without the further "
    "periods the motion class integrates with the leading tangent vector (chaos, quasi-periodic).",
)


@command("simulate", [NO_CLASSIFY], MODEL, STATE, integration(), OUTPUT, SYSTEM)
def simulate(inp: Inputs) -> None:
    """Integrate one operating point and report its steady response (Poincaré points, period, impact, amplitudes),
    with physical values for the configured gear pair: pinion speed, dynamic transmission error (µm), dynamic mesh
    force (N), dynamic factor, spectrum peaks in Hz and mesh orders."""
    from ..analysis.physical import add_physical, simulate_physical, steady_physical
    from ..analysis.steady import simulate as run_simulate

    model = inp.model()
    opts = inp.options(model.omega)
    with inp.progress("simulate", "periods") as bar:
        res = run_simulate(model, opts, inp.state0(), progress=bar, classify=not inp.no_classify)
    summary = res.to_json()
    if inp.system is not None:  # a system: the reference mesh's physical values and every mesh's
        summary = {**inp.system_summary(model, summary), **inp.scales().operating_point(model)}
        paths = inp.write(res.to_dataset(), "simulate") if inp.out is not None else []
    elif inp.out is None:  # nothing to write: the same summary without building the Dataset
        paths: list[str] = []
        summary.update(steady_physical(res, inp.scales()))
    else:
        ds = add_physical(res.to_dataset(), inp.scales())
        paths = inp.write(ds, "simulate")
        summary.update(simulate_physical(ds))
    summary["poincare"] = summary.pop("poincare")  # the long list last, after the summary keys
    finish(summary, paths, inp, render.simulate)


LYAPUNOV_RUN = integration(periods=2000, periods_help="Forcing periods over which the exponents are averaged.")


BLOCKS = option("blocks", int, 20, help="Blocks of the block-statistics uncertainty (>= 2).")


@command("lyapunov", [BLOCKS], MODEL, STATE, LYAPUNOV_RUN, OUTPUT, SYSTEM)
def lyapunov(inp: Inputs) -> None:
    """Both Lyapunov exponents (per unit τ) by the Benettin method with Gram–Schmidt each period, with their
    uncertainty from block statistics, and the motion class."""
    from .. import validate
    from ..analysis.lyapunov import lyapunov_spectrum

    model = inp.model()
    scales = inp.scales()
    opts = inp.options(model.omega)
    validate.exponents_computable(model, [model.omega])
    nb = validate.integer("blocks", inp.blocks, 2, validate.MAX_PERIODS)
    if opts.periods < nb:
        raise ModelError(
            f"periods: {opts.periods} periods cannot be cut into --blocks {nb} blocks; give at least "
            f"{nb} periods (or fewer blocks, >= 2)"
        )
    if model.state_dim > 2 and not inp.json_out:  # a system: say what the full spectrum costs before it runs
        from ..backend import tangent_work

        total = opts.transient + opts.periods
        ratio = (opts.transient + opts.periods * tangent_work([model])) / max(total, 1)
        typer.echo(
            f"lyapunov: the full spectrum integrates {model.state_dim} tangent vectors with the state over the "
            f"{opts.periods} recorded periods, about {ratio:.0f}x the work of a plain run of the same {total} "
            "periods (simulate classifies with the leading one)",
            err=True,
        )
    with inp.progress("lyapunov", "periods") as bar:
        res = lyapunov_spectrum(model, opts, inp.state0(), blocks=nb, progress=bar)
    _finish_point(inp, model, scales, res, "lyapunov", render.lyapunov)


def _finish_point(inp: Inputs, model: Any, scales: Any, res: Any, stem: str, show: Any) -> None:
    """Write the result of one point with its physical values (with ``--out``) and print its summary."""
    from ..analysis.physical import add_physical, physical_json

    paths = inp.write(add_physical(res.to_dataset(), scales), stem) if inp.out is not None else []
    finish(inp.system_summary(model, physical_json(res.to_json(), model, scales)), paths, inp, show)


@command("orbit", [PERIOD, GUESS], MODEL, STATE, integration(periods=None), OUTPUT, SYSTEM)
def orbit(inp: Inputs) -> None:
    """Find a period-n orbit by shooting (Newton on the n-period map, Jacobian = monodromy matrix) and report its
    section points, Floquet multipliers, stability, extremes and impact state."""
    from .. import validate
    from ..analysis.periodic import shoot

    model = inp.model()
    scales = inp.scales()
    opts = inp.options(model.omega, periods=1)
    n = validate.integer("period", inp.period, 1, 1024)
    g = parse_guess(inp.guess, model.state_dim)
    with inp.progress("orbit", "periods", on=g is None) as bar:
        res = shoot(
            model,
            n,
            g,
            dtau=opts.dtau,
            accurate=opts.accurate,
            state0=inp.state0(),
            transient=opts.transient,
            progress=bar,
        )
    _finish_point(inp, model, scales, res, "orbit", render.orbit)


CONTINUATION_RUN = integration(
    periods=None,
    accurate=option(
        "accurate",
        bool,
        True,
        "--accurate/--default-mode",
        panel="Integration",
        help="Accurate mode (steps split at u = ±D; the default here, since its Floquet multipliers vary smoothly "
        "along a branch) or the default integration mode (faster; multipliers jump by O(Δτ) where RK4 stages "
        "cross ±D).",
    ),
)


CONTINUATION_OPTIONS = [
    CONTINUATION_PARAM,
    option(
        "start",
        float | None,
        help="Parameter value where the branch starts (the first orbit is found there by shooting).",
    ),
    CONTINUATION_STOP,
    PERIOD,
    GUESS,
    option(
        "switch",
        bool,
        True,
        "--switch/--no-switch",
        help="Switch at period doublings onto the period-2n branch and continue it.",
    ),
    option("max_period", int, 4, help="Largest period reached by branch switching."),
    option(
        "ds_max",
        float | None,
        help="Largest arclength step in (u, u', p/|stop - start|) (default 0.01: at least 100 steps over the "
        "interval).",
    ),
    option(
        "sweep_num",
        int,
        CONTINUATION_SWEEP_NUM,
        help="Points of the brute-force up/down sweep drawn under the figure with --out (0: none).",
    ),
]


@command("continuation", CONTINUATION_OPTIONS, OMEGA_RANGE, RPM_RANGE, MODEL, STATE, CONTINUATION_RUN, OUTPUT, SYSTEM)
def continuation(inp: Inputs) -> None:
    """Pseudo-arclength continuation of periodic orbits in any parameter: stable and unstable branches, folds,
    period doublings (with branch switching), Neimark–Sacker points and grazing; with --out the figure shows the
    branches over the brute-force up/down sweep."""
    from .. import validate
    from ..analysis.periodic import continuation as run_continuation
    from ..analysis.physical import add_physical, physical_json

    model = inp.model()
    scales = inp.scales()
    name, start_v, stop_v = inp.param_range(*given_range(inp), what="continuation")
    opts = inp.options(model.with_param(name, start_v).omega, periods=1)
    opts.check_for(model.with_param(name, stop_v).omega)
    n = validate.integer("period", inp.period, 1, 1024)
    mp = validate.integer("max-period", inp.max_period, 1, 1024)
    nsw = validate.integer("sweep-num", inp.sweep_num, 0, 100_000)
    if inp.ds_max is not None:
        validate.positive("ds-max", inp.ds_max)
    g = parse_guess(inp.guess, model.state_dim)
    state0 = inp.state0()
    with inp.progress("continuation", param=name) as bar:
        res = run_continuation(
            model,
            name,
            start_v,
            stop_v,
            n,
            g,
            dtau=opts.dtau,
            accurate=opts.accurate,
            switch=inp.switch,
            max_period=mp,
            ds_max=inp.ds_max,
            state0=state0,
            transient=opts.transient,
            progress=bar,
        )
    paths: list[str] = []
    if inp.out is not None:
        from ..analysis.context import continuation_context
        from ..io import attach, write_netcdf
        from ..plot.periodic import SWEEP_CONTEXT
        from .output import out_paths

        ds = add_physical(res.to_dataset(), scales)
        if nsw > 0:
            sweep_ds = continuation_context(
                model,
                name,
                start_v,
                stop_v,
                num=nsw,
                dtau=opts.dtau,
                transient=opts.transient,
                state0=state0,
                progress=not inp.json_out,
            )
            sweep_ds = add_physical(sweep_ds, scales)
            ds = attach(ds, SWEEP_CONTEXT, sweep_ds)  # the file redraws the figure with its sweep
        paths = inp.write(ds, "continuation")
        if nsw > 0:  # beside the result's file, listed after it
            nc = out_paths(inp.out, "continuation")[0]
            paths.insert(1, str(write_netcdf(sweep_ds, nc.with_name(nc.stem + "_sweep.nc"))))
    finish(
        inp.system_summary(model, physical_json(res.to_json(), model, scales, param=name), result=res),
        paths,
        inp,
        render.continuation,
    )
