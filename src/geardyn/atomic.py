"""Atomic file writes: a temporary file in the same folder, flushed to disk, renamed over the target.

Every file geardyn writes (NetCDF results, figures, reports, TOML sections, checkpoint chunks) goes
through :func:`atomic_write`, so a reader never sees a partial file and a failed or interrupted write
leaves nothing behind:

* the temporary file is ``.<name>.<random>.tmp`` beside the target; it is removed on any error, and
  every temporary file in progress is listed so that an interrupted process removes them as it leaves
  (:func:`discard_temporaries`); those of a process killed outright (``kill -9``) are removed by the
  next write of the same file (:func:`remove_stale`);
* an error is an :class:`OSError` naming the *target* file (never the temporary one) and the reason;
* content produced by a library that cannot fail cleanly on a full disk (HDF5, which may crash the
  process) is produced in memory first (:func:`write_netcdf_bytes`) and written by Python, which
  fails with ``ENOSPC``/``EFBIG`` like any write.
"""

from __future__ import annotations

import errno
import os
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["atomic_write", "atomic_write_bytes", "discard_temporaries", "remove_stale", "write_netcdf_bytes"]

_PENDING: set[str] = set()
_LOCK = threading.Lock()


def discard_temporaries() -> None:
    """Remove the temporary files of every write in progress (a process about to end mid-write)."""
    with _LOCK:
        pending = list(_PENDING)
        _PENDING.clear()
    for tmp in pending:
        _drop(tmp)


def remove_stale(path: str | Path) -> list[Path]:
    """Remove the temporary files left beside ``path`` by a process killed while writing it.

    Parameters
    ----------
    path : str or Path
        The target file.

    Returns
    -------
    list of Path
        The files removed.
    """
    import glob

    path = Path(path)
    removed = []
    try:
        candidates = list(path.parent.glob(f".{glob.escape(path.name)}.*.tmp"))
    except OSError:
        return removed
    with _LOCK:
        mine = set(_PENDING)
    for p in candidates:
        if str(p) in mine:
            continue
        try:
            p.unlink()
            removed.append(p)
        except OSError:
            pass
    return removed


def _temp_beside(path: Path) -> str:
    """A new temporary file next to ``path`` with the permissions a plain ``open`` would give."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with _LOCK:
        _PENDING.add(tmp)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    return tmp


def _fsync_dir(directory: Path) -> None:
    """Make a rename in ``directory`` durable (POSIX; a no-op where directories cannot be opened)."""
    try:
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path: str | Path, write: Callable[[str], Any]) -> Path:
    """Run ``write(tmp)`` on a temporary file beside ``path``, make it durable and rename it to ``path``.

    Parameters
    ----------
    path : str or Path
        The target file (its folder is created if missing).
    write : callable
        ``write(tmp)`` writes the whole content to the file named ``tmp``.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OSError
        Naming ``path`` (its ``filename``) and the reason, for any failure to write it; nothing is left.
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory, not a file", str(path))
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(path)
        tmp = _temp_beside(path)
        write(tmp)
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
        _fsync_dir(path.parent)
    except OSError as e:
        _drop(tmp)
        reason = e.strerror or (os.strerror(e.errno) if e.errno else str(e))
        raise type(e)(e.errno or errno.EIO, f"cannot write: {reason}", str(path)) from None
    except BaseException:
        _drop(tmp)
        raise
    finally:
        if tmp is not None:
            with _LOCK:
                _PENDING.discard(tmp)
    return path


def _drop(tmp: str | None) -> None:
    if tmp is None:
        return
    try:
        os.unlink(tmp)
    except OSError:
        pass


def atomic_write_bytes(path: str | Path, data: bytes | memoryview) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file in the same folder, fsync, rename).

    Parameters
    ----------
    path : str or Path
        The file (its folder is created if missing).
    data : bytes
        The content.

    Returns
    -------
    Path
        ``path``.
    """
    return atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))


def write_netcdf_bytes(fill: Callable[[Any], None]) -> memoryview:
    """The bytes of a NetCDF (HDF5) file produced in memory by ``fill(buffer)``.

    HDF5 crashes the process on some write errors of a full disk; in memory it cannot meet one.

    Parameters
    ----------
    fill : callable
        ``fill(buffer)`` writes the file into the binary buffer, e.g.
        ``ds.to_netcdf(buffer, engine="h5netcdf")``.

    Returns
    -------
    memoryview
        The file's bytes.
    """
    import io

    buf = io.BytesIO()
    fill(buf)
    return buf.getbuffer()
