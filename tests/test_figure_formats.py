"""``--format`` and ``--dpi``: every command that draws (and ``geardyn plot``) saves its figures in the formats
asked for, at the resolution asked for, and refuses a bad value before computing anything."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.errors import ModelError
from geardyn.io import read_netcdf
from geardyn.plot import save_figures
from geardyn.plot.common import DPI
from geardyn.validate import figure_formats

SHORT = ["--transient", "20", "--periods", "8"]
MAGIC = {"png": b"\x89PNG", "pdf": b"%PDF", "svg": b"<?xml"}
BEVEL = str(Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_bevel_8dof.toml")


def _run(*args: str, code: int = 0):
    r = CliRunner().invoke(app, list(args))
    assert r.exit_code == code, r.output
    return r


def _files(r) -> list[Path]:
    return [Path(f) for f in json.loads(r.stdout)["files"]]


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """(directory, files) of one ``simulate --out`` at the default format and resolution."""
    d = tmp_path_factory.mktemp("simulate")
    return d, _files(_run("simulate", "--omega", "0.8", *SHORT, "--json", "--out", str(d)))


def test_simulate_saves_every_format_at_the_resolution_asked_for(tmp_path, simulated):
    a, base = simulated
    r = _run(
        "simulate",
        "--omega",
        "0.8",
        *SHORT,
        "--json",
        "--out",
        str(tmp_path / "b"),
        "--format",
        "png,PDF, svg",
        "--dpi",
        "240",
    )
    files = _files(r)
    stems = [p.stem for p in base if p.suffix == ".png"]
    assert [(p.stem, p.suffix) for p in files if p.suffix != ".nc"] == [
        (s, f".{f}") for s in stems for f in ("png", "pdf", "svg")
    ]
    for p in files[1:]:
        assert p.read_bytes().startswith(MAGIC[p.suffix[1:]]), p.name
    for p in (f for f in files if f.suffix == ".png"):
        big, small = Image.open(p), Image.open(a / p.name)
        assert big.info["dpi"] == pytest.approx((240, 240), abs=0.05)
        assert big.size[0] == pytest.approx(2 * small.size[0], rel=0.02)  # 240 dpi against the default 120 (text
        # and the tight bounding box round to whole pixels at each resolution)
    assert DPI == 120  # the CLI's default (--dpi)


def test_plot_modes_and_a_map_take_the_formats(tmp_path, simulated):
    r = _run("plot", str(simulated[0] / "simulate.nc"), "--out", str(tmp_path / "p"), "--format", "svg", "--json")
    assert {p.suffix for p in _files(r)} == {".svg"} and len(_files(r)) == 5
    r = _run("modes", "--system", BEVEL, "--out", str(tmp_path / "m"), "--format", "pdf", "--json")
    assert [p.name for p in _files(r)] == ["modes.nc", "campbell.pdf"]
    r = _run(
        "map",
        "--x",
        "omega",
        "--x-start",
        "0.6",
        "--x-stop",
        "0.8",
        "--x-num",
        "2",
        "--y",
        "xi0",
        "--y-start",
        "0.05",
        "--y-stop",
        "0.1",
        "--y-num",
        "2",
        "--settle",
        "0",
        *SHORT,
        "--out",
        str(tmp_path / "map"),
        "--format",
        "svg,png",
        "--json",
    )
    names = [p.name for p in _files(r)]
    assert "map_motion.svg" in names and "map_motion.png" in names and not any(n.endswith(".pdf") for n in names)


@pytest.mark.parametrize(
    "args, message",
    [
        (["--format", "jpg"], "format: expected png, pdf, svg"),
        (["--format", ""], "format:"),
        (["--dpi", "0"], "dpi: must be an integer >= 10"),
    ],
)
def test_bad_format_or_dpi_refused_before_the_run(tmp_path, args, message):
    r = _run(
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "0.5",
        "--stop",
        "1.5",
        "--num",
        "3",
        *SHORT,
        "--out",
        str(tmp_path),
        *args,
        code=2,
    )
    assert message in r.output and len(r.output.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())  # nothing computed, nothing written


def test_save_figures_in_python_takes_a_list_of_formats(tmp_path, simulated):
    ds = read_netcdf(simulated[0] / "simulate.nc")
    paths = save_figures(ds, tmp_path / "py", fmt=["svg", "pdf"], dpi=80)
    assert [p.suffix for p in paths[:2]] == [".svg", ".pdf"] and len(paths) == 10
    assert figure_formats("PNG, .svg,png") == ("png", "svg")
    with pytest.raises(ModelError, match="format"):
        save_figures(ds, tmp_path / "bad", fmt="tiff")
