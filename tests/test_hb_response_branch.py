"""The response read off an HB branch: a point whose stability could not be decided does not end a stable
segment, jumps are placed only at folds, and every grid point on a stable segment is solved (issue: on the 8-DOF
bevel pair with Hill's multipliers the down jump sat at a point that is not a fold, and grid points in the middle
of a stable branch came out empty)."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.hb import hb_continuation
from geardyn.analysis.hb import response as R
from geardyn.model import GearModel
from geardyn.status import Status

GRID = np.linspace(0.5, 0.65, 31)


@pytest.fixture(scope="module")
def branch():
    """Two folds (a hysteresis loop) and a grazing in ω ∈ [0.5, 0.65] at H = 8."""
    return hb_continuation(GearModel(), "omega", 0.5, 0.65, harmonics=8)


def _same_response(a, b):
    ja, jb = json.loads(a.attrs["jumps"]), json.loads(b.attrs["jumps"])
    assert [(j["sweep"], j["direction"], j["omega"]) for j in ja] == [
        (j["sweep"], j["direction"], j["omega"]) for j in jb
    ]
    for x, y in zip(ja, jb):
        assert x["amplitude_to"] == pytest.approx(y["amplitude_to"], rel=1e-9)
    assert json.loads(a.attrs["hysteresis"]) == json.loads(b.attrs["hysteresis"])
    np.testing.assert_array_equal(a["status"].values, b["status"].values)
    np.testing.assert_allclose(a["amplitude"].values, b["amplitude"].values, rtol=1e-9, atol=1e-12)


def _undecided(res, idx):
    bad = copy.copy(res)
    bad.status = res.status.copy()
    bad.multipliers = res.multipliers.copy()
    bad.status[idx] = int(Status.UNRESOLVED)
    bad.multipliers[idx] = np.nan
    return bad


def test_the_case_has_two_folds_and_jumps_at_them(branch):
    folds = sorted(b.value for b in branch.of_type("fold"))
    ds = R.response_from_branch(branch, GRID)
    jumps = json.loads(ds.attrs["jumps"])
    assert len(folds) == 2 and sorted(j["omega"] for j in jumps) == folds
    assert np.all(ds["status"].values[:, :] == int(Status.OK))  # every grid point on a stable solution


def test_undecided_points_inside_stable_runs_do_not_end_them(branch):
    st = branch.stable
    inner = [i for i in range(1, st.size - 1) if st[i - 1] and st[i] and st[i + 1]]
    picks = [inner[len(inner) // 4], inner[len(inner) // 2], inner[3 * len(inner) // 4]]
    bad = _undecided(branch, picks)
    assert not np.any(bad.stable[picks])
    np.testing.assert_array_equal(R.decided_stability(bad), st)
    assert [(s.omega[0], s.omega[-1]) for s in R.stable_segments(bad)] == [
        (s.omega[0], s.omega[-1]) for s in R.stable_segments(branch)
    ]
    _same_response(R.response_from_branch(bad, GRID), R.response_from_branch(branch, GRID))


def test_undecided_point_next_to_a_located_event_stays_unstable(branch):
    fold = branch.of_type("fold")[0]
    i = int(np.argmin(np.abs(branch.values - fold.value)))  # a point next to the fold, on either side
    j = i if not branch.stable[i] else i + (1 if not branch.stable[i + 1] else -1)
    assert not branch.stable[j]
    assert not R.decided_stability(_undecided(branch, [j]))[j]


def test_jumps_only_at_folds(branch):
    """Without its located folds a branch's stable segments end with no event: no jump is placed there (it used
    to jump to the nearest stable segment, at a point that is not a fold)."""
    nofold = copy.copy(branch)
    nofold.bifurcations = [b for b in branch.bifurcations if b.type != "fold"]
    ds = R.response_from_branch(nofold, GRID)
    assert json.loads(ds.attrs["jumps"]) == []
    one = copy.copy(branch)
    keep = min(branch.of_type("fold"), key=lambda b: b.value)
    one.bifurcations = [b for b in branch.bifurcations if b.type != "fold" or b is keep]
    jumps = json.loads(R.response_from_branch(one, GRID).attrs["jumps"])
    assert [j["omega"] for j in jumps] == [keep.value]


def test_grid_point_whose_newton_fails_is_reached_from_the_branch(branch, monkeypatch):
    """Newton from the interpolated coefficients failing at a grid point (as it did in the middle of a stable
    branch) no longer leaves it empty: the point is reached from the nearest branch point in small steps."""
    ref = R.response_from_branch(branch, GRID)
    newton = R.HBEquations.newton
    failed = []

    def flaky(eq, x0, w=None, **kw):
        if w in GRID[5:25:4] and w not in failed:
            failed.append(w)
            return x0, Status.NOT_CONVERGED, 0, math.inf
        return newton(eq, x0, w, **kw)

    monkeypatch.setattr(R.HBEquations, "newton", flaky)
    ds = R.response_from_branch(branch, GRID)
    assert len(failed) == 5
    _same_response(ds, ref)


@pytest.mark.slow
def test_bevel_pair_with_hill_multipliers_jumps_at_its_folds():
    """The issue's case: the 8-DOF bevel pair's branch with Hill's multipliers has points of undecided stability
    inside its stable segments (ω ≈ 0.900 and 0.923 at H = 16); the jumps are at its two folds all the same."""
    from geardyn.analysis.hb import hb_continuation
    from geardyn.systems import load_system

    s = load_system(Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_bevel_8dof.toml")
    res = hb_continuation(s, "omega", 0.6, 1.2, harmonics=16, floquet="hill")
    assert np.any(res.status == int(Status.UNRESOLVED))
    ds = R.response_from_branch(res, np.linspace(0.6, 1.2, 61))
    folds = sorted(b.value for b in res.of_type("fold"))
    jumps = json.loads(ds.attrs["jumps"])
    assert len(folds) == 2 and sorted(j["omega"] for j in jumps) == folds
    assert json.loads(ds.attrs["hysteresis"]) == [folds]
    ns = min(b.value for b in res.of_type("neimark-sacker"))
    w = ds["omega"].values
    assert np.all(ds["status"].values[:, w < ns] == int(Status.OK))  # every grid point below the torus filled
