"""``geardyn reproduce``: every study of the paper, computed and judged, and the report.

Each study (:mod:`geardyn.paper.studies`) runs geardyn's analyses on the paper's Table 1 model,
registers its data, and judges the paper's claims (:mod:`geardyn.paper.claims`) with a stated rule,
returning a :class:`~geardyn.paper.report.Section`.  The studies never plot: :func:`write_outputs`
writes the data (NetCDF) and draws each Dataset's figures with :func:`geardyn.plot.save_figures`
into ``figures/<name>/``, and :func:`link_figures` puts the drawn files into the report, which
:func:`run` then writes.

Settings the paper leaves unstated have a declared default (:class:`~geardyn.paper.settings.Settings`),
with the reason written into the report, and every claim is also judged under the other readings
of them (:mod:`geardyn.paper.studies.readings`, :mod:`geardyn.paper.studies.readings_jumps`): its
verdict is one of four kinds (:data:`geardyn.paper.verdicts.VERDICT_RULES`, stated once in the
report).  No setting is tuned silently.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import xarray as xr

from ..errors import PlotError
from ..io import write_netcdf
from ..model import DEFAULT_DTAU
from ..plot import save_figures
from ..sweep import local_pool
from .report import RunInfo, Section, write_report
from .settings import FIGURE_REF, Context, Settings
from .studies.backlash import study_backlash
from .studies.damping import study_xi0, study_xi1
from .studies.facts import study_facts
from .studies.formula import study_formula
from .studies.jumps import compute_responses, study_jumps, study_table4
from .studies.readings import damping_readings, run_screen
from .studies.readings_jumps import jump_readings, run_lockstep
from .studies.readings_section import fixed_readings, readings_section
from .studies.stability import jump_continuation, study_orbits, study_stability
from .studies.tables import study_tables
from .table1 import TABLE1
from .verdicts import VERDICT_RULES

__all__ = [
    "STUDIES",
    "Settings",
    "link_figures",
    "run",
    "run_info",
    "run_studies",
    "settings_section",
    "write_output",
    "write_outputs",
]

#: The studies that need only the context, in report order (the jump studies share their responses).
STUDIES: list[Callable[[Context], Section]] = [study_xi0, study_xi1, study_backlash]

TITLE = "geardyn reproduction of the spiral bevel gear paper"
INTRO = [
    "This report reruns every study of the paper 'Nonlinear Dynamic Response of Spiral Bevel Gear Pairs with "
    "Time-Varying Backlash' with geardyn and judges each of its claims under every reading of what the paper "
    "leaves open: reproduced, reproduced under a named reading, contradicted, or not testable, with the readings "
    "tried, the numbers and the figures that show it.",
    "Source: 'Nonlinear Dynamic Response of Spiral Bevel Gear Pairs with Time-Varying Backlash', as its text was "
    "given to this project; that text names no authors, journal, year or DOI, so none is cited here.",
]


def run_studies(ctx: Context) -> list[Section]:
    """Run every study in report order (the continuation starts first, on a worker if there is a pool).

    Parameters
    ----------
    ctx : Context

    Returns
    -------
    list of Section
    """
    s = ctx.settings
    key = s.xi0_set[0]
    args = (ctx.model_at(key), *s.continuation_omega)
    kw = {
        "sweep_num": s.continuation_sweep_num,
        "sweep_options": s.response_options.replace(periods=s.continuation_sweep_periods),
    }
    # the continuation (and its brute-force sweep) is long and sequential: start it first, on a worker if any
    branch_future = ctx.executor.submit(jump_continuation, *args, **kw) if ctx.executor is not None else None
    sections = [study(ctx) for study in STUDIES]
    jd = compute_responses(ctx)
    sections += [study_jumps(ctx, jd), study_table4(ctx, jd), study_formula(ctx, jd), study_stability(ctx)]
    ctx.log("periodic orbits through the first jump")
    branch = branch_future.result() if branch_future is not None else jump_continuation(*args, **kw)
    sections.insert(-3, study_orbits(ctx, branch, jd))
    findings = {c.id: c for sec in sections for c in sec.claims}
    default_holds = {cid: f.verdict == "reproduced" for cid, f in findings.items()}
    ctx.log("readings: screen of the damping and backlash claims")
    dres = damping_readings(ctx, run_screen(ctx), findings)
    ctx.log("readings: lockstep responses of the jump claims")
    jr = run_lockstep(ctx)
    jres = jump_readings(ctx, jr, findings)
    fixed_readings(findings)
    return [
        *study_facts(ctx),
        *sections,
        *study_tables(ctx, dres, jr, jres, default_holds, findings),
        readings_section(ctx, findings),
    ]


def settings_section(s: Settings, elapsed: float, total: float | None = None) -> Section:
    """The report's first section: the model, the choices the paper leaves open, the verdict rules.

    Parameters
    ----------
    s : Settings
    elapsed : float
        Computation time of the studies (s).
    total : float, optional
        With the data and figures written (s): the time the command reports.

    Returns
    -------
    Section
    """
    return Section(
        "Settings",
        [
            f"Model: the paper's Table 1 (ξ0 = {TABLE1['xi0']}, ξ1 = {TABLE1['xi1']}, κ1 = {TABLE1['kappa1']}, "
            f"f_p = {TABLE1['fp']}, ε1 = {TABLE1['eps1']} i.e. f_e = {TABLE1['eps1']:g} ω² cos θ, D = {TABLE1['D']:g}, "
            f"phases 0), RK4 with Δτ = {DEFAULT_DTAU:g} (h = T/ceil(T/Δτ)), {s.transient} transient and {s.periods} "
            "recorded periods per point.",
            f"Default reading: ω = {s.omega_damping:g} for the damping and backlash studies (not stated in the paper; "
            "ω = 1 puts the mesh frequency at the linear natural frequency), phases φ_c1 = φ_k1 = φ_e1 = 0, and the "
            "paper's backlash b in mm read as D = b/(2 mm), as its Table 3 pairs them. Every claim is also judged "
            f"under the other readings (section 'Readings'): ω on a grid of step 0.01, φ_c1 and φ_k1 over "
            "{0, π/2, π, 3π/2}, and D = b/(1 mm) or b/(0.1 mm).",
            "Verdict rules, applied by every study below:",
            *VERDICT_RULES,
            f"Computation time: {elapsed:.1f} s for the studies"
            + (f", {total:.1f} s with their data and figures (the time the command reports)." if total else "."),
        ],
    )


def write_output(ds: xr.Dataset, nc: Path, figures: Path | None) -> list[Path]:
    """Write one study's Dataset (NetCDF, atomically) and draw its figures into ``figures``.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.
    nc : Path
        The NetCDF file.
    figures : Path or None
        The directory of its figures (:func:`geardyn.plot.save_figures`); None: data only.

    Returns
    -------
    list of Path
        The figure files, main figure first.
    """
    write_netcdf(ds, nc)
    return [] if figures is None else save_figures(ds, figures)


def write_outputs(ctx: Context) -> dict[str, list[str]]:
    """Write every registered Dataset and its figures, in parallel on the run's executor.

    Parameters
    ----------
    ctx : Context

    Returns
    -------
    dict
        Name → figure paths relative to ``ctx.out``, main figure first.
    """
    names = list(ctx.pending)
    jobs = [
        (ctx.pending[n], ctx.out / ctx.datasets[n], None if n in ctx.data_only else ctx.out / "figures" / n)
        for n in names
    ]
    if ctx.executor is None:
        drawn = [write_output(*job) for job in jobs]
    else:
        drawn = [f.result() for f in [ctx.executor.submit(write_output, *job) for job in jobs]]
    ctx.pending.clear()
    return {n: [Path(p).relative_to(ctx.out).as_posix() for p in paths] for n, paths in zip(names, drawn)}


def link_figures(sections: Sequence[Section], figures: Mapping[str, Sequence[str]]) -> None:
    """Replace the figure references of the studies (:meth:`Context.figure`) by the drawn main figures.

    Parameters
    ----------
    sections : sequence of Section
        Changed in place: their figure lists and the evidence of their claims.
    figures : mapping
        Name → figure paths (:func:`write_outputs`).

    Raises
    ------
    PlotError
        If a referenced Dataset has no figure.
    """

    def resolve(ref: str) -> str:
        if not ref.startswith(FIGURE_REF):
            return ref
        name = ref.removeprefix(FIGURE_REF)
        if not figures.get(name):
            raise PlotError(f"no figure was drawn for {name!r}, which the report refers to")
        return figures[name][0]

    for s in sections:
        s.figures = [(resolve(p), caption) for p, caption in s.figures]
        for c in s.claims:
            c.evidence = [resolve(e) for e in c.evidence]


#: The command line recorded for a run started from Python (:func:`run` without ``command``).
PYTHON_COMMAND = "geardyn.reproduce.run (from Python)"


def run_info(settings: Settings, command: str | None = None) -> RunInfo:
    """Where a run's report comes from: geardyn's version, the date and time now (UTC), the command
    line, and what the run changes from the full reproduction.

    Parameters
    ----------
    settings : Settings
        The run's settings.
    command : str, optional
        The command line (default :data:`PYTHON_COMMAND`).

    Returns
    -------
    RunInfo
    """
    from .. import __version__

    date = datetime.now(UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")
    return RunInfo(__version__, date, command or PYTHON_COMMAND, settings.run_kind(), settings.changes())


def run(
    out: str | Path,
    settings: Settings = Settings(),
    *,
    log: Callable[[str], None] = lambda s: None,
    executor: Executor | None = None,
    command: str | None = None,
) -> dict[str, Any]:
    """Run every study, draw the figures, write the report.

    Parameters
    ----------
    out : str or Path
        The report directory (created): ``report.md``, ``report.html``, ``claims.json``, ``run.json``,
        ``data/`` and ``figures/``.
    settings : Settings, optional
        The run's settings (``Settings.quick()`` for a reduced run).
    log : callable, optional
        Receives one progress line per step.
    executor : concurrent.futures.Executor, optional
        Where the sweeps run; default a local pool of ``settings.workers`` processes (none for 1).
    command : str, optional
        The command line, written into the report (default :data:`PYTHON_COMMAND`).

    Returns
    -------
    dict
        ``paths`` (the report files), ``claims`` (every :class:`~geardyn.paper.report.Finding`),
        ``run`` (the :class:`~geardyn.paper.report.RunInfo`) and ``seconds``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    info = run_info(settings, command)
    if info.reduced:
        log(info.banner("listed in the report"))
    own = executor is None and settings.workers > 1
    if own:
        executor = local_pool(settings.workers)
    try:
        ctx = Context(out, settings, executor, log)
        sections = run_studies(ctx)
        t_compute = time.perf_counter() - t0
        log("data and figures")
        figures = write_outputs(ctx)
    finally:
        if own:
            executor.shutdown(wait=True)
    link_figures(sections, figures)
    t_total = time.perf_counter() - t0  # what the command reports: the studies, their data and figures
    sections.insert(0, settings_section(settings, t_compute, t_total))
    paths = write_report(
        out,
        TITLE,
        INTRO,
        sections,
        meta={
            "settings": asdict(settings),
            "compute_s": t_compute,
            "total_s": t_total,
            "datasets": ctx.datasets,
            "figures": figures,
        },
        labels=ctx.labels,
        run=info,
    )
    return {
        "paths": {k: str(v) for k, v in paths.items()},
        "claims": [c for s in sections for c in s.claims],
        "run": info,
        "seconds": t_total,
    }
