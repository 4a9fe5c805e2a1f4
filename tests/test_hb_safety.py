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
from geardyn.analysis.hb.damping import undamped_modes
from geardyn.errors import ModelError
from geardyn.model import GearModel
from geardyn.systems import load_system
from geardyn.systems.assemble import assemble
from geardyn.systems.description import Body, Connection, Mesh, SystemDescription

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "systems"
PLANETARY = EXAMPLES / "planetary_lin_parker_1999.toml"


# ------------------------------------------------------------------------------ damping
def _mathieu_boundaries(kappa: float) -> tuple[float, float]:
    """ω of the two boundaries of the first instability tongue of y'' + (1 + κ cos ωτ) y = 0 near ω = 2, from the
    characteristic values of Mathieu's equation (DLMF 28.2; scipy): with z = ωτ/2 it is y_zz + (a − 2q cos 2z) y = 0,
    a = 4/ω², q = −2κ/ω², and the tongue's boundaries are a = a_1(2κ/ω²) and a = b_1(2κ/ω²) (a_1(−q) = b_1(q))."""
    from scipy.optimize import brentq
    from scipy.special import mathieu_a, mathieu_b

    def f(w, fn):
        return 4.0 / w**2 - fn(1, 2.0 * kappa / w**2)

    return brentq(f, 1.7, 2.0, args=(mathieu_a,), xtol=1e-15), brentq(f, 2.0, 2.3, args=(mathieu_b,), xtol=1e-15)


def test_undamped_mathieu_tongue_is_located_on_the_unit_circle():
    """Without damping, in permanent contact (f_p = 0.5 > 0, D = 1, no STE), the variational equation is Mathieu's:
    the period-1 solution is unstable between the two period-doubling boundaries of the tongue near ω = 2 and
    neutrally stable outside.  det(I + M) locates both; the reference are Mathieu's characteristic values (an
    integration of the variational equation by DOP853 at rtol 1e-13 gives the same boundaries to 1e-14)."""
    lo, hi = _mathieu_boundaries(0.2)
    code, stdout, err = _main(
        "hb --param omega --start 1.8 --stop 2.2 --xi0 0 --xi1 0 --kappa1 0.2 --fp 0.5 --fe 0 --backlash 1 "
        "--json".split()
    )
    assert code == 0, err
    s = json.loads(stdout)
    assert s["conservative"] and s["end"] == "reached the end of the interval"
    pd = sorted(b["omega"] for b in s["bifurcations"] if b["type"] == "period-doubling")
    assert [b["type"] for b in s["bifurcations"]] == ["period-doubling"] * 2
    assert abs(pd[0] - lo) < 1e-4 and abs(pd[1] - hi) < 1e-4, (pd, lo, hi)  # measured 7.7e-9 and 1.2e-8
    for b in s["branch"]:
        w = b["omega"]
        if abs(w - lo) > 1e-3 and abs(w - hi) > 1e-3:
            assert b["stable"] is (not lo < w < hi), b
        assert min(b[k] for k in ("u_min",)) > 1.0  # no contact loss: the linear theory applies


def test_conservative_models_and_the_damping_continued_through_zero():
    from geardyn.analysis.hb.damping import require_decidable

    assert require_decidable(GearModel(xi0=0.0, xi=())) is True
    assert require_decidable(GearModel(xi0=0.0, xi=(0.05,))) is True  # ξ1 averages out: the product is exp(0) = 1
    assert require_decidable(GearModel(xi0=0.0), "xi0", 0.0, 0.05) is False  # damped at one end
    assert require_decidable(GearModel(xi0=0.1), "xi0", 0.0, 0.0) is True


def test_undamped_unforced_planetary_is_neutrally_stable_and_bounded(tmp_path):
    """The Lin & Parker planetary (undamped, unforced, backlash-free: every multiplier on the unit circle) once ran
    over 15 minutes reporting a Neimark–Sacker point at every pair grazing the circle; without damping no such test
    is made, the branch is neutrally stable and ends at the interval's end."""
    code, stdout, err = _main(
        ["hb", "--system", str(PLANETARY), "--param", "omega", "--start", "0.5", "--stop", "1.5", "--json"]
    )
    assert code == 0, err
    s = json.loads(stdout)
    assert s["conservative"] and s["end"] == "reached the end of the interval"
    assert not [b for b in s["bifurcations"] if b["type"] == "neimark-sacker"]
    assert all(b["stable"] for b in s["branch"])


def test_a_free_coordinate_the_gauge_cannot_fix_is_refused_in_one_line():
    """A body tied to the gear by a damper only moves freely (zero stiffness) but is damped: not a rigid-body mode
    (no damping along it), so its mean is undetermined and harmonic balance has no isolated solution."""
    from geardyn.analysis.hb.damping import require_decidable

    m = _satellites()
    desc = m.description
    s3 = Body("s3", ("theta",), inertia=0.01)
    damper = Connection.along("damper", {("g", "theta"): 1.0, ("s3", "theta"): -1.0}, 0.0, damping=5.0)
    free = assemble(
        SystemDescription(bodies=desc.bodies + (s3,), meshes=desc.meshes, connections=desc.connections + (damper,))
    )
    with pytest.raises(ModelError, match=r"^system: the coordinate .* moves freely") as e:
        require_decidable(free)
    assert "\n" not in str(e.value)
    require_decidable(m)  # its free rotation is a rigid-body mode: fixed by the gauge


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
    import geardyn.sweep.progress as P

    monkeypatch.setattr(P, "PROGRESS_DELAY", 1e9)  # no progress lines on a loaded machine: only the error

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
