"""geardyn's tooth stiffness against independent references on three standard spur pairs (19/48 m 3.2,
23/47 m 5, 30/30 m 4; steel, 20°, ISO 53 profile A, bore radius 0.25 × pitch radius; the tooth-pair files
examples/tooth_*.toml):

* an independent potential-energy implementation (``benchmarks/tooth_fe_model.py``: the rack-cut fillet in
  the closed form of the trochoid, exact contact positions along the line of action, adaptive quadrature;
  nothing of geardyn): mean stiffness per face width within 5 %, curve shape within 3 % RMS;
* ISO 6336-1 Method B c_γα = (0.75 ε_α + 0.25) c′: within 20 %;
* (slow) a 2-D plane-stress finite-element model of the whole gear (scikit-fem, the ``validate`` extra):
  bending + shear + axial + foundation compliance within 10 % at seven points along each gear's contact
  (observed ≤ 3.8 %); the single-pair stiffness reduction of a root crack of 25 % and of 50 % within 20 % of
  the FE's (the slit's tip refined by four halvings, converged to 0.2 %: ``docs/excitation.md``).  The
  crack's stress intensity at the fillet is the larger of the strip's and the notch's short-crack one; with
  the strip's alone the reduction at 25 % is 0.6-0.7 of the FE's (the table in ``docs/excitation.md``).  The
  same tolerance holds from 37.5 % to 75 % depth on the 19/48 pinion.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from tooth_fe_model import Gear, pair_stiffness  # noqa: E402

from geardyn.tooth.config import load_case  # noqa: E402
from geardyn.tooth.energy import hertz_compliance, tooth_compliance  # noqa: E402
from geardyn.tooth.mesh import mesh_stiffness  # noqa: E402
from geardyn.tooth.result import iso_beside  # noqa: E402

PAIRS = ("tooth_19_48", "tooth_23_47", "tooth_30_30")


def _geo(name):
    return load_case(ROOT / "examples" / f"{name}.toml").geometry


def _gears(geo):
    return [Gear(int(g.teeth), geo.m_n, x=g.x, bore=g.bore_radius, E=g.E, nu=g.nu) for g in geo.gears]


@pytest.mark.parametrize("name", PAIRS)
def test_mean_and_shape_against_an_independent_potential_energy_reference_and_iso(name):
    geo = _geo(name)
    ms = mesh_stiffness(geo, 100.0, points=64)
    k = ms.stiffness / geo.face_width
    _, k_ref = pair_stiffness(*_gears(geo), points=64, u_f="contact")
    assert k.mean() == pytest.approx(k_ref.mean(), rel=0.05)
    assert np.sqrt(np.mean((k / k.mean() - k_ref / k_ref.mean()) ** 2)) < 0.03
    iso = iso_beside(ms)
    assert abs(iso["mesh_mean_over_c_gamma"] - 1.0) < 0.20


@pytest.mark.slow
@pytest.mark.parametrize("name", PAIRS)
def test_compliance_and_crack_against_finite_elements(name):
    pytest.importorskip("skfem")
    from tooth_fe_model import build_mesh, crack_depth_of, fe_compliance

    geo = _geo(name)
    s = np.linspace(geo.s_A, geo.s_E, 7)
    fe = []
    for gear in (0, 1):
        radii = geo.contact_radius(gear, s)
        c_fe = fe_compliance(build_mesh(_gears(geo)[gear], radii, level=1.0), radii)
        c_g = tooth_compliance(geo, gear, radii).total
        np.testing.assert_array_less(np.abs(c_g / c_fe - 1.0), 0.10)
        fe.append((c_g, c_fe))
    ch = hertz_compliance(geo.gears[0].E, geo.gears[0].nu, geo.gears[1].E, geo.gears[1].nu)
    radii = geo.contact_radius(0, s)
    (c0, f0), (w, wf) = fe
    ratio = {}
    for depth in (0.25, 0.5):
        fg = build_mesh(_gears(geo)[0], radii, level=1.0, crack=depth, tip=4)
        d = crack_depth_of(fg, depth)
        f1 = fe_compliance(fg, radii)
        c1 = tooth_compliance(geo, 0, radii, crack_depth=d).total
        red_g = np.mean(1 - (c0 + w + ch) / (c1 + w + ch))
        red_f = np.mean(1 - (f0 + wf + ch) / (f1 + wf + ch))
        ratio[depth] = red_g / red_f
    assert abs(ratio[0.25] - 1.0) < 0.20, ratio
    assert abs(ratio[0.5] - 1.0) < 0.20, ratio


@pytest.mark.slow
def test_crack_reduction_follows_the_finite_elements_with_depth():
    # beyond the two depths: the same tolerance at 37.5 %, 62.5 % and 75 % of h_c on the 19/48 pinion
    # (observed 1.05-1.06 of the FE's; the section laws fall with depth against it, docs/excitation.md)
    pytest.importorskip("skfem")
    from tooth_fe_model import build_mesh, crack_depth_of, fe_compliance

    geo = _geo("tooth_19_48")
    s = np.linspace(geo.s_A, geo.s_E, 7)
    radii, wheel = geo.contact_radius(0, s), geo.contact_radius(1, s)
    g0, g1 = _gears(geo)
    ch = hertz_compliance(geo.gears[0].E, geo.gears[0].nu, geo.gears[1].E, geo.gears[1].nu)
    f0, wf = fe_compliance(build_mesh(g0, radii), radii), fe_compliance(build_mesh(g1, wheel), wheel)
    c0, w = tooth_compliance(geo, 0, radii).total, tooth_compliance(geo, 1, wheel).total
    for depth in (0.375, 0.625, 0.75):
        fg = build_mesh(g0, radii, crack=depth, tip=4)
        d = crack_depth_of(fg, depth)
        assert d == pytest.approx(depth, abs=0.002)
        red_f = np.mean(1 - (f0 + wf + ch) / (fe_compliance(fg, radii) + wf + ch))
        red_g = np.mean(1 - (c0 + w + ch) / (tooth_compliance(geo, 0, radii, crack_depth=d).total + w + ch))
        assert abs(red_g / red_f - 1.0) < 0.20, (depth, red_g / red_f)
