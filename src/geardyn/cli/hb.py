"""Harmonic balance: ``geardyn hb`` (a branch of periodic responses by HB continuation, with Floquet stability)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..errors import ModelError
from ..model import DEFAULT_DTAU
from . import render
from .app import EXIT_FAILURE, console, say_error
from .options import MODEL, OUTPUT, RPM_RANGE, STATE, ContinuationParamOpt, Inputs, StopOpt, command, finish, option
from .ranges import OMEGA_RANGE, both_spellings

__all__ = ["MAX_HARMONICS", "MAX_PERIOD"]

#: Largest H and n accepted (the Hill matrix has 2(2H + 1) rows; n·H harmonics of ω are resolved); the pair
#: with an excitation of several mesh cycles takes up to ``MAX_DEFAULT_HARMONICS`` (1024) harmonics of ω/(P n).
MAX_HARMONICS = 512
MAX_PERIOD = 64
#: Largest --max-points accepted.
MAX_POINTS_LIMIT = 1_000_000

SHOOTING_RUN = [
    option(
        "dtau",
        float,
        DEFAULT_DTAU,
        "--dtau",
        panel="Integration",
        help="RK4 step Δτ of the shooting of --compare-shooting (T/ceil(T/Δτ)); HB does not integrate.",
    ),
    option(
        "accurate",
        bool,
        True,
        "--accurate/--default-mode",
        panel="Integration",
        help="Shooting of --compare-shooting in the accurate mode (steps split at u = ±D; the default) or in the "
        "default integration mode.",
    ),
]


def system_model(path: Path | None, inp: Inputs) -> Any:
    """The model HB runs on: the 1-DOF model of the common options, or the multi-DOF system of ``--system``
    (with ``--omega``/``--rpm`` and the mesh options applied to its reference mesh).

    Raises
    ------
    ModelError
        For a bad system file, or options that do not apply to a system (``--config``, ``--torque``, ``--fp``).
    """
    if path is None:
        return inp.model()
    from .system_input import load_cli_system

    return load_cli_system(dict(inp.values, system=path))


def system_range(
    s: Any, inp: Inputs, param: str | None, start: float | None, stop: float | None
) -> tuple[str, float, float]:
    """The continued parameter of a system (a system parameter name, ω by default with an rpm range) and its range
    (``--rpm-start/--rpm-stop`` converted with the system's reference mesh).

    Raises
    ------
    ModelError
        For a missing or incomplete range, an unknown parameter or an rpm range for another parameter.
    """
    from .. import validate

    rpm = (inp.values.get("rpm_start"), inp.values.get("rpm_stop"))
    if any(v is not None for v in rpm):
        if None in rpm or start is not None or stop is not None or (param or "omega") != "omega":
            raise ModelError("rpm-start: give both --rpm-start and --rpm-stop, for omega, instead of --start/--stop")
        param, (start, stop) = (
            "omega",
            (
                s.scaling.omega_from_rpm(validate.number("rpm-start", rpm[0])),
                s.scaling.omega_from_rpm(validate.number("rpm-stop", rpm[1])),
            ),
        )
    if param is None:
        raise ModelError(
            "param: give the continuation parameter (--param), or a pinion-speed range (--rpm-start/--rpm-stop)"
        )
    if start is None or stop is None:
        raise ModelError("start: give the parameter range (--start and --stop)")
    start, stop = validate.number("start", start), validate.number("stop", stop)
    s.with_param(param, start)
    return param, start, stop


def show(s: dict[str, Any], paths: list[str]) -> None:
    """The branch and its bifurcations for people."""
    from rich.table import Table

    p = s["param"]
    vals = [b[p] for b in s["branch"]]
    n_st = sum(1 for b in s["branch"] if b["stable"])
    console.print(
        f"HB branch in {p}: {len(vals)} points from {min(vals):.6g} to {max(vals):.6g} "
        f"(H = {s['harmonics']}, period {s['period']}, N = {s['samples']}; {n_st} stable); "
        f"converged: {s['converged']}; end: {s['end']}",
        markup=False,
        highlight=False,
    )
    t = Table(title="Bifurcations")
    for col in ("type", p, "u_min", "u_max", "multipliers", "detail"):
        t.add_column(col)
    for b in s["bifurcations"]:
        mus = ", ".join("n/a" if m[0] is None else f"{complex(*m):.4f}" for m in b["multipliers"])
        t.add_row(b["type"], f"{b[p]:.6f}", f"{b['u_min']:.4f}", f"{b['u_max']:.4f}", mus, b["detail"])
    console.print(t)
    sh = s.get("shooting")
    if sh:
        console.print(
            "shooting: " + ", ".join(f"{b['type']} {b[p]:.6f}" for b in sh["bifurcations"]),
            markup=False,
            highlight=False,
        )
    render.files(paths)


@command("hb", OMEGA_RANGE, RPM_RANGE, MODEL, STATE, SHOOTING_RUN, OUTPUT)
def hb(
    inp: Inputs,
    param: ContinuationParamOpt = None,
    start: Annotated[
        float | None,
        typer.Option(
            "--start",
            help="Parameter value where the branch starts (the first solution from the attractor reached by simulation from rest there).",
        ),
    ] = None,
    stop: StopOpt = None,
    harmonics: Annotated[
        int | None,
        typer.Option(
            "--harmonics",
            help="H: harmonics of ω/n retained (see docs/hb.md for the accuracy at each H); default 16, and for an --excitation of P mesh cycles (harmonics of ω/(P n)) the larger of 16·P and n times the excitation's harmonics, at most 1024.",
        ),
    ] = None,
    period: Annotated[
        int,
        typer.Option(
            "--period", help="n: period of the response in forcing periods (n > 1: subharmonic, harmonics of ω/n)."
        ),
    ] = 1,
    system: Annotated[
        Path | None,
        typer.Option(
            "--system",
            help="A multi-DOF system file (examples/systems/*.toml) instead of the 1-DOF model: every DOF's harmonics, the elastic multipliers (rigid-body modes left out); --param takes the system's parameter names (omega, mesh.xi0, ...); the JSON adds 'meshes'.",
        ),
    ] = None,
    compare_shooting: Annotated[
        bool,
        typer.Option(
            "--compare-shooting",
            help="Also continue the branch by shooting (period map) and overlay it on the figure; its bifurcations in the JSON.",
        ),
    ] = False,
    ds_max: Annotated[
        float | None,
        typer.Option(
            "--ds-max",
            help="Largest arclength step in (coefficients, p/|stop - start|) (default 0.02; 0.2 with --system).",
        ),
    ] = None,
    floquet: Annotated[
        str,
        typer.Option(
            "--floquet",
            help="How the Floquet multipliers are computed: 'monodromy' (one period integrated from the solution, refined by a Newton step; the default) or 'hill' (Hill's method).",
        ),
    ] = "monodromy",
    max_points: Annotated[
        int,
        typer.Option(
            "--max-points",
            help="Largest number of branch points; a branch that reaches it before --stop ends there with a warning.",
        ),
    ] = 3000,
) -> None:
    """Harmonic balance (AFT, exact dead-zone switches) with Floquet stability (monodromy or Hill): a branch of period-n responses
    continued in any parameter through its folds, with folds, period doublings, Neimark–Sacker points and
    grazing located; with --out the figure shows it stable solid and unstable dashed (over the shooting branch
    with --compare-shooting).  A model or system without damping is refused (no stability can be decided); a
    branch whose first solution does not converge exits with code 1 and writes nothing."""
    from .. import validate
    from ..analysis.hb import hb_continuation
    from ..analysis.hb.continuation import DS_MAX
    from ..analysis.hb.solve import DEFAULT_HARMONICS, MAX_DEFAULT_HARMONICS, default_harmonics
    from ..analysis.physical import add_physical, physical_json

    param, start, stop = both_spellings(param, start, stop, inp.omega_start, inp.omega_stop)  # either spelling
    n = validate.integer("period", period, 1, MAX_PERIOD)
    mp = validate.integer("max-points", max_points, 2, MAX_POINTS_LIMIT)
    model = system_model(system, inp)
    multi = system is None and model.period_multiple() > 1  # a forcing period of P > 1 mesh cycles: ω/(P n)
    if harmonics is None:
        H = default_harmonics(model, n) if multi else DEFAULT_HARMONICS
    else:
        H = validate.integer("harmonics", harmonics, 1, MAX_DEFAULT_HARMONICS if multi else MAX_HARMONICS)
    if system is not None:
        from ..analysis.hb.system_continuation import SYSTEM_DS_MAX

        dsm = SYSTEM_DS_MAX if ds_max is None else validate.positive("ds-max", ds_max)
        return _hb_system(
            inp, model, system_range(model, inp, param, start, stop), H, n, dsm, compare_shooting, floquet, mp
        )
    dsm = DS_MAX if ds_max is None else validate.positive("ds-max", ds_max)
    scales = inp.scales()
    name, start_v, stop_v = inp.param_range(param, start, stop, what="continuation")
    with _progress(inp, name) as bar:
        res = hb_continuation(
            model,
            name,
            start_v,
            stop_v,
            harmonics=H,
            period=n,
            ds_max=dsm,
            floquet=floquet,
            max_points=mp,
            progress=bar,
        )
    _check_result(res, start_v)
    summary = physical_json(res.to_json(), model, scales, param=name)
    shoot_ds = None
    if compare_shooting:
        from ..analysis.periodic import continuation as shooting

        ws = [model.with_param(name, v).omega for v in (start_v, stop_v)]
        opts = validate.options(inp.dtau, 0, 1, inp.accurate, ws)
        with _progress(inp, name, "shooting") as bar:
            sres = shooting(
                model,
                name,
                start_v,
                stop_v,
                n,
                dtau=opts.dtau,
                accurate=opts.accurate,
                switch=False,
                state0=inp.state0(),
                progress=bar,
            )
        shoot_ds = sres.to_dataset()
        summary["shooting"] = {
            "bifurcations": [b.to_json() for b in sres.bifurcations],
            "dtau": opts.dtau,
            "accurate": opts.accurate,
        }
    paths: list[str] = []
    if inp.out is not None:
        from ..io import attach
        from ..plot.hb import SHOOTING_CONTEXT

        ds = add_physical(res.to_dataset(), scales)
        if shoot_ds is not None:
            ds = attach(ds, SHOOTING_CONTEXT, shoot_ds)  # the file redraws the figure with the shooting branch
        paths = inp.write(ds, "hb")
    finish(summary, paths, inp, show)


def _progress(inp: Inputs, name: str, what: str = "hb") -> Any:
    """The progress display of a continuation (none with ``--json``)."""
    from ..analysis.bifurcation import param_symbol
    from ..sweep.progress import task_progress

    try:
        sym = param_symbol(name)
    except (KeyError, ValueError):  # a system's parameter (<mesh>.xi0, ...) by its name
        sym = name
    return task_progress(f"{what} {sym}", unit=f"Δ{sym} traced", enabled=not inp.json_out)


def _check_result(res: Any, start: float) -> None:
    """Refuse a run that gave no branch (exit code 1, nothing written); warn in one line when the branch stopped at
    the point limit."""
    if not res.converged or res.values.size < 2:
        why = (
            f"{res.end}; try another --start or more --harmonics"
            if not res.converged
            else f"no second point ({res.end}); try a smaller --ds-max or another --start"
        )
        say_error(f"error: harmonic balance gave no branch: at {res.param} = {start:.6g}, {why}")
        raise typer.Exit(code=EXIT_FAILURE)
    if res.end.startswith("max points"):
        say_error(
            f"warning: the branch stopped at {res.values.size} points (--max-points) at {res.param} = "
            f"{res.values[-1]:.6g}, before the end of the interval; raise --max-points or --ds-max"
        )


def _hb_system(
    inp: Inputs,
    s: Any,
    rng: tuple[str, float, float],
    H: int,
    n: int,
    dsm: float,
    compare_shooting: bool,
    floquet: str = "monodromy",
    mp: int = 3000,
) -> None:
    """``geardyn hb --system``: the branch of the system (per-point values of the reference mesh, ``meshes`` per
    mesh); with ``--compare-shooting`` the shooting continuation's bifurcations in the JSON and its branch in
    ``hb.nc`` and on the figure."""
    from .. import validate
    from ..analysis.hb.damping import require_damping, undamped_modes
    from ..analysis.hb.system_continuation import hb_system_continuation

    name, start_v, stop_v = rng
    require_damping(s, name, start_v, stop_v)
    free = undamped_modes(s)
    if free:
        say_error(
            f"warning: {len(free)} elastic mode(s) of the system have no damping (at "
            f"{', '.join(f'{f:.6g}' for f in sorted(set(free)))} Hz): their Floquet multipliers stay on the "
            f"unit circle, so no point is asymptotically stable and pairs grazing the circle are reported as "
            f"Neimark–Sacker points"
        )
    with _progress(inp, name) as bar:
        res = hb_system_continuation(
            s,
            name,
            start_v,
            stop_v,
            harmonics=H,
            period=n,
            ds_max=dsm,
            state0=inp.state0(),
            floquet=floquet,
            max_points=mp,
            progress=bar,
        )
    _check_result(res, start_v)
    summary = res.to_json()
    if compare_shooting:
        from ..analysis.periodic import continuation

        opts = validate.options(inp.dtau, 0, 1, inp.accurate, [])
        sres = continuation(s, name, start_v, stop_v, n, dtau=opts.dtau, accurate=opts.accurate, state0=inp.state0())
        summary["shooting"] = {
            "bifurcations": sres.to_json()["bifurcations"],
            "dtau": opts.dtau,
            "accurate": opts.accurate,
        }
    paths: list[str] = []
    if inp.out is not None:
        from ..io import attach
        from ..plot.hb import SHOOTING_CONTEXT

        ds = res.to_dataset()
        if compare_shooting:
            ds = attach(ds, SHOOTING_CONTEXT, sres.to_dataset())  # the file redraws the figure with shooting
        paths = inp.write(ds, "hb")
    finish(summary, paths, inp, show)
