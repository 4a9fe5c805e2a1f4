"""Every fault tends to the healthy tooth as its size tends to 0 (crack depth, spall size, wear depth,
broken fraction): mean and minimum mesh stiffness equal the healthy pair's to 1e-9, and a small fault
moves them by a small amount (no step at 0)."""

import numpy as np
import pytest

from geardyn.tooth.faults import Broken, Crack, Spall, Wear
from geardyn.tooth.geometry import pair_geometry
from geardyn.tooth.mesh import mesh_stiffness

GEO = pair_geometry(19, 48, 0.0032, face_width=0.016)
TORQUE = 100.0


def _stats(faults, cycles=19):
    ms = mesh_stiffness(GEO, TORQUE, faults=faults, cycles=cycles, points=64)
    return ms.mean_stiffness, float(ms.stiffness.min()), float(ms.ste.mean())


HEALTHY = _stats([])

ZERO = {
    "crack": [Crack(0, 0, 0.0)],
    "partial crack": [Crack(0, 0, 0.0, length=0.5)],
    "spall length": [Spall(0, 0, 0.5, 0.0, 0.005)],
    "spall width": [Spall(0, 0, 0.5, 0.002, 0.0)],
    "spall depth": [Spall(0, 0, 0.5, 0.002, 0.005, depth=0.0)],
    "wear": [Wear(0, 0.0)],
    "wear sliding on one tooth": [Wear(1, 0.0, "sliding", tooth=3)],
    "broken": [Broken(0, 0, 1.0)],
}


@pytest.mark.parametrize("kind", list(ZERO))
def test_fault_of_size_zero_is_the_healthy_pair(kind):
    mean, low, ste = _stats(ZERO[kind])
    assert mean == pytest.approx(HEALTHY[0], rel=1e-9)
    assert low == pytest.approx(HEALTHY[1], rel=1e-9)
    assert ste == pytest.approx(HEALTHY[2], rel=1e-9)


SMALL = {
    "crack": lambda e: [Crack(0, 0, 0.5 * e)],
    "spall": lambda e: [Spall(0, 0, 0.5, 0.004 * e, 0.016 * e, depth=50e-6 * e)],
    "wear": lambda e: [Wear(0, 20e-6 * e, "sliding")],
    "broken": lambda e: [Broken(0, 0, 1.0 - 0.2 * e)],
}


@pytest.mark.parametrize("kind", list(SMALL))
def test_small_faults_move_the_stiffness_and_ste_continuously(kind):
    # the change of mean stiffness and STE at size 1e-3 is at most 1e-2 of the change at size 1 (no step at 0)
    big = np.array(_stats(SMALL[kind](1.0))) - np.array(HEALTHY)
    small = np.array(_stats(SMALL[kind](1e-3))) - np.array(HEALTHY)
    assert np.any(np.abs(big) > 0)
    for i in (0, 2):
        assert abs(small[i]) <= 1e-2 * abs(big[i]) + 1e-9 * abs(HEALTHY[i])
