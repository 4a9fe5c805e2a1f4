"""``geardyn modes``: natural frequencies, mode shapes, strain-energy fractions and the Campbell diagram of a system."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from ..errors import ModelError
from .options import OUTPUT, Inputs, command, finish


def _orders(text: str) -> tuple[int, ...]:
    try:
        vals = tuple(int(p) for p in text.split(","))
    except ValueError:
        vals = ()
    if not vals or any(v < 1 for v in vals):
        raise ModelError(f"orders: expected positive integers separated by commas, got {text!r}")
    return vals


def _figure(report: dict[str, Any], path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    camp = report["campbell"]
    lo, hi = camp["rpm_range"]
    fig, ax = plt.subplots(figsize=(7, 5))
    for f in report["frequencies_hz"]:
        if f > 0:
            ax.axhline(f, color="0.6", lw=0.8)
    for line in camp["lines"]:
        ax.plot([lo, hi], [line["hz_per_rpm"] * lo, line["hz_per_rpm"] * hi], lw=1.2,
                label=f"{line['mesh']} order {line['order']}")
    for c in camp["crossings"]:
        ax.plot(c["rpm"], c["frequency_hz"], "o", ms=4, color="k")
    ax.set_xlabel("pinion speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(report.get("title") or "Campbell diagram")
    ax.legend(fontsize=8)
    import io

    from ..atomic import atomic_write_bytes

    out = path / "campbell.png" if path.suffix == "" else path
    buf = io.BytesIO()
    fig.savefig(buf, dpi=120, format=out.suffix.lstrip(".").lower() or "png")
    plt.close(fig)
    return atomic_write_bytes(out, buf.getbuffer())


def _render(summary: dict[str, Any], paths: list[str]) -> None:
    from rich.console import Console
    from rich.table import Table

    t = Table(title=f"modes — {summary.get('title') or ''}")
    for col in ("mode", "frequency (Hz)", "mesh-dominated", "largest energy"):
        t.add_column(col)
    for i, (m, e) in enumerate(zip(summary["modes"], summary["energy_fractions"])):
        top = max(e.items(), key=lambda kv: kv[1]) if e else ("—", 0.0)
        t.add_row(str(i + 1), "rigid (0)" if m["rigid"] else f"{m['frequency_hz']:.6g}",
                  "yes" if m["mesh_dominated"] else "no", f"{top[0]} {top[1]:.3f}")
    c = Console()
    c.print(t)
    camp = summary.get("campbell")
    if camp:
        for x in camp["crossings"]:
            c.print(f"crossing: {x['rpm']:.6g} rpm, mode {x['mode']}, order {x['order']} of {x['mesh']}")
    for p in paths:
        c.print(f"wrote {p}")


@command("modes", OUTPUT)
def modes(
    inp: Inputs,
    system: Annotated[Path, typer.Option("--system", help="TOML file of the multi-DOF system.")],
    rpm_max: Annotated[float, typer.Option("--rpm-max", help="Upper end of the Campbell diagram's speed range (rpm).")] = 10000.0,
    orders: Annotated[str, typer.Option("--orders", help="Mesh orders of the Campbell diagram, e.g. '1,2,3'.")] = "1,2,3",
    clearances: Annotated[str, typer.Option("--clearances", help="Clearance elements 'contact' (stiffness on) or 'open'.")] = "contact",
) -> None:
    """Natural frequencies (Hz, ascending; rigid-body modes 0), M-orthonormal mode shapes and modal strain-energy
    fractions per element at mean mesh stiffness, and the Campbell diagram against pinion speed with the
    mesh-order crossings (rpm, mode, order); --out writes the Campbell figure."""
    from .. import validate
    from ..systems import load_description, modes_report
    from .options import choice

    desc = load_description(system)
    hi = validate.positive("rpm-max", rpm_max)
    rep = modes_report(desc, (0.0, hi), _orders(orders), choice("clearances", clearances, ("contact", "open")))
    paths: list[str] = []
    if inp.out is not None:
        if rep.get("campbell") is None:
            raise ModelError(f"out: no Campbell diagram: {rep.get('campbell_note')}")
        paths = [str(_figure(rep, Path(inp.out)))]
    finish(rep, paths, inp, _render)
