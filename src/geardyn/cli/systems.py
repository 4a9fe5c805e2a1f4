"""``geardyn modes``: natural frequencies, mode shapes, strain-energy fractions and the Campbell diagram of a system."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import ModelError
from .options import OUTPUT, Inputs, choice, command, finish, option


def _orders(text: str) -> tuple[int, ...]:
    try:
        vals = tuple(int(p) for p in text.split(","))
    except ValueError:
        vals = ()
    if not vals or any(v < 1 for v in vals):
        raise ModelError(f"orders: expected positive integers separated by commas, got {text!r}")
    return vals


def _render(summary: dict[str, Any]) -> None:

    from .render import console as c
    from .render import plain, table

    t = table(
        f"modes — {summary.get('title') or ''}", "mode", "frequency (Hz)", "mesh-dominated", "largest strain energy"
    )
    for m, e in zip(summary["modes"], summary["energy_fractions"]):
        top = max(e.items(), key=lambda kv: kv[1]) if e else ("—", 0.0)
        t.add_row(
            str(m["mode"]),
            "0 (rigid body)" if m["rigid"] else f"{m['frequency_hz']:.6g}",
            "yes" if m["mesh_dominated"] else "no",
            "—" if m["rigid"] else f"{top[0]} {top[1]:.3f}",
        )
    c.print(t)
    if summary.get("degenerate"):
        c.print(
            "degenerate (one frequency): "
            + "; ".join("modes " + ", ".join(map(str, g)) for g in summary["degenerate"]),
            markup=False,
        )
    camp = summary.get("campbell")
    if summary.get("campbell_note"):
        plain(summary["campbell_note"])
    if camp and camp.get("gyroscopic"):
        plain(
            "gyroscopic terms on: the table gives the modes at standstill; the Campbell diagram solves them at "
            "each speed (branches, forward and backward whirl)"
        )
    if camp and camp["crossings"]:
        gyro = bool(camp.get("gyroscopic"))
        x_col = "pinion speed (rpm)" if camp["x"] == "rpm" else "mesh frequency (Hz)"
        x = table("Campbell crossings", x_col, "frequency (Hz)", "modes", "line", *(["whirl"] if gyro else []))
        for cr in camp["crossings"]:
            x.add_row(
                f"{cr['x']:.6g}",
                f"{cr['frequency_hz']:.6g}",
                ", ".join(map(str, cr["modes"])),
                camp["lines"][cr["line"]]["label"],
                *([cr["whirl"]] if gyro else []),
            )
        c.print(x)


MODES_OPTIONS = [
    option("system", Path, ..., help="TOML file of the multi-DOF system."),
    option("rpm_max", float, 10000.0, help="Upper end of the Campbell diagram's speed range (rpm)."),
    option(
        "hz_max",
        float | None,
        help="Upper end of the reference mesh frequency (Hz) of a Campbell diagram drawn against it (a "
        "reference mesh without teeth); default 1.2 times where the lowest order meets the highest mode.",
    ),
    option("orders", str, "1,2,3", help="Mesh orders of the Campbell diagram, e.g. '1,2,3'."),
    option("clearances", str, "contact", help="Clearance elements 'contact' (stiffness on) or 'open'."),
]


@command("modes", MODES_OPTIONS, OUTPUT)
def modes(inp: Inputs) -> None:
    """Natural frequencies (Hz, ascending; modes numbered from 1, rigid-body modes 0 Hz), M-orthonormal mode
    shapes and modal strain-energy fractions per element at mean mesh stiffness, and the Campbell diagram with
    the crossings of the mesh orders (against pinion speed, or against the mesh frequency when the reference
    mesh gives no teeth); --out writes modes.nc and the Campbell figure."""
    from .. import validate
    from ..systems import load_description, modes_report
    from ..systems.modes import modes_budget_of_file

    modes_budget_of_file(inp.system)  # a system too large is refused before its file is loaded
    desc = load_description(inp.system)
    hi = validate.positive("rpm-max", inp.rpm_max)
    hz = None if inp.hz_max is None else (0.0, validate.positive("hz-max", inp.hz_max))
    clearances = choice("clearances", inp.clearances, ("contact", "open"))
    rep = modes_report(desc, (0.0, hi), _orders(inp.orders), clearances, hz)
    paths: list[str] = []
    if inp.out is not None:
        from ..systems.modes_data import modes_dataset

        paths = inp.write(modes_dataset(rep), "modes")
    finish(rep, paths, inp, _render)
