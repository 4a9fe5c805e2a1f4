"""Measured transmission error: recovery of known orders from a synthetic record, refusal of malformed files."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.cli import app
from geardyn.config import load_config
from geardyn.errors import ConfigError
from geardyn.te import analyse_te, mesh_section, read_te

runner = CliRunner()
Z1, Z2 = 14, 39
MESH = [(1.0, 0.4), (0.25, -1.0)]  # (amplitude um, phase rad) of mesh harmonics 1, 2
SIDE = [(Z1 + 1.0, 0.08, 0.2), (Z1 - Z1 / Z2, 0.05, 1.1), (1.0, 0.1, -0.7)]  # (pinion order, amp, phase)
NOISE = 0.02  # um, standard deviation


def _synthetic(path: Path, *, time_unit: str | None = None, rpm: float = 600.0, n: int = 30000) -> Path:
    phi = np.linspace(0.0, 2 * math.pi * 1.5 * Z2 / Z1, n, endpoint=False)
    rng = np.random.default_rng(7)
    te = 0.3 + NOISE * rng.standard_normal(n)
    for l, (a, p) in enumerate(MESH, start=1):
        te += a * np.cos(l * Z1 * phi + p)
    for o, a, p in SIDE:
        te += a * np.cos(o * phi + p)
    if time_unit is None:
        x, head = np.degrees(phi), "angle [deg], TE [um]"
    else:
        x, head = phi / (rpm * math.pi / 30.0) * 1e3, "time (ms); TE (µm)"
    sep = "," if time_unit is None else ";"
    path.write_text(head + "\n" + "\n".join(f"{a:.9f}{sep}{b:.9f}" for a, b in zip(x, te)) + "\n", encoding="utf-8")
    return path


def _check(res):
    tol = 1e-3 * MESH[0][0]  # 1e-3 of the (largest) mesh amplitude
    for row, (a, p) in zip(res.mesh, MESH):
        assert abs(row["amplitude_um"] - a) < tol
        assert abs(math.remainder(row["phase_rad"] - p, 2 * math.pi)) * a < tol
    assert res.mesh[2]["amplitude_um"] < tol
    by_order = {round(r["order"], 9): r for r in res.sidebands}
    for o, a, p in SIDE:
        r = by_order[round(o, 9)]
        assert abs(r["amplitude_um"] - a) < tol and abs(math.remainder(r["phase_rad"] - p, 2 * math.pi)) * a < tol
    others = [r["amplitude_um"] for r in res.sidebands if all(abs(r["order"] - o) > 1e-9 for o, _, _ in SIDE)]
    assert max(others) < tol
    assert res.mean_um == pytest.approx(0.3, abs=tol)


def test_synthetic_record_recovered(tmp_path):
    res = analyse_te(read_te(_synthetic(tmp_path / "te.csv")), Z1, Z2)
    _check(res)
    assert res.hunting_mesh_cycles == math.lcm(Z1, Z2) == 546
    assert not res.periodic_over_mesh_cycle and res.sideband_share > 0.05
    assert res.residual_share == pytest.approx(
        NOISE / np.sqrt(0.5 * (1 + 0.25**2 + sum(a * a for _, a, _ in SIDE)) + NOISE**2), rel=0.05
    )


def test_time_record_with_speed(tmp_path):
    p = _synthetic(tmp_path / "te_t.txt", time_unit="ms", rpm=600.0)
    res = analyse_te(read_te(p, rpm=600.0), Z1, Z2)
    _check(res)
    with pytest.raises(ConfigError, match=r"te_t.txt: line 1: a time record needs the pinion speed"):
        read_te(p)


def test_mesh_section_is_accepted_by_a_config(tmp_path):
    res = analyse_te(read_te(_synthetic(tmp_path / "te.csv")), Z1, Z2)
    section = mesh_section(res)
    assert "sideband" in section and "546 mesh cycles" in section
    pair = (Path(__file__).resolve().parents[1] / "examples" / "iso10300_sample1.toml").read_text(encoding="utf-8")
    pair = pair.split("\n[mesh]")[0]  # the sample's own mesh section is replaced by the measured one
    cfg_path = tmp_path / "cfg.toml"
    cfg_path.write_text(pair + "\n" + section, encoding="utf-8")
    cfg = load_config(cfg_path)
    b_c = cfg.b_c
    assert [e * b_c * 1e6 for e in cfg.model.eps][:2] == pytest.approx([1.0, 0.25], abs=1e-3)
    assert cfg.model.phi_e[:2] == pytest.approx([0.4, -1.0], abs=2e-3)
    assert "e" in cfg.assumed


def test_cli_te_json_and_out(tmp_path):
    p = _synthetic(tmp_path / "te.csv")
    out = tmp_path / "mesh.toml"
    r = runner.invoke(app, ["te", str(p), "--teeth", "14,39", "--json", "--out", str(out)])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    assert s["hunting_period_mesh_cycles"] == 546 and s["periodic_over_mesh_cycle"] is False
    assert s["mesh_harmonics"][0]["amplitude_um"] == pytest.approx(1.0, abs=1e-3)
    assert out.read_text(encoding="utf-8") == s["mesh_section"] and s["files"] == [str(out)]
    r = runner.invoke(app, ["te", str(p), "--teeth", "14"])
    assert r.exit_code == 2 and "teeth" in r.output


BAD = {
    "words.csv": ("angle [deg], TE [um]\nabc, def\n", r"line 2: expected two numbers"),
    "empty.csv": ("angle [deg], TE [um]\n# nothing measured\n", r"line 2: no numeric rows"),
    "one.csv": ("angle [deg], TE [um]\n" + "".join(f"{i}\n" for i in range(20)), r"line 2: expected two columns"),
    "commas.csv": (
        "angle [rad], TE [um]\n,\n" + "".join(f"{i},0.1\n" for i in range(20)),
        r"line 2: expected two columns \(angle or time, TE\), got 0",
    ),
    "nan.csv": (
        "angle [deg], TE [um]\n" + "".join(f"{i},{'nan' if i == 5 else 0.1}\n" for i in range(20)),
        r"line 7: not a finite number",
    ),
    "back.csv": (
        "angle [deg], TE [um]\n" + "".join(f"{i if i != 9 else 3},0.1\n" for i in range(20)),
        r"line 11: the angle must increase strictly: 3 follows 8 \(line 10\)",
    ),
    "force.csv": (
        "angle [deg], TE [N]\n" + "".join(f"{i},0.1\n" for i in range(20)),
        r"line 1: TE unit 'n' is not a length",
    ),
    "mass.csv": (
        "x [kg], TE [um]\n" + "".join(f"{i},0.1\n" for i in range(20)),
        r"line 1: first-column unit 'kg' is neither an angle",
    ),
    "nounit.csv": ("angle, TE\n" + "".join(f"{i},0.1\n" for i in range(20)), r"line 1: units not stated"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_malformed_files_refused_with_file_and_line(tmp_path, name):
    text, msg = BAD[name]
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError, match=rf"{name}: {msg}"):
        read_te(p)
    r = runner.invoke(app, ["te", str(p), "--teeth", "14,39"])
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and "line " in lines[0]


def test_units_from_options_and_headerless_file(tmp_path):
    p = tmp_path / "plain.txt"
    phi = np.linspace(0, 4 * math.pi, 4000, endpoint=False)
    p.write_text("\n".join(f"{a} {0.001 * math.cos(Z1 * a)}" for a in phi), encoding="utf-8")
    with pytest.raises(ConfigError, match="units not stated"):
        read_te(p)
    sig = read_te(p, x_unit="rad", te_unit="mm")
    res = analyse_te(sig, Z1, Z1)
    assert res.mesh[0]["amplitude_um"] == pytest.approx(1.0, abs=1e-9)
    with pytest.raises(ConfigError, match="gives the TE column in 'um', the option 'mm'"):
        read_te(_synthetic(tmp_path / "te.csv"), te_unit="mm")
