"""What a user sees: run-up panels on one x scale, every figure saved at one resolution, and a system with no
excitation said to be one."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.io import read_netcdf
from geardyn.plot import draw
from geardyn.plot.common import DPI
from geardyn.systems import load_system
from geardyn.systems.notes import excitation_note

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"


def _invoke(*args: str):
    r = CliRunner().invoke(app, list(args))
    assert r.exit_code == 0, r.output
    return r


@pytest.fixture(scope="module")
def runup_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("runup")
    _invoke(
        "runup",
        "--rpm-start",
        "1700",
        "--rpm-stop",
        "2000",
        "--duration",
        "0.5",
        "--num",
        "3",
        "--json",
        "--out",
        str(d),
    )
    return d


def test_runup_panels_share_one_x_scale(runup_dir):
    """The colour bar of the order map sits beside its panel: the three panels have the same left and right
    edges and limits, so a jump is at the same x in all three (it was not: the bar narrowed the top panel)."""
    art = draw(read_netcdf(runup_dir / "runup.nc"), "runup")
    art.figure.canvas.draw()
    boxes = [a.get_window_extent() for a in art.axes]
    assert len(boxes) == 3
    for b in boxes[1:]:
        assert b.x0 == pytest.approx(boxes[0].x0, abs=0.5) and b.x1 == pytest.approx(boxes[0].x1, abs=0.5)
    assert len({a.get_xlim() for a in art.axes}) == 1


def test_every_figure_is_saved_at_one_resolution(runup_dir, tmp_path):
    """HB, run-up and every other figure go through one save at :data:`DPI`."""
    _invoke(
        "hb",
        "--param",
        "omega",
        "--start",
        "0.5",
        "--stop",
        "0.65",
        "--harmonics",
        "8",
        "--json",
        "--out",
        str(tmp_path),
    )
    pngs = sorted(tmp_path.glob("*.png")) + sorted(runup_dir.glob("*.png"))
    assert {p.name for p in pngs} >= {"hb.png", "runup.png"}
    for p in pngs:
        assert Image.open(p).info["dpi"] == pytest.approx((DPI, DPI), abs=0.05)  # stored as pixels per metre, p.name


def test_a_system_without_excitation_says_so():
    """Lin & Parker's planetary set has no load and no STE: from rest its response is zero, and the output says
    that it is a system for the modes; a loaded system (the bevel pair) gets no such note, nor a start off rest."""
    planetary = load_system(EX / "planetary_lin_parker_1999.toml")
    assert "no excitation" in excitation_note(planetary) and "geardyn modes" in excitation_note(planetary)
    assert excitation_note(planetary, (0.1, 0.0)) is None
    assert excitation_note(load_system(EX / "paper_bevel_8dof.toml")) is None
    r = json.loads(
        _invoke(
            "simulate",
            "--system",
            str(EX / "planetary_lin_parker_1999.toml"),
            "--omega",
            "0.5",
            "--transient",
            "20",
            "--periods",
            "4",
            "--json",
        ).stdout
    )
    assert r["amplitude"] == 0.0 and "no excitation" in r["note"]
