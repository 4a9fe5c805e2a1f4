"""Stiffness harmonics from the contact ratios: closed form against the exact waveform's spectrum."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.errors import ModelError
from geardyn.standards import mesh_stiffness_harmonics, mesh_stiffness_waveform

NS = 8192
THETA = np.arange(NS) * 2 * math.pi / NS


def _spectrum(w: np.ndarray, r: int) -> tuple[float, float]:
    c = np.fft.rfft(w)[r] / NS
    return 2 * abs(c), float(np.angle(c))


@pytest.mark.parametrize("ea, eb", [(1.165, 1.227), (1.6, 0.0), (1.35, 0.4), (1.9, 2.7), (1.01, 2.095)])
def test_closed_form_matches_the_waveform(ea, eb):
    h = mesh_stiffness_harmonics(ea, eb, 4)
    w = mesh_stiffness_waveform(ea, eb, THETA)
    assert w.mean() == pytest.approx(1.0, abs=2e-4 if eb == 0 else 1e-6)
    # the series k/k0 = 1 + sum kappa_r cos(r theta + phi_r) reproduces the waveform's harmonics
    tol = 2e-3 if eb == 0 else 1e-5  # sampling error: ~1/NS at the spur jumps, ~1/NS² at the kinks
    for r in range(1, 5):
        amp, ph = _spectrum(w, r)
        assert h.kappa[r - 1] == pytest.approx(amp, abs=tol)
        if amp > 1e-3:
            assert math.cos(h.phi[r - 1] - ph) == pytest.approx(1.0, abs=1e-3)


def test_spur_limit_is_single_double_contact():
    ea = 1.6
    w = mesh_stiffness_waveform(ea, 0.0, THETA)
    # two pairs during eps_alpha - 1 = 0.6 of the cycle, one pair during the rest
    assert set(np.round(w * ea, 12)) == {1.0, 2.0}
    assert np.mean(w * ea == 2.0) == pytest.approx(0.6, abs=1 / NS)
    h = mesh_stiffness_harmonics(ea, 0.0, 3)
    for r, k in enumerate(h.kappa, start=1):
        assert k == pytest.approx(2 * abs(math.sin(math.pi * r * ea)) / (math.pi * r * ea))


def test_whole_contact_ratios_give_constant_stiffness():
    h = mesh_stiffness_harmonics(2.0, 0.0, 3)
    assert max(h.kappa) < 1e-15
    # a face contact ratio of one smooths every harmonic away, whatever eps_alpha
    h = mesh_stiffness_harmonics(1.37, 1.0, 3)
    assert max(h.kappa) < 1e-15
    w = mesh_stiffness_waveform(1.37, 1.0, THETA)
    assert np.ptp(w) < 1e-12


def test_face_overlap_multiplies_by_sinc():
    ea, eb = 1.3, 0.45
    spur = mesh_stiffness_harmonics(ea, 0.0, 3)
    spiral = mesh_stiffness_harmonics(ea, eb, 3)
    for r in range(1, 4):
        x = math.pi * r * eb
        assert spiral.kappa[r - 1] == pytest.approx(spur.kappa[r - 1] * abs(math.sin(x) / x))


def test_iso_tr_10300_30_sample1_kappa1():
    # sample 1: eps_va = 1.165, eps_vb = 1.227 (ISO/TR 10300-30, printed); the issue estimates 0.05
    h = mesh_stiffness_harmonics(1.165, 1.227, 3)
    assert h.kappa[0] == pytest.approx(0.046, abs=5e-4)
    assert h.kappa[0] < 0.2 / 4  # four times smaller than the paper's kappa1 = 0.2


def test_bad_input():
    with pytest.raises(ModelError, match="eps_alpha"):
        mesh_stiffness_harmonics(0.0, 1.0)
    with pytest.raises(ModelError, match="eps_beta"):
        mesh_stiffness_harmonics(1.2, -0.1)
    with pytest.raises(ModelError, match="n_harmonics"):
        mesh_stiffness_harmonics(1.2, 0.5, 0)
    assert mesh_stiffness_harmonics(1.2, 0.5, 2).to_dict()["kappa"] == list(mesh_stiffness_harmonics(1.2, 0.5, 2).kappa)
