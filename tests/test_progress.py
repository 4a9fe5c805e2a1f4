"""Progress reporting: sweeps count points (also in local pool workers), the response's bar has its
own label, single computations report (done, total), ``--json`` keeps stderr silent, and no
number changes with a progress display."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from cli_run import run_cli as _cli

import geardyn.sweep.progress as P
from geardyn.analysis.bifurcation import bifurcation, continuation_chunk, fixed_chunk, grid_chunk
from geardyn.analysis.lyapunov import lyapunov_spectrum
from geardyn.analysis.periodic import continuation
from geardyn.analysis.response import frequency_response
from geardyn.model import GearModel, IntegrationOptions
from geardyn.sweep import Chunk

FAST = IntegrationOptions(transient=40, periods=16)
OMEGAS = np.linspace(0.8, 1.2, 5)
LINEAR = dict(D=0.0, xi=(), kappa=(), fp=0.2, eps=(0.5,))


@pytest.fixture
def drawn(monkeypatch):
    """Every state the sweep bars are drawn in: (completed, total, unit, description)."""
    seen: list[tuple[int, int, str, str]] = []
    redraw = P.Progress._redraw

    def spy(self):
        done, total = self._current()
        seen.append((done, total, self._unit, self._description))
        redraw(self)

    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    monkeypatch.setattr(P.Progress, "_redraw", spy)
    return seen


def test_continuation_sweep_counts_points_in_process(drawn, capsys):
    bifurcation(GearModel(), "omega", OMEGAS, mode="continue", sweep="both", options=FAST, progress=True)
    assert {u for *_, u, _ in drawn} == {"points"}
    assert {t for _, t, *_ in drawn} == {10}
    done = [d for d, *_ in drawn]
    assert done == sorted(done) and done[-1] == 10
    assert set(range(1, 10)) <= set(done)  # point by point, not 0/2 chunks then 2/2
    err = capsys.readouterr().err
    assert "10/10 points" in err and "chunks" not in err and "bifurcation ω" in err
    assert P._SINK is None and not P._ACTIVE  # the bar stopped listening


def test_fixed_sweep_counts_points(drawn, capsys):
    bifurcation(GearModel(), "omega", np.linspace(0.8, 1.2, 6), options=FAST, chunk_points=2, progress=True)
    assert drawn[-1][:3] == (6, 6, "points")
    assert "6/6 points" in capsys.readouterr().err


def test_pool_workers_report_points_through_the_shared_counter(drawn, monkeypatch):
    counters = []
    watch = P.Progress.watch

    def spy(self, counter):
        counters.append(counter)
        watch(self, counter)

    monkeypatch.setattr(P.Progress, "watch", spy)
    bifurcation(
        GearModel(),
        "omega",
        OMEGAS,
        mode="continue",
        sweep="both",
        options=FAST,
        progress=True,
        workers=2,
        processes=True,
    )
    assert len(counters) == 1 and counters[0].value == 10  # every point ticked in a worker
    assert drawn[-1][:3] == (10, 10, "points")
    # without a bar the pool gets no counter
    counters.clear()
    bifurcation(
        GearModel(), "omega", OMEGAS[:2], mode="continue", sweep="both", options=FAST, workers=2, processes=True
    )
    assert counters == []


def test_resumed_chunks_count_their_points_at_start():
    pts = np.linspace(0.8, 1.2, 7)[:, None]
    common = ((0.0, 0.0), FAST, False, 0, True)
    chunks = [
        Chunk(0, grid_chunk, (GearModel(), ["omega"], pts[:3]) + common),
        Chunk(1, grid_chunk, (GearModel(), ["omega"], pts[3:]) + common),
    ]
    bar = P.Progress.for_chunks(chunks, {0: {}}, "demo")
    try:
        assert bar.counts_points and bar.completed == 3 and bar._total == 7
        P.tick(2)  # a point reported by the running chunk function
        assert bar.completed == 5
        bar.advance(chunks[1])
        assert bar.completed == 7
    finally:
        bar.close()
    assert P._SINK is None


def test_chunk_functions_say_how_many_points_they_hold():
    models = [GearModel(omega=w) for w in OMEGAS]
    assert P.chunk_points(Chunk(0, fixed_chunk, (models, (0.0, 0.0), FAST))) == 5
    assert P.chunk_points(Chunk(0, continuation_chunk, (models[:2], (0.0, 0.0), FAST))) == 2
    assert P.chunk_points(Chunk(0, np.sum, ((1, 2),))) is None  # counted as a chunk
    P.tick(3)  # no bar: nothing happens


def test_response_bar_says_response(drawn, capsys):
    frequency_response(GearModel(), 0.8, 1.2, 4, options=FAST, progress=True)
    assert {d for *_, d in drawn} == {"response ω"}
    err = capsys.readouterr().err
    assert "response ω" in err and "bifurcation" not in err
    ds = bifurcation(GearModel(), "xi0", [0.05, 0.1], options=FAST, progress=True, description="my sweep")
    assert drawn[-1][3] == "my sweep" and "my sweep: 0 of 2 points diverged" in capsys.readouterr().err
    assert ds.attrs["param"] == "xi0"


def test_progress_leaves_the_numbers_unchanged():
    kw = dict(mode="continue", sweep="both", options=FAST)
    a = bifurcation(GearModel(), "omega", OMEGAS, **kw)
    b = bifurcation(GearModel(), "omega", OMEGAS, progress=True, **kw)
    xr.testing.assert_identical(a, b)


def _calls():
    calls: list[tuple[float, float]] = []
    return calls, lambda done, total: calls.append((done, total))


def _increasing_to_total(calls):
    done = [d for d, _ in calls]
    total = [t for _, t in calls]
    assert done == sorted(done) and total == sorted(total)
    assert all(d <= t for d, t in calls)
    assert calls[-1][0] == calls[-1][1] > 0


def test_continuation_reports_the_parameter_span_covered():
    m = GearModel(omega=1.2, xi0=0.05, **LINEAR)
    calls, cb = _calls()
    res = continuation(m, "omega", 1.2, 1.05, 1, switch=False, progress=cb)
    _increasing_to_total(calls)
    assert calls[0] == (0.0, pytest.approx(0.15)) and calls[-1] == (pytest.approx(0.15),) * 2
    assert len(calls) > 3  # intermediate points, not only start and end
    plain = continuation(m, "omega", 1.2, 1.05, 1, switch=False)
    assert res.to_json() == plain.to_json()
    np.testing.assert_array_equal(res.branches[0].states, plain.branches[0].states)


def test_continuation_with_switching_adds_the_switched_branches():
    calls, cb = _calls()
    res = continuation(GearModel(xi0=0.08), "omega", 0.3, 1.0, 1, progress=cb)
    _increasing_to_total(calls)
    span = 0.7
    assert calls[-1][1] >= span * (1 - 1e-12)
    if len(res.branches) > 1:  # each switched branch adds its own distance to cover
        assert calls[-1][1] > span


@pytest.mark.parametrize("accurate", [False, True])
@pytest.mark.parametrize("omega", [1.2, 0.8])  # chaotic, periodic
def test_lyapunov_reports_periods(accurate, omega, monkeypatch):
    """With a progress report the run is followed as it goes (the default mode's transient in pieces of whole
    periods, each continuing the state; the recorded periods counted as the kernel writes them): the numbers are
    those of one run, bit for bit."""
    import geardyn.backend as B

    monkeypatch.setattr(B, "FIRST_PIECE_STEPS", 1)  # transient pieces of a period or so
    monkeypatch.setattr(B, "PIECE_SECONDS", 1e-4)
    calls, cb = _calls()
    opts = IntegrationOptions(transient=50, periods=237, accurate=accurate)
    res = lyapunov_spectrum(GearModel(omega=omega), opts, progress=cb)
    done = [d for d, _ in calls]
    assert calls[0] == (0, 287) and calls[-1] == (287, 287) and all(t == 287 for _, t in calls)
    assert done == sorted(done)
    if not accurate:  # the pair's accurate mode carries its contact region across periods: no transient pieces
        assert len({d for d in done if 0 < d < 50}) >= 5
    plain = lyapunov_spectrum(GearModel(omega=omega), opts)
    np.testing.assert_array_equal(res.exponents, plain.exponents)
    np.testing.assert_array_equal(res.uncertainty, plain.uncertainty)
    np.testing.assert_array_equal(res.log, plain.log)
    assert res.motion == plain.motion


def test_task_progress_draws_on_stderr_and_is_silent_when_disabled(monkeypatch, capsys):
    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    with P.task_progress("demo task", unit="Δω") as cb:
        cb(0.0, 2.0)
        cb(1.0, 2.0)
        cb(2.0, 2.0)
    err = capsys.readouterr().err
    assert "demo task" in err and "2/2 Δω" in err and "100%" in err
    with P.task_progress("spin", unit="periods", fmt=".0f", indeterminate=True) as cb:
        cb(0, 300)
        cb(300, 300)
    assert "300 periods requested" in capsys.readouterr().err
    with P.task_progress("quiet", enabled=False) as cb:
        assert cb is None
    assert capsys.readouterr().err == ""


# ------------------------------------------------------------------------- through the command line
CLI_RUNS = {
    "response": [
        "response",
        "--omega-start",
        "0.8",
        "--omega-stop",
        "1.2",
        "--num",
        "4",
        "--transient",
        "40",
        "--periods",
        "16",
    ],
    "lyapunov": ["lyapunov", "--transient", "20", "--periods", "100"],
    "continuation": [
        "continuation",
        "--param",
        "omega",
        "--start",
        "1.2",
        "--stop",
        "1.1",
        "--no-switch",
        "--backlash",
        "0",
        "--kappa1",
        "0",
        "--xi1",
        "0",
    ],
}
CLI_LABEL = {"response": "response ω", "lyapunov": "lyapunov", "continuation": "continuation ω"}


@pytest.mark.parametrize("name", sorted(CLI_RUNS))
def test_cli_draws_progress_unless_json(name, monkeypatch):
    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    code, out, err = _cli(CLI_RUNS[name])
    assert code == 0, err
    assert CLI_LABEL[name] in err
    code, out, err = _cli(CLI_RUNS[name] + ["--json"])
    assert code == 0 and out.lstrip().startswith("{")
    assert err == ""


# ------------------------------------------------------------------------- stderr not a terminal
def test_progress_to_a_file_is_written_while_the_sweep_runs(tmp_path):
    """With stderr redirected to a file, the sweep's progress is there while it runs (not only at its end), as
    plain lines at most one per PLAIN_INTERVAL seconds (plus the first and the last)."""
    import os
    import subprocess
    import sys
    import time

    err = tmp_path / "stderr.txt"
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(filter(None, [str(Path(P.__file__).parents[2]), os.environ.get("PYTHONPATH")])),
    )
    argv = [
        sys.executable,
        "-m",
        "geardyn.cli",
        "response",
        "--omega-start",
        "0.6",
        "--omega-stop",
        "1.2",
        "--num",
        "30",
        "--transient",
        "400",
        "--periods",
        "60",
    ]
    with open(err, "w") as fh:
        t0 = time.monotonic()
        proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=fh, env=env)
        seen_running = None
        while proc.poll() is None:
            text = err.read_text()
            if seen_running is None and "response ω: " in text and "points" in text:
                seen_running = text
            time.sleep(0.05)
        elapsed = time.monotonic() - t0
    assert proc.returncode == 0
    assert seen_running is not None, "no progress line before the command ended"
    assert "\x1b[" not in seen_running  # plain text, no terminal control sequences
    lines = [ln for ln in err.read_text().splitlines() if ln.startswith("response ω: ") and "points (" in ln]
    assert lines[-1].startswith("response ω: 60/60 points (100%)")
    assert 2 <= len(lines) <= 2 + elapsed / P.PLAIN_INTERVAL


def test_plain_lines_are_rate_limited(monkeypatch, capsys):
    """Many updates in a short time give the first line, the last one and nothing between (stderr captured: not
    a terminal)."""
    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    monkeypatch.setattr(P, "PLAIN_INTERVAL", 3600.0)
    with P.task_progress("busy", unit="steps", fmt=".0f") as cb:
        for k in range(1001):
            cb(k, 1000)
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2 and lines[0].startswith("busy: starting")
    assert lines[1].startswith("busy: 1000/1000 steps (100%), elapsed 0:00:0")
