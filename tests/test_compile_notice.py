"""A compile of a kernel is announced by the progress of the command that waits for it, and left out of its ETA."""

from __future__ import annotations

import geardyn._cache_guard as guard
from geardyn.sweep import progress as prog


def test_a_compile_is_announced_once_by_an_enabled_bar_and_never_by_a_disabled_one(capsys, monkeypatch):
    monkeypatch.setattr(prog, "PROGRESS_DELAY", 3600.0)  # the bar itself never appears in this test
    with prog.task_progress("simulate", unit="periods", enabled=False) as bar:
        assert bar is None
        for cb in list(guard._callbacks):
            cb("the integrator")
    assert capsys.readouterr().err == ""
    with prog.task_progress("simulate", unit="periods") as bar:
        for cb in list(guard._callbacks):
            cb("the integrator")
            cb("the N-DOF integrator")  # a second compile in the same run: said once
    err = capsys.readouterr().err
    assert err.splitlines() == ["compiling the integrator, first run only"]
    assert guard._callbacks == []  # the closed bar listens no more


def test_the_eta_of_a_plain_progress_line_leaves_the_compile_out(capsys, monkeypatch):
    clock = {"now": 100.0, "compiled": 0.0}
    monkeypatch.setattr(prog.time, "monotonic", lambda: clock["now"])
    monkeypatch.setattr(guard, "compile_seconds", lambda: clock["compiled"])
    bar = prog._TaskBar("simulate", "periods", False, ".0f")
    try:
        bar._plain = prog._stderr_console()
        clock["now"], clock["compiled"] = 130.0, 20.0  # 30 s elapsed, 20 of them compiling
        bar.update(10, 40)  # 10 of 40 periods in 10 s of integration: 30 s to go
        with bar._lock:
            bar._line()
    finally:
        bar._plain = None
        bar.close()
    line = capsys.readouterr().err.splitlines()[0]
    assert "elapsed 0:00:30" in line and "ETA 0:00:30" in line, line
