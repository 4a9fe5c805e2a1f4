"""Tooth-pair stiffness by the potential-energy method against closed forms and ISO 6336-1."""

import math

import numpy as np
import pytest

from geardyn.errors import ModelError
from geardyn.standards.iso6336 import cylindrical_mesh
from geardyn.tooth.energy import cantilever_compliance, hertz_compliance
from geardyn.tooth.faults import Broken, Crack, Modifications, Spall, Wear
from geardyn.tooth.geometry import pair_geometry
from geardyn.tooth.mesh import mesh_stiffness, share_load

E, NU = 206e9, 0.3


def test_hertz_term_is_yang_sun_closed_form():
    # Yang & Sun (1985): k_h = pi E L / (4 (1 - nu^2)) for one material, per unit width L = 1
    assert hertz_compliance(E, NU, E, NU) == pytest.approx(4 * (1 - NU**2) / (math.pi * E), rel=1e-15)
    assert hertz_compliance(E, NU, 2 * E, 0.25) == pytest.approx(
        2 / math.pi * ((1 - NU**2) / E + (1 - 0.0625) / (2 * E)), rel=1e-15
    )


@pytest.mark.parametrize("alpha_deg", [0.0, 15.0, 30.0])
def test_rectangular_cantilever_reduced_from_the_integrals(alpha_deg):
    L, w, h_l = 6e-3, 4e-3, 1.5e-3
    y = np.linspace(0.0, L, 4001) + 0.05  # clamped at y = 0.05 m
    a = math.radians(alpha_deg)
    kb, ks, ka = cantilever_compliance(y, np.full_like(y, w), np.array([y[-1]]), np.array([h_l]), np.array([a]), E, NU)
    c, s = math.cos(a), math.sin(a)
    I, A, G = w**3 / 12, w, E / (2 * (1 + NU))
    # closed forms: int_0^L [c (L - x) - s h]^2 / (E I) dx, 1.2 c^2 L / (G A), s^2 L / (E A)
    bending = (c * c * L**3 / 3 - c * s * h_l * L**2 + s * s * h_l**2 * L) / (E * I)
    assert kb[0] == pytest.approx(bending, rel=1e-6)
    assert ks[0] == pytest.approx(1.2 * c * c * L / (G * A), rel=1e-12)
    assert ka[0] == pytest.approx(s * s * L / (E * A), rel=1e-12) if alpha_deg else ka[0] == 0.0
    if alpha_deg == 0.0:  # Timoshenko cantilever: L^3/(3EI) + 1.2 L/(GA)
        assert kb[0] + ks[0] == pytest.approx(L**3 / (3 * E * I) + 1.2 * L / (G * A), rel=1e-6)


def test_two_equal_pairs_share_the_load_equally():
    k = np.array([[3e8, 3e8]])
    d = share_load(k, np.zeros((1, 2)), 1000.0)
    assert d[0] == pytest.approx(1000.0 / 6e8, rel=1e-15)
    # a pair of equal gears: at the phase where the two pairs sit symmetrically about the middle of the
    # path of contact, each carries half the load
    geo = pair_geometry(25, 25, 0.004, face_width=0.02)
    s_mid = 0.5 * (geo.s_A + geo.s_E)
    theta = (s_mid - 0.5 * geo.p_bt - geo.s_A) / geo.p_bt
    ms = mesh_stiffness(geo, 200.0, phases=np.array([theta]))
    assert ms.pairs_in_contact[0] == 2
    np.testing.assert_allclose(ms.share[0, :2], [0.5, 0.5], rtol=1e-12)


def test_linear_tip_relief_ste_below_and_above_the_transition_load():
    k1, k2, C = 4e8, 3e8, 10e-6
    k = np.array([[k1, k2]])
    e = np.array([[0.0, C]])
    F_t = k1 * C  # transition: the unrelieved pair alone deflects by C
    for F in (0.3 * F_t, 0.9 * F_t):  # below: one pair carries everything
        assert share_load(k, e, F)[0] == pytest.approx(F / k1, rel=1e-14)
    for F in (1.1 * F_t, 3.0 * F_t):  # above: both, delta = (F + k2 C)/(k1 + k2)
        assert share_load(k, e, F)[0] == pytest.approx((F + k2 * C) / (k1 + k2), rel=1e-14)


def test_tip_relief_in_the_mesh_below_and_above_transition():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    La = 0.25 * geo.p_bt
    mods = Modifications(tip_relief=(20e-6, 0.0), tip_length=(La, 0.0))
    # a phase where the older pair is in the pinion's tip-relief zone and the newer one at the start
    theta = np.array([0.5])
    healthy = mesh_stiffness(geo, 5.0, phases=theta)
    lo = mesh_stiffness(geo, 5.0, phases=theta, modifications=mods)
    hi = mesh_stiffness(geo, 5000.0, phases=theta, modifications=mods)
    s_old = geo.s_A + 1.5 * geo.p_bt
    e_old = 20e-6 * (s_old - (geo.s_E - La)) / La
    assert 0 < e_old < 20e-6
    k_tot = healthy.stiffness_unmodified[0]
    assert lo.pairs_in_contact[0] == 1 and hi.pairs_in_contact[0] == 2
    k_new = lo.stiffness[0]  # only the new pair carries at low load
    assert lo.ste[0] == pytest.approx(lo.force / k_new, rel=1e-12)
    assert hi.ste[0] == pytest.approx((hi.force + (k_tot - k_new) * e_old) / k_tot, rel=1e-9)


@pytest.mark.parametrize(
    "z1,z2,m", [(18, 36, 0.002), (20, 40, 0.003), (25, 25, 0.005), (30, 75, 0.004), (40, 60, 0.006)]
)
def test_mean_mesh_stiffness_within_20_percent_of_iso_6336(z1, z2, m):
    geo = pair_geometry(z1, z2, m, face_width=0.03)
    ms = mesh_stiffness(geo, 500.0)
    iso = cylindrical_mesh(z1, z2, m, math.radians(20.0), 0.0, 0.03)  # C_F = 1, C_M = 0.8, C_R = 1, C_B
    ratio = ms.mean_stiffness / 0.03 / iso.c_gamma_alpha
    assert abs(ratio - 1.0) < 0.20
    assert geo.eps_alpha == pytest.approx(iso.eps_alpha, rel=1e-12)


def test_crack_reduces_stiffness_monotonically_with_depth():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    means, mins = [], []
    for depth in (0.0, 0.1, 0.25, 0.5, 0.75):
        ms = mesh_stiffness(geo, 100.0, faults=[Crack(0, 0, depth)] if depth else [], cycles=20, points=32)
        means.append(ms.mean_stiffness)
        mins.append(ms.stiffness.min())
    assert np.all(np.diff(means) < 0) and np.all(np.diff(mins) < 0)


def test_faults_enter_as_data_on_any_tooth():
    geo = pair_geometry(20, 40, 0.003, face_width=0.02)
    healthy = mesh_stiffness(geo, 100.0, cycles=40, points=32, slices=10)
    faults = [
        Crack(0, 3, 0.8, length=0.5),
        Spall(1, 7, at=0.5, length=1e-3, width=5e-3, depth=1e-3),
        Broken(0, 11, remaining=0.7),
        Wear(1, 2e-6, kind="sliding"),
    ]
    ms = mesh_stiffness(geo, 100.0, faults=faults, slices=10, points=32)
    assert ms.cycles == 40  # lcm(20, 40): faults on both gears
    cycle = np.floor(ms.phase).astype(int)
    k_h = np.tile(healthy.stiffness, 1)
    for tooth, gear in ((3, 0), (11, 0), (7, 1)):
        z = (20, 40)[gear]
        # cycles in which that tooth is in mesh (entered at cycle n with n mod z == tooth, or one before)
        near = np.isin(cycle % z, [tooth, (tooth + 1) % z])
        assert np.all(ms.stiffness[near] <= k_h[near] * (1 + 1e-12))
        assert np.any(ms.stiffness[near] < 0.95 * k_h[near])
    with pytest.raises(ModelError):
        mesh_stiffness(geo, 100.0, faults=[Crack(0, 25, 0.5)])


def test_bevel_pair_through_its_virtual_cylindrical_gears_matches_iso_10300():
    from geardyn.standards.iso10300 import bevel_mesh

    bm = bevel_mesh(23, 47, 7.28e-3, math.radians(35.0), math.radians(20.0), math.radians(90.0), 0.1)
    geo = pair_geometry(bm.z_v1, bm.z_v2, 7.28e-3, beta=bm.beta_v, face_width=bm.b_v_eff, teeth=(23, 47))
    # the path of contact of the virtual gears by this module's geometry against ISO 10300-1's g_va formula
    assert geo.eps_alpha == pytest.approx(bm.eps_valpha, rel=1e-10)
    assert geo.eps_beta == pytest.approx(bm.eps_vbeta, rel=1e-10)
    ms = mesh_stiffness(geo, 1932.0, faults=[Crack(0, 22, 0.5)], points=8)
    assert ms.cycles == 23  # the real pinion's teeth index the faults
    with pytest.raises(ModelError):
        mesh_stiffness(geo, 1932.0, faults=[Crack(0, 23, 0.5)])
