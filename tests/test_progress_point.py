"""Progress of the single-point computations (issue 23: every computation over a second shows progress, also when
stderr is a file): ``simulate``, ``orbit``'s simulation, ``runup`` and ``bench`` report as they go, for the pair
and a system alike, and every number is that of the run without progress, bit for bit.

``integrate_batch(..., progress=...)`` runs a long transient in pieces of whole periods where the backend continues
a run from a period's end state exactly (the pair's default mode, both modes of a mesh-vector system), and follows
the recorded periods' rows as the kernel writes them (the kernel in a thread)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_run import run_cli as _cli

import geardyn.backend as B
import geardyn.integrate as I
import geardyn.sweep.progress as P
from geardyn.analysis.periodic import shoot
from geardyn.analysis.runup import runup, steady_response
from geardyn.analysis.steady import simulate
from geardyn.model import GearModel, IntegrationOptions
from geardyn.systems import load_system
from geardyn.tooth.excitation import Excitation, excitation_model

SYSTEMS = Path(__file__).resolve().parents[1] / "examples" / "systems"
TORS = str(SYSTEMS / "paper_torsional.toml")
BEVEL = str(SYSTEMS / "paper_bevel_8dof.toml")
FIELDS = ("poincare", "end_state", "status", "stats", "nsteps", "lyapunov_log", "tangent")


@pytest.fixture(autouse=True)
def small_pieces(monkeypatch):
    """Transient pieces of a few periods, so that short runs go in many pieces."""
    monkeypatch.setattr(B, "FIRST_PIECE_STEPS", 1)
    monkeypatch.setattr(B, "PIECE_SECONDS", 1e-4)


def _calls():
    calls: list[tuple[int, int]] = []
    return calls, lambda d, n: calls.append((d, n))


def _same(a: I.BatchResult, b: I.BatchResult) -> None:
    for k in FIELDS:
        x, y = getattr(a, k), getattr(b, k)
        assert (x is None) == (y is None), k
        if x is not None:
            assert x.shape == y.shape and np.array_equal(x, y, equal_nan=True), k


def _counted(calls: list[tuple[int, int]], total: int) -> list[int]:
    done = [d for d, _ in calls]
    assert calls and calls[-1] == (total, total) and all(n == total for _, n in calls)
    assert done == sorted(done) and len(set(done)) == len(done)  # increasing, ending at the total
    return done


def _table_model() -> GearModel:
    base = GearModel(omega=0.8, xi0=0.05, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=(), fp=0.3, D=0.6)
    exc = Excitation(
        np.array([1.25, 1.2, 1.1, 0.7, 0.8, 1.15]) * 3e8,
        np.array([0, 2, 5, 5, 1, -3]) * 1e-7,
        1,
        phase=np.array([0.0, 0.1, 0.3, 0.3, 0.55, 0.9]),
    )
    return excitation_model(base, exc, b_c=1e-5, evaluation="table", harmonics=3)


# ------------------------------------------------------------------------------------------ the kernel door
@pytest.mark.parametrize("case", ["pair", "pair-accurate", "pair-table", "system", "system-accurate"])
def test_trajectory_with_progress_is_the_trajectory_without(case):
    model = {
        "pair": GearModel(omega=1.2),
        "pair-accurate": GearModel(omega=1.2),
        "pair-table": _table_model(),
        "system": load_system(BEVEL).with_param("omega", 0.8),
        "system-accurate": load_system(TORS).with_param("omega", 0.8),
    }[case]
    acc = case.endswith(("accurate", "table"))
    tr = 12 if case == "system-accurate" else 60
    opts = IntegrationOptions(transient=tr, periods=20, accurate=acc)
    calls, cb = _calls()
    a = I.trajectory(model, None, opts, history_periods=4, progress=cb)
    b = I.trajectory(model, None, opts, history_periods=4)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.tau, b.tau)
    _same(a.summary, b.summary)
    done = _counted(calls, tr + 20)
    if case.startswith("system") or case == "pair":  # the transient in pieces, each reported
        assert sum(0 < d < tr for d in done) >= 3
    else:  # the pair's accurate mode carries its contact region across periods: its transient in one run
        assert all(d == 0 or d >= tr for d in done)  # (0 first: the bar shows at once)


@pytest.mark.parametrize("kind", ["none", "lyapunov", "monodromy", "adaptive", "no-poincare"])
def test_a_batch_with_progress_is_the_batch_without(kind):
    """Enough points for the lanes; points diverging in the transient (negative damping) end as in one run."""
    models = [GearModel(omega=w) for w in np.linspace(0.5, 1.5, 9)] + [
        GearModel(omega=0.8, xi0=x) for x in (-0.3, -0.02)
    ]
    opts = IntegrationOptions(transient=120, periods=30, adaptive=kind == "adaptive")
    kw = {"lyapunov": kind == "lyapunov", "monodromy": kind == "monodromy", "record_poincare": kind != "no-poincare"}
    calls, cb = _calls()
    a = I.integrate_batch(models, None, opts, progress=cb, **kw)
    b = I.integrate_batch(models, None, opts, **kw)
    _same(a, b)
    assert list(b.status[-2:]) == [I.ST_DIVERGED, I.ST_DIVERGED] and np.all(b.status[:-2] == I.ST_OK)
    _counted(calls, 150)


def test_a_point_diverging_in_a_late_piece_ends_as_in_one_run():
    m = GearModel(omega=0.8, xi0=-0.004)
    for tr in (2, 40, 400):
        opts = IntegrationOptions(transient=tr, periods=10)
        calls, cb = _calls()
        a, b = (
            I.trajectory(m, None, opts, history_periods=3, progress=cb),
            I.trajectory(m, None, opts, history_periods=3),
        )
        assert np.array_equal(a.x, b.x, equal_nan=True)
        _same(a.summary, b.summary)
        _counted(calls, tr + 10)
    assert b.summary.status[0] == I.ST_DIVERGED


def test_simulate_reports_its_periods_and_its_settling_pass():
    """A chaotic point is integrated on by the classification: the total grows by that pass, the count ends there."""
    m = GearModel(omega=1.2)
    opts = IntegrationOptions(transient=50, periods=100)
    calls, cb = _calls()
    a, b = simulate(m, opts, progress=cb), simulate(m, opts)
    assert a.to_json() == b.to_json() and np.array_equal(a.traj.x, b.traj.x)
    done, totals = [d for d, _ in calls], [n for _, n in calls]
    assert done == sorted(done) and totals == sorted(totals)
    assert (150, 150) in calls and calls[-1][0] == calls[-1][1] > 150  # the settling pass after the 150 periods
    assert b.summary["motion"] == "chaotic"


def test_a_systems_simulate_reports_and_keeps_its_numbers():
    s = load_system(BEVEL).with_param("omega", 0.8)
    opts = IntegrationOptions(transient=1000, periods=30)
    calls, cb = _calls()
    a, b = simulate(s, opts, progress=cb), simulate(s, opts)
    assert a.to_json() == b.to_json() and np.array_equal(a.traj.x, b.traj.x)
    assert b.summary["motion"] == "period-1"
    assert sum(0 < d < 1000 for d in _counted(calls, 1030)) >= 3


@pytest.mark.parametrize("system", [False, True])
def test_shooting_reports_the_simulation_of_its_guess(system):
    m = load_system(BEVEL).with_param("omega", 0.8) if system else GearModel(omega=0.8)
    calls, cb = _calls()
    a, b = shoot(m, 1, transient=80, progress=cb), shoot(m, 1, transient=80)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.monodromy, b.monodromy) and a.converged
    done = _counted(calls, calls[-1][1])
    assert calls[-1][1] > 80 and sum(0 < d < 80 for d in done) >= 3


def test_runup_reports_its_blocks():
    m = GearModel()
    calls, cb = _calls()
    a = runup(m, 0.7, 1.1, 600.0, max_blocks=20, settle=20, progress=cb)
    b = runup(m, 0.7, 1.1, 600.0, max_blocks=20, settle=20)
    nb = a.omega.size
    assert calls == [(k, nb) for k in range(nb + 1)] + [(nb, nb)]
    for k in ("order_amplitude", "amplitude", "dynamic_factor", "omega"):
        assert np.array_equal(getattr(a, k), getattr(b, k))
    calls, cb = _calls()
    assert steady_response(m, [0.8, 0.9, 1.0], periods=4, transient=10, progress=cb) == steady_response(
        m, [0.8, 0.9, 1.0], periods=4, transient=10
    )
    assert calls == [(k, 6) for k in range(1, 7)]


# ------------------------------------------------------------------------------------------ the command line
CLI_RUNS = {
    "simulate": ["simulate", "--transient", "200", "--periods", "20000"],
    "simulate-accurate": ["simulate", "--accurate", "--transient", "10", "--periods", "3000"],
    "simulate-system": ["simulate", "--system", BEVEL, "--omega", "0.8", "--transient", "20", "--periods", "2000"],
    "orbit": ["orbit", "--transient", "20000"],
    "orbit-system": ["orbit", "--system", BEVEL, "--omega", "0.8", "--transient", "2000"],
    "runup": ["runup", "--omega-start", "0.7", "--omega-stop", "1.1", "--tau-duration", "3000", "--num", "0"],
    "bench": ["bench", "--workload", "W2", "--repeats", "2"],
}
UNIT = {"simulate": "periods", "orbit": "periods", "runup": "blocks", "bench": "runs"}


@pytest.mark.parametrize("name", sorted(CLI_RUNS))
def test_cli_writes_plain_progress_lines_unless_json(name, monkeypatch):
    """Stderr captured (not a terminal): plain lines, the first as the run starts, others while it runs, the last at
    100 %; nothing on stderr with --json."""
    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    monkeypatch.setattr(P, "PLAIN_INTERVAL", 0.01)
    monkeypatch.setattr(I, "PROGRESS_POLL", 0.005)
    label = name.split("-")[0]
    code, out, err = _cli(CLI_RUNS[name])
    assert code == 0, err
    assert "\x1b[" not in err
    lines = [ln for ln in err.splitlines() if ln.startswith(f"{label}: ")]
    assert lines[0].startswith(f"{label}: starting")
    unit = UNIT[label]
    last = re.match(rf"{label}: (\d+)/(\d+) {unit} \(100%\), elapsed ", lines[-1])
    assert last and last.group(1) == last.group(2), lines[-1]
    counts = [int(m.group(1)) for ln in lines if (m := re.match(rf"{label}: (\d+)/\d+ {unit} ", ln))]
    assert any(0 < c < int(last.group(2)) for c in counts), err
    code, out, err = _cli(CLI_RUNS[name] + ["--json"])
    assert code == 0 and out.lstrip().startswith("{") and err == ""
