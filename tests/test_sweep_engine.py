"""The sweep engine under faults: worker counts, checkpoints, resume, kill -9, Ctrl-C, divergence (DESIGN §6, §7)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import sweep_fixtures as F
from geardyn import sweep as S
from geardyn.io import read_netcdf, write_netcdf
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.sweep import Chunk, SweepInterrupted, checkpoint_dir, chunked, grid_models, run_chunks

HERE = Path(__file__).resolve().parent
OMEGAS = np.linspace(0.6, 1.4, 6)
#: A chunk of one point under these options takes ~0.1 s: long enough to interrupt a sweep mid-run.
SLOW = IntegrationOptions(transient=3000, periods=16)


def chunk_files(d: Path) -> list[Path]:
    return sorted(d.glob("chunk-*.npz"))


@pytest.fixture(scope="module")
def reference() -> xr.Dataset:
    """The uninterrupted in-process sweep every other run must reproduce exactly."""
    return F.sweep("omega", OMEGAS, workers=1)


# ------------------------------------------------------------------------- engines agree
def test_workers_1_and_2_give_identical_datasets(reference):
    two = F.sweep("omega", OMEGAS, workers=2)
    xr.testing.assert_identical(reference, two)
    assert set(np.unique(reference["period"].values)) - {0} , "the grid should hold periodic points"


def test_any_executor_gives_identical_dataset(reference):
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(2) as ex:
        xr.testing.assert_identical(reference, F.sweep("omega", OMEGAS, executor=ex))


def test_chunk_size_does_not_change_the_result(reference):
    xr.testing.assert_identical(reference, F.sweep("omega", OMEGAS, chunk_points=4))


# ------------------------------------------------------------------------- checkpoints
def test_checkpoint_resume_runs_only_missing_chunks(tmp_path, reference, monkeypatch):
    ck = tmp_path / "ck"
    full = F.sweep("omega", OMEGAS, checkpoint=ck)
    xr.testing.assert_identical(reference, full)
    files = chunk_files(ck)
    assert len(files) == 3
    files[1].unlink()
    kept = {p.name: p.stat().st_mtime_ns for p in chunk_files(ck)}
    saved: list[int] = []
    real = S._save_chunk
    monkeypatch.setattr(S, "_save_chunk", lambda d, i, r: (saved.append(i), real(d, i, r)))
    xr.testing.assert_identical(reference, F.sweep("omega", OMEGAS, checkpoint=ck, resume=True))
    assert saved == [1]  # only the missing chunk ran
    assert {p.name: p.stat().st_mtime_ns for p in chunk_files(ck) if p.name in kept} == kept


def test_corrupt_or_partial_chunk_files_are_recomputed(tmp_path, reference):
    ck = tmp_path / "ck"
    F.sweep("omega", OMEGAS, checkpoint=ck)
    chunk_files(ck)[0].write_bytes(b"PK\x03\x04 truncated")
    (ck / ".chunk-000001.npz.abc.tmp").write_bytes(b"left by a killed writer")
    xr.testing.assert_identical(reference, F.sweep("omega", OMEGAS, checkpoint=ck, resume=True))
    assert not list(ck.glob(".*.tmp"))


def test_resume_refuses_a_checkpoint_of_another_sweep(tmp_path):
    ck = tmp_path / "ck"
    F.sweep("omega", OMEGAS, checkpoint=ck)
    with pytest.raises(ModelError, match=r"^resume: .*different sweep"):
        F.sweep("omega", OMEGAS[:-1], checkpoint=ck, resume=True)
    # without --resume the old checkpoint is replaced
    F.sweep("omega", OMEGAS[:-1], checkpoint=ck)
    assert len(chunk_files(ck)) == 3


def test_chunk_writes_are_durable(tmp_path, monkeypatch):
    synced: list[Path] = []
    real = S._fsync_dir
    monkeypatch.setattr(S, "_fsync_dir", lambda d: (synced.append(Path(d)), real(d)))
    F.sweep("omega", OMEGAS[:2], checkpoint=tmp_path / "ck")
    assert synced.count(tmp_path / "ck") >= 2  # manifest and the chunk, each followed by a directory fsync


def test_checkpoint_dir_sits_next_to_the_output(tmp_path):
    assert checkpoint_dir(tmp_path / "bif.nc") == tmp_path / "bif.nc.chunks"
    d = checkpoint_dir(tmp_path / "bif.nc")
    F.sweep("omega", OMEGAS[:2], checkpoint=d)
    S.remove_checkpoint(d)
    assert not d.exists()


# ------------------------------------------------------------------------- interruption
def test_ctrl_c_in_process_keeps_finished_chunks_and_resumes(tmp_path, reference):
    ck = tmp_path / "ck"
    flag = tmp_path / "stop"
    flag.touch()
    models = grid_models(GearModel(), ["omega"], [OMEGAS])
    chunks = [Chunk(i, F.interrupt_at_chunk, (str(flag), 2, i, models[s], F.FAST))
              for i, s in enumerate(chunked(len(models), 2))]
    with pytest.raises(SweepInterrupted) as ei:
        run_chunks(chunks, checkpoint=ck)
    e = ei.value
    assert (e.finished, e.total, e.checkpoint) == (2, 3, ck)
    assert "--resume" in str(e) and "\n" not in str(e)
    assert len(chunk_files(ck)) == 2
    flag.unlink()
    xr.testing.assert_identical(reference, F.to_dataset("omega", OMEGAS, run_chunks(chunks, checkpoint=ck, resume=True)))


def test_lost_local_worker_process_does_not_lose_the_sweep(tmp_path, reference):
    models = grid_models(GearModel(), ["omega"], [OMEGAS])
    marker = str(tmp_path / "crashed")
    chunks = [Chunk(i, F.crash_once_chunk, (marker, models[s], F.FAST)) for i, s in enumerate(chunked(len(models), 2))]
    out = run_chunks(chunks, workers=2)
    assert os.path.exists(marker)  # one worker process did die
    xr.testing.assert_identical(reference, F.to_dataset("omega", OMEGAS, out))


def _script_args(out: Path, *extra: str) -> list[str]:
    return ["--out", str(out), "--num", "10", "--chunk", "1", "--transient", str(SLOW.transient),
            "--periods", str(SLOW.periods), *extra]


def _start_sweep(out: Path, *extra: str) -> subprocess.Popen:
    """The sweep script in its own process group (so that signals reach it and its workers only)."""
    args = [sys.executable, str(HERE / "sweep_fixtures.py"), *_script_args(out, *extra)]
    return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


def _wait_for_chunks(proc: subprocess.Popen, d: Path, n: int, timeout: float = 120) -> None:
    t0 = time.monotonic()
    while len(chunk_files(d)) < n:
        assert proc.poll() is None, f"sweep ended early: {proc.communicate()}"
        assert time.monotonic() - t0 < timeout, "no chunks written"
        time.sleep(0.02)


@pytest.fixture(scope="module")
def slow_reference(tmp_path_factory) -> xr.Dataset:
    """The uninterrupted run of the script's sweep, in process, through a NetCDF file as the script does."""
    nc = tmp_path_factory.mktemp("uninterrupted") / "sweep.nc"
    write_netcdf(F.sweep("omega", np.linspace(0.6, 1.4, 10), SLOW, chunk_points=1), nc)
    return read_netcdf(nc)


def test_kill_9_then_resume_equals_uninterrupted(tmp_path, slow_reference):
    nc = tmp_path / "sweep.nc"
    ck = checkpoint_dir(nc)
    proc = _start_sweep(tmp_path)
    try:
        _wait_for_chunks(proc, ck, 3)
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    done = chunk_files(ck)
    assert 3 <= len(done) < 10 and not nc.exists()
    for p in done:  # every chunk on disk is complete
        with np.load(p) as z:
            assert z["status"].shape == (1,)
    mtimes = {p.name: p.stat().st_mtime_ns for p in done}
    assert F.main(_script_args(tmp_path, "--resume")) == 0
    assert {p.name: p.stat().st_mtime_ns for p in chunk_files(ck) if p.name in mtimes} == mtimes  # not redone
    xr.testing.assert_identical(slow_reference, read_netcdf(nc))


def test_ctrl_c_with_worker_processes_stops_cleanly_then_resumes(tmp_path, slow_reference):
    nc = tmp_path / "sweep.nc"
    ck = checkpoint_dir(nc)
    proc = _start_sweep(tmp_path, "--workers", "2")
    try:
        _wait_for_chunks(proc, ck, 2)
        os.killpg(proc.pid, signal.SIGINT)  # as a terminal does: the whole process group
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("interrupted: ") and "--resume" in lines[0]
    assert 2 <= len(chunk_files(ck)) < 10
    assert F.main(_script_args(tmp_path, "--resume")) == 0  # resumed in process, on one worker
    xr.testing.assert_identical(slow_reference, read_netcdf(nc))


# ------------------------------------------------------------------------- divergence and progress
def test_negative_damping_points_diverge_and_the_sweep_goes_on(capsys):
    xi0 = np.linspace(-0.3, 0.2, 11)
    ds = F.sweep("xi0", xi0, IntegrationOptions(transient=60, periods=16), chunk_points=4, progress=True,
                 description="xi0 sweep")
    status = ds["status"].values
    neg, pos = xi0 < -1e-12, xi0 > 1e-12
    assert np.all(status[neg] == S.ST_DIVERGED)
    assert np.all(status[pos] == 0)
    for v in ("amplitude", "rms", "u_min", "u_max", "poincare_u", "poincare_v"):
        assert np.all(np.isnan(ds[v].values[neg])), v
        assert np.all(np.isfinite(ds[v].values[pos])), v
    assert np.all(ds["period"].values[neg] == -1)
    err = capsys.readouterr().err
    n_bad = int(np.count_nonzero(status == S.ST_DIVERGED))
    assert f"xi0 sweep: {n_bad} of 11 points diverged" in err


def test_divergence_summary_counts_status_entries():
    rows = [{"status": np.array([0, 1, 1])}, {"status": np.array([[1, 0]])}]
    assert S.divergence_summary(rows) == (3, 5)
    assert S.divergence_summary([{"x": np.zeros(2)}]) is None


def test_progress_bar_only_when_asked(capsys, monkeypatch):
    F.sweep("omega", OMEGAS[:2])
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(S, "PROGRESS_DELAY", 0.0)
    F.sweep("omega", OMEGAS[:4], progress=True, description="demo")
    err = capsys.readouterr().err
    assert "demo" in err and "chunks" in err and "0 of 4 points diverged" in err


def test_run_chunks_refuses_bad_arguments(tmp_path, monkeypatch):
    chunks = F.make_chunks("omega", OMEGAS[:2])
    for w in (0, -1, 1.5, True):
        with pytest.raises(ModelError, match="^workers: "):
            run_chunks(chunks, workers=w)
    with pytest.raises(ModelError, match="indices must be unique"):
        run_chunks(chunks + chunks)
    monkeypatch.setattr(S, "DASK_CONNECT_TIMEOUT", 1)
    with pytest.raises(ModelError, match="^scheduler: cannot connect"):
        run_chunks(chunks, scheduler="tcp://127.0.0.1:9")
    with pytest.raises(ModelError, match="empty"):
        S.concat_results([])
    (tmp_path / "file").write_text("x")
    with pytest.raises(ModelError, match="^out: "):
        run_chunks(chunks, checkpoint=tmp_path / "file")
