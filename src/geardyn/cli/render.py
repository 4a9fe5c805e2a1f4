"""Tables and lines printed for people (``--json`` prints the summaries themselves)."""

from __future__ import annotations

from typing import Any

import numpy as np
from rich.markup import escape
from rich.table import Table

from .._docfill import SUMMARY, parameters
from .app import console

__all__ = ["continuation", "files", "intervals", "meshes", "orbit", "simulate"]


_summary_doc = parameters(SUMMARY)


def _num(x: Any) -> str:
    return "n/a" if x is None else f"{x:.6g}"


#: What the tables print for the dynamic factor of a mesh that carries no static load (its max force has no scale).
NO_STATIC_LOAD = "no static load"


def _no_load(d: dict[str, Any]) -> bool:
    """Whether a summary (or a mesh's entry) has a mesh force but no static load to divide it by."""
    f = d.get("static_force_N")
    return (
        d.get("dynamic_factor") is None
        and isinstance(f, (int, float))
        and f == 0
        and d.get("mesh_force_max_N") is not None
    )


def _flat(x: Any) -> list[Any]:
    """The scalars of a summary entry: a value, or the values of its (nested) lists and dicts."""
    if isinstance(x, dict):
        return [v for y in x.values() for v in _flat(y)]
    if isinstance(x, (list, tuple)):
        return [v for y in x for v in _flat(y)]
    return [x]


def _cell(x: Any) -> str:
    """One table cell: a number, the range of a sweep's numbers, or the count of each of its labels."""
    from collections import Counter

    vals = [v for v in _flat(x) if v is not None]
    if not vals:
        return "n/a"
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
        finite = [float(v) for v in vals if np.isfinite(v)]
        if not finite:
            return "n/a"
        lo, hi = min(finite), max(finite)
        return f"{lo:.6g}" if lo == hi else f"{lo:.6g} … {hi:.6g}"
    if len(vals) == 1:
        return str(vals[0])
    return ", ".join(f"{k} ×{n}" for k, n in Counter(str(v) for v in vals).most_common())


#: Columns of the per-mesh table of a system: summary key, header (the units of the pair's tables).
MESH_COLUMNS = (
    ("backlash_um", "half backlash D (µm)"),
    ("dte_min_um", "DTE min (µm)"),
    ("dte_max_um", "DTE max (µm)"),
    ("dte_amplitude_um", "DTE half peak-to-peak (µm)"),
    ("amplitude", "amplitude δ"),
    ("impact", "impact"),
    ("mesh_force_max_N", "max mesh force (N)"),
    ("static_force_N", "static force (N)"),
    ("dynamic_factor", "dynamic factor"),
)


def meshes(s: dict[str, Any]) -> None:
    """The meshes of a system's result: each mesh's half backlash, DTE (µm), impact state, forces (N) and dynamic
    factor, over the points of a sweep their range (columns a command does not compute are left out).

    Parameters
    ----------
    s : dict
        A command's summary with its ``meshes`` entries.
    """
    rows = [{**m, "dynamic_factor": NO_STATIC_LOAD} if _no_load(m) else m for m in s.get("meshes") or []]
    cols = [(k, h) for k, h in MESH_COLUMNS if any(k in m and any(v is not None for v in _flat(m[k])) for m in rows)]
    # one row per quantity, one column per mesh (a sweep: the range over its points)
    t = table(
        f"{len(rows)} mesh(es) of the system"
        + (f", reference mesh {s['reference_mesh']}" if s.get("reference_mesh") else ""),
        "mesh",
        *(m["name"] for m in rows),
    )
    for k, h in cols:
        t.add_row(h, *(_cell(m.get(k)) for m in rows))
    console.print(t)
    if s.get("note"):
        plain(f"note: {s['note']}")


def table(title: str, *columns: str, **column: Any) -> Table:
    """A table titled ``title`` with ``columns`` (each with the keywords ``column`` of ``Table.add_column``)."""
    t = Table(title=title)
    for c in columns:
        t.add_column(c, **column)
    return t


def plain(*lines: str) -> None:
    """Print each line as it is (no markup, no highlighting)."""
    for line in lines:
        console.print(line, markup=False, highlight=False)


def files(paths: list[str]) -> None:
    """One ``wrote FILE`` line per file written.

    Parameters
    ----------
    paths : list of str
        The files written.
    """
    plain(*(f"wrote {f}" for f in paths))


@_summary_doc
def simulate(s: dict[str, Any]) -> None:
    """The steady response of ``geardyn simulate``."""
    t = Table(title=f"Steady response at ω = {s['omega']:g}", show_header=False)
    t.add_row("motion", s["motion"])
    t.add_row("impact state", s["impact"])
    for k, lab in (
        ("amplitude", "amplitude (half peak-to-peak)"),
        ("rms", "RMS about mean"),
        ("mean", "mean"),
        ("u_min", "u_min"),
        ("u_max", "u_max"),
    ):
        t.add_row(lab, _num(s[k]))
    t.add_row("largest Lyapunov exponent λ1 (per unit τ)", _num(s.get("lle")))
    cf = s["contact_fractions"]
    t.add_row(
        "time in drive / separation / back contact", " / ".join(_num(cf[k]) for k in ("drive", "separation", "back"))
    )
    pts = s["poincare"]
    shown = pts[-(s["period"] or 4) :]
    t.add_row(f"last {len(shown)} Poincaré points (u, u')", "\n".join(f"({p[0]:.6f}, {p[1]:.6f})" for p in shown))
    if "rpm" in s:
        for k, lab in (
            ("rpm", "pinion speed (rpm)"),
            ("mesh_frequency_Hz", "mesh frequency (Hz)"),
            ("torque_N_m", "pinion torque, balanced (N·m)"),
            ("static_force_N", "static mesh force F_p (N)"),
            ("mesh_force_max_N", "max dynamic mesh force, elastic + viscous (N)"),
            ("mesh_force_min_N", "min dynamic mesh force, elastic + viscous (N)"),
            ("contact_force_max_N", "max contact force (N)"),
            ("contact_force_min_N", "min contact force, < 0 on the back flank (N)"),
            ("dynamic_factor", "dynamic factor (max force / F_p)"),
            ("dte_rms_um", "DTE RMS about mean (µm)"),
            ("dte_amplitude_um", "DTE half peak-to-peak (µm)"),
            ("backlash_um", "half backlash (µm)"),
        ):
            if k == "torque_N_m" and s.get(k) is None and "meshes" in s:
                continue  # a system: its loads are in its file, the static force of each mesh in its table
            if k in s:
                t.add_row(lab, NO_STATIC_LOAD if k == "dynamic_factor" and _no_load(s) else _num(s[k]))
        if peaks := s.get("spectrum_peaks") or []:
            t.add_row(
                "largest spectral lines (order, Hz, µm)",
                "\n".join(f"{p['order']:g}, {p['frequency_Hz']:.6g}, {p['amplitude_um']:.4g}" for p in peaks),
            )
    console.print(t)
    if "pair" in s:
        plain(f"gear pair: {s['pair']}")
    plain(*(f"note: {n}" for n in s.get("notes", [])))  # a long forcing period's classification budget, its history


def geometry(summary: dict[str, Any], rows: list[tuple[str, str, str, str]]) -> None:
    """The gear pair table of ``geardyn geometry`` with its assumed inputs and notes."""
    t = table(
        f"Gear pair geometry: {summary['title'] or summary['source']}",
        "quantity",
        "value",
        "unit",
        "note",
        overflow="fold",
    )
    for q, v, u, note in rows:
        t.add_row(q, v, u, note, style="yellow" if note.startswith("assumed") else None)
    console.print(t)
    lines = [f"source: {summary['source']}", f"backlash scale: {summary['backlash_reading']}"]
    for a in summary["assumptions"]:
        v = f"{a['value']:.6g}" if isinstance(a["value"], (int, float)) else str(a["value"])
        lines.append(f"assumed {a['name']} = {v}{' ' + a['unit'] if a['unit'] else ''}: {a['source']}")
    plain(*lines, *(f"note: {n}" for n in summary["notes"]))


@_summary_doc
def orbit(s: dict[str, Any]) -> None:
    """A shot periodic orbit with its Floquet multipliers."""
    t = Table(title=f"Period-{s['requested_period']} orbit at ω = {s['omega']:g}", show_header=False)
    t.add_row(
        "converged", f"{s['converged']} ({s['status']}, {s['iterations']} Newton iterations, residual {s['residual']})"
    )
    t.add_row("minimal period", str(s["period"]))
    t.add_row("state (u, u') at θ = 0", f"({s['state'][0]:.10g}, {s['state'][1]:.10g})")
    t.add_row("section points", "\n".join(f"({p[0]:.8f}, {p[1]:.8f})" for p in s["points"]))
    t.add_row(
        "Floquet multipliers",
        "\n".join(f"{m[0]:+.8f} {m[1]:+.8f}i  (|μ| = {abs(complex(*m)):.8f})" for m in s["multipliers"]),
    )
    t.add_row("stable", f"{s['stable']} (instability: {s['instability']})")
    for k in ("u_min", "u_max", "amplitude"):
        t.add_row(k, "n/a" if s[k] is None else f"{s[k]:.8g}")
    t.add_row("impact state", s["impact"])
    if "rpm" in s:
        t.add_row("pinion speed (rpm)", _num(s["rpm"]))
        for k in ("u_min", "u_max", "amplitude"):
            t.add_row(f"{k} (µm)", _num(s.get(f"{k}_um")))
    console.print(t)


@_summary_doc
def continuation(s: dict[str, Any]) -> None:
    """Branches and bifurcations of a continuation."""
    p = s["param"]
    t = table(f"Branches in {p} from {s['start']:g} to {s['stop']:g}", "branch", "period", "points", "from", "end")
    for b in s["branches"]:
        src = "" if b["from"] is None else f"{b['from']['type']} at {p} = {b['from'][p]:.6g}"
        t.add_row(str(b["branch"]), str(b["period"]), str(b["points"]), src, b["end"])
    console.print(t)
    t = table("Bifurcations", "type", p, "period", "branch", "amplitude", "multipliers", "detail")
    for b in s["bifurcations"]:
        mus = ", ".join(f"{complex(*m):.4f}" for m in b["multipliers"])
        t.add_row(
            b["type"], f"{b[p]:.6f}", str(b["period"]), str(b["branch"]), f"{b['amplitude']:.4f}", mus, b["detail"]
        )
    console.print(t)
    plain(*(f"note: {n}" for n in s.get("notes", [])))


def lyapunov(s: dict[str, Any]) -> None:
    """Both exponents with their uncertainty and the Liouville check."""

    def fmt(x: Any) -> str:
        return "n/a" if x is None else f"{x:+.6f}"

    console.print(
        f"Lyapunov exponents at ω = {s['omega']:g} over {s['periods']} periods (per unit τ, ± one standard error):"
    )
    n = len(s["exponents"])
    for i in range(n):
        console.print(f"  λ{i + 1} = {fmt(s['exponents'][i])} ± {s['uncertainty'][i] or float('nan'):.2e}")
    if n == 2:
        console.print(f"  λ1 + λ2 = {fmt(s['sum'])}   (−2ξ0 = {s['expected_sum']:+.6f})")
    else:  # a system: the sum equals the mean trace of the Jacobian
        console.print(f"  λ1 + … + λ{n} = {fmt(s['sum'])}   (mean trace of the Jacobian = {s['expected_sum']:+.6f})")
    console.print(f"  motion: {s['motion']}")


@_summary_doc
def intervals(s: dict[str, Any]) -> None:
    """Motion intervals of a bifurcation diagram, per sweep."""
    iv = s["intervals"]
    groups = iv if isinstance(iv, dict) else {s["sweep"]: iv}
    rpm = s.get("values_rpm") if s["param"] == "omega" else None

    def speed(w: float) -> str:  # the pinion speed of an ω of the sweep (rpm is linear in ω)
        return f"{float(np.interp(w, s['values'], rpm)):.1f}"

    for lab, rows in groups.items():
        t = table(
            f"Motion over {s['param']} ({lab})",
            "from",
            "to",
            *(("from (rpm)", "to (rpm)") if rpm else ()),
            "points",
            "motion",
        )
        for r in rows:
            cells = [f"{r['from']:.6g}", f"{r['to']:.6g}"] + ([speed(r["from"]), speed(r["to"])] if rpm else [])
            t.add_row(*cells, str(r["points"]), r["motion"])
        console.print(t)


def response(s: dict[str, Any]) -> None:
    """Jumps and hysteresis intervals of a frequency response."""
    t = table("Jumps", "sweep", "ω (midpoint)", "from → to", "direction", "size", "pinion speed (rpm)", "size (µm)")
    for j in s["jumps"]:
        t.add_row(
            j["sweep"],
            f"{j['omega']:.6g}",
            f"{j['omega_from']:.6g} → {j['omega_to']:.6g}",
            j["direction"],
            f"{j['size']:.4g}",
            f"{j['rpm']:.1f} ({j['rpm_from']:.1f} → {j['rpm_to']:.1f})",
            f"{j['size_um']:.4g}",
        )
    console.print(t)
    hy = ", ".join(f"[{a:.6g}, {b:.6g}]" for a, b in s["hysteresis"]) or "none"
    hy_rpm = ", ".join(f"[{a:.1f}, {b:.1f}]" for a, b in s.get("hysteresis_rpm", [])) or "none"
    plain(f"hysteresis (coexisting attractors): ω {hy}; rpm {hy_rpm}")
    if s.get("coexistence"):
        co = ", ".join(f"[{a:.6g}, {b:.6g}]" for a, b in s["coexistence"])
        plain(f"coexistence (the sweeps end on different attractors, no jump at a bound): ω {co}")
    plain(f"gear pair: {s['physical']['pair']}")


def parameter_map(s: dict[str, Any]) -> None:
    """Counts of a 2-D parameter map."""
    counts = ", ".join(f"{k}: {v}" for k, v in s["motion_counts"].items())
    console.print(f"map of {s['y']} × {s['x']}: {len(s['y_values'])} × {len(s['x_values'])} points; {counts}")


def basins(s: dict[str, Any], n_u: int, n_v: int) -> None:
    """The attractors of a basin computation and their basin shares."""
    speed = f", {s['rpm']:.1f} rpm" if "rpm" in s else ""
    t = table(
        f"Attractors at ω = {s['omega']:g}{speed} ({n_u} × {n_v} initial states)",
        "label",
        "motion",
        "basin share",
        "amplitude",
        *(("amplitude (µm)",) if speed else ()),
        "Poincaré points (u, u')",
    )
    for a in s["attractors"]:
        pts = a["points"][:4]
        txt = "; ".join(f"({p[0]:.4f}, {p[1]:.4f})" for p in pts) + (" …" if len(a["points"]) > 4 else "")
        um = (f"{a['amplitude_um']:.4g}",) if speed and "amplitude_um" in a else (("n/a",) if speed else ())
        t.add_row(str(a["label"]), a["motion"], f"{100 * a['fraction']:.1f} %", f"{a['amplitude']:.4g}", *um, txt)
    console.print(t)
    if s["diverged_fraction"] > 0:
        console.print(f"diverged: {100 * s['diverged_fraction']:.1f} % of the initial states")


def claims(res: dict[str, Any]) -> None:
    """The verdicts of ``geardyn reproduce``: a reduced run said first, the totals, then per claim the paper's
    statement beside its verdict (the deciding evidence is in the report)."""
    from ..paper.report import one_reading_text, totals_text

    style = {"reproduced": "green", "reproduced under a reading": "cyan", "contradicted": "red", "not testable": "dim"}
    run = res.get("run")
    if run is not None and run.reduced:
        console.print(f"[bold yellow]{escape(run.banner('listed in the report'))}[/]")
    console.print(escape(one_reading_text(res["claims"], run)), style="bold", highlight=False)
    t = Table(title=escape("Per claim, each under its own nearest reading: " + totals_text(res["claims"], run)))
    t.add_column("id", no_wrap=True)
    t.add_column("the paper says", overflow="fold", ratio=3)
    t.add_column("verdict", overflow="fold", ratio=2)
    for c in res["claims"]:
        verdict = c.verdict + (f" ({c.reading})" if getattr(c, "reading", "") else "")
        t.add_row(c.id, escape(c.statement), f"[{style.get(c.verdict, 'white')}]{escape(verdict)}[/]")
    console.print(t)
    if run is not None:
        console.print(escape(run.provenance()), style="dim", highlight=False)
    more = "; verdicts may differ from the full run's" if run is not None and run.reduced else ""
    plain(f"report (deciding evidence, readings, figures): {res['paths']['html']} ({res['seconds']:.1f} s{more})")


def bench(res: dict[str, Any]) -> None:
    """Timings of ``geardyn bench``."""
    t = table(f"geardyn bench ({res['threads']} thread(s), minimum of {res['repeats']} runs)", "workload")
    for col in ("wall (s)", "RK4 steps", "ns/step"):
        t.add_column(col, justify="right")
    for name, r in res["workloads"].items():
        t.add_row(name, f"{r['wall_s']:.4f}", f"{r['steps']:,}", f"{r['ns_per_step']:.2f}")
    console.print(t)
    m = res["machine"]
    plain(f"{m['cpu']}, {m['cores']} cores, load average {m.get('load_average', 'n/a')}")
