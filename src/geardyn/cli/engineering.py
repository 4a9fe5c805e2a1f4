"""Commands for the engineer's front end: ``te`` (measured transmission error) and ``runup`` (speed ramps)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.table import Table

from ..errors import ModelError
from .app import console, emit_json
from .options import CONFIG, MODEL, OUTPUT, Inputs, command, finish, option

JSON_ONLY = [p for p in OUTPUT if p.name == "json_out"]

TE_OPTIONS = [
    option("teeth", str, ..., "--teeth", help="Teeth of pinion and gear, z1,z2 (e.g. 14,39)."),
    option("harmonics", int, 3, "--harmonics", help="Mesh harmonics fitted (orders l z1, l = 1 … L)."),
    option("shaft_orders", int, 2, "--shaft-orders",
           help="Shaft orders j fitted for each shaft, alone and as sidebands l z1 ± j (pinion), l z1 ± j z1/z2 (gear)."),
    option("x_unit", Optional[str], None, "--x-unit",
           help="Unit of the first column when the header does not state it: deg, rad, rev (angle) or s, ms, us (time)."),
    option("te_unit", Optional[str], None, "--te-unit", help="Unit of the TE column when the header does not state it: um, mm, nm, m."),
    option("te_rpm", Optional[float], None, "--rpm", help="Pinion speed (rpm) of a time record."),
    option("te_out", Optional[Path], None, "--out", help="Write the [mesh] section (TOML) to this file."),
    *JSON_ONLY,
]


def _teeth(text: str) -> tuple[int, int]:
    try:
        z1, z2 = (int(t) for t in text.replace(";", ",").split(","))
    except ValueError:
        raise ModelError(f"teeth: expected z1,z2 (two whole numbers, e.g. 14,39), got {text!r}") from None
    if z1 < 1 or z2 < 1:
        raise ModelError(f"teeth: numbers of teeth must be >= 1, got {text!r}")
    return z1, z2


@command("te", TE_OPTIONS)
def te(
    inp: Inputs,
    file: Annotated[Path, typer.Argument(help="Measured TE record: two columns (angle or time, TE), header with units optional.")],
) -> None:
    """Measured transmission error: mesh-order harmonics with phases, shaft-order sidebands, hunting period, and a
    [mesh] section (mesh orders only) the other commands accept."""
    from ..te import analyse_te, mesh_section, read_te

    z1, z2 = _teeth(inp.teeth)
    sig = read_te(file, x_unit=inp.x_unit, te_unit=inp.te_unit, rpm=inp.te_rpm)
    res = analyse_te(sig, z1, z2, harmonics=inp.harmonics, shaft_orders=inp.shaft_orders)
    section = mesh_section(res)
    summary = res.to_json()
    summary["abscissa"] = sig.abscissa
    summary["mesh_section"] = section
    files = []
    if inp.te_out is not None:
        inp.te_out.write_text(section, encoding="utf-8")
        files.append(str(inp.te_out))
    if inp.json_out:
        summary["files"] = files
        emit_json(summary)
        return
    _show_te(summary, files)


def _show_te(s: dict[str, Any], files: list[str]) -> None:
    t = Table(title=f"Mesh harmonics of {s['source']} (z1 = {s['z1']}, z2 = {s['z2']})")
    for col in ("l", "pinion order", "amplitude (µm)", "phase (deg)"):
        t.add_column(col, justify="right")
    for r in s["mesh_harmonics"]:
        t.add_row(str(r["mesh_harmonic"]), f"{r['order']:.6g}", f"{r['amplitude_um']:.5g}", f"{r['phase_deg']:.4g}")
    console.print(t)
    side = sorted(s["sidebands"], key=lambda r: -r["amplitude_um"])[:8]
    t = Table(title="Largest shaft orders and sidebands")
    for col in ("kind", "shaft", "pinion order", "amplitude (µm)", "phase (deg)"):
        t.add_column(col)
    for r in side:
        t.add_row(r["kind"], r.get("shaft", ""), f"{r['order']:.6g}", f"{r['amplitude_um']:.5g}", f"{r['phase_deg']:.4g}")
    console.print(t)
    lines = [
        f"hunting period: {s['hunting_period_mesh_cycles']} mesh cycles ({s['hunting_period_pinion_revolutions']:.6g} "
        f"pinion revolutions); the record covers {s['record_pinion_revolutions']:.4g} pinion revolutions",
        f"sidebands: {100 * s['sideband_share']:.3g} % of the fitted orders' RMS; the forcing is "
        + ("periodic over one mesh cycle to that share" if s["periodic_over_mesh_cycle"]
           else "NOT periodic over one mesh cycle (the model keeps the mesh orders only)"),
        f"residual: {100 * s['residual_share']:.3g} % of the signal's RMS",
        *[f"left out: {x}" for x in s["left_out"]],
    ]
    for line in lines:
        console.print(line, markup=False, highlight=False)
    console.print(s["mesh_section"], markup=False, highlight=False, soft_wrap=True)
    for f in files:
        console.print(f"wrote {f}", markup=False, highlight=False)


def attach_iso_kv(config: Optional[Path], model: Any, ds: Any, summary: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    """Add the ISO K_v-B curve (JSON ``iso_kv``, Dataset attribute ``iso_kv``) to a frequency response over ω.

    Only when the configured pair has the ISO inputs K_v needs (``f_pt`` among its ``[gear_pair]`` keys); the
    response is returned unchanged otherwise.
    """
    import json

    from ..config import load_config
    from ..geometry.iso import iso_kv_block

    cfg = load_config(config)
    if cfg.pair is None or "f_pt" not in cfg.iso_inputs or "rpm" not in ds.coords:
        return ds, summary
    sc = cfg.scales
    u_max = {str(s): ds["u_max"].sel(sweep=s).values for s in ds["sweep"].values}
    block = iso_kv_block(cfg.pair, cfg.iso_inputs, torque=float(sc.torque_from_fp(model.fp)),
                         rpm=ds["rpm"].values, u_max=u_max, D=model.D, fp=model.fp,
                         model_resonance_rpm=float(sc.rpm_from_omega(1.0)))
    ds = ds.copy()
    ds.attrs["iso_kv"] = json.dumps(block)
    return ds, {**summary, "iso_kv": block}
