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
import sweep_fixtures as F
import xarray as xr
from cli_run import run_cli

from geardyn import sweep as S
from geardyn.errors import SweepError
from geardyn.io import read_netcdf
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.sweep import Chunk, SweepInterrupted, checkpoint_dir, chunked, run_chunks
from geardyn.system import build_models

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
    assert set(np.unique(reference["period"].values)) - {0}, "the grid should hold periodic points"


def test_threads_and_processes_give_identical_datasets(reference):
    xr.testing.assert_identical(reference, F.sweep("omega", OMEGAS, workers=3))
    xr.testing.assert_identical(reference, F.sweep("omega", OMEGAS, workers=2, processes=True))
    with pytest.raises(ModelError, match="^processes: "):
        run_chunks(F.make_chunks("omega", OMEGAS[:2]), processes="yes")


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
    real = S.checkpoints._save_chunk
    monkeypatch.setattr(S.checkpoints, "_save_chunk", lambda d, i, r: (saved.append(i), real(d, i, r)))
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
    with pytest.raises(SweepError, match=r"^resume: .*different sweep"):
        F.sweep("omega", OMEGAS[:-1], checkpoint=ck, resume=True)
    # without --resume the old checkpoint is replaced
    F.sweep("omega", OMEGAS[:-1], checkpoint=ck)
    assert len(chunk_files(ck)) == 3


def test_chunk_writes_are_durable(tmp_path, monkeypatch):
    import geardyn.atomic as gio

    synced: list[Path] = []
    real = gio._fsync_dir
    monkeypatch.setattr(gio, "_fsync_dir", lambda d: (synced.append(Path(d)), real(d)))
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
    models = build_models(GearModel(), ["omega"], np.asarray(OMEGAS, float)[:, None])
    chunks = [
        Chunk(i, F.interrupt_at_chunk, (str(flag), 2, i, models[s], F.FAST))
        for i, s in enumerate(chunked(len(models), 2))
    ]
    with pytest.raises(SweepInterrupted) as ei:
        run_chunks(chunks, checkpoint=ck)
    e = ei.value
    assert (e.finished, e.total, e.checkpoint) == (2, 3, ck)
    assert "--resume" in str(e) and "\n" not in str(e)
    assert len(chunk_files(ck)) == 2
    flag.unlink()
    xr.testing.assert_identical(
        reference, F.to_dataset("omega", OMEGAS, run_chunks(chunks, checkpoint=ck, resume=True))
    )


def test_lost_local_worker_process_does_not_lose_the_sweep(tmp_path, reference):
    models = build_models(GearModel(), ["omega"], np.asarray(OMEGAS, float)[:, None])
    marker = str(tmp_path / "crashed")
    chunks = [Chunk(i, F.crash_once_chunk, (marker, models[s], F.FAST)) for i, s in enumerate(chunked(len(models), 2))]
    out = run_chunks(chunks, workers=2, processes=True)
    assert os.path.exists(marker)  # one worker process did die
    xr.testing.assert_identical(reference, F.to_dataset("omega", OMEGAS, out))


def _wait_for_chunks(proc: subprocess.Popen, d: Path, n: int, timeout: float = 120) -> None:
    t0 = time.monotonic()
    while len(chunk_files(d)) < n:
        assert proc.poll() is None, f"sweep ended early: {proc.communicate()}"
        assert time.monotonic() - t0 < timeout, "no chunks written"
        time.sleep(0.02)


# ------------------------------------------------------------------------- divergence and progress
def test_negative_damping_points_diverge_and_the_sweep_goes_on(capsys):
    xi0 = np.linspace(-0.3, 0.2, 11)
    ds = F.sweep(
        "xi0", xi0, IntegrationOptions(transient=60, periods=16), chunk_points=4, progress=True, description="xi0 sweep"
    )
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
    monkeypatch.setattr(S.progress, "PROGRESS_DELAY", 0.0)
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
    monkeypatch.setattr(S.executors, "DASK_CONNECT_TIMEOUT", 1)
    with pytest.raises(SweepError, match="^scheduler: cannot connect"):
        run_chunks(chunks, scheduler="tcp://127.0.0.1:9")
    with pytest.raises(ModelError, match="empty"):
        S.concat_results([])
    (tmp_path / "file").write_text("x")
    with pytest.raises(SweepError, match="^out: "):
        run_chunks(chunks, checkpoint=tmp_path / "file")


# ------------------------------------------------------------------------- through the command line
BIF = [
    "bifurcation",
    "--param",
    "omega",
    "--start",
    "0.6",
    "--stop",
    "1.4",
    "--num",
    "8",
    "--chunk-size",
    "1",
    "--transient",
    str(SLOW.transient),
    "--periods",
    str(SLOW.periods),
    "--settle",
    "0",
]


def start_cli(*args: str) -> subprocess.Popen:
    """``geardyn ARGS`` in its own process group (signals reach it and its workers only)."""
    return subprocess.Popen(
        [sys.executable, "-m", "geardyn.cli", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


@pytest.fixture(scope="module")
def bif_reference(tmp_path_factory) -> xr.Dataset:
    out = tmp_path_factory.mktemp("bifurcation")
    code, _, err = run_cli(BIF + ["--out", str(out), "--json"])
    assert code == 0, err
    assert not checkpoint_dir(out / "bifurcation.nc").exists()  # dropped once the result is written
    return read_netcdf(out / "bifurcation.nc")


def live_processes_in_group(pgid: int) -> list[int]:
    """Processes of a process group that have not ended (Linux /proc)."""
    pids = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_bytes().rsplit(b")", 1)[1].split()
            except (OSError, IndexError):
                continue
            if int(fields[2]) == pgid and fields[0] != b"Z":
                pids.append(int(d.name))
    return pids


def test_cli_bifurcation_killed_with_sigkill_then_resumed(tmp_path, bif_reference):
    ck = checkpoint_dir(tmp_path / "bifurcation.nc")
    proc = start_cli(*BIF, "--out", str(tmp_path), "--workers", "2", "--json")
    try:
        _wait_for_chunks(proc, ck, 3)
        proc.send_signal(signal.SIGKILL)  # the main process only, as `kill -9 PID` does
        proc.wait(timeout=30)
        if Path("/proc/self/stat").exists():  # its worker processes notice and end too
            t0 = time.monotonic()
            while live_processes_in_group(proc.pid) and time.monotonic() - t0 < 20:
                time.sleep(0.1)
            assert not live_processes_in_group(proc.pid)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    done = len(chunk_files(ck))
    assert 3 <= done < 8 and not (tmp_path / "bifurcation.nc").exists()
    for p in chunk_files(ck):  # every chunk on disk is complete
        with np.load(p) as z:
            assert z["status"].shape == (1,)
    code, out, err = run_cli(BIF + ["--out", str(tmp_path), "--resume"])
    assert code == 0, err
    xr.testing.assert_identical(bif_reference, read_netcdf(tmp_path / "bifurcation.nc"))
    assert not ck.exists()


def test_cli_bifurcation_ctrl_c_says_how_to_resume(tmp_path, bif_reference):
    ck = checkpoint_dir(tmp_path / "bifurcation.nc")
    proc = start_cli(*BIF, "--out", str(tmp_path), "--workers", "2", "--json")
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
    assert lines[0].startswith("interrupted: ") and "--resume" in lines[0] and str(ck) in lines[0]
    assert out == ""
    code, out, err = run_cli(BIF + ["--out", str(tmp_path), "--resume", "--json"])
    assert code == 0, err
    xr.testing.assert_identical(bif_reference, read_netcdf(tmp_path / "bifurcation.nc"))


def test_cli_resume_needs_out_and_the_same_sweep(tmp_path):
    code, _, err = run_cli(BIF + ["--resume"])
    assert code == 2 and err.startswith("error: resume: needs --out")
    ck = checkpoint_dir(tmp_path / "bifurcation.nc")
    ck.mkdir()
    (ck / S.MANIFEST).write_text('{"fingerprint": "another sweep", "chunks": 3}')
    code, _, err = run_cli(BIF + ["--out", str(tmp_path), "--resume"])
    assert code == 2 and "different sweep" in err and len(err.strip().splitlines()) == 1


def test_cli_xi0_sweep_marks_negative_damping_diverged():
    import json

    argv = [
        "bifurcation",
        "--param",
        "xi0",
        "--start",
        "-0.3",
        "--stop",
        "0.2",
        "--num",
        "11",
        "--transient",
        "60",
        "--periods",
        "16",
        "--settle",
        "0",
    ]
    code, out, err = run_cli(argv + ["--json"])
    assert code == 0, err
    assert err == ""  # silent with --json
    s = json.loads(out)
    xi0 = np.array(s["values"])
    status = np.array(s["status"])
    assert np.all(status[xi0 < -1e-12] == "diverged") and np.all(status[xi0 > 1e-12] == "ok")
    assert all(m == "diverged" for m, x in zip(s["motion"], xi0) if x < -1e-12)
    code, out, err = run_cli(argv)
    assert code == 0, err
    n_bad = int(np.count_nonzero(status == "diverged"))
    assert f"{n_bad} of 11 points diverged" in err


def test_fingerprint_depends_on_values_not_object_identity():
    name = "".join(["ome", "ga"])  # equal to the interned "omega", another object (as from the command line)
    assert name == "omega" and name is not sys.intern("omega")
    a = [Chunk(0, F.steady_chunk, (GearModel(), ("omega",), F.FAST))]
    b = [Chunk(0, F.steady_chunk, (GearModel(), (name,), F.FAST))]
    assert S.fingerprint(a) == S.fingerprint(b)


# ------------------------------------------------------------------------- chunks sized by cost
def test_chunks_sized_by_cost_cover_the_grid_whatever_the_workers():
    from geardyn.grid import Grid

    opts = IntegrationOptions(transient=20, periods=10)
    small = Grid.linspace("omega", 0.5, 1.5, 200)
    sl = S.chunk_slices(small, GearModel(), opts, S.SweepOptions(workers=2))
    assert sl == S.chunk_slices(small, GearModel(), opts, S.SweepOptions(workers=1))
    assert len(sl) == S.MIN_CHUNKS and sl[0].start == 0 and sl[-1].stop == 200
    assert all(a.stop == b.start for a, b in zip(sl, sl[1:]))
    big = Grid.product(("xi0", np.linspace(0.05, 0.3, 500)), ("omega", np.linspace(0.5, 0.75, 500)))
    sl = S.chunk_slices(big, GearModel(), opts, S.SweepOptions())
    steps = big.steps_per_period(GearModel(), opts.dtau) * 30
    per_chunk = [steps[s].sum() * S.STEP_SECONDS for s in sl]
    assert 0.5 * S.CHUNK_SECONDS < min(per_chunk) and max(per_chunk) < 1.5 * S.CHUNK_SECONDS
    assert S.chunk_slices(big, GearModel(), opts, S.SweepOptions(chunk_points=1000)) == big.slices(1000)
