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
import math
from collections import Counter
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import ModelError
from .output import engine_keywords

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


def _settle(kw: dict[str, Any]) -> int:
    from .. import validate

    return validate.integer("settle", kw.get("settle", 1000), 0, validate.MAX_PERIODS)


def _simulate(values: dict[str, Any], kw: dict[str, Any]):
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
    return out, res.to_dataset, None


def _lyapunov(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.lyapunov import lyapunov_spectrum

    s = load_cli_system(values)
    blocks = int(kw.get("blocks", 20))
    res = lyapunov_spectrum(s, _opts(values), _state(values), blocks=max(blocks, 2))
    return res.to_json(), res.to_dataset, None


def _guess(s: Any, g: Any):
    if g is None:
        return None
    try:
        return [float(p) for p in str(g).split(",")]
    except ValueError:
        raise ModelError(f"guess: expected {s.state_dim} numbers (q̃, q̃') separated by commas, got {g!r}") from None


def _orbit(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.periodic import shoot

    s = load_cli_system(values)
    opts = _opts(values, periods=1)
    o = shoot(s, int(kw.get("period", 1)), _guess(s, kw.get("guess")), dtau=opts.dtau,
              accurate=opts.accurate, state0=_state(values), transient=opts.transient)
    return o.to_json(), o.to_dataset, None


def _coords(s: Any, values: dict[str, Any], n: int) -> list[int] | None:
    from ..analysis.basins import coordinate_index

    text = values.get("coords")
    if text is None:
        return None
    idx = [coordinate_index(s, p) for p in str(text).split(",") if p.strip()]
    if len(idx) < n:
        raise ModelError(f"coords: give {n} coordinate(s) separated by commas, got {text!r}")
    return idx


def _with_meshes(summary: dict[str, Any], ds: Any) -> dict[str, Any]:
    from ..systems.report import result_meshes

    summary["meshes"] = result_meshes(ds)
    return summary


def _bifurcation(values: dict[str, Any], kw: dict[str, Any]):
    from .. import validate
    from ..analysis.bifurcation import MODES, SWEEPS, bifurcation, bifurcation_json
    from ..grid import linspace_values, param_name
    s = load_cli_system(values)
    param = param_name(kw.get("param") or "omega")
    if kw.get("start") is None or kw.get("stop") is None:
        raise ModelError("start: give the parameter range (--start and --stop) with --system")
    s.with_param(param, float(kw["start"]))
    vals = linspace_values(kw["start"], kw["stop"], validate.integer("num", kw.get("num", 101), 1, validate.MAX_GRID_POINTS))
    mode = choice("mode", kw.get("mode", "fixed"), MODES)
    sweep = choice("sweep", kw.get("sweep", "up"), SWEEPS)
    engine = engine_keywords(values, "bifurcation")
    ds = bifurcation(s, param, vals, mode=mode, sweep=sweep, state0=_state(values), options=_opts(values),
                     lyapunov=bool(kw.get("lyap", False)), settle_periods=_settle(kw), **engine)
    return _with_meshes(bifurcation_json(ds), ds), ds, engine


def _response(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.response import MEASURES, frequency_response, response_json

    s = load_cli_system(values)
    lo, hi = values.get("omega_start"), values.get("omega_stop")
    if lo is None or hi is None:
        raise ModelError("omega-start: give the ω range (--omega-start and --omega-stop) with --system")
    measure = choice("measure", kw.get("measure", "amplitude"), MEASURES)
    method = choice("method", kw.get("method", "sweep"), ("sweep", "hb"))
    if method == "hb":  # one harmonic-balance branch of the system (its reference mesh)
        from ..analysis.hb import hb_response

        ds = hb_response(s, float(lo), float(hi), int(kw.get("num", 71)), measure=measure, state0=_state(values))
        return {**response_json(ds), "method": "hb"}, ds, None
    engine = engine_keywords(values, "response")
    ds = frequency_response(s, float(lo), float(hi), int(kw.get("num", 71)), measure=measure, options=_opts(values),
                            state0=_state(values), lyapunov=bool(kw.get("lyap", False)), settle_periods=_settle(kw),
                            **engine)
    return _with_meshes(response_json(ds), ds), ds, engine


def _map(values: dict[str, Any], kw: dict[str, Any]):
    from .. import validate
    from ..analysis.maps import map_json, parameter_map
    from ..grid import linspace_values

    s = load_cli_system(values)
    ax = {}
    for a in ("x", "y"):
        name = values.get(a)
        lo, hi = values.get(f"{a}_start"), values.get(f"{a}_stop")
        if lo is None or hi is None:
            raise ModelError(f"{a}_start: give --{a}-start and --{a}-stop with --system")
        s.with_param(name, float(lo))
        n = validate.integer(f"{a}-num", values.get(f"{a}_num"), 1, 100_000)
        ax[a] = (name, linspace_values(lo, hi, n, label=a))
    engine = engine_keywords(values, "map")
    ds = parameter_map(s, ax["x"][0], ax["x"][1], ax["y"][0], ax["y"][1], mode=kw.get("mode", "fixed"),
                       state0=_state(values), options=_opts(values), lyapunov=bool(kw.get("lyap", False)),
                       settle_periods=_settle(kw), **engine)
    return _with_meshes(map_json(ds), ds), ds, engine


def _basins(values: dict[str, Any], kw: dict[str, Any]):
    from .. import validate
    from ..analysis.basins import basins, basins_json

    s = load_cli_system(values)
    c = _coords(s, values, 2)  # None: the reference mesh's (δ, δ'), as the 1-DOF basins' (u0, v0)
    nu = validate.integer("nu", kw.get("nu", 41), 1, 100_000)
    nv = validate.integer("nv", kw.get("nv", 41), 1, 100_000)
    engine = engine_keywords(values, "basins")
    ds = basins(s, (float(kw.get("u_min", -3.0)), float(kw.get("u_max", 3.0))),
                (float(kw.get("v_min", -3.0)), float(kw.get("v_max", 3.0))), nu, nv,
                coordinates=None if c is None else (c[0], c[1]), options=_opts(values), settle_periods=_settle(kw),
                **engine)
    return _with_meshes(basins_json(ds), ds), ds, engine


def _continuation(values: dict[str, Any], kw: dict[str, Any]):
    from ..analysis.periodic import continuation
    from ..labels import IMPACT_LABELS, impact_state

    s = load_cli_system(values)
    param = kw.get("param") or "omega"
    if kw.get("start") is None or kw.get("stop") is None:
        raise ModelError("start: give the parameter range (--start and --stop) with --system")
    opts = _opts(values, periods=1)
    res = continuation(s, param, float(kw["start"]), float(kw["stop"]), int(kw.get("period", 1)),
                       _guess(s, kw.get("guess")), dtau=opts.dtau, accurate=opts.accurate, ds_max=kw.get("ds_max"),
                       state0=_state(values), switch=bool(kw.get("switch", True)),
                       max_period=int(kw.get("max_period", 4)))
    out = res.to_json()
    ext = [b.extrema for b in res.branches if b.extrema is not None]
    ext = __import__("numpy").concatenate(ext) if ext else __import__("numpy").zeros((0, len(s.elements), 2))
    um = s.scaling.b_c * 1e6
    out["meshes"] = [{"name": e.name, "backlash_um": e.gap * um, "u_min": ext[:, i, 0].tolist(),
                      "u_max": ext[:, i, 1].tolist(), "amplitude": (0.5 * (ext[:, i, 1] - ext[:, i, 0])).tolist(),
                      "dte_amplitude_um": (0.5 * (ext[:, i, 1] - ext[:, i, 0]) * um).tolist(),
                      "impact": [IMPACT_LABELS[impact_state(float(lo), e.gap)] for lo in ext[:, i, 0]],
                      "dynamic_factor": None} for i, e in enumerate(s.elements) if e.kind == "mesh"]
    r = s.rigid_basis().shape[1]
    out["rigid_body_modes"] = r
    if r:
        out["notes"] = out["notes"] + [f"{2 * r} multipliers equal to 1 belong to the rigid-body mode(s) and "
                                       f"are left out; the multipliers listed are the elastic ones"]
    return out, res.to_dataset, None


_HANDLERS = {"simulate": _simulate, "lyapunov": _lyapunov, "orbit": _orbit, "bifurcation": _bifurcation,
             "response": _response, "map": _map, "basins": _basins, "continuation": _continuation}


def choice(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """``value`` if it is one of ``allowed``, else a one-line refusal."""
    if value not in allowed:
        raise ModelError(f"{name}: must be one of {', '.join(allowed)}, got {value!r}")
    return value


def run_system(name: str, inp: Any, kw: dict[str, Any]) -> None:
    """Run command ``name`` on the system of ``--system`` and print its summary.

    The analysis is the command's own (the same functions as for the pair, on the system); with ``--out`` its
    Dataset (the command's kind) and figures are written as the pair's are.

    Parameters
    ----------
    name : str
        The command (one of :data:`SYSTEM_COMMANDS`).
    inp : Inputs
        The command's shared option values (``inp.values``, ``system`` among them) and its writer.
    kw : dict
        The command's own options by keyword.

    Raises
    ------
    GeardynError
        For a bad system file or option (the decorator prints one line).
    """
    from ..systems.notes import excitation_note
    from .app import emit_json

    values = inp.values
    summary, ds, engine = _HANDLERS[name](values, kw)
    if (note := excitation_note(load_cli_system(values), _state(values))) is not None:
        summary["note"] = note
    files = inp.write(ds() if callable(ds) else ds, name, engine) if values.get("out") is not None else []
    if values.get("json_out"):
        summary["files"] = files
        emit_json(summary)
        return
    _print(name, summary, files)


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


#: Columns of the per-mesh table: summary key, header (units as the pair's tables give them).
_MESH_COLUMNS = (("backlash_um", "half backlash D (µm)"), ("dte_min_um", "DTE min (µm)"), ("dte_max_um", "DTE max (µm)"),
                 ("dte_amplitude_um", "DTE half peak-to-peak (µm)"), ("amplitude", "amplitude δ"),
                 ("impact", "impact"), ("mesh_force_max_N", "max mesh force (N)"), ("static_force_N", "static force (N)"),
                 ("dynamic_factor", "dynamic factor"))


def _print(name: str, s: dict[str, Any], paths: list[str]) -> None:
    from rich.console import Console
    from rich.table import Table

    if "x_values" in s:  # a map
        where = f"{s['x']} = {_cell(s['x_values'])}, {s['y']} = {_cell(s['y_values'])}"
    elif "u0" in s and "attractors" in s:  # basins
        where = f"ω = {s['omega']:.6g}, u0 = {_cell(s['u0'])}, v0 = {_cell(s['v0'])}"
    elif "param" in s and isinstance(s.get("values"), list) and s["values"]:
        where = f"{s['param']} = {_cell(s['values'])} ({len(s['values'])} points)"
    elif isinstance(s.get("omega"), (int, float)):
        where = f"ω = {s['omega']:.6g}" + (f" ({s['rpm']:.1f} rpm)" if s.get("rpm") is not None else "")
    elif "start" in s and "stop" in s:
        where = f"{s['param']} from {s['start']:.6g} to {s['stop']:.6g}"
    elif isinstance(s.get("omega"), list):
        where = f"ω = {_cell(s['omega'])} ({len(s['omega'])} points)"
    else:  # a map or basins: the ranges of its coordinates
        where = ", ".join(f"{k} = {_cell(s[k])}" for k in ("x_values", "y_values", "u0", "v0") if k in s)
    meshes = s.get("meshes", [])
    cols = [(k, h) for k, h in _MESH_COLUMNS if any(_flat(m.get(k)) != [None] and k in m for m in meshes)]
    t = Table(title=f"{name} — {len(meshes)} mesh(es), {where}")
    t.add_column("mesh")
    for _, h in cols:
        t.add_column(h)
    for m in meshes:
        t.add_row(m["name"], *(_cell(m.get(k)) for k, _ in cols))
    c = Console()
    c.print(t)
    for k in ("exponents", "elastic_multipliers"):  # every value of a point's spectrum
        if s.get(k) is not None:
            c.print(f"{k}: {s[k]}")
    for k in ("motion", "period", "stable", "rigid_body_note", "status", "note"):
        if s.get(k) is not None:
            c.print(f"{k}: {_cell(s[k])}", markup=False, highlight=False)
    if "jumps" in s:
        j = Table(title=f"Jumps ({s.get('measure', 'amplitude')} of the reference mesh)")
        for col in ("sweep", "ω (midpoint)", "from → to", "direction", "size"):
            j.add_column(col)
        for r in s["jumps"]:
            j.add_row(r["sweep"], f"{r['omega']:.6g}", f"{r['omega_from']:.6g} → {r['omega_to']:.6g}", r["direction"],
                      f"{r['size']:.4g}")
        c.print(j)
        for key, what in (("hysteresis", "hysteresis (coexisting attractors, a jump at a bound)"),
                          ("coexistence", "coexistence (the sweeps end on different attractors, no jump at a bound)")):
            iv = ", ".join(f"[{a:.6g}, {b:.6g}]" for a, b in s.get(key, [])) or "none"
            c.print(f"{what}: ω {iv}", markup=False, highlight=False)
    for f in paths:
        c.print(f"wrote {f}", markup=False, highlight=False)
