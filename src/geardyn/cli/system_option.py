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
import json
import math
from collections import Counter
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import ModelError
from .app import emit_json
from .output import engine_keywords, out_paths

__all__ = ["SYSTEM", "SYSTEM_COMMANDS", "run_system"]

SYSTEM_PANEL = "Multi-DOF system"
SYSTEM = [inspect.Parameter(
    "system", inspect.Parameter.KEYWORD_ONLY, default=None,
    annotation=Annotated[Optional[Path], typer.Option(
        "--system", rich_help_panel=SYSTEM_PANEL,
        help="TOML file of a multi-DOF system (bodies, bearings, meshes; see examples/systems): the analysis runs "
             "on it, and the JSON summary adds one entry per mesh under 'meshes'.")]),
    inspect.Parameter(
    "coords", inspect.Parameter.KEYWORD_ONLY, default=None,
    annotation=Annotated[Optional[str], typer.Option(
        "--coords", rich_help_panel=SYSTEM_PANEL,
        help="With --system: state coordinates, DOF labels or 'label'' for a rate (e.g. x_p,x_p'): the two axes "
             "of the basins' slice (--u-min/--u-max, --v-min/--v-max; default the reference mesh's DOF), or the "
             "coordinate whose Poincaré points a bifurcation keeps.")])]

#: Commands that take ``--system``.
SYSTEM_COMMANDS = ("simulate", "lyapunov", "orbit", "continuation", "bifurcation", "response", "map", "basins")
_NOT_MODEL = {"config", "rpm", "torque", "omega", "fp"}


def load_cli_system(values: dict[str, Any]):
    """The system of ``--system`` with ``--omega``/``--rpm`` and the mesh options applied."""
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


def _simulate(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.systems_data import simulate_dataset
    from ..analysis.steady import simulate

    s = load_cli_system(values)
    res = simulate(s, _opts(values), _state(values))
    out = res.to_json()
    ref = next(m for m in out["meshes"] if m["name"] == out["reference_mesh"])
    for k in ("dynamic_factor", "dte_min_um", "dte_max_um", "dte_amplitude_um", "mesh_force_max_N",
              "mesh_force_min_N", "static_force_N"):
        out[k] = ref.get(k)
    sc = s.scaling
    out["natural_frequency_Hz"] = sc.omega_n / (2.0 * 3.141592653589793)
    out["mesh_frequency_Hz"] = s.omega * sc.omega_n / (2.0 * 3.141592653589793)
    out["rpm"] = sc.rpm_from_omega(s.omega) if sc.teeth is not None else None
    out["poincare"] = out.pop("poincare")
    return out, (lambda: simulate_dataset(res))


def _lyapunov(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.systems_data import lyapunov_dataset
    from ..analysis.lyapunov import lyapunov_spectrum

    s = load_cli_system(values)
    blocks = int(kw.get("blocks", 20))
    res = lyapunov_spectrum(s, _opts(values), _state(values), blocks=max(blocks, 2))
    return res.to_json(), (lambda: lyapunov_dataset(res))


def _guess(s: Any, g: Any):
    if g is None:
        return None
    try:
        return [float(p) for p in str(g).split(",")]
    except ValueError:
        raise ModelError(f"guess: expected {s.state_dim} numbers (q̃, q̃') separated by commas, got {g!r}") from None


def _orbit(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.systems_data import orbit_dataset
    from ..analysis.periodic import shoot

    s = load_cli_system(values)
    opts = _opts(values, periods=1)
    o = shoot(s, int(kw.get("period", 1)), _guess(s, kw.get("guess")), dtau=opts.dtau,
              accurate=opts.accurate, state0=_state(values), transient=opts.transient)
    return o.to_json(), (lambda: orbit_dataset(o))


def _coords(s: Any, values: dict[str, Any], n: int) -> list[int] | None:
    from ..analysis.systems_grid import coordinate_index

    text = values.get("coords")
    if text is None:
        return None
    idx = [coordinate_index(s, p) for p in str(text).split(",") if p.strip()]
    if len(idx) < n:
        raise ModelError(f"coords: give {n} coordinate(s) separated by commas, got {text!r}")
    return idx


def _bifurcation(values: dict[str, Any], kw: dict[str, Any]):
    from .. import validate
    from ..analysis.systems_sweep import sweep_json, system_sweep

    s = load_cli_system(values)
    param = kw.get("param") or "omega"
    if kw.get("start") is None or kw.get("stop") is None:
        raise ModelError("start: give the parameter range (--start and --stop) with --system")
    s.with_param(param, float(kw["start"]))
    _, vals = validate.axis("omega", kw["start"], kw["stop"], kw.get("num", 101)) if param == "omega" else \
        (param, __import__("numpy").linspace(float(kw["start"]), float(kw["stop"]), int(kw.get("num", 101))))
    c = _coords(s, values, 1)
    mode = kw.get("mode", "fixed")
    if mode not in ("fixed", "continue"):
        raise ModelError(f"mode: must be one of fixed, continue, got {mode!r}")
    ds = system_sweep(s, param, list(vals), mode=mode, sweep=kw.get("sweep", "up"), options=_opts(values),
                      coordinate=None if c is None else c[0], engine=engine_keywords(values, "system_bifurcation"))
    return sweep_json(ds), ds


def _response(values: dict[str, Any], kw: dict[str, Any]):
    import numpy as np

    from ..analysis.systems_sweep import sweep_json, system_response_jumps, system_sweep

    s = load_cli_system(values)
    lo, hi = values.get("omega_start"), values.get("omega_stop")
    if lo is None or hi is None:
        raise ModelError("omega-start: give the ω range (--omega-start and --omega-stop) with --system")
    measure = kw.get("measure", "amplitude")
    if measure not in ("amplitude", "u_min", "u_max", "rms", "mean"):
        raise ModelError(f"measure: must be one of amplitude, rms, u_max, u_min, mean, got {measure!r}")
    method = kw.get("method", "sweep")
    if method not in ("sweep", "hb"):
        raise ModelError(f"method: must be one of sweep, hb, got {method!r}")
    if method == "hb":  # one harmonic-balance branch of the system (its reference mesh)
        from ..analysis.hb import hb_response
        from ..analysis.response import response_json

        ds = hb_response(s, float(lo), float(hi), int(kw.get("num", 71)), measure=measure, state0=_state(values),
                         progress=not values.get("json_out"))
        return {**response_json(ds), "method": "hb"}, ds
    ds = system_sweep(s, "omega", list(np.linspace(float(lo), float(hi), int(kw.get("num", 71)))), mode="continue",
                      sweep="both", options=_opts(values), engine=engine_keywords(values, "system_response"),
                      kind="system_response")
    jumps, hyst = system_response_jumps(ds, measure)
    ds.attrs.update(measure=measure, jumps=json.dumps(jumps), hysteresis=json.dumps(hyst))
    sw = sweep_json(ds)
    sw["measure"] = measure
    sw["jumps"] = jumps
    sw["hysteresis"] = hyst
    return sw, ds


def _map(values: dict[str, Any], kw: dict[str, Any]):
    from .. import validate
    from ..analysis.systems_grid import grid_json, system_map

    s = load_cli_system(values)
    ax = {}
    for a in ("x", "y"):
        name = values.get(a)
        lo, hi = values.get(f"{a}_start"), values.get(f"{a}_stop")
        if lo is None or hi is None:
            raise ModelError(f"{a}_start: give --{a}-start and --{a}-stop with --system")
        s.with_param(name, float(lo))
        n = validate.integer(f"{a}-num", values.get(f"{a}_num"), 1, 100_000)
        ax[a] = (name, __import__("numpy").linspace(float(lo), float(hi), n))
    ds = system_map(s, ax["x"][0], ax["x"][1], ax["y"][0], ax["y"][1], mode=kw.get("mode", "fixed"), options=_opts(values),
                    engine=engine_keywords(values, "system_map"))
    return grid_json(ds), ds


def _basins(values: dict[str, Any], kw: dict[str, Any]):
    from .. import validate
    from ..analysis.systems_grid import grid_json, system_basins
    s = load_cli_system(values)
    c = _coords(s, values, 2)  # None: the reference mesh's (δ, δ'), as the 1-DOF basins' (u0, v0)
    nu = validate.integer("nu", kw.get("nu", 41), 1, 100_000)
    nv = validate.integer("nv", kw.get("nv", 41), 1, 100_000)
    ds = system_basins(s, None if c is None else (c[0], c[1]), (float(kw.get("u_min", -3.0)), float(kw.get("u_max", 3.0))),
                       (float(kw.get("v_min", -3.0)), float(kw.get("v_max", 3.0))), nu, nv,
                       options=_opts(values), engine=engine_keywords(values, "system_basins"))
    return grid_json(ds), ds


def _continuation(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.systems_continuation import system_continuation

    s = load_cli_system(values)
    param = kw.get("param") or "omega"
    if kw.get("start") is None or kw.get("stop") is None:
        raise ModelError("start: give the parameter range (--start and --stop) with --system")
    opts = _opts(values, periods=1)
    res = system_continuation(s, param, float(kw["start"]), float(kw["stop"]), int(kw.get("period", 1)),
                              _guess(s, kw.get("guess")), dtau=opts.dtau, accurate=opts.accurate,
                              ds_max=kw.get("ds_max"), state0=_state(values), switch=bool(kw.get("switch", True)),
                              max_period=int(kw.get("max_period", 4)))
    return res.to_json(), (lambda: res.to_dataset())


_HANDLERS = {"simulate": _simulate, "lyapunov": _lyapunov, "orbit": _orbit, "bifurcation": _bifurcation,
             "response": _response, "map": _map, "basins": _basins, "continuation": _continuation}


def _write(values: dict[str, Any], ds: Any) -> list[str]:
    from ..io import write_netcdf
    from ..plot import save_figures
    stem = ds.attrs["geardyn_kind"]
    nc, figdir = out_paths(Path(values["out"]), stem)
    files = [str(write_netcdf(ds, nc))] + [str(p) for p in save_figures(ds, figdir, fmt=values.get("fig_format", "png"),
                                                                         dpi=values.get("dpi", 120))]
    if values.get("resume") is not None:
        from ..sweep import checkpoint_dir, remove_checkpoint

        if checkpoint_dir(nc).exists():
            remove_checkpoint(checkpoint_dir(nc))
    return files


def run_system(name: str, values: dict[str, Any], kw: dict[str, Any]) -> None:
    """Run command ``name`` on the system of ``--system`` and print its summary.

    With ``--out`` the result's NetCDF file (kind ``system_<command>``) and its figures (the figure
    registry, :mod:`geardyn.plot.systems`) are written; ``geardyn plot`` on the file redraws them.

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
    summary, ds = _HANDLERS[name](values, kw)
    from ..systems.notes import excitation_note
    if (note := excitation_note(load_cli_system(values), _state(values))) is not None:
        summary["note"] = note
    files: list[str] = []
    if values.get("out") is not None:
        files = _write(values, ds() if callable(ds) else ds)
    if values.get("json_out"):
        summary["files"] = files
        emit_json(summary)
        return
    _print(name, summary)
    for f in files:
        print(f"wrote {f}")


def _flat(x: Any) -> list[Any]:
    """The scalars of a summary entry: a value, or the values of its (nested) lists and dicts."""
    if isinstance(x, dict):
        return [v for y in x.values() for v in _flat(y)]
    if isinstance(x, (list, tuple)):
        return [v for y in x for v in _flat(y)]
    return [x]


def _cell(x: Any) -> str:
    """One table cell: a number, the range of a sweep's numbers, or the count of each of its labels."""
    vals = [v for v in _flat(x) if v is not None]
    if not vals:
        return "—"
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
        finite = [float(v) for v in vals if math.isfinite(v)]
        if not finite:
            return "—"
        lo, hi = min(finite), max(finite)
        return f"{lo:.6g}" if lo == hi else f"{lo:.6g} … {hi:.6g}"
    if len(vals) == 1:
        return str(vals[0])
    counts = Counter(str(v) for v in vals)
    return ", ".join(f"{k} ×{n}" for k, n in counts.most_common())


def _print(name: str, s: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    if "param" in s and isinstance(s.get("values"), list) and s["values"]:
        where = f"{s['param']} = {_cell(s['values'])} ({len(s['values'])} points)"
    elif isinstance(s.get("omega"), (int, float)):
        where = f"omega = {s['omega']:.6g}"
    elif "start" in s and "stop" in s:
        where = f"{s['param']} from {s['start']:.6g} to {s['stop']:.6g}"
    else:  # a map or basins: the ranges of its coordinates
        where = ", ".join(f"{k} = {_cell(v)}" for k, v in s.get("coords", {}).items())
    t = Table(title=f"{name} — {len(s.get('meshes', []))} mesh(es), {where}")
    for col in ("mesh", "u_min", "u_max", "amplitude", "impact", "dynamic factor"):
        t.add_column(col)
    for m in s.get("meshes", []):
        t.add_row(m["name"], *(_cell(m.get(k)) for k in ("u_min", "u_max", "amplitude", "impact", "dynamic_factor")))
    c = Console()
    c.print(t)
    for k in ("exponents", "elastic_multipliers"):  # every value of a point's spectrum
        if s.get(k) is not None:
            c.print(f"{k}: {s[k]}")
    for k in ("motion", "period", "stable", "rigid_body_note", "status", "note"):
        if s.get(k) is not None:
            c.print(f"{k}: {_cell(s[k])}")
