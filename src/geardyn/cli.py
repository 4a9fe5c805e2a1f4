"""The ``geardyn`` command line: parses options, calls the library, prints.  Nothing else."""

from __future__ import annotations

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


def fail(message: str) -> "typer.Exit":
    """Print one line naming the bad input and return the exit (code 2) to raise."""
    err_console.print(f"error: {message}", markup=False, highlight=False)
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


def base_model(config: Optional[Path]) -> GearModel:
    """The model of ``--config`` (or the paper's defaults)."""
    if config is None:
        return GearModel()
    from .config import load_config

    return load_config(config).model


def build_model(
    config: Optional[Path] = None,
    *,
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
    """The config's model with the command-line values applied on top (validated)."""
    m = base_model(config)
    given = {
        "omega": omega, "xi0": xi0, "xi1": xi1, "kappa1": kappa1, "fp": fp, "eps1": fe, "D": backlash,
        "phi_c1": phi_c, "phi_k1": phi_k, "phi_e1": phi_e,
    }
    for name, value in given.items():
        if value is not None:
            m = m.with_param(name, value)
    return m


def build_options(dtau: float, transient: int, periods: int, accurate: bool, omega: float | None = None) -> IntegrationOptions:
    opts = IntegrationOptions(dtau=dtau, transient=transient, periods=periods, accurate=accurate)
    if omega is not None:
        opts.check_for(omega)
    return opts


def out_paths(out: Path, stem: str) -> tuple[Path, Path]:
    """(NetCDF file, figure directory) for ``--out``: a directory, or a file name ending in .nc."""
    if out.suffix == ".nc":
        return out, out.parent
    return out / f"{stem}.nc", out


# ---------------------------------------------------------------- commands
@app.command()
def simulate(
    config: ConfigOpt = None,
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
    """Integrate one operating point and report its steady response (Poincaré points, period, impact, amplitudes)."""
    from .analysis.steady import simulate as run_simulate

    try:
        model = build_model(config, omega=omega, xi0=xi0, xi1=xi1, kappa1=kappa1, fp=fp, fe=fe, backlash=backlash,
                            phi_c=phi_c, phi_k=phi_k, phi_e=phi_e)
        opts = build_options(dtau, transient, periods, accurate, model.omega)
        for name, val in (("u0", u0), ("v0", v0)):
            if not (abs(val) < float("inf")):
                raise ModelError(f"{name}: must be a finite number, got {val!r}")
        res = run_simulate(model, opts, (u0, v0))
    except ModelError as e:
        raise fail(str(e))
    files: list[str] = []
    if out is not None:
        from .io import write_netcdf
        from .plot.simulate import save_all

        nc, figdir = out_paths(out, "simulate")
        ds = res.to_dataset()
        files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_all(ds, figdir)]
    summary = res.to_json()
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
    console.print(t)
    for f in files:
        console.print(f"wrote {f}")


@app.command()
def geometry(config: ConfigOpt = None, json_out: JsonOpt = False) -> None:
    """Gear pair geometry: pitch cones, directional radii, equivalent mass, k0, ω_n, static mesh force (assumed values marked)."""
    from .config import load_config
    from .geometry import summary_rows

    try:
        summary = load_config(config).geometry_summary()
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


def main() -> None:
    """Entry point: run the app, turning model errors into one-line messages with exit code 2."""
    try:
        app()
    except ModelError as e:
        err_console.print(f"error: {e}", markup=False, highlight=False)
        raise SystemExit(2) from None


if __name__ == "__main__":
    main()
