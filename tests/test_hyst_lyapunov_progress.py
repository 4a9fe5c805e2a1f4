"""``geardyn lyapunov --system`` shows its progress like the pair's (issue 23: every computation over a second shows
progress, also when stderr is a file), and the numbers are those of the run without progress, bit for bit.

The mesh-vector kernel cannot start from a given tangent basis, so a system's recorded periods cannot be cut into
blocks as the pair's are: its transient goes in blocks, and its recorded periods run in one kernel call whose
written rows are counted while it runs (``integrate_batch(..., progress=...)``)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from cli_run import run_cli as _cli

import geardyn.integrate as I
import geardyn.sweep.progress as P
from geardyn.analysis.lyapunov import lyapunov_spectrum
from geardyn.model import IntegrationOptions
from geardyn.systems import load_system

TORS = str(Path(__file__).resolve().parents[1] / "examples" / "systems" / "paper_torsional.toml")


@pytest.mark.parametrize("accurate, periods", [(False, 120), (True, 40)])
def test_a_systems_spectrum_with_progress_is_the_spectrum_without(accurate, periods, monkeypatch):
    import geardyn.backend as B

    monkeypatch.setattr(B, "FIRST_PIECE_STEPS", 1)  # transient pieces of a period or so
    monkeypatch.setattr(B, "PIECE_SECONDS", 1e-4)
    s = load_system(TORS).with_param("omega", 0.8)
    opts = IntegrationOptions(transient=40, periods=periods, accurate=accurate)
    total = 40 + periods
    plain = lyapunov_spectrum(s, opts)
    calls: list[tuple[int, int]] = []
    followed = lyapunov_spectrum(s, opts, progress=lambda d, n: calls.append((d, n)))
    np.testing.assert_array_equal(followed.exponents, plain.exponents)
    np.testing.assert_array_equal(followed.uncertainty, plain.uncertainty)
    np.testing.assert_array_equal(followed.log, plain.log)
    assert followed.to_json() == plain.to_json()
    done = [d for d, _ in calls]
    assert calls[0] == (0, total) and calls[-1] == (total, total) and all(n == total for _, n in calls)
    assert done == sorted(done)
    assert len({d for d in done if 0 < d < 40}) >= 5  # the transient in pieces, each reported


def test_the_recorded_periods_are_counted_while_the_kernel_runs(monkeypatch):
    """One kernel call of 400 recorded periods, looked at every millisecond: the counts reported before its end lie
    strictly between the transient and the total (the kernel's rows were followed, not counted at the end)."""
    monkeypatch.setattr(I, "PROGRESS_POLL", 0.001)
    s = load_system(TORS).with_param("omega", 0.8)
    calls: list[tuple[int, int]] = []
    res = I.integrate_batch(
        [s],
        None,
        IntegrationOptions(transient=5, periods=400),
        lyapunov=True,
        progress=lambda d, n: calls.append((d, n)),
    )
    plain = I.integrate_batch([s], None, IntegrationOptions(transient=5, periods=400), lyapunov=True)
    np.testing.assert_array_equal(res.lyapunov_log, plain.lyapunov_log)
    np.testing.assert_array_equal(res.poincare, plain.poincare)
    assert calls[-1] == (405, 405)
    assert any(5 < d < 405 for d, _ in calls)


def test_lyapunov_on_a_system_draws_progress_unless_json(monkeypatch):
    """Stderr captured (not a terminal): plain progress lines, the first when the run starts, one at most every
    PLAIN_INTERVAL seconds while it runs, the last at 100 %; nothing with --json."""
    monkeypatch.setattr(P, "PROGRESS_DELAY", 0.0)
    monkeypatch.setattr(P, "PLAIN_INTERVAL", 0.02)
    argv = ["lyapunov", "--system", TORS, "--omega", "0.8", "--transient", "200", "--periods", "400"]
    code, out, err = _cli(argv)
    assert code == 0, err
    cost = (
        "lyapunov: the full spectrum integrates"  # a system's cost line, printed before the run (docs/performance.md)
    )
    assert err.splitlines()[0].startswith(cost)
    lines = [ln for ln in err.splitlines() if ln.startswith("lyapunov: ") and not ln.startswith(cost)]
    assert lines[0].startswith("lyapunov: starting") and lines[-1].startswith("lyapunov: 600/600 periods (100%)")
    assert "\x1b[" not in err
    counts = [int(m.group(1)) for ln in lines if (m := re.match(r"lyapunov: (\d+)/600 periods", ln))]
    assert any(0 < c < 600 for c in counts), err
    assert "λ1" in out
    code, out, err = _cli(argv + ["--json"])
    assert code == 0 and out.lstrip().startswith("{") and err == ""
