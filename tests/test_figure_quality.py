"""What the figures show, checked on the drawn artists: contact lines at the plotted backlash, text that
does not overlap, legends clear of the data, titles with the model parameters, NaN cells in a colour of
their own with a legend entry."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
import xarray as xr
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.io import read_netcdf
from geardyn.plot import draw, figures_for
from geardyn.plot.common import NAN_COLOR, parameter_text, symbol

MODEL = {
    "D": 1.0,
    "eps": [0.5],
    "fp": 0.2,
    "kappa": [0.2],
    "omega": 1.0,
    "phi_c": [0.0],
    "phi_e": [0.0],
    "phi_k": [0.0],
    "xi": [0.05],
    "xi0": 0.1,
}

RUNS = {
    "simulate": ["simulate", "--rpm", "2400", "--transient", "30", "--periods", "8"],
    "bifurcation_D": [
        "bifurcation",
        "--param",
        "D",
        "--start",
        "0.05",
        "--stop",
        "1",
        "--num",
        "5",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "map": [
        "map",
        "--x",
        "omega",
        "--y",
        "D",
        "--rpm-start",
        "1000",
        "--rpm-stop",
        "4000",
        "--x-num",
        "4",
        "--y-start",
        "0.1",
        "--y-stop",
        "1",
        "--y-num",
        "6",
        "--transient",
        "20",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "orbit": ["orbit", "--omega", "1.2", "--transient", "50"],
    "basins": ["basins", "--omega", "1.2", "--nu", "3", "--nv", "3", "--transient", "20", "--periods", "16"],
}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """name -> Dataset written by a tiny run of each command."""
    out = {}
    for name, args in RUNS.items():
        d = tmp_path_factory.mktemp(name)
        r = CliRunner().invoke(app, args + ["--json", "--out", str(d)])
        assert r.exit_code == 0, r.output
        out[name] = read_netcdf(next(d.glob(f"{args[0]}.nc")))
    return out


def _response(param="omega"):
    """A response result whose two jumps lie close together (their labels would collide)."""
    x = np.linspace(0.4, 0.8, 9)
    up = np.where(x < 0.6, 0.2, 1.1)
    down = np.where(x < 0.52, 0.2, 1.1)
    jumps = [
        {"sweep": "down", param: 0.525, "amplitude_from": 1.1, "amplitude_to": 0.2},
        {"sweep": "up", param: 0.615, "amplitude_from": 0.25, "amplitude_to": 1.1},
        {"sweep": "up", param: 0.635, "amplitude_from": 0.3, "amplitude_to": 1.0},
    ]
    return xr.Dataset(
        {"amplitude": (("sweep", param), np.stack([up, down]))},
        coords={"sweep": ["up", "down"], param: x},
        attrs={
            "geardyn_kind": "response",
            "param": param,
            "measure": "amplitude",
            "model": json.dumps(MODEL),
            "jumps": json.dumps(jumps),
            "hysteresis": json.dumps([[0.525, 0.615]]),
        },
    )


def _stability():
    om = np.linspace(0.4, 2.2, 10)
    crit = np.array([np.nan, 0.08, 0.11, 0.2, 0.22, 0.21, 0.15, np.nan, np.nan, np.nan])
    kinds = ["stable" if np.isnan(c) else "period-doubling" for c in crit]
    return xr.Dataset(
        {
            "xi0_critical": ("omega", crit),
            "bifurcation_type": ("omega", kinds),
            "xi0_critical_linear": ("omega", np.r_[np.zeros(8), 0.055, 0.0]),
            "xi0_paper": 0.4899,
        },
        coords={"omega": om},
        attrs={"geardyn_kind": "stability_comparison", "model": json.dumps(MODEL)},
    )


def _texts(fig):
    """(name, window extent) of every visible text of a figure: titles, axis labels, texts, annotations
    and whole legends (tick labels are left to matplotlib)."""
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    out = []
    for ax in fig.axes:
        items = [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        for child in ax.get_children():  # secondary axes carry labels of their own
            if hasattr(child, "xaxis") and child is not ax and hasattr(child, "get_xlabel"):
                items += [child.xaxis.label, child.yaxis.label]
        for t in items:
            if t.get_visible() and t.get_text().strip():
                out.append((t.get_text(), t.get_window_extent(renderer)))
        legend = ax.get_legend()
        if legend is not None:
            out.append(("legend", legend.get_window_extent(renderer)))
    return out


def _assert_no_overlap(fig, what):
    for (a, ba), (b, bb) in itertools.combinations(_texts(fig), 2):
        assert not ba.overlaps(bb), f"{what}: {a!r} overlaps {b!r}"


def _data_points(ax):
    pts = [
        np.column_stack(line.get_data())
        for line in ax.get_lines()
        if line.get_transform() is ax.transData and line.get_visible()
    ]
    pts += [c.get_offsets() for c in ax.collections if c.get_offset_transform() is ax.transData]
    pts = [np.asarray(p, dtype=float).reshape(-1, 2) for p in pts]
    pts = np.concatenate(pts) if pts else np.zeros((0, 2))
    return ax.transData.transform(pts[np.all(np.isfinite(pts), axis=1)])


def _assert_legends_clear_of_data(fig, what):
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        box = legend.get_window_extent(renderer)
        inside = [p for p in _data_points(ax) if box.contains(*p)]
        assert not inside, f"{what}: the legend covers {len(inside)} data points"


def test_contact_lines_follow_the_swept_backlash(results):
    ds = results["bifurcation_D"]
    art = draw(ds, "bifurcation")
    lines = [a for a in art.axes[0].get_lines() if a.get_gid() == "contact"]
    assert len(lines) == 2
    D = np.sort(ds["D"].values)
    for line, sign in zip(lines, (1, -1)):
        x, y = (np.asarray(v, dtype=float) for v in line.get_data())
        np.testing.assert_allclose(x, D)
        np.testing.assert_allclose(y, sign * D)  # u = ±D of each plotted point, not of the base model


def test_contact_lines_at_the_model_backlash_when_it_is_fixed(results):
    art = draw(results["simulate"], "time_history")
    lines = [a for a in art.axes[0].get_lines() if a.get_gid() == "contact"]
    assert sorted(float(line.get_ydata()[0]) for line in lines) == [-1.0, 1.0]


def test_jump_labels_collide_neither_with_each_other_nor_with_arrows():
    ds = _response()
    art = draw(ds, "response")
    labels = [t for t in art.axes[0].texts if t.get_text()]
    assert [t.get_text() for t in labels] == ["ω = 0.525", "ω = 0.615", "ω = 0.635"]
    _assert_no_overlap(art.figure, "response")
    renderer = art.figure.canvas.get_renderer()
    arrows = [t.arrow_patch.get_window_extent(renderer) for t in art.axes[0].texts if not t.get_text()]
    for t in labels:
        assert not any(t.get_window_extent(renderer).overlaps(b) for b in arrows), t.get_text()


@pytest.mark.parametrize("stem", ["time_history", "phase_portrait", "spectrum", "physical_time_history", "spectrum_hz"])
def test_simulate_figures_have_no_overlapping_text(results, stem):
    art = draw(results["simulate"], stem)
    _assert_no_overlap(art.figure, stem)


def test_spectrum_labels_fit_their_axes(results):
    for stem in ("spectrum", "spectrum_hz"):
        fig = draw(results["simulate"], stem).figure
        renderer = fig.canvas.get_renderer()
        ax = fig.axes[0]
        assert ax.yaxis.label.get_window_extent(renderer).height <= ax.get_window_extent(renderer).height, stem


@pytest.mark.parametrize("name", ["stability", "time_history", "physical_time_history", "response"])
def test_legends_hide_no_data(results, name):
    if name == "stability":
        art = draw(_stability(), "stability_boundary")
    elif name == "response":
        art = draw(_response(), "response")
    else:
        art = draw(results["simulate"], name)
    _assert_legends_clear_of_data(art.figure, name)
    _assert_no_overlap(art.figure, name)


@pytest.mark.parametrize("name", list(RUNS))
def test_every_title_carries_the_parameters(results, name):
    ds = results[name]
    exclude = [ds.attrs[k] for k in ("param", "x", "y") if k in ds.attrs]
    for spec in figures_for(ds):
        fig = spec(ds).figure
        titles = " ".join(ax.get_title() for ax in fig.axes)
        for part in ("ξ0 = 0.1", "κ1 = 0.2", "f_p = 0.2"):
            assert part in titles, f"{spec.stem}: {titles!r}"
        assert "xi0" not in titles and "omega=" not in titles, spec.stem
        if "D" not in exclude and spec.stem != "amplitude_um_vs_rpm":
            assert "D = 1" in titles, f"{spec.stem}: {titles!r}"


def test_parameter_symbols():
    assert [symbol(n) for n in ("omega", "xi0", "xi1", "kappa2", "fp", "eps1", "D", "rpm")] == [
        "ω",
        "ξ0",
        "ξ1",
        "κ2",
        "f_p",
        "ε1",
        "D",
        "rpm",
    ]
    ds = xr.Dataset(attrs={"model": json.dumps(MODEL)})
    assert parameter_text(ds, ["omega", "backlash"]) == "ξ0 = 0.1, ξ1 = 0.05, κ1 = 0.2, f_p = 0.2, ε1 = 0.5"


def test_map_draws_missing_exponents_in_a_colour_of_their_own(results):
    ds = results["map"]
    lle = ds["lle"].values.copy()
    lle[0, 0] = np.nan
    lle[1, 0] = 0.0
    ds = ds.assign(lle=(ds["lle"].dims, lle))
    art = draw(ds, "map_lle")
    ax = art.axes[0]
    (nan_cells,) = [c for c in ax.collections if c.get_gid() == "nan"]
    assert nan_cells.get_hatch()
    mesh = ax.collections[0]
    zero = mesh.cmap(mesh.norm(0.0))
    grey = nan_cells.cmap(0.0)
    assert np.allclose(grey[:3], [int(NAN_COLOR[i : i + 2], 16) / 255 for i in (1, 3, 5)])
    assert np.linalg.norm(np.subtract(grey[:3], zero[:3])) > 0.2  # not the colour of λ1 = 0
    legend = ax.get_legend()
    assert legend is not None and any("NaN" in t.get_text() for t in legend.get_texts())
    _assert_no_overlap(art.figure, "map_lle")


def test_amplitude_against_rpm_of_a_map_has_markers_a_colour_bar_and_a_title(results):
    ds = results["map"]
    art = draw(ds, "amplitude_um_vs_rpm")
    ax = art.axes[0]
    lines = [a for a in ax.get_lines() if isinstance(a, Line2D)]
    assert len(lines) == ds.sizes["D"]
    assert all(line.get_marker() not in (",", "None", None, "") and line.get_markersize() >= 3 for line in lines)
    assert len({tuple(line.get_color()) for line in lines}) == len(lines)
    assert any(a.get_ylabel() == "half backlash D" for a in art.figure.axes[1:])  # the colour bar of the rows
    assert "against pinion speed" in ax.get_title()
    few = ds.isel(D=[0, 1])
    ax = draw(few, "amplitude_um_vs_rpm").axes[0]
    assert isinstance(ax.get_legend(), Legend) and [t.get_text() for t in ax.get_legend().get_texts()] == [
        f"D = {v:.4g}" for v in few["D"].values
    ]


def test_amplitude_against_rpm_of_a_large_map_draws_evenly_spaced_rows_and_says_so(results):
    """Of more rows than MAX_CURVES, evenly spaced ones are drawn, the first and the last among them."""
    from geardyn.plot.physical import MAX_CURVES

    ds = results["map"]
    n = 3 * MAX_CURVES + 5
    d = np.linspace(0.1, 1.0, n)
    amp = ds["amplitude_um"].isel(D=0).values[None, :] * (1.0 + d[:, None])  # row k scaled by 1 + D_k
    big = xr.Dataset(
        {"amplitude_um": (("D", "omega"), amp, ds["amplitude_um"].attrs)},
        coords={"D": ("D", d, ds["D"].attrs), "omega": ds["omega"], "rpm": ds["rpm"]},
        attrs=ds.attrs,
    )
    ax = draw(big, "amplitude_um_vs_rpm").axes[0]
    lines = ax.get_lines()
    assert len(lines) == MAX_CURVES
    rows = [int(np.argmin(np.abs(amp[:, 0] - line.get_ydata()[0]))) for line in lines]
    assert rows[0] == 0 and rows[-1] == n - 1 and np.ptp(np.diff(rows)) <= 1  # evenly spaced
    assert all(np.array_equal(line.get_ydata(), amp[k]) for line, k in zip(lines, rows))
    assert f"({MAX_CURVES} of {n} D values, evenly spaced)" in ax.get_title()


def test_every_figure_of_the_runs_has_no_overlapping_text(results):
    for name, ds in results.items():
        for spec in figures_for(ds):
            _assert_no_overlap(spec(ds).figure, f"{name}/{spec.stem}")


def test_figures_over_omega_of_a_physical_pair_read_in_rpm_too(tmp_path):
    """Issue: `bifurcation`, `continuation` and `basins` given --rpm plotted in ω only."""
    from geardyn.cli import main
    from geardyn.io import read_netcdf
    from geardyn.plot import draw

    def run(*argv):
        try:
            main(list(argv))
        except SystemExit as e:
            assert e.code in (0, None)

    run(
        "bifurcation",
        "--rpm-start",
        "1500",
        "--rpm-stop",
        "3000",
        "--num",
        "6",
        "--transient",
        "20",
        "--periods",
        "8",
        "--out",
        str(tmp_path / "b"),
        "--json",
    )
    run(
        "basins",
        "--rpm",
        "2400",
        "--nu",
        "3",
        "--nv",
        "3",
        "--transient",
        "20",
        "--periods",
        "8",
        "--out",
        str(tmp_path / "s"),
        "--json",
    )
    art = draw(read_netcdf(tmp_path / "b" / "bifurcation.nc"), "bifurcation")
    tops = [a for ax in art.figure.axes for a in ax.child_axes]
    assert any(t.get_xlabel() == "pinion speed [rpm]" for t in tops)
    from geardyn.plot.common import rpm_per_omega

    ds = read_netcdf(tmp_path / "b" / "bifurcation.nc")
    w = ds["omega"].values
    assert rpm_per_omega(ds) * w[0] == pytest.approx(1500.0, rel=1e-9)  # the top axis reads the swept rpm
    assert rpm_per_omega(ds) * w[-1] == pytest.approx(3000.0, rel=1e-9)
    art = draw(read_netcdf(tmp_path / "s" / "basins.nc"), "basins")
    assert "2400 rpm" in art.axes[0].get_title()


def test_cells_of_a_large_even_grid_are_an_image_of_the_same_cells():
    """plot.common.cells: at IMAGE_CELLS cells on evenly spaced axes, an image spanning the cell edges and
    holding the values in place; a mesh of quadrilaterals on uneven axes or fewer cells."""
    from matplotlib.collections import QuadMesh
    from matplotlib.figure import Figure
    from matplotlib.image import AxesImage

    from geardyn.plot.common import IMAGE_CELLS, cells

    n = int(np.ceil(np.sqrt(IMAGE_CELLS)))
    x, y = np.linspace(0.5, 0.75, n), np.linspace(0.05, 0.3, n + 1)
    z = np.add.outer(np.arange(y.size), 10.0 * np.arange(x.size))
    ax = Figure().add_subplot()
    im = cells(ax, x, y, z, cmap="viridis")
    assert isinstance(im, AxesImage) and np.array_equal(im.get_array(), z)
    dx, dy = x[1] - x[0], y[1] - y[0]
    assert np.allclose(
        im.get_extent(), [x[0] - dx / 2, x[-1] + dx / 2, y[0] - dy / 2, y[-1] + dy / 2], rtol=0, atol=1e-12
    )
    edges = Figure().add_subplot().pcolormesh(x, y, z, shading="nearest").get_coordinates()  # the mesh's cells
    assert np.allclose(
        im.get_extent(), [edges[0, 0, 0], edges[0, -1, 0], edges[0, 0, 1], edges[-1, 0, 1]], rtol=0, atol=1e-12
    )
    uneven = np.r_[x[:-1], x[-1] + 0.5]
    assert isinstance(cells(Figure().add_subplot(), uneven, y, z), QuadMesh)
    assert isinstance(cells(Figure().add_subplot(), x[:3], y[:3], z[:3, :3]), QuadMesh)
