"""The adaptive transient: same labels and orbits as the fixed transient, same results on any engine."""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest
import xarray as xr

from geardyn.analysis.bifurcation import bifurcation
from geardyn.analysis.classify import detect_period
from geardyn.integrate import integrate_batch
from geardyn.io import read_netcdf
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.sweep import checkpoint_dir

#: Periodic (ω < 1) and chaotic (ω > 1.1) points of the W1 grid, full W1 lengths.
OMEGAS = np.linspace(0.5, 1.5, 200)[::8]
FIXED = IntegrationOptions(transient=300, periods=200)
ADAPTIVE = FIXED.replace(adaptive=True)


@pytest.fixture(scope="module")
def pair():
    models = [GearModel(omega=float(w)) for w in OMEGAS]
    return integrate_batch(models, options=FIXED), integrate_batch(models, options=ADAPTIVE)


def test_same_labels_and_orbits_as_the_fixed_transient(pair):
    fixed, adaptive = pair
    pf = np.array([detect_period(p) for p in fixed.poincare])
    pa = np.array([detect_period(p) for p in adaptive.poincare])
    assert np.array_equal(pf, pa)
    per = pf > 0
    assert per.sum() >= 5 and (~per).sum() >= 5, "the grid should hold periodic and non-periodic points"
    assert np.max(np.abs(fixed.poincare[per] - adaptive.poincare[per])) <= 1e-8
    assert np.max(np.abs(fixed.end_state[per] - adaptive.end_state[per])) <= 1e-8
    for k in ("amplitude", "mean", "rms"):
        assert np.max(np.abs(getattr(fixed, k)[per] - getattr(adaptive, k)[per])) <= 1e-8
    assert np.max(np.abs(fixed.contact_fractions[per] - adaptive.contact_fractions[per])) <= 1e-6
    # points that never converge run the full transient and record in full: the same bits
    assert np.array_equal(fixed.poincare[~per], adaptive.poincare[~per])
    assert np.array_equal(fixed.stats[~per], adaptive.stats[~per])


def test_lanes_and_scalar_paths_agree(pair):
    _, adaptive = pair
    for i in (0, 3, len(OMEGAS) - 1):
        one = integrate_batch([GearModel(omega=float(OMEGAS[i]))], options=ADAPTIVE)
        assert np.array_equal(one.poincare[0], adaptive.poincare[i])
        assert np.array_equal(one.stats[0], adaptive.stats[i])
        assert np.array_equal(one.end_state[0], adaptive.end_state[i])


def test_with_exponents_only_the_transient_is_shortened():
    models = [GearModel(omega=w) for w in (0.6, 0.8)]
    f = integrate_batch(models, options=FIXED, lyapunov=True)
    a = integrate_batch(models, options=ADAPTIVE, lyapunov=True)
    assert a.lyapunov_log.shape == f.lyapunov_log.shape
    assert np.max(np.abs(f.poincare - a.poincare)) <= 1e-8
    assert np.max(np.abs(f.lyapunov_log.sum(axis=1) - a.lyapunov_log.sum(axis=1))) <= 1e-6


def test_accurate_mode_is_refused():
    with pytest.raises(ModelError, match="^adaptive: "):
        IntegrationOptions(adaptive=True, accurate=True)


SWEEP = np.linspace(0.6, 1.4, 12)
SHORT = IntegrationOptions(transient=300, periods=64, adaptive=True)


@pytest.fixture(scope="module")
def reference():
    return bifurcation(GearModel(), "omega", SWEEP, options=SHORT, settle_periods=0)


def test_sweep_same_for_workers_and_chunk_sizes(reference):
    xr.testing.assert_identical(
        reference, bifurcation(GearModel(), "omega", SWEEP, options=SHORT, settle_periods=0, workers=2, chunk_points=5)
    )
    xr.testing.assert_identical(
        reference, bifurcation(GearModel(), "omega", SWEEP, options=SHORT, settle_periods=0, chunk_points=1)
    )


def test_continuation_sweep_runs_adaptive():
    f = bifurcation(
        GearModel(), "omega", SWEEP[:4], mode="continue", options=SHORT.replace(adaptive=False), settle_periods=0
    )
    a = bifurcation(GearModel(), "omega", SWEEP[:4], mode="continue", options=SHORT, settle_periods=0)
    assert np.array_equal(f["period"].values, a["period"].values)
    per = f["period"].values > 0
    assert np.max(np.abs(f["poincare_u"].values[per] - a["poincare_u"].values[per])) <= 1e-8


def test_cli_adaptive_killed_with_sigkill_then_resumed(tmp_path):
    from test_sweep_engine import _wait_for_chunks, chunk_files, run_cli, start_cli

    argv = [
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "1.15",
        "--stop",
        "1.45",
        "--num",
        "8",
        "--chunk-size",
        "1",
        "--transient",
        "3000",
        "--periods",
        "16",
        "--settle",
        "0",
        "--adaptive",
    ]
    ref_dir = tmp_path / "ref"
    code, _, err = run_cli(argv + ["--out", str(ref_dir), "--json"])
    assert code == 0, err
    ck = checkpoint_dir(tmp_path / "bifurcation.nc")
    proc = start_cli(*argv, "--out", str(tmp_path), "--workers", "2", "--json")
    try:
        _wait_for_chunks(proc, ck, 2)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
        time.sleep(1.5)  # its workers notice and end
    finally:
        import os

        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    assert 2 <= len(chunk_files(ck)) < 8
    code, _, err = run_cli(argv + ["--out", str(tmp_path), "--resume", "--json"])
    assert code == 0, err
    xr.testing.assert_identical(read_netcdf(ref_dir / "bifurcation.nc"), read_netcdf(tmp_path / "bifurcation.nc"))
