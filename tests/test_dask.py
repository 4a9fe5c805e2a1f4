"""Sweeps on a real dask.distributed cluster (DESIGN §7): a scheduler and workers started as
separate processes on 127.0.0.1; the results equal the local ones, also when a worker is killed
in the middle of the sweep."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

distributed = pytest.importorskip("distributed")

import sweep_fixtures as F  # noqa: E402

from geardyn.model import IntegrationOptions  # noqa: E402

HERE = Path(__file__).resolve().parent
OMEGAS = np.linspace(0.6, 1.4, 6)
#: One point per chunk takes ~0.1 s with these options: a worker is busy when it is killed.
SLOW = IntegrationOptions(transient=3000, periods=16)
KILL_OMEGAS = np.linspace(0.6, 1.4, 16)
START_TIMEOUT = 90


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """A scheduler and workers, each its own process (``python -m dask scheduler|worker``)."""

    def __init__(self, workdir: Path) -> None:
        self.workdir = workdir
        self.procs: dict[str, subprocess.Popen] = {}
        self.env = dict(os.environ)
        self.env["PYTHONPATH"] = os.pathsep.join([str(HERE)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
        self.port = free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self._start("scheduler", ["scheduler", "--host", "127.0.0.1", "--port", str(self.port), "--no-dashboard"])

    def _start(self, name: str, args: list[str]) -> None:
        log = open(self.workdir / f"{name}.log", "w")
        self.procs[name] = subprocess.Popen(
            [sys.executable, "-m", "dask", *args],
            stdout=log,
            stderr=subprocess.STDOUT,
            env=self.env,
            cwd=self.workdir,
            start_new_session=True,
        )
        log.close()

    def add_worker(self, name: str) -> None:
        self._start(
            name,
            [
                "worker",
                self.address,
                "--name",
                name,
                "--nthreads",
                "1",
                "--no-nanny",
                "--no-dashboard",
                "--host",
                "127.0.0.1",
                "--death-timeout",
                "60",
                "--local-directory",
                str(self.workdir),
            ],
        )

    def client(self):
        return distributed.Client(self.address, timeout=START_TIMEOUT, set_as_default=False)

    def wait_for_workers(self, n: int) -> None:
        with self.client() as c:
            c.wait_for_workers(n, timeout=START_TIMEOUT)

    def worker_address(self, client, name: str) -> str:
        for addr, info in client.scheduler_info(n_workers=-1)["workers"].items():
            if info.get("name") == name:
                return addr
        raise LookupError(name)

    def close(self) -> None:
        """Stop the scheduler and its workers (gracefully, then by force); never leaves a process behind."""
        try:
            with distributed.Client(self.address, timeout=5, set_as_default=False) as c:
                c.shutdown()
        except Exception:  # the cluster is already gone or unreachable: the processes are stopped below
            pass
        deadline = time.monotonic() + 5
        for p in self.procs.values():
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("dask"))
    try:
        c.add_worker("w1")
        c.add_worker("w2")
        c.wait_for_workers(2)
        yield c
    finally:
        c.close()


def test_dask_cluster_gives_the_local_result(cluster, tmp_path):
    local = F.sweep("omega", OMEGAS, workers=1)
    remote = F.sweep("omega", OMEGAS, scheduler=cluster.address, checkpoint=tmp_path / "ck")
    xr.testing.assert_identical(local, remote)
    with cluster.client() as c:  # the chunks did run on both workers' processes, not here
        assert len(c.scheduler_info(n_workers=-1)["workers"]) == 2


def test_client_executor_gives_the_local_result(cluster):
    """``Client.get_executor()`` handed to the engine as any concurrent.futures executor."""
    from geardyn.sweep import SweepOptions

    local = F.sweep("omega", OMEGAS, workers=1)
    with cluster.client() as c:
        remote = F.sweep("omega", OMEGAS, engine=SweepOptions(executor=c.get_executor()))
    xr.testing.assert_identical(local, remote)


def test_sweep_survives_a_worker_killed_mid_run(cluster, tmp_path):
    local = F.sweep("omega", KILL_OMEGAS, SLOW, chunk_points=1, workers=1)
    cluster.add_worker("victim")
    cluster.wait_for_workers(3)
    ck = tmp_path / "ck"
    killed: dict[str, object] = {}

    def killer() -> None:
        try:
            with cluster.client() as c:
                addr = cluster.worker_address(c, "victim")
                t0 = time.monotonic()
                while time.monotonic() - t0 < START_TIMEOUT:
                    busy = c.processing(workers=[addr]).get(addr, ())
                    if busy and len(list(ck.glob("chunk-*.npz"))) >= 1:
                        killed["tasks"] = list(busy)
                        killed["done_before"] = len(list(ck.glob("chunk-*.npz")))
                        cluster.procs["victim"].send_signal(signal.SIGKILL)
                        return
                    time.sleep(0.01)
        except BaseException as e:  # reported by the assertions below
            killed["error"] = e

    th = threading.Thread(target=killer)
    th.start()
    try:
        remote = F.sweep("omega", KILL_OMEGAS, SLOW, chunk_points=1, scheduler=cluster.address, checkpoint=ck)
    finally:
        th.join(timeout=START_TIMEOUT)
    assert "error" not in killed, killed
    assert killed.get("tasks"), "the victim worker was never seen busy"
    assert killed["done_before"] < KILL_OMEGAS.size
    assert cluster.procs["victim"].wait(timeout=10) == -signal.SIGKILL
    xr.testing.assert_identical(local, remote)
    assert len(list(ck.glob("chunk-*.npz"))) == KILL_OMEGAS.size


def test_lost_scheduler_stops_the_sweep_in_one_line_keeping_finished_chunks(tmp_path, monkeypatch):
    from geardyn import sweep as S

    monkeypatch.setattr(S.executors, "DASK_CONNECT_TIMEOUT", 2)  # how long the client tries to reconnect
    c = Cluster(tmp_path)
    try:
        c.add_worker("only")
        c.wait_for_workers(1)
        ck = tmp_path / "ck"

        def kill_scheduler() -> None:
            t0 = time.monotonic()
            while not list(ck.glob("chunk-*.npz")) and time.monotonic() - t0 < START_TIMEOUT:
                time.sleep(0.01)
            c.procs["scheduler"].send_signal(signal.SIGKILL)

        th = threading.Thread(target=kill_scheduler)
        th.start()
        with pytest.raises(S.SweepFailed) as ei:
            F.sweep("omega", KILL_OMEGAS, SLOW, chunk_points=1, scheduler=c.address, checkpoint=ck)
        th.join()
    finally:
        c.close()
    e = ei.value
    assert str(e).startswith(f"sweep stopped: lost the Dask scheduler {c.address}") and "\n" not in str(e)
    assert "--resume" in str(e) and 1 <= e.finished < e.total == KILL_OMEGAS.size
    assert len(list(ck.glob("chunk-*.npz"))) == e.finished


def test_gearbox_response_on_the_cluster_equals_one_process(cluster, tmp_path):
    """A two-stage gearbox built from its geometry (shafts as beams, 120 states), its response over speed up
    and down: the Dask cluster's Dataset is the one of one process, every attribute included."""
    from test_gearbox import _file

    from geardyn import load_system
    from geardyn.analysis.response import frequency_response

    model = load_system(_file(tmp_path, z=(23, 40, 40, 56)))  # stage 2 at 40/40 of stage 1: forcing period 1
    opts = IntegrationOptions(dtau=0.05, transient=2, periods=2)
    kw = dict(options=opts, state0=model.initial_state(), lyapunov=False, settle_periods=0, progress=False)
    w = model.omega
    local = frequency_response(model, 0.9 * w, 1.1 * w, 3, workers=1, **kw)
    remote = frequency_response(model, 0.9 * w, 1.1 * w, 3, scheduler=cluster.address, **kw)
    assert np.isfinite(local["amplitude"].values).all()  # integrated, not diverged
    xr.testing.assert_identical(local, remote)
