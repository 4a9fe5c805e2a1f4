"""Run-up through a speed ramp: a slow ramp follows the steady response; the speed blocks are fine enough."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.analysis.runup import block_error, runup, steady_response
from geardyn.cli import app
from geardyn.errors import ModelError
from geardyn.model import GearModel

MODEL = GearModel()  # the paper's Table 1 values
# ramp rate dω/dτ = 0.1 / 10000 = 1e-5 over ω = 0.4 … 0.5, below the jump of the up sweep (ω ≈ 0.6)
W0, W1, T = 0.40, 0.50, 10000.0
TOL = 1e-2  # relative to the steady amplitude


@pytest.fixture(scope="module")
def slow():
    return runup(MODEL, W0, W1, T, max_blocks=30)


def test_slow_ramp_equals_the_quasi_static_response(slow):
    assert not slow.diverged and slow.ramp_rate == pytest.approx(1e-5)
    pick = np.arange(0, slow.omega.size, 6)
    qs = steady_response(MODEL, slow.omega[pick], periods=slow.cycles, transient=400)
    for k, i in enumerate(pick):
        a_qs = qs["up"]["order_amplitude"][k]
        assert abs(slow.order_amplitude[i, 0] - a_qs) <= TOL * a_qs, (slow.omega[i], slow.order_amplitude[i, 0], a_qs)
        assert abs(slow.amplitude[i] - qs["up"]["amplitude"][k]) <= TOL * qs["up"]["amplitude"][k]
        assert abs(slow.dynamic_factor[i] - qs["up"]["dynamic_factor"][k]) <= TOL * qs["up"]["dynamic_factor"][k]


def test_speed_blocks_against_a_reference_stepped_every_mesh_cycle(slow):
    ref = runup(MODEL, W0, W1, T, cycles_per_block=1)
    assert ref.cycles == 1 and ref.omega.size > 20 * slow.omega.size
    err = block_error(slow, ref)
    assert err["amplitude"] < 1e-3 and err["jump_shift_omega"] == 0.0
    # the blocks cover the ramp: speeds within it, mesh phase advanced by whole cycles per block
    assert W0 <= slow.omega.min() and slow.omega.max() <= W1 + 1e-12
    assert np.all(np.diff(slow.tau) > 0) and slow.tau[-1] == pytest.approx(T, rel=0.02)


def test_fast_ramp_lags_the_jump():
    # through the jump of the up sweep (between ω = 0.57 and 0.63): a fast ramp jumps later than a slow one
    slow = runup(MODEL, 0.5, 0.7, 40000.0, max_blocks=80)
    fast = runup(MODEL, 0.5, 0.7, 800.0, cycles_per_block=1)

    def jump(r):
        return r.omega[int(np.argmax(np.diff(r.order_amplitude[:, 0])))]

    assert jump(fast) > jump(slow) + 0.005


def test_bad_ramps_refused():
    with pytest.raises(ModelError, match="omega_stop: must differ"):
        runup(MODEL, 0.5, 0.5, 100.0)
    with pytest.raises(ModelError, match="duration: must be a finite number > 0"):
        runup(MODEL, 0.5, 0.6, -1.0)
    with pytest.raises(ModelError, match="mesh cycles, more than"):
        runup(MODEL, 0.5, 0.6, 1e12)


def test_cli_runup(tmp_path):
    r = CliRunner().invoke(
        app,
        [
            "runup",
            "--rpm-start",
            "1200",
            "--rpm-stop",
            "1500",
            "--duration",
            "0.5",
            "--num",
            "3",
            "--json",
            "--out",
            str(tmp_path),
        ],
    )
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert s["rpm"][0] == pytest.approx(1200, rel=0.01) and s["ramp_rate_rpm_per_s"] == pytest.approx(600, rel=1e-9)
    assert set(s["quasi_static"]) >= {"up", "down", "rpm"} and len(s["order_amplitude"]) == 3
    assert (tmp_path / "runup.png").is_file() and (tmp_path / "runup.nc").is_file()
    r = CliRunner().invoke(app, ["runup", "--rpm-start", "1200", "--rpm-stop", "1500"])
    assert r.exit_code == 2 and "duration" in r.output
