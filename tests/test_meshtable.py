"""The nodes of a mesh table evaluated as given (geardyn.meshtable), against hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.meshtable import check_table, kernel_table, table_values
from geardyn.model import ModelError


def test_collinear_nodes_are_not_breakpoints():
    # k: 1 at 0, 1.5 at 0.25 and 2 at 0.5 (one straight line), jump to 0.5 at 0.5, back to 1 at 1 ≡ 0
    rows = kernel_table(((0.0, 0.25, 0.5, 0.5), (1.0, 1.5, 2.0, 0.5), ()), 1)
    assert rows.shape == (3, 7)  # nodes 0 and 0.5, and node 0 again one period on
    assert np.allclose(rows[:, 0], [0.0, math.pi, 2 * math.pi])
    assert np.allclose(rows[0, 1:3], [1.0, 1.0]) and np.allclose(rows[1, 1:3], [2.0, 0.5])
    assert np.allclose(rows[:2, 5], [1.0 / math.pi, 0.5 / math.pi])  # slopes per radian of θ
    constant = kernel_table(((0.0, 0.5), (1.0, 1.0), (0.2, 0.2)), 1)
    assert constant.shape == (2, 7) and np.all(constant[0, 5:] == 0.0)


def test_values_right_continuous_and_periodic():
    table = ((0.5, 1.0, 1.0, 1.5), (2.0, 1.0, 3.0, 2.5), (0.0, 0.1, 0.3, 0.0)), 2
    th = 2 * math.pi * np.array([0.0, 0.25, 0.5, 1.0, 1.25, 1.75]) / 2  # mesh cycles → forcing phase (P = 2)
    K, e = table_values(*table, th)
    # before the first node (0.5): the wrap segment from 1.5 (2.5) to 2.5 ≡ 0.5 (2.0); slope −0.5 per cycle
    assert np.allclose(K, [2.25, 2.125, 2.0, 3.0, 2.75, 2.375])
    assert np.allclose(e, [0.0, 0.0, 0.0, 0.3, 0.15, 0.0])
    assert np.allclose(table_values(*table, th + 2 * math.pi)[0], K)


@pytest.mark.parametrize(
    "table, match",
    [
        (((0.0, 0.5, 0.5, 0.5), (1.0,) * 4, ()), "at most twice"),
        (((0.0, 0.6, 0.5), (1.0,) * 3, ()), "non-decreasing"),
        (((0.0, 1.0), (1.0, 1.0), ()), "non-decreasing"),
        (((0.0, 0.5), (1.0, 0.0), ()), "> 0"),
        (((0.0, 0.5), (1.0, 1.0), (0.0,)), "one of each"),
    ],
)
def test_refused(table, match):
    with pytest.raises(ModelError, match=match):
        check_table(table, 1)
