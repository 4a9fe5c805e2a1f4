"""Periodic orbits: shooting, Floquet analysis, continuation, bifurcations (issue 4).

The default run takes well under a minute once the kernel is compiled; the ω-sweeps of the
closing note for ξ0 = 0.08 and 0.1 and the stability-boundary comparison are marked ``slow``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg

from geardyn.analysis import periodic as P
from geardyn.model import GearModel, IntegrationOptions

#: The linear limit: no backlash (D = 0: always in contact), constant coefficients.
LINEAR = dict(D=0.0, xi=(), kappa=(), fp=0.2, eps=(0.5,))


def linear_amplitude(omega: float, xi0: float, eps: float = 0.5) -> float:
    """Steady amplitude of u'' + 2ξ0 u' + u = f_p + ε ω² cos θ."""
    return eps * omega**2 / math.hypot(1.0 - omega**2, 2.0 * xi0 * omega)


@pytest.fixture(scope="module")
def branch_008():
    """Continuation of the paper's defaults with ξ0 = 0.08 over ω ∈ [0.3, 1.0] (accurate mode)."""
    return P.continuation(GearModel(xi0=0.08), "omega", 0.3, 1.0, 1)


# ------------------------------------------------------------------------------------ Floquet
def test_floquet_classification():
    f = P.floquet(np.diag([0.5, -0.3]), 1, 2.0)
    assert f.stable and f.instability == "none" and f.crossing is None
    assert np.allclose(f.exponents, np.log([0.5, 0.3]) / 2.0)
    assert P.floquet(np.diag([1.5, 0.2]), 1, 1.0).instability == "saddle"
    assert P.floquet(np.diag([1.5, 0.2]), 1, 1.0).crossing == "fold"
    assert P.floquet(np.diag([-1.5, 0.2]), 1, 1.0).crossing == "period-doubling"
    rot = 1.1 * np.array([[math.cos(1.0), -math.sin(1.0)], [math.sin(1.0), math.cos(1.0)]])
    f = P.floquet(rot, 1, 1.0)
    assert f.instability == "unstable-focus" and f.crossing == "neimark-sacker"
    assert P.floquet(np.diag([2.0, -3.0]), 1, 1.0).instability == "repeller"


def test_paper_stability_damping_value():
    assert P.paper_stability_damping(0.2) == pytest.approx(0.5 * math.sqrt(0.96), rel=1e-15)
    assert P.paper_stability_damping(0.0) == 0.5
    cond = P.paper_stability_condition(GearModel())
    assert cond["xi0_paper"] == pytest.approx(0.4898979485566356)
    assert cond["above_paper_condition"] is False
    with pytest.raises(ValueError, match="kappa1"):
        P.paper_stability_damping(1.5)


# ----------------------------------------------------------------------------------- shooting
@pytest.mark.parametrize("omega", [0.6, 1.3])
@pytest.mark.parametrize("n", [1, 2])
@pytest.mark.parametrize("accurate", [False, True])
def test_linear_multipliers_equal_matrix_exponential(omega, n, accurate):
    xi0 = 0.05
    m = GearModel(omega=omega, xi0=xi0, **LINEAR)
    orb = P.shoot(m, n, accurate=accurate)
    assert orb.converged
    A = np.array([[0.0, 1.0], [-1.0, -2.0 * xi0]])
    exact = scipy.linalg.expm(A * n * m.period)
    assert np.max(np.abs(orb.monodromy - exact)) < 1e-7
    mu = np.sort_complex(orb.multipliers)
    mu_exact = np.sort_complex(np.linalg.eigvals(exact))
    assert np.max(np.abs(mu - mu_exact)) < 1e-7
    # the orbit itself is the closed-form steady state u = f_p + A cos(θ − φ)
    assert orb.amplitude == pytest.approx(linear_amplitude(omega, xi0), rel=1e-7)
    assert orb.minimal_period == 1 and orb.stable


def test_shooting_converges_quadratically_to_an_unstable_orbit():
    # ω = 0.8, ξ0 = 0.08: the period-1 orbit is a flip saddle (the attractor is period-2)
    m = GearModel(omega=0.8, xi0=0.08)
    orb = P.shoot(m, 1, guess=(1.2, 0.0))
    assert orb.converged and orb.iterations <= 8
    r = orb.residuals
    assert r[-1] < 1e-12
    quad = [(a, b) for a, b in zip(r[:-1], r[1:]) if 1e-13 < b and a < 1e-2]
    assert quad, r
    assert all(b <= 50.0 * a * a for a, b in quad), r
    fl = orb.floquet
    assert not orb.stable and fl.instability == "flip-saddle" and fl.multipliers[0].real < -1.0


def test_guess_from_simulation_and_minimal_period():
    m = GearModel(omega=0.8, xi0=0.08)
    two = P.shoot(m, 2)
    assert two.converged and two.minimal_period == 2 and two.stable
    four = P.shoot(m, 4, guess=two.state)  # the period-2 orbit solves P^4 x = x too
    assert four.converged and four.minimal_period == 2
    js = two.to_json()
    for key in ("state", "points", "period", "multipliers", "stable", "u_min", "u_max", "impact", "converged"):
        assert key in js
    assert len(js["points"]) == 2 and js["period"] == 2
    assert js["impact"] == "single-sided impact"


@pytest.mark.parametrize("omega,n", [(0.7, 1), (0.8, 2), (0.9, 4), (0.99, 1)])
@pytest.mark.parametrize("accurate", [False, True])
def test_determinant_on_nonsmooth_orbits(omega, n, accurate):
    """det M = exp(−2ξ0 nT) (the damping harmonic averages out) on orbits with contact loss."""
    m = GearModel(omega=omega, xi0=0.08)
    guess = P.shoot(m, n).state if n > 1 else (1.2, 0.0)
    orb = P.shoot(m, n, guess=guess, accurate=accurate)
    assert orb.converged
    assert orb.u_min < m.D  # the orbit leaves drive-side contact: a non-smooth orbit
    det = float(np.linalg.det(orb.monodromy))
    assert det == pytest.approx(math.exp(-2.0 * m.xi0 * n * m.period), rel=1e-6)


@pytest.mark.parametrize("omega,n", [(0.75, 1), (0.8, 2), (0.9, 4), (0.5, 1)])
def test_largest_lyapunov_exponent_equals_floquet(omega, n):
    """λ1 of the chaos-diagnostics module = ln|μ_max|/(nT) for a stable period-n orbit."""
    from geardyn.analysis.lyapunov import lyapunov_spectrum

    m = GearModel(omega=omega, xi0=0.08)
    orb = P.shoot(m, n)
    assert orb.converged and orb.stable and orb.minimal_period == n
    expected = math.log(orb.floquet.max_modulus) / (n * m.period)
    lyap = lyapunov_spectrum(m, IntegrationOptions(transient=0, periods=4000), state0=orb.state, classify=False)
    err = float(lyap.uncertainty[0])
    assert abs(lyap.exponents[0] - expected) <= max(4.0 * err, 1e-8), (lyap.exponents, expected, err)
    assert orb.floquet.exponents[0] == pytest.approx(expected)


# ------------------------------------------------------------------------------- continuation
def test_linear_continuation_matches_closed_form_amplitude():
    xi0 = 0.1
    res = P.continuation(GearModel(xi0=xi0, **LINEAR), "omega", 0.5, 1.5, 1)
    assert len(res.branches) == 1
    br = res.branches[0]
    assert br.values[0] == pytest.approx(0.5) and br.values[-1] == pytest.approx(1.5)
    assert len(br) > 40
    exact = np.array([linear_amplitude(w, xi0) for w in br.values])
    assert np.max(np.abs(br.amplitude / exact - 1.0)) < 1e-6
    # the resonance peak is resolved (the branch passes through ω = 1 with A ≈ ε/(2ξ0))
    assert br.amplitude.max() == pytest.approx(0.5 / (2 * xi0), rel=2e-2)
    assert res.bifurcations == [] and bool(np.all(br.stable))
    # multipliers of the linear oscillator: exp((−ξ0 ± i√(1−ξ0²))T)
    T = 2 * np.pi / br.values
    mu = np.abs(br.multipliers[:, 0])
    assert np.allclose(mu, np.exp(-xi0 * T), rtol=1e-7)


def test_continuation_downwards_and_in_other_parameters():
    xi0 = 0.05
    m = GearModel(omega=1.2, xi0=xi0, **LINEAR)
    res = P.continuation(m, "omega", 1.2, 1.05, 1, switch=False)
    br = res.branches[0]
    assert br.values[0] == pytest.approx(1.2) and br.values[-1] == pytest.approx(1.05)
    assert np.all(np.diff(br.values) < 0)
    # in ξ0: the amplitude at ω = 0.9 follows the closed form as the damping changes
    res = P.continuation(GearModel(omega=0.9, xi0=0.2, **LINEAR), "xi0", 0.2, 0.1, 1)
    br = res.branches[0]
    exact = np.array([linear_amplitude(0.9, x) for x in br.values])
    assert np.max(np.abs(br.amplitude / exact - 1.0)) < 1e-6


def test_neimark_sacker_where_the_damping_changes_sign():
    """Linear oscillator, continuation in ξ0 through 0: the complex pair exp((−ξ0 ± iω_d)T) crosses the unit circle."""
    m = GearModel(omega=0.7, xi0=0.05, **LINEAR)
    res = P.continuation(m, "xi0", 0.05, -0.05, 1)
    ns = res.of_type("neimark-sacker")
    assert len(ns) == 1 and ns[0].located
    assert abs(ns[0].value) < 1e-7
    assert np.all(np.abs(np.abs(ns[0].multipliers) - 1.0) < 1e-6)
    assert [b.type for b in res.bifurcations] == ["neimark-sacker"]


def test_folds_bracket_the_hysteresis_of_up_down_sweeps(branch_008):
    """ξ0 = 0.08: the two folds of the period-1 branch bracket the interval where the up and down
    sweeps end on different attractors, each to within one grid step."""
    from geardyn.analysis.response import frequency_response, hysteresis_intervals

    folds = sorted(b.value for b in branch_008.of_type("fold", n=1))
    assert len(folds) == 2
    f_low, f_high = folds
    step = 0.005
    grid = np.round(np.arange(0.50, 0.64 + step / 2, step), 6)
    resp = frequency_response(
        GearModel(xi0=0.08),
        float(grid[0]),
        float(grid[-1]),
        grid.size,
        options=IntegrationOptions(transient=300, periods=16),
    )
    hyst = hysteresis_intervals(resp)
    assert len(hyst) == 1, hyst
    w_a, w_b = hyst[0]
    # the interval's bounds are the midpoints of the grid steps where the sweeps jump: the fold where the
    # upper branch ends lies within half a step of w_a, the fold where the lower one ends within half a step of w_b
    assert abs(f_low - w_a) <= step / 2 + 1e-9, (f_low, hyst)
    assert abs(f_high - w_b) <= step / 2 + 1e-9, (f_high, hyst)
    # the middle branch between the folds is unstable, the outer ones stable
    br = branch_008.branches[0]
    i_lo = int(np.argmin(np.abs(br.values - f_low) + (br.amplitude < 0.8) * 10))
    assert br.stable[i_lo - 3] and not br.stable[i_lo + 3] or not br.stable[i_lo - 3] and br.stable[i_lo + 3]
    mid = (br.values > f_low + 0.01) & (br.values < f_high - 0.01) & (br.amplitude > 0.4) & (br.amplitude < 1.0)
    assert mid.any() and not br.stable[mid].any()


def test_period_doubling_where_brute_force_turns_period_two(branch_008):
    pds = [b for b in branch_008.of_type("period-doubling", n=1) if b.value > 0.7]
    assert len(pds) == 1
    w_pd = pds[0].value
    assert 0.74 < w_pd < 0.78
    # brute force (same accurate mode, long transient because the multiplier is near −1)
    from geardyn.analysis.classify import detect_period
    from geardyn.integrate import integrate_batch

    grid = np.array([0.750, 0.755, 0.760, 0.765])
    opts = IntegrationOptions(transient=3000, periods=16, accurate=True)
    res = integrate_batch([GearModel(xi0=0.08, omega=float(w)) for w in grid], (1.2, 0.0), opts)
    periods = np.array([detect_period(res.poincare[i], tol=1e-6) for i in range(grid.size)])
    assert set(periods) <= {1, 2}, periods
    last1 = grid[periods == 1].max()
    first2 = grid[periods == 2].min()
    assert np.all(grid[periods == 1] < first2)  # period 1 below, period 2 above
    assert last1 < w_pd < first2, (w_pd, grid, periods)


def test_branch_switching_onto_the_period_two_branch(branch_008):
    two = [b for b in branch_008.branches if b.n == 2 and b.origin is not None and b.origin.value > 0.7]
    assert len(two) == 1
    br = two[0]
    assert br.values.min() == pytest.approx(br.origin.value, abs=1e-9)
    assert br.values.max() == pytest.approx(1.0)
    # the branch passes ω = 0.8; corrected there it is the stable period-2 orbit that simulation reaches
    i = int(np.argmin(np.abs(br.values - 0.8)))
    assert abs(br.values[i] - 0.8) < 0.01
    m = GearModel(xi0=0.08, omega=0.8)
    on_branch = P.shoot(m, 2, guess=br.states[i], accurate=True)
    from_sim = P.shoot(m, 2, accurate=True)
    assert on_branch.converged and from_sim.converged and from_sim.stable and from_sim.minimal_period == 2
    d = min(np.abs(on_branch.points - from_sim.points).max(), np.abs(on_branch.points[::-1] - from_sim.points).max())
    assert d < 1e-8
    # period-4 branch born on the period-2 branch and merging back into it
    four = [b for b in branch_008.branches if b.n == 4 and b.end.startswith("merged")]
    assert len(four) == 1
    pd2 = sorted(b.value for b in branch_008.of_type("period-doubling", n=2))
    assert pd2[0] == pytest.approx(four[0].values.min(), abs=1e-6)
    assert pd2[1] == pytest.approx(four[0].values.max(), abs=1e-4)


def test_grazing_is_located_on_the_contact_boundary(branch_008):
    gz = [b for b in branch_008.of_type("grazing") if b.n == 1]
    assert gz, branch_008.bifurcations
    g = gz[0]
    assert 0.55 < g.value < 0.6
    assert abs(g.u_min - 1.0) < 1e-7
    umin, _ = P.orbit_extrema(GearModel(xi0=0.08, omega=g.value), g.state, 1, accurate=True)
    assert abs(umin - 1.0) < 1e-7


def test_continuation_dataset_and_json(branch_008, tmp_path):
    from geardyn.io import read_netcdf, write_netcdf

    js = branch_008.to_json()
    assert js["param"] == "omega"
    pt = js["branch"][0]
    for key in ("omega", "amplitude", "stable", "multipliers"):
        assert key in pt
    assert {b["type"] for b in js["bifurcations"]} <= set(P.BIFURCATION_TYPES)
    assert all("omega" in b for b in js["bifurcations"])
    ds = branch_008.to_dataset()
    for v in ("omega", "amplitude", "stable", "multiplier_re", "poincare_u", "bifurcation_type"):
        assert "units" in ds[v].attrs and "long_name" in ds[v].attrs
    assert json.loads(ds.attrs["model"])["xi0"] == 0.08
    back = read_netcdf(write_netcdf(ds, tmp_path / "c.nc"))
    assert back.sizes["point"] == ds.sizes["point"]


def test_default_mode_continuation_agrees_with_accurate_mode():
    """Default mode: the same bifurcations, displaced by the discretisation (its multipliers jump by
    O(Δτ) where RK4 stages cross ±D; back-and-forth crossings are filtered)."""
    m = GearModel(xi0=0.08)
    acc = P.continuation(m, "omega", 0.55, 0.65, 1, switch=False)
    dft = P.continuation(m, "omega", 0.55, 0.65, 1, switch=False, accurate=False)
    ta = [(b.type, b.value) for b in acc.bifurcations]
    td = [(b.type, b.value) for b in dft.bifurcations]
    assert [t for t, _ in ta] == [t for t, _ in td], (ta, td)
    for (_, a), (_, d) in zip(ta, td):
        assert abs(a - d) < 2e-3


# ------------------------------------------------------------------------------- command line
def run_cli(capsys, *args):
    from geardyn.cli import main

    code = 0
    try:
        main(list(args))
    except SystemExit as e:
        code = int(e.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_orbit_json(capsys):
    code, out, _ = run_cli(capsys, "orbit", "--omega", "0.8", "--xi0", "0.08", "--period", "2", "--json")
    assert code == 0
    js = json.loads(out)
    for key in ("state", "points", "period", "multipliers", "stable", "u_min", "u_max", "impact", "converged"):
        assert key in js
    assert js["converged"] and js["stable"] and js["period"] == 2
    assert len(js["points"]) == 2 and len(js["multipliers"]) == 2 and len(js["multipliers"][0]) == 2


def test_cli_continuation_json_and_files(capsys, tmp_path):
    code, out, _ = run_cli(
        capsys,
        "continuation",
        "--param",
        "omega",
        "--start",
        "0.65",
        "--stop",
        "0.5",
        "--xi0",
        "0.08",
        "--no-switch",
        "--sweep-num",
        "6",
        "--transient",
        "100",
        "--out",
        str(tmp_path),
        "--json",
    )
    assert code == 0
    js = json.loads(out)
    assert js["branch"] and all({"omega", "amplitude", "stable", "multipliers"} <= set(p) for p in js["branch"])
    assert js["branch"][0]["omega"] == pytest.approx(0.65) and js["branch"][-1]["omega"] == pytest.approx(0.5)
    assert sum(b["type"] == "fold" for b in js["bifurcations"]) == 2
    assert any(not p["stable"] for p in js["branch"])
    names = {p.split("/")[-1] for p in js["files"]}
    assert {"continuation.nc", "continuation_sweep.nc", "continuation.png"} <= names
    assert (tmp_path / "continuation.png").stat().st_size > 0


def test_cli_continuation_first_orbit_settles_for_transient_periods(capsys, monkeypatch):
    """--transient is the settling of the simulation that gives the first orbit's guess (as for orbit), not only
    of the sweep drawn under the figure."""
    import sys

    C = sys.modules["geardyn.analysis.periodic.continuation"]
    seen = []

    def shoot(*a, **kw):
        seen.append(kw.get("transient"))
        return real(*a, **kw)

    real = C.shoot
    monkeypatch.setattr(C, "shoot", shoot)
    code, _, err = run_cli(
        capsys,
        "continuation",
        "--param",
        "omega",
        "--start",
        "0.65",
        "--stop",
        "0.64",
        "--xi0",
        "0.08",
        "--no-switch",
        "--transient",
        "37",
        "--json",
    )
    assert code == 0, err
    assert seen == [37]


@pytest.mark.parametrize(
    "args,name",
    [
        (("orbit", "--omega", "-1"), "omega"),
        (("orbit", "--guess", "1,x"), "guess"),
        (("orbit", "--period", "0"), "period"),
        (("continuation", "--param", "nope", "--start", "0.3", "--stop", "1"), "parameter"),
        (("continuation", "--param", "omega", "--start", "0.3", "--stop", "0.3"), "stop"),
        (("continuation", "--param", "D", "--start", "1", "--stop", "-1"), "D"),
        (("continuation", "--param", "omega", "--start", "0.3", "--stop", "1", "--max-period", "0"), "max-period"),
    ],
)
def test_cli_bad_input(capsys, args, name):
    code, out, err = run_cli(capsys, *args, "--json")
    assert code == 2
    assert out == ""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and name in lines[0]


# ------------------------------------------------------------------------------- long studies
def _summary(res):
    return [(b.type, b.n, round(b.value, 6)) for b in res.bifurcations]


@pytest.mark.slow
def test_closing_note_bifurcations_xi0_010():
    res = P.continuation(GearModel(xi0=0.1), "omega", 0.3, 1.0, 1)
    folds = sorted(b.value for b in res.of_type("fold", n=1))
    assert len(folds) == 2 and 0.54 < folds[0] < 0.57 and 0.61 < folds[1] < 0.63
    pd = [b.value for b in res.of_type("period-doubling", n=1)]
    assert len(pd) == 1 and 0.77 < pd[0] < 0.80
    print(_summary(res))


@pytest.mark.slow
def test_stability_boundary_against_paper_condition():
    ds = P.compare_stability_condition(GearModel(), np.round(np.arange(0.3, 2.501, 0.1), 6))
    paper = float(ds["xi0_paper"])
    crit = ds["xi0_critical"].values
    lin = ds["xi0_critical_linear"].values
    # the paper's ½√(1 − κ1²) = 0.49 is far above every Floquet boundary found
    assert np.nanmax(crit) < 0.5 * paper
    assert np.nanmax(lin) < 0.2 * paper
    # the linear contact model is unstable only inside the parametric tongues (principal one at ω ≈ 2)
    assert float(ds["omega"].values[np.nanargmax(lin)]) == pytest.approx(2.0, abs=0.11)
