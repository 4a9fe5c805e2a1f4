"""Commands around the analyses: ``geometry``, ``plot``, ``reproduce``, ``bench``."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from ..errors import GeardynError
from . import render
from .app import emit_json, err_console, fail
from .options import CONFIG, FIGURE_OPTIONS, JSON_ONLY, RPM, TORQUE, Inputs, command, option


@command("geometry", CONFIG, [RPM, TORQUE], JSON_ONLY)
def geometry(inp: Inputs) -> None:
    """Gear pair geometry: pitch cones, directional radii, equivalent mass, k0, ω_n, static mesh force (assumed
    values marked)."""
    from ..config import load_config
    from ..geometry import summary_rows

    summary = load_config(inp.config).at(rpm=inp.rpm, torque=inp.torque).geometry_summary()
    if inp.json_out:
        emit_json(summary)
        return
    render.geometry(summary, summary_rows(summary))


PLOT_OPTIONS = [
    option("out", Path | None, help="Directory for the figures (default: the file's directory)."),
    *FIGURE_OPTIONS,
    option(
        "physical",
        bool,
        False,
        "--physical",
        help="Also draw physical-unit figures (rpm, µm, N) with the gear pair of --config (default pair: the "
        "paper's Table 1) when the file has no physical variables.",
    ),
    *CONFIG,
    *JSON_ONLY,
]


@command("plot", PLOT_OPTIONS)
def plot_cmd(
    inp: Inputs,
    file: Annotated[Path, typer.Argument(help="A NetCDF result written by a geardyn command (--out) or by Python.")],
) -> None:
    """Redraw the figures of a saved result from its NetCDF file, chosen by its kind (simulate, bifurcation,
    response, map, basins, orbit, continuation, ...)."""
    from ..io import read_netcdf
    from ..plot import save_figures

    if not file.is_file():
        raise fail(f"file: {file} not found" + (" (it is a directory)" if file.is_dir() else ""))
    try:
        ds = read_netcdf(file)
    except (OSError, ValueError, TypeError, KeyError, RuntimeError) as e:
        raise fail(
            f"file: cannot read {file} as a NetCDF result ({type(e).__name__}: {' '.join(str(e).split())[:200]})"
        ) from None
    _check_attributes(file, ds)
    try:
        if inp.physical or inp.config is not None:
            from ..analysis.physical import add_physical

            if "geardyn_system" in ds.attrs and ds.attrs["geardyn_system"] != "pair":
                raise fail(
                    f"--physical: {file} is a result of a system file, whose scales are its own; the gear pair of "
                    "--config (the paper's Table 1 by default) would draw another pair's rpm, µm and N"
                )

            ds = add_physical(ds, None if (inp.config is None and "physical_scales" in ds.attrs) else inp.scales())
        files = [str(p) for p in save_figures(ds, inp.out if inp.out is not None else file.parent, **inp.figures())]
    except GeardynError as e:
        raise fail(f"{file}: {e}") from None
    except OSError:
        raise
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, RecursionError) as e:
        kind = ds.attrs.get("geardyn_kind")
        raise fail(
            f"{file}: not a complete geardyn{' ' + str(kind) if isinstance(kind, str) else ''} result "
            f"({type(e).__name__}: {' '.join(str(e).split())[:120]}); it cannot be drawn"
        ) from None
    if inp.json_out:
        emit_json({"kind": ds.attrs.get("geardyn_kind"), "files": files})
        return
    render.files(files)


#: Largest attribute of a result file drawn by ``plot`` (characters of a string, elements of an array).
MAX_ATTRIBUTE_SIZE = 1_000_000
MAX_ATTRIBUTE_ELEMENTS = 10_000


def _check_attributes(file: Path, ds) -> None:
    """Refuse a result whose attributes are too large to be a geardyn result's (they would be parsed)."""
    import numpy as np

    for where, attrs in [("", ds.attrs)] + [(f"{name}.", v.attrs) for name, v in ds.variables.items()]:
        for key, val in attrs.items():
            if isinstance(val, str) and len(val) > MAX_ATTRIBUTE_SIZE:
                raise fail(
                    f"{file}: attribute {where}{key} holds {len(val)} characters; at most "
                    f"{MAX_ATTRIBUTE_SIZE} in a geardyn result"
                )
            if np.size(val) > MAX_ATTRIBUTE_ELEMENTS:
                raise fail(
                    f"{file}: attribute {where}{key} holds {np.size(val)} elements; at most "
                    f"{MAX_ATTRIBUTE_ELEMENTS} in a geardyn result"
                )


@command("reproduce", JSON_ONLY)
def reproduce(
    inp: Inputs,
    out: Annotated[
        Path, typer.Option(help="Directory for report.html, report.md, claims.json, figures and data.")
    ] = Path("results"),
    quick: Annotated[
        bool,
        typer.Option(
            "--quick",
            help=(
                "A reduced run (coarse grids, short runs) that exercises every study; its report and summary say "
                "so, and its verdicts may differ from the full run's."
            ),
        ),
    ] = False,
    workers: Annotated[int, typer.Option(help="Worker processes for the sweeps.")] = 2,
) -> None:
    """Run every study of the paper on its Table 1 pair and write a report judging each claim."""
    from .. import validate
    from ..reproduce import Settings, run
    from .output import check_out

    workers = validate.workers(workers)
    check_out(out, file_suffixes=())
    settings = replace(Settings.quick() if quick else Settings(), workers=workers)
    log = (lambda m: None) if inp.json_out else (lambda m: err_console.print(f"… {m}", markup=False, highlight=False))
    import shlex
    from dataclasses import asdict

    from .options import _at_default

    typed = {"out", "workers"} - _at_default(dict.fromkeys(("out", "workers")))[0]  # (all of them outside a command)
    command = shlex.join(  # the command as typed: an option left at its default is not shown
        ["geardyn", "reproduce"]
        + ["--out", str(out)] * ("out" in typed)
        + ["--quick"] * quick
        + ["--workers", str(workers)] * ("workers" in typed)
        + ["--json"] * inp.json_out
    )
    res = run(out, settings, log=log, command=command)
    if inp.json_out:
        emit_json(
            {
                "report": res["paths"],
                "seconds": res["seconds"],
                "run": asdict(res["run"]),
                "claims": [
                    {"id": c.id, "statement": c.statement, "verdict": c.verdict, "computed": c.computed}
                    for c in res["claims"]
                ],
            }
        )
        return
    render.claims(res)


#: Most timed runs of ``bench`` per workload (each workload takes about a second).
MAX_REPEATS = 100


@command("bench", JSON_ONLY)
def bench(
    inp: Inputs,
    workload: Annotated[str, typer.Option(help="W1 (bifurcation), W2 (trajectory), W3 (Lyapunov) or all.")] = "all",
    threads: Annotated[int | None, typer.Option(help="Kernel threads (default: all cores).")] = None,
    repeats: Annotated[int, typer.Option(help="Timed runs per workload; the minimum is reported.")] = 5,
) -> None:
    """Time the integrator on the standard workloads (in-process, after JIT warm-up, minimum of the runs)."""
    from ..bench import WORKLOADS, run_benchmarks

    names = list(WORKLOADS) if workload.lower() == "all" else [workload]
    from .. import validate

    if threads is not None:
        validate.integer("threads", threads, 1, validate.MAX_WORKERS)
    validate.integer("repeats", repeats, 1, MAX_REPEATS)
    with inp.progress("bench", "runs") as bar:
        res = run_benchmarks(names, threads=threads, repeats=repeats, progress=bar)
    if inp.json_out:
        emit_json(res)
        return
    render.bench(res)
