"""Each shaft's signal is resampled for its own mesh harmonics: a healthy wheel with many more teeth than
its pinion keeps healthy indicators, and a pinion crack shows in the pinion's."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from geardyn.signature.run import per_rev

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("z, top", [(19, 0.0), (48, 0.0), (48, 3.37), (48, 32.0), (97, 1.0)])
def test_at_least_16_points_per_period_of_every_mesh_harmonic(z, top):
    n = per_rev(z, top)
    assert n & (n - 1) == 0
    assert n / z >= 16 and n / (z * max(top, 1.0)) >= 16
    assert n < 2 * 16 * z * max(top, 1.0)  # the next power of 2, no more


@pytest.mark.slow
def test_crack_depth_sweep_of_a_19_48_pair():
    out = subprocess.run(
        [sys.executable, "-m", "geardyn.cli", "signature", str(ROOT / "examples/tooth_19_48.toml")]
        + ["--rpm", "3000", "--sweep-depths", "0,0.25,0.5", "--json"],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    ind = json.loads(out.stdout)["indicators"]
    fm4 = ind["fm4"]["pinion"]
    assert 2.0 <= fm4[0] <= 4.5
    assert fm4[1] > 2 * fm4[0] and fm4[2] > 2 * fm4[0]
    for k in ("na4", "energy_ratio"):
        v = ind[k]["pinion"]
        assert v[0] < v[1] < v[2]
    # the healthy wheel: its mesh harmonics are not folded into its difference signal
    assert ind["energy_ratio"]["wheel"][0] < 0.1
    assert 2.0 <= ind["fm4"]["wheel"][0] <= 4.5
