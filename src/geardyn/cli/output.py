"""Where a command's ``--out`` goes (its NetCDF file, figures and a sweep's checkpoint), and the output of
a result too large to hold twice: its NetCDF file written releasing its variables, then its figures
drawn from the file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["TIME_BUDGET", "check_budget", "check_out", "engine_keywords", "out_paths", "write_released"]

#: Estimated computing time a command may take (s), unless the environment variable
#: ``GEARDYN_TIME_BUDGET`` gives another number of seconds: 1 hour.
TIME_BUDGET = 3600.0
#: Estimated kernel time of one RK4 step: a single trajectory (simulate, lyapunov: one point, with its
#: recording) and a sweep point (SIMD lanes, per thread; ``geardyn.sweep.STEP_SECONDS``).
TRAJECTORY_STEP_SECONDS = 1.0e-7
#: Estimated time of one RK4 step of a system per degree of freedom, trajectory or sweep point (per thread), on
#: the 110-DOF two-stage gearbox: its default ``simulate`` took 436 s of CPU for 46.7e6 steps (0.85e-7 s a DOF),
#: a 400-point response 435 s on 2 threads for 5.4e7 steps (1.5e-7 s a DOF, on a loaded machine).
SYSTEM_STEP_SECONDS_PER_DOF = 1.2e-7
#: Memory a recorded forcing period takes: of a single trajectory (its statistics and history, measured
#: about 620 bytes) and of a sweep point (its Poincaré point), and a sweep point's fixed share (bytes).
TRAJECTORY_PERIOD_BYTES = 1024
SWEEP_PERIOD_BYTES = 16
SWEEP_POINT_BYTES = 1024


def time_budget() -> float:
    """The time budget in seconds (:data:`TIME_BUDGET`, or ``GEARDYN_TIME_BUDGET``)."""
    import math
    import os

    try:
        t = float(os.environ.get("GEARDYN_TIME_BUDGET", TIME_BUDGET))
    except ValueError:
        return TIME_BUDGET
    return t if math.isfinite(t) and t > 0 else TIME_BUDGET


def memory_budget() -> float:
    """Half of this machine's physical memory (bytes; 8 GB where it cannot be read)."""
    import os

    try:
        return 0.5 * os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 8e9


def _human_time(s: float) -> str:
    return f"{s:.3g} s" if s < 120 else f"{s / 60:.3g} min" if s < 7200 else f"{s / 3600:.3g} h"


def check_budget(opts: Any, omegas: Any, points: int, *, cycles: int = 1, dofs: int = 1) -> None:
    """Refuse, before computing, a run whose estimated memory or computing time exceeds the budgets
    (:func:`memory_budget`, :func:`time_budget`); the message gives the estimate.

    Parameters
    ----------
    opts : IntegrationOptions
        Step, transient and recorded periods.
    omegas : sequence of float
        The forcing frequencies of the points (the steps per period follow from them); none: no time check.
    points : int
        Points of the run (1: a single trajectory).
    cycles : int
        Mesh cycles of the forcing period (the transient and recorded periods count forcing periods).
    dofs : int
        Degrees of freedom: 1 the pair (its compiled point kernels), more a system's N-DOF kernel.

    Raises
    ------
    ModelError
        Naming the options, the estimate and the budget.
    """
    import math

    import numpy as np

    from ..errors import ModelError

    points = max(1, int(points))
    pe, tr = int(opts.periods), int(opts.transient)
    if points == 1:
        need = pe * TRAJECTORY_PERIOD_BYTES
    else:
        need = points * (pe * SWEEP_PERIOD_BYTES + SWEEP_POINT_BYTES)
    have = memory_budget()
    if need > have:
        raise ModelError(
            f"periods: {points} point(s) × {pe} recorded periods need about {need / 1e9:.3g} GB of memory; "
            f"at most {have / 1e9:.3g} GB (half this machine's memory): fewer points or --periods"
        )
    ws = np.asarray(omegas, dtype=float).ravel()
    ws = ws[np.isfinite(ws) & (ws > 0)]
    if not ws.size:
        return
    steps = float(np.mean(np.ceil(max(1, int(cycles)) * 2.0 * math.pi / ws / opts.dtau)))
    total = steps * (tr + pe) * points
    threads = 1
    if points > 1:  # a single trajectory runs on one thread: no need to import numba here
        import numba

        threads = max(1, int(numba.config.NUMBA_NUM_THREADS))
    if dofs > 1:
        step_s = SYSTEM_STEP_SECONDS_PER_DOF * dofs
    elif points == 1:
        step_s = TRAJECTORY_STEP_SECONDS
    else:
        from ..sweep import STEP_SECONDS

        step_s = STEP_SECONDS
    seconds = total * step_s / threads
    budget = time_budget()
    if seconds > budget:
        per = "forcing period" if cycles > 1 else "period"
        raise ModelError(
            f"periods: {points} point(s) × ({tr} transient + {pe} recorded periods) × {steps:.3g} steps per {per}"
            f"{f' ({dofs} DOF)' if dofs > 1 else ''} = {total:.3g} RK4 steps, about {_human_time(seconds)} of "
            f"computing; the budget is {_human_time(budget)} (GEARDYN_TIME_BUDGET seconds): fewer points or "
            f"periods, or a larger --dtau"
        )


def check_out(out: Any, option: str = "out", *, file_suffixes: tuple[str, ...] = (".nc",)) -> Path:
    """Refuse an output path that cannot be written before anything is computed.

    ``out`` names a file when its suffix is one of ``file_suffixes`` (any case), else a directory.
    Refused: an empty name; a file name that is an existing directory; a directory name that is an
    existing file; a folder that cannot be created or written.

    Parameters
    ----------
    out : str or Path
        The value of the option.
    option : str
        The option's name, for the message.
    file_suffixes : tuple of str
        Suffixes (lower case) that make ``out`` a file name.

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    ModelError
        One line naming the option, the path and what is wrong.
    """
    import os

    from ..errors import ModelError

    text = str(out) if out is not None else ""
    if not text.strip():
        raise ModelError(f"{option}: empty; give a directory or a file name")
    if "\0" in text:
        raise ModelError(f"{option}: the path contains a NUL character")
    out = Path(text)
    is_file = out.suffix.lower() in file_suffixes
    try:
        if is_file and out.is_dir():
            raise ModelError(
                f"{option}: {out} is a directory; give a file name ({'/'.join(file_suffixes)}) or a "
                f"directory name without that suffix"
            )
        if not is_file and out.exists() and not out.is_dir():
            raise ModelError(f"{option}: {out} exists and is not a directory")
        folder = out.parent if is_file else out
        probe = folder
        while not probe.exists() and probe != probe.parent:
            probe = probe.parent
        if probe.exists() and not probe.is_dir():
            raise ModelError(f"{option}: cannot create {folder}: {probe} is a file")
        if probe.exists() and not os.access(probe, os.W_OK | os.X_OK):
            raise ModelError(f"{option}: cannot write in {probe} (permission denied)")
    except OSError as e:  # a name too long, a loop of links ...
        raise ModelError(f"{option}: cannot use {text[:200]!r} ({e.strerror or e})") from None
    return out


def out_paths(out: Path, stem: str) -> tuple[Path, Path]:
    """(NetCDF file, figure directory) for ``--out``: a directory, or a file name ending in .nc (any case).

    Parameters
    ----------
    out : Path
        The value of ``--out``.
    stem : str
        File stem of the NetCDF file inside a directory (``<out>/<stem>.nc``).

    Returns
    -------
    nc, figures : Path
        The NetCDF file and the directory the figures go to.
    """
    out = Path(out)
    if out.suffix.lower() == ".nc":
        return out, out.parent
    return out / f"{stem}.nc", out


def engine_keywords(values: dict[str, Any], stem: str) -> dict[str, Any]:
    """Validated keyword arguments of :func:`geardyn.sweep.run_chunks` from a command's sweep-engine options.

    With ``--out`` the finished chunks are checkpointed next to the NetCDF file (``<nc>.chunks``).  The
    progress bar goes to stderr unless ``--json``.  An engine option the command does not have takes
    its default.

    Parameters
    ----------
    values : dict
        The command's option values (``out``, ``workers``, ``processes``, ``scheduler``, ``resume``,
        ``json_out``).
    stem : str
        File stem of the NetCDF file (its checkpoint directory is named after it).

    Returns
    -------
    dict
        ``workers``, ``processes``, ``scheduler``, ``checkpoint``, ``resume`` and ``progress``.

    Raises
    ------
    ModelError
        For an invalid engine option, or ``--resume`` without ``--out``.
    """
    from .. import validate
    from ..errors import ModelError
    from ..sweep import checkpoint_dir

    out = values.get("out")
    nc = out_paths(Path(out), stem)[0] if out is not None else None
    if values.get("resume") and nc is None:
        raise ModelError("resume: needs --out (a resumable sweep keeps its finished chunks next to its output)")
    scheduler = validate.scheduler(values.get("scheduler"))
    if scheduler is not None:
        probe_scheduler(scheduler)
    return {
        "workers": validate.workers(values.get("workers", 1)),
        "processes": bool(values.get("processes", False)),
        "scheduler": scheduler,
        "checkpoint": checkpoint_dir(nc) if nc is not None else None,
        "resume": bool(values.get("resume", False)),
        "progress": not values.get("json_out"),
    }


#: Seconds a Dask scheduler is given to accept a connection and send its handshake.
HANDSHAKE_TIMEOUT = 5.0


def probe_scheduler(address: str, timeout: float = HANDSHAKE_TIMEOUT) -> None:
    """Check that a ``tcp://`` address is a Dask scheduler before a sweep relies on it.

    A Dask server sends its handshake (an 8-byte length, then msgpack frames naming its ``compression``
    and ``pickle-protocol``) as soon as it accepts a connection; an endpoint that refuses, stays
    silent for ``timeout`` seconds or sends anything else is refused in one line.  Other schemes (TLS,
    in-process) are left to Dask.

    Parameters
    ----------
    address : str
        ``tcp://HOST:PORT`` (port 8786 when not given).
    timeout : float
        Seconds for the connection and the handshake.

    Raises
    ------
    SweepError
        Naming the address and what was found there.
    """
    import socket
    import struct
    import time

    from ..errors import SweepError
    from ..validate import _SCHEDULER

    m = _SCHEDULER.match(address)
    if m is None or (m.group(1) or "tcp") != "tcp":
        return
    host, port_n = m.group(2).strip("[]"), int(m.group(3) or 8786)
    deadline = time.monotonic() + timeout

    def receive(sock: socket.socket, n: int) -> bytes:
        data = b""
        while len(data) < n:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError
            sock.settimeout(left)
            part = sock.recv(n - len(data))
            if not part:
                break
            data += part
        return data

    try:
        with socket.create_connection((host, port_n), timeout=timeout) as sock:
            head = receive(sock, 8)
            size = struct.unpack("<Q", head)[0] if len(head) == 8 else 0
            body = receive(sock, size) if 0 < size <= 1_000_000 else b""
    except TimeoutError:
        raise SweepError(f"scheduler: {address} did not answer as a Dask scheduler within {timeout:g} s") from None
    except (OSError, ValueError, OverflowError) as e:
        raise SweepError(f"scheduler: cannot connect to {address} ({getattr(e, 'strerror', None) or e})") from None
    if b"pickle-protocol" not in body and b"compression" not in body:
        raise SweepError(f"scheduler: {address} is not a Dask scheduler (it answered something else)")


def write_released(ds: Any, nc: Path, figdir: Path, fmt: Any = ("png",), dpi: int = 120) -> list[str]:
    """The NetCDF file of ``ds`` written releasing its variables (:func:`_write_releasing`), then its
    figures drawn from the file (:func:`_figures_from_file`); the files written.

    What the computation left is collected and given back first.  What is held then is frozen out of
    the garbage collector meanwhile, so that the collections before each figure walk only what the
    output made (a full collection after a sweep walks about 170 000 objects: 0.1 s each).

    Parameters
    ----------
    ds : xarray.Dataset
        The result; its data variables are dropped as they are written.
    nc : Path
        The NetCDF file.
    figdir : Path
        Where the figures go.
    fmt : sequence of str
        Their file formats (:func:`geardyn.validate.figure_formats`).
    dpi : int
        Their resolution.

    Returns
    -------
    list of str
        The NetCDF file, then the figures.
    """
    import gc

    from ..sweep.executors import release_free_memory

    gc.collect()  # what the sweep left is given back before the writer's own buffers come in
    release_free_memory()
    frozen_before = gc.get_freeze_count()
    gc.freeze()
    try:
        return [str(_write_releasing(ds, nc)), *_figures_from_file(nc, figdir, fmt, dpi)]
    finally:
        if not frozen_before:  # (what a caller froze is unfrozen by that caller)
            gc.unfreeze()


def _write_releasing(ds: Any, nc: Path) -> Path:
    """:func:`geardyn.io.write_netcdf` one variable at a time, each dropped from ``ds`` once written.

    The coordinates and attributes go first, then each data variable is added (variables
    computed when read, e.g. :func:`geardyn.analysis.physical.add_physical` with ``lazy``, are
    computed then), so that the file is written without holding a copy of the result; it reads
    back as the Dataset ``write_netcdf`` writes.  Atomic as ``write_netcdf`` (produced in memory, then
    written: a full disk is an :class:`OSError` naming the file).
    """
    from ..atomic import atomic_write_bytes, write_netcdf_bytes
    from ..io import annotate

    annotate(ds)
    names = list(ds.data_vars)

    def write(buf: Any) -> None:
        from xarray.backends import H5NetCDFStore

        # One open file, in memory (HDF5 never meets a full disk; the variables move from ds into it).
        # Written from this thread alone, so without xarray's write lock, whose look-up of a Dask
        # scheduler imports Dask (where installed) for nothing.
        store = H5NetCDFStore.open(buf, mode="w", lock=False)
        try:
            ds.drop_vars(names).dump_to_store(store)
            for name in names:
                ds[[name]].drop_vars(list(ds.coords)).dump_to_store(store)
                del ds[name]
        finally:
            store.close()

    return atomic_write_bytes(nc, write_netcdf_bytes(write))


def _figures_from_file(nc: Path, figdir: Path, fmt: Any = ("png",), dpi: int = 120) -> list[str]:
    """The figures of the result in ``nc``, drawn from the file opened lazily (each loads what it draws).

    Memory freed before a figure is given back first (reference cycles collected; free heap pages
    returned to the system where glibc is used), so that each figure starts from what is held.
    """
    import gc

    import xarray as xr

    from ..plot import figures_for
    from ..plot.common import save
    from ..sweep.executors import release_free_memory

    files = []
    with xr.open_dataset(nc, engine="h5netcdf", cache=False) as ds:  # nothing kept once drawn
        for spec in figures_for(ds):
            gc.collect()
            release_free_memory()
            art = spec(ds)
            files += [str(save(art, figdir / f"{spec.stem}.{f}", dpi=dpi)) for f in fmt]
    gc.collect()
    return files
