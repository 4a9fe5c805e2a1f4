"""The pair's harmonic balance with an excitation of P > 1 mesh cycles (harmonics of ω/P, ω the mesh frequency).

Exact theory: a one-cycle series written as a 3-cycle one (harmonic j of ω becomes harmonic 3j of ω/3) is the same
equation, so HB with P = 3 and 3H harmonics has the one-cycle solution's coefficients on the harmonics 3k (zero
elsewhere), the same states, amplitudes, folds and jumps at the same mesh frequency, and the Floquet multipliers of
its forcing period (three mesh periods) are the cubes of the one-cycle ones.  The cracked pinion tooth over one
revolution (P = 20) is checked against shooting (an independent integration of the period map).
"""

import json

import numpy as np
import pytest

from geardyn.analysis.hb import hb_continuation, hb_solve
from geardyn.analysis.hb.equations import DEFAULT_HARMONICS, MAX_DEFAULT_HARMONICS, default_harmonics
from geardyn.analysis.hb.response import response_from_branch
from geardyn.analysis.periodic.orbit import shoot
from geardyn.errors import ModelError
from geardyn.model import GearModel
from geardyn.tooth import Crack, mesh_stiffness, pair_geometry, pair_model


def repeated(m: GearModel, P: int = 3) -> GearModel:
    """``m`` with its series written over P mesh cycles (harmonic j of ω → harmonic P·j of ω/P)."""

    def z(t):
        return tuple(x for v in t for x in (0.0,) * (P - 1) + (v,))

    return m.replace(
        xi=z(m.xi), phi_c=z(m.phi_c), kappa=z(m.kappa), phi_k=z(m.phi_k), eps=z(m.eps), phi_e=z(m.phi_e), cycles=P
    )


def spread(a: np.ndarray, H: int, P: int = 3) -> np.ndarray:
    """Coefficients [a0, a1..aH, b1..bH] of H harmonics as those of P·H harmonics of φ/P."""
    out = np.zeros(2 * P * H + 1)
    k = P * np.arange(1, H + 1)
    out[0], out[k], out[P * H + k] = a[0], a[1 : H + 1], a[H + 1 :]
    return out


@pytest.fixture(scope="module")
def crack():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    ms = mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, 0.5)], points=16)
    m, _sc = pair_model(ms, 1000.0, harmonics=64)
    assert m.cycles == 20 and m.n_harmonics == 64
    return m


@pytest.mark.parametrize("w, n", [(0.7, 1), (1.2, 1), (0.9, 2)])  # stable, unstable (μ = −4.9), period 2
def test_three_cycle_series_equals_the_one_cycle_model(w, n):
    # period n: n forcing periods, 2 mesh periods for P = 1 and 6 for P = 3 (harmonic k of ω/2 is 3k of ω/6)
    m1 = GearModel(omega=w)
    m3 = repeated(m1)
    s1, s3 = hb_solve(m1, period=n), hb_solve(m3, period=n)
    assert s1.status == 0 and s3.status == 0
    assert s3.harmonics == 3 * DEFAULT_HARMONICS  # the default: 16 mesh orders
    np.testing.assert_allclose(s3.coefficients, spread(s1.coefficients, s1.harmonics), rtol=0, atol=1e-10)
    np.testing.assert_allclose(s3.state(), s1.state(), rtol=0, atol=1e-10)
    assert s3.amplitude == pytest.approx(s1.amplitude, abs=1e-10)
    # the forcing period is 3 mesh periods: μ(P = 3) = μ(P = 1)³; the monodromy's relative error is about
    # T ρ STEP_ANGLE⁴/120 (docs/hb.md): 5e-7 over the 6 mesh periods of n = 2 at ω = 0.9, three times that cubed
    assert s1.period == s3.period == n
    np.testing.assert_allclose(s3.multipliers, s1.multipliers**3, rtol=5e-6, atol=1e-9)
    t1, u1 = s1.signal(64)
    t3, u3 = s3.signal(192)
    np.testing.assert_allclose(t3[:64], t1, rtol=1e-14)  # τ over n forcing periods, 3n mesh periods
    for k in range(3):  # the same u in each n mesh periods
        np.testing.assert_allclose(u3[64 * k : 64 * (k + 1)], u1, atol=1e-10)


def test_three_cycle_series_hill_multipliers():
    # Hill's method: the central copies give the same multipliers, to Hill's truncation (~2e-4 at H = 16, docs/hb.md)
    m1, m3 = GearModel(omega=0.7), repeated(GearModel(omega=0.7))
    ref = hb_solve(m1).multipliers ** 3
    s3 = hb_solve(m3, floquet="hill")
    assert s3.hill.status == 0
    np.testing.assert_allclose(s3.multipliers, ref, rtol=0, atol=1e-3)


def test_three_cycle_series_continuation_and_response():
    # the branch in the mesh frequency: the same grazing, folds and period doubling, the same jumps
    m1 = GearModel()
    r1 = hb_continuation(m1, "omega", 0.5, 0.8, guess="linear")
    r3 = hb_continuation(repeated(m1), "omega", 0.5, 0.8, guess="linear")
    assert r3.harmonics == 48 and r3.end == r1.end == "reached the end of the interval"
    ev1 = sorted((b.type, b.value) for b in r1.bifurcations)
    ev3 = sorted((b.type, b.value) for b in r3.bifurcations)
    assert [t for t, _ in ev3] == [t for t, _ in ev1] == ["fold", "fold", "grazing", "period-doubling"]
    np.testing.assert_allclose([v for _, v in ev3], [v for _, v in ev1], rtol=0, atol=1e-8)
    assert min(r3.values) >= 0.5 - 1e-12 and max(r3.values) <= 0.8 + 0.02
    g = np.linspace(0.5, 0.8, 13)
    d1, d3 = response_from_branch(r1, g), response_from_branch(r3, g)
    for k in ("amplitude", "u_min", "u_max", "mean"):
        np.testing.assert_allclose(d3[k].values, d1[k].values, rtol=0, atol=1e-9, equal_nan=True)
    np.testing.assert_array_equal(d3["period"].values, d1["period"].values)
    j1, j3 = json.loads(d1.attrs["jumps"]), json.loads(d3.attrs["jumps"])
    assert len(j1) == len(j3) == 2
    for a, b in zip(j1, j3):
        assert (a["sweep"], a["direction"]) == (b["sweep"], b["direction"])
        assert b["omega"] == pytest.approx(a["omega"], abs=1e-8)
        assert b["size"] == pytest.approx(a["size"], abs=1e-7)


def test_default_harmonics_and_its_bound(crack):
    assert default_harmonics(GearModel()) == DEFAULT_HARMONICS
    assert default_harmonics(crack) == 20 * DEFAULT_HARMONICS  # 320 > the excitation's 64
    assert default_harmonics(crack, 2) == 320
    full = crack.replace(kappa=crack.kappa + (0.0,) * 575 + (1e-6,))  # 640 harmonics of ω/20 carried
    assert full.n_harmonics == 640 and default_harmonics(full) == 640
    big = GearModel(kappa=(0.0,) * 69 + (0.2,), cycles=70)  # 16·70 = 1120 > 1024
    with pytest.raises(ModelError, match="give the harmonics explicitly"):
        default_harmonics(big)
    assert MAX_DEFAULT_HARMONICS == 1024


@pytest.mark.parametrize(
    "w, atol_state, atol_amp",
    [
        (0.6, 1e-8, 1e-8),  # in contact all round: HB's series converges fast (1e-11 from shooting at 0.0025)
        (0.95, 3e-4, 1e-5),  # contact loss (u_min < D): algebraic convergence, velocity 1.3e-4 off at H = 320
    ],
)
def test_crack_over_one_revolution_against_shooting(crack, w, atol_state, atol_amp):
    m = crack.replace(omega=w)
    hb = hb_solve(m)
    assert hb.status == 0 and hb.harmonics == 320
    orb = shoot(m, 1, guess=hb.state(), dtau=0.005, accurate=True)  # its own fixed point of the revolution map
    assert orb.status == 0
    np.testing.assert_allclose(hb.state(), orb.state, rtol=0, atol=atol_state)
    assert hb.amplitude == pytest.approx(0.5 * (orb.u_max - orb.u_min), abs=atol_amp)
    mu = np.linalg.eigvals(orb.monodromy)
    np.testing.assert_allclose(np.sort_complex(hb.multipliers), np.sort_complex(mu), rtol=1e-5)
    assert (w > 0.9) == (hb.u_min < m.D)


def test_crack_continuation_parameter_is_the_mesh_frequency(crack):
    # 128 harmonics of ω/20 (mesh orders to 6.4) keep this quick; the branch's ω is the mesh frequency
    r = hb_continuation(crack, "omega", 0.6, 0.605, harmonics=128, guess="linear", ds_max=0.2)
    assert r.converged and r.end == "reached the end of the interval"
    assert r.values[0] == 0.6 and r.values[-1] >= 0.605
    s = hb_solve(crack.replace(omega=float(r.values[-1])), harmonics=128, guess=r.coefficients[-1])
    np.testing.assert_allclose(s.coefficients, r.coefficients[-1], atol=1e-9)
    assert np.all(r.stable)


def _tables(tmp_path):
    """A one-cycle excitation table and the same table over 3 cycles (JSON, docs/excitation.md)."""
    th = 2 * np.pi * np.arange(16) / 16
    k = 2e9 * (1 + 0.2 * np.cos(th) + 0.05 * np.cos(2 * th + 0.3))
    e = 25e-6 * np.cos(th)
    one, three = tmp_path / "one.json", tmp_path / "three.json"
    one.write_text(json.dumps({"cycles": 1, "stiffness_N_per_m": list(k), "ste_m": list(e)}))
    three.write_text(json.dumps({"cycles": 3, "stiffness_N_per_m": list(np.tile(k, 3)), "ste_m": list(np.tile(e, 3))}))
    return one, three


def _cli(args):
    from typer.testing import CliRunner

    from geardyn.cli import app

    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


def test_cli_hb_with_a_three_cycle_excitation(tmp_path):
    one, three = _tables(tmp_path)
    rng = ["--param", "omega", "--start", "0.5", "--stop", "0.65", "--ds-max", "0.05", "--json"]
    a = _cli(["hb", "--excitation", str(one), "--harmonics", "8", *rng])
    b = _cli(["hb", "--excitation", str(three), "--harmonics", "24", *rng])
    assert (a["harmonics"], b["harmonics"]) == (8, 24) and a["converged"] and b["converged"]
    fa = [x for x in a["bifurcations"] if x["type"] == "fold"]
    fb = [x for x in b["bifurcations"] if x["type"] == "fold"]
    assert len(fa) == len(fb) == 2
    for x, y in zip(fa, fb):  # the mesh frequency, and its pinion speed
        assert y["omega"] == pytest.approx(x["omega"], abs=1e-8) and y["rpm"] == pytest.approx(x["rpm"], rel=1e-8)


@pytest.mark.slow  # two HB branches at H = 16 and 48 read off on a grid (about 15 s)
def test_cli_response_method_hb_with_a_three_cycle_excitation(tmp_path):
    one, three = _tables(tmp_path)
    g = ["--omega-start", "0.54", "--omega-stop", "0.64", "--num", "5", "--method", "hb", "--json"]  # H = 16, 48
    ra, rb = _cli(["response", "--excitation", str(one), *g]), _cli(["response", "--excitation", str(three), *g])
    ja, jb = ra["jumps"], rb["jumps"]
    assert len(ja) == len(jb) == 2
    for x, y in zip(ja, jb):
        assert y["omega"] == pytest.approx(x["omega"], abs=1e-8) and y["size"] == pytest.approx(x["size"], abs=1e-7)
    assert rb["up"]["amplitude"] == pytest.approx(ra["up"]["amplitude"], abs=1e-9)


def test_response_keeps_the_grid_end_where_the_branch_starts_rounded():
    # a branch from 0.8 to 0.82 starts at (0.8/0.02)·0.02 = 0.8000000000000002: the grid's first point is on it
    m = GearModel(xi0=0.3)
    from geardyn.analysis.hb import hb_response

    ds = hb_response(m, 0.8, 0.82, 3)
    assert np.all(ds["status"].values == 0)
    ref = hb_solve(m.replace(omega=0.8))
    np.testing.assert_allclose(ds["amplitude"].values[:, 0], ref.amplitude, rtol=0, atol=1e-9)


def test_three_cycle_series_continuation_in_another_parameter():
    # the mean load f_p at ω = 0.6: the same grazing (contact loss ends) as the one-cycle model
    m1 = GearModel(omega=0.6)
    r1 = hb_continuation(m1, "fp", 0.2, 0.6, guess="linear")
    r3 = hb_continuation(repeated(m1), "fp", 0.2, 0.6, guess="linear")
    assert [b.type for b in r3.bifurcations] == [b.type for b in r1.bifurcations] == ["grazing"]
    assert r3.bifurcations[0].value == pytest.approx(r1.bifurcations[0].value, abs=1e-10)


@pytest.mark.slow  # H = 640 and shooting at Δτ = 0.0025 (about 15 s)
def test_crack_with_contact_loss_converges_in_the_harmonics(crack):
    # with contact loss the series converges algebraically: doubling H from 320 to 640 takes the state's error
    # against shooting from 1.3e-4 to 1.2e-5 (benchmarks/hb_cycles.py)
    m = crack.replace(omega=0.95)
    h320 = hb_solve(m)
    ref = shoot(m, 1, guess=h320.state(), dtau=0.0025, accurate=True)
    h640 = hb_solve(
        m,
        harmonics=640,
        guess=np.concatenate([h320.coefficients[:321], np.zeros(320), h320.coefficients[321:], np.zeros(320)]),
    )
    assert h640.status == 0
    e320 = np.max(np.abs(h320.state() - ref.state))
    e640 = np.max(np.abs(h640.state() - ref.state))
    assert e640 < e320 / 5 and e640 < 3e-5


def test_derivative_in_the_mesh_frequency(crack):
    # ∂R/∂ω (ω the mesh frequency) against a central difference of the residual, and the bordered matrix's column
    from geardyn.analysis.hb import HBEquations

    s = HBEquations(crack, 64, param="omega")
    a = HBEquations(crack.replace(omega=0.6), 64).linear_guess()[0]
    a[1:] += 0.01 * np.random.default_rng(0).normal(size=a.size - 1)  # any coefficients
    d = 1e-6
    fd = (s.residual(a, 0.6 + d, jacobian=False)[0] - s.residual(a, 0.6 - d, jacobian=False)[0]) / (2 * d)
    an = s.dR_dp(a, 0.6)
    assert np.max(np.abs(an - fd)) <= 1e-7 * np.max(np.abs(an))
    _R, A = s.bordered(a, 0.6, 0.01)
    np.testing.assert_allclose(A[:-1, -1], 0.01 * an, rtol=1e-12, atol=1e-15)
