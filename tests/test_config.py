"""TOML configurations with units: loading, conversion and refusal of bad input."""

from __future__ import annotations

import json
import math
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.config import load_config, packaged_config_path
from geardyn.errors import ConfigError
from geardyn.model import ModelError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

PAIR = """\
[gear_pair]
z1 = 23
z2 = 47
m_mn = "7.28 mm"
beta_m = "35 deg"
alpha_n = "20 deg"
j_n = "0.1 mm"
I1 = "1.772 kg*m^2"
I2 = "1.873 kg*m^2"
r1 = "125.5 mm"
r2 = "256 mm"
face_width = "100 mm"
"""


def write(tmp_path: Path, text: str, name: str = "pair.toml") -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text), encoding="utf-8")
    return p


def test_packaged_copy_is_identical_to_example():
    assert packaged_config_path().read_text(encoding="utf-8") == (EXAMPLES / "paper_table1.toml").read_text(
        encoding="utf-8"
    )


def test_paper_config_gives_table1_model():
    cfg = load_config(None)
    m = cfg.model
    assert (m.xi0, m.xi, m.kappa, m.eps, m.fp, m.D) == (0.1, (0.05,), (0.2,), (0.5,), 0.2, 1.0)
    assert m.phi_c == m.phi_k == m.phi_e == (0.0,)
    # 3000 rpm with k0 = 100 mm × 20 N/(mm·µm) = 2e9 N/m and m_e = 38.4636 kg
    assert m.omega == pytest.approx(2 * math.pi * 23 * 3000 / 60 / math.sqrt(2e9 / 38.46360), rel=1e-6)
    assert cfg.rpm == pytest.approx(3000.0)
    # torque follows from f_p: T1 = f_p k0 b_n R1
    assert cfg.torque == pytest.approx(0.2 * 2e9 * 5e-5 * 0.0966038, rel=1e-6)
    assert {"face_width", "c_gamma", "k0", "hand", "drive_side", "rpm"} <= set(cfg.assumed)
    s = cfg.geometry_summary()
    assert s["F_p_N"] == pytest.approx(2.0e4, rel=1e-12)
    assert s["delta1_deg"] == pytest.approx(26.0754, abs=1e-4)


def test_example_file_equals_default_and_realistic_example_loads():
    assert load_config(EXAMPLES / "paper_table1.toml").model == load_config(None).model
    auto = load_config(EXAMPLES / "automotive_hypoid_like.toml")
    assert auto.pair.z1 < auto.pair.z2
    assert 0 < auto.model.omega < 5
    assert len(auto.model.eps) >= 1 and all(math.isfinite(e) for e in auto.model.eps)
    assert auto.assumed  # its assumptions are listed


def test_units_are_converted(tmp_path):
    p = write(
        tmp_path,
        PAIR.replace('"7.28 mm"', '"0.00728 m"').replace('"35 deg"', '"0.6108652382 rad"')
        + '\n[operating]\nrpm = "314.1592653589793 rad/s"\ntorque = "1.5 kN*m"\n',
    )
    cfg = load_config(p)
    assert cfg.pair.m_mn == pytest.approx(7.28e-3)
    assert math.degrees(cfg.pair.beta_m) == pytest.approx(35.0, rel=1e-9)
    assert cfg.rpm == pytest.approx(3000.0, rel=1e-12)
    assert cfg.torque == pytest.approx(1500.0)
    assert cfg.model.fp == pytest.approx(1500.0 / cfg.pair.R1 / (2e9 * 5e-5), rel=1e-12)


def test_dimensional_mesh_and_table3_reading(tmp_path):
    p = write(
        tmp_path,
        PAIR
        + """
        [mesh]
        c0 = "5e4 N*s/m"
        k = ["400 N/um"]
        e = ["25 um", "5 um"]
        phi_e = ["0 deg", "90 deg"]
        characteristic_length = "1 mm"
        [operating]
        rpm = "2000 rpm"
        torque = "1000 N*m"
        """,
    )
    cfg = load_config(p)
    m = cfg.model
    assert m.kappa == pytest.approx((0.2,))
    assert m.eps == pytest.approx((0.025, 0.005))  # b_c = 1 mm
    assert m.phi_e == pytest.approx((0.0, math.pi / 2))
    assert m.D == pytest.approx(0.05)  # b_n = 0.05 mm, Table 3 reading
    assert m.xi0 == pytest.approx(5e4 / (2 * cfg.pair.m_e * cfg.pair.omega_n))
    assert "Table 3" in cfg.backlash_reading


def test_model_section_overrides_and_operating_point_follows(tmp_path):
    p = write(tmp_path, PAIR + '\n[mesh]\nfp = 0.2\n[operating]\nrpm = "3000 rpm"\n[model]\nomega = 0.5\n')
    cfg = load_config(p)
    assert cfg.model.omega == 0.5
    assert cfg.rpm == pytest.approx(0.5 * cfg.pair.omega_n * 60 / (2 * math.pi * 23))
    assert any("overrides" in n for n in cfg.notes)
    moved = cfg.at(rpm=1500.0, torque=966.0)
    assert moved.model.omega == pytest.approx(cfg.scales.omega_from_rpm(1500.0))
    assert moved.scales.torque_from_fp(moved.model.fp) == pytest.approx(966.0)


def test_assumed_inline_table(tmp_path):
    p = write(tmp_path, PAIR + '\n[operating]\nrpm = { value = "1000 rpm", assumed = "typical value" }\n')
    cfg = load_config(p)
    a = {x.name: x for x in cfg.assumptions}
    assert a["rpm"].source == "typical value" and a["rpm"].value == 1000.0


# ---------------------------------------------------------------------------- refusals
def test_unknown_key_refused_with_file_line_and_allowed(tmp_path):
    p = write(tmp_path, PAIR + 'face_widht = "90 mm"\n')
    with pytest.raises(ConfigError) as ei:
        load_config(p)
    msg = str(ei.value)
    assert str(p) in msg and "face_widht" in msg and "line 13" in msg and "allowed" in msg and "face_width" in msg
    assert "\n" not in msg


def test_unknown_section_refused(tmp_path):
    p = write(tmp_path, PAIR + "[gearpair]\nz1 = 3\n")
    with pytest.raises(ConfigError, match=r"unknown section or key 'gearpair'"):
        load_config(p)


@pytest.mark.parametrize(
    "old,new,key,what",
    [
        ('"7.28 mm"', '"7.28 kg"', "m_mn", "length"),
        ('"35 deg"', '"35 mm"', "beta_m", "angle"),
        ('"35 deg"', "35", "beta_m", "angle"),
        ('"1.772 kg*m^2"', '"1.772 kg"', "I1", "moment of inertia"),
        ('"0.1 mm"', '"0.1 furlongs per parsec"', "j_n", "length"),
        ('"256 mm"', '"inf mm"', "r2", "finite"),
    ],
)
def test_wrong_unit_refused(tmp_path, old, new, key, what):
    p = write(tmp_path, PAIR.replace(old, new, 1))
    with pytest.raises(ConfigError) as ei:
        load_config(p)
    msg = str(ei.value)
    assert str(p) in msg and f"[gear_pair] {key}" in msg and what in msg


def test_speed_in_hz_refused(tmp_path):
    p = write(tmp_path, PAIR + '\n[operating]\nrpm = "50 Hz"\n')
    with pytest.raises(ConfigError, match=r"line 15: \[operating\] rpm: .*rpm"):
        load_config(p)


@pytest.mark.parametrize(
    "old,new,key",
    [
        ('"35 deg"', '"95 deg"', "beta_m"),
        ("z1 = 23", "z1 = 0", "z1"),
        ('"1.873 kg*m^2"', '"-1 kg*m^2"', "I2"),
    ],
)
def test_out_of_range_refused_with_line(tmp_path, old, new, key):
    text = PAIR.replace(old, new, 1)
    line = 1 + text.splitlines().index(next(ln for ln in text.splitlines() if ln.startswith(key + " ")))
    p = write(tmp_path, text)
    with pytest.raises(ModelError) as ei:
        load_config(p)
    msg = str(ei.value)
    assert f"line {line}:" in msg and key in msg and str(p) in msg


def test_mesh_stiffness_out_of_range_refused(tmp_path):
    p = write(tmp_path, PAIR + "\n[mesh]\nkappa = [0.7, 0.5]\n")
    with pytest.raises(ModelError, match=r"\[mesh\] kappa: sum of \|kappa_r\| must be < 1"):
        load_config(p)


def test_missing_file_refused(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(ConfigError, match=r"nope\.toml: configuration file not found"):
        load_config(missing)


def test_toml_syntax_error_names_file_and_line(tmp_path):
    p = write(tmp_path, PAIR + "[operating]\nrpm = = 3\n")
    with pytest.raises(ConfigError) as ei:
        load_config(p)
    msg = str(ei.value)
    assert str(p) in msg and "line 14" in msg and "TOML syntax error" in msg


def test_missing_required_key_refused(tmp_path):
    p = write(tmp_path, PAIR.replace("z2 = 47\n", ""))
    with pytest.raises(ConfigError, match=r"\[gear_pair\] missing key\(s\) z2"):
        load_config(p)


def test_both_nondimensional_and_dimensional_refused(tmp_path):
    p = write(tmp_path, PAIR + '\n[mesh]\nkappa = [0.2]\nk = ["400 N/um"]\n')
    with pytest.raises(ModelError, match=r"kappa/k: give the harmonics either"):
        load_config(p)


# ---------------------------------------------------------------------------- the geometry command
runner = CliRunner()


def test_cli_geometry_json_keys():
    r = runner.invoke(app, ["geometry", "--json"])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    for k in ("delta1_deg", "delta2_deg", "R1_m", "R2_m", "m_e_kg", "F_p_N", "omega_n_rad_s", "assumed"):
        assert k in s
    assert s["m_e_kg"] == pytest.approx(38.4636, rel=1e-5)
    assert s["omega_n_rad_s"] == pytest.approx(7210.91, rel=1e-6)
    assert "k0" in s["assumed"]


def test_cli_geometry_table_and_error(tmp_path):
    r = runner.invoke(app, ["geometry"])
    assert r.exit_code == 0 and "directional radius R1" in r.stdout and "assumed" in r.stdout
    bad = write(tmp_path, PAIR + "bogus = 1\n")
    r = runner.invoke(app, ["geometry", "--config", str(bad)])
    assert r.exit_code == 2
    assert "bogus" in r.output and "error:" in r.output


# ---------------------------------------------------------------- ISO 10300-1 keys, k0 methods, κ from geometry
def _geometry_json(*args):
    r = runner.invoke(app, ["geometry", *args, "--json"])
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


def _digits(value, printed, units=0.5):
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    assert abs(value - float(printed)) <= units * 10.0**-decimals + 1e-12, (value, printed)


def test_cli_geometry_iso_sample1_matches_printed_values():
    s = _geometry_json("--config", str(EXAMPLES / "iso10300_sample1.toml"))
    _digits(s["contact_ratio_alpha"], "1.165")
    _digits(s["contact_ratio_beta"], "1.227")
    _digits(s["contact_ratio_total"], "2.392")
    _digits(s["b_v_eff_mm"], "21.590")
    _digits(s["c_gamma_N_per_mm_um"], "20.0")
    _digits(s["K_v"], "1.020")
    assert s["resonance_ratio"] == pytest.approx(1200 / s["resonance_speed_rpm"], rel=1e-12)
    assert isinstance(s["kappa_from_geometry"], list) and len(s["kappa_from_geometry"]) == 3
    # the ISO inputs make k0 = c_gamma b_v,eff the default
    assert s["k0_method"] == "iso"
    assert s["k0_N_per_m"] == pytest.approx(20e9 * 21.59e-3, rel=1e-12) == s["k0_iso_N_per_m"]
    names = {a["name"] for a in s["assumptions"]}
    assert {"k0", "offset", "zeta_mp", "I1", "I2", "j_n"} <= names
    assert all(a["source"] for a in s["assumptions"])


def test_cli_geometry_iso_hypoid_sample2_matches_printed_values():
    s = _geometry_json("--config", str(EXAMPLES / "iso10300_sample2_hypoid.toml"))
    _digits(s["contact_ratio_alpha"], "1.010")
    _digits(s["contact_ratio_beta"], "2.096", units=1.0)  # m_mn printed rounded (see test_iso10300)
    _digits(s["contact_ratio_total"], "3.106")
    _digits(s["b_v_eff_mm"], "24.880")
    _digits(s["K_v"], "1.016")
    assert s["k0_method"] == "iso" and s["r2_m"] == pytest.approx(141.877e-3 / 2)
    assert any("hypoid" in n for n in s["notes"])


def test_paper_pair_keeps_its_k0_and_reports_iso_next_to_it():
    s = _geometry_json()
    assert s["k0_method"] == "face_width" and s["k0_N_per_m"] == pytest.approx(2e9, rel=1e-12)
    # ISO: b_v,eff = 0.85 x 100 mm, c_gamma = 20 N/(mm um) at the line load of T1 = 1932 N m (C_F = 1)
    assert s["k0_iso_N_per_m"] == pytest.approx(1.7e9, rel=1e-12)
    assert 1.2 < s["contact_ratio_alpha"] < 1.4 and 2.0 < s["contact_ratio_beta"] < 2.3
    assert s["kappa_from_geometry"][0] < 0.05
    assert any("κ1 = 0.2 is" in n for n in s["notes"])
    r = runner.invoke(app, ["geometry"])
    text = " ".join(r.stdout.split())
    assert "ε_vα" in text and "κ1 from" in text and "the model uses k0 = 2000 N/µm (face_width)" in text
    assert "c_γ b_v,eff = 20 N/(mm·µm) × 85 mm = 1700 N/µm" in text


def test_k0_method_options(tmp_path):
    iso = (EXAMPLES / "iso10300_sample1.toml").read_text(encoding="utf-8")
    p = write(tmp_path, iso.replace('face_width = "25.4 mm"', 'face_width = "25.4 mm"\nk0_method = "face_width"'))
    cfg = load_config(p)
    assert cfg.k0_method == "face_width" and cfg.pair.k0_mean == pytest.approx(20e9 * 25.4e-3)
    p = write(tmp_path, PAIR + 'k0_method = "iso"\n', "iso.toml")
    cfg = load_config(p)
    assert cfg.k0_method == "iso" and cfg.pair.k0_mean == pytest.approx(20e9 * 85e-3)
    assert any(a.name == "k0" and "ISO 10300-1" in a.source for a in cfg.assumptions)
    p = write(tmp_path, PAIR + 'k0 = "2000 N/um"\nk0_method = "iso"\n', "both.toml")
    with pytest.raises(ModelError, match=r"line 14: \[gear_pair\] k0_method: give k0 or k0_method"):
        load_config(p)
    # a configuration without ISO inputs keeps c_gamma x face width
    assert load_config(write(tmp_path, PAIR, "plain.toml")).pair.k0_mean == pytest.approx(2e9)
    assert load_config(EXAMPLES / "automotive_hypoid_like.toml").k0_method == "face_width"


def test_kappa_from_geometry(tmp_path):
    p = write(tmp_path, PAIR + '[mesh]\nkappa = "geometry"\neps = [0.5]\n')
    cfg = load_config(p)
    s = cfg.geometry_summary()
    assert list(cfg.model.kappa) == pytest.approx(s["kappa_from_geometry"])
    assert [math.degrees(x) for x in cfg.model.phi_k] == pytest.approx(s["phi_k_from_geometry_deg"])
    assert any('kappa = "geometry"' in n for n in cfg.notes)
    with pytest.raises(ConfigError, match=r"\[mesh\] phi_k: not with kappa"):
        load_config(write(tmp_path, PAIR + '[mesh]\nkappa = "geometry"\nphi_k = [0.1]\n', "b.toml"))
    with pytest.raises(ConfigError, match=r"\[mesh\] kappa: expected numbers or the word"):
        load_config(write(tmp_path, PAIR + '[mesh]\nkappa = "geometric"\n', "c.toml"))


def test_geometry_footer_follows_the_given_torque_and_speed():
    r = runner.invoke(app, ["geometry", "--rpm", "2400", "--torque", "1500"])
    assert r.exit_code == 0
    assert "1932" not in r.stdout and "follows from f_p" not in r.stdout
    assert "T1 = 1500 N·m given for this run" in r.stdout
    assert "3000" not in r.stdout.split("assumed")[-1] or "rpm = 3000" not in r.stdout


# ---------------------------------------------------------------- non-dimensional configurations
NONDIM = """\
title = "non-dimensional study"
[mesh]
xi0 = 0.08
xi = [0.05]
kappa = [0.2, 0.05]
phi_k = [0, 0.3]
eps = [0.5]
fp = 0.2
[operating]
omega = 0.9
"""


def test_nondimensional_config_runs_every_command(tmp_path):
    p = write(tmp_path, NONDIM)
    cfg = load_config(p)
    assert cfg.pair is None
    m = cfg.model
    assert (m.omega, m.xi0, m.xi, m.kappa, m.phi_k, m.eps, m.fp) == (
        0.9,
        0.08,
        (0.05,),
        (0.2, 0.05),
        (0.0, 0.3),
        (0.5,),
        0.2,
    )
    for args in (
        ["simulate", "--periods", "8", "--transient", "20"],
        ["orbit", "--period", "1"],
        ["lyapunov", "--periods", "20", "--transient", "20"],
        [
            "bifurcation",
            "--param",
            "omega",
            "--start",
            "0.8",
            "--stop",
            "1.0",
            "--num",
            "3",
            "--transient",
            "20",
            "--periods",
            "4",
            "--settle",
            "0",
        ],
        ["response", "--omega-start", "0.8", "--omega-stop", "1.0", "--num", "3", "--transient", "20", "--settle", "0"],
    ):
        r = runner.invoke(app, [*args, "--config", str(p), "--json"])
        assert r.exit_code == 0, (args, r.output)
        out = json.loads(r.stdout)
        # no gear pair: no speed, torque, force or length to report (geardyn.analysis.physical)
        assert "physical" in out and out["physical"] is None, args
    r = runner.invoke(app, ["simulate", "--config", str(p), "--rpm", "3000"])
    assert r.exit_code == 2 and "no [gear_pair]" in r.output
    r = runner.invoke(app, ["geometry", "--config", str(p)])
    assert r.exit_code == 2 and "no [gear_pair]" in r.output


def test_nondimensional_config_refuses_physical_keys_and_unknown_sections(tmp_path):
    with pytest.raises(ConfigError, match=r"line 4: \[operating\] rpm: needs a gear pair"):
        load_config(write(tmp_path, '[mesh]\nxi0 = 0.1\n[operating]\nrpm = "3000 rpm"\n'))
    with pytest.raises(ConfigError, match=r"\[mesh\] e: needs a gear pair"):
        load_config(write(tmp_path, '[mesh]\ne = ["1 um"]\n', "e.toml"))
    p = write(tmp_path, NONDIM + "[solver]\nsteps = 3\n", "u.toml")
    with pytest.raises(ConfigError, match=r"u.toml: line 11: unknown section or key 'solver' \(a section \[solver\]\)"):
        load_config(p)
    r = runner.invoke(app, ["simulate", "--config", str(p)])
    assert r.exit_code == 2 and "[solver]" in r.output and len(r.output.strip().splitlines()) == 1


def test_packaged_quantities_hold_pint_values_and_cover_the_packaged_file():
    """The packaged pair is read without pint; each value it uses instead is pint's, bit for bit."""
    import subprocess
    import sys

    from geardyn import _config_values as cv
    from geardyn._packaged_quantities import PACKAGED_QUANTITIES

    kinds = {k.label: k for k in vars(cv).values() if isinstance(k, cv._Kind)}
    for (label, text), value in PACKAGED_QUANTITIES.items():
        assert value.hex() == float(cv._ureg().Quantity(text).to(kinds[label].unit).magnitude).hex(), text
    code = (
        "import sys; from geardyn.config import load_config; c = load_config(None); "
        "print('pint' in sys.modules, c.pair is not None)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "True"]
