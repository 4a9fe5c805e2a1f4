"""Every axis label of a system's figure names the mesh it shows (issue 23 item 6), written once for pair and systems:
the figures are the pair's, drawn from a copy of the result whose reference-mesh variables name the mesh
(``geardyn.plot.mesh_names``).  The drawn artists are inspected: axis labels (also the rpm and ω axes on top), the
legend entries of u and the contact lines."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from cli_run import run_cli

from geardyn.io import read_netcdf
from geardyn.plot import figures_for
from geardyn.plot.mesh_names import of_mesh

DATA = Path(__file__).parent / "data"
#: A label showing a quantity of the reference mesh: its deflection u or δ (and rates), displacements, DTE, amplitudes,
#: the mesh frequency ω or the pinion speed.
MESH_QUANTITY = re.compile(
    r"(?<![\w/])(u|δ|du/dτ|dδ/dτ)(?![\w/])|displacement|DTE|amplitude|ω(?!_n)|pinion speed|mesh force"
)
#: The system's results (``data/hyst/labels``): the torsional example with its mesh named 'bevel' (``"mesh"`` replaced
#: by ``"bevel"`` in ``examples/systems/paper_torsional.toml``), written by ``geardyn KIND ... --system bevel.toml
#: --out DIR`` with these arguments.
RUNS = {
    "simulate": ["simulate", "--omega", "0.8", "--transient", "30", "--periods", "4"],
    "bifurcation": [
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "0.7",
        "--stop",
        "0.9",
        "--num",
        "3",
        "--transient",
        "20",
        "--periods",
        "8",
    ],
    "response": [
        "response",
        "--omega-start",
        "0.7",
        "--omega-stop",
        "0.9",
        "--num",
        "3",
        "--transient",
        "20",
        "--periods",
        "8",
    ],
}


def run(*args: str) -> None:
    code, _out, err = run_cli(args)
    assert not code, err


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict[str, object]:
    """The system's stored results and the pair's response (run here, short)."""
    out = {f"system {kind}": read_netcdf(DATA / "hyst" / "labels" / f"{kind}.nc") for kind in RUNS}
    root = tmp_path_factory.mktemp("labels")
    run(*RUNS["response"], "--json", "--out", str(root))
    out["pair response"] = read_netcdf(root / "response.nc")
    return out


def _labels(art) -> list[str]:
    """The axis labels of a drawn figure: every Axes and its secondary (rpm, ω) axes."""
    axes = list(art.figure.axes) + [c for a in art.figure.axes for c in a.child_axes]
    return [t for a in axes for t in (a.get_xlabel(), a.get_ylabel()) if t]


@pytest.mark.parametrize("kind", list(RUNS))
def test_every_label_of_a_systems_figure_names_its_mesh(results, kind):
    ds = results[f"system {kind}"]
    specs = figures_for(ds)
    assert specs
    checked = 0
    for spec in specs:
        art = spec(ds)
        for text in _labels(art):
            if MESH_QUANTITY.search(text) and "each" not in text:  # (per-element figures name each in a legend)
                assert "mesh 'bevel'" in " ".join(text.split()), f"{spec.stem}: {text!r}"
                checked += 1
    assert checked >= len(specs)


def test_the_pairs_figures_keep_their_labels(results):
    ds = results["pair response"]
    for spec in figures_for(ds):
        assert not any("mesh '" in t for t in _labels(spec(ds)))


def test_the_labels_of_a_systems_time_history_and_bifurcation_diagram(results):
    """The exact labels: u of the mesh on the time history (its legend too) and the bifurcation diagram's section and
    contact lines, ω and the pinion speed of the mesh on the sweeps."""
    ds = results["system simulate"]
    spec = {s.stem: s for s in figures_for(ds)}
    art = spec["time_history"](ds)
    ax = art.axes[0]
    assert " ".join(ax.get_ylabel().split()) == ("dynamic transmission error u of mesh 'bevel' (non-dimensional) [b_c]")
    assert "u of mesh 'bevel'" in [t.get_text() for t in ax.get_legend().get_texts()]
    art = spec["spectrum"](ds)
    assert art.axes[0].get_ylabel() == "amplitude of u of mesh 'bevel'"
    art = spec["phase_portrait"](ds)
    assert art.axes[0].get_ylabel() == "velocity du/dτ of mesh 'bevel' (non-dimensional)"

    ds = results["system response"]
    spec = {s.stem: s for s in figures_for(ds)}
    art = spec["response_bifurcation"](ds)
    ax = art.axes[0]
    assert ax.get_ylabel() == "Poincaré section u of mesh 'bevel' (θ ≡ 0)"
    assert "contact u of mesh 'bevel' = ±D" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert art.figure.axes[-1].get_xlabel() == "mesh frequency ω = ω_e/ω_n of mesh 'bevel'"
    assert [c.get_xlabel() for c in ax.child_axes] == ["pinion speed of mesh 'bevel' [rpm]"]
    art = spec["response_rpm"](ds)
    ax = art.axes[0]
    assert ax.get_xlabel() == "pinion speed of mesh 'bevel' [rpm]"
    assert ax.get_ylabel() == "half peak-to-peak DTE of mesh 'bevel' [µm]"
    assert [c.get_xlabel() for c in ax.child_axes] == ["ω = ω_e/ω_n of mesh 'bevel'"]


def test_files_of_the_earlier_system_kinds_name_the_mesh():
    """A ``system_response`` file of an earlier version ("deflection δ of the reference mesh") names the mesh too."""
    ds = read_netcdf(DATA / "system_kinds" / "system_response.nc")
    for spec in figures_for(ds):
        for text in _labels(spec(ds)):
            assert "reference mesh" not in text


def test_of_mesh_names_the_mesh_after_the_symbol_or_at_the_end():
    class Result:  # what of_mesh reads: the result's system attribute
        attrs = {"system": '{"reference_mesh": "bevel"}'}

    ds = Result()
    assert of_mesh("RMS of u about its mean", ds) == "RMS of u of mesh 'bevel' about its mean"
    assert of_mesh("u_min, u_max", ds) == "u_min, u_max of mesh 'bevel'"
    assert of_mesh("deflection δ of the reference mesh", ds) == "deflection δ of mesh 'bevel'"
    assert of_mesh("u of mesh 'bevel'", ds) == "u of mesh 'bevel'"
    Result.attrs = {}
    assert of_mesh("RMS of u about its mean", Result()) == "RMS of u about its mean"
