"""A system's tables in the units of the pair's, with each mesh's static load and dynamic factor (issue 23 item 6):
the static mesh force comes from the system's loads, the dynamic factor is max mesh force / static mesh force, and a
mesh that carries no static load says so instead of a dash or "n/a"."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from cli_run import run_cli

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"


def run(*args: str) -> str:
    """``geardyn ARGS`` in this process; its stdout with runs of white space made one space (rich wraps tables)."""
    code, out, err = run_cli(args)
    assert not code, err
    return " ".join(out.split())


def _value(text: str, row: str) -> float:
    m = re.search(re.escape(row) + r" │ ([-+0-9.e]+) │", text)
    assert m, f"no row {row!r} in {text}"
    return float(m.group(1))


def test_a_loaded_system_prints_its_static_mesh_force_and_dynamic_factor():
    """paper_torsional.toml loads its mesh with f_p = 0.2 as balanced torques: the static mesh force is f_p k b_c =
    0.2 × 2000 N/µm × 50 µm = 20 000 N (the file's stiffness and half backlash 0.1 mm / 2), and the dynamic factor
    printed is the printed max mesh force over it."""
    out = run(
        "simulate",
        "--system",
        str(EX / "paper_torsional.toml"),
        "--omega",
        "0.8",
        "--transient",
        "30",
        "--periods",
        "8",
    )
    assert _value(out, "half backlash D (µm)") == pytest.approx(50.0)
    assert _value(out, "static force (N)") == pytest.approx(20000.0, rel=1e-6)
    assert _value(out, "static mesh force F_p (N)") == pytest.approx(20000.0, rel=1e-6)
    fmax = _value(out, "max dynamic mesh force, elastic + viscous (N)")
    kv = _value(out, "dynamic factor (max force / F_p)")
    assert kv == pytest.approx(fmax / 20000.0, rel=1e-5) and kv > 1.0
    assert _value(out, "dynamic factor") == pytest.approx(kv, rel=1e-5)  # the mesh table's row
    assert "n/a" not in out and "—" not in out
    assert "pinion speed (rpm)" in out and "DTE min (µm)" in out


def test_a_system_without_load_says_no_static_load(tmp_path):
    """The torsional example without its [[load]]: its mesh carries no static load (the eccentricity still drives
    it), and the mesh table and the summary say so."""
    text = (EX / "paper_torsional.toml").read_text()
    start = text.index("[[load]]")
    unloaded = tmp_path / "unloaded.toml"
    unloaded.write_text(text[:start] + "\n".join(text[start:].splitlines()[3:]))
    out = run("simulate", "--system", str(unloaded), "--omega", "0.8", "--transient", "30", "--periods", "8")
    assert _value(out, "static force (N)") == 0.0
    assert _value(out, "max dynamic mesh force, elastic + viscous (N)") > 0.0
    assert "dynamic factor │ no static load │" in out
    assert "dynamic factor (max force / F_p) │ no static load │" in out


def test_the_mesh_table_says_no_static_load_for_each_mesh_without_one(capsys):
    from geardyn.cli import render

    meshes = [
        {"name": f"m{i}", "backlash_um": 0.0, "mesh_force_max_N": 0.0, "static_force_N": 0.0, "dynamic_factor": None}
        for i in range(2)
    ]
    meshes.append(
        {
            "name": "loaded",
            "backlash_um": 10.0,
            "mesh_force_max_N": 300.0,
            "static_force_N": 200.0,
            "dynamic_factor": 1.5,
        }
    )
    render.meshes({"meshes": meshes})
    rows = [r for r in capsys.readouterr().out.splitlines() if "dynamic" in r]
    assert rows and rows[0].count("no static load") == 2 and "1.5" in rows[0]


def test_the_pair_without_load_says_no_static_load():
    out = run("simulate", "--omega", "0.8", "--fp", "0", "--transient", "5", "--periods", "4")
    assert "static mesh force F_p (N) │ 0 │" in out
    assert "dynamic factor (max force / F_p) │ no static load │" in out
