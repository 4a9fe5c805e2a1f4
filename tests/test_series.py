"""The mesh coefficients' Fourier series at many angles (geardyn.series), against a plain per-sample sum."""

from __future__ import annotations

import math

import numpy as np

from geardyn.series import BLOCK, series_values


def _plain(c, th, i, ratio, derivative):
    """x_i(θ) or dx_i/dθ summed in plain Python floats with math.cos/math.sin."""
    s = 0.0 if derivative else c[i, 0, 0]
    for j in range(1, c.shape[1]):
        a, b = c[i, j]
        w = j * ratio
        s += (
            w * (b * math.cos(w * th) - a * math.sin(w * th))
            if derivative
            else a * math.cos(w * th) + b * math.sin(w * th)
        )
    return s


def test_values_and_derivatives_equal_a_plain_sum_across_blocks():
    rng = np.random.default_rng(3)
    c = rng.normal(size=(3, 40, 2)) / np.arange(1, 41)[None, :, None]
    th = rng.uniform(-50.0, 400.0, 2 * BLOCK + 17)  # two whole blocks and a short one
    for ratio in (1.0, 0.35):
        x0, x2, d0, d2 = series_values(c, th, (0, 2), ratio=ratio, derivative=True)
        for k in rng.choice(th.size, 60, replace=False).tolist() + [0, BLOCK - 1, BLOCK, th.size - 1]:
            scale = np.sum(np.abs(c))  # a bound on each series
            assert abs(x0[k] - _plain(c, th[k], 0, ratio, False)) < 1e-14 * scale
            assert abs(x2[k] - _plain(c, th[k], 2, ratio, False)) < 1e-14 * scale
            assert abs(d0[k] - _plain(c, th[k], 0, ratio, True)) < 1e-14 * scale * 40
            assert abs(d2[k] - _plain(c, th[k], 2, ratio, True)) < 1e-14 * scale * 40


def test_a_value_does_not_depend_on_its_block_or_the_shape():
    rng = np.random.default_rng(4)
    c = rng.normal(size=(2, 12, 2))
    th = rng.uniform(0.0, 100.0, BLOCK + 5)
    (whole,) = series_values(c, th, (1,))
    alone = np.array([series_values(c, t, (1,))[0] for t in th[BLOCK - 3 : BLOCK + 5]])
    assert np.array_equal(whole[BLOCK - 3 : BLOCK + 5], alone)
    (grid,) = series_values(c, th[:12].reshape(3, 4), (1,))
    assert grid.shape == (3, 4) and np.array_equal(grid.reshape(-1), whole[:12])


def test_constant_series_and_scalar_angle():
    c = np.array([[[2.5, 0.0]], [[-1.0, 0.0]]])  # harmonic 0 only
    x, dx = series_values(c, 1.7, (0,), derivative=True)
    assert x.shape == () and float(x) == 2.5 and float(dx) == 0.0
