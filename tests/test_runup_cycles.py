"""Run-up with an excitation of P > 1 mesh cycles: blocks of whole forcing periods, mesh orders tracked.

Exact theory: a one-cycle series written over 3 cycles (harmonic j of ω → harmonic 3j of ω/3) is the same
equation, and with blocks of whole forcing periods, the settling a whole number of them and the one-cycle step, the
run-up integrates the same steps: it equals the one-cycle model's run-up to rounding (amplified only where the
response is unstable: past the period doubling at ω = 0.784 of the paper's pair, so the ramps here stop before it).
"""

import numpy as np
import pytest

from geardyn.analysis.runup import runup, steady_response
from geardyn.errors import ModelError
from geardyn.model import GearModel
from geardyn.tooth import Crack, mesh_stiffness, pair_geometry, pair_model


def repeated(m: GearModel, P: int) -> GearModel:
    """``m`` with its series written over P mesh cycles (harmonic j of ω → harmonic P·j of ω/P)."""

    def z(t):
        return tuple(x for v in t for x in (0.0,) * (P - 1) + (v,))

    return m.replace(
        xi=z(m.xi), phi_c=z(m.phi_c), kappa=z(m.kappa), phi_k=z(m.phi_k), eps=z(m.eps), phi_e=z(m.phi_e), cycles=P
    )


@pytest.mark.parametrize("accurate", [False, True])
def test_three_cycle_series_runup_equals_the_one_cycle_model(accurate):
    # through the jump up at ω ≈ 0.636 (half peak-to-peak 0.25 → 1.15), stopping before the period doubling
    m1 = GearModel()
    kw = dict(cycles_per_block=3, settle=30, accurate=accurate)
    r1 = runup(m1, 0.5, 0.75, 1500.0, **kw)
    r3 = runup(repeated(m1, 3), 0.5, 0.75, 1500.0, **kw)
    assert r3.cycles == 3 and r3.options.periods == 1 and r1.options.periods == 3
    np.testing.assert_array_equal(r3.omega, r1.omega)
    assert r1.amplitude.max() > 1.0 and r1.amplitude.min() < 0.3  # the jump is in the ramp
    np.testing.assert_allclose(r3.amplitude, r1.amplitude, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r3.order_amplitude, r1.order_amplitude, rtol=0, atol=1e-12)
    np.testing.assert_allclose(r3.dynamic_factor, r1.dynamic_factor, rtol=0, atol=1e-11)
    # the spectrum in orders j/3: the mesh orders are the tracked ones
    assert r1.spectrum is None and r3.spectrum.shape == (r3.omega.size, 11)
    np.testing.assert_allclose(r3.spectrum_orders[2::3], [1, 2, 3], rtol=1e-15)
    np.testing.assert_allclose(r3.spectrum[:, 2::3], r3.order_amplitude, rtol=0, atol=1e-12)


def test_blocks_are_whole_forcing_periods():
    m3 = repeated(GearModel(), 3)
    with pytest.raises(ModelError, match="multiple of the excitation's 3"):
        runup(m3, 0.5, 0.6, 500.0, cycles_per_block=4)
    r = runup(m3, 0.5, 0.6, 500.0, max_blocks=40, settle=3)  # default: ~40 blocks, rounded up to 3 cycles
    assert r.cycles % 3 == 0 and r.cycles >= 3
    ds = r.to_dataset()
    assert ds.attrs["excitation_cycles"] == 3 and ds["spectrum"].dims == ("block", "spectrum_order")
    js = r.to_json()
    assert js["excitation_cycles"] == 3 and len(js["spectrum"]) == 11 and js["spectrum_orders"][2] == 1.0
    assert "spectrum" not in runup(GearModel(), 0.5, 0.6, 500.0, settle=3).to_json()


def test_steady_response_counts_mesh_periods():
    m1 = GearModel()
    w = [0.55, 0.7]
    a = steady_response(m1, w, periods=6, transient=60)
    b = steady_response(repeated(m1, 3), w, periods=6, transient=60)
    for lab in ("up", "down"):
        np.testing.assert_allclose(b[lab]["amplitude"], a[lab]["amplitude"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(b[lab]["order_amplitude"], a[lab]["order_amplitude"], rtol=0, atol=1e-12)


def test_cracked_tooth_runup_shows_shaft_order_sidebands():
    # a 75 % root crack on pinion tooth 0 (20 teeth; a depth is a share of the half-thickness where the crack starts,
    # a milder crack at one depth than the section model's, so the test takes a deeper one): the excitation repeats
    # every revolution, P = 20; beside the healthy pair's series written over the same 20 cycles, the sidebands
    # 1 ± 1/20, 1 ± 2/20 of mesh order 1 rise from the ramp's leakage to a share of the mesh order's amplitude
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    crack, _ = pair_model(mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, 0.75)], points=16), 1000.0, harmonics=64)
    healthy, _ = pair_model(mesh_stiffness(geo, 100.0, points=16), 1000.0)
    healthy = repeated(healthy, 20)
    assert crack.cycles == healthy.cycles == 20
    kw = dict(cycles_per_block=20, settle=200, orders=2, dtau=0.05)
    rc = runup(crack, 0.5, 0.7, 4000.0, **kw)
    rh = runup(healthy, 0.5, 0.7, 4000.0, **kw)
    assert not rc.diverged and rc.omega.size > 10
    o = rc.spectrum_orders
    side = [int(np.argmin(np.abs(o - x))) for x in (0.9, 0.95, 1.05, 1.1)]
    mesh1 = int(np.argmin(np.abs(o - 1.0)))
    np.testing.assert_allclose(rc.spectrum[:, mesh1], rc.order_amplitude[:, 0], rtol=1e-9)
    sc = rc.spectrum[:, side].sum(axis=1)
    sh = rh.spectrum[:, side].sum(axis=1)
    # the healthy pair's leakage is largest in the first blocks (the ramp's start); the crack's sidebands are above
    # it in every block and ten times it in most
    assert np.all(sc > 2 * sh) and np.median(sc / sh) > 10
    assert np.median(sc / rc.order_amplitude[:, 0]) > 0.05


def test_cli_runup_with_a_three_cycle_excitation(tmp_path):
    import json

    from typer.testing import CliRunner

    from geardyn.cli import app

    th = 2 * np.pi * np.arange(16) / 16
    k = 2e9 * (1 + 0.2 * np.cos(th) + 0.05 * np.cos(2 * th + 0.3))
    e = 25e-6 * np.cos(th)
    one, three = tmp_path / "one.json", tmp_path / "three.json"
    one.write_text(json.dumps({"cycles": 1, "stiffness_N_per_m": list(k), "ste_m": list(e)}))
    three.write_text(json.dumps({"cycles": 3, "stiffness_N_per_m": list(np.tile(k, 3)), "ste_m": list(np.tile(e, 3))}))
    args = [
        "runup",
        "--omega-start",
        "0.5",
        "--omega-stop",
        "0.7",
        "--tau-duration",
        "1000",
        "--cycles-per-block",
        "3",
        "--settle",
        "30",
        "--num",
        "0",
        "--json",
    ]
    ra = CliRunner().invoke(app, [*args, "--excitation", str(one)])
    rb = CliRunner().invoke(app, [*args, "--excitation", str(three), "--out", str(tmp_path / "o")])
    assert ra.exit_code == 0 and rb.exit_code == 0, (ra.output, rb.output)
    a, b = json.loads(ra.stdout), json.loads(rb.stdout)
    assert b["excitation_cycles"] == 3 and b["cycles_per_block"] == 3 and b["rpm"] == a["rpm"]
    # the tables' series agree to rounding (a DFT of 16 and of 48 points)
    np.testing.assert_allclose(b["amplitude"], a["amplitude"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(b["order_amplitude"], a["order_amplitude"], rtol=0, atol=1e-9)
    assert (tmp_path / "o" / "runup.nc").is_file() and (tmp_path / "o" / "runup.png").is_file()
    r = CliRunner().invoke(app, [*args[:-1], "--excitation", str(three), "--cycles-per-block", "4"])
    assert r.exit_code != 0 and "multiple of the excitation's 3" in r.output


def test_the_runup_figure_maps_every_order_of_a_multi_cycle_excitation():
    # the top panel of a P = 3 run-up is the spectrum over the orders j/3 (log colours), the one-cycle one the
    # mesh orders only
    from matplotlib.collections import QuadMesh
    from matplotlib.colors import LogNorm

    from geardyn.plot.runup import runup_figure

    r3 = runup(repeated(GearModel(), 3), 0.5, 0.6, 500.0, max_blocks=12, settle=3)
    fig3 = runup_figure(r3.to_dataset()).figure
    top = fig3.axes[0]
    quad = [c for c in top.collections if isinstance(c, QuadMesh)][0]
    assert isinstance(quad.norm, LogNorm)
    lo, hi = top.get_ylim()
    assert lo < 1 / 3 and hi > 3.5  # orders 1/3 … 11/3 drawn
    assert "j/3" in top.get_ylabel()
    r1 = runup(GearModel(), 0.5, 0.6, 500.0, max_blocks=12, settle=3)
    top1 = runup_figure(r1.to_dataset()).figure.axes[0]
    quad1 = [c for c in top1.collections if isinstance(c, QuadMesh)][0]
    assert not isinstance(quad1.norm, LogNorm) and top1.get_ylabel() == "mesh order"
