"""Every verdict rule of the reproduction on constructed data: where it must fail and where it must pass."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from geardyn.analysis.classify import MOTION_CHAOTIC, MOTION_PERIODIC
from geardyn.paper.claims import CLAIMS
from geardyn.paper.readings import BACKLASH_READINGS, Reading, phase_pairs
from geardyn.paper.studies.jumps import fluctuation
from geardyn.paper.studies.readings import _judge, intervals_text, lle_sign_holds
from geardyn.paper.verdicts import (
    FLUCT_MIN,
    MATCH_REPRODUCED,
    fluctuation_trend,
    jump_holds,
    jump_type_at,
    length_fraction,
    section_spread,
)


# --- ranges by length --------------------------------------------------------------------------------------------
def test_length_fraction_weighs_each_point_by_the_interval_it_stands_for():
    x = [0.0, 0.25, 0.5, 0.75, 1.0]  # cells 0.125, 0.25, 0.25, 0.25, 0.125 of [0, 1]
    frac, total = length_fraction(x, [True, True, True, True, False], 0.0, 1.0)
    assert frac == pytest.approx(0.875, abs=1e-15) and total == pytest.approx(1.0, abs=1e-15)
    assert frac >= MATCH_REPRODUCED  # passes
    frac, _ = length_fraction(x, [False, True, True, True, False], 0.0, 1.0)
    assert frac == pytest.approx(0.75, abs=1e-15) and frac < MATCH_REPRODUCED  # fails


def test_an_uneven_grid_cannot_decide_a_range_claim():
    # ten points crowded into [0, 0.09] where the claim holds, one at 1.0 where it fails: 10 of 11 grid points
    # (91 %) but the matching cells end at the midpoint 0.545, so 54.5 % of the length: the claim fails
    x = [0.01 * i for i in range(10)] + [1.0]
    ok = [True] * 10 + [False]
    assert sum(ok) / len(ok) >= MATCH_REPRODUCED  # what a count of grid points would say
    frac, _ = length_fraction(x, ok, 0.0, 1.0)
    assert frac == pytest.approx(0.545, abs=1e-12) and frac < MATCH_REPRODUCED


def test_open_ends_and_unbounded_ranges_are_cut_to_the_grid():
    x = [0.02, 0.04, 0.064, 0.08]
    frac, total = length_fraction(x, [True, True, False, False], -np.inf, 0.064, hi_open=True)
    assert total == pytest.approx(0.052 - 0.01, abs=1e-12)  # [0.01, 0.052]; the point on the open end counts nothing
    assert frac == pytest.approx(1.0)
    assert np.isnan(length_fraction(x, [True] * 4, 0.5, 0.6)[0])


# --- fluctuation measured as fluctuation ---------------------------------------------------------------------------
def _response(amplitudes, sections):
    w = np.linspace(0.6, 0.9, len(amplitudes))
    pc = np.asarray(sections, dtype=float)  # (ω, section, 2)
    return xr.Dataset(
        {
            "amplitude": (("sweep", "omega"), np.asarray([amplitudes], float)),
            "poincare_u": (("sweep", "omega", "section"), pc[None, ..., 0]),
            "poincare_v": (("sweep", "omega", "section"), pc[None, ..., 1]),
        },
        coords={"sweep": ["up"], "omega": w},
    )


def test_spread_is_zero_for_period_one_whatever_the_amplitude():
    one = [[[1.0, 0.5]] * 4] * 5  # period-1 at every ω
    rising = _response([0.1, 0.5, 0.9, 1.3, 1.7], one)  # a resonance flank: amplitude steps, no fluctuation
    assert fluctuation(rising, 0.0) == 0.0
    two = [[[1.0, 0.5], [1.2, 0.5]] * 2] * 5  # period-2: points ±0.1 about their centroid
    assert fluctuation(_response([1.0] * 5, two), 0.0) == pytest.approx(0.1, abs=1e-15)
    assert section_spread(np.array([[0.0, 0.0], [0.0, 2.0]])) == pytest.approx(1.0)


def test_a_trend_of_fluctuation_needs_fluctuation_and_a_strict_trend():
    ok, why = fluctuation_trend([0.0, 0.0, 0.0], True)  # nothing fluctuates: the claim cannot hold
    assert not ok and "no fluctuation" in why
    ok, _ = fluctuation_trend([FLUCT_MIN / 10, FLUCT_MIN / 20, FLUCT_MIN / 30], True)
    assert not ok
    assert fluctuation_trend([0.3, 0.2, 0.1], True)[0]
    assert not fluctuation_trend([0.3, 0.2, 0.1], False)[0]
    assert not fluctuation_trend([0.3, 0.3, 0.1], True)[0]  # not strict
    assert not fluctuation_trend([0.3, float("nan"), 0.1], True)[0]


# --- jumps by direction and location ------------------------------------------------------------------------------
def _j(w, d):
    return {"omega": w, "direction": d, "sweep": "up" if d == "up" else "down", "size": 0.4}


def test_the_opposite_jump_fails_a_jump_type():
    loop = [_j(0.615, "up"), _j(0.585, "down")]  # a hysteresis loop straddling ω = 0.6 symmetrically
    assert jump_type_at(loop, 0.6, 0.05) == "both"
    assert not jump_holds(loop, 0.6, "upward", 0.05) and not jump_holds(loop, 0.6, "downward", 0.05)
    down = [_j(0.59, "down")]
    assert not jump_holds(down, 0.6, "upward", 0.05) and jump_holds(down, 0.6, "downward", 0.05)
    near_up = [_j(0.62, "up"), _j(0.55, "down")]
    assert jump_holds(near_up, 0.6, "up", 0.05) and not jump_holds(near_up, 0.6, "down", 0.05)


def test_jump_location_is_tested():
    far = [_j(0.985, "up")]
    assert not jump_holds(far, 0.95, "up", 0.03) and jump_holds(far, 0.95, "up", 0.04)
    assert jump_holds([], 0.4, "none", 0.05) and not jump_holds([_j(0.42, "up")], 0.4, "none", 0.05)
    assert not jump_holds([], 0.6, "upward", 0.05)


# --- two-part claims ------------------------------------------------------------------------------------------------
def _point(motion, period, lle, err):
    return {
        "motion": np.array([motion]),
        "period": np.array([period]),
        "lle": np.array([lle]),
        "lle_err": np.array([err]),
    }


def test_both_parts_of_a_motion_and_exponent_claim_are_required():
    def t32(r):  # quasi-2-periodic (period-2) and λ1 near zero
        return _judge("T3-2", (), r)

    assert t32(_point(MOTION_PERIODIC, 2, 0.002, 1e-4))[0]
    assert not t32(_point(MOTION_PERIODIC, 2, -0.08, 1e-4))[0]  # the motion alone
    assert not t32(_point(MOTION_CHAOTIC, 0, 0.002, 1e-4))[0]  # the exponent alone

    def t33(r):
        return _judge("T3-3", (), r)

    assert t33(_point(MOTION_CHAOTIC, 0, 0.03, 1e-3))[0] and not t33(_point(MOTION_CHAOTIC, 0, 0.002, 1e-3))[0]
    assert lle_sign_holds("negative", -0.1, 1e-6) and not lle_sign_holds("negative", -0.002, 1e-3)
    assert not lle_sign_holds("positive", float("nan"), 0.0)


def test_both_bifurcation_points_are_required():
    x = [0.02, 0.04, 0.06, 0.08, 0.2, 0.5, 0.8, 0.9]

    def judge(r):
        return _judge("XI0-BIF", x, r)

    C, P = MOTION_CHAOTIC, MOTION_PERIODIC
    both = {"motion": np.array([C, C, C, P, P, P, C, C]), "period": np.array([0, 0, 0, 4, 2, 2, 0, 0])}
    assert judge(both)[0]
    first_only = {"motion": np.array([C, C, C, P, P, P, P, P]), "period": np.array([0, 0, 0, 4, 2, 2, 2, 2])}
    assert not judge(first_only)[0]
    second_only = {"motion": np.array([C, P, P, P, P, P, C, C]), "period": np.array([0, 4, 4, 4, 2, 2, 0, 0])}
    assert not judge(second_only)[0]


# --- readings -------------------------------------------------------------------------------------------------------
def test_readings_cover_the_phases_and_the_three_backlash_readings():
    full, one = phase_pairs(True), phase_pairs(False)
    assert len(full) == 16 and len(set(full)) == 16 and full[0] == (0.0, 0.0)
    assert len(one) == 7 and one[0] == (0.0, 0.0) and all(a == 0 or b == 0 for a, b in one)
    assert BACKLASH_READINGS == {"b/2": 2.0, "b": 1.0, "b/0.1": 0.1}
    r = Reading(0.0, np.pi / 2, "b/0.1", 1.23)
    assert r.D(0.5) == pytest.approx(5.0) and not r.is_default
    assert r.text == "ω = 1.23, φ_c1 = 0, φ_k1 = π/2, D = b/(0.1 mm)"
    assert "stiffness phase φ_k1 = π/2" in r.changes() and "D = b/(0.1 mm)" in r.changes()
    assert Reading(backlash="b/2").is_default and Reading(omega=1.0).is_default
    assert intervals_text([0.62, 0.63, 0.64, 0.9]) == "0.62–0.64, 0.90" and intervals_text([]) == "none"
    assert CLAIMS["T3-2"].numbers["lyapunov"] == "near zero"
