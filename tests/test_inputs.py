"""A run's files are read once, and a tooth-pair excitation file is its own pair (``geardyn.inputs``).

* Each configuration, system or tooth-pair file is parsed once per command, however often the command asks for
  its model and scales (every TOML file goes through one parser: ``tomllib.loads`` is counted).
* ``--excitation TOOTH.toml`` with a speed or torque takes z1, the mean mesh stiffness and the torque of that
  file: its scales are checked against the closed forms of the pair's blanks (``docs/excitation.md``), and a
  configuration of another pair is refused in one line.
* The Lyapunov precision limit is the library's: a Python caller gets it.
"""

from __future__ import annotations

import json
import math
import tomllib
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from cli_run import run_cli

from geardyn import GearModel, IntegrationOptions, lyapunov_spectrum
from geardyn.errors import ModelError

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
SPUR = EX / "tooth_healthy_spur.toml"
FAST = ["--transient", "10", "--periods", "4"]


@pytest.fixture
def parsed(monkeypatch):
    """Count the TOML texts parsed (by their first line) while a command runs."""
    seen: Counter = Counter()
    loads = tomllib.loads

    def counting(text, *a, **kw):
        seen[text.lstrip("\ufeff").splitlines()[0] if text.strip() else ""] += 1
        return loads(text, *a, **kw)

    monkeypatch.setattr(tomllib, "loads", counting)
    return seen


def _first_line(path: Path) -> str:
    return path.read_text(encoding="utf-8").splitlines()[0]


@pytest.mark.parametrize(
    "args, files",
    [
        (["simulate", "--config", EX / "paper_table1.toml", "--rpm", "2000", "--torque", "1000", *FAST], 1),
        (
            ["lyapunov", "--config", EX / "paper_table1.toml", "--rpm", "2000", "--transient", "10", "--periods", "40"],
            1,
        ),
        (
            ["bifurcation", "--config", EX / "paper_table1.toml", "--rpm-start", "2000", "--rpm-stop", "3000"]
            + ["--num", "2", *FAST],
            1,
        ),
        (["simulate", "--system", EX / "systems" / "paper_torsional.toml", "--rpm", "2000", *FAST], 1),
        (["orbit", "--system", EX / "systems" / "paper_torsional.toml", "--omega", "0.8", "--transient", "10"], 1),
        (["response", "--excitation", SPUR, "--rpm-start", "1000", "--rpm-stop", "2000", "--num", "2", *FAST], 1),
    ],
    ids=["simulate-config", "lyapunov-config", "bifurcation-config", "simulate-system", "orbit-system", "tooth"],
)
def test_each_file_is_read_once_per_command(parsed, args, files):
    code, out, err = run_cli([*args, "--json"])
    assert code == 0, err
    given = [Path(a) for a in args if isinstance(a, Path)]
    assert len(given) == files
    for path in given:
        assert parsed[_first_line(path)] == 1, (path, dict(parsed))
    assert sum(parsed.values()) == files, dict(parsed)  # nothing else (no packaged pair read beside it)


def _blank_scales(z1=20, z2=40, m=3e-3, b=20e-3, alpha=math.radians(20.0), rho=7850.0):
    """m_e and the base radii of two solid steel blanks at their reference radii (spur, no profile shift)."""
    r1, r2 = m * z1 / 2, m * z2 / 2
    I1, I2 = (0.5 * rho * math.pi * b * r**4 for r in (r1, r2))
    rb1, rb2 = r1 * math.cos(alpha), r2 * math.cos(alpha)
    return I1 * I2 / (I1 * rb2**2 + I2 * rb1**2), rb1, rb2


def test_a_tooth_pair_file_drives_the_scales_of_a_response_in_rpm():
    from geardyn.tooth.geometry import pair_geometry
    from geardyn.tooth.mesh import mesh_stiffness

    code, out, err = run_cli(
        ["response", "--excitation", SPUR, "--rpm-start", "1000", "--rpm-stop", "6000", "--num", "3", *FAST, "--json"]
    )
    assert code == 0, err
    s = json.loads(out)
    pair = s["tooth_pair"]
    assert (pair["z1"], pair["z2"], pair["mesh_torque_N_m"]) == (20, 40, 100.0)  # the file's [tooth_pair]
    # k0: the mean of the pair's mesh stiffness, computed here from the geometry alone (the file's modifications
    # change the table, so the reference is that table's mean, not a handbook value)
    from geardyn.tooth.config import load_case

    case = load_case(SPUR)
    geo = pair_geometry(20, 40, 3e-3, alpha_n=math.radians(20), beta=0.0, face_width=20e-3)
    ms = mesh_stiffness(geo, 100.0, modifications=case.modifications, points=64)
    k0 = float(np.mean(ms.stiffness))
    assert pair["k0_N_per_um"] == pytest.approx(k0 * 1e-6, rel=1e-12)
    sc = s["physical"]["scales"]
    assert sc["z1"] == 20 and sc["k0_N_per_m"] == pytest.approx(k0, rel=1e-12)
    m_e, rb1, _ = _blank_scales()
    assert sc["m_e_kg"] == pytest.approx(m_e, rel=1e-12) and sc["R1_m"] == pytest.approx(rb1, rel=1e-12)
    # the speed range: ω = 2π z1 n / 60 / √(k0/m_e) at both ends
    wn = math.sqrt(k0 / m_e)
    omegas = [2 * math.pi * 20 * n / 60 / wn for n in (1000.0, 6000.0)]
    assert s["omega"][0] == pytest.approx(omegas[0], rel=1e-12) and s["omega"][-1] == pytest.approx(
        omegas[1], rel=1e-12
    )
    # the load: the file's torque, balanced, f_p = T1/(r_b1 k0 b_c) with the default b_c = 10 µm
    assert s["physical"]["fp"] == pytest.approx(100.0 / (rb1 * k0 * 10e-6), rel=1e-12)
    assert s["physical"]["scales"]["source"].endswith("tooth_healthy_spur.toml")


def test_simulate_with_a_tooth_pair_takes_its_speed_and_torque_through_that_pair():
    code, out, err = run_cli(["simulate", "--excitation", SPUR, "--rpm", "3000", "--torque", "150", *FAST, "--json"])
    assert code == 0, err
    s = json.loads(out)
    m_e, rb1, _ = _blank_scales()
    k0 = s["tooth_pair"]["k0_N_per_um"] * 1e6
    assert s["omega"] == pytest.approx(2 * math.pi * 20 * 3000 / 60 / math.sqrt(k0 / m_e), rel=1e-12)
    assert s["fp"] == pytest.approx(150.0 / (rb1 * k0 * 10e-6), rel=1e-12)


def test_a_configuration_of_another_pair_beside_a_tooth_file_is_refused_in_one_line():
    code, out, err = run_cli(["simulate", "--config", EX / "paper_table1.toml", "--excitation", SPUR, "--rpm", "3000"])
    assert code == 2
    line = err.strip()
    assert "\n" not in line and "z1 = 20" in line and "z1 = 23" in line, err


def test_the_lyapunov_precision_limit_holds_for_a_python_caller():
    from geardyn import bifurcation

    # e^(-2 ξ0 2π/ω) below e^-700: ω < 4π ξ0 / 700 = 0.0017952 for ξ0 = 0.1
    with pytest.raises(ModelError, match=r"^omega: Lyapunov exponents need ω >= 0\.001795"):
        lyapunov_spectrum(GearModel(omega=1e-3), IntegrationOptions(transient=1, periods=2))
    with pytest.raises(ModelError, match=r"^omega: Lyapunov exponents need ω >= 0\.001795"):
        bifurcation(
            GearModel(), "omega", [1e-3, 0.5], lyapunov=True, options=IntegrationOptions(transient=1, periods=2)
        )
    lyapunov_spectrum(GearModel(omega=0.0018), IntegrationOptions(transient=1, periods=2))  # just above: computed


def test_continuation_draws_the_librarys_context_sweep(tmp_path):
    """The brute-force sweep under a continuation is :func:`geardyn.analysis.context.continuation_context`: a
    Python caller gets the same Dataset, bit for bit."""
    from geardyn import read_netcdf
    from geardyn.analysis.context import continuation_context

    args = ["continuation", "--param", "omega", "--start", "0.6", "--stop", "0.62", "--transient", "10"]
    code, out, err = run_cli([*args, "--sweep-num", "3", "--out", tmp_path, "--json"])
    assert code == 0, err
    drawn = read_netcdf(tmp_path / "continuation_sweep.nc")
    ds = continuation_context(GearModel(), "omega", 0.6, 0.62, num=3, transient=10)
    assert drawn["omega"].values.tolist() == ds["omega"].values.tolist()
    np.testing.assert_array_equal(drawn["poincare_u"].values, ds["poincare_u"].values)
    np.testing.assert_array_equal(drawn["period"].values, ds["period"].values)
