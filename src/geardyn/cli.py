"""The ``geardyn`` command line: parses options, calls the library, prints.  Nothing else."""

from __future__ import annotations

import errno
import json
import sys
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.console import Console

from .model import DEFAULT_DTAU, DEFAULT_PERIODS, DEFAULT_TRANSIENT, GearModel, IntegrationOptions, ModelError

app = typer.Typer(
    name="geardyn",
    help="Nonlinear dynamics of gear pairs with backlash.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True)


@app.callback()
def _root() -> None:
    """geardyn: simulate and analyse the nonlinear dynamics of a gear pair with backlash."""


def say_error(message: str) -> None:
    """Print ``message`` on stderr as one line (never wrapped, no markup)."""
    err_console.print(" ".join(str(message).split()), markup=False, highlight=False, soft_wrap=True)


def fail(message: str) -> "typer.Exit":
    """Print one line naming the bad input and return the exit (code 2) to raise."""
    say_error(f"error: {message}")
    return typer.Exit(code=2)


def emit_json(obj: Any) -> None:
    sys.stdout.write(json.dumps(obj, indent=2, allow_nan=True, default=_json_default) + "\n")


def _json_default(o: Any) -> Any:
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


# ---------------------------------------------------------------- options shared by every command
ConfigOpt = Annotated[Optional[Path], typer.Option("--config", help="TOML file with the gear pair, mesh and operating point (default: the paper's Table 1).")]
OmegaOpt = Annotated[Optional[float], typer.Option("--omega", help="Mesh frequency ω = ω_e/ω_n (non-dimensional, > 0).")]
Xi0Opt = Annotated[Optional[float], typer.Option("--xi0", help="Mean damping ratio ξ0.")]
Xi1Opt = Annotated[Optional[float], typer.Option("--xi1", help="First damping harmonic ξ1.")]
Kappa1Opt = Annotated[Optional[float], typer.Option("--kappa1", help="First stiffness harmonic κ1 (|κ| sum < 1).")]
FpOpt = Annotated[Optional[float], typer.Option("--fp", help="Mean load f_p (non-dimensional).")]
FeOpt = Annotated[Optional[float], typer.Option("--fe", help="First STE harmonic ε1 (forcing ω² ε1 cos θ; the paper's 0.5).")]
BacklashOpt = Annotated[Optional[float], typer.Option("--backlash", help="Half backlash D (non-dimensional, >= 0; 0 = no backlash).")]
PhiCOpt = Annotated[Optional[float], typer.Option("--phi-c", help="Phase of the first damping harmonic (rad).")]
PhiKOpt = Annotated[Optional[float], typer.Option("--phi-k", help="Phase of the first stiffness harmonic (rad).")]
PhiEOpt = Annotated[Optional[float], typer.Option("--phi-e", help="Phase of the first STE harmonic (rad).")]
U0Opt = Annotated[float, typer.Option("--u0", help="Initial displacement u at θ = 0.")]
V0Opt = Annotated[float, typer.Option("--v0", help="Initial velocity u' at θ = 0.")]
DtauOpt = Annotated[float, typer.Option("--dtau", help="Target RK4 step Δτ; the step is T/ceil(T/Δτ).")]
TransientOpt = Annotated[int, typer.Option("--transient", help="Forcing periods discarded before recording.")]
PeriodsOpt = Annotated[int, typer.Option("--periods", help="Forcing periods recorded (Poincaré points).")]
AccurateOpt = Annotated[bool, typer.Option("--accurate", help="Split steps at the contact crossings u = ±D (4th order through contact loss).")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print a machine-readable summary on stdout.")]
OutOpt = Annotated[Optional[Path], typer.Option("--out", help="Directory (or .nc file) for NetCDF data and PNG figures.")]
WorkersOpt = Annotated[int, typer.Option("--workers", help="Local worker processes for a sweep (1: in this process).")]
SchedulerOpt = Annotated[Optional[str], typer.Option("--scheduler", help="Run the sweep on a running Dask scheduler, tcp://HOST:PORT (workers need geardyn installed).")]
ResumeOpt = Annotated[bool, typer.Option("--resume", help="Complete an interrupted sweep with the same --out: chunks already finished are kept.")]
# physical front-end: operating point of the configured gear pair (default: the paper's Table 1 pair, k0 assumed)
RpmOpt = Annotated[Optional[float], typer.Option("--rpm", help="Pinion speed in rpm (sets ω for the gear pair of --config; default pair: the paper's Table 1, k0 = 2000 N/µm assumed).")]
TorqueOpt = Annotated[Optional[float], typer.Option("--torque", help="Pinion torque in N·m, balanced (sets f_p for the gear pair of --config).")]
RpmStartOpt = Annotated[Optional[float], typer.Option("--rpm-start", help="Start of an ω sweep given as pinion speed in rpm (with --rpm-stop).")]
RpmStopOpt = Annotated[Optional[float], typer.Option("--rpm-stop", help="End of an ω sweep given as pinion speed in rpm (with --rpm-start).")]


def sweep_engine(workers: int, scheduler: Optional[str], resume: bool, nc: Optional[Path], json_out: bool) -> dict[str, Any]:
    """Validated keyword arguments of :func:`geardyn.sweep.run_chunks` from the common sweep options.

    With ``--out`` the finished chunks are checkpointed next to the NetCDF file ``nc``
    (``<nc>.chunks``, see :func:`geardyn.sweep.checkpoint_dir`); call :func:`finish_sweep` once the
    final file is written.  The progress bar and divergence summary go to stderr unless ``--json``.
    """
    from . import validate
    from .sweep import checkpoint_dir

    if resume and nc is None:
        raise ModelError("resume: needs --out (a resumable sweep keeps its finished chunks next to its output)")
    return {
        "workers": validate.workers(workers),
        "scheduler": validate.scheduler(scheduler),
        "checkpoint": checkpoint_dir(nc) if nc is not None else None,
        "resume": bool(resume),
        "progress": not json_out,
    }


def finish_sweep(engine: dict[str, Any]) -> None:
    """Remove a sweep's checkpoint once its final NetCDF file has been written."""
    from .sweep import remove_checkpoint

    if engine.get("checkpoint") is not None:
        remove_checkpoint(engine["checkpoint"])


def base_model(config: Optional[Path]) -> GearModel:
    """The model of ``--config`` (or the paper's defaults)."""
    if config is None:
        return GearModel()
    from .config import load_config

    return load_config(config).model


def pair_scales(config: Optional[Path]):
    """Physical scales of the gear pair of ``--config`` (default: the paper's Table 1 pair, k0 assumed)."""
    from .units import PhysicalScales, configured_pair

    return PhysicalScales.from_config(configured_pair(config))


def rpm_range(
    config: Optional[Path],
    rpm_start: Optional[float],
    rpm_stop: Optional[float],
    start: Optional[float] = None,
    stop: Optional[float] = None,
    param: str = "omega",
) -> tuple[Optional[float], Optional[float]]:
    """(start, stop) of a sweep: ``--rpm-start/--rpm-stop`` converted to ω, else ``start, stop`` as given."""
    from .units import sweep_range

    if rpm_start is None and rpm_stop is None:
        return start, stop
    return sweep_range(pair_scales(config), rpm_start, rpm_stop, start, stop, param=param)


def build_model(
    config: Optional[Path] = None,
    *,
    rpm: Optional[float] = None,
    torque: Optional[float] = None,
    omega: Optional[float] = None,
    xi0: Optional[float] = None,
    xi1: Optional[float] = None,
    kappa1: Optional[float] = None,
    fp: Optional[float] = None,
    fe: Optional[float] = None,
    backlash: Optional[float] = None,
    phi_c: Optional[float] = None,
    phi_k: Optional[float] = None,
    phi_e: Optional[float] = None,
) -> GearModel:
    """The config's model with the command-line values applied on top (validated).

    ``rpm`` (pinion speed) and ``torque`` (pinion torque, N·m) set ω and f_p through the scales of
    the configured gear pair; they cannot be combined with ``omega`` / ``fp``.
    """
    m = base_model(config)
    if rpm is not None or torque is not None:
        from .units import operating_overrides

        phys = operating_overrides(pair_scales(config), rpm=rpm, torque=torque, omega=omega, fp=fp)
        omega, fp = phys.get("omega", omega), phys.get("fp", fp)
    given = {
        "omega": omega, "xi0": xi0, "xi1": xi1, "kappa1": kappa1, "fp": fp, "eps1": fe, "D": backlash,
        "phi_c1": phi_c, "phi_k1": phi_k, "phi_e1": phi_e,
    }
    for name, value in given.items():
        if value is not None:
            m = m.with_param(name, value)
    return m


def build_options(dtau: float, transient: int, periods: int, accurate: bool, omega: float | None = None) -> IntegrationOptions:
    """Validated integration options (checked against ``omega`` when given; see :func:`geardyn.validate.options`)."""
    from . import validate

    return validate.options(dtau, transient, periods, accurate, () if omega is None else (omega,))


def out_paths(out: Path, stem: str) -> tuple[Path, Path]:
    """(NetCDF file, figure directory) for ``--out``: a directory, or a file name ending in .nc."""
    if out.suffix == ".nc":
        return out, out.parent
    return out / f"{stem}.nc", out


# ---------------------------------------------------------------- commands
@app.command()
def simulate(
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    periods: PeriodsOpt = DEFAULT_PERIODS,
    accurate: AccurateOpt = False,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Integrate one operating point and report its steady response (Poincaré points, period, impact, amplitudes),
    with physical values for the configured gear pair: pinion speed, dynamic transmission error (µm), dynamic mesh
    force (N), dynamic factor, spectrum peaks in Hz and mesh orders."""
    from .analysis.physical import add_physical, simulate_physical
    from .analysis.steady import simulate as run_simulate

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        opts = build_options(dtau, transient, periods, accurate, model.omega)
        for name, val in (("u0", u0), ("v0", v0)):
            if not (abs(val) < float("inf")):
                raise ModelError(f"{name}: must be a finite number, got {val!r}")
        res = run_simulate(model, opts, (u0, v0))
        ds = add_physical(res.to_dataset(), pair_scales(config))
    except ModelError as e:
        raise fail(str(e))
    files: list[str] = []
    if out is not None:
        from .io import write_netcdf
        from .plot import save_figures

        nc, figdir = out_paths(out, "simulate")
        files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_figures(ds, figdir)]
    summary = res.to_json()
    summary.update(simulate_physical(ds))
    if json_out:
        summary["files"] = files
        emit_json(summary)
        return
    _print_simulate(summary, files)


def _print_simulate(s: dict[str, Any], files: list[str]) -> None:
    from rich.table import Table

    t = Table(title=f"Steady response at ω = {s['omega']:g}", show_header=False)
    t.add_row("motion", s["motion"])
    t.add_row("impact state", s["impact"])

    def num(x: Any) -> str:
        return "n/a" if x is None else f"{x:.6g}"

    for k, lab in (("amplitude", "amplitude (half peak-to-peak)"), ("rms", "RMS about mean"), ("mean", "mean"),
                   ("u_min", "u_min"), ("u_max", "u_max")):
        t.add_row(lab, num(s[k]))
    cf = s["contact_fractions"]
    t.add_row("time in drive / separation / back contact", " / ".join(num(cf[k]) for k in ("drive", "separation", "back")))
    pts = s["poincare"]
    shown = pts[-(s["period"] or 4):]
    t.add_row(f"last {len(shown)} Poincaré points (u, u')", "\n".join(f"({p[0]:.6f}, {p[1]:.6f})" for p in shown))
    if "rpm" in s:
        for k, lab in (("rpm", "pinion speed (rpm)"), ("mesh_frequency_Hz", "mesh frequency (Hz)"),
                       ("torque_N_m", "pinion torque, balanced (N·m)"), ("static_force_N", "static mesh force F_p (N)"),
                       ("mesh_force_max_N", "max dynamic mesh force (N)"), ("mesh_force_min_N", "min dynamic mesh force (N)"),
                       ("dynamic_factor", "dynamic factor (max force / F_p)"), ("dte_rms_um", "DTE RMS about mean (µm)"),
                       ("dte_amplitude_um", "DTE half peak-to-peak (µm)"), ("backlash_um", "half backlash (µm)")):
            t.add_row(lab, num(s[k]))
        peaks = s.get("spectrum_peaks") or []
        t.add_row("largest spectral lines (order, Hz, µm)",
                  "\n".join(f"{p['order']:g}, {p['frequency_Hz']:.6g}, {p['amplitude_um']:.4g}" for p in peaks))
    console.print(t)
    if "pair" in s:
        console.print(f"gear pair: {s['pair']}", markup=False, highlight=False)
    for f in files:
        console.print(f"wrote {f}")


@app.command()
def geometry(config: ConfigOpt = None, rpm: RpmOpt = None, torque: TorqueOpt = None, json_out: JsonOpt = False) -> None:
    """Gear pair geometry: pitch cones, directional radii, equivalent mass, k0, ω_n, static mesh force (assumed values marked)."""
    from .config import load_config
    from .geometry import summary_rows

    try:
        summary = load_config(config).at(rpm=rpm, torque=torque).geometry_summary()
    except ModelError as e:
        raise fail(str(e))
    if json_out:
        emit_json(summary)
        return
    from rich.table import Table

    t = Table(title=f"Gear pair geometry: {summary['title'] or summary['source']}")
    for col in ("quantity", "value", "unit", "note"):
        t.add_column(col, overflow="fold")
    for q, v, u, note in summary_rows(summary):
        t.add_row(q, v, u, note, style="yellow" if note.startswith("assumed") else None)
    console.print(t)
    lines = [f"source: {summary['source']}", f"backlash scale: {summary['backlash_reading']}"]
    for a in summary["assumptions"]:
        v = f"{a['value']:.6g}" if isinstance(a["value"], (int, float)) else str(a["value"])
        lines.append(f"assumed {a['name']} = {v}{' ' + a['unit'] if a['unit'] else ''}: {a['source']}")
    lines += [f"note: {n}" for n in summary["notes"]]
    for line in lines:
        console.print(line, markup=False, highlight=False)


@app.command("plot")
def plot_cmd(
    file: Annotated[Path, typer.Argument(help="A NetCDF result written by a geardyn command (--out) or by Python.")],
    out: Annotated[Optional[Path], typer.Option("--out", help="Directory for the PNG figures (default: the file's directory).")] = None,
    physical: Annotated[bool, typer.Option("--physical", help="Also draw physical-unit figures (rpm, µm, N) with the gear pair of --config (default pair: the paper's Table 1) when the file has no physical variables.")] = False,
    config: ConfigOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """Redraw the figures of a saved result from its NetCDF file, chosen by its kind (simulate, bifurcation, response, map, basins, orbit, continuation, ...)."""
    from .io import read_netcdf
    from .plot import PlotUnavailable, save_figures

    if not file.is_file():
        raise fail(f"file: {file} not found")
    try:
        ds = read_netcdf(file)
    except (OSError, ValueError) as e:
        raise fail(f"file: cannot read {file} as a NetCDF result ({type(e).__name__}: {e})")
    try:
        if physical or config is not None:
            from .analysis.physical import add_physical

            ds = add_physical(ds, None if (config is None and "physical_scales" in ds.attrs) else pair_scales(config))
        files = [str(p) for p in save_figures(ds, out if out is not None else file.parent)]
    except (PlotUnavailable, ModelError) as e:
        raise fail(f"{file}: {e}")
    if json_out:
        emit_json({"kind": ds.attrs.get("geardyn_kind"), "files": files})
        return
    for f in files:
        console.print(f"wrote {f}", markup=False, highlight=False)


# ---------------------------------------------------------------- periodic orbits: shooting and continuation
PeriodOpt = Annotated[int, typer.Option("--period", help="Period n of the orbit in forcing periods (Newton solves P^n(x) = x).")]
GuessOpt = Annotated[Optional[str], typer.Option("--guess", help="Shooting guess 'u,v' at θ = 0 (default: the state reached by simulating --transient periods from --u0, --v0).")]
#: Points of the brute-force up/down sweep drawn under a continuation figure, and its recorded periods.
CONTINUATION_SWEEP_NUM = 101
CONTINUATION_SWEEP_PERIODS = 32


def _parse_guess(text: Optional[str]) -> Optional[tuple[float, float]]:
    """'u,v' → (u, v); None when not given."""
    if text is None:
        return None
    try:
        vals = tuple(float(p) for p in text.split(","))
    except ValueError:
        vals = ()
    if len(vals) != 2 or not all(abs(v) < float("inf") for v in vals):
        raise ModelError(f"guess: expected two finite numbers 'u,v', got {text!r}")
    return vals  # type: ignore[return-value]


@app.command()
def orbit(
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    period: PeriodOpt = 1,
    guess: GuessOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    accurate: AccurateOpt = False,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Find a period-n orbit by shooting (Newton on the n-period map, Jacobian = monodromy matrix) and report its
    section points, Floquet multipliers, stability, extremes and impact state."""
    from . import validate
    from .analysis.periodic import shoot
    from .analysis.physical import add_physical, physical_json

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        opts = build_options(dtau, transient, 1, accurate, model.omega)
        n = validate.integer("period", period, 1, 1024)
        g = _parse_guess(guess)
        state0 = validate.initial_state(u0, v0)
        res = shoot(model, n, g, dtau=opts.dtau, accurate=opts.accurate, state0=state0, transient=opts.transient)
    except ModelError as e:
        raise fail(str(e))
    files: list[str] = []
    if out is not None:
        from .io import write_netcdf
        from .plot import save_figures

        nc, figdir = out_paths(out, "orbit")
        ds = add_physical(res.to_dataset(), scales)
        files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_figures(ds, figdir)]
    summary = physical_json(res.to_json(), model, scales)
    if json_out:
        summary["files"] = files
        emit_json(summary)
        return
    _print_orbit(summary, files)


def _print_orbit(s: dict[str, Any], files: list[str]) -> None:
    from rich.table import Table

    t = Table(title=f"Period-{s['requested_period']} orbit at ω = {s['omega']:g}", show_header=False)
    t.add_row("converged", f"{s['converged']} ({s['status']}, {s['iterations']} Newton iterations, residual {s['residual']})")
    t.add_row("minimal period", str(s["period"]))
    t.add_row("state (u, u') at θ = 0", f"({s['state'][0]:.10g}, {s['state'][1]:.10g})")
    t.add_row("section points", "\n".join(f"({p[0]:.8f}, {p[1]:.8f})" for p in s["points"]))
    t.add_row("Floquet multipliers", "\n".join(f"{m[0]:+.8f} {m[1]:+.8f}i  (|μ| = {abs(complex(*m)):.8f})"
                                                for m in s["multipliers"]))
    t.add_row("stable", f"{s['stable']} (instability: {s['instability']})")
    for k in ("u_min", "u_max", "amplitude"):
        t.add_row(k, "n/a" if s[k] is None else f"{s[k]:.8g}")
    t.add_row("impact state", s["impact"])
    console.print(t)
    for f in files:
        console.print(f"wrote {f}")


@app.command()
def continuation(
    param: Annotated[Optional[str], typer.Option("--param", help="Continuation parameter: omega, xi0, xiK, kappaR, fp, epsL (fe), D (backlash), phi_cK, phi_kR, phi_eL (default omega with --rpm-start/--rpm-stop).")] = None,
    start: Annotated[Optional[float], typer.Option("--start", help="Parameter value where the branch starts (the first orbit is found there by shooting).")] = None,
    stop: Annotated[Optional[float], typer.Option("--stop", help="Parameter value where the continuation ends (may lie below --start).")] = None,
    rpm_start: RpmStartOpt = None,
    rpm_stop: RpmStopOpt = None,
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    period: PeriodOpt = 1,
    guess: GuessOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    accurate: Annotated[bool, typer.Option("--accurate/--default-mode", help="Accurate mode (steps split at u = ±D; the default here, since its Floquet multipliers vary smoothly along a branch) or the default integration mode (faster; multipliers jump by O(Δτ) where RK4 stages cross ±D).")] = True,
    switch: Annotated[bool, typer.Option("--switch/--no-switch", help="Switch at period doublings onto the period-2n branch and continue it.")] = True,
    max_period: Annotated[int, typer.Option("--max-period", help="Largest period reached by branch switching.")] = 4,
    ds_max: Annotated[Optional[float], typer.Option("--ds-max", help="Largest arclength step in (u, u', p/|stop - start|) (default 0.01: at least 100 steps over the interval).")] = None,
    sweep_num: Annotated[int, typer.Option("--sweep-num", help="Points of the brute-force up/down sweep drawn under the figure with --out (0: none).")] = CONTINUATION_SWEEP_NUM,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Pseudo-arclength continuation of periodic orbits in any parameter: stable and unstable branches, folds,
    period doublings (with branch switching), Neimark–Sacker points and grazing; with --out the figure shows the
    branches over the brute-force up/down sweep."""
    from . import validate
    from .analysis.periodic import continuation as run_continuation
    from .analysis.physical import add_physical, physical_json
    from .model import canonical_param

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        if param is None and (rpm_start is not None or rpm_stop is not None):
            param = "omega"
        if param is None:
            raise ModelError("param: give the continuation parameter (--param), or a pinion-speed range (--rpm-start/--rpm-stop)")
        name = canonical_param(param)
        start, stop = rpm_range(config, rpm_start, rpm_stop, start, stop, name)
        if start is None or stop is None:
            raise ModelError("start: give the parameter range (--start and --stop), or --rpm-start and --rpm-stop for omega")
        start_v, stop_v = validate.number("start", start), validate.number("stop", stop)
        m0 = model.with_param(name, start_v)
        opts = build_options(dtau, transient, 1, accurate, m0.omega)
        opts.check_for(model.with_param(name, stop_v).omega)
        n = validate.integer("period", period, 1, 1024)
        mp = validate.integer("max-period", max_period, 1, 1024)
        nsw = validate.integer("sweep-num", sweep_num, 0, 100_000)
        if ds_max is not None:
            validate.positive("ds-max", ds_max)
        g = _parse_guess(guess)
        state0 = validate.initial_state(u0, v0)
        res = run_continuation(model, name, start_v, stop_v, n, g, dtau=opts.dtau, accurate=opts.accurate,
                               switch=switch, max_period=mp, ds_max=ds_max, state0=state0)
        sweep_ds = None
        if out is not None and nsw > 0:
            from .analysis.bifurcation import bifurcation, sweep_values

            sweep_ds = bifurcation(model, name, sweep_values(start_v, stop_v, nsw), mode="continue", sweep="both",
                                   state0=state0, options=IntegrationOptions(dtau=opts.dtau, transient=opts.transient,
                                                                             periods=CONTINUATION_SWEEP_PERIODS))
    except ModelError as e:
        raise fail(str(e))
    files: list[str] = []
    if out is not None:
        from .io import attach, write_netcdf
        from .plot import save_figures
        from .plot.periodic import SWEEP_CONTEXT

        nc, figdir = out_paths(out, "continuation")
        ds = add_physical(res.to_dataset(), scales)
        if sweep_ds is not None:
            sweep_ds = add_physical(sweep_ds, scales)
            ds = attach(ds, SWEEP_CONTEXT, sweep_ds)  # the file redraws the figure with its sweep
        files = [str(write_netcdf(ds, nc))]
        if sweep_ds is not None:
            files.append(str(write_netcdf(sweep_ds, nc.with_name(nc.stem + "_sweep.nc"))))
        files += [str(p) for p in save_figures(ds, figdir)]
    summary = physical_json(res.to_json(), model, scales, param=name)
    if json_out:
        summary["files"] = files
        emit_json(summary)
        return
    _print_continuation(summary, files)


def _print_continuation(s: dict[str, Any], files: list[str]) -> None:
    from rich.table import Table

    p = s["param"]
    t = Table(title=f"Branches in {p} from {s['start']:g} to {s['stop']:g}")
    for col in ("branch", "period", "points", "from", "end"):
        t.add_column(col)
    for b in s["branches"]:
        src = "" if b["from"] is None else f"{b['from']['type']} at {p} = {b['from'][p]:.6g}"
        t.add_row(str(b["branch"]), str(b["period"]), str(b["points"]), src, b["end"])
    console.print(t)
    t = Table(title="Bifurcations")
    for col in ("type", p, "period", "branch", "amplitude", "multipliers", "detail"):
        t.add_column(col)
    for b in s["bifurcations"]:
        mus = ", ".join(f"{complex(*m):.4f}" for m in b["multipliers"])
        t.add_row(b["type"], f"{b[p]:.6f}", str(b["period"]), str(b["branch"]), f"{b['amplitude']:.4f}", mus, b["detail"])
    console.print(t)
    for note in s.get("notes", []):
        console.print(f"note: {note}", markup=False, highlight=False)
    for f in files:
        console.print(f"wrote {f}")

# ---------------------------------------------------------------- chaos diagnostics and sweeps
ModeOpt = Annotated[str, typer.Option("--mode", help="fixed: every point from (u0, v0); continue: each point from the previous end state.")]
SweepDirOpt = Annotated[str, typer.Option("--sweep", help="Continuation direction: up (increasing), down (decreasing) or both.")]
LyapunovFlagOpt = Annotated[bool, typer.Option("--lyapunov", help="Largest Lyapunov exponent for every point (otherwise only for non-periodic points, to classify them).")]
SettleOpt = Annotated[int, typer.Option("--settle", help="Further periods (with exponents) for points not periodic after the transient, before classification (0: none).")]
ChunkOpt = Annotated[int, typer.Option("--chunk-size", help="Points per chunk of a fixed-initial-state sweep.")]


def _sweep_files(ds: Any, out: Optional[Path], stem: str, engine: dict[str, Any]) -> list[str]:
    """Write a sweep's NetCDF file and figures (with --out), then drop its checkpoint."""
    if out is None:
        return []
    from .io import write_netcdf
    from .plot import save_figures

    nc, figdir = out_paths(out, stem)
    files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_figures(ds, figdir)]
    finish_sweep(engine)
    return files


def _choice(name: str, value: str, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise ModelError(f"{name}: must be one of {', '.join(allowed)}, got {value!r}")
    return value


@app.command()
def lyapunov(
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    periods: Annotated[int, typer.Option("--periods", help="Forcing periods over which the exponents are averaged.")] = 2000,
    accurate: AccurateOpt = False,
    blocks: Annotated[int, typer.Option("--blocks", help="Blocks of the block-statistics uncertainty (>= 2).")] = 20,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Both Lyapunov exponents (per unit τ) by the Benettin method with Gram–Schmidt each period, with their
    uncertainty from block statistics, and the motion class."""
    from . import validate
    from .analysis.lyapunov import lyapunov_spectrum
    from .analysis.physical import add_physical, physical_json

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        opts = build_options(dtau, transient, periods, accurate, model.omega)
        nb = validate.integer("blocks", blocks, 2, max(2, opts.periods))
        res = lyapunov_spectrum(model, opts, validate.initial_state(u0, v0), blocks=nb)
    except ModelError as e:
        raise fail(str(e))
    files: list[str] = []
    if out is not None:
        from .io import write_netcdf
        from .plot import save_figures

        nc, figdir = out_paths(out, "lyapunov")
        ds = add_physical(res.to_dataset(), scales)
        files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_figures(ds, figdir)]
    s = physical_json(res.to_json(), model, scales)
    if json_out:
        s["files"] = files
        emit_json(s)
        return

    def fmt(x: Any) -> str:
        return "n/a" if x is None else f"{x:+.6f}"

    console.print(f"Lyapunov exponents at ω = {s['omega']:g} over {s['periods']} periods (per unit τ, ± one standard error):")
    for i in range(2):
        console.print(f"  λ{i + 1} = {fmt(s['exponents'][i])} ± {s['uncertainty'][i] or float('nan'):.2e}")
    console.print(f"  λ1 + λ2 = {fmt(s['sum'])}   (−2ξ0 = {s['expected_sum']:+.6f})")
    console.print(f"  motion: {s['motion']}")
    for f in files:
        console.print(f"wrote {f}")


@app.command()
def bifurcation(
    param: Annotated[Optional[str], typer.Option("--param", help="Swept parameter: omega, xi0, xiK, kappaR, fp, epsL (fe), D (backlash), phi_cK, phi_kR, phi_eL (default omega with --rpm-start/--rpm-stop).")] = None,
    start: Annotated[Optional[float], typer.Option("--start", help="First parameter value.")] = None,
    stop: Annotated[Optional[float], typer.Option("--stop", help="Last parameter value.")] = None,
    rpm_start: RpmStartOpt = None,
    rpm_stop: RpmStopOpt = None,
    num: Annotated[int, typer.Option("--num", help="Number of parameter values.")] = 101,
    mode: ModeOpt = "fixed",
    sweep: SweepDirOpt = "up",
    lyap: LyapunovFlagOpt = False,
    settle: SettleOpt = 1000,
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    periods: PeriodsOpt = DEFAULT_PERIODS,
    accurate: AccurateOpt = False,
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    resume: ResumeOpt = False,
    chunk_size: ChunkOpt = 16,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Bifurcation diagram over any parameter: Poincaré points, period, motion class, impact state and amplitudes
    per point (and the largest Lyapunov exponent with --lyapunov); fixed initial state or continuation, up/down/both."""
    from . import validate
    from .analysis.bifurcation import MODES, SWEEPS, bifurcation as run_bifurcation, bifurcation_json
    from .analysis.physical import add_physical, physical_json
    from .model import canonical_param

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        if param is None and (rpm_start is not None or rpm_stop is not None):
            param = "omega"
        if param is None:
            raise ModelError("param: give the swept parameter (--param), or a pinion-speed range (--rpm-start/--rpm-stop)")
        start, stop = rpm_range(config, rpm_start, rpm_stop, start, stop, canonical_param(param))
        if start is None or stop is None:
            raise ModelError("start: give the parameter range (--start and --stop), or --rpm-start and --rpm-stop for omega")
        name, values = validate.axis(param, start, stop, num)
        models = validate.grid(model, [(name, values)])
        opts = build_options(dtau, transient, periods, accurate)
        for m in models:
            opts.check_for(m.omega)
        _choice("mode", mode, MODES)
        _choice("sweep", sweep, SWEEPS)
        nset = validate.integer("settle", settle, 0)
        nc = out_paths(out, "bifurcation")[0] if out is not None else None
        engine = sweep_engine(workers, scheduler, resume, nc, json_out)
        ds = run_bifurcation(model, name, values, mode=mode, sweep=sweep, state0=validate.initial_state(u0, v0),
                             options=opts, lyapunov=lyap, settle_periods=nset,
                             chunk_points=validate.chunk_points(chunk_size), **engine)
        ds = add_physical(ds, scales)
    except ModelError as e:
        raise fail(str(e))
    files = _sweep_files(ds, out, "bifurcation", engine)
    s = physical_json(bifurcation_json(ds), model, scales, param=name)
    if json_out:
        s["files"] = files
        emit_json(s)
        return
    _print_intervals(s, files)


def _print_intervals(s: dict[str, Any], files: list[str]) -> None:
    from rich.table import Table

    iv = s["intervals"]
    groups = iv if isinstance(iv, dict) else {s["sweep"]: iv}
    for lab, rows in groups.items():
        t = Table(title=f"Motion over {s['param']} ({lab})")
        for col in ("from", "to", "points", "motion"):
            t.add_column(col)
        for r in rows:
            t.add_row(f"{r['from']:.6g}", f"{r['to']:.6g}", str(r["points"]), r["motion"])
        console.print(t)
    for f in files:
        console.print(f"wrote {f}")


@app.command()
def response(
    omega_start: Annotated[Optional[float], typer.Option("--omega-start", help="Lowest ω of the sweeps.")] = None,
    omega_stop: Annotated[Optional[float], typer.Option("--omega-stop", help="Highest ω of the sweeps.")] = None,
    rpm_start: RpmStartOpt = None,
    rpm_stop: RpmStopOpt = None,
    torque: TorqueOpt = None,
    num: Annotated[int, typer.Option("--num", help="Number of ω values (the jumps are located to within one step).")] = 71,
    measure: Annotated[str, typer.Option("--measure", help="Amplitude measure: amplitude (half peak-to-peak), rms, u_max, u_min or mean.")] = "amplitude",
    lyap: LyapunovFlagOpt = False,
    settle: SettleOpt = 1000,
    config: ConfigOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    periods: PeriodsOpt = DEFAULT_PERIODS,
    accurate: AccurateOpt = False,
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    resume: ResumeOpt = False,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Amplitude-frequency response swept up and down with state continuation: jumps (ω, direction, size, sweep)
    and hysteresis intervals where the sweeps end on different attractors."""
    from . import validate
    from .analysis.physical import add_physical, physical_json
    from .analysis.response import MEASURES, frequency_response, response_json

    try:
        model = build_model(config, torque=torque, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp, fe=fe, backlash=backlash,
                            phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        omega_start, omega_stop = rpm_range(config, rpm_start, rpm_stop, omega_start, omega_stop)
        if omega_start is None or omega_stop is None:
            raise ModelError("omega_start: give the range as --omega-start/--omega-stop or as --rpm-start/--rpm-stop")
        _, values = validate.axis("omega", omega_start, omega_stop, num)
        validate.grid(model, [("omega", values)])
        opts = build_options(dtau, transient, periods, accurate, float(values.min()))
        _choice("measure", measure, MEASURES)
        nset = validate.integer("settle", settle, 0)
        nc = out_paths(out, "response")[0] if out is not None else None
        engine = sweep_engine(workers, scheduler, resume, nc, json_out)
        ds = frequency_response(model, float(values[0]), float(values[-1]), values.size, options=opts,
                                state0=validate.initial_state(u0, v0), measure=measure, lyapunov=lyap,
                                settle_periods=nset, **engine)
        ds = add_physical(ds, scales)
    except ModelError as e:
        raise fail(str(e))
    files = _sweep_files(ds, out, "response", engine)
    s = physical_json(response_json(ds), model, scales, param="omega")
    if json_out:
        s["files"] = files
        emit_json(s)
        return
    from rich.table import Table

    t = Table(title="Jumps")
    for col in ("sweep", "ω (midpoint)", "from → to", "direction", "size", "pinion speed (rpm)", "size (µm)"):
        t.add_column(col)
    for j in s["jumps"]:
        t.add_row(j["sweep"], f"{j['omega']:.6g}", f"{j['omega_from']:.6g} → {j['omega_to']:.6g}", j["direction"],
                  f"{j['size']:.4g}", f"{j['rpm']:.1f} ({j['rpm_from']:.1f} → {j['rpm_to']:.1f})", f"{j['size_um']:.4g}")
    console.print(t)
    hy = ", ".join(f"[{a:.6g}, {b:.6g}]" for a, b in s["hysteresis"]) or "none"
    hy_rpm = ", ".join(f"[{a:.1f}, {b:.1f}]" for a, b in s.get("hysteresis_rpm", [])) or "none"
    console.print(f"hysteresis (coexisting attractors): ω {hy}; rpm {hy_rpm}", markup=False, highlight=False)
    console.print(f"gear pair: {s['physical']['pair']}", markup=False, highlight=False)
    for f in files:
        console.print(f"wrote {f}")


@app.command("map")
def map_cmd(
    x: Annotated[str, typer.Option("--x", help="Parameter along the horizontal axis (e.g. omega).")],
    y: Annotated[str, typer.Option("--y", help="Parameter along the vertical axis (e.g. xi0 or D).")],
    x_start: Annotated[Optional[float], typer.Option("--x-start", help="First x value (for x = omega also as --rpm-start).")] = None,
    x_stop: Annotated[Optional[float], typer.Option("--x-stop", help="Last x value (for x = omega also as --rpm-stop).")] = None,
    y_start: Annotated[Optional[float], typer.Option("--y-start", help="First y value (for y = omega also as --rpm-start).")] = None,
    y_stop: Annotated[Optional[float], typer.Option("--y-stop", help="Last y value (for y = omega also as --rpm-stop).")] = None,
    rpm_start: RpmStartOpt = None,
    rpm_stop: RpmStopOpt = None,
    x_num: Annotated[int, typer.Option("--x-num", help="Number of x values.")] = 41,
    y_num: Annotated[int, typer.Option("--y-num", help="Number of y values.")] = 21,
    mode: ModeOpt = "fixed",
    lyap: LyapunovFlagOpt = False,
    settle: SettleOpt = 1000,
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    u0: U0Opt = 0.0,
    v0: V0Opt = 0.0,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    periods: PeriodsOpt = DEFAULT_PERIODS,
    accurate: AccurateOpt = False,
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    resume: ResumeOpt = False,
    chunk_size: ChunkOpt = 16,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """2-D parameter map (e.g. ω × ξ0, ω × D) of motion class, impact state, amplitude and largest exponent."""
    from . import validate
    from .analysis.bifurcation import MODES
    from .analysis.maps import map_json, parameter_map
    from .analysis.physical import add_physical, physical_json
    from .model import canonical_param

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        if rpm_start is not None or rpm_stop is not None:
            if canonical_param(y) == "omega":
                y_start, y_stop = rpm_range(config, rpm_start, rpm_stop, y_start, y_stop, "omega")
            else:
                x_start, x_stop = rpm_range(config, rpm_start, rpm_stop, x_start, x_stop, canonical_param(x))
        for nm, val in (("x_start", x_start), ("x_stop", x_stop), ("y_start", y_start), ("y_stop", y_stop)):
            if val is None:
                raise ModelError(f"{nm}: required (for an omega axis a pinion-speed range --rpm-start/--rpm-stop also works)")
        xn, xv = validate.axis(x, x_start, x_stop, x_num)
        yn, yv = validate.axis(y, y_start, y_stop, y_num)
        opts = build_options(dtau, transient, periods, accurate)
        validate.grid(model, [(yn, yv), (xn, xv)], opts)
        _choice("mode", mode, MODES)
        nset = validate.integer("settle", settle, 0)
        nc = out_paths(out, "map")[0] if out is not None else None
        engine = sweep_engine(workers, scheduler, resume, nc, json_out)
        ds = parameter_map(model, xn, xv, yn, yv, mode=mode, state0=validate.initial_state(u0, v0), options=opts,
                           lyapunov=lyap, settle_periods=nset, chunk_points=validate.chunk_points(chunk_size), **engine)
        ds = add_physical(ds, scales)
    except ModelError as e:
        raise fail(str(e))
    files = _sweep_files(ds, out, "map", engine)
    s = physical_json(map_json(ds), model, scales)
    if json_out:
        s["files"] = files
        emit_json(s)
        return
    counts = ", ".join(f"{k}: {v}" for k, v in s["motion_counts"].items())
    console.print(f"map of {s['y']} × {s['x']}: {len(s['y_values'])} × {len(s['x_values'])} points; {counts}")
    for f in files:
        console.print(f"wrote {f}")


@app.command()
def basins(
    u_min: Annotated[float, typer.Option("--u-min", help="Smallest initial displacement u0.")] = -3.0,
    u_max: Annotated[float, typer.Option("--u-max", help="Largest initial displacement u0.")] = 3.0,
    v_min: Annotated[float, typer.Option("--v-min", help="Smallest initial velocity v0.")] = -3.0,
    v_max: Annotated[float, typer.Option("--v-max", help="Largest initial velocity v0.")] = 3.0,
    nu: Annotated[int, typer.Option("--nu", help="Grid points along u0.")] = 41,
    nv: Annotated[int, typer.Option("--nv", help="Grid points along v0.")] = 41,
    settle: SettleOpt = 1000,
    config: ConfigOpt = None,
    rpm: RpmOpt = None,
    torque: TorqueOpt = None,
    omega: OmegaOpt = None,
    xi0: Xi0Opt = None,
    xi1: Xi1Opt = None,
    kappa1: Kappa1Opt = None,
    fp: FpOpt = None,
    fe: FeOpt = None,
    backlash: BacklashOpt = None,
    phi_c: PhiCOpt = None,
    phi_k: PhiKOpt = None,
    phi_e: PhiEOpt = None,
    dtau: DtauOpt = DEFAULT_DTAU,
    transient: TransientOpt = DEFAULT_TRANSIENT,
    periods: Annotated[int, typer.Option("--periods", help="Forcing periods recorded per initial state (>= 2 × the largest period detected).")] = 64,
    accurate: AccurateOpt = False,
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    resume: ResumeOpt = False,
    chunk_size: Annotated[int, typer.Option("--chunk-size", help="Initial states per chunk.")] = 64,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """Basins of attraction: a grid of initial states (u0, v0) at θ = 0, each labelled by the attractor it reaches
    (attractors identified by their Poincaré cycles)."""
    from . import validate
    from .analysis.basins import basins as run_basins, basins_json
    from .analysis.physical import add_physical, physical_json

    try:
        model = build_model(config, rpm=rpm, torque=torque, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp,
                            fe=fe, backlash=backlash, phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        scales = pair_scales(config)
        opts = build_options(dtau, transient, periods, accurate, model.omega)
        lo_u, hi_u = validate.number("u-min", u_min), validate.number("u-max", u_max)
        lo_v, hi_v = validate.number("v-min", v_min), validate.number("v-max", v_max)
        n_u, n_v = validate.integer("nu", nu, 1, 100_000), validate.integer("nv", nv, 1, 100_000)
        nset = validate.integer("settle", settle, 0)
        nc = out_paths(out, "basins")[0] if out is not None else None
        engine = sweep_engine(workers, scheduler, resume, nc, json_out)
        ds = run_basins(model, (lo_u, hi_u), (lo_v, hi_v), n_u, n_v, options=opts, settle_periods=nset,
                        chunk_points=validate.chunk_points(chunk_size), **engine)
        ds = add_physical(ds, scales)
    except ModelError as e:
        raise fail(str(e))
    files = _sweep_files(ds, out, "basins", engine)
    s = physical_json(basins_json(ds), model, scales)
    if json_out:
        s["files"] = files
        emit_json(s)
        return
    from rich.table import Table

    t = Table(title=f"Attractors at ω = {s['omega']:g} ({n_u} × {n_v} initial states)")
    for col in ("label", "motion", "basin share", "amplitude", "Poincaré points (u, u')"):
        t.add_column(col)
    for a in s["attractors"]:
        pts = a["points"][:4]
        txt = "; ".join(f"({p[0]:.4f}, {p[1]:.4f})" for p in pts) + (" …" if len(a["points"]) > 4 else "")
        t.add_row(str(a["label"]), a["motion"], f"{100 * a['fraction']:.1f} %", f"{a['amplitude']:.4g}", txt)
    console.print(t)
    if s["diverged_fraction"] > 0:
        console.print(f"diverged: {100 * s['diverged_fraction']:.1f} % of the initial states")
    for f in files:
        console.print(f"wrote {f}")


#: Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
EXIT_INTERRUPTED = 130


@app.command()
def reproduce(
    out: Annotated[Path, typer.Option("--out", help="Directory for report.html, report.md, claims.json, figures and data.")] = Path("results"),
    quick: Annotated[bool, typer.Option("--quick", help="A reduced run (coarse grids, short runs) that exercises every study.")] = False,
    workers: Annotated[int, typer.Option("--workers", help="Worker processes for the sweeps.")] = 2,
    json_out: JsonOpt = False,
) -> None:
    """Run every study of the paper on its Table 1 pair and write a report judging each claim."""
    from dataclasses import replace

    from .reproduce import Settings, run

    if workers < 1:
        raise fail(f"workers: must be >= 1, got {workers}")
    settings = replace(Settings.quick() if quick else Settings(), workers=workers)
    log = (lambda m: None) if json_out else (lambda m: err_console.print(f"… {m}", markup=False, highlight=False))
    res = run(out, settings, log=log)
    claims = res["claims"]
    if json_out:
        emit_json({"report": res["paths"], "seconds": res["seconds"],
                   "claims": [{"id": c.id, "verdict": c.verdict, "computed": c.computed} for c in claims]})
        return
    from rich.table import Table

    t = Table(title="Claims of the paper")
    for col in ("id", "verdict", "computed"):
        t.add_column(col, overflow="fold")
    style = {"reproduced": "green", "partly reproduced": "yellow", "not reproduced": "red"}
    for c in claims:
        t.add_row(c.id, f"[{style[c.verdict]}]{c.verdict}[/]", c.computed)
    console.print(t)
    console.print(f"report: {res['paths']['html']} ({res['seconds']:.1f} s)")


@app.command()
def bench(
    workload: Annotated[str, typer.Option("--workload", help="W1 (bifurcation), W2 (trajectory), W3 (Lyapunov) or all.")] = "all",
    threads: Annotated[Optional[int], typer.Option("--threads", help="Kernel threads (default: all cores).")] = None,
    repeats: Annotated[int, typer.Option("--repeats", help="Timed runs per workload; the minimum is reported.")] = 5,
    json_out: JsonOpt = False,
) -> None:
    """Time the integrator on the standard workloads (in-process, after JIT warm-up, minimum of the runs)."""
    from .bench import WORKLOADS, run_benchmarks

    names = list(WORKLOADS) if workload.lower() == "all" else [workload]
    if threads is not None and threads < 1:
        raise fail(f"threads: must be >= 1, got {threads}")
    if repeats < 1:
        raise fail(f"repeats: must be >= 1, got {repeats}")
    res = run_benchmarks(names, threads=threads, repeats=repeats)
    if json_out:
        emit_json(res)
        return
    from rich.table import Table

    t = Table(title=f"geardyn bench ({res['threads']} thread(s), minimum of {res['repeats']} runs)")
    for col in ("workload", "wall (s)", "RK4 steps", "ns/step"):
        t.add_column(col, justify="right" if col != "workload" else "left")
    for name, r in res["workloads"].items():
        t.add_row(name, f"{r['wall_s']:.4f}", f"{r['steps']:,}", f"{r['ns_per_step']:.2f}")
    console.print(t)
    m = res["machine"]
    console.print(f"{m['cpu']}, {m['cores']} cores, load average {m.get('load_average', 'n/a')}", markup=False, highlight=False)


def main(argv: Optional[list[str]] = None) -> None:
    """Entry point: run the app; every input error becomes one line on stderr, never a traceback.

    Exit codes: 0 success; 2 invalid input (model and option errors, unknown options, values
    that do not parse, bad configuration files); 130 interrupted by Ctrl-C (a sweep says how to
    resume); 1 other failures such as an unwritable output or a lost Dask scheduler.
    """
    from .sweep import SweepFailed, SweepInterrupted

    # typer's parser exceptions (its own vendored click, or click itself in older versions)
    cx = sys.modules[typer.BadParameter.__module__]
    usage_error, click_exception = cx.UsageError, cx.ClickException
    no_args_is_help = getattr(cx, "NoArgsIsHelpError", ())
    try:
        rv = app(args=argv, prog_name="geardyn", standalone_mode=False)
    except no_args_is_help as e:  # type: ignore[misc]
        print(e.ctx.get_help() if e.ctx is not None else e.format_message())
        raise SystemExit(0) from None
    except usage_error as e:
        where = f" (see 'geardyn {e.ctx.info_name} --help')" if e.ctx is not None and e.ctx.parent is not None else ""
        say_error(f"error: {e.format_message()}{where}")
        raise SystemExit(2) from None
    except ModelError as e:
        say_error(f"error: {e}")
        raise SystemExit(2) from None
    except SweepInterrupted as e:
        say_error(str(e))
        raise SystemExit(EXIT_INTERRUPTED) from None
    except SweepFailed as e:
        say_error(f"error: {e}")
        raise SystemExit(1) from None
    except typer.Abort:
        say_error("interrupted")
        raise SystemExit(EXIT_INTERRUPTED) from None
    except click_exception as e:
        say_error(f"error: {e.format_message()}")
        raise SystemExit(e.exit_code) from None
    except OSError as e:
        if e.errno == errno.EPIPE:  # output piped into a program that stopped reading
            raise SystemExit(1) from None
        name = f" {e.filename}" if getattr(e, "filename", None) else ""
        say_error(f"error: cannot access{name}: {e.strerror or e}")
        raise SystemExit(1) from None
    if rv == EXIT_INTERRUPTED:  # Ctrl-C outside a sweep (typer maps it to exit code 130)
        say_error("interrupted")
    if isinstance(rv, int) and not isinstance(rv, bool):
        raise SystemExit(rv)


if __name__ == "__main__":
    main()
