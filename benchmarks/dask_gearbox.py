"""A gearbox's response over speed in one process and on a local 2-worker Dask cluster: same Dataset, wall times.

Runs the response over speed of ``geardyn response --system FILE --rpm-start A --rpm-stop B --num N`` (the
shipped two-stage helical gearbox, ``examples/gearbox/two_stage_helical.toml``, by default; 200 speeds), the
library call the command makes (:func:`geardyn.analysis.response.frequency_response`), twice in this process
running this checkout (``src`` first on ``sys.path``):

* ``local``: in one process (``workers=1``);
* ``dask``: ``scheduler=tcp://127.0.0.1:PORT``, the command's ``--scheduler``, on a cluster this script starts:
  a ``dask scheduler`` and two ``dask worker --nthreads 1`` processes on 127.0.0.1 (started, and waited for,
  before the timed run).

The two Datasets are compared with ``xarray.testing.assert_identical``.  Left out of the comparison, because
they legitimately differ between the runs, are the attributes listed in :data:`RUN_ATTRS` that are present
(the result records the sweep engine it ran on); every other attribute, every coordinate and every value must
be identical.  The response's up- and down-sweeps are two chains of state continuation (one chunk each): on
the cluster they run at the same time, one per worker, so the ideal ratio is 2.

Run: ``python benchmarks/dask_gearbox.py [--num 200] [--rpm-start 1000] [--rpm-stop 3000] [--dtau 0.05]
[--transient 1|auto] [--periods 1] [--settle 0] [--system FILE] [--order dask-first]``.  Writes
``benchmarks/results/dask_gearbox.json`` (both wall times, their ratio, the settings, the machine's load
average before and after, and which attributes were left out of the comparison).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
#: The checkout whose ``src`` runs, here and on the workers (``--src``).
SRC = ROOT / "src"
#: Attributes that differ between two runs of the same sweep (the command and the run's own record).
RUN_ATTRS = ("command", "created", "provenance", "elapsed_s", "wall_s", "run")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def env() -> dict[str, str]:
    e = dict(os.environ)
    e["PYTHONPATH"] = os.pathsep.join([str(SRC)] + [p for p in [e.get("PYTHONPATH")] if p])
    return e


class Cluster:
    """A Dask scheduler and two single-thread workers, each its own process."""

    def __init__(self, workdir: Path, workers: int = 2) -> None:
        self.port = free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.procs: list[subprocess.Popen] = []
        self.workdir = workdir
        self._start("scheduler", ["scheduler", "--host", "127.0.0.1", "--port", str(self.port), "--no-dashboard"])
        for i in range(workers):
            self._start(
                f"w{i + 1}",
                [
                    "worker",
                    self.address,
                    "--name",
                    f"w{i + 1}",
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                    "--host",
                    "127.0.0.1",
                    "--death-timeout",
                    "120",
                    "--local-directory",
                    str(workdir),
                ],
            )
        import distributed

        with distributed.Client(self.address, timeout=300, set_as_default=False) as c:
            c.wait_for_workers(workers, timeout=300)

    def _start(self, name: str, args: list[str]) -> None:
        log = open(self.workdir / f"{name}.log", "w")
        self.procs.append(
            subprocess.Popen(
                [sys.executable, "-m", "dask", *args],
                stdout=log,
                stderr=subprocess.STDOUT,
                env=env(),
                cwd=self.workdir,
                start_new_session=True,
            )
        )
        log.close()

    def close(self) -> None:
        import distributed

        try:
            with distributed.Client(self.address, timeout=10, set_as_default=False) as c:
                c.shutdown()
        except Exception:  # already gone: the processes are stopped below
            pass
        for p in self.procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def shown(path: str) -> str:
    """A path as the result shows it: relative to this checkout, else its name only (no machine paths)."""
    p = Path(path).resolve()
    return str(p.relative_to(ROOT)) if p.is_relative_to(ROOT) else f"(another copy) {p.name}"


def model_and_grid(a: argparse.Namespace):
    """The gearbox model, its ω grid from the rpm range and the integration options."""
    from geardyn import IntegrationOptions, load_system
    from geardyn.analysis.bifurcation import sweep_values
    from geardyn.systems.report import physical_scales

    model = load_system(a.system)
    sc = physical_scales(model)
    w0, w1 = float(sc.omega_from_rpm(a.rpm_start)), float(sc.omega_from_rpm(a.rpm_stop))
    if a.transient == "auto":
        from geardyn.analysis.settle import settle_periods

        tr = settle_periods(model, sweep_values(w0, w1, a.num)).periods
    else:
        tr = int(a.transient)
    return model, (w0, w1), IntegrationOptions(dtau=a.dtau, transient=tr, periods=a.periods)


def response(model, w, opts, a, **engine):
    from geardyn.analysis.response import frequency_response

    t0 = time.perf_counter()
    ds = frequency_response(
        model,
        w[0],
        w[1],
        a.num,
        options=opts,
        state0=model.initial_state(),
        lyapunov=False,
        settle_periods=a.settle,
        progress=False,
        **engine,
    )
    return ds, time.perf_counter() - t0


def compare(da, db) -> list[str]:
    """Assert the two Datasets identical but for :data:`RUN_ATTRS`; the names of those that were present."""
    import xarray as xr

    da, db = da.copy(), db.copy()
    dropped = sorted({k for k in RUN_ATTRS if k in da.attrs or k in db.attrs})
    for ds in (da, db):
        for k in RUN_ATTRS:
            ds.attrs.pop(k, None)
    xr.testing.assert_identical(da, db)
    return dropped


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--system", default="examples/gearbox/two_stage_helical.toml")
    ap.add_argument("--num", type=int, default=200)
    ap.add_argument("--rpm-start", type=float, default=1000.0)
    ap.add_argument("--rpm-stop", type=float, default=3000.0)
    ap.add_argument("--dtau", type=float, default=0.05)
    ap.add_argument("--transient", default="1")
    ap.add_argument("--periods", type=int, default=1)
    ap.add_argument("--settle", type=int, default=0, help="response --settle (0: classify without more periods)")
    ap.add_argument("--order", choices=("local-first", "dask-first"), default="local-first")
    ap.add_argument("--note", default="", help="a line stored with the result (what was run, and why)")
    ap.add_argument("--src", type=Path, default=None, help="the checkout's src directory to run (default: this one)")
    ap.add_argument("--out", type=Path, default=RESULTS / "dask_gearbox.json")
    a = ap.parse_args(argv)

    global SRC
    SRC = (a.src or SRC).resolve()
    sys.path.insert(0, str(SRC))
    model, w, opts = model_and_grid(a)
    warm = argparse.Namespace(**{**vars(a), "num": 2, "settle": 0})
    work = Path(tempfile.mkdtemp(prefix="dask_gearbox_"))
    load0 = os.getloadavg()
    try:
        cluster = Cluster(work)
        try:
            engines = {"local": {"workers": 1}, "dask": {"scheduler": cluster.address}}
            names = ["local", "dask"] if a.order == "local-first" else ["dask", "local"]
            ds, wall = {}, {}
            for n in names:  # untimed: the compiled kernels loaded here and on both workers
                response(model, w, opts.replace(transient=0, periods=1), warm, **engines[n])
            for n in names:
                ds[n], wall[n] = response(model, w, opts, a, **engines[n])
            dropped = compare(ds["local"], ds["dask"])
        finally:
            cluster.close()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    import numpy as np

    codes, counts = np.unique(np.asarray(ds["local"]["motion"].values).ravel(), return_counts=True)
    out = {
        "what": "geardyn response over rpm of a gearbox system: one process vs a local 2-worker Dask cluster",
        "system": shown(a.system),
        "src": str(SRC.relative_to(ROOT)) if SRC.is_relative_to(ROOT) else "another checkout (--src)",
        "num": a.num,
        "rpm": [a.rpm_start, a.rpm_stop],
        "omega": list(w),
        "options": {"dtau": opts.dtau, "transient": opts.transient, "periods": opts.periods, "settle": a.settle},
        "transient_given": a.transient,
        "command": (
            f"geardyn response --system {shown(a.system)} --rpm-start {a.rpm_start:g} --rpm-stop {a.rpm_stop:g} "
            f"--num {a.num} --dtau {a.dtau:g} --transient {opts.transient} --periods {a.periods} --settle {a.settle} "
            "[--scheduler tcp://127.0.0.1:PORT]"
        ),
        "order": a.order,
        "note": a.note,
        "wall_s": {n: round(w, 2) for n, w in wall.items()},
        "ratio_local_over_dask": round(wall["local"] / wall["dask"], 3),
        "identical": True,
        "attrs_left_out": dropped,
        "motion_counts_local": {str(k): int(c) for k, c in zip(codes, counts)},
        "loadavg_before": [round(x, 2) for x in load0],
        "loadavg_after": [round(x, 2) for x in os.getloadavg()],
        "cpus": os.cpu_count(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
    }
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
