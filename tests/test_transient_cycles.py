"""``--transient Ncycles``: a transient given in reference mesh cycles, rounded up to whole forcing periods
ceil(N / P), P = ``model.period_multiple()``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from geardyn import GearModel
from geardyn.analysis.settle import cycles_to_periods, transient_cycles
from geardyn.cli.options import Inputs
from geardyn.errors import ModelError
from geardyn.systems import Body, Mesh, SystemDescription, assemble

ROOT = Path(__file__).resolve().parents[1]
GEARBOX = ROOT / "examples" / "gearbox" / "two_stage_helical.toml"


def _two_mesh(ratio2: float) -> SystemDescription:
    """Two meshes, the second at ``ratio2`` times the first's mesh frequency (as in test_systems)."""
    bodies = (
        Body("a", ("theta",), inertia=1.0),
        Body("b", ("theta",), inertia=2.0),
        Body("c", ("theta",), inertia=3.0),
    )
    m1 = Mesh("m1", ((("a", "theta"), 0.1), (("b", "theta"), -0.2)), 1e8, backlash=1e-4, kappa=(0.1,))
    m2 = Mesh("m2", ((("b", "theta"), 0.1), (("c", "theta"), -0.3)), 2e8, backlash=1e-4, ratio=ratio2)
    return SystemDescription(bodies=bodies, meshes=(m1, m2))


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "geardyn.cli", *args], capture_output=True, text=True, cwd=ROOT, timeout=900
    )


@pytest.mark.parametrize(("text", "cycles"), [("3000cycles", 3000), (" 7 Cycles ", 7), ("0cycles", 0)])
def test_cycles_text_is_parsed(text, cycles):
    assert transient_cycles(text) == cycles


@pytest.mark.parametrize("text", ["300", "auto", "AUTO"])
def test_periods_and_auto_are_not_cycles(text):
    assert transient_cycles(text) is None


def test_pair_cycles_are_forcing_periods():
    m = GearModel(omega=0.8)
    assert m.period_multiple() == 1
    assert [cycles_to_periods(c, m) for c in (0, 1, 3000)] == [0, 1, 3000]
    inp = Inputs({"transient": "3000cycles", "json_out": True})
    inp.model = lambda **_: m  # the run's model without files
    assert inp.transient() == 3000


def test_system_cycles_round_up_to_whole_forcing_periods():
    s = assemble(_two_mesh(47 / 23))
    assert s.period_multiple() == 23
    # ceil(N / 23): 23 -> 1, 24 -> 2, 46 -> 2, 47 -> 3, 3000 -> 131 (23 * 130 = 2990 < 3000 <= 3013)
    assert [cycles_to_periods(c, s) for c in (0, 1, 23, 24, 46, 47, 3000)] == [0, 1, 1, 2, 2, 3, 131]


def test_quasi_periodic_system_refuses_cycles():
    import math

    with pytest.raises(ModelError, match="incommensurate"):
        cycles_to_periods(10, assemble(_two_mesh(math.sqrt(2))))


@pytest.mark.parametrize("value", ["3000mc", "1.5cycles", "cycles", "10periods"])
def test_cli_bad_cycles_suffix_exits_2_in_one_line(value):
    r = _cli("simulate", "--omega", "0.8", "--transient", value)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "--transient" in r.stderr and "cycles" in r.stderr


def test_cli_pair_cycles_is_the_run_with_that_count_and_says_it_once():
    args = ["simulate", "--omega", "0.8", "--periods", "8"]
    said = _cli(*args, "--transient", "20cycles")
    assert said.returncode == 0, said.stderr
    assert said.stderr.count("transient: 20 reference mesh cycles = 20 forcing periods") == 1
    cyc = _cli(*args, "--json", "--transient", "20cycles")
    assert cyc.returncode == 0, cyc.stderr
    assert "reference mesh cycles" not in cyc.stderr  # not with --json
    fixed = _cli(*args, "--json", "--transient", "20")
    assert json.loads(cyc.stdout) == json.loads(fixed.stdout)


def test_cli_gearbox_64_cycles_is_one_forcing_period_bit_for_bit(tmp_path):
    """two_stage_helical.toml without its motor's order: stage 2 at 19/64 of stage 1, so P = 64 stage-1 mesh
    cycles per forcing period."""
    meshes = tmp_path / "meshes_only.toml"
    text = GEARBOX.read_text()
    meshes.write_text(text.replace('orders = [{ order = 2, amplitude = "30 N*m", phase = "0 deg" }]', ""))
    args = ["simulate", "--system", str(meshes), "--periods", "1", "--dtau", "0.2", "--json"]
    cyc = _cli(*args, "--transient", "64cycles")
    assert cyc.returncode == 0, cyc.stderr
    one = _cli(*args, "--transient", "1")
    assert one.returncode == 0, one.stderr
    assert cyc.stdout == one.stdout


def test_forcing_period_note_counts_cycles_and_skips_auto():
    """The gearbox's note on the RK4 steps of --transient + --periods takes Ncycles in forcing periods and leaves
    out auto (not yet known) instead of failing on it."""
    from geardyn.cli.system_input import _periods_given

    assert _periods_given({"transient": "65cycles", "periods": 1}, 64) == 3
    assert _periods_given({"transient": "auto", "periods": 1}, 64) == 0
    assert _periods_given({"transient": "5", "periods": 1}, 64) == 6
