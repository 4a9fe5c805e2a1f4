"""The root crack at the fillet: the notch's inputs against ISO 6336-3's closed forms, and the crack's stress
intensity in its two limits.

* The fillet at the crack's start: geardyn's 30° point is found on its tabulated trochoid (the numerical
  envelope of the rack's tip rounding) and its radius of curvature by central differences.  ISO 6336-3:2006
  (Method B, eqs. for E, G, H, ϑ, s_Fn and ρ_F of an external gear cut by a rack) gives both in closed form
  for a generated tooth; the chord s_Fn = 2 h_c and the fillet radius ρ_F must agree to 0.5 % (observed
  ≤ 0.25 %), for profiles A and D and a shifted pinion.
* The crack's compliance (``energy.crack_compliance``, the module docstring's integral): for a crack much
  shorter than the fillet radius the bending factor is the notch's 1.12 Y_S (Lukáš 1987), so the compliance
  tends to (2π W²/E)(ξ²/2)[(1.12 Y_S · 6M/W² + 1.12 N/W)² + (1.122 V/W)²] (ξ = a/W), checked to 1e-4 at
  a = 1e-5 h_c; without a fillet (ρ_F = 0, the radial root) it is the strip's closed form; and its excess
  over the strip falls with depth, the short-crack effect fading once the crack runs past the notch's
  stress field (a few tenths of ρ_F).
"""

import math

import numpy as np
import pytest

from geardyn.tooth.energy import TADA_BENDING, crack_compliance, load_point, stress_correction
from geardyn.tooth.geometry import pair_geometry


def _iso_fillet(z, x, h_fP, rho_fP, alpha=math.radians(20.0)):
    """ISO 6336-3 Method B: (s_Fn, ρ_F) in modules of an external spur gear cut by a rack."""
    E = math.pi / 4 - h_fP * math.tan(alpha) - (1 - math.sin(alpha)) * rho_fP / math.cos(alpha)
    G = rho_fP - h_fP + x
    H = 2 / z * (math.pi / 2 - E) - math.pi / 3
    th = math.pi / 6
    for _ in range(200):
        th = 2 * G / z * math.tan(th) - H
    s_Fn = z * math.sin(math.pi / 3 - th) + math.sqrt(3) * (G / math.cos(th) - rho_fP)
    rho_F = rho_fP + 2 * G * G / (math.cos(th) * (z * math.cos(th) ** 2 - 2 * G))
    return s_Fn, rho_F


@pytest.mark.parametrize(
    "z1, z2, x1, rack",
    [(19, 48, 0.0, "A"), (23, 47, 0.0, "A"), (30, 30, 0.0, "A"), (19, 48, 0.3, "A"), (25, 40, 0.0, "D")],
)
def test_fillet_chord_and_radius_at_the_30_degree_point_are_iso_6336_3s(z1, z2, x1, rack):
    m = 0.004
    geo = pair_geometry(z1, z2, m, x1=x1, x2=-x1, face_width=0.02, rack=rack)
    h_fP, rho_fP = {"A": (1.25, 0.38), "D": (1.40, 0.39)}[rack]
    for g, (z, x) in enumerate(((z1, x1), (z2, -x1))):
        sec = geo.sections[g]
        s_Fn, rho_F = _iso_fillet(z, x, h_fP, rho_fP)
        assert 2 * sec.h[sec.crack_start] / m == pytest.approx(s_Fn, rel=5e-3)
        assert sec.rho_F / m == pytest.approx(rho_F, rel=5e-3)


def test_radial_root_has_no_fillet():
    geo = pair_geometry(20, 40, 0.003, root="radial")
    assert geo.sections[0].rho_F == 0.0


def _loads(geo):
    sec = geo.sections[0]
    return sec, load_point(sec, geo.contact_radius(0, np.linspace(geo.s_A, geo.s_E, 5)))


def test_a_short_crack_sees_the_notch_stress():
    geo = pair_geometry(19, 48, 0.0032)
    sec, (d, h_l, a1) = _loads(geo)
    i = sec.crack_start
    y_c, h_c = float(sec.y[i]), float(sec.h[i])
    W, E = 2 * h_c, geo.gears[0].E
    depth = 1e-5
    xi = depth * h_c / W
    M = np.cos(a1) * (d - y_c) - np.sin(a1) * h_l
    N, V = -np.sin(a1), np.cos(a1)
    Y_S = stress_correction(W, M / np.cos(a1), sec.rho_F)
    limit = (
        2 * math.pi * W**2 / E * xi**2 / 2 * ((1.12 * Y_S * 6 * M / W**2 + 1.12 * N / W) ** 2 + (1.122 * V / W) ** 2)
    )
    got = crack_compliance(depth, y_c, h_c, d, h_l, a1, E, sec.rho_F)
    np.testing.assert_allclose(got, limit, rtol=1e-4)
    assert np.all(Y_S > 1.2)  # the fillet raises the stress: a notch factor above ISO's floor of 1.2


def test_without_a_fillet_the_strip_alone_and_the_notch_fades_with_depth():
    geo = pair_geometry(19, 48, 0.0032)
    sec, (d, h_l, a1) = _loads(geo)
    i = sec.crack_start
    y_c, h_c, E = float(sec.y[i]), float(sec.h[i]), geo.gears[0].E
    depths = (0.05, 0.1, 0.25, 0.5, 0.75)
    strip = np.array([crack_compliance(q, y_c, h_c, d, h_l, a1, E) for q in depths])
    notch = np.array([crack_compliance(q, y_c, h_c, d, h_l, a1, E, sec.rho_F) for q in depths])
    # the strip's closed form: pure bending at ξ small, K = 1.122 σ √(πa)
    W = 2 * h_c
    M = np.cos(a1) * (d - y_c) - np.sin(a1) * h_l
    pure = crack_compliance(1e-5, y_c, h_c, d, h_l, np.zeros_like(a1), E)
    xi = 1e-5 * h_c / W
    np.testing.assert_allclose(
        pure,
        2 * math.pi * W**2 / E * xi**2 / 2 * ((TADA_BENDING[0] * 6 * (d - y_c) / W**2) ** 2 + (1.122 / W) ** 2),
        rtol=1e-4,
    )
    assert M.shape == notch[0].shape
    excess = notch / strip
    assert np.all(excess >= 1.0)
    assert np.all(np.diff(excess, axis=0) < 0)  # the short-crack excess falls with depth at every load point
