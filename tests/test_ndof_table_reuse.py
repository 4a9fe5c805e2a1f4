"""The N-DOF worker's tables of one forcing period (coefficients, orders' cosines, element groups) serve the next
point of a thread when its table inputs are the same bit for bit: a batch gives, point for point, the numbers of
each point run alone (the reference is the kernel on a batch of one, which tabulates once)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn.integrate import integrate_batch
from geardyn.model import IntegrationOptions
from geardyn.systems import load_system

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

OPTS = IntegrationOptions(transient=1, periods=2)


def _system(which, tmp_path):
    if which == "spur_healthy":  # 6 DOF, 256 harmonics: the dense step
        return load_system(ROOT / "examples/systems/spur_healthy.toml").with_param("omega", 1.0)
    from ndof_scaling import chain_toml

    return load_system(chain_toml(2, tmp_path / "chain.toml"))  # 12 DOF: the sparse step


def _steps(models):
    """One step count for every point (h ≤ 0.01 at the slowest): points then differ only where the test says."""
    return max(math.ceil(m.sampling_period / 0.01) for m in models)


def _same_as_alone(models, states, steps):
    batch = integrate_batch(models, states, OPTS, threads=1, steps=steps)
    assert np.all(batch.status == 0)  # ST_OK: bounded motion, so the comparison is of numbers
    for p, m in enumerate(models):
        one = integrate_batch([m], states[p : p + 1], OPTS, threads=1, steps=steps)
        for name in ("poincare", "end_state", "stats"):
            a = np.asarray(getattr(batch, name))[p]
            b = np.asarray(getattr(one, name))[0]
            assert a.tobytes() == b.tobytes(), (name, p)
    return batch


@pytest.mark.parametrize("which", ["spur_healthy", "chain"])
def test_points_of_one_model_give_the_numbers_of_each_point_alone(which, tmp_path):
    s = _system(which, tmp_path)
    states = np.array([s.initial_state(u0, v0) for u0, v0 in [(0.0, 0.0), (1.0, -0.5), (-1.5, 0.3), (0.5, 1.0)]])
    models = [s] * len(states)
    batch = _same_as_alone(models, states, _steps(models))
    # different initial states: different motions (the points were not one computation copied)
    assert len({np.asarray(batch.poincare)[p, 0].tobytes() for p in range(len(states))}) == len(states)


@pytest.mark.parametrize("which", ["spur_healthy", "chain"])
def test_alternating_omegas_tabulate_anew_at_every_point(which, tmp_path):
    """Two ω alternately with one step count N: consecutive points differ in ω (and T_f) only, so a table kept from
    the point before would give other numbers."""
    s = _system(which, tmp_path)
    w = s.omega
    models = [s.with_param("omega", x) for x in (w, 1.25 * w, w, 1.25 * w)]
    states = np.array([s.initial_state(u0, 0.0) for u0 in (0.0, 0.0, 0.5, 0.5)])
    batch = _same_as_alone(models, states, _steps(models))
    pc = np.asarray(batch.poincare)
    assert pc[0].tobytes() != pc[1].tobytes() and pc[2].tobytes() != pc[3].tobytes()
