"""Physical front-end: rpm and N·m in, µm, N, Hz and the dynamic factor out (issue: the engineer's view).

The reference values here are computed independently from the paper's Table 1 with plain
formulas (directional radius r cos α_n cos β_m, m_e = I1 I2/(I2 R1² + I1 R2²), F_p = T1/R1,
ω_e = 2π z1 n/60, the assumed k0 = 100 mm × 20 N/(mm·µm)), not with geardyn's conversions.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.analysis.physical import mesh_force, physical_json
from geardyn.cli import app, build_model
from geardyn.config import load_config
from geardyn.io import read_netcdf
from geardyn.model import GearModel, ModelError
from geardyn.units import PhysicalScales, omega_range, operating_overrides, scales_of, sweep_range

# ----------------------------------------------------------------------------- Table 1, by hand
Z1 = 23
LAM = math.cos(math.radians(20.0)) * math.cos(math.radians(35.0))
R1 = 0.1255 * LAM
R2 = 0.256 * LAM
I1, I2 = 1.772, 1.873
M_E = I1 * I2 / (I2 * R1**2 + I1 * R2**2)
K0 = 0.100 * 20e9  # assumed: face width 100 mm × c_γ 20 N/(mm·µm)
B_N = 0.05e-3  # half of the 0.1 mm normal backlash; b_c = b_n (D = 1)
OMEGA_N = math.sqrt(K0 / M_E)
XI0, XI1, KAPPA1, EPS1 = 0.1, 0.05, 0.2, 0.5

RPM = 2400.0
TORQUE = 1500.0


def omega_of(rpm: float) -> float:
    return 2 * math.pi * Z1 * rpm / 60.0 / OMEGA_N


def fp_of(torque: float) -> float:
    return torque / R1 / (K0 * B_N)


def run_json(args: list[str]) -> dict:
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


# ----------------------------------------------------------------------------- operating point
def test_table1_speed_and_torque_to_model_and_back():
    omega, fp = omega_of(RPM), fp_of(TORQUE)
    assert omega == pytest.approx(0.80164, abs=1e-5)  # stated: 2400 rpm ↔ ω = 0.8016 with k0 = 2000 N/µm
    assert fp == pytest.approx(0.155273, abs=1e-6)  # stated: 1500 N·m ↔ f_p = 0.1553
    sc = scales_of(None)
    assert sc.k0_N_per_m == pytest.approx(K0) and "k0" in sc.assumed
    ov = operating_overrides(sc, rpm=RPM, torque=TORQUE)
    assert ov["omega"] == pytest.approx(omega, rel=1e-12)
    assert ov["fp"] == pytest.approx(fp, rel=1e-12)
    m_cfg = load_config(None).at(rpm=RPM, torque=TORQUE).model
    m_cli = build_model(None, rpm=RPM, torque=TORQUE)
    for m in (m_cfg, m_cli):
        assert m.omega == pytest.approx(omega, rel=1e-12) and m.fp == pytest.approx(fp, rel=1e-12)
        assert (m.xi0, m.xi, m.kappa, m.eps, m.D) == (XI0, (XI1,), (KAPPA1,), (EPS1,), 1.0)
    # and back
    assert sc.rpm_from_omega(omega) == pytest.approx(RPM, rel=1e-12)
    assert sc.torque_from_fp(fp) == pytest.approx(TORQUE, rel=1e-12)
    assert sc.hz_from_omega(omega) == pytest.approx(Z1 * RPM / 60.0, rel=1e-12)
    op = sc.operating_point(m_cli)
    assert op["rpm"] == pytest.approx(RPM) and op["torque_N_m"] == pytest.approx(TORQUE)
    assert op["static_force_N"] == pytest.approx(TORQUE / R1, rel=1e-12)
    # the geometry command at the same operating point
    g = run_json(["geometry", "--rpm", str(RPM), "--torque", str(TORQUE), "--json"])
    assert g["omega"] == pytest.approx(omega, rel=1e-12) and g["fp"] == pytest.approx(fp, rel=1e-12)
    assert g["F_p_N"] == pytest.approx(TORQUE / R1, rel=1e-12)
    assert "k0" in g["assumed"] and "rpm" not in g["assumed"]  # the speed was given, k0 is assumed


def test_scales_agree_with_the_geometry_scales_and_survive_json():
    cfg = load_config(None)
    sc, ref = PhysicalScales.from_config(cfg), cfg.scales
    x = np.array([0.3, 0.8, 1.7])
    assert np.allclose(sc.omega_from_rpm(x * 1000), ref.omega_from_rpm(x * 1000), rtol=1e-14)
    assert np.allclose(sc.N_from_force(x), ref.N_from_force(x), rtol=1e-14)
    assert np.allclose(sc.um_from_u(x), ref.um_from_u(x), rtol=1e-14)
    assert sc.fp_from_torque(1500.0) == pytest.approx(ref.fp_from_torque(1500.0), rel=1e-14)
    assert PhysicalScales.from_json(sc.to_json()) == sc
    assert sc.omega_n_rad_s == pytest.approx(OMEGA_N, rel=1e-12) and sc.m_e_kg == pytest.approx(M_E, rel=1e-12)


def test_rpm_range_to_omega_range():
    sc = scales_of(None)
    w0, w1 = omega_range(sc, 900.0, 3600.0)
    assert (w0, w1) == (pytest.approx(omega_of(900.0), rel=1e-12), pytest.approx(omega_of(3600.0), rel=1e-12))
    assert sweep_range(sc, None, None, 0.5, 0.7) == (0.5, 0.7)
    for args, word in (
        ((sc, 900.0, None), "both"),
        ((sc, 900.0, 1000.0, 0.5, None), "not both"),
        ((sc, -1.0, 1000.0), "> 0 rpm"),
    ):
        with pytest.raises(ModelError, match=word):
            sweep_range(*args)
    with pytest.raises(ModelError, match="swept parameter"):
        sweep_range(sc, 900.0, 1000.0, param="xi0")


@pytest.mark.parametrize(
    "args, word",
    [
        (["simulate", "--rpm", "2400", "--omega", "0.8"], "rpm:"),
        (["simulate", "--torque", "1500", "--fp", "0.2"], "torque:"),
        (["simulate", "--rpm", "-5"], "rpm:"),
        (["bifurcation", "--rpm-start", "900"], "rpm_start:"),
        (["bifurcation", "--param", "xi0", "--rpm-start", "900", "--rpm-stop", "1000"], "rpm_start:"),
        (["response", "--rpm-start", "900", "--rpm-stop", "1000", "--omega-start", "0.3"], "rpm_start:"),
    ],
)
def test_bad_physical_options_refused(args, word):
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2
    assert word in r.output and "Traceback" not in r.output


# ----------------------------------------------------------------------------- physical outputs
def test_linear_limit_mesh_force_and_dynamic_factor_in_newtons():
    """Constant coefficients and a load high enough that contact is never lost: the mesh force is
    F_p + |k0 + i c0 ω_e| |U| cos(...) with U = m_e ω_e² e1 / (k0 − m_e ω_e² + i c0 ω_e), all dimensional."""
    torque = 20000.0
    s = run_json(
        [
            "simulate",
            "--rpm",
            str(RPM),
            "--torque",
            str(torque),
            "--xi1",
            "0",
            "--kappa1",
            "0",
            "--transient",
            "300",
            "--periods",
            "32",
            "--json",
        ]
    )
    assert s["impact"] == "no impact" and s["u_min"] > 1.0
    w_e = 2 * math.pi * Z1 * RPM / 60.0
    c0 = 2 * XI0 * M_E * OMEGA_N
    e1 = EPS1 * B_N
    U = M_E * w_e**2 * e1 / (K0 - M_E * w_e**2 + 1j * c0 * w_e)
    F_p = torque / R1
    F_amp = abs(K0 + 1j * c0 * w_e) * abs(U)
    assert s["static_force_N"] == pytest.approx(F_p, rel=1e-12)
    assert s["mesh_force_max_N"] == pytest.approx(F_p + F_amp, rel=1e-5)
    assert s["mesh_force_min_N"] == pytest.approx(F_p - F_amp, rel=1e-5)
    assert s["mesh_force_mean_N"] == pytest.approx(F_p, rel=1e-6)
    assert s["dynamic_factor"] == pytest.approx((F_p + F_amp) / F_p, rel=1e-5)
    assert s["dte_amplitude_um"] == pytest.approx(abs(U) * 1e6, rel=1e-4)
    assert s["dte_rms_um"] == pytest.approx(abs(U) / math.sqrt(2) * 1e6, rel=1e-6)
    assert s["dte_mean_um"] == pytest.approx((B_N + F_p / K0) * 1e6, rel=1e-6)  # b_n + static deflection
    top = s["spectrum_peaks"][0]
    assert top["order"] == 1.0 and top["frequency_Hz"] == pytest.approx(Z1 * RPM / 60.0, rel=1e-12)
    assert top["amplitude_um"] == pytest.approx(abs(U) * 1e6, rel=1e-6)
    assert s["rpm"] == pytest.approx(RPM) and s["omega"] == pytest.approx(omega_of(RPM), rel=1e-12)


def test_physical_outputs_are_nondimensional_values_times_scales(tmp_path):
    """Paper defaults at 2400 rpm and 1500 N·m (separation every period): every physical output of
    simulate equals the non-dimensional quantity times its scale, recomputed here from the saved
    time history with the model's force law written out."""
    s = run_json(
        [
            "simulate",
            "--rpm",
            str(RPM),
            "--torque",
            str(TORQUE),
            "--transient",
            "200",
            "--periods",
            "40",
            "--json",
            "--out",
            str(tmp_path / "sim"),
        ]
    )
    for key in ("omega", "rpm", "dynamic_factor", "mesh_force_max_N", "dte_rms_um"):
        assert key in s
    assert s["impact"] != "no impact"  # the nonlinear case
    ds = read_netcdf(tmp_path / "sim" / "simulate.nc")
    omega = omega_of(RPM)
    th = omega * ds["tau"].values
    u, v = ds["u"].values, ds["v"].values
    f_u = np.where(u > 1, u - 1, np.where(u < -1, u + 1, 0.0))
    force = 2 * (XI0 + XI1 * np.cos(th)) * v + (1 + KAPPA1 * np.cos(th)) * f_u  # F_n/(k0 b_c)
    F_p = TORQUE / R1
    assert s["mesh_force_max_N"] == pytest.approx(force.max() * K0 * B_N, rel=1e-10)
    assert s["dynamic_factor"] == pytest.approx(force.max() * K0 * B_N / F_p, rel=1e-10)
    assert s["dynamic_factor"] == pytest.approx(force.max() / fp_of(TORQUE), rel=1e-10)
    assert s["dte_rms_um"] == pytest.approx(s["rms"] * B_N * 1e6, rel=1e-12)
    assert s["dte_amplitude_um"] == pytest.approx(s["amplitude"] * B_N * 1e6, rel=1e-12)
    assert s["backlash_um"] == pytest.approx(50.0)
    # the stored variables
    assert np.allclose(ds["mesh_force_N"].values, force * K0 * B_N, rtol=1e-10, atol=1e-6)
    assert np.allclose(ds["dte_um"].values, u * B_N * 1e6, rtol=1e-12)
    assert np.allclose(ds["time_s"].values, ds["tau"].values / OMEGA_N, rtol=1e-12)
    assert np.allclose(ds["frequency_Hz"].values, ds["order"].values * Z1 * RPM / 60.0, rtol=1e-12)
    assert ds["mesh_force_N"].attrs["units"] == "N" and ds["dte_um"].attrs["units"] == "µm"
    # the library function agrees with the formula written out here
    m = GearModel(omega=omega, fp=fp_of(TORQUE))
    assert np.allclose(mesh_force(m, ds["tau"].values, u, v), force, rtol=1e-12, atol=1e-12)
    # in steady state the mean mesh force is the static one (mean of u'' and of the STE forcing vanish)
    assert s["mesh_force_mean_N"] == pytest.approx(F_p, rel=2e-3)


def test_response_against_rpm_gives_speeds_and_jumps_in_rpm():
    s = run_json(
        [
            "response",
            "--rpm-start",
            "1500",
            "--rpm-stop",
            "2000",
            "--num",
            "3",
            "--transient",
            "50",
            "--periods",
            "16",
            "--settle",
            "0",
            "--json",
        ]
    )
    assert s["rpm"] == pytest.approx([1500.0, 1750.0, 2000.0])
    assert s["omega"] == pytest.approx([omega_of(r) for r in (1500.0, 1750.0, 2000.0)], rel=1e-12)
    for j in s["jumps"]:
        assert j["rpm"] == pytest.approx(60.0 * j["omega"] * OMEGA_N / (2 * math.pi * Z1), rel=1e-12)
        assert j["size_um"] == pytest.approx(j["size"] * B_N * 1e6)
    assert len(s["hysteresis_rpm"]) == len(s["hysteresis"])
    assert "k0 = 2000 N/µm (assumed" in s["physical"]["pair"]


def test_physical_json_adds_units_everywhere():
    summ = {
        "omega": 0.5,
        "u_min": 0.2,
        "exponents": [0.01, -0.21],
        "branch": [{"omega": 0.6, "amplitude": 0.1}],
        "param": "omega",
        "values": [0.5, 1.0],
        "hysteresis": [[0.5, 0.6]],
        "start": 0.5,
        "stop": 1.0,
    }
    out = physical_json(summ, GearModel(omega=0.5), None, param="omega")
    assert out["rpm"] == pytest.approx(60 * 0.5 * OMEGA_N / (2 * math.pi * Z1))
    assert out["u_min_um"] == pytest.approx(0.2 * B_N * 1e6)
    assert out["exponents_per_s"] == pytest.approx([0.01 * OMEGA_N, -0.21 * OMEGA_N])
    assert out["branch"][0]["rpm"] == pytest.approx(60 * 0.6 * OMEGA_N / (2 * math.pi * Z1))
    assert out["branch"][0]["amplitude_um"] == pytest.approx(0.1 * B_N * 1e6)
    assert out["values_rpm"] == pytest.approx([60 * w * OMEGA_N / (2 * math.pi * Z1) for w in (0.5, 1.0)])
    assert out["hysteresis_rpm"][0][1] == pytest.approx(60 * 0.6 * OMEGA_N / (2 * math.pi * Z1))
    assert out["rpm_stop"] == pytest.approx(60 * 1.0 * OMEGA_N / (2 * math.pi * Z1))
    assert out["physical"]["static_force_N"] == pytest.approx(0.2 * K0 * B_N)
    assert summ == {
        "omega": 0.5,
        "u_min": 0.2,
        "exponents": [0.01, -0.21],
        "branch": [{"omega": 0.6, "amplitude": 0.1}],
        "param": "omega",
        "values": [0.5, 1.0],
        "hysteresis": [[0.5, 0.6]],
        "start": 0.5,
        "stop": 1.0,
    }


def test_dimensional_config_drives_the_physical_front_end():
    """The automotive example: its own pair and operating point (2500 rpm, 300 N·m) set ω, f_p and the scales."""
    from pathlib import Path

    cfg_path = Path(__file__).resolve().parents[1] / "examples" / "automotive_hypoid_like.toml"
    cfg = load_config(cfg_path)
    sc = PhysicalScales.from_config(cfg)
    s = run_json(["simulate", "--config", str(cfg_path), "--transient", "100", "--periods", "16", "--json"])
    assert s["rpm"] == pytest.approx(2500.0, rel=1e-9) and s["torque_N_m"] == pytest.approx(300.0, rel=1e-9)
    assert s["static_force_N"] == pytest.approx(300.0 / cfg.pair.R1, rel=1e-9)
    assert s["omega"] == pytest.approx(2 * math.pi * 11 * 2500 / 60 / sc.omega_n_rad_s, rel=1e-12)
    s2 = run_json(
        [
            "simulate",
            "--config",
            str(cfg_path),
            "--rpm",
            "4000",
            "--torque",
            "150",
            "--transient",
            "100",
            "--periods",
            "16",
            "--json",
        ]
    )
    assert s2["rpm"] == pytest.approx(4000.0) and s2["torque_N_m"] == pytest.approx(150.0)


def test_lazy_physical_copies_are_computed_when_read_with_the_same_bits():
    import xarray as xr

    from geardyn.analysis.physical import add_physical

    u = np.array([0.1, 0.5, 1.2, np.nan])
    ds = xr.Dataset(
        {"amplitude": ("omega", u), "lle": ("omega", [-0.1, 0.0, 0.02, np.nan])}, coords={"omega": [0.5, 0.8, 1.1, 1.4]}
    )
    sc = scales_of(None)
    lazy = add_physical(ds, sc, lazy=True)
    assert not isinstance(lazy["amplitude_um"].variable._data, np.ndarray)  # held as a lazily indexed array
    np.testing.assert_array_equal(lazy["amplitude_um"].values, u * sc.b_c_m * 1e6)
    np.testing.assert_array_equal(lazy["amplitude_um"][1:3].values, lazy["amplitude_um"].values[1:3])
    np.testing.assert_array_equal(lazy["lle_per_s"].values, add_physical(ds, sc)["lle_per_s"].values)
