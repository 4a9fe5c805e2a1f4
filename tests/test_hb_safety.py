"""HB on models where it can say nothing or runs long: a model without damping is refused in one line, a system
with undamped elastic modes is named in a warning, the branch is bounded by a number of points with a message, the
continuation reports its progress, and a run with no branch exits 1 and writes no file."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_run import run_cli as _main

from geardyn.analysis.hb import hb_continuation
from geardyn.analysis.hb.damping import require_damping, undamped_modes
from geardyn.errors import ModelError
from geardyn.model import GearModel
from geardyn.systems import load_system
from geardyn.systems.assemble import assemble
from geardyn.systems.description import Body, Connection, Mesh, SystemDescription

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "systems"
PLANETARY = EXAMPLES / "planetary_lin_parker_1999.toml"


# ------------------------------------------------------------------------------ damping
def test_undamped_planetary_is_refused_in_one_line_and_writes_nothing(tmp_path):
    """The issue's command (undamped, unforced, backlash-free: every multiplier on the unit circle) ran over 15
    minutes printing nothing; it is refused at once."""
    out = tmp_path / "out"
    code, stdout, err = _main(
        ["hb", "--system", str(PLANETARY), "--param", "omega", "--start", "0.5", "--stop", "1.5", "--out", str(out)]
    )
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith("error: the system has no damping") and "Liouville" in lines[0]
    assert stdout == "" and not out.exists()
    code, _, err = _main(
        [
            "response",
            "--method",
            "hb",
            "--system",
            str(PLANETARY),
            "--omega-start",
            "0.5",
            "--omega-stop",
            "1.5",
            "--num",
            "5",
        ]
    )
    assert code == 2 and "no damping" in err and len(err.strip().splitlines()) == 1


def test_pair_without_damping_is_refused_unless_the_damping_is_continued_through_zero():
    undamped = GearModel(xi0=0.0, xi=())
    with pytest.raises(ModelError, match=r"^the model has no damping \(xi0 = 0\)"):
        hb_continuation(undamped, "omega", 0.5, 0.6)
    code, _, err = _main(["hb", "--param", "omega", "--start", "0.5", "--stop", "0.6", "--xi0", "0"])
    assert code == 2 and err.startswith("error: the model has no damping") and "--xi0 > 0" in err
    # xi1 alone averages to zero: the multipliers' product is still exp(0) = 1
    with pytest.raises(ModelError, match="no damping"):
        require_damping(GearModel(xi0=0.0, xi=(0.05,)))
    require_damping(undamped, "xi0", 0.0, 0.05)  # damped at one end: continued through zero, allowed
    require_damping(undamped, "xi0", -0.05, 0.05)
    with pytest.raises(ModelError):
        require_damping(GearModel(xi0=0.1), "xi0", 0.0, 0.0)


def _satellites(ks=2.0e3, Js=0.01, xi0=0.1):
    """A pinion–gear mesh (damped) and two equal satellites on the gear by undamped torsional springs: the mode with
    the satellites in opposition (gear and pinion still) has no damping, at exactly √(k_s/J_s)/2π."""
    bodies = (
        Body("p", ("theta",), inertia=0.02),
        Body("g", ("theta",), inertia=0.05),
        Body("s1", ("theta",), inertia=Js),
        Body("s2", ("theta",), inertia=Js),
    )
    mesh = Mesh("mesh", ((("p", "theta"), 0.05), (("g", "theta"), -0.1)), 2e8, backlash=1e-4, teeth=20, xi0=xi0)
    springs = tuple(Connection.along(f"spring{i}", {("g", "theta"): 1.0, (f"s{i}", "theta"): -1.0}, ks) for i in (1, 2))
    return assemble(SystemDescription(bodies=bodies, meshes=(mesh,), connections=springs))


def test_undamped_modes_are_found_exactly():
    ks, Js = 2.0e3, 0.01
    free = undamped_modes(_satellites(ks, Js))
    assert free == [pytest.approx(math.sqrt(ks / Js) / (2 * math.pi), rel=1e-9)]
    assert undamped_modes(load_system(EXAMPLES / "paper_bevel_8dof.toml")) == []  # bearings and mesh damped
    assert undamped_modes(GearModel()) == []
    # the planetary: every elastic mode undamped, at Lin & Parker's (1999) Table 2, N = 3 (Hz; the rotational
    # modes simple, the translational ones degenerate pairs; the rigid rotation left out)
    rotational = (1475.7, 1930.3, 2658.3, 7462.8, 11775.3)
    translational = (743.2, 1102.4, 1896.0, 2276.4, 6986.3, 9647.9)
    table2 = sorted(rotational + translational + translational)
    assert undamped_modes(load_system(PLANETARY)) == pytest.approx(table2, rel=1e-4)


def test_system_with_an_undamped_mode_is_warned_in_one_line(tmp_path):
    toml = tmp_path / "sat.toml"
    toml.write_text(_SAT_TOML)
    code, stdout, err = _main(
        [
            "hb",
            "--system",
            str(toml),
            "--param",
            "omega",
            "--start",
            "0.5",
            "--stop",
            "0.52",
            "--harmonics",
            "4",
            "--max-points",
            "3",
            "--json",
        ]
    )
    warn = [ln for ln in err.splitlines() if "no damping" in ln]
    assert code == 0, err
    assert len(warn) == 1 and warn[0].startswith("warning: 1 elastic mode(s) of the system have no damping")
    assert f"{math.sqrt(2.0e3 / 0.01) / (2 * math.pi):.6g} Hz" in warn[0]
    assert json.loads(stdout)["branch"]


_SAT_TOML = """
title = "pair with two undamped satellites"
[[body]]
name = "p"
dofs = ["theta"]
inertia = "0.02 kg*m^2"
[[body]]
name = "g"
dofs = ["theta"]
inertia = "0.05 kg*m^2"
[[body]]
name = "s1"
dofs = ["theta"]
inertia = "0.01 kg*m^2"
[[body]]
name = "s2"
dofs = ["theta"]
inertia = "0.01 kg*m^2"
[[connection]]
name = "spring1"
vector = { g = { theta = "1 m" }, s1 = { theta = "-1 m" } }
stiffness = "2e3 N/m"
[[connection]]
name = "spring2"
vector = { g = { theta = "1 m" }, s2 = { theta = "-1 m" } }
stiffness = "2e3 N/m"
[[mesh]]
name = "mesh"
vector = { p = { theta = "50 mm" }, g = { theta = "-100 mm" } }
stiffness = "2e8 N/m"
backlash = "0.1 mm"
xi0 = 0.1
[[load]]
mesh = "mesh"
fp = 0.2
"""


# ------------------------------------------------------------------------------ bounded steps, progress
def test_branch_stops_at_max_points_with_a_message():
    res = hb_continuation(GearModel(), "omega", 0.5, 0.65, harmonics=8, max_points=6)
    assert res.values.size == 6 and res.end.startswith("max points: stopped at 6 points before the end")
    code, stdout, err = _main(
        [
            "hb",
            "--param",
            "omega",
            "--start",
            "0.5",
            "--stop",
            "0.65",
            "--harmonics",
            "8",
            "--max-points",
            "6",
            "--json",
        ]
    )
    s = json.loads(stdout)
    assert code == 0 and len(s["branch"]) == 6 and s["end"] == res.end
    warn = [ln for ln in err.splitlines() if ln.startswith("warning:")]
    assert len(warn) == 1 and "--max-points" in warn[0] and "6 points" in warn[0]
    code, _, err = _main(["hb", "--param", "omega", "--start", "0.5", "--stop", "0.65", "--max-points", "1"])
    assert code == 2 and err.startswith("error: max-points")


def test_continuation_reports_the_parameter_span_covered():
    calls = []
    res = hb_continuation(GearModel(), "omega", 0.65, 0.5, harmonics=8, progress=lambda d, t: calls.append((d, t)))
    done = [d for d, _ in calls]
    assert calls[0] == (0.0, pytest.approx(0.15)) and calls[-1] == (pytest.approx(0.15),) * 2
    assert done == sorted(done) and len(calls) > 10 and all(t == calls[0][1] for _, t in calls)
    plain = hb_continuation(GearModel(), "omega", 0.65, 0.5, harmonics=8)
    np.testing.assert_array_equal(res.values, plain.values)  # the report changes no number
    np.testing.assert_array_equal(res.coefficients, plain.coefficients)


def test_hb_progress_on_stderr_unless_json(monkeypatch):
    import geardyn.sweep.progress as P

    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    argv = ["hb", "--param", "omega", "--start", "0.5", "--stop", "0.55", "--harmonics", "8"]
    code, _, err = _main(argv)
    assert code == 0 and "hb ω: 0.05/0.05 Δω traced (100%)" in err
    code, _, err = _main(argv + ["--json"])
    assert code == 0 and err == ""
    code, _, err = _main(["response", "--method", "hb", "--omega-start", "0.5", "--omega-stop", "0.55", "--num", "3"])
    assert code == 0 and "response ω (HB): 0.05/0.05 Δω traced (100%)" in err


# ------------------------------------------------------------------------------ no result
def test_failed_start_exits_1_and_writes_no_figure(tmp_path):
    """(It exited 0 and wrote an empty figure with an ω axis from −0.04 to 0.04.)"""
    out = tmp_path / "out"
    argv = ["hb", "--param", "omega", "--start", "1.2", "--stop", "1.3", "--harmonics", "2", "--period", "3"]
    code, stdout, err = _main(argv + ["--out", str(out)])
    lines = err.strip().splitlines()
    assert code == 1 and len(lines) == 1 and stdout == "", err
    assert lines[0].startswith("error: harmonic balance gave no branch: at omega = 1.2, start: not converged")
    assert not out.exists() or not any(out.iterdir())
    code, stdout, _ = _main(argv + ["--json"])
    assert code == 1 and stdout == ""


def test_hb_response_that_resolves_no_point_exits_1_and_writes_nothing(tmp_path, monkeypatch):
    import geardyn.analysis.hb as hb

    real = hb.hb_response

    def unresolved(*a, **k):  # the real response with every point made unresolved
        ds = real(*a, **k)
        for name in ds.data_vars:
            if ds[name].dtype.kind == "f":
                ds[name][...] = np.nan
        return ds

    monkeypatch.setattr(hb, "hb_response", unresolved)
    out = tmp_path / "r"
    code, stdout, err = _main(
        ["response", "--method", "hb", "--omega-start", "0.5", "--omega-stop", "0.6", "--num", "3", "--out", str(out)]
    )
    assert code == 1
    assert "resolved no point" in err and len(err.strip().splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())
