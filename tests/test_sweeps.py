"""Bifurcation sweeps, frequency response (jumps and hysteresis), maps and basins.

The hysteresis case is the forced backlash oscillator with constant mesh coefficients (κ1 = ξ1 = 0,
ξ0 = 0.1, f_p = 0.2, ε1 = 0.5, D = 1).  Its softening (loss of contact) bends the resonance to
low frequencies: a low, grazing branch and a high, impacting branch coexist between two folds.
The folds are computed independently here from the exact piecewise-linear solution (closed form
in each contact region, crossing times by root finding) and the continuation sweeps up and down
must jump across them and report the interval between them.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from scipy.optimize import brentq, fsolve, minimize_scalar

from geardyn.analysis.basins import basins, basins_json
from geardyn.analysis.bifurcation import bifurcation, bifurcation_json
from geardyn.analysis.classify import MOTION_PERIODIC
from geardyn.analysis.maps import map_json, parameter_map
from geardyn.analysis.response import detect_jumps, frequency_response, hysteresis_intervals, response_json
from geardyn.io import read_netcdf, write_netcdf
from geardyn.model import GearModel, IntegrationOptions, ModelError

XI0, FP, EPS, D = 0.1, 0.2, 0.5, 1.0
SOFT = GearModel(xi0=XI0, xi=(0.0,), kappa=(0.0,), fp=FP, eps=(EPS,), D=D)
FAST = IntegrationOptions(transient=300, periods=64)


# ------------------------------------------------------------------ exact piecewise-linear reference
class PiecewiseLinear:
    """Exact solution of u'' + 2ξ0 u' + f(u; D) = f_p + ω² ε cos(ωτ) (constant coefficients)."""

    def __init__(self, omega: float) -> None:
        self.w = omega
        self.A = omega**2 * EPS
        self.wd = np.sqrt(1.0 - XI0**2)

    def _particular(self, k: float) -> tuple[float, float]:
        w = self.w
        M = np.array([[k - w * w, 2 * XI0 * w], [-2 * XI0 * w, k - w * w]])
        X, Y = np.linalg.solve(M, [self.A, 0.0])
        return X, Y

    def segment(self, r: int, t0: float, u0: float, v0: float):
        """u(t), u'(t) in contact region r (1 drive side, 0 separation, -1 back side) from (u0, v0) at t0."""
        k = 1.0 if r else 0.0
        w = self.w
        X, Y = self._particular(k)
        off = r * D

        def part(t):
            p = X * np.cos(w * t) + Y * np.sin(w * t)
            dp = w * (-X * np.sin(w * t) + Y * np.cos(w * t))
            return (FP + p, dp) if k else (FP / (2 * XI0) * t + p, FP / (2 * XI0) + dp)

        p0, dp0 = part(t0)
        W0, V0 = u0 - off - p0, v0 - dp0
        if k:
            C1, C2 = W0, (V0 + XI0 * W0) / self.wd

            def f(t):
                s = t - t0
                e, c, sn = np.exp(-XI0 * s), np.cos(self.wd * s), np.sin(self.wd * s)
                p, dp = part(t)
                return (
                    off + p + e * (C1 * c + C2 * sn),
                    dp + e * (-XI0 * (C1 * c + C2 * sn) + self.wd * (-C1 * sn + C2 * c)),
                )
        else:
            C2 = -V0 / (2 * XI0)
            C1 = W0 - C2

            def f(t):
                e = np.exp(-2 * XI0 * (t - t0))
                p, dp = part(t)
                return off + p + C1 + C2 * e, dp - 2 * XI0 * C2 * e

        return f

    def period_map(self, x, samples: int = 400) -> np.ndarray:
        T = 2 * np.pi / self.w
        t, u, v = 0.0, float(x[0]), float(x[1])
        r = 1 if (u > D or (u == D and v > 0)) else (-1 if (u < -D or (u == -D and v < 0)) else 0)
        for _ in range(64):
            f = self.segment(r, t, u, v)
            ts = np.linspace(t, T, max(int(samples * (T - t) / T), 8))
            us = f(ts)[0]
            hit = None
            for b in (D, -D) if r == 0 else (r * D,):
                g = us - b
                for i in np.flatnonzero(np.sign(g[1:]) != np.sign(g[:-1])):
                    lo = max(ts[i], t + 1e-12)
                    if np.sign(f(lo)[0] - b) == np.sign(f(ts[i + 1])[0] - b):
                        continue
                    tc = brentq(lambda s: f(s)[0] - b, lo, ts[i + 1], xtol=1e-15, rtol=1e-15)
                    if hit is None or tc < hit[0]:
                        hit = (tc, b)
                    break
            if hit is None:
                return np.array(f(T))
            t, u = hit
            v = f(t)[1]
            r = (1 if u > 0 else -1) if r == 0 else 0
        raise RuntimeError("too many contact changes in one period")


def _branch_omega(u0: float, guess: list[float]) -> float:
    """ω of the period-1 orbit through Poincaré point (u0, v0), solving for (v0, ω) from ``guess``."""

    def G(z):
        y = PiecewiseLinear(z[1]).period_map((u0, z[0]))
        return [y[0] - u0, y[1] - z[0]]

    z, info, ier, _ = fsolve(G, guess, full_output=True, xtol=1e-13)
    assert np.max(np.abs(info["fvec"])) < 1e-10, (u0, guess, ier)
    guess[:] = list(z)
    return float(z[1])


def reference_folds() -> tuple[float, float]:
    """(ω of the high branch's fold, ω of the low branch's fold): the extremes of ω along each branch."""
    g = [0.05, 0.59]  # low branch near its fold (v0, ω), from u0 = 1.53
    _branch_omega(1.53, g)
    low = minimize_scalar(
        lambda u: -_branch_omega(u, g), bounds=(1.55, 1.62), method="bounded", options={"xatol": 1e-7}
    )
    g = [0.6, 0.55]  # high branch (v0, ω) from u0 = 0.35
    for u in np.arange(0.35, 0.80, 0.05):
        _branch_omega(u, g)
    high = minimize_scalar(
        lambda u: _branch_omega(u, g), bounds=(0.75, 0.95), method="bounded", options={"xatol": 1e-7}
    )
    return float(high.fun), float(-low.fun)


#: The folds from :func:`reference_folds` (recomputed and checked in the slow test).
FOLD_HIGH, FOLD_LOW = 0.540651, 0.595003


def test_piecewise_linear_reference_matches_kernel_map():
    from geardyn.integrate import period_map

    for x in ((1.0, 0.0), (2.0, 0.5), (0.0, 0.0), (-1.5, 1.0)):
        ref = PiecewiseLinear(0.6).period_map(x)
        got = period_map(SOFT.replace(omega=0.6), x, 1, dtau=0.002, accurate=True)[0][-1]
        assert np.allclose(got, ref, atol=1e-9)


# ------------------------------------------------------------------ jumps and hysteresis
GRID = np.round(np.arange(0.503, 0.64, 0.01), 6)  # keeps ≥ 0.002 away from both folds


@pytest.fixture(scope="module")
def soft_response() -> xr.Dataset:
    return frequency_response(SOFT, float(GRID[0]), float(GRID[-1]), GRID.size, options=FAST)


def test_continuation_sweeps_reproduce_the_hysteresis_interval(soft_response):
    ds = soft_response
    assert list(ds["sweep"].values) == ["up", "down"]
    hy = json.loads(ds.attrs["hysteresis"])
    # the interval runs between the midpoints of the grid steps that hold the two folds (where the jumps are
    # reported), so each bound lies within half a grid step of its exact fold
    a_in, a_out = GRID[GRID > FOLD_HIGH].min(), GRID[GRID < FOLD_HIGH].max()
    b_in, b_out = GRID[GRID < FOLD_LOW].max(), GRID[GRID > FOLD_LOW].min()
    assert hy == [[pytest.approx(0.5 * (a_out + a_in)), pytest.approx(0.5 * (b_in + b_out))]]
    half = 0.5 * float(np.diff(GRID).max())
    assert abs(hy[0][0] - FOLD_HIGH) <= half and abs(hy[0][1] - FOLD_LOW) <= half
    assert json.loads(ds.attrs["coexistence"]) == []
    # inside: two different period-1 attractors; the high one impacts, the low one barely separates
    w = float(GRID[(GRID > FOLD_HIGH) & (GRID < FOLD_LOW)][2])
    up, down = ds.sel(omega=w, sweep="up"), ds.sel(omega=w, sweep="down")
    assert int(up["motion"]) == int(down["motion"]) == MOTION_PERIODIC
    assert float(down["amplitude"]) > 4 * float(up["amplitude"])


def test_jumps_at_the_folds(soft_response):
    jumps = json.loads(soft_response.attrs["jumps"])
    assert len(jumps) == 2
    up = next(j for j in jumps if j["sweep"] == "up")
    down = next(j for j in jumps if j["sweep"] == "down")
    assert up["direction"] == "up" and up["omega_from"] < FOLD_LOW < up["omega_to"]
    assert down["direction"] == "down" and down["omega_to"] < FOLD_HIGH < down["omega_from"]
    assert up["size"] > 0.8 and down["size"] > 0.8
    s = response_json(soft_response)
    assert set(s) >= {"jumps", "hysteresis"}
    assert set(s["jumps"][0]) >= {"omega", "direction", "size", "sweep"}


def test_jump_detection_synthetic():
    x = np.linspace(0.0, 1.0, 41)
    up = np.where(x < 0.61, 0.2 + 0.1 * x, 1.5 - 0.2 * x)
    down = np.where(x < 0.41, 0.2 + 0.1 * x, 1.5 - 0.2 * x)
    noisy = up.copy()
    band = x > 0.75  # scatter (as of chaotic amplitudes): no jumps
    noisy[band] += 0.15 * np.where(np.arange(band.sum()) % 2, 1.0, -1.0) * (1 + 0.3 * np.sin(37 * x[band]))
    ds = xr.Dataset(
        {"amplitude": (("sweep", "omega"), np.stack([noisy, down]))},
        coords={"sweep": ["up", "down"], "omega": x},
        attrs={"param": "omega"},
    )
    j = detect_jumps(ds)
    assert [(d["sweep"], d["direction"]) for d in j] == [("up", "up"), ("down", "down")]
    assert [d["omega"] for d in j] == [pytest.approx(0.6125), pytest.approx(0.4125)]
    assert j[0]["size"] == pytest.approx(abs(up[25] - up[24]))


def test_response_refuses_bad_grid():
    with pytest.raises(ModelError, match="omega"):
        frequency_response(SOFT, -0.5, 1.0, 5)
    with pytest.raises(ModelError, match="measure"):
        frequency_response(SOFT, 0.5, 1.0, 5, measure="loudness")


# ------------------------------------------------------------------ bifurcation sweeps
def test_fixed_sweep_dataset_and_json(tmp_path):
    vals = [0.5, 0.8, 1.2]
    ds = bifurcation(GearModel(), "omega", vals, options=FAST, lyapunov=True)
    assert ds["poincare_u"].dims == ("sweep", "omega", "section") and ds.sizes["section"] == 64
    assert list(ds["sweep"].values) == ["fixed"]
    s = bifurcation_json(ds)
    assert s["param"] == "omega" and s["values"] == vals
    assert s["motion"] == ["period-1", "period-2", "chaotic"]
    assert s["period"] == [1, 2, None] and len(s["impact"]) == 3
    assert all(np.isfinite(s["lle"])) and s["lle"][2] > 0
    p = write_netcdf(ds, tmp_path / "b.nc")
    back = read_netcdf(p)
    xr.testing.assert_identical(back.drop_attrs(), ds.drop_attrs())
    assert back["lle"].attrs["units"] == "1/τ"


def test_fixed_sweep_independent_of_chunking():
    vals = np.linspace(0.9, 1.3, 7)
    a = bifurcation(GearModel(), "omega", vals, options=FAST, chunk_points=2)
    b = bifurcation(GearModel(), "omega", vals, options=FAST, chunk_points=16)
    xr.testing.assert_identical(a, b)


def test_sweep_any_parameter_and_down_direction():
    ds = bifurcation(GearModel(omega=0.8), "backlash", [0.5, 1.0], mode="continue", sweep="down", options=FAST)
    assert "D" in ds.dims and list(ds["sweep"].values) == ["down"]
    # the down sweep starts at the largest value from (u0, v0) and continues to the smaller one
    assert list(ds["state"].values) == ["u", "u'"]
    assert np.allclose(ds["start_state"].sel(D=1.0), 0.0)
    np.testing.assert_array_equal(ds["start_state"].sel(D=0.5), ds["end_state"].sel(D=1.0))
    ds = bifurcation(GearModel(), "phi_k1", [0.0, 1.0], options=FAST)
    assert ds["phi_k1"].attrs["units"] == "rad"
    with pytest.raises(ModelError, match="mode"):
        bifurcation(GearModel(), "omega", [1.0], mode="sideways")
    with pytest.raises(ModelError, match="unknown parameter"):
        bifurcation(GearModel(), "speed", [1.0])


def test_continuation_restarts_after_divergence():
    ds = bifurcation(GearModel(omega=0.8), "xi0", [-0.2, 0.1], mode="continue", sweep="up", options=FAST)
    st = ds["status"].sel(sweep="up").values
    assert st.tolist() == [1, 0]
    assert int(ds["restarted"].sel(sweep="up", xi0=0.1)) == 1
    assert bifurcation_json(ds)["motion"] == ["diverged", "period-2"]


# ------------------------------------------------------------------ maps and basins
def test_parameter_map_fixed_and_continue():
    xs, ys = [0.6, 0.8, 1.2], [0.08, 0.12]
    a = parameter_map(GearModel(), "omega", xs, "xi0", ys, options=FAST)
    assert a["motion"].dims == ("xi0", "omega") and a["motion"].shape == (2, 3)
    s = map_json(a)
    assert s["x"] == "omega" and s["y"] == "xi0" and len(s["motion"]) == 2 and len(s["motion"][0]) == 3
    assert s["motion"][0][1] == "period-2"
    b = parameter_map(GearModel(), "omega", xs, "xi0", ys, mode="continue", options=FAST)
    assert b["motion"].shape == (2, 3)
    with pytest.raises(ModelError, match="different"):
        parameter_map(GearModel(), "omega", xs, "omega", ys)


def test_basins_identify_the_coexisting_attractors(soft_response):
    w = float(GRID[(GRID > FOLD_HIGH) & (GRID < FOLD_LOW)][2])
    ds = basins(SOFT.replace(omega=w), (-2.5, 2.5), (-2.0, 2.0), 7, 6, options=FAST)
    assert ds["attractor"].shape == (6, 7)
    s = basins_json(ds)
    assert len(s["attractors"]) == 2 and all(a["motion"] == "period-1" for a in s["attractors"])
    assert sum(a["fraction"] for a in s["attractors"]) == pytest.approx(1.0)
    # the two attractors are the end states of the up and down sweeps at this ω
    pts = np.array([a["points"][0] for a in s["attractors"]])
    for lab in ("up", "down"):
        r = soft_response.sel(omega=w, sweep=lab)
        x = np.array([float(r["poincare_u"][-1]), float(r["poincare_v"][-1])])
        assert np.min(np.max(np.abs(pts - x), axis=1)) < 1e-4


# ------------------------------------------------------------------ CLI
def test_cli_json_keys(tmp_path):
    from typer.testing import CliRunner

    from geardyn.cli import app

    run = CliRunner()
    r = run.invoke(app, ["lyapunov", "--omega", "1.2", "--transient", "100", "--periods", "200", "--json"])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert len(s["exponents"]) == 2 and len(s["uncertainty"]) == 2
    assert abs(sum(s["exponents"]) + 0.2) < 1e-6
    r = run.invoke(
        app,
        [
            "bifurcation",
            "--param",
            "omega",
            "--start",
            "0.8",
            "--stop",
            "1.2",
            "--num",
            "2",
            "--transient",
            "100",
            "--periods",
            "64",
            "--lyapunov",
            "--json",
            "--out",
            str(tmp_path / "bif"),
        ],
    )
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert {"param", "values", "period", "motion", "impact", "lle"} <= set(s)
    assert (tmp_path / "bif" / "bifurcation.nc").exists() and (tmp_path / "bif" / "bifurcation.png").exists()
    assert not (tmp_path / "bif" / "bifurcation.nc.chunks").exists()
    r = run.invoke(
        app,
        [
            "response",
            "--omega-start",
            "0.50",
            "--omega-stop",
            "0.62",
            "--num",
            "5",
            "--kappa1",
            "0",
            "--xi1",
            "0",
            "--transient",
            "200",
            "--periods",
            "32",
            "--json",
        ],
    )
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert {"jumps", "hysteresis"} <= set(s)
    r = run.invoke(
        app,
        [
            "map",
            "--x",
            "omega",
            "--x-start",
            "0.6",
            "--x-stop",
            "0.8",
            "--x-num",
            "2",
            "--y",
            "D",
            "--y-start",
            "0.5",
            "--y-stop",
            "1",
            "--y-num",
            "2",
            "--transient",
            "100",
            "--periods",
            "32",
            "--json",
        ],
    )
    assert r.exit_code == 0, r.output
    assert {"x", "y", "motion", "impact", "amplitude", "lle"} <= set(json.loads(r.stdout))
    r = run.invoke(
        app,
        [
            "basins",
            "--omega",
            "0.57",
            "--kappa1",
            "0",
            "--xi1",
            "0",
            "--nu",
            "3",
            "--nv",
            "2",
            "--transient",
            "200",
            "--json",
        ],
    )
    assert r.exit_code == 0, r.output
    assert {"attractors", "labels"} <= set(json.loads(r.stdout))
    r = run.invoke(app, ["bifurcation", "--param", "omega", "--start", "0.8", "--stop", "1.2", "--mode", "sideways"])
    assert r.exit_code == 2


# ------------------------------------------------------------------ slow studies
@pytest.mark.slow
def test_reference_folds_recomputed():
    high, low = reference_folds()
    assert high == pytest.approx(FOLD_HIGH, abs=2e-6)
    assert low == pytest.approx(FOLD_LOW, abs=2e-6)


@pytest.mark.slow
def test_fine_response_brackets_the_folds():
    grid = np.round(np.arange(0.5305, 0.6, 0.002), 6)
    ds = frequency_response(
        SOFT, float(grid[0]), float(grid[-1]), grid.size, options=IntegrationOptions(transient=600, periods=64)
    )
    hy = hysteresis_intervals(ds)
    lo = 0.5 * (grid[grid > FOLD_HIGH].min() + grid[grid < FOLD_HIGH].max())
    hi = 0.5 * (grid[grid < FOLD_LOW].max() + grid[grid > FOLD_LOW].min())
    assert hy == [[pytest.approx(lo), pytest.approx(hi)]]


def test_hysteresis_is_never_zero_width_and_always_has_its_jump():
    """A single grid point of coexisting attractors gives an interval one grid step wide around it, bounded
    by the jumps; attractors that differ with no jump at either bound are listed as coexistence instead."""
    from geardyn.analysis.response import coexistence_intervals

    x = np.round(np.linspace(0.70, 0.80, 11), 6)
    n = x.size
    amp_up = np.where(x < 0.765, 0.3, 1.2)  # the up sweep jumps between 0.76 and 0.77
    amp_down = np.where(x < 0.755, 0.3, 1.2)  # the down sweep jumps between 0.76 and 0.75
    period = np.ones((2, n), np.int64)
    motion = np.full((2, n), MOTION_PERIODIC, np.int64)
    pu = np.stack([amp_up, amp_down])[..., None] * np.ones((1, 1, 4))
    ds = xr.Dataset(
        {
            "amplitude": (("sweep", "omega"), np.stack([amp_up, amp_down])),
            "mean": (("sweep", "omega"), np.zeros((2, n))),
            "status": (("sweep", "omega"), np.zeros((2, n), np.int64)),
            "period": (("sweep", "omega"), period),
            "motion": (("sweep", "omega"), motion),
            "poincare_u": (("sweep", "omega", "section"), pu),
            "poincare_v": (("sweep", "omega", "section"), 0 * pu),
        },
        coords={"sweep": ["up", "down"], "omega": x},
        attrs={"param": "omega", "measure": "amplitude"},
    )
    hy, co = coexistence_intervals(ds)
    assert hy == [[pytest.approx(0.755), pytest.approx(0.765)]] and co == []
    assert hy[0][1] - hy[0][0] == pytest.approx(0.01)
    # the same disagreement at one point with equal amplitudes (no jump in the measure): coexistence only
    same = ds.copy(deep=True)
    same["amplitude"][:] = 0.5
    same["poincare_u"][1, 6] = 2.0  # a different orbit of the same amplitude at ω = 0.76
    hy, co = coexistence_intervals(same)
    assert hy == [] and co == [[pytest.approx(0.755), pytest.approx(0.765)]]
