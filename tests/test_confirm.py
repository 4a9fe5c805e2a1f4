"""Classification that respects F1 (analysis.confirm), and the F1/F2 facts of the report against exact theory."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.analysis.classify import MOTION_PERIODIC, MOTION_QUASIPERIODIC, MOTION_UNRESOLVED
from geardyn.analysis.confirm import CONFIRM_HALVED, CONFIRM_NONE, confirm_point, needs_confirmation
from geardyn.analysis.periodic import shoot
from geardyn.paper.studies.facts import F2_D, f1_check, f2_check
from geardyn.paper.table1 import TABLE1_MODEL


def test_which_labels_are_re_examined():
    assert needs_confirmation(MOTION_QUASIPERIODIC, 0, 0.0) and needs_confirmation(MOTION_UNRESOLVED, 0, np.nan)
    assert needs_confirmation(MOTION_PERIODIC, 4, -0.05) and not needs_confirmation(MOTION_PERIODIC, 3, -0.05)
    assert not needs_confirmation(MOTION_PERIODIC, 1, -0.1)
    assert needs_confirmation(3, 0, 0.004) and not needs_confirmation(3, 0, 0.05)


def test_a_closed_curve_label_is_never_kept_for_positive_damping():
    # ξ0 = 0.028, ω = 1: a 200-period run after a 300-period transient labels it quasi-periodic (5 loops)
    m = TABLE1_MODEL.replace(xi0=0.028)
    from geardyn.integrate import integrate_batch
    from geardyn.model import IntegrationOptions

    res = integrate_batch([m], (0.0, 0.0), IntegrationOptions(transient=300, periods=200))
    r = confirm_point(m, res.end_state[0], res.poincare[0], MOTION_QUASIPERIODIC, 0, 0.0055, 0.002, long_periods=1500)
    assert r["motion"] != MOTION_QUASIPERIODIC  # F1: no invariant closed curve exists for ξ0 > 0
    assert r["confirmed"] != CONFIRM_NONE


def test_a_period_2n_label_yields_to_a_stable_period_n_orbit_and_not_otherwise():
    m = TABLE1_MODEL.replace(omega=0.4)  # a stable period-1 orbit
    orb = shoot(m, 1)
    assert orb.converged and orb.stable
    section = np.vstack([orb.state + 1e-4, orb.state - 1e-4])  # a slowly converging orbit read as period-2
    r = confirm_point(m, orb.state, section, MOTION_PERIODIC, 2, -0.05, 1e-4)
    assert r["period"] == 1 and r["confirmed"] == CONFIRM_HALVED
    # a true period-2 orbit: the period-1 orbit shot from its points is unstable, the label stays
    m2 = TABLE1_MODEL  # ω = 1, ξ0 = 0.1: period-2
    o2 = shoot(m2, 2)
    assert o2.converged and o2.stable and o2.minimal_period == 2
    r2 = confirm_point(m2, o2.state, o2.points, MOTION_PERIODIC, 2, -0.07, 1e-4)
    assert r2["period"] == 2 and r2["confirmed"] == CONFIRM_NONE


def test_f1_period_map_determinant_is_exp_minus_4_pi_xi0_over_omega():
    for r in f1_check(TABLE1_MODEL, transient=200):
        assert r["det"] == pytest.approx(math.exp(-4 * math.pi * r["xi0"] / r["omega"]), rel=1e-8)


def test_f2_without_back_contact_the_response_does_not_depend_on_D():
    r = f2_check(TABLE1_MODEL, transient=300, periods=32)
    free = ~r["back"]
    assert free.sum() >= 2 and (~free).sum() >= 1
    amp = r["amplitude"][free]
    assert np.ptp(amp) <= 1e-9 * amp.max()
    assert np.ptp(r["u_max_rel"][free]) <= 1e-9 * abs(r["u_max_rel"][free]).max()
    assert np.all(np.abs(r["amplitude"][~free] - amp[0]) > 1e-3)  # with back contact it does
    assert list(r["D"]) == list(F2_D)
