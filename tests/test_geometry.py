"""Geometry identities of the spiral bevel pair and the physical ↔ non-dimensional conversions."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import scipy.linalg

from geardyn.geometry import (
    DEFAULT_C_GAMMA,
    MeshHarmonics,
    SpiralBevelGearPair,
    drive_side_from_rotation,
    geometry_summary,
)
from geardyn.model import GearModel, ModelError

DEG = math.pi / 180.0


def table1(**changes) -> SpiralBevelGearPair:
    """The paper's Table 1 pair (SI units) with the assumed face width 100 mm and c_γ = 20 N/(mm·µm)."""
    kw = dict(
        z1=23,
        z2=47,
        m_mn=7.28e-3,
        beta_m=35 * DEG,
        alpha_n=20 * DEG,
        Sigma=90 * DEG,
        j_n=0.1e-3,
        I1=1.772,
        I2=1.873,
        r1=0.1255,
        r2=0.256,
        face_width=0.1,
        xi0=0.1,
    )
    kw.update(changes)
    return SpiralBevelGearPair(**kw)


# ---------------------------------------------------------------------------- pitch cones
@pytest.mark.parametrize(
    "z1,z2,sigma_deg", [(23, 47, 90), (11, 41, 90), (20, 20, 90), (17, 43, 60), (15, 31, 120), (9, 50, 75)]
)
def test_pitch_cone_angles_sum_to_shaft_angle(z1, z2, sigma_deg):
    p = table1(z1=z1, z2=z2, Sigma=sigma_deg * DEG, r1=None, r2=None, face_width=None)
    assert p.delta1 + p.delta2 == pytest.approx(sigma_deg * DEG, abs=1e-14)
    # tan δ1 = sin Σ / (z2/z1 + cos Σ) and the symmetric relation for δ2
    S = sigma_deg * DEG
    assert math.tan(p.delta1) == pytest.approx(math.sin(S) / (z2 / z1 + math.cos(S)), rel=1e-12)
    assert math.tan(p.delta2) == pytest.approx(math.sin(S) / (z1 / z2 + math.cos(S)), rel=1e-12)
    # the pitch cones roll: pitch radii at any cone distance are in the ratio z1 : z2
    assert math.sin(p.delta1) / math.sin(p.delta2) == pytest.approx(z1 / z2, rel=1e-12)


def test_table1_pitch_cone_angles():
    p = table1()
    assert math.degrees(p.delta1) == pytest.approx(math.degrees(math.atan(23 / 47)), abs=1e-12)
    assert math.degrees(p.delta1) == pytest.approx(26.0754, abs=1e-4)
    assert math.degrees(p.delta2) == pytest.approx(63.9246, abs=1e-4)


# ---------------------------------------------------------------------------- vectors
ANGLES = [(20, 35), (14.5, 0), (25, 45), (20, 10), (22.5, 30), (17.5, 60)]


@pytest.mark.parametrize(
    "alpha_deg,beta_deg,hand,side,sigma_deg",
    [
        (a, b, h, s, S)
        for (a, b), h, s, S in itertools.product(ANGLES, ("left", "right"), ("concave", "convex"), (90, 70, 115))
    ],
)
def test_directional_radius_from_vectors(alpha_deg, beta_deg, hand, side, sigma_deg):
    p = table1(alpha_n=alpha_deg * DEG, beta_m=beta_deg * DEG, hand=hand, drive_side=side, Sigma=sigma_deg * DEG)
    mv = p.mesh_vectors()
    lam = math.cos(alpha_deg * DEG) * math.cos(beta_deg * DEG)
    for R, rvec, j, n, r in ((p.R1, mv.r1, mv.j1, mv.n1, 0.1255), (p.R2, mv.r2, mv.j2, mv.n2, 0.256)):
        # unit vectors, and the mesh point at distance r_l from its axis
        assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-14)
        assert np.linalg.norm(j) == pytest.approx(1.0, abs=1e-14)
        assert np.linalg.norm(rvec - (rvec @ j) * j) == pytest.approx(r, rel=1e-12)
        # R_l = n_l·(j_l × r_l) computed from the vectors equals r_l cos α_n cos β_m
        assert float(n @ np.cross(j, rvec)) == pytest.approx(R, rel=1e-14)
        assert R == pytest.approx(r * lam, rel=1e-12)
    # the normal is tilted by α_n out of the common pitch plane and by β_m from the running direction
    assert float(mv.n1 @ mv.p) == pytest.approx(math.sin(alpha_deg * DEG), abs=1e-12)
    assert float(mv.n1 @ mv.t) == pytest.approx(lam, abs=1e-12)
    # the axes make the shaft angle; each pitch point moves along t when its gear turns positively
    assert abs(float(mv.j1 @ mv.j2)) == pytest.approx(abs(math.cos(sigma_deg * DEG)), abs=1e-12)
    assert float(np.cross(mv.j1, mv.r1) @ mv.t) > 0 and float(np.cross(mv.j2, mv.r2) @ mv.t) > 0


@pytest.mark.parametrize("sigma_deg", [90, 60, 120])
@pytest.mark.parametrize("hand", ["left", "right"])
@pytest.mark.parametrize("side", ["concave", "convex"])
def test_force_components_match_bevel_gear_formulas(sigma_deg, hand, side):
    """Axial and radial force shares from the vectors equal the usual bevel-gear force formulas.

    Per unit tangential force W_t, with s = −1 when the pinion drives on its concave flank and +1
    on its convex flank: pinion axial (tan α sin δ1 − s sin β cos δ1)/cos β, radial
    (tan α cos δ1 + s sin β sin δ1)/cos β; gear axial (tan α sin δ2 + s sin β cos δ2)/cos β, radial
    (tan α cos δ2 − s sin β sin δ2)/cos β.
    """
    a, b = 20 * DEG, 35 * DEG
    p = table1(Sigma=sigma_deg * DEG, hand=hand, drive_side=side)
    comp = p.mesh_vectors().force_components()
    wt = math.cos(a) * math.cos(b)  # tangential share of a unit normal force
    s = -1.0 if side == "concave" else 1.0
    d1, d2 = p.delta1, p.delta2
    ta, sb, cb = math.tan(a), math.sin(b), math.cos(b)
    expected = {
        "pinion": ((ta * math.sin(d1) - s * sb * math.cos(d1)) / cb, (ta * math.cos(d1) + s * sb * math.sin(d1)) / cb),
        "gear": ((ta * math.sin(d2) + s * sb * math.cos(d2)) / cb, (ta * math.cos(d2) - s * sb * math.sin(d2)) / cb),
    }
    for g, (ax, rad) in expected.items():
        assert comp[g]["axial"] == pytest.approx(wt * ax, abs=1e-12)
        assert comp[g]["radial"] == pytest.approx(wt * rad, abs=1e-12)
    assert comp["pinion"]["tangential"] == pytest.approx(-wt, abs=1e-12)
    assert comp["gear"]["tangential"] == pytest.approx(wt, abs=1e-12)
    # equal and opposite mesh forces: the magnitudes of all three components add up to 1
    for g in comp:
        assert sum(v**2 for v in comp[g].values()) == pytest.approx(1.0, abs=1e-12)


def test_concave_drive_pushes_pinion_out_of_mesh():
    # Table 1: pinion concave drives → the pinion's axial force points away from the apex
    comp = table1(drive_side="concave").mesh_vectors().force_components()
    assert comp["pinion"]["axial"] > 0.5
    comp = table1(drive_side="convex").mesh_vectors().force_components()
    assert comp["pinion"]["axial"] < 0


def test_hand_mirrors_vectors_but_not_torsional_model():
    left, right = table1(hand="left"), table1(hand="right")
    ml, mr = left.mesh_vectors(), right.mesh_vectors()
    # the normal is mirrored through the plane of the axes (z → −z), the running sense reverses
    assert np.allclose(ml.n1 * [1, 1, -1], mr.n1, atol=1e-14)
    assert np.allclose(ml.j1, -mr.j1, atol=1e-14)
    assert left.rotation_sense() == ("clockwise", "counterclockwise")
    assert right.rotation_sense() == ("counterclockwise", "clockwise")
    assert left.R1 == pytest.approx(right.R1, rel=1e-14) and left.m_e == pytest.approx(right.m_e, rel=1e-14)


@pytest.mark.parametrize("hand", ["left", "right"])
@pytest.mark.parametrize("rotation", ["clockwise", "counterclockwise"])
def test_drive_side_from_rotation_is_consistent_with_vectors(hand, rotation):
    side = drive_side_from_rotation(hand, rotation)
    assert table1(hand=hand, drive_side=side).rotation_sense()[0] == rotation
    assert drive_side_from_rotation("left", "clockwise") == "concave"


# ---------------------------------------------------------------------------- equivalent mass, loads
def test_equivalent_mass_is_the_two_inertia_eigenfrequency():
    """The nonzero natural frequency of the two-inertia torsional system with mesh stiffness k0
    along the line of action equals √(k0/m_e)."""
    cases = ((23, 47, 1.772, 1.873, 0.1255, 0.256), (11, 41, 8e-4, 0.05, 0.0247, 0.092), (12, 48, 0.3, 3.0, 0.05, 0.2))
    for z1, z2, I1, I2, r1, r2 in cases:  # radii at the mean pitch point of a pair of those teeth (module from r1)
        m = 2 * r1 * math.cos(35 * DEG) / z1
        p = table1(z1=z1, z2=z2, m_mn=m, I1=I1, I2=I2, r1=r1, r2=r2, face_width=None)
        R1, R2, k0 = p.R1, p.R2, p.k0_mean
        K = k0 * np.array([[R1 * R1, -R1 * R2], [-R1 * R2, R2 * R2]])
        M = np.diag([I1, I2])
        w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
        assert w2[0] == pytest.approx(0.0, abs=1e-9 * w2[1])  # rigid-body rotation
        assert math.sqrt(w2[1]) == pytest.approx(p.omega_n, rel=1e-12)
        assert p.m_e == pytest.approx(I1 * I2 / (I2 * R1**2 + I1 * R2**2), rel=1e-14)


def test_table1_values():
    p = table1()
    lam = math.cos(20 * DEG) * math.cos(35 * DEG)
    assert p.R1 == pytest.approx(0.1255 * lam, rel=1e-12)
    assert p.R1 == pytest.approx(0.0966038, rel=1e-6)
    assert p.R2 == pytest.approx(0.1970563, rel=1e-6)
    assert p.m_e == pytest.approx(38.4636, rel=1e-5)
    assert p.k0_mean == pytest.approx(0.1 * DEFAULT_C_GAMMA, rel=1e-14) == pytest.approx(2.0e9)
    assert p.omega_n == pytest.approx(math.sqrt(2.0e9 / 38.4636012), rel=1e-8)
    assert p.omega_n == pytest.approx(7210.91, rel=1e-6)


@pytest.mark.parametrize("T1", [1.0, 500.0, 1932.0, -300.0])
def test_static_force_balanced_is_T1_over_R1(T1):
    p = table1()
    assert p.static_force(T1) == pytest.approx(T1 / p.R1, rel=1e-13)
    assert p.static_force(T1, T1 * p.R2 / p.R1) == pytest.approx(T1 / p.R1, rel=1e-13)


def test_static_force_unbalanced_from_the_two_equations():
    """F_p from the equations of motion: with F = F_p constant and u constant (u'' = 0 ⇒
    R1 θ1'' = R2 θ2''), the two gears accelerate together; check the formula against that."""
    p = table1()
    T1, T2 = 1500.0, 2500.0
    Fp = p.static_force(T1, T2)
    a1 = (T1 - p.R1 * Fp) / p.I1
    a2 = (p.R2 * Fp - T2) / p.I2
    assert p.R1 * a1 == pytest.approx(p.R2 * a2, rel=1e-12)
    assert Fp != pytest.approx(T1 / p.R1, rel=1e-3)


def test_xi0_from_c0_and_back():
    p = table1()
    q = table1(xi0=None, c0=p.c0_mean)
    assert q.xi0_mean == pytest.approx(0.1, rel=1e-12)
    assert p.c0_mean == pytest.approx(2 * 0.1 * p.m_e * p.omega_n, rel=1e-14)


def test_face_width_default_and_k0_given():
    p = table1(face_width=None)
    r_m = 0.1255 / math.sin(p.delta1)
    b = p.resolved.face_width
    assert b == pytest.approx(0.3 * (r_m + b / 2), rel=1e-12)
    assert "face_width" in [a.name for a in p.assumptions] and "k0" in [a.name for a in p.assumptions]
    q = table1(k0=1.5e9)
    assert q.k0_mean == 1.5e9
    assert "k0" not in [a.name for a in q.assumptions]
    assert "face_width" not in [a.name for a in q.assumptions]


def test_mean_pitch_radius_default():
    p = table1(r1=None, r2=None)
    assert p.resolved.r1 == pytest.approx(7.28e-3 * 23 / (2 * math.cos(35 * DEG)), rel=1e-14)
    assert {"r1", "r2"} <= {a.name for a in p.assumptions}


# ---------------------------------------------------------------------------- conversions
def test_conversions_round_trip():
    p = table1()
    sc = p.scales()
    rpm = np.array([100.0, 1234.5, 3000.0, 9000.0])
    assert np.allclose(sc.rpm_from_omega(sc.omega_from_rpm(rpm)), rpm, rtol=1e-14)
    # ω_e = 2π z1 n1/60: 3000 rpm, 23 teeth → 1150 Hz
    assert p.mesh_frequency(3000.0) / (2 * math.pi) == pytest.approx(1150.0, rel=1e-14)
    assert sc.hz_from_omega(sc.omega_from_rpm(3000.0)) == pytest.approx(1150.0, rel=1e-13)
    um = np.array([-12.5, 0.0, 50.0, 3.3])
    assert np.allclose(sc.um_from_u(sc.u_from_um(um)), um, rtol=1e-14)
    assert sc.u_from_um(50.0) == pytest.approx(1.0)  # b_c = b_n = 50 µm
    F = np.array([0.0, 1.0e4, 2.0e4])
    assert np.allclose(sc.N_from_force(sc.force_from_N(F)), F, rtol=1e-14)
    assert sc.force_from_N(1.0e5) == pytest.approx(1.0)  # k0 b_c = 2e9 N/m × 50 µm = 1e5 N
    t = np.array([0.0, 1e-3, 0.25])
    assert np.allclose(sc.s_from_tau(sc.tau_from_s(t)), t, rtol=1e-14)
    assert sc.tau_from_s(1.0) == pytest.approx(p.omega_n)
    assert sc.kappa_from_k(sc.k_from_kappa(0.2)) == pytest.approx(0.2)
    assert sc.xi_from_c(sc.c_from_xi(0.05)) == pytest.approx(0.05)


def test_table1_operating_point_to_model_and_back():
    """Table 1 at 3000 rpm and T1 = 1932 N·m (balanced) → ω and f_p, and back."""
    p = table1()
    m = p.gear_model(3000.0, 1932.0, mesh=MeshHarmonics(xi=(0.05,), kappa=(0.2,), eps=(0.5,)))
    # ω = 2π·23·3000/60 / √(k0/m_e)
    assert m.omega == pytest.approx(2 * math.pi * 1150.0 / 7210.909, rel=1e-6)
    assert m.omega == pytest.approx(1.002046, rel=1e-6)
    # f_p = (T1/R1)/(k0 b_n) = (1932/0.0966038)/(2e9·5e-5)
    assert m.fp == pytest.approx(1932.0 / 0.09660377 / 1.0e5, rel=1e-6)
    assert m.fp == pytest.approx(0.199992, rel=1e-5)
    assert (m.xi0, m.xi, m.kappa, m.eps, m.D) == (0.1, (0.05,), (0.2,), (0.5,), 1.0)
    sc = p.scales()
    assert sc.rpm_from_omega(m.omega) == pytest.approx(3000.0, rel=1e-13)
    assert sc.torque_from_fp(m.fp) == pytest.approx(1932.0, rel=1e-13)


def test_dimensional_harmonics_match_nondimensional():
    p = table1()
    sc = p.scales()
    dim = MeshHarmonics(c=(sc.c_from_xi(0.05),), k=(0.2 * p.k0_mean,), e=(25e-6, 5e-6), phi_e=(0.0, 0.3))
    m = p.gear_model(2000.0, 1000.0, mesh=dim)
    assert m.xi == pytest.approx((0.05,)) and m.kappa == pytest.approx((0.2,))
    assert m.eps == pytest.approx((0.5, 0.1)) and m.phi_e == (0.0, 0.3)


def test_table3_backlash_reading():
    p = table1(j_n=0.7e-3)
    m = p.gear_model(3000.0, 1000.0, b_c=1e-3)
    assert m.D == pytest.approx(0.35)  # Table 3: 0.7 mm ↔ 0.35
    assert p.scales(1e-3).force_scale_N == pytest.approx(2.0e6)


def test_summary_keys_and_values():
    s = geometry_summary(table1(), rpm=3000.0, torque=1932.0)
    for k in ("delta1_deg", "delta2_deg", "R1_m", "R2_m", "m_e_kg", "F_p_N", "omega_n_rad_s", "assumed"):
        assert k in s
    assert s["delta1_deg"] + s["delta2_deg"] == pytest.approx(90.0)
    assert s["F_p_N"] == pytest.approx(1932.0 / s["R1_m"], rel=1e-13)
    assert {"hand", "drive_side", "c_gamma", "k0"} <= set(s["assumed"])
    assert "face_width" not in s["assumed"]  # given explicitly and not declared assumed


@pytest.mark.parametrize(
    "change,word",
    [
        (dict(z1=0), "z1"),
        (dict(z2=12.5), "z2"),
        (dict(beta_m=95 * DEG), "beta_m"),
        (dict(alpha_n=0.0), "alpha_n"),
        (dict(Sigma=180 * DEG), "Sigma"),
        (dict(I1=-1.0), "I1"),
        (dict(r2=float("nan")), "r2"),
        (dict(j_n=-1e-4), "j_n"),
        (dict(hand="up"), "hand"),
        (dict(drive_side="coast"), "drive_side"),
        (dict(c0=1.0), "xi0/c0"),
        (dict(k0=0.0), "k0"),
    ],
)
def test_bad_geometry_refused(change, word):
    with pytest.raises(ModelError, match=word):
        table1(**change)


def test_no_backlash_needs_characteristic_length():
    p = table1(j_n=0.0)
    with pytest.raises(ModelError, match="b_c"):
        p.scales()
    m = p.gear_model(3000.0, 1000.0, b_c=1e-6)
    assert isinstance(m, GearModel) and m.D == 0.0
