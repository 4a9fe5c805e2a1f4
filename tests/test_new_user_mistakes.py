"""A first gearbox file written from docs/gearbox.md, and the mistakes a new user makes in it.

Each mistake must be refused in one line naming the key and its bound (exit code 2), never turned into a
plausible result.  The gearbox is a two-stage reducer (21/55 spur teeth, then 17/61 helical teeth) on three
shafts of Timoshenko elements; each case edits one line of it.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_run import run_cli

#: The reducer: five linear bearings, a torque on the input pinion and the balancing torque on the output wheel.
GEARBOX = """
title = "two-stage reducer 21/55 then 17/61"

[operating]
rpm = "3000 rpm"

[[shaft]]
name = "input"
segments = [{ length = "30 mm", outer = "30 mm" }, { length = "100 mm", outer = "35 mm" },
            { length = "30 mm", outer = "30 mm" }]
elements_per_segment = 1

[[shaft]]
name = "inter"
segments = [{ length = "25 mm", outer = "40 mm" }, { length = "160 mm", outer = "48 mm" },
            { length = "25 mm", outer = "40 mm" }]
elements_per_segment = 1

[[shaft]]
name = "output"
segments = [{ length = "30 mm", outer = "50 mm" }, { length = "140 mm", outer = "60 mm" },
            { length = "30 mm", outer = "50 mm" }]
elements_per_segment = 1

[[gear]]
name = "p1"
shaft = "input"
position = "80 mm"
teeth = 21
module = "2.5 mm"
face_width = "25 mm"

[[gear]]
name = "w1"
shaft = "inter"
position = "60 mm"
teeth = 55
module = "2.5 mm"
face_width = "25 mm"

[[gear]]
name = "p2"
shaft = "inter"
position = "150 mm"
teeth = 17
module = "3.5 mm"
helix_angle = "12 deg"
hand = "right"
face_width = "35 mm"

[[gear]]
name = "w2"
shaft = "output"
position = "120 mm"
teeth = 61
module = "3.5 mm"
helix_angle = "12 deg"
hand = "left"
face_width = "35 mm"

[[mesh]]
name = "s1"
pinion = "p1"
gear = "w1"
backlash = "0.08 mm"
xi0 = 0.05

[[mesh]]
name = "s2"
pinion = "p2"
gear = "w2"
center_angle = "90 deg"
backlash = "0.1 mm"
xi0 = 0.05

[[bearing]]
name = "in_A"
shaft = "input"
position = "15 mm"
kx = "3e8 N/m"
ky = "3e8 N/m"
kz = "1e8 N/m"

[[bearing]]
name = "in_B"
shaft = "input"
position = "145 mm"
kx = "3e8 N/m"
ky = "3e8 N/m"

[[bearing]]
name = "mid_A"
shaft = "inter"
position = "12 mm"
kx = "4e8 N/m"
ky = "4e8 N/m"
kz = "1e8 N/m"

[[bearing]]
name = "mid_B"
shaft = "inter"
position = "198 mm"
kx = "4e8 N/m"
ky = "4e8 N/m"

[[bearing]]
name = "out_A"
shaft = "output"
position = "15 mm"
kx = "5e8 N/m"
ky = "5e8 N/m"
kz = "1e8 N/m"

[[bearing]]
name = "out_B"
shaft = "output"
position = "185 mm"
kx = "5e8 N/m"
ky = "5e8 N/m"

[[load]]
gear = "p1"
torque = "80 N*m"

[[load]]
gear = "w2"
torque = "balance"
"""


def _file(tmp_path: Path, old: str = "", new: str = "") -> Path:
    text = GEARBOX
    if old:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    f = tmp_path / "gb.toml"
    f.write_text(text, encoding="utf-8")
    return f


def _refused(argv: list[str]) -> str:
    code, _, err = run_cli(argv)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, err
    assert len(lines) == 1, err
    return lines[0]


def test_the_reducer_as_written_is_read(tmp_path):
    code, out, err = run_cli(["modes", "--system", _file(tmp_path), "--json"])
    assert code == 0, err
    assert '"forcing_period_mesh_cycles": 55' in out  # 21/55 then 17/61: stage 2 at 17/55 of stage 1


# Each case: (the line changed, its replacement, words the one-line message must hold).
MISTAKES = {
    "a torque on a gear written as body (no mesh stiffness)": (
        'gear = "p1"\ntorque = "80 N*m"',
        'body = "p1"\ntorque = "80 N*m"',
        ["body", "is a gear", "gear = 'p1'"],
    ),
    "a torque on a gear written as body (mesh stiffness given)": (
        'gear = "p1"\ntorque = "80 N*m"',
        'body = "p1"\ntorque = "80 N*m"',
        ["body", "is a gear"],
    ),
    "gears of different modules": (
        'teeth = 55\nmodule = "2.5 mm"',
        'teeth = 55\nmodule = "3 mm"',
        ["'s1'", "module:", "2.5 mm", "3 mm"],
    ),
    "a negative damping ratio": ("xi0 = 0.05\n\n[[mesh]]", "xi0 = -0.05\n\n[[mesh]]", ["xi0", ">= 0", "-0.05"]),
    "a backlash in mm that should be µm": ('backlash = "0.08 mm"', 'backlash = "80 mm"', ["backlash", "80 mm"]),
    "a typo in the hand of a helix": ('hand = "right"', 'hand = "rigth"', ["[[gear]] 'p2' hand:", "'rigth'"]),
}


@pytest.mark.parametrize("case", MISTAKES)
def test_a_mistake_is_refused_in_one_line_naming_its_key(tmp_path, case):
    old, new, words = MISTAKES[case]
    if "mesh stiffness given" in case:  # both meshes get a stiffness: the tooth model does not need the torque
        f = _file(tmp_path, "xi0 = 0.05\n\n[[mesh]]", 'xi0 = 0.05\nstiffness = "400 N/um"\n\n[[mesh]]')
        text = f.read_text().replace("xi0 = 0.05\n\n[[bearing]]", 'xi0 = 0.05\nstiffness = "400 N/um"\n\n[[bearing]]')
        f.write_text(text.replace(old, new))
    else:
        f = _file(tmp_path, old, new)
    line = _refused(["modes", "--system", f, "--json"])
    for w in words:
        assert w in line, line
    assert "gear 'p2': gear 'p2'" not in line


def test_rpm_zero_on_a_system_names_rpm(tmp_path):
    line = _refused(["simulate", "--system", _file(tmp_path), "--rpm", "0", "--json"])
    assert line.startswith("error: rpm:") and "> 0" in line, line
    assert "np.float64" not in line


def test_plot_physical_refuses_a_system_result(tmp_path):
    """--physical draws with a gear pair's scales (the paper's by default): on a system result these are another
    pair's rpm, µm and N, so it is refused and nothing is drawn."""
    system = Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_torsional.toml"
    code, _, err = run_cli(
        ["simulate", "--system", system, "--omega", "0.8", "--transient", "5", "--periods", "4", "--out", tmp_path]
    )
    assert code == 0, err
    line = _refused(["plot", tmp_path / "simulate.nc", "--physical", "--out", tmp_path / "fig"])
    assert "--physical" in line and "system" in line, line
    assert not (tmp_path / "fig").exists()


def test_three_points_of_a_smooth_response_show_no_jump():
    """A sweep of three speeds over a smooth rise (the reducer's stage-1 DTE at 2000, 3000 and 4000 rpm: 2.90,
    3.30, 3.26 µm, the same up and down): its one neighbouring step is no measure of a typical step, so the rise
    is not a jump."""
    import numpy as np
    import xarray as xr

    from geardyn.analysis.response import detect_jumps

    a = np.array([0.07244, 0.08262, 0.08142])
    ds = xr.Dataset(
        {"amplitude": (("sweep", "omega"), np.stack([a, a]))},
        coords={"sweep": ["up", "down"], "omega": [0.0885, 0.1327, 0.1770]},
        attrs={"param": "omega"},
    )
    assert detect_jumps(ds) == []
