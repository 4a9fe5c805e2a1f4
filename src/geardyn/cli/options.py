"""The options the commands share, generated once: model options from the parameter registry, the operating
point, the initial state, integration, the sweep engine and the output.

A command declares only its own options and names the groups it takes::

    @command("simulate", MODEL, STATE, integration(), OUTPUT)
    def simulate(inp: Inputs) -> None:
        model = inp.model()
        ...

:func:`command` adds the groups' options to the command's signature (so ``--help`` and ``docs/cli.md`` list
them), collects their values into one :class:`Inputs`, and turns every :class:`~geardyn.errors.GeardynError`
into one line on stderr and exit code 2.
"""

from __future__ import annotations

import functools
import inspect
import sys
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from .. import params
from ..errors import GeardynError, ModelError, SweepFailed, SweepInterrupted
from ..model import DEFAULT_DTAU, DEFAULT_PERIODS, DEFAULT_TRANSIENT, GearModel, IntegrationOptions
from .app import GeardynCommand, app, emit_json, fail, say_error
from .output import check_budget, check_out, engine_keywords, out_paths, write_released

__all__ = [
    "CONFIG",
    "ENGINE",
    "EXCITATION",
    "FIGURE_OPTIONS",
    "JSON_ONLY",
    "MODEL",
    "OUTPUT",
    "STATE",
    "SYSTEM",
    "Inputs",
    "build_model",
    "choice",
    "command",
    "finish",
    "integration",
    "sweep_range",
    "model_group",
    "option",
    "param_option",
    "CONTINUATION_PARAM",
    "CONTINUATION_STOP",
]

_P = inspect.Parameter
MODEL_PANEL = "Model (non-dimensional)"
PHYSICAL_PANEL = "Gear pair and operating point"
RUN_PANEL = "Integration"
ENGINE_PANEL = "Sweep engine"
OUTPUT_PANEL = "Output"


def option(
    dest: str,
    kind: Any,
    default: Any = None,
    *flags: str,
    help: str,
    panel: str | None = None,
    metavar: str | None = None,
) -> inspect.Parameter:
    """One keyword-only typer option as a signature parameter.

    Parameters
    ----------
    dest : str
        The keyword the command function receives.
    kind : type
        The option's type annotation (``float``, ``Path | None``, ``bool`` for a flag ...).
    default : object
        The value when the option is not given (default None).
    *flags : str
        The option's flags, e.g. ``"--dtau"``; none: typer's, ``--`` and ``dest`` with ``-`` for ``_`` (an
        on/off flag of type ``bool`` names its flags).
    help : str
        The help text.
    panel : str, optional
        The ``--help`` panel it is listed in.
    metavar : str, optional
        The value's placeholder in ``--help`` (default: typer's).

    Returns
    -------
    inspect.Parameter
        A keyword-only parameter annotated with its ``typer.Option``.
    """
    return _P(
        dest,
        _P.KEYWORD_ONLY,
        default=default,
        annotation=Annotated[kind, typer.Option(*flags, help=help, rich_help_panel=panel, metavar=metavar)],
    )


CONFIG = [
    option(
        "config",
        Path | None,
        panel=PHYSICAL_PANEL,
        help="TOML file with the gear pair, mesh and operating point (default: the paper's Table 1).",
    )
]
RPM = option(
    "rpm",
    float | None,
    panel=PHYSICAL_PANEL,
    help="Pinion speed in rpm (sets ω for the gear pair of --config, else of a tooth-pair --excitation file; "
    "default pair: the paper's Table 1, k0 = 2000 N/µm assumed).",
)
TORQUE = option(
    "torque",
    float | None,
    panel=PHYSICAL_PANEL,
    help="Pinion torque in N·m, balanced (sets f_p for the gear pair of --config, else of a tooth-pair "
    "--excitation file).",
)
TORQUE_ORDER = option(
    "torque_order",
    list[str] | None,
    metavar="ORDER:AMPLITUDE[:PHASE]",
    panel=PHYSICAL_PANEL,
    help="A torque order ORDER:AMPLITUDE[:PHASE] (repeatable; PHASE in rad, default 0): a load harmonic "
    "of constant amplitude. With --config of a gear pair: ORDER of the pinion speed (frequency "
    "ORDER/z1 of the mesh frequency), AMPLITUDE a pinion torque in N·m (the gear's torque steady). "
    "Otherwise (no --config, or a non-dimensional configuration): ORDER of the mesh frequency "
    "(e.g. 2 or 1/2), AMPLITUDE non-dimensional like --fp.",
)
EXCITATION = option("excitation", Path | None, panel=PHYSICAL_PANEL, help=params.EXCITATION_HELP)
EVALUATION = option(
    "excitation_evaluation",
    str | None,
    panel=PHYSICAL_PANEL,
    help="series (default) or table: with --accurate, the table as given, piecewise linear with its jumps.",
)
RPM_RANGE = [
    option(
        "rpm_start",
        float | None,
        panel=PHYSICAL_PANEL,
        help="Start of an ω sweep given as pinion speed in rpm (with --rpm-stop).",
    ),
    option(
        "rpm_stop",
        float | None,
        panel=PHYSICAL_PANEL,
        help="End of an ω sweep given as pinion speed in rpm (with --rpm-start).",
    ),
]


def model_group(*, omega: bool = True) -> list[inspect.Parameter]:
    """``--config``, the operating point and one option per registry family (see :func:`geardyn.params.cli_options`).

    Parameters
    ----------
    omega : bool
        Include ``--omega`` and ``--rpm``; ``False`` for commands that sweep ω themselves.

    Returns
    -------
    list of inspect.Parameter
    """
    return [
        *CONFIG,
        EXCITATION,
        EVALUATION,
        *([RPM] if omega else []),
        TORQUE,
        TORQUE_ORDER,
        *(
            option(o.dest, float | None, None, o.flag, help=o.help, panel=MODEL_PANEL)
            for o in params.cli_options()
            if omega or o.param != "omega"
        ),
    ]


MODEL = model_group()
STATE = [
    option("u0", float, 0.0, help="Initial displacement u at θ = 0.", panel=RUN_PANEL),
    option("v0", float, 0.0, help="Initial velocity u' at θ = 0.", panel=RUN_PANEL),
]
ACCURATE_HELP = "Split steps at the contact crossings u = ±D (4th order through contact loss)."


ADAPTIVE_HELP = (
    "Adaptive transient: --transient becomes a maximum; each point stops its transient once its "
    "Poincaré points have converged onto a period-n cycle (n <= 32, estimated distance 1e-10) and "
    "records that cycle; other points run the full transient."
)


def integration(
    *,
    periods: int | None = DEFAULT_PERIODS,
    periods_help: str = "Forcing periods recorded (Poincaré points).",
    accurate: inspect.Parameter | None = None,
    adaptive: bool = False,
) -> list[inspect.Parameter]:
    """The integration options ``--dtau --transient [--periods] --accurate [--adaptive]``.

    ``--dtau`` and ``--transient`` default to :data:`~geardyn.model.DEFAULT_DTAU` and
    :data:`~geardyn.model.DEFAULT_TRANSIENT`.

    Parameters
    ----------
    periods : int or None
        Default of ``--periods`` (default :data:`~geardyn.model.DEFAULT_PERIODS`); ``None`` leaves
        ``--periods`` out.
    periods_help : str
        Help text of ``--periods``.
    accurate : inspect.Parameter, optional
        A command's own ``--accurate`` option in place of the standard one.
    adaptive : bool
        Add ``--adaptive`` (the sweep commands).

    Returns
    -------
    list of inspect.Parameter
    """
    group = [
        option("dtau", float, DEFAULT_DTAU, help="Target RK4 step Δτ; the step is T/ceil(T/Δτ).", panel=RUN_PANEL),
        option(
            "transient",
            str,
            str(DEFAULT_TRANSIENT),
            help="Forcing periods discarded before recording; or N followed by 'cycles' (e.g. 3000cycles): N "
            "reference mesh cycles, rounded up to whole forcing periods; or auto: as many as the least damped mode "
            "of the linearised system takes to decay by e^-12 (at least 4, at most 20000; docs/analysis.md). Not "
            "given, with a forcing period of several reference mesh cycles: auto's count (at least 1), and the "
            "default --periods in mesh cycles (at least 4 forcing periods), said before the run.",
            panel=RUN_PANEL,
        ),
    ]
    if periods is not None:
        group.append(option("periods", int, periods, help=periods_help, panel=RUN_PANEL))
    group.append(accurate or option("accurate", bool, False, "--accurate", help=ACCURATE_HELP, panel=RUN_PANEL))
    if adaptive:
        group.append(option("adaptive", bool, False, "--adaptive", help=ADAPTIVE_HELP, panel=RUN_PANEL))
    return group


ENGINE = [
    option(
        "workers",
        int,
        1,
        panel=ENGINE_PANEL,
        help="Chunks of a sweep integrated at once, on threads of this process (1: one at a time on every "
        "kernel thread; N: N at a time on 1/N of them each).",
    ),
    option(
        "processes",
        bool,
        False,
        "--processes",
        panel=ENGINE_PANEL,
        help="Run the --workers in local worker processes instead of threads (a worker process that dies "
        "is replaced; each process costs 140-190 MB of memory).",
    ),
    option(
        "scheduler",
        str | None,
        panel=ENGINE_PANEL,
        help="Run the sweep on a running Dask scheduler, tcp://HOST:PORT (workers need geardyn installed).",
    ),
    option(
        "resume",
        bool,
        False,
        "--resume",
        panel=ENGINE_PANEL,
        help="Complete an interrupted sweep with the same --out: chunks already finished are kept.",
    ),
]
OUTPUT = [
    option("json_out", bool, False, "--json", help="Print a machine-readable summary on stdout.", panel=OUTPUT_PANEL),
    option(
        "out",
        Path | None,
        help="Directory (or .nc file) for NetCDF data and figures.",
        panel=OUTPUT_PANEL,
    ),
]
#: ``--json`` alone, of the commands that write no result file.
JSON_ONLY = OUTPUT[:1]
#: How figures are saved (with ``--out``; and by ``geardyn plot``).
FIGURE_OPTIONS = [
    option(
        "fig_format",
        str,
        "png",
        "--format",
        panel=OUTPUT_PANEL,
        help="File formats of the figures, comma-separated: png, pdf, svg (e.g. png,pdf).",
    ),
    option("dpi", int, 120, panel=OUTPUT_PANEL, help="Resolution of PNG figures (dots per inch)."),
]
OUTPUT += FIGURE_OPTIONS
SYSTEM_PANEL = "Multi-DOF system"
#: ``--system``, taken by the commands that run on a multi-DOF system (:mod:`geardyn.cli.system_input`).
SYSTEM = [
    option(
        "system",
        Path | None,
        panel=SYSTEM_PANEL,
        help="TOML file of a multi-DOF system (bodies, bearings, meshes; see examples/systems): the analysis "
        "runs on it, and the JSON summary adds one entry per mesh under 'meshes'.",
    )
]


# ---------------------------------------------------------------- the physical front end
def _at_default(values: dict[str, Any]) -> tuple[set[str], str | None]:
    """The options of ``values`` the user did not give (their source the default), from the running command's
    click context (of the click typer runs on: its own vendored copy in newer typer), and the command's name; none
    outside a command (every value counts as given)."""
    import importlib

    core = sys.modules[typer.Context.__mro__[1].__module__]
    ctx = importlib.import_module(core.__name__.rsplit(".", 1)[0] + ".globals").get_current_context(silent=True)
    if ctx is None:
        return set(), None
    at_default = (core.ParameterSource.DEFAULT, core.ParameterSource.DEFAULT_MAP)  # a name it does not know: given
    return {name for name in values if ctx.get_parameter_source(name) in at_default}, ctx.info_name


def build_model(
    config: Path | None = None,
    *,
    rpm: float | None = None,
    torque: float | None = None,
    excitation: Path | None = None,
    evaluation: str | None = None,
    torque_orders: Any = None,
    **values: float | None,
) -> GearModel:
    """The model of a configuration and excitation file with the command-line values applied on top (validated):
    :meth:`geardyn.inputs.PairInputs.model`.

    Parameters
    ----------
    config : Path, optional
        Configuration file (default: the paper's Table 1, or the pair of a tooth-pair ``excitation``).
    rpm, torque : float, optional
        Pinion speed and pinion torque (N·m, balanced): they set ω and f_p through the scales of the
        run's gear pair and cannot be combined with ``omega`` / ``fp``.
    excitation : Path, optional
        A mesh excitation table (``docs/excitation.md``) in place of the config's stiffness and STE series.
    evaluation : str, optional
        ``"series"`` or ``"table"``: how the excitation table is evaluated (default: the configuration's, else series).
    torque_orders : list of str, optional
        ``--torque-order`` texts ``ORDER:AMPLITUDE[:PHASE]`` (:func:`geardyn.torque_orders.parse_cli`), added to the
        configuration's: pinion orders and torques (N·m) for a gear pair, else mesh orders, non-dimensional.
    **values
        The registry's model options by keyword (``omega``, ``xi0``, …); ``None`` keeps the config's value.

    Raises
    ------
    ModelError
        For an unknown keyword or an invalid value.
    """
    from ..inputs import PairInputs

    return PairInputs(config, excitation, evaluation).model(
        rpm=rpm, torque=torque, torque_orders=torque_orders, **values
    )


class Inputs:
    """The values of a command's shared option groups, with the checked objects built from them.

    Every value is also an attribute (``inp.json_out``, ``inp.rpm_start``, ...).

    Parameters
    ----------
    values : dict
        The shared options' values by keyword, as the command received them.
    """

    def __init__(self, values: dict[str, Any]) -> None:
        self.values = values
        self._pair: Any = None
        self._systems: dict[tuple, Any] = {}
        self._defaults, self._command = _at_default(values)

    def __getattr__(self, name: str) -> Any:
        try:
            return self.__dict__["values"][name]
        except KeyError:
            raise AttributeError(name) from None

    def model(self, **fixed: float | None) -> Any:
        """The model of ``--config`` (or the system of ``--system``, the model options on its reference mesh) with
        the model options and the operating point applied: a System.

        Parameters
        ----------
        **fixed : float or None
            Model options set by the command itself (keywords of :func:`build_model`), over the given ones.

        Raises
        ------
        ModelError
            For an invalid value or a conflicting ``--rpm`` / ``--torque``.
        """
        v = self.values
        if v.get("system") is not None:  # the system of the file, the options applied to its reference mesh
            if v.get("torque_order"):
                raise ModelError(
                    "--torque-order: applies to the pair; with --system write orders = [{order, amplitude, phase}] "
                    "on a drive or load of the system file"
                )
            key = tuple(sorted((k, x) for k, x in fixed.items() if x is not None))
            if key not in self._systems:  # one system (and one read of its file) per set of fixed values
                from .system_input import load_cli_system

                # the notes before the run leave a default transient and record to the long-run plan (options())
                at_default = {"transient_default": self._fixed_default("transient", DEFAULT_TRANSIENT)}
                self._systems[key] = load_cli_system({**v, **dict(key), **at_default})
            return self._systems[key]
        given = {**{o.dest: v.get(o.dest) for o in params.cli_options()}, **fixed}
        return self.pair().model(rpm=v.get("rpm"), torque=v.get("torque"), torque_orders=v.get("torque_order"), **given)

    def pair(self) -> Any:
        """The gear pair's files of ``--config`` and ``--excitation``, each read once for the command
        (:class:`geardyn.inputs.PairInputs`)."""
        if self._pair is None:
            from ..inputs import PairInputs

            v = self.values
            self._pair = PairInputs(v.get("config"), v.get("excitation"), v.get("excitation_evaluation"))
        return self._pair

    def scales(self):
        """The physical scales of the run's gear pair (of a system's reference mesh with ``--system``)."""
        if self.values.get("system") is not None:
            from ..systems.report import physical_scales

            return physical_scales(self.model())
        return self.pair().scales()

    def options(
        self, omega: float | None = None, *, periods: int | None = None, omegas: Any = (), points: int = 1
    ) -> IntegrationOptions:
        """Validated integration options, checked against ``omega`` (or every one of ``omegas``) and against the
        memory the recorded periods of ``points`` points take.

        Parameters
        ----------
        omega : float, optional
            The forcing frequency the step is checked against.
        periods : int, optional
            Recorded periods in place of ``--periods`` (1 for commands without it).
        omegas : sequence of float
            Every frequency of a sweep, checked likewise.
        points : int
            Parameter points whose recorded periods are held in memory at once.

        Returns
        -------
        IntegrationOptions
            The options of the command line (``--dtau``, ``--transient``, ``--periods``, ``--accurate``,
            ``--adaptive``).

        Raises
        ------
        ModelError
            For an invalid step, transient or period count, or too much memory.
        """
        from .. import validate

        v = self.values
        n = periods if periods is not None else v.get("periods", 1)
        ws = omegas if omega is None else (*omegas, omega)  # a sweep's array passed as it is, not as a list
        plan = self.long_run(ws, periods)
        if plan is not None:
            n = plan.periods if periods is None and "periods" in v else n
        opts = validate.options(
            v["dtau"], plan.transient if plan is not None else self.transient(ws), n, v["accurate"], ws
        )
        validate.recorded(points, opts.periods)
        model = self.model() if v.get("system") is not None else None  # the pair: its own per-period constants
        check_budget(
            opts,
            ws,
            points,
            cycles=(model.period_multiple() or 1) if model else 1,
            dofs=model.state_dim // 2 if model else 1,
        )
        return opts.replace(adaptive=True) if v.get("adaptive") else opts

    def long_run(self, omegas: Any = (), periods: int | None = None) -> Any:
        """The counts of a run whose forcing period spans several reference mesh cycles when ``--transient`` or
        ``--periods`` was not given (:func:`geardyn.analysis.settle.long_run`), said once on stderr before the run;
        None when both were given, or the forcing period is one mesh cycle (the fixed defaults stand).

        Parameters
        ----------
        omegas : sequence of float
            The run's frequencies (the transient is that of the highest).
        periods : int, optional
            Recorded periods set by the command (not ``--periods``).

        Returns
        -------
        geardyn.analysis.settle.LongRun or None
        """
        v = self.values
        t_default = self._fixed_default("transient", DEFAULT_TRANSIENT)
        p_default = periods is None and self._fixed_default("periods", DEFAULT_PERIODS)
        if not (t_default or p_default) or not isinstance(v.get("dtau"), (int, float)):
            return None
        model = self.model()
        p = model.period_multiple()
        if not p or int(p) <= 1:
            return None
        import numpy as np

        from .. import validate
        from ..analysis.settle import long_run

        dtau, _, _ = validate.counts(v["dtau"])
        ws = np.atleast_1d(np.asarray(omegas, dtype=float))
        given_t = None if t_default else self.transient(omegas)
        given_p = (periods if periods is not None else v.get("periods")) if not p_default else None
        validate.counts(transient=given_t, periods=given_p)  # refused before the plan's note is said of them
        plan = long_run(
            model,
            dtau,
            transient=given_t,
            periods=given_p,
            default_transient=DEFAULT_TRANSIENT if t_default else None,
            default_periods=v.get("periods") if p_default else None,
            omegas=ws if ws.size else None,
        )
        # simulate classifies within the plan's budget; a sweep's points are classified by its --settle
        note = plan.note(classify=self._command == "simulate", per_point=ws.size > 1) if plan is not None else None
        if note is not None and self._new(note):
            if v.get("system") is None:  # a system's file note says the forcing period already
                say_error(f"forcing period: {plan.cycles} mesh cycles; {plan.steps:,} RK4 steps each (dtau = {dtau:g})")
            for line in note.splitlines():
                say_error(line)
        return plan

    def _new(self, note: str) -> bool:
        """Whether ``note`` is not yet said on stderr by this command (a command may ask twice); it counts as said."""
        said = self.__dict__.setdefault("_said", set())
        return note not in said and not said.add(note)

    def _fixed_default(self, name: str, value: int) -> bool:
        """Whether option ``name`` was not given and its default is the fixed count ``value`` (a command with its
        own default, as ``rattle``'s transient or ``lyapunov``'s periods, keeps it)."""
        return name in self._defaults and str(self.values.get(name)).strip() == str(value)

    def transient(self, omegas: Any = ()) -> Any:
        """``--transient`` as a number of forcing periods: ``auto`` is the count of
        :func:`geardyn.analysis.settle.settle_periods` for the run's model at the highest of ``omegas`` (said on
        stderr); ``Ncycles`` is N reference mesh cycles, :func:`geardyn.analysis.settle.cycles_to_periods` of the
        run's model (said on stderr, not with ``--json``); a number is passed on as given, checked by
        :func:`geardyn.validate.options`.

        Raises
        ------
        ModelError
            For a text that is neither a whole number, ``Ncycles`` nor ``auto``, ``auto`` for a model without
            damping, or ``Ncycles`` for a quasi-periodic system.
        """
        from ..analysis.settle import cycles_to_periods, transient_cycles

        t = self.values.get("transient", DEFAULT_TRANSIENT)
        if not isinstance(t, str):
            return t
        cycles = transient_cycles(t)
        if cycles is not None:
            n = cycles_to_periods(cycles, self.model())
            note = f"transient: {cycles} reference mesh cycles = {n} forcing periods"
            if not self.values.get("json_out") and self._new(note):
                say_error(note)
            return n
        if t.strip().lower() == "auto":
            import numpy as np

            from ..analysis.settle import settle_periods

            ws = np.atleast_1d(np.asarray(omegas, dtype=float))
            s = settle_periods(self.model(), ws if ws.size else None)
            if self._new(s.note()):
                say_error(s.note())
            return s.periods
        try:
            return int(t.strip())
        except ValueError:
            raise ModelError(
                f"--transient: must be an integer (forcing periods, >= 0), Ncycles (reference mesh cycles) or auto, "
                f"got {t!r}"
            ) from None

    def system_summary(self, model: Any, summary: dict[str, Any], ds: Any = None, result: Any = None) -> dict:
        """``summary`` with what a ``--system`` adds (:func:`geardyn.cli.system_input.mesh_summary`: ``meshes`` of a
        sweep's ``ds`` or a continuation's ``result``, ...); the pair's as it is."""
        v = self.values
        if v.get("system") is None:
            return summary
        from .system_input import mesh_summary

        return mesh_summary(model, summary, ds, result, state0=(v.get("u0") or 0.0, v.get("v0") or 0.0))

    def progress(self, what: str, unit: str = "", *, param: str | None = None, on: bool = True) -> Any:
        """A progress bar on stderr (:func:`geardyn.sweep.progress.task_progress`, counts), none with ``--json``;
        with ``param`` that of a continuation in it (``"what ω"``, ``Δω`` traced)."""
        from ..sweep.progress import task_progress

        fmt = ".0f"
        if param is not None:
            from ..analysis.bifurcation import param_symbol

            try:
                sym = param_symbol(param)
            except (KeyError, ValueError):  # a system's parameter (<mesh>.xi0, ...) by its name
                sym = param
            what, unit, fmt = f"{what} {sym}", f"Δ{sym} traced", ".4g"
        return task_progress(what, unit=unit, fmt=fmt, enabled=on and not self.json_out)

    def param_range(
        self, param: str | None, start: float | None, stop: float | None, *, what: str = "swept"
    ) -> tuple[str, float, float]:
        """The canonical name and the finite range of a swept (or continued) parameter.

        ``--rpm-start/--rpm-stop`` give ω's range in pinion speed (and make ω the default parameter); a
        model option given for the same parameter is refused (:meth:`not_swept`).
        """
        from .. import validate
        from ..grid import param_name

        if param is None and (self.values.get("rpm_start") is not None or self.values.get("rpm_stop") is not None):
            param = "omega"
        if param is None:
            raise ModelError(
                f"param: give the {what} parameter (--param), or a pinion-speed range (--rpm-start/--rpm-stop)"
            )
        name = param_name(param)
        self.not_swept(name)
        start, stop = sweep_range(self, start, stop, name)
        if start is None or stop is None:
            raise ModelError(
                "start: give the parameter range (--start and --stop), or --rpm-start and --rpm-stop for omega"
            )
        return name, validate.number("start", start), validate.number("stop", stop)

    def not_swept(self, *names: str) -> None:
        """Refuse a model option given for a parameter the command sweeps (it would be silently overridden).

        Parameters
        ----------
        *names : str
            The swept parameters.

        Raises
        ------
        ModelError
            If the option of one of them (or ``--rpm`` / ``--torque`` for ω / f_p) was given.
        """
        flags = {o.param: (o.dest, o.flag) for o in params.cli_options()}
        physical = {"omega": ("rpm", "--rpm"), "fp": ("torque", "--torque")}
        for name in names:
            for dest, flag in filter(None, (flags.get(name), physical.get(name))):
                if self.values.get(dest) is not None:
                    raise ModelError(
                        f"{flag.lstrip('-')}: {flag} {self.values[dest]:g} conflicts with the swept "
                        f"parameter {name}; give its range instead"
                    )

    def state0(self) -> tuple[float, float]:
        """The initial state (u0, v0)."""
        from .. import validate

        return validate.initial_state(self.values["u0"], self.values["v0"])

    def engine(self, stem: str) -> dict[str, Any]:
        """Validated keyword arguments of :func:`geardyn.sweep.run_chunks` from the sweep-engine options
        (:func:`geardyn.cli.output.engine_keywords`); call :meth:`write` with them once the result is complete.

        Parameters
        ----------
        stem : str
            File stem of the NetCDF file (its checkpoint directory is named after it).

        Returns
        -------
        dict
            ``workers``, ``processes``, ``scheduler``, ``checkpoint``, ``resume`` and ``progress``.

        Raises
        ------
        ModelError
            For an invalid engine option, or ``--resume`` without ``--out``.
        """
        return engine_keywords(self.values, stem)

    def figures(self) -> dict[str, Any]:
        """``fmt`` and ``dpi`` of :func:`geardyn.plot.save_figures` from ``--format`` and ``--dpi``, checked.

        Returns
        -------
        dict
            ``{"fmt": tuple of str, "dpi": int}`` (PNG at 120 dpi for a command without the options).

        Raises
        ------
        ModelError
            For an unknown format or a resolution out of range.
        """
        from .. import validate

        return {
            "fmt": validate.figure_formats(self.values.get("fig_format", "png")),
            "dpi": validate.dpi(self.values.get("dpi", 120)),
        }

    def write(self, ds: Any, stem: str, engine: dict[str, Any] | None = None, *, release: bool = False) -> list[str]:
        """With ``--out``: write the result's NetCDF file and its figures, then drop a sweep's checkpoint.

        Parameters
        ----------
        ds : xarray.Dataset
            The result.
        stem : str
            File stem of the NetCDF file inside an ``--out`` directory.
        engine : dict, optional
            The :meth:`engine` keywords of a sweep (its checkpoint is removed).
        release : bool
            Once the NetCDF file is written, drop the variables of ``ds`` (in place) and draw the
            figures from the file, each loading only what it draws: for results too large to hold
            next to their figures.

        Returns
        -------
        list of str
            The files written (none without ``--out``).
        """
        out = self.values.get("out")
        if out is None:
            return []
        nc, figdir = out_paths(out, stem)
        if release:
            files = write_released(ds, nc, figdir, **self.figures())
        else:
            from ..io import write_netcdf
            from ..plot import save_figures

            files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_figures(ds, figdir, **self.figures())]
        if engine is not None and engine.get("checkpoint") is not None:
            from ..sweep import remove_checkpoint

            remove_checkpoint(engine["checkpoint"])
        return files


def finish(summary: dict[str, Any], paths: list[str], inp: Inputs, show: Any, *extra: Any) -> None:
    """Print the summary as JSON (with the files written) or as tables for people.

    Parameters
    ----------
    summary : dict
        The command's JSON summary (``files`` is added for ``--json``).
    paths : list of str
        The files written.
    inp : Inputs
        The command's inputs (``--json`` decides the form).
    show : callable
        ``show(summary, *extra)``, the table renderer (:mod:`geardyn.cli.render`); the files written are
        listed after it.
    *extra : object
        Further arguments of ``show``.
    """
    pair = inp._pair
    if pair is not None and pair.summary() is not None:  # a tooth-pair excitation drives the scales: that pair
        summary["tooth_pair"] = pair.summary()
    if inp.json_out:
        summary["files"] = paths
        emit_json(summary)
        return
    from .render import files, meshes

    if "meshes" in summary:  # a system: its meshes first
        meshes(summary)
    show(summary, *extra)
    files(paths)


def choice(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """``value`` if it is one of ``allowed``, else a one-line refusal.

    Parameters
    ----------
    name : str
        The option, named in the message.
    value : str
        The given value.
    allowed : tuple of str
        The accepted values.

    Returns
    -------
    str
        ``value``.

    Raises
    ------
    ModelError
        If ``value`` is not allowed.
    """
    if value not in allowed:
        raise ModelError(f"{name}: must be one of {', '.join(allowed)}, got {value!r}")
    return value


def sweep_range(
    inp: Inputs, start: float | None, stop: float | None, param: str = "omega"
) -> tuple[float | None, float | None]:
    """(start, stop) of a sweep: ``--rpm-start/--rpm-stop`` converted to ω, else ``start, stop`` as given.

    Parameters
    ----------
    inp : Inputs
        The command's inputs (``rpm_start``, ``rpm_stop`` and the configured pair).
    start, stop : float, optional
        The range as given in non-dimensional units.
    param : str
        The swept parameter (an rpm range sweeps ω only, see :func:`geardyn.units.sweep_range`).

    Returns
    -------
    start, stop : float or None

    Raises
    ------
    ModelError
        If an rpm range is incomplete, combined with a non-dimensional one, given for another
        parameter than ω, or given without a gear pair.
    """
    from ..units import sweep_range as convert

    if inp.rpm_start is None and inp.rpm_stop is None:
        return start, stop
    return convert(inp.scales(), inp.rpm_start, inp.rpm_stop, start, stop, param=param)


def param_option(what: str) -> inspect.Parameter:
    """The ``--param`` option of a command that varies one model parameter, the names it takes listed
    from the parameter registry (:func:`geardyn.params.parameter_names`).

    Parameters
    ----------
    what : str
        What the parameter is to the command (``"Swept parameter"``, ``"Continuation parameter"``).

    Returns
    -------
    inspect.Parameter
        ``--param``, a ``str | None`` option (see :func:`option`).
    """
    return option(
        "param", str | None, help=f"{what}: {params.parameter_names()} (default omega with --rpm-start/--rpm-stop)."
    )


#: ``--param`` of a continuation (HB or shooting).
CONTINUATION_PARAM = param_option("Continuation parameter")
#: ``--stop`` of a continuation (HB or shooting).
CONTINUATION_STOP = option(
    "stop", float | None, help="Parameter value where the continuation ends (may lie below --start)."
)


#: Suffixes that make a command's ``--out`` a file name (else a directory); the NetCDF commands: ``.nc``.
OUT_FILES = {"plot": (), "modes": (".png", ".pdf", ".svg")}


def command(name: str, *groups: list[inspect.Parameter]) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register ``fn(inp, **own_options)`` as a command that also takes the options of ``groups``.

    The command receives an :class:`Inputs` of the groups' values and its own options as keywords;
    a :class:`~geardyn.errors.GeardynError` it raises becomes one line on stderr and exit code 2.

    Parameters
    ----------
    name : str
        The command's name.
    *groups : list of inspect.Parameter
        Shared option groups (:data:`MODEL`, :data:`ENGINE`, :func:`integration` ...).

    Returns
    -------
    callable
        A decorator that registers ``fn`` on the app and returns it unchanged.
    """

    def deco(fn: Callable[..., Any]) -> Callable[..., Any]:
        hints = typing.get_type_hints(fn, include_extras=True)
        own = [
            p.replace(annotation=hints.get(p.name, p.annotation), kind=_P.KEYWORD_ONLY)
            for p in list(inspect.signature(fn).parameters.values())[1:]
        ]
        shared = [p for g in groups for p in g]

        @functools.wraps(fn)
        def wrapper(**kw: Any) -> Any:
            import warnings

            import numpy as np

            inp = Inputs({p.name: kw.pop(p.name) for p in shared})
            # No floating-point warning reaches the user: an overflowing input is refused by the checks that
            # follow (a value that is not finite), a diverging point carries its status.
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                try:
                    # a bad --format, --dpi or --out is refused before the computation, not after it
                    if "fig_format" in inp.values:
                        inp.figures()
                    if inp.values.get("out") is not None:
                        check_out(inp.values["out"], file_suffixes=OUT_FILES.get(name, (".nc",)))
                    return fn(inp, **kw)
                except GeardynError as e:
                    if isinstance(e, (SweepInterrupted, SweepFailed)):  # stopped from outside: main reports it
                        raise
                    raise fail(str(e)) from None

        every = own + shared
        wrapper.__signature__ = inspect.Signature(every)  # type: ignore[attr-defined]
        wrapper.__annotations__ = {p.name: p.annotation for p in every}
        del wrapper.__wrapped__
        app.command(name, cls=GeardynCommand)(wrapper)
        return fn

    return deco
