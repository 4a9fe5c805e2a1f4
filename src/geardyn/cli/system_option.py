"""``--system FILE``: the commands on a multi-DOF system file (``examples/systems/*.toml``).

:data:`SYSTEM` is the option group the commands of :data:`SYSTEM_COMMANDS` take; when ``--system`` is
given, the ``command`` decorator hands the call to :func:`run_system`, which loads the system,
applies ``--omega`` / ``--rpm`` (and any mesh option, to the reference mesh), runs the analysis on
the N-DOF kernel and prints the command's usual summary plus ``meshes`` (one entry per mesh:
``name``, ``u_min``, ``u_max``, ``amplitude``, ``impact``, ``dynamic_factor``, ...).  Commands not
yet available on systems refuse with one line.
"""

from __future__ import annotations

import inspect
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import ModelError
from .app import emit_json

__all__ = ["SYSTEM", "SYSTEM_COMMANDS", "run_system"]

SYSTEM_PANEL = "Multi-DOF system"
SYSTEM = [inspect.Parameter(
    "system", inspect.Parameter.KEYWORD_ONLY, default=None,
    annotation=Annotated[Optional[Path], typer.Option(
        "--system", rich_help_panel=SYSTEM_PANEL,
        help="TOML file of a multi-DOF system (bodies, bearings, meshes; see examples/systems): the analysis runs "
             "on it, and the JSON summary adds one entry per mesh under 'meshes'.")])]

#: Commands that take ``--system``.
SYSTEM_COMMANDS = ("simulate", "lyapunov", "orbit", "continuation", "bifurcation", "response", "map", "basins")
_NOT_MODEL = {"config", "rpm", "torque", "omega", "fp"}


def load_cli_system(values: dict[str, Any]):
    """The system of ``--system`` with ``--omega``/``--rpm`` and the mesh options applied.

    Parameters
    ----------
    values : dict
        The command's shared option values (``system``, ``omega``, ``rpm``, model options ...).

    Returns
    -------
    SystemModel

    Raises
    ------
    ModelError
        For a bad system file, or options that do not apply to a system (``--config``,
        ``--torque``, ``--fp``, ``--rpm`` with ``--omega``).
    """
    from .. import params
    from ..systems import load_system

    path = values["system"]
    if values.get("config") is not None:
        raise ModelError("system: --system and --config cannot be combined (the system file holds the gear data)")
    if values.get("torque") is not None or values.get("fp") is not None:
        raise ModelError("system: the loads come from the system file; --torque and --fp do not apply with --system")
    s = load_system(path)
    if values.get("rpm") is not None and values.get("omega") is not None:
        raise ModelError("rpm: give --rpm or --omega, not both")
    if values.get("rpm") is not None:
        s = s.with_param("omega", s.scaling.omega_from_rpm(float(values["rpm"])))
    if values.get("omega") is not None:
        s = s.with_param("omega", float(values["omega"]))
    for o in params.cli_options():
        v = values.get(o.dest)
        if v is not None and o.dest not in _NOT_MODEL and o.param not in ("omega", "fp"):
            s = s.with_param(o.param, float(v))
    return s


def _opts(values: dict[str, Any], periods: int | None = None):
    from .. import validate

    n = periods if periods is not None else values.get("periods", 1)
    return validate.options(values["dtau"], values["transient"], n, values["accurate"], [])


def _state(values: dict[str, Any]) -> tuple[float, float]:
    return (float(values.get("u0", 0.0)), float(values.get("v0", 0.0)))


def _simulate(values: dict[str, Any], kw: dict[str, Any]) -> dict[str, Any]:
    from ..analysis.systems_steady import simulate_system

    s = load_cli_system(values)
    out = simulate_system(s, _opts(values), _state(values)).to_json()
    ref = next(m for m in out["meshes"] if m["name"] == out["reference_mesh"])
    for k in ("dynamic_factor", "dte_min_um", "dte_max_um", "dte_amplitude_um", "mesh_force_max_N",
              "mesh_force_min_N", "static_force_N"):
        out[k] = ref.get(k)
    sc = s.scaling
    out["natural_frequency_Hz"] = sc.omega_n / (2.0 * 3.141592653589793)
    out["mesh_frequency_Hz"] = s.omega * sc.omega_n / (2.0 * 3.141592653589793)
    out["rpm"] = sc.rpm_from_omega(s.omega) if sc.teeth is not None else None
    out["poincare"] = out.pop("poincare")
    return out


def _lyapunov(values: dict[str, Any], kw: dict[str, Any]) -> dict[str, Any]:
    from ..analysis.systems_lyapunov import system_lyapunov

    s = load_cli_system(values)
    blocks = int(kw.get("blocks", 20))
    return system_lyapunov(s, _opts(values), _state(values), blocks=max(blocks, 2)).to_json()


def _orbit(values: dict[str, Any], kw: dict[str, Any]) -> dict[str, Any]:
    from ..analysis.systems_orbit import shoot_system

    s = load_cli_system(values)
    opts = _opts(values, periods=1)
    g = kw.get("guess")
    guess = None
    if g is not None:
        try:
            guess = [float(p) for p in str(g).split(",")]
        except ValueError:
            raise ModelError(f"guess: expected {s.state_dim} numbers (q̃, q̃') separated by commas, got {g!r}") from None
    o = shoot_system(s, int(kw.get("period", 1)), guess, dtau=opts.dtau, accurate=opts.accurate,
                     state0=_state(values), transient=opts.transient)
    return o.to_json()


def _periodic_refusal(name: str):
    def run(values: dict[str, Any], kw: dict[str, Any]) -> dict[str, Any]:
        from ..analysis.systems_orbit import require_periodic

        s = load_cli_system(values)
        if name in ("continuation",):
            require_periodic(s, name)
        raise ModelError(f"system: {name} --system is not available yet; simulate, lyapunov, orbit, bifurcation "
                         f"and response are")
    return run


def _bifurcation(values: dict[str, Any], kw: dict[str, Any]) -> dict[str, Any]:
    from .. import validate
    from ..analysis.systems_sweep import system_sweep

    s = load_cli_system(values)
    param = kw.get("param") or "omega"
    if kw.get("start") is None or kw.get("stop") is None:
        raise ModelError("start: give the parameter range (--start and --stop) with --system")
    name, vals = validate.axis(param, kw["start"], kw["stop"], kw.get("num", 101))
    return system_sweep(s, name, list(vals), mode={"fixed": "fixed"}.get(kw.get("mode", "fixed"), "continue"),
                        sweep=kw.get("sweep", "up"), options=_opts(values))


def _response(values: dict[str, Any], kw: dict[str, Any]) -> dict[str, Any]:
    import numpy as np

    from ..analysis.systems_sweep import system_response_jumps, system_sweep

    s = load_cli_system(values)
    lo, hi = values.get("omega_start"), values.get("omega_stop")
    if lo is None or hi is None:
        raise ModelError("omega-start: give the ω range (--omega-start and --omega-stop) with --system")
    sw = system_sweep(s, "omega", list(np.linspace(float(lo), float(hi), int(kw.get("num", 71)))), mode="continue",
                      sweep="both", options=_opts(values))
    measure = kw.get("measure", "amplitude")
    sw["measure"] = measure
    sw["jumps"] = system_response_jumps(sw, measure if measure in ("amplitude", "u_min", "u_max") else "amplitude")
    return sw


_HANDLERS = {"simulate": _simulate, "lyapunov": _lyapunov, "orbit": _orbit, "bifurcation": _bifurcation,
             "response": _response}


def run_system(name: str, values: dict[str, Any], kw: dict[str, Any]) -> None:
    """Run command ``name`` on the system of ``--system`` and print its summary.

    Parameters
    ----------
    name : str
        The command (one of :data:`SYSTEM_COMMANDS`).
    values : dict
        The command's shared option values (``system`` among them).
    kw : dict
        The command's own options by keyword.

    Raises
    ------
    GeardynError
        For a bad system file or option (the decorator prints one line).
    """
    handler = _HANDLERS.get(name) or _periodic_refusal(name)
    summary = handler(values, kw)
    if values.get("out") is not None:
        raise ModelError("out: --out with --system is not available yet (use --json)")
    if values.get("json_out"):
        summary["files"] = []
        emit_json(summary)
        return
    _print(name, summary)


def _print(name: str, s: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    t = Table(title=f"{name} — {len(s.get('meshes', []))} mesh(es), omega = {s.get('omega'):.6g}")
    for col in ("mesh", "u_min", "u_max", "amplitude", "impact", "dynamic factor"):
        t.add_column(col)
    f = lambda x: "—" if x is None else (f"{x:.6g}" if isinstance(x, float) else str(x))  # noqa: E731
    for m in s.get("meshes", []):
        t.add_row(m["name"], f(m.get("u_min")), f(m.get("u_max")), f(m.get("amplitude")), str(m.get("impact")),
                  f(m.get("dynamic_factor")))
    c = Console()
    c.print(t)
    for k in ("motion", "period", "exponents", "elastic_multipliers", "stable", "rigid_body_note", "status"):
        if k in s and s[k] is not None:
            c.print(f"{k}: {s[k]}")
