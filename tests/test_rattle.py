"""Gear rattle (geardyn.analysis.rattle): impact detection against scipy's DOP853 with events, the measures,
the reduction of a two-gear system file to its pair against the closed-form equivalent mass, the map and the
command."""

from __future__ import annotations

import json
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn.analysis.rattle import crossings, pair_of_system, rattle, rattle_map
from geardyn.errors import ModelError
from geardyn.model import GearModel, IntegrationOptions

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "gearbox" / "rattle_idle.toml"

#: A loose pair that rattles on both flanks: light load, two torque orders of the mesh frequency.
RATTLING = GearModel(
    omega=0.5,
    xi0=0.02,
    xi=(),
    kappa=(0.1,),
    eps=(),
    fp=0.002,
    D=1.0,
    torque_orders=((Fraction(1, 4), 0.02, 0.0), (Fraction(3, 4), 0.015, 1.0)),
)


def _dop853_events(model: GearModel, x0, t_end: float):
    """Entries into and exits from contact by DOP853 with events on u = ±D (an independent reference)."""

    def drive(t, y):
        return y[0] - model.D

    def back(t, y):
        return y[0] + model.D

    sol = solve_ivp(
        model.rhs, (0.0, t_end), x0, method="DOP853", rtol=1e-12, atol=1e-12, events=(drive, back), max_step=0.5
    )
    assert sol.status == 0
    out = []
    for flank, ts, ys in ((1, sol.t_events[0], sol.y_events[0]), (-1, sol.t_events[1], sol.y_events[1])):
        for t, y in zip(ts, ys):
            entering = (y[1] > 0) if flank > 0 else (y[1] < 0)
            out.append((t, flank, y[1], entering))
    return sorted(out)


def test_impacts_match_dop853_with_events():
    res = rattle(RATTLING, IntegrationOptions(dtau=0.005, transient=40, periods=3, accurate=True))
    assert res.regime() == "double-sided rattle"
    ref = _dop853_events(RATTLING, (res.u[0], res.v[0]), float(res.tau[-1]))
    e = res.events
    for entering, (t, f, v) in (
        (True, ("time", "flank", "velocity")),
        (False, ("rebound_time", "rebound_flank", "rebound_velocity")),
    ):
        want = [r for r in ref if r[3] == entering]
        assert len(want) == e[t].size >= 3
        assert np.array_equal(np.array([r[1] for r in want]), e[f])
        assert np.max(np.abs(np.array([r[0] for r in want]) - e[t])) < 1e-6
        assert np.max(np.abs(np.array([r[2] for r in want]) - e[v])) < 1e-6
    # the measures from those events
    js = res.to_json()
    n_drive = int(np.sum(e["flank"] == 1))
    assert js["flanks"]["drive"]["impacts_per_cycle"] == n_drive / 3
    assert js["flanks"]["back"]["impact_velocity_max"] == pytest.approx(np.max(np.abs(e["velocity"][e["flank"] < 0])))
    loss = 0.5 * (np.sum(e["velocity"] ** 2) - np.sum(e["rebound_velocity"] ** 2)) / 3
    assert js["rattle_index"] == pytest.approx(loss, rel=1e-12) and loss > 0  # damping takes energy in contact


def test_crossings_of_a_known_signal():
    """u = 2 sin τ with D = 1: the drive flank entered at τ = π/6 + 2πk with u' = √3, left at 5π/6 + 2πk;
    the back flank entered at 7π/6 + 2πk with u' = −√3."""
    tau = np.linspace(0.0, 4 * math.pi, 401)
    ev = crossings(tau, 2 * np.sin(tau), 2 * np.cos(tau), 1.0)
    want = np.sort(np.concatenate([np.pi / 6 + 2 * np.pi * np.arange(2), 7 * np.pi / 6 + 2 * np.pi * np.arange(2)]))
    assert np.allclose(ev["time"], want, atol=1e-6)
    assert np.array_equal(ev["flank"], [1, -1, 1, -1])
    assert np.allclose(ev["velocity"], [math.sqrt(3), -math.sqrt(3)] * 2, atol=1e-5)
    assert np.allclose(
        ev["rebound_time"],
        np.sort(np.concatenate([5 * np.pi / 6 + 2 * np.pi * np.arange(2), 11 * np.pi / 6 + 2 * np.pi * np.arange(2)])),
        atol=1e-6,
    )


def test_no_impact_when_the_mesh_never_separates():
    loaded = RATTLING.replace(fp=1.0, kappa=(), phi_k=())
    res = rattle(loaded, IntegrationOptions(dtau=0.01, transient=60, periods=2, accurate=True))
    assert res.regime() == "no impact" and res.rattle_index() == 0.0
    assert res.to_json()["flanks"]["drive"]["impacts_per_cycle"] == 0.0


def test_rattle_needs_backlash_and_a_pair():
    with pytest.raises(ModelError, match="D"):
        rattle(RATTLING.replace(D=0.0))


def test_the_example_reduces_to_its_pair():
    """The two-gear file's pair against the equivalent-mass closed form: m_e = 1/(R1²/I1 + R2²/I2), the
    relative coordinate δ = R1 θ1 − R2 θ2 forced by m_e (R1 T1/I1 − R2 T2/I2)."""
    from geardyn.systems import load_system

    s = load_system(EXAMPLE)
    m = pair_of_system(s)
    I1, I2, R1, R2 = 0.01, 4.9e-4, 0.03406, 0.03876  # the file's inertias and base radii
    k, b_c, T1, T2, dT = 210e6, 0.05e-3, 0.04394, -0.05, 5.0
    me = 1.0 / (R1**2 / I1 + R2**2 / I2)
    wn = math.sqrt(k / me)
    assert m.omega == pytest.approx(2 * math.pi * 29 * 800 / 60 / wn, rel=1e-9)
    assert m.fp == pytest.approx(me * (R1 * T1 / I1 - R2 * T2 / I2) / (k * b_c), rel=1e-9)
    ((q, a, ph),) = m.torque_orders
    assert q == Fraction(2, 29) and ph == 0.0  # the engine's 2nd order of the input gear's speed (29 teeth)
    assert a == pytest.approx(me * R1 * dT / I1 / (k * b_c), rel=1e-9)
    assert m.D == 1.0 and m.xi0 == pytest.approx(0.02, rel=1e-12)
    assert s.period_multiple() == 29


def test_orders_in_a_system_file_change_the_response(tmp_path):
    from geardyn.systems import load_system

    opts = IntegrationOptions(dtau=0.05, transient=8, periods=2, accurate=True)
    with_orders = rattle(pair_of_system(load_system(EXAMPLE)), opts)
    text = EXAMPLE.read_text().replace('orders = [{ order = 2, amplitude = "5 N*m", phase = "0 deg" }]', "")
    p = tmp_path / "no_orders.toml"
    p.write_text(text)
    quiet = pair_of_system(load_system(p))
    assert quiet.torque_orders == ()
    with pytest.raises(ModelError, match="torque_orders"):  # no order, nothing drives the rattle map
        rattle_map(quiet, [quiet.omega], [1.0], opts)
    assert with_orders.regime() != "no impact"
    # without the order: pressed onto the drive flank by the drag alone (the same time span: its forcing period
    # is one mesh period, the order's 29)
    still = rattle(quiet, opts.replace(transient=8 * 29, periods=2 * 29))
    assert still.regime() == "no impact" and still.u.min() > quiet.D


def test_rattle_map_dataset_and_figure(tmp_path):
    from geardyn.plot import save_figures

    opts = IntegrationOptions(dtau=0.01, transient=20, periods=2, accurate=True)
    ds = rattle_map(RATTLING, [0.4, 0.5], [0.5, 1.0, 1.5], opts)
    assert ds.attrs["geardyn_kind"] == "rattle_map"
    assert ds["rattle_index"].dims == ("omega", "amplitude_scale") and ds["rattle_index"].shape == (2, 3)
    one = rattle(RATTLING.replace(omega=0.5), opts)
    assert ds["rattle_index"].sel(omega=0.5, amplitude_scale=1.0).item() == pytest.approx(one.rattle_index(), rel=1e-12)
    assert ds["impacts_drive"].attrs["long_name"]
    files = save_figures(ds, tmp_path)
    assert [Path(f).name for f in files] == ["rattle_map.png"]


# ---------------------------------------------------------------- the command
def test_cli_rattle_example(tmp_path):
    from cli_run import run_cli

    code, out, err = run_cli(
        [
            "rattle",
            "--system",
            EXAMPLE,
            "--json",
            "--transient",
            "10",
            "--periods",
            "3",
            "--dtau",
            "0.05",
            "--map-points",
            "2",
            "--scale-points",
            "2",
            "--rpm-start",
            "700",
            "--rpm-stop",
            "900",
            "--out",
            tmp_path,
        ]
    )
    assert code == 0, err
    s = json.loads(out)
    for key in ("impacts_per_cycle", "rattle_index", "rattle_index_J", "flanks", "rpm"):
        assert key in s
    assert s["flanks"]["drive"]["impacts_per_cycle"] > 0 and s["flanks"]["drive"]["impact_velocity_max_m_s"] > 0
    assert s["rpm"] == pytest.approx(800.0, rel=1e-9)
    names = sorted(Path(f).name for f in s["files"])
    assert names == ["rattle.nc", "rattle.png", "rattle_map.nc", "rattle_map.png"]
    assert s["map"]["rpm"] == pytest.approx([700.0, 900.0], rel=1e-9)
    redraw = tmp_path / "redraw"
    code, out, err = run_cli(["plot", tmp_path / "rattle_map.nc", "--out", redraw, "--json"])
    assert code == 0, err
    assert sorted(p.name for p in redraw.iterdir()) == ["rattle_map.png"]


@pytest.mark.parametrize(
    "args, key",
    [
        (["--omega", "1"], "torque_orders"),  # the default pair has no order
        (["--torque-order", "1/2:0.1", "--D", "0"], "D"),
        (["--torque-order", "1/2:0.1", "--map-points", "2", "--scale-max", "-1"], "scale_max"),
    ],
)
def test_cli_rattle_bad_input_exits_2(args, key):
    from cli_run import run_cli

    code, out, err = run_cli(["rattle", "--json", "--transient", "1", "--periods", "1", *args])
    assert code == 2, (out, err)
    assert key in err and len(err.strip().splitlines()) == 1


def test_system_orders_run_beyond_the_pair_and_bad_ones_are_refused(tmp_path):
    """A system with orders and a bearing (no pair of it) runs through the mesh-vector kernel; a bad order is
    refused in one line."""
    from cli_run import run_cli

    text = EXAMPLE.read_text() + '\n[[connection]]\nname = "brg"\nbody = "loose_gear"\nktheta = "1e3 N*m/rad"\n'
    p = tmp_path / "bearing.toml"
    p.write_text(text)
    code, out, err = run_cli(["simulate", "--system", p, "--json", "--periods", "1", "--transient", "0"])
    assert code == 0, err
    assert "forcing period: 29 cycles" in err and "order at 2/29" in err
    bad = EXAMPLE.read_text().replace("order = 2,", "order = -2,")
    p.write_text(bad)
    code, out, err = run_cli(["rattle", "--system", p, "--json"])
    assert code == 2 and "orders" in err and len(err.strip().splitlines()) == 1
