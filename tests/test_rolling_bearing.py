"""The rolling-element bearing as an element law of the N-DOF kernel, against independent references.

The system is ``examples/systems/ball_bearing.toml``: a shaft (x, y, θ) on a ball bearing of 8 balls with
clearance under a constant radial load, driving a gear through a torsional mesh.  The mesh acts on the rotations
only, so the shaft's (x, y) obey on their own, in SI,

    m x'' = F_x − c_x x' − K Σ_j max(δ_j, 0)^n cos ψ_j,   m y'' = F_y − c_y y' − K Σ_j max(δ_j, 0)^n sin ψ_j,
    δ_j = x cos ψ_j + y sin ψ_j − c,   ψ_j = Ω_c t + 2πj/Z,   Ω_c = Ω (1 − d_b cos α/d_m)/2,

with Ω the shaft speed (the mesh frequency over its 20 teeth).  The references below write these equations from
the file's numbers and integrate them with SciPy (DOP853), or solve the static problem with Harris's load
distribution (:mod:`tests.test_bearings`), none of them with the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, root

from geardyn import load_system
from geardyn.errors import ConfigError, ModelError
from geardyn.integrate import IntegrationOptions, trajectory

FILE = "examples/systems/ball_bearing.toml"
# the file's numbers (SI)
MASS, Z, K, N_EXP, CLEAR = 2.0, 8, 8e9, 1.5, 5e-6
DM, DB = 0.040, 0.010
FX, FY = 500.0, -2000.0
K_MESH, R1, R2, I1, I2, TEETH = 2e8, 0.030, 0.060, 1e-3, 4e-3, 20
BC = 0.05e-3  # half the backlash


def _scales():
    m_e = 1.0 / (R1**2 / I1 + R2**2 / I2)
    return math.sqrt(K_MESH / m_e)  # ω_n (rad/s)


def _reference(omega: float, cx: float, t_end: float, t_eval: np.ndarray, y0=(0.0, 0.0, 0.0, 0.0), K=K, N_EXP=N_EXP):
    """DOP853 of the shaft's (x, y) in SI (module docstring)."""
    wn = _scales()
    shaft_speed = omega * wn / TEETH  # the mesh frequency ω ω_n over the pinion's teeth
    cage = shaft_speed * (1.0 - DB / DM) / 2.0
    ang = 2.0 * np.pi * np.arange(Z) / Z

    def rhs(t, s):
        x, y, vx, vy = s
        psi = cage * t + ang
        c, sn = np.cos(psi), np.sin(psi)
        d = np.maximum(x * c + y * sn - CLEAR, 0.0)
        q = K * d**N_EXP
        return [vx, vy, (FX - cx * vx - np.sum(q * c)) / MASS, (FY - cx * vy - np.sum(q * sn)) / MASS]

    sol = solve_ivp(rhs, (0.0, t_end), list(y0), method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t_eval)
    assert sol.success
    return sol.y


def test_the_file_reads_the_bearing_and_its_ball_pass_ratio():
    m = load_system(FILE)
    (b,) = m.bearings
    assert [e.name for e in m.elements] == ["mesh", "brg.x", "brg.y"]
    assert [e.law.code for e in m.elements] == [0, 1, 1]
    # the cage at (1 - 10/40)/2 = 3/8 of the shaft speed, 8 balls: 3 per revolution, 3/20 of the mesh frequency
    assert b.ratio == 3 / 20 and m.period_multiple() == 20
    assert b.K == pytest.approx(K * BC**0.5 / K_MESH, rel=1e-14)
    assert b.clearance == pytest.approx(CLEAR / BC, rel=1e-14)
    assert m.scaling.omega_n_rad_s == pytest.approx(_scales(), rel=1e-14)
    # the static mesh force (the nonlinear static problem with the bearing): the shaft's 30 N·m on its 30 mm radius
    assert m.static_force() * K_MESH * BC == pytest.approx(30.0 / R1, rel=1e-9)


def test_trajectory_agrees_with_dop853_of_the_same_equations():
    """geardyn's RK4 (Δτ = 0.005) against DOP853 (rtol 1e-10) over two forcing periods (40 mesh cycles): the
    shaft leaves the centre, takes up the clearance and settles on the balls with the cage turning."""
    m = load_system(FILE)
    tr = trajectory(m, None, IntegrationOptions(dtau=0.005, transient=0, periods=2), history_periods=2)
    wn = _scales()
    t = tr.tau / wn
    ref = _reference(m.omega, 200.0, t[-1], t)
    x, y = BC * tr.x[:, 0], BC * tr.x[:, 1]
    scale = np.max(np.abs(ref[1]))
    err = max(np.max(np.abs(x - ref[0])), np.max(np.abs(y - ref[1]))) / scale
    assert err < 1e-6, err  # measured 5.8e-8
    # the accurate mode takes the bearing as smooth (no split): the same trajectory to the same accuracy
    tra = trajectory(m, None, IntegrationOptions(dtau=0.005, transient=0, periods=2, accurate=True), history_periods=2)
    assert np.max(np.abs(BC * tra.x[:, 1] - ref[1])) / scale < 1e-6


def test_a_roller_bearing_agrees_with_dop853_too(tmp_path):
    """The same shaft on rollers (exponent 10/9, K = 2e9 N/m^(10/9)), dampers 2000 N·s/m, against DOP853 of its
    equations.  The roller's force has an unbounded second derivative at contact (δ^(1/9)), so RK4 converges at
    about order 2.7 there: measured 2.6e-6, 4.1e-7 and 4.3e-8 at Δτ = 0.01, 0.005 and 0.0025 (lightly damped,
    the shaft rattles in its clearance and the comparison measures that sensitivity instead)."""
    text = open(FILE).read().replace('type = "ball"', 'type = "roller"')
    text = text.replace('value = "8e9 N/m^1.5"', 'value = "2e9 N/m^(10/9)"')
    text = text.replace('cx = "200 N*s/m"', 'cx = "2000 N*s/m"').replace('cy = "200 N*s/m"', 'cy = "2000 N*s/m"')
    p = tmp_path / "roller.toml"
    p.write_text(text)
    m = load_system(p)
    assert m.bearings[0].exponent == 10.0 / 9.0
    tr = trajectory(m, None, IntegrationOptions(dtau=0.005, transient=0, periods=2), history_periods=2)
    t = tr.tau / _scales()
    ref = _reference(m.omega, 2000.0, t[-1], t, K=2e9, N_EXP=10.0 / 9.0)
    scale = np.max(np.abs(ref[1]))
    err = max(np.max(np.abs(BC * tr.x[:, 0] - ref[0])), np.max(np.abs(BC * tr.x[:, 1] - ref[1]))) / scale
    assert err < 1e-6, err  # measured 4.1e-7


def harris_radial_load(delta_r: float) -> float:
    """Harris's F_r = Z K (δ_r − c)^n J_r(ε), J_r by quadrature (tests/test_bearings.py)."""
    from test_bearings import harris_radial_load as hr

    return hr(delta_r, 2 * CLEAR, Z, K, N_EXP)


def _discrete_static(F: float, psi0: float) -> float:
    """The deflection along the load of the discrete bearing at the cage angle ψ0 (element j at ψ0 + 2πj/Z from
    the load line), by root finding of the test's own force sum: along the load alone where the balls lie
    symmetrically about it (ψ0 = 0 or π/Z), else in the plane (the shaft also moves across the load)."""
    ang = psi0 + 2.0 * np.pi * np.arange(Z) / Z
    c, s = np.cos(ang), np.sin(ang)

    def g(d):
        return float(np.sum(K * np.maximum(d * c - CLEAR, 0.0) ** N_EXP * c)) - F

    d0 = brentq(g, CLEAR, 1e-3, xtol=1e-16, rtol=1e-15)
    if np.isclose(psi0 % (2 * np.pi / Z), 0.0) or np.isclose(psi0 % (2 * np.pi / Z), np.pi / Z):
        return d0

    def g2(p):
        q = K * np.maximum(p[0] * c + p[1] * s - CLEAR, 0.0) ** N_EXP
        return [(np.sum(q * c) - F) / F, np.sum(q * s) / F]

    sol = root(g2, [d0, 0.0], method="hybr", tol=1e-13)
    assert np.max(np.abs(g2(sol.x))) < 1e-12
    return float(sol.x[0])


def test_static_deflection_agrees_with_harris():
    """A long, heavily damped run at a low shaft speed (the ball pass far below the shaft's natural frequency):
    the deflection along the load follows the quasi-static discrete bearing at every cage angle, its mean is
    Harris's δ_r for the load (the load distribution's closed form), and its extremes are the discrete bearing's
    at a ball on the load line and at two balls straddling it."""
    from dataclasses import replace

    from geardyn.systems.assemble import assemble

    desc = load_system(FILE).description
    b = desc.rolling_bearings[0]
    desc = replace(desc, rolling_bearings=(replace(b, cx=4e3, cy=4e3),), omega=0.005)
    m = assemble(desc)
    tr = trajectory(m, None, IntegrationOptions(dtau=0.05, transient=2, periods=1), history_periods=1)
    F = math.hypot(FX, FY)
    u = np.array([FX, FY]) / F  # the load direction
    d = BC * (tr.x[:, 0] * u[0] + tr.x[:, 1] * u[1])
    # quasi-static: at each sample, the discrete bearing's static deflection at that cage angle from the load line
    wn = _scales()
    cage = m.omega * wn / TEETH * (1.0 - DB / DM) / 2.0 * tr.tau / wn
    load_angle = math.atan2(u[1], u[0])
    k = np.arange(0, d.size, max(1, d.size // 97))
    qs = np.array([_discrete_static(F, c - load_angle) for c in cage[k]])
    assert np.max(np.abs(d[k] - qs)) / np.mean(qs) < 2e-5  # measured 5.0e-6
    # Harris: the load distribution of the cage-averaged bearing
    dr = brentq(lambda x: harris_radial_load(x) - F, CLEAR * 1.0001, 1e-3, xtol=1e-16)
    # the discrete bearing's mean deflection over a ball pass against the continuous distribution: 3.5e-4
    assert np.mean(d) == pytest.approx(dr, rel=1e-3)
    assert np.max(d) == pytest.approx(_discrete_static(F, math.pi / Z), rel=1e-6)  # measured 1.3e-8
    assert np.min(d) == pytest.approx(_discrete_static(F, 0.0), rel=1e-6)  # measured 2.5e-8


def test_the_varying_compliance_frequency_is_the_ball_pass_frequency():
    """The steady response under a constant load varies at Z Ω_c, 3/20 of the mesh frequency: 3 cycles per forcing
    period of 20 mesh cycles; the spectrum of the displacement has its largest line there."""
    m = load_system(FILE)
    P = 4
    tr = trajectory(m, None, IntegrationOptions(dtau=0.01, transient=20, periods=P), history_periods=P)
    y = tr.x[:-1, 1] - np.mean(tr.x[:-1, 1])
    spec = np.abs(np.fft.rfft(y))
    k = int(np.argmax(spec[1:])) + 1
    assert k == 3 * P  # line k of P forcing periods: k/P per forcing period = 3
    # in physical units: the ball-pass frequency of the geometry
    f_line = k / (P * m.sampling_period) * m.scaling.omega_n_rad_s  # cycles per tau, tau = omega_n t
    shaft_hz = m.omega * m.scaling.omega_n_rad_s / (2 * math.pi) / TEETH
    assert f_line == pytest.approx(Z * shaft_hz * (1 - DB / DM) / 2, rel=1e-12)
    # the bearing's element rows are counted by the law's counters (loaded towards the load: plus in x, minus in y)
    fr = tr.summary.law_fractions(1)
    assert fr["plus"][0] == 1.0 and fr["minus"][0] == 0.0
    assert tr.summary.law_fractions(2)["minus"][0] == 1.0


BAD = [
    ("elements = 8", "elements = 2", "elements"),
    ('radial_clearance = "5 um"', 'radial_clearance = "5 mm"', "radial_clearance"),
    ('element_diameter = "10 mm"', 'element_diameter = "50 mm"', "element_diameter"),
    ('contact_angle = "0 deg"', 'contact_angle = "95 deg"', "contact_angle"),
    ('type = "ball"', 'type = "needle"', "type"),
    ('value = "8e9 N/m^1.5"', 'value = "8e9 N/m^2"', "load_deflection"),
    ('body = "shaft"\nelements', 'body = "gear"\nelements', "body"),
]


@pytest.mark.parametrize("old, new, key", BAD)
def test_bad_bearings_are_refused_in_one_line_naming_the_key(tmp_path, old, new, key):
    text = open(FILE).read()
    assert old in text
    p = tmp_path / "bad.toml"
    p.write_text(text.replace(old, new, 1))
    with pytest.raises((ModelError, ConfigError)) as e:
        load_system(p)
    msg = str(e.value)
    assert "\n" not in msg and key in msg, msg


def test_attrs_round_trip_keeps_the_bearing():
    from geardyn.systems import SystemModel

    m = load_system(FILE)
    back = SystemModel.from_attrs(m.to_attrs())
    a, b = m.arrays(), back.arrays()
    for f in a._fields:
        assert np.array_equal(getattr(a, f), getattr(b, f)), f


def test_harmonic_balance_takes_the_bearing_as_two_rows_of_one_law():
    """The HB form has the bearing's x and y rows with the System's own law (tests/test_hb_rolling.py solves it)."""
    m = load_system(FILE)
    f = m.hb_form()
    rows = [e for e in f.elements if e.kind == "bearing"]
    assert [e.name for e in rows] == ["brg.x", "brg.y"]
    assert all(e.law == "rolling_bearing" and e.rule == m.elements[1].law for e in rows)
    assert np.array_equal(rows[0].V, m.Vb[0]) and np.array_equal(rows[1].V, m.Vb[1])


def _settled(m, periods=10):
    tr = trajectory(m, None, IntegrationOptions(dtau=0.01, transient=periods, periods=1), history_periods=1)
    return tr.x[-1]


def test_monodromy_is_the_derivative_of_the_period_map():
    """The tangent of the kernel (the bearing's 2 × 2 stiffness with its cross terms in the Jacobian) is the
    derivative of the discrete period map: against central differences of the map (the shaft on its balls, the
    mesh in contact)."""
    from geardyn.integrate import period_map

    m = load_system(FILE)
    x0 = _settled(m)
    _, J, _, ok = period_map(m, x0, 1, dtau=0.01)
    assert ok
    d = x0.size
    fd = np.empty((d, d))
    for j in range(d):
        h = 1e-6 * max(1.0, abs(x0[j]))
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        fd[:, j] = (period_map(m, xp, 1, dtau=0.01)[0][-1] - period_map(m, xm, 1, dtau=0.01)[0][-1]) / (2 * h)
    b = np.ix_([0, 1, 4, 5], [0, 1, 4, 5])  # the shaft's (x, y, x', y'): the bearing's block
    err = np.max(np.abs(J - fd)[b]) / np.max(np.abs(J[b]))
    assert err < 1e-6, err  # measured 3.0e-7
    assert np.max(np.abs(J - fd)) < 1e-6 * np.max(np.abs(J))
    # the bearing's cross terms matter: x and y are coupled in the map
    assert abs(J[0, 1]) > 0.05 * abs(J[0, 0]) and abs(J[1, 0]) > 0.05 * abs(J[1, 1])


def test_leading_exponent_with_few_vectors_is_the_largest_floquet_multiplier():
    """The leading exponent from one tangent vector beside the plain step (its Jacobian–vector products from the
    sparse rows, the bearing's cross terms included) is log|μ| / T_f of the largest elastic Floquet multiplier of
    the settled periodic orbit (from the full monodromy of the other tangent path)."""
    from geardyn.analysis.lyapunov import spectrum_from_log
    from geardyn.integrate import integrate_batch, period_map

    m = load_system(FILE)
    x0 = _settled(m, 30)
    x1, J, _, _ = period_map(m, x0, 1, dtau=0.01)
    assert np.max(np.abs(x1[-1] - x0)) < 1e-9  # the orbit is periodic with the forcing
    mu = np.linalg.eigvals(J)
    elastic = mu[np.abs(mu - 1.0) > 1e-6]
    lam_floquet = math.log(np.max(np.abs(elastic))) / m.sampling_period
    r = integrate_batch(
        [m], x0[None, :], IntegrationOptions(dtau=0.01, transient=0, periods=60), lyapunov=True, tangents=1
    )
    lam, _ = spectrum_from_log(r.lyapunov_log, np.array([m.sampling_period]))
    assert lam[0, 0] == pytest.approx(lam_floquet, rel=2e-2)


def test_a_bad_bearing_exits_2_in_one_line_from_the_command_line(tmp_path):
    from typer.testing import CliRunner

    from geardyn.cli import app

    p = tmp_path / "bad.toml"
    p.write_text(open(FILE).read().replace('radial_clearance = "5 um"', 'radial_clearance = "-5 um"'))
    r = CliRunner().invoke(app, ["simulate", "--system", str(p), "--json"])
    assert r.exit_code == 2
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "radial_clearance" in lines[0], r.output


def test_bearing_parameters_by_name_and_a_batch_over_the_clearance():
    """``brg.clearance`` (c̃) is a parameter like a mesh's: a batch of two clearances runs in one call and each
    point is the system of its own clearance, bit for bit."""
    from geardyn.integrate import integrate_batch

    m = load_system(FILE)
    assert m.get("brg.clearance") == pytest.approx(CLEAR / BC, rel=1e-14)
    assert set(m.parameters()) >= {"brg.clearance", "brg.K", "brg.cx", "brg.cy"}
    with pytest.raises(ModelError, match="brg.exponent: a rolling bearing's parameters"):
        m.get("brg.exponent")
    pts = [m.with_param("brg.clearance", c) for c in (0.0, 0.4)]
    opts = IntegrationOptions(dtau=0.01, transient=2, periods=1)
    both = integrate_batch(pts, None, opts)
    for i, p in enumerate(pts):
        one = integrate_batch([p], None, opts)
        assert np.array_equal(both.end_state[i], one.end_state[0])
    assert not np.allclose(both.end_state[0], both.end_state[1])


GEARBOX = "examples/gearbox/two_stage_helical.toml"


def test_the_shipped_gearbox_has_two_ball_bearings_and_keeps_its_period_bound(tmp_path):
    """in_B (input shaft, a 6207 size) and mid_B (intermediate, 6208 size) are ball bearings with 10 µm clearance;
    their ball-pass frequencies (Z (1 − d/D_p)/2 times the shaft's speed 1 and 23/64 of the input's, over the
    stage-1 mesh frequency of 23 per input revolution) are taken to the nearest multiple of 1/1472, so the forcing
    period (1472 stage-1 mesh cycles) stays within max_period = 1500."""
    from fractions import Fraction

    from geardyn.systems import load_description

    d = load_description(GEARBOX)
    names = [b.name for b in d.rolling_bearings]
    assert names == ["in_B", "mid_B"]
    exact = {
        "in_B": 9 * (1 - 11.112 / 53.5) / 2 / 23,
        "mid_B": 9 * (1 - 12.7 / 60) / 2 * Fraction(23, 64) / 23,
    }
    for b in d.rolling_bearings:
        assert 1472 % b.ratio.denominator == 0
        assert abs(float(b.ratio) - float(exact[b.name])) <= 0.5 / 1472 + 1e-15
        assert b.bearing.clearance == pytest.approx(10e-6, rel=1e-12)
    assert d.kinematics["forcing_period_mesh_cycles"] == 1472
    assert load_system(GEARBOX).period_multiple() == 1472
    text = open(GEARBOX).read()
    bad = tmp_path / "bad.toml"
    bad.write_text(
        text.replace(
            'type = "ball"\nelements = 9\npitch_diameter = "53.5 mm"',
            'type = "ball"\nkx = "1e8 N/m"\nelements = 9\npitch_diameter = "53.5 mm"',
        )
    )
    with pytest.raises(ConfigError, match="kx: not allowed in a rolling bearing"):
        load_description(bad)
    bad.write_text(
        text.replace(
            'type = "ball"\nelements = 9\npitch_diameter = "53.5 mm"', 'elements = 9\npitch_diameter = "53.5 mm"', 1
        )
    )
    with pytest.raises(ConfigError, match='give type = "ball" or "roller"'):
        load_description(bad)
