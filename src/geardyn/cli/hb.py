"""Harmonic balance: ``geardyn hb`` (a branch of periodic responses by HB continuation, with Floquet stability)."""

from __future__ import annotations

from typing import Any

from ..model import DEFAULT_DTAU
from . import render
from .app import EXIT_FAILURE, console, fail, say_error
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
    option,
)
from .ranges import OMEGA_RANGE, given_range

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


def show(s: dict[str, Any]) -> None:
    """The branch and its bifurcations for people."""
    p = s["param"]
    vals = [b[p] for b in s["branch"]]
    n_st = sum(1 for b in s["branch"] if b["stable"])
    render.plain(
        f"HB branch in {p}: {len(vals)} points from {min(vals):.6g} to {max(vals):.6g} "
        f"(H = {s['harmonics']}, period {s['period']}, N = {s['samples']}; {n_st} stable); "
        f"converged: {s['converged']}; end: {s['end']}"
    )
    t = render.table("Bifurcations", "type", p, "u_min", "u_max", "multipliers", "detail")
    for b in s["bifurcations"]:
        mus = ", ".join("n/a" if m[0] is None else f"{complex(*m):.4f}" for m in b["multipliers"])
        t.add_row(b["type"], f"{b[p]:.6f}", f"{b['u_min']:.4f}", f"{b['u_max']:.4f}", mus, b["detail"])
    console.print(t)
    if sh := s.get("shooting"):
        render.plain("shooting: " + ", ".join(f"{b['type']} {b[p]:.6f}" for b in sh["bifurcations"]))


HB_OPTIONS = [
    CONTINUATION_PARAM,
    option(
        "start",
        float | None,
        help="Parameter value where the branch starts (the first solution from the attractor reached by "
        "simulation from rest there).",
    ),
    CONTINUATION_STOP,
    option(
        "harmonics",
        int | None,
        help="H: harmonics of ω/n retained (see docs/hb.md for the accuracy at each H); default 16, and for an "
        "forcing period of P mesh cycles (harmonics of ω/(P n): an --excitation of several cycles, torque orders, "
        "a system's mesh ratios or rolling bearings) the larger of 16·P and n times the excitation's harmonics, "
        "at most 1024; below P·n the mesh frequency is not resolved (a warning says so).",
    ),
    option(
        "period",
        int,
        1,
        help="n: period of the response in forcing periods (n > 1: subharmonic, harmonics of ω/n).",
    ),
    option(
        "compare_shooting",
        bool,
        False,
        "--compare-shooting",
        help="Also continue the branch by shooting (period map) and overlay it on the figure; its bifurcations in "
        "the JSON.",
    ),
    option(
        "ds_max",
        float | None,
        help="Largest arclength step in (coefficients, p/|stop - start|) (default 0.02 for the pair, 0.2 for a "
        "--system).",
    ),
    option(
        "floquet",
        str,
        "monodromy",
        help="How the Floquet multipliers are computed: 'monodromy' (one period integrated from the solution, "
        "refined by a Newton step; the default) or 'hill' (Hill's method).",
    ),
    option(
        "max_points",
        int,
        3000,
        help="Largest number of branch points; a branch that reaches it before --stop ends there with a warning.",
    ),
]


@command("hb", HB_OPTIONS, OMEGA_RANGE, RPM_RANGE, MODEL, STATE, SHOOTING_RUN, OUTPUT, SYSTEM)
def hb(inp: Inputs) -> None:
    """Harmonic balance (AFT, exact dead-zone switches) with Floquet stability (monodromy or Hill): a branch of
    period-n responses continued in any parameter through its folds, with folds, period doublings, Neimark–Sacker
    points and grazing located; with --out the figure shows it stable solid and unstable dashed (over the shooting
    branch with --compare-shooting).  With --system the branch is the system's (every DOF's harmonics, the elastic
    multipliers; --param takes its parameter names).  Without damping the multipliers lie on the unit circle: folds
    and period doublings are located by det(I - M) and det(I + M) and stable means neutrally stable; a branch whose
    first solution does not converge exits with code 1 and writes nothing."""
    from .. import validate
    from ..analysis.hb import hb_continuation
    from ..analysis.hb.damping import undamped_modes
    from ..analysis.hb.equations import DEFAULT_HARMONICS, MAX_DEFAULT_HARMONICS, default_harmonics
    from ..analysis.physical import add_physical, physical_json

    param, start, stop = given_range(inp)
    n = validate.integer("period", inp.period, 1, MAX_PERIOD)
    mp = validate.integer("max-points", inp.max_points, 2, MAX_POINTS_LIMIT)
    model = inp.model()
    P = model.hb_form(n).periods // n  # a forcing period of P mesh cycles: harmonics of ω/(P n)
    if inp.harmonics is None:
        H = default_harmonics(model, n)
    else:
        H = validate.integer("harmonics", inp.harmonics, 1, MAX_DEFAULT_HARMONICS if P > 1 else MAX_HARMONICS)
        if 1 < P and H < P * n:
            say_error(
                f"warning: --harmonics {H} stops below the mesh frequency (harmonic {P * n} of ω/{P * n}: the forcing "
                f"period spans {P} mesh cycles), so the mesh stiffness's variation is not in the balance; the default "
                f"takes {P}·{DEFAULT_HARMONICS}"
            )
    dsm = None if inp.ds_max is None else validate.positive("ds-max", inp.ds_max)
    scales = inp.scales()
    name, start_v, stop_v = inp.param_range(param, start, stop, what="continuation")
    free = undamped_modes(model) if model.mean_trace() != 0 else []
    if free:
        say_error(
            f"warning: {len(free)} elastic mode(s) of the system have no damping (at "
            f"{', '.join(f'{f:.6g}' for f in sorted(set(free)))} Hz): their Floquet multipliers stay on the "
            f"unit circle, so no point is asymptotically stable and pairs grazing the circle are reported as "
            f"Neimark–Sacker points"
        )
    with inp.progress("hb", param=name) as bar:
        res = hb_continuation(
            model,
            name,
            start_v,
            stop_v,
            harmonics=H,
            period=n,
            ds_max=dsm,
            state0=inp.state0(),
            floquet=inp.floquet,
            max_points=mp,
            progress=bar,
        )
    _check_result(res, start_v)
    summary = physical_json(res.to_json(), model, scales, param=name)
    shoot_ds = None
    if inp.compare_shooting:
        from ..analysis.periodic import continuation as shooting

        ws = [model.with_param(name, v).omega for v in (start_v, stop_v)]
        opts = validate.options(inp.dtau, 0, 1, inp.accurate, ws)
        with inp.progress("shooting", param=name) as bar:
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
            "bifurcations": sres.to_json()["bifurcations"],
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


def _check_result(res: Any, start: float) -> None:
    """Refuse a run that gave no branch (exit code 1, nothing written); warn in one line when the branch stopped at
    the point limit."""
    if not res.converged or res.values.size < 2:
        why = (
            f"{res.end}; try another --start or more --harmonics"
            if not res.converged
            else f"no second point ({res.end}); try a smaller --ds-max or another --start"
        )
        raise fail(f"harmonic balance gave no branch: at {res.param} = {start:.6g}, {why}", EXIT_FAILURE)
    if res.end.startswith("max points"):
        say_error(
            f"warning: the branch stopped at {res.values.size} points (--max-points) at {res.param} = "
            f"{res.values[-1]:.6g}, before the end of the interval; raise --max-points or --ds-max"
        )
