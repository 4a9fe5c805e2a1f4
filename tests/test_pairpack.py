"""The pair's kernel arrays (:mod:`geardyn.pairpack`): the stiffness bound and the step count against closed forms.

``pack_points`` against ``pack_models`` of the same models, and their shared refusals, are in
``test_streaming.py``; the packed orders in ``test_orders.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.errors import ModelError
from geardyn.pairpack import pack_models, steps_per_period, stiffness_minimum


def _dense_minimum(kappa, phi, n=200_001):
    theta = np.linspace(0.0, 2.0 * np.pi, n)
    j = np.arange(1, len(kappa) + 1)[:, None]
    return float((1.0 + np.sum(np.asarray(kappa)[:, None] * np.cos(j * theta + np.asarray(phi)[:, None]), 0)).min())


@pytest.mark.parametrize("kappa, phi", [(0.3, 0.0), (0.7, 1.1), (-0.45, -2.0)])
def test_one_harmonic_bound_is_within_the_margin_below_one_minus_kappa(kappa, phi):
    # 1 + κ cos(θ + φ) has the exact minimum 1 − |κ|; the bound subtracts at most 0.02
    got = stiffness_minimum([kappa], [phi])
    assert 1.0 - abs(kappa) - 0.02 <= got <= 1.0 - abs(kappa)


@pytest.mark.parametrize(
    "kappa, phi",
    [([0.4, 0.3, 0.2], [0.0, 0.5, -1.0]), ([0.1] * 12, np.linspace(0, 3, 12).tolist()), ([0.5, 0.49], [0.0, np.pi])],
)
def test_several_harmonics_bound_is_below_a_dense_sampling_and_close_to_it(kappa, phi):
    dense = _dense_minimum(kappa, phi)
    got = stiffness_minimum(kappa, phi)
    assert got <= dense
    assert dense - got <= 0.02 + 1e-9


def test_no_harmonic_is_the_constant_stiffness():
    assert stiffness_minimum([], []) == 1.0


@pytest.mark.parametrize("omega, dtau", [(1.0, 0.02), (0.37, 0.05), (2.5, 0.013)])
def test_steps_per_period_is_the_fewest_steps_not_longer_than_dtau(omega, dtau):
    n = int(steps_per_period(omega, dtau))
    period = 2.0 * math.pi / omega
    assert period / n <= dtau < period / (n - 1)


def test_steps_per_period_is_per_frequency():
    got = steps_per_period(np.array([0.5, 1.0, 2.0]), 0.1)
    assert got.dtype == np.int64
    assert got.tolist() == [math.ceil(2 * math.pi / w / 0.1) for w in (0.5, 1.0, 2.0)]


def test_packing_no_model_is_refused():
    with pytest.raises(ModelError, match="empty parameter grid"):
        pack_models([])
