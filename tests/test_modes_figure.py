"""``geardyn modes``: the ``modes`` Dataset, its registered Campbell figure (drawn artists inspected) and one
mode numbering in the table, the crossings, the JSON and the file."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from matplotlib.text import Annotation, Text
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.io import read_netcdf
from geardyn.plot import draw, figures_for
from geardyn.systems import load_description, modes_report
from geardyn.systems.modes_data import modes_dataset

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
PLANETARY = EX / "planetary_lin_parker_1999.toml"
BEVEL = EX / "paper_bevel_8dof.toml"
SRC = Path(__file__).resolve().parents[1] / "src" / "geardyn"


def _invoke(*args: str):
    r = CliRunner().invoke(app, list(args))
    assert r.exit_code == 0, r.output
    return r


def _drawn(ds):
    art = draw(ds, "campbell")
    ax = art.axes[0]
    horizontal = [
        a for a in ax.lines if np.ptp(a.get_ydata()) == 0 and a.get_linestyle() == "-" and list(a.get_xdata()) == [0, 1]
    ]  # axhline: x in axes fraction
    orders = [
        a for a in ax.lines if a.get_label() and not a.get_label().startswith("_") and a.get_label() != "crossing"
    ]
    labels = [a.get_text() for a in ax.texts if isinstance(a, Annotation)]
    return art, ax, horizontal, orders, labels


def test_planetary_campbell_figure_one_line_per_mode_and_order_legend_outside():
    """Lin & Parker's planetary set (no tooth count): drawn against the mesh frequency, one labelled line per
    natural frequency (degenerate pairs named together), one line per order for the six meshes, and the
    legend below the axes, overlapping none of the data."""
    rep = modes_report(load_description(PLANETARY))
    ds = modes_dataset(rep)
    art, ax, horizontal, orders, labels = _drawn(ds)
    distinct = sorted({round(f, 6) for f in rep["frequencies_hz"] if f > 0})
    assert len(horizontal) == len(distinct) == 11
    assert sorted(round(a.get_ydata()[0], 6) for a in horizontal) == distinct
    assert [a.get_label() for a in orders] == ["order 1", "order 2", "order 3"]
    assert len(labels) == 12  # the 11 frequencies and the rigid-body mode
    assert "modes 2, 3: 743.16 Hz" in labels and "mode 1: rigid body" in labels and "mode 18: 11775 Hz" in labels
    numbers = sorted(int(n) for t in labels for n in re.findall(r"\d+(?=[,:])", t.split(":")[0] + ":"))
    assert numbers == list(range(1, 19))  # every mode named once
    assert "mesh frequency of sun_planet1 [Hz]" == ax.get_xlabel()
    fig = art.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    leg = ax.get_legend()
    assert [t.get_text() for t in leg.get_texts()] == ["order 1", "order 2", "order 3", "crossing"]
    assert not leg.get_window_extent(renderer).overlaps(ax.get_window_extent(renderer))
    # the mode labels sit right of the axes and do not overlap one another
    boxes = sorted((Text.get_window_extent(a, renderer) for a in ax.texts), key=lambda b: b.y0)  # text, not connector
    assert all(b.x0 > ax.get_window_extent(renderer).x1 for b in boxes)
    assert all(lo.y1 <= hi.y0 + 0.5 for lo, hi in zip(boxes, boxes[1:]))
    # crossings: one dot per (line, frequency) within the range
    dots = next(a for a in ax.lines if a.get_label() == "crossing")
    assert len(dots.get_xdata()) == len(rep["campbell"]["crossings"]) == ds.sizes["crossing"]


def test_modes_out_writes_the_dataset_and_plot_redraws_it(tmp_path):
    out = tmp_path / "pl"
    r = json.loads(_invoke("modes", "--system", str(PLANETARY), "--json", "--out", str(out)).stdout)
    assert sorted(Path(f).name for f in r["files"]) == ["campbell.png", "modes.nc"]
    ds = read_netcdf(out / "modes.nc")
    assert ds.attrs["geardyn_kind"] == "modes" and [f.stem for f in figures_for(ds)] == ["campbell"]
    assert list(ds["mode"].values) == [m["mode"] for m in r["modes"]] == list(range(1, 19))
    np.testing.assert_array_equal(ds["frequency_Hz"].values, r["frequencies_hz"])
    assert list(ds["crossing_mode"].values) == [c["mode"] for c in r["campbell"]["crossings"]]
    assert ds["frequency_Hz"].attrs["units"] == "Hz"
    again = tmp_path / "again"
    p = json.loads(_invoke("plot", str(out / "modes.nc"), "--out", str(again), "--json").stdout)
    assert p["kind"] == "modes" and [Path(f).name for f in p["files"]] == ["campbell.png"]
    assert (again / "campbell.png").stat().st_size > 10_000


def test_modes_numbering_is_one_in_table_crossings_and_json():
    """The table, the crossing table and the JSON number the modes alike, from 1 (the bevel pair's mesh mode is 8)."""
    j = json.loads(_invoke("modes", "--system", str(BEVEL), "--rpm-max", "5000", "--json").stdout)
    mesh_mode = next(m["mode"] for m in j["modes"] if m["mesh_dominated"])
    assert mesh_mode == 8 and j["degenerate"] == [[3, 4], [6, 7]]
    last = j["campbell"]["crossings"][-1]
    assert last["rpm"] == pytest.approx(4221.2, abs=0.1) and last["modes"] == [8] and last["order"] == 1
    text = _invoke("modes", "--system", str(BEVEL), "--rpm-max", "5000").stdout
    rows = re.findall(r"│ (\d+)\s+│ ([\d.]+|0 \(rigid body\))", text)
    assert [int(n) for n, _ in rows[:8]] == list(range(1, 9))
    assert re.search(r"│ 4221\.2\s+│ 1618\.13\s+│ 8\s+│ order 1", text)
    assert re.search(r"│ 291\.764\s+│ 335\.528\s+│ 3, 4\s+│ order 3", text)  # one row for the degenerate pair


def test_no_module_sets_a_matplotlib_backend():
    offenders = [str(p.relative_to(SRC)) for p in SRC.rglob("*.py") if "matplotlib.use(" in p.read_text()]
    assert offenders == []


def test_hz_max_sets_the_mesh_frequency_range_of_a_system_without_teeth():
    j = json.loads(_invoke("modes", "--system", str(PLANETARY), "--hz-max", "3000", "--json").stdout)
    c = j["campbell"]
    assert c["x"] == "mesh_frequency_hz" and c["x_range"] == [0.0, 3000.0]
    assert c["crossings"] and all(0.0 <= x["x"] <= 3000.0 for x in c["crossings"])
    assert max(x["x"] for x in c["crossings"]) == pytest.approx(2658.32, abs=0.01)  # mode 12, order 1
    r = CliRunner().invoke(app, ["modes", "--system", str(PLANETARY), "--hz-max", "-1"])
    assert r.exit_code == 2 and "hz-max" in r.output
