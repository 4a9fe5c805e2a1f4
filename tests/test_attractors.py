"""One "same attractor" test for the frequency response and the basins of attraction."""

from __future__ import annotations

import numpy as np

from geardyn.analysis import attractors as A
from geardyn.analysis import basins as B
from geardyn.analysis import response as R
from geardyn.analysis.classify import MOTION_CHAOTIC, MOTION_PERIODIC, MOTION_QUASIPERIODIC


def test_cycles_match_in_any_phase_within_tolerance():
    c = np.array([[0.1, 0.2], [0.3, -0.4], [0.5, 0.0]])
    assert A.same_cycle(c, c[[2, 0, 1]])
    assert A.same_cycle(c, c + 0.5e-3)
    assert not A.same_cycle(c, c + 2e-3)
    assert not A.same_cycle(c, c[:2])  # a point of c has no partner


def test_periodic_and_non_periodic_attractors_differ():
    per = A.Attractor(1, MOTION_PERIODIC, np.zeros((1, 2)), np.array([1.0, 0.0]))
    qp = A.Attractor(0, MOTION_QUASIPERIODIC, np.zeros((4, 2)), np.array([1.0, 0.0]))
    ch = A.Attractor(0, MOTION_CHAOTIC, np.zeros((4, 2)), np.array([1.0, 0.0]))
    assert not A.same_attractor(per, qp, signature_tol=1.0)
    assert A.same_attractor(qp, ch, signature_tol=0.1, match_motion=False)  # the response's test
    assert not A.same_attractor(qp, ch, signature_tol=0.1)  # the basins' test
    assert not A.same_attractor(
        qp, A.Attractor(0, MOTION_QUASIPERIODIC, qp.points, np.array([1.2, 0.0])), signature_tol=0.1
    )


def test_response_and_basins_share_the_module():
    assert B.identify_attractors is A.identify_attractors
    assert R.ATTRACTOR_TOL == B.CYCLE_TOL == A.CYCLE_TOL
    assert R.NONPERIODIC_TOL == B.NONPERIODIC_TOL == A.NONPERIODIC_TOL


def test_identify_attractors_numbers_by_basin_size():
    cyc1 = np.array([[0.5, 0.1]] * 8)
    cyc2 = np.tile([[1.0, 0.2], [-1.0, 0.3]], (4, 1))
    rows = {
        "period": np.array([1, 2, 2, -1, 2]),
        "motion": np.array([MOTION_PERIODIC] * 3 + [-1, MOTION_PERIODIC]),
        "status": np.array([0, 0, 0, 1, 0]),
        "amplitude": np.array([0.1, 1.0, 1.0, np.nan, 1.0]),
        "mean": np.zeros(5),
        "u_min": np.zeros(5),
        "u_max": np.zeros(5),
        "poincare": np.stack([cyc1, cyc2, cyc2[::-1].copy(), cyc1, cyc2 + 1e-5]),
    }
    labels, atts = A.identify_attractors(rows)
    np.testing.assert_array_equal(labels, [1, 0, 0, -1, 0])
    assert [a["period"] for a in atts] == [2, 1] and [a["count"] for a in atts] == [3, 1]
    np.testing.assert_array_equal(atts[0]["points"], [[-1.0, 0.3], [1.0, 0.2]])  # the cycle, sorted
