"""Condition indicators against closed forms; order tracking, TSA and the signals of a known record."""

import math

import numpy as np
import pytest

from geardyn.signature import (
    Acquisition,
    crest_factor,
    energy_ratio,
    fm0,
    fm4,
    kurtosis,
    m6a,
    m8a,
    na4,
    order_spectrum,
    pulse_times,
    rms,
    sideband_level,
    split_tsa,
    tsa,
)

N = 4096
SINE = np.sin(2 * np.pi * 8 * np.arange(N) / N)


def test_indicators_of_a_sine_are_their_closed_forms():
    assert rms(SINE) == pytest.approx(1 / math.sqrt(2), rel=1e-12)
    assert crest_factor(SINE) == pytest.approx(math.sqrt(2), rel=1e-12)
    assert kurtosis(SINE) == pytest.approx(1.5, rel=1e-12)  # E sin^4 / (E sin^2)^2 = (3/8)/(1/4)
    assert m6a(SINE) == pytest.approx(2.5, rel=1e-12)  # (5/16)/(1/8)
    assert m8a(SINE) == pytest.approx(35 / 8, rel=1e-12)  # (35/128)/(1/16)
    assert fm4(SINE) == kurtosis(SINE) and na4(SINE) == kurtosis(SINE)


def test_indicators_of_gaussian_noise():
    x = np.random.default_rng(3).normal(size=400_000)
    assert kurtosis(x) == pytest.approx(3.0, abs=0.03)
    assert m6a(x) == pytest.approx(15.0, rel=0.03)  # 15 sigma^6
    assert m8a(x) == pytest.approx(105.0, rel=0.08)  # 105 sigma^8


def test_na4_normalises_by_the_average_variance_of_the_records():
    r1, r2 = SINE, 2 * SINE
    # variance of r2 = 4 * 0.5 = 2, average with r1's 0.5 is 1.25: NA4 = E r2^4 / 1.25^2 = (16 * 3/8) / 1.5625
    assert na4(r2, [r1]) == pytest.approx(6.0 / 1.5625, rel=1e-12)


def _record(signal, rpm=600.0, fs=20_000.0, revs=8):
    t = np.arange(int(revs * 60 / rpm * fs)) / fs
    phi = 2 * np.pi * rpm / 60 * t
    wrapped = np.mod(phi + np.pi, 2 * np.pi) - np.pi
    sigma = 4 * 2 * np.pi * rpm / 60 / fs
    return Acquisition(
        time=t, accel=signal(phi), tach=5 * np.exp(-0.5 * (wrapped / sigma) ** 2), fs=fs, rpm=rpm, z1=20, z2=40
    )


def test_order_tracking_tsa_and_the_split_signals():
    z = 20
    # mesh order 20 (amplitude 1), sideband 21 (0.1), shaft order 1 (0.3) and an order 7.5 that the TSA averages out
    acq = _record(lambda p: np.cos(z * p) + 0.1 * np.cos((z + 1) * p + 0.4) + 0.3 * np.cos(p) + 0.2 * np.cos(7.5 * p))
    tp = pulse_times(acq.tach, acq.fs)
    np.testing.assert_allclose(np.diff(tp), 0.1, rtol=1e-6)
    assert tp.size == 7  # the pulses at 0 and at the end of the record are cut: 6 whole revolutions
    orders, amp = order_spectrum(acq, 256)
    for o, a in ((20, 1.0), (21, 0.1), (1, 0.3), (7.5, 0.2)):
        assert amp[np.argmin(abs(orders - o))] == pytest.approx(a, rel=1e-3)
    avg = tsa(acq, 256)
    parts = split_tsa(avg, z)
    ang = 2 * np.pi * np.arange(256) / 256
    # the half order 7.5 changes sign every revolution: it averages out over the 6 whole revolutions
    np.testing.assert_allclose(avg, np.cos(z * ang) + 0.1 * np.cos((z + 1) * ang + 0.4) + 0.3 * np.cos(ang), atol=2e-3)
    assert parts["mesh_amplitudes"][0] == pytest.approx(1.0, rel=1e-3)
    np.testing.assert_allclose(parts["residual"], 0.1 * np.cos((z + 1) * ang + 0.4), atol=2e-3)
    np.testing.assert_allclose(parts["regular"], avg, atol=2e-3)  # shaft order, mesh order, first sideband
    assert np.max(np.abs(parts["difference"])) < 2e-3
    assert fm0(avg, parts["mesh_amplitudes"]) == pytest.approx(np.ptp(avg) / np.sum(parts["mesh_amplitudes"]))
    assert sideband_level(avg, parts["sidebands"]) == pytest.approx(0.1 / np.std(avg), rel=1e-2)
    assert energy_ratio(parts["difference"], parts["regular"]) < 3e-3
