"""The hysteresis loop of a response: a run of differing attractors bounded by the jumps is hysteresis, for the pair
and for systems alike (issue 23 item 2).

``data/hyst/bevel_8dof_response_window.nc`` is the window ω = 0.88 … 0.97 of
``geardyn response --system examples/systems/paper_bevel_8dof.toml --omega-start 0.6 --omega-stop 1.2 --num 61``
(the variables the attractor test reads, the last 64 Poincaré sections).  There the up sweep jumps between 0.93 and
0.94 and the down sweep between 0.92 and 0.91; the point each sweep reaches just after its jump (0.94 on the up
sweep, 0.91 on the down sweep) lies on the other sweep's cycle to 1e-6 but was detected with period 3 and 7 (its
section points still scatter by more than the period test's 1e-6), so the run of differing attractors reached one
grid point beyond each jump and the loop was filed as coexistence.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from geardyn.analysis.attractors import Attractor, same_attractor
from geardyn.analysis.classify import MOTION_PERIODIC
from geardyn.analysis.response import annotate_response, coexistence_intervals, detect_jumps

WINDOW = Path(__file__).parent / "data" / "hyst" / "bevel_8dof_response_window.nc"


@pytest.fixture(scope="module")
def bevel() -> xr.Dataset:
    return xr.load_dataset(WINDOW)


def test_the_bevel_pairs_points_after_its_jumps_are_the_other_sweeps_cycle(bevel):
    """What the stored data hold: at 0.91 and 0.94 the two sweeps' last section points agree to 1e-6 although the
    detected periods differ; at 0.92 and 0.93 the amplitudes differ threefold (two attractors)."""

    def at(w, s):
        return bevel.sel(sweep=s).sel(omega=w, method="nearest")

    for w, periods in ((0.91, (1, 7)), (0.94, (3, 1))):
        up, down = at(w, "up"), at(w, "down")
        assert (int(up["period"]), int(down["period"])) == periods
        for v in ("poincare_u", "poincare_v"):  # the last 8 section points of both sweeps: one point to 1e-6
            pts = np.concatenate([up[v].values[-8:], down[v].values[-8:]])
            assert float(np.ptp(pts)) < 1e-6
    for w in (0.92, 0.93):
        assert float(at(w, "down")["amplitude"]) > 2.5 * float(at(w, "up")["amplitude"])


def test_the_bevel_pairs_main_loop_is_hysteresis_between_its_jumps(bevel):
    jumps = detect_jumps(bevel)
    assert [(j["sweep"], j["direction"], j["omega_from"], j["omega_to"]) for j in jumps] == [
        ("up", "up", pytest.approx(0.93), pytest.approx(0.94)),
        ("down", "down", pytest.approx(0.92), pytest.approx(0.91)),
    ]
    hy, co = coexistence_intervals(bevel, jumps=jumps)
    # from the midpoint of the down jump's step to that of the up jump's: the two grid points 0.92 and 0.93
    assert hy == [[pytest.approx(0.915), pytest.approx(0.935)]]
    assert co == []
    ds = annotate_response(bevel.copy())
    assert json.loads(ds.attrs["hysteresis"]) == [[pytest.approx(0.915), pytest.approx(0.935)]]


def test_cycles_of_one_point_are_the_same_attractor_whatever_period_was_detected():
    """A cycle detected with period 7 whose points all lie on the period-1 point is that orbit; a true period-2
    orbit (points apart) is not the period-1 orbit."""
    one = Attractor(1, MOTION_PERIODIC, np.array([[1.4107378, 0.0513369]]), np.array([0.2, 1.2]))
    scatter = 1e-7 * np.sin(np.arange(14.0)).reshape(7, 2)
    seven = Attractor(7, MOTION_PERIODIC, one.points + scatter, one.signature)
    two = Attractor(2, MOTION_PERIODIC, np.array([[1.40, 0.05], [1.42, 0.06]]), one.signature)
    assert same_attractor(one, seven, signature_tol=0.01) and same_attractor(seven, one, signature_tol=0.01)
    assert not same_attractor(one, two, signature_tol=0.01) and not same_attractor(two, one, signature_tol=0.01)


def _synthetic(amp_up: np.ndarray, amp_down: np.ndarray, x: np.ndarray) -> xr.Dataset:
    n = x.size
    pu = np.stack([amp_up, amp_down])[..., None] * np.ones((1, 1, 4))
    return xr.Dataset(
        {
            "amplitude": (("sweep", "omega"), np.stack([amp_up, amp_down])),
            "mean": (("sweep", "omega"), np.zeros((2, n))),
            "status": (("sweep", "omega"), np.zeros((2, n), np.int64)),
            "period": (("sweep", "omega"), np.ones((2, n), np.int64)),
            "motion": (("sweep", "omega"), np.full((2, n), MOTION_PERIODIC, np.int64)),
            "poincare_u": (("sweep", "omega", "section"), pu),
            "poincare_v": (("sweep", "omega", "section"), 0 * pu),
        },
        coords={"sweep": ["up", "down"], "omega": x},
        attrs={"param": "omega", "measure": "amplitude"},
    )


def test_a_jump_one_step_inside_the_run_bounds_the_loop_and_the_rest_is_coexistence():
    """The up sweep jumps between 0.76 and 0.77 and the down sweep between 0.73 and 0.72; the points just after
    the jumps (0.77 up, 0.72 down) have not reached the other sweep's orbit (a section point 0.01 away, beyond the
    cycle tolerance).  The loop runs between the jumps; the unsettled points beyond them are listed as coexistence."""
    x = np.round(np.linspace(0.70, 0.80, 11), 6)
    amp_up = np.where(x < 0.765, 0.3, 1.2)
    amp_down = np.where(x < 0.725, 0.3, 1.2)
    ds = _synthetic(amp_up, amp_down, x)
    ds["poincare_u"][0, 7, :] = 1.21  # up sweep at 0.77: not yet on the down sweep's orbit
    ds["poincare_u"][1, 2, :] = 0.31  # down sweep at 0.72: not yet on the up sweep's orbit
    hy, co = coexistence_intervals(ds)
    assert hy == [[pytest.approx(0.725), pytest.approx(0.765)]]
    assert co == [[pytest.approx(0.715), pytest.approx(0.725)], [pytest.approx(0.765), pytest.approx(0.775)]]


def test_a_loop_with_a_jump_at_one_end_only_is_hysteresis():
    """The up sweep jumps between 0.76 and 0.77; the down sweep leaves its attractor at the lower end with no jump
    in the measure (it slides onto the up sweep's orbit from 0.73 to 0.72, amplitude 0.35 → 0.3): the run 0.73 …
    0.76 is still a hysteresis loop, bounded by the up jump."""
    x = np.round(np.linspace(0.70, 0.80, 11), 6)
    amp_up = np.where(x < 0.765, 0.3, 1.2)
    amp_down = np.array([0.3, 0.3, 0.3, 0.35, 0.55, 0.75, 0.95, 1.2, 1.2, 1.2, 1.2])
    ds = _synthetic(amp_up, amp_down, x)
    jumps = detect_jumps(ds)
    assert [(j["sweep"], j["omega_from"], j["omega_to"]) for j in jumps] == [("up", 0.76, 0.77)]
    hy, co = coexistence_intervals(ds, jumps=jumps)
    assert hy == [[pytest.approx(0.725), pytest.approx(0.765)]] and co == []
