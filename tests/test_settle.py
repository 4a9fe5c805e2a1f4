"""``--transient auto``: the transient from the decay time of the least damped linearised mode
(geardyn.analysis.settle), against the exact free decay of a linear damped oscillator and an independent
eigenvalue computation; the default transient is unchanged without the option."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from geardyn import GearModel, IntegrationOptions, load_system
from geardyn.analysis.settle import CAP_PERIODS, DECAY_EFOLDS, FLOOR_PERIODS, decay_rate, settle_periods
from geardyn.errors import ModelError
from geardyn.integrate import integrate_batch

ROOT = Path(__file__).resolve().parents[1]


def linear_pair(omega: float, xi0: float, fp: float = 0.1) -> GearModel:
    """u'' + 2ξ0 u' + u = fp: no backlash, no harmonics (a linear damped oscillator, ω_n = 1)."""
    return GearModel(omega=omega, xi0=xi0, xi=(), kappa=(), eps=(), fp=fp, D=0.0)


def free_decay(t: float, xi0: float) -> float:
    """u(t) − fp of the oscillator released from u − fp = 1, u' = 0 (underdamped): exact."""
    wd = math.sqrt(1.0 - xi0 * xi0)
    return math.exp(-xi0 * t) * (math.cos(wd * t) + xi0 / wd * math.sin(wd * t))


@pytest.mark.parametrize("xi0", [0.02, 0.1, 0.3])
def test_pair_rate_is_zeta_omega_n_and_the_count_the_first_period_past_e_minus_k(xi0):
    m = linear_pair(0.8, xi0)
    assert decay_rate(m) == pytest.approx(xi0, rel=1e-12)  # λ = −ξ0 ± i√(1 − ξ0²)
    s = settle_periods(m)
    T = 2.0 * math.pi / 0.8
    # the envelope e^(−ξ0 t) of the exact solution: below e^−K after the count, not one period earlier
    assert math.exp(-xi0 * s.periods * T) <= math.exp(-DECAY_EFOLDS) * (1 + 1e-12)
    assert s.periods == FLOOR_PERIODS or math.exp(-xi0 * (s.periods - 1) * T) > math.exp(-DECAY_EFOLDS)
    assert s.periods == max(FLOOR_PERIODS, math.ceil(DECAY_EFOLDS / xi0 / T - 1e-9))


def test_overdamped_pair_rate_is_the_slow_root():
    xi0 = 2.0
    assert decay_rate(linear_pair(0.8, xi0)) == pytest.approx(xi0 - math.sqrt(xi0 * xi0 - 1.0), rel=1e-10)


def test_the_integrated_pair_after_the_auto_transient_is_the_exact_free_decay():
    """RK4 from u − fp = 1 through the auto count: the Poincaré point is the closed form at (n + 1)·T (the first
    recorded period's end), and its deflection is within the e^−K envelope."""
    xi0, omega, fp = 0.1, 0.8, 0.1
    m = linear_pair(omega, xi0, fp)
    n = settle_periods(m).periods
    assert n == 16  # 12/0.1 = 120 τ over T = 7.854: 15.3 periods
    res = integrate_batch([m], (fp + 1.0, 0.0), IntegrationOptions(transient=n, periods=1))
    u = float(res.poincare[0, 0, 0])
    T = 2.0 * math.pi / omega
    exact = fp + free_decay((n + 1) * T, xi0)
    assert abs(u - exact) < 1e-9
    envelope = math.exp(-DECAY_EFOLDS) * math.sqrt(1.0 + xi0 * xi0 / (1.0 - xi0 * xi0))
    assert abs(u - fp) <= envelope


def test_the_count_is_that_of_the_highest_omega_and_scales_with_it():
    m = linear_pair(0.5, 0.05)
    lo, hi = settle_periods(m, [0.5]), settle_periods(m, [0.5, 2.0])
    assert lo.periods == math.ceil(12 / 0.05 / (2 * math.pi / 0.5))  # 19.1 -> 20
    assert hi.periods == math.ceil(12 / 0.05 / (2 * math.pi / 2.0))  # 76.4 -> 77


def test_floor_and_cap():
    assert settle_periods(linear_pair(0.1, 0.9)).periods == FLOOR_PERIODS
    s = settle_periods(linear_pair(3.0, 1e-5))
    assert s.periods == CAP_PERIODS and s.capped and "capped" in s.note()


def test_system_rate_against_the_full_state_matrix_eigenvalues():
    """The 8-DOF bevel pair (rigid rotation left out by the deflation): the rate equals the least −Re λ of the
    full 2n-state matrix computed with scipy, the eigenvalues at 0 (the free drift) set aside."""
    s = load_system(ROOT / "examples/systems/paper_bevel_8dof.toml")
    Mi = np.asarray(s.Mi)
    K = np.array(s.Kb) + sum(m.k * np.outer(v, v) for m, v in zip(s.meshes, s.V))
    C = np.array(s.Cb) + sum(2 * m.xi0 * np.outer(v, v) for m, v in zip(s.meshes, s.V))
    n = Mi.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])
    lam = scipy.linalg.eigvals(A)
    lam = lam[np.abs(lam) > 1e-6]
    assert decay_rate(s) == pytest.approx(float(np.min(-lam.real)), rel=1e-8)


def test_an_undamped_mode_refuses_auto():
    with pytest.raises(ModelError, match="transient: auto needs every mode damped"):
        settle_periods(load_system(ROOT / "examples/systems/planetary_lin_parker_1999.toml"))


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "geardyn.cli", *args], capture_output=True, text=True, cwd=ROOT, timeout=600
    )


def test_cli_transient_auto_is_the_run_with_that_count():
    """``--transient auto`` says its count on stderr and gives the result of ``--transient N`` exactly."""
    args = ["simulate", "--omega", "0.8", "--periods", "8", "--json"]
    auto = _cli(*args, "--transient", "auto")
    assert auto.returncode == 0, auto.stderr
    assert "transient auto: 16 forcing periods" in auto.stderr  # ξ0 = 0.1 (Table 1): 120 τ / 7.854
    fixed = _cli(*args, "--transient", "16")
    assert fixed.returncode == 0, fixed.stderr
    assert json.loads(auto.stdout) == json.loads(fixed.stdout)


@pytest.mark.parametrize("value", ["abc", "1.5"])
def test_cli_bad_transient_exits_2_in_one_line(value):
    r = _cli("simulate", "--omega", "0.8", "--transient", value)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "--transient" in r.stderr and "auto" in r.stderr
