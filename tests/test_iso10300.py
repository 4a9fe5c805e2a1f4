"""ISO 10300-1 virtual cylindrical gears against the printed samples of ISO/TR 10300-30.

Printed values: ISO/TR 10300-30:2024 sample 1 (Annex A, spiral bevel pair) and sample 2 (Annex B,
hypoid pair), as transcribed in the public repository afuentesaz/AGMAStandards
(ISO10300Calc/Calc/SelfTest.cs).  Each check allows half a unit of the last printed digit unless
a comment says why the sample's own rounded inputs need one unit.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import pint
import pytest

from geardyn.errors import ModelError
from geardyn.standards import bevel_mesh, cylindrical_mesh, dynamic_factor_method_b, method_b_coefficients

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
_U = pint.UnitRegistry()


def _si(v):
    if isinstance(v, dict):
        v = v["value"]
    if isinstance(v, str):
        return _U.Quantity(v).to_base_units().magnitude
    return float(v)


def _mesh_from_toml(name: str):
    cfg = tomllib.loads((EXAMPLES / name).read_text(encoding="utf-8"))
    g, op = cfg["gear_pair"], cfg["operating"]
    opt = {
        k: _si(g[k])
        for k in (
            "beta_m2",
            "alpha_lim",
            "offset",
            "zeta_mp",
            "zeta_m",
            "d_m1",
            "d_m2",
            "delta1",
            "delta2",
            "h_am1",
            "h_am2",
            "b2_eff",
            "K_A",
            "f_pt",
            "density",
        )
        if k in g
    }
    return bevel_mesh(
        int(g["z1"]),
        int(g["z2"]),
        _si(g["m_mn"]),
        _si(g["beta_m"]),
        _si(g["alpha_n"]),
        _si(g["Sigma"]),
        _si(g["face_width"]),
        torque1=_si(op["torque"]),
        speed1=_si(op["rpm"]),
        **opt,
    )


def _printed(value: float, printed: str, units: float = 0.5) -> None:
    """value matches the printed number to ``units`` of its last printed digit."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    assert abs(value - float(printed)) <= units * 10.0**-decimals + 1e-12, (value, printed)


@pytest.fixture(scope="module")
def sample1():
    return _mesh_from_toml("iso10300_sample1.toml")


@pytest.fixture(scope="module")
def sample2():
    return _mesh_from_toml("iso10300_sample2_hypoid.toml")


def test_sample1_contact_ratios_and_face_width(sample1):
    j = sample1.to_json()
    _printed(j["contact_ratio_alpha"], "1.165")
    _printed(j["contact_ratio_beta"], "1.227")
    _printed(j["contact_ratio_total"], "2.392")
    _printed(j["b_v_eff_mm"], "21.590")
    _printed(j["b_v_mm"], "25.400")
    _printed(j["virtual_gears"]["p_vet_mm"], "11.262")
    # g_va = 13.1206 here against the printed 13.120: the sample computes from unrounded d_m and delta
    _printed(j["virtual_gears"]["g_valpha_mm"], "13.120", units=1.0)


def test_sample1_virtual_gears(sample1):
    v = sample1.to_json()["virtual_gears"]
    # the virtual diameters inherit the rounding of the printed d_m (3 decimals): one unit allowed,
    # and d_v2 = u^2 d_v1 amplifies it by u^2 = 7.8 (two units)
    _printed(v["d_v_mm"][0], "58.350", units=1.0)
    _printed(v["d_v_mm"][1], "452.804", units=2.5)
    _printed(v["d_va_mm"][0], "68.023")
    _printed(v["d_va_mm"][1], "455.984", units=2.5)
    _printed(v["d_vb_mm"][0], "53.323")
    _printed(v["d_vb_mm"][1], "413.796", units=2.5)
    _printed(v["alpha_vet_deg"], "23.957")
    _printed(v["beta_vb_deg"], "32.615")
    _printed(v["beta_v_deg"], "35.0")
    _printed(v["m_vt_mm"], "3.923")
    _printed(v["z_v"][0], "14.875")
    _printed(v["z_v"][1], "115.431", units=1.0)


def test_sample1_stiffness_resonance_and_kv(sample1):
    j = sample1.to_json()
    # line load F_vmt K_A / b_v,eff = 557 N/mm >= 100 N/mm: C_F = 1, c_gamma = 20, c' = 14 N/(mm um)
    assert j["C_F"] == 1.0
    assert j["c_gamma_N_per_mm_um"] == pytest.approx(20.0)
    assert j["c_prime_N_per_mm_um"] == pytest.approx(14.0)
    assert sample1.F_mt1 == pytest.approx(2000 * 300 / 54.918, rel=1e-12)
    _printed(sample1.F_mt1, "10925.3", units=1.0)  # printed F_mt1 (10925.4 from the printed d_m1)
    # n_E1 and N are not among the transcribed printed values; they are checked by their formula
    m_red = j["m_red_kg_per_mm"]
    assert j["resonance_speed_rpm"] == pytest.approx(30000 / (math.pi * 14) * math.sqrt(20 / m_red), rel=1e-12)
    assert j["resonance_ratio"] == pytest.approx(1200 / j["resonance_speed_rpm"], rel=1e-12)
    assert j["K_v_sector"] == "subcritical"
    _printed(j["K_v"], "1.020")


def test_sample1_kappa_from_geometry(sample1):
    kappa = sample1.to_json()["kappa_from_geometry"]
    assert isinstance(kappa, list) and len(kappa) == 3
    # the estimate: eps_va ~ 1.17 and eps_vb ~ 1.23 give kappa1 ~ 0.05
    assert kappa[0] == pytest.approx(0.046, abs=0.0005)


def test_sample2_hypoid(sample2):
    j = sample2.to_json()
    _printed(j["contact_ratio_alpha"], "1.010")
    # eps_vb and p_vet are proportional to m_mn, printed rounded as 2.640 mm: one unit allowed
    _printed(j["contact_ratio_beta"], "2.096", units=1.0)
    _printed(j["contact_ratio_total"], "3.106")
    _printed(j["b_v_eff_mm"], "24.880")
    _printed(j["b_v_mm"], "29.271")
    _printed(j["virtual_gears"]["g_valpha_mm"], "10.435")
    # p_vet = pi m_mn cos(alpha_vet)/cos(beta_v): the rounding of m_mn (+-0.0005 mm of 2.640 mm)
    # alone moves it by +-0.002 mm, two units of the printed digit
    _printed(j["virtual_gears"]["p_vet_mm"], "10.329", units=2.0)
    _printed(j["virtual_gears"]["d_vb_mm"][1], "342.334", units=1.0)
    _printed(sample2.F_vmt, "10427.4", units=2.0)
    assert j["K_v_sector"] == "subcritical"
    _printed(j["K_v"], "1.016")
    assert math.degrees(sample2.alpha_nD) == pytest.approx(17.748)
    assert math.degrees(sample2.alpha_nC) == pytest.approx(22.252)


def test_assumed_inputs_are_listed():
    m = bevel_mesh(23, 47, 7.28e-3, math.radians(35), math.radians(20), math.radians(90), 0.1)
    names = {a.name for a in m.assumed}
    assert {"offset", "beta_m2", "d_m1", "delta1", "h_am1", "b2_eff", "density", "torque1", "K_v"} <= names
    assert all(a.source for a in m.assumed)
    assert m.K_v is None and m.N is None
    j = m.to_json()
    assert j["K_v"] is None and j["resonance_speed_rpm"] > 0
    # no offset: pitch cones from the ratio, d_m from the module
    assert m.delta1 == pytest.approx(math.atan(23 / 47))
    assert m.d_m1 == pytest.approx(23 * 7.28e-3 / math.cos(math.radians(35)))


def test_hypoid_needs_its_mean_point_data():
    with pytest.raises(ModelError, match="zeta_mp"):
        bevel_mesh(13, 42, 2.64e-3, math.radians(50), math.radians(20), math.radians(90), 0.03, offset=0.015)


def test_low_load_factor_reduces_stiffness():
    m = bevel_mesh(
        14,
        39,
        3.2133e-3,
        math.radians(35),
        math.radians(20),
        math.radians(90),
        25.4e-3,
        torque1=3.0,
        speed1=100.0,
        f_pt=26e-6,
    )
    # F_vmt / b_v,eff = 109 N / 21.6 mm = 5.06 N/mm: C_F = 0.0506
    assert m.C_F == pytest.approx(2 * 3.0 / m.d_m1 / m.b_v_eff / 1e5)
    assert m.c_gamma == pytest.approx(20e9 * m.C_F)
    assert m.c_prime == pytest.approx(14e9 * m.C_F)


def test_method_b_sectors_are_continuous_at_their_ends():
    B, e = 0.6, 2.39
    kv_main = dynamic_factor_method_b(1.0, B, e)[0]
    assert dynamic_factor_method_b(1.25, B, e)[0] == pytest.approx(kv_main)
    assert dynamic_factor_method_b(1.2500001, B, e)[0] == pytest.approx(kv_main, abs=1e-5)
    kv_super = dynamic_factor_method_b(2.0, B, e)[0]
    assert dynamic_factor_method_b(1.4999999, B, e)[0] == pytest.approx(kv_super, abs=1e-5)
    assert [dynamic_factor_method_b(n, B, e)[1] for n in (0.5, 1.0, 1.3, 2.0)] == [
        "subcritical",
        "main resonance",
        "intermediate",
        "supercritical",
    ]
    cv = method_b_coefficients(1.4)
    assert (cv["cv1"], cv["cv2"], cv["cv3"], cv["cv7"]) == (0.32, 0.34, 0.23, 0.75)
    # cv7 is continuous at eps_gamma = 1.5 and 2.5
    assert method_b_coefficients(1.5)["cv7"] == pytest.approx(0.75)
    assert method_b_coefficients(2.5)["cv7"] == pytest.approx(1.0)


def test_spur_limit_and_bevel_to_cylindrical():
    # spur gears: eps_beta = 0 and eps_gamma = eps_alpha
    s = cylindrical_mesh(20, 20, 1e-3, math.radians(20), 0.0, 0.01)
    assert s.eps_beta == 0.0 and s.eps_gamma == s.eps_alpha
    # closed form of 20:20 standard spur gears, alpha = 20 deg, h_a = m: eps_alpha = 1.5570
    ra, rb = 11.0, 10.0 * math.cos(math.radians(20))
    closed = (2 * math.sqrt(ra**2 - rb**2) - 20.0 * math.sin(math.radians(20))) / (math.pi * math.cos(math.radians(20)))
    assert s.eps_alpha == pytest.approx(closed, rel=1e-12)
    assert round(s.eps_alpha, 3) == 1.557
    # a straight bevel pair with Sigma = 90 deg has the contact ratio of its virtual spur pair
    m = bevel_mesh(20, 20, 1e-3, 0.0, math.radians(20), math.radians(90), 0.01)
    zv = 20 / math.cos(math.pi / 4)
    d_v = zv * 1e-3
    rav, rbv = d_v / 2 + 1e-3, d_v / 2 * math.cos(math.radians(20))
    ev = (2 * math.sqrt(rav**2 - rbv**2) - d_v * math.sin(math.radians(20))) / (
        math.pi * 1e-3 * math.cos(math.radians(20))
    )
    assert m.eps_valpha == pytest.approx(ev, rel=1e-12) and m.eps_vbeta == 0.0


def test_helical_face_contact_ratio_and_iso6336_stiffness():
    h = cylindrical_mesh(17, 53, 4e-3, math.radians(20), math.radians(15), 0.05, torque1=500.0)
    assert h.eps_beta == pytest.approx(0.05 * math.sin(math.radians(15)) / (math.pi * 4e-3))
    # ISO 6336-1: c_gamma_alpha = c'(0.75 eps_alpha + 0.25), c_gamma_beta = 0.85 c_gamma_alpha
    assert h.c_gamma_alpha == pytest.approx(h.c_prime * (0.75 * h.eps_alpha + 0.25))
    assert h.c_gamma_beta == pytest.approx(0.85 * h.c_gamma_alpha)
    # the usual range of c' of steel gears (ISO 6336-1 gives 14 N/(mm um) as a typical value)
    assert 12e9 < h.c_prime < 18e9
    # profile shift raises the working pressure angle and keeps a_w = a cos(alpha_t)/cos(alpha_wt)
    p = cylindrical_mesh(17, 53, 4e-3, math.radians(20), 0.0, 0.05, x1=0.3, x2=0.1)
    assert p.alpha_wt > math.radians(20) and p.a_w > 0.5 * (p.d1 + p.d2)


def test_response_carries_the_iso_kv_curve(tmp_path):
    import json

    from typer.testing import CliRunner

    from geardyn.cli import app

    r = CliRunner().invoke(
        app,
        [
            "response",
            "--config",
            str(EXAMPLES / "iso10300_sample1.toml"),
            "--rpm-start",
            "5000",
            "--rpm-stop",
            "30000",
            "--num",
            "6",
            "--transient",
            "60",
            "--settle",
            "0",
            "--json",
            "--out",
            str(tmp_path),
        ],
    )
    assert r.exit_code == 0, r.output
    b = json.loads(r.stdout)["iso_kv"]
    assert len(b["K_v"]) == len(b["rpm"]) == 6 and set(b["simulated"]) == {"up", "down"}
    assert b["resonance_speed_rpm"] == pytest.approx(b["sector_bounds_rpm"]["subcritical_end"] / 0.75)
    # K_v at 1200 rpm (the sample's speed) is the printed one; here the grid's own speeds
    one = bevel_mesh(
        14,
        39,
        3.2133e-3,
        math.radians(35),
        math.radians(20),
        math.radians(90),
        25.4e-3,
        d_m1=54.918e-3,
        d_m2=152.987e-3,
        delta1=math.radians(19.747),
        delta2=math.radians(70.253),
        h_am1=4.837e-3,
        h_am2=1.590e-3,
        b2_eff=21.59e-3,
        K_A=1.1,
        f_pt=26e-6,
        torque1=b["torque_N_m"],
        speed1=5000 * math.pi / 30,
    )
    assert b["K_v"][0] == pytest.approx(one.K_v, rel=1e-12)
    assert b["sector"][0] == "subcritical" and "main resonance" in b["sector"]
    assert all(v is None or v >= 0 for v in b["simulated"]["up"])
    assert (tmp_path / "response_iso_kv.png").is_file()
    # a pair without the ISO inputs K_v needs (the paper's) has no iso_kv block
    r = CliRunner().invoke(
        app,
        [
            "response",
            "--rpm-start",
            "2000",
            "--rpm-stop",
            "3000",
            "--num",
            "3",
            "--transient",
            "30",
            "--settle",
            "0",
            "--json",
        ],
    )
    assert r.exit_code == 0 and "iso_kv" not in json.loads(r.stdout)
