"""Checkpoints of a sweep: each finished chunk written durably next to a manifest of the sweep.

A :class:`CheckpointStore` is a directory holding ``manifest.json`` (a fingerprint of the sweep
and its number of chunks) and one ``chunk-NNNNNN.npz`` per finished chunk.  Every file is written
through a temporary file, fsync, rename and an fsync of the directory
(:func:`geardyn.io.atomic_write_bytes`), so a process killed at any moment (even ``kill -9``)
leaves only complete chunk files, and a resumed sweep returns exactly the arrays of an
uninterrupted one.

Integrity: every chunk file carries the sweep's fingerprint, its own index and a SHA-256 checksum of
its arrays.  On resume a chunk that belongs to another sweep, sits under another index or does not
verify is reported in one line on stderr, removed and computed again; a manifest that cannot be read
is reported and the resume refused (running without ``--resume`` starts over); ``--resume`` with no
checkpoint says so and runs the whole sweep; temporary files left by a killed process (of the chunks
and of the final output) are removed.
"""

from __future__ import annotations

import hashlib
import io as _io
import json
import pickle
import queue
import sys
import threading
import zipfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic import remove_stale
from ..errors import SweepError
from ..io import atomic_write_bytes

__all__ = [
    "MANIFEST",
    "CheckpointStore",
    "active_checkpoints",
    "checkpoint_dir",
    "fingerprint",
    "prepare_checkpoint",
    "remove_checkpoint",
]

#: File name of the checkpoint manifest (fingerprint of the sweep and its number of chunks).
MANIFEST = "manifest.json"
#: Name of the entry of a chunk file holding its identity (sweep fingerprint, index, checksum).
CHUNK_META = "__geardyn_chunk__"

#: Fingerprint of the sweep of each checkpoint directory opened by this process (in the order opened).
_OPEN: dict[str, str] = {}


def active_checkpoints() -> list[Path]:
    """The checkpoint directories of the sweeps this process has opened and not removed."""
    return [Path(d) for d in _OPEN if Path(d, MANIFEST).exists()]


def report(message: str) -> None:
    """One line on stderr about the checkpoint (a chunk recomputed, nothing to resume ...)."""
    try:
        sys.stderr.write(" ".join(message.split()) + "\n")
        sys.stderr.flush()
    except (OSError, ValueError, AttributeError):
        pass


def checkpoint_dir(out_file: str | Path) -> Path:
    """The checkpoint directory used for the sweep whose final result goes to ``out_file``.

    ``results/bifurcation.nc`` → ``results/bifurcation.nc.chunks``: next to the output, so that
    ``--out`` alone decides where a resumable sweep keeps its finished chunks.

    Parameters
    ----------
    out_file : path
        The final NetCDF file of the sweep.

    Returns
    -------
    Path
    """
    p = Path(out_file)
    return p.with_name(p.name + ".chunks")


def remove_checkpoint(directory: str | Path) -> None:
    """Delete a checkpoint directory (after the final result has been written).

    Only the files a checkpoint consists of are removed; a directory holding anything else is left.

    Parameters
    ----------
    directory : path
        The checkpoint directory (missing: nothing to do).
    """
    d = Path(directory)
    _OPEN.pop(str(d), None)
    if not d.is_dir():
        return
    for p in d.iterdir():
        if p.name == MANIFEST or p.name.startswith(("chunk-", ".chunk-", f".{MANIFEST}")):
            p.unlink(missing_ok=True)
    try:
        d.rmdir()
    except OSError:  # something else lives there: leave it
        pass


def fingerprint(chunks: Sequence[Any]) -> str:
    """A hash identifying the work of a sweep (functions and arguments of all chunks).

    Parameters
    ----------
    chunks : sequence of Chunk

    Returns
    -------
    str
        SHA-256 hex digest.
    """
    h = hashlib.sha256()
    for c in chunks:
        h.update(f"{c.index}:{c.fn.__module__}.{c.fn.__qualname__}:".encode())
        h.update(_value_bytes(c.args))
    return h.hexdigest()


def _value_bytes(obj: Any) -> bytes:
    """A pickle of ``obj`` that depends on its value only.

    The pickle memo is off: with it, an object met twice is written once and then referenced, so
    equal arguments would pickle differently depending on whether two of their strings happen to
    be the same object (an interned ``"omega"`` from code, or an equal one from the command line).
    """
    buf = _io.BytesIO()
    p = pickle.Pickler(buf, protocol=4)
    p.fast = True
    p.dump(obj)
    return buf.getvalue()


def _chunk_path(directory: Path, index: int) -> Path:
    return directory / f"chunk-{index:06d}.npz"


def checksum(result: dict[str, np.ndarray]) -> str:
    """SHA-256 of a chunk's arrays (names, dtypes, shapes and bytes, in name order)."""
    h = hashlib.sha256()
    for k in sorted(result):
        a = np.ascontiguousarray(result[k])
        h.update(f"{k}:{a.dtype.str}:{a.shape}:".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _save_chunk(directory: Path, index: int, result: dict[str, np.ndarray]) -> None:
    meta = {"fingerprint": _OPEN.get(str(directory), ""), "index": int(index), "checksum": checksum(result)}
    buf = _io.BytesIO()
    np.savez(buf, **result, **{CHUNK_META: np.array(json.dumps(meta))})
    atomic_write_bytes(_chunk_path(directory, index), buf.getbuffer())


def _load_chunk(directory: Path, index: int) -> dict[str, np.ndarray] | None:
    """A finished chunk, or None if it is missing, unreadable, of another sweep or index, or does not verify
    (reported in one line, removed, and then run again)."""
    p = _chunk_path(directory, index)
    if not p.exists():
        return None
    why = None
    try:
        with np.load(p, allow_pickle=False) as z:
            out = {k: z[k] for k in z.files}
        meta = json.loads(str(out.pop(CHUNK_META))) if CHUNK_META in out else None
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, RuntimeError) as e:
        why = f"unreadable ({type(e).__name__})"
        meta = out = None
    if why is None:
        fp = _OPEN.get(str(directory))
        if not isinstance(meta, dict):
            why = "it carries no sweep fingerprint"
        elif fp is not None and meta.get("fingerprint") != fp:
            why = "it belongs to another sweep"
        elif meta.get("index") != index:
            why = f"it is chunk {meta.get('index')!r} of its sweep"
        elif meta.get("checksum") != checksum(out):
            why = "its checksum does not verify"
    if why is not None:
        report(f"checkpoint: {p.name} in {directory} is not used ({why}); chunk {index} is computed again")
        p.unlink(missing_ok=True)
        return None
    return out


def _clear_temporaries(directory: Path) -> None:
    """Remove temporary files left by a process killed in the middle of a write."""
    for p in directory.glob(".*.tmp"):
        p.unlink(missing_ok=True)


def prepare_checkpoint(directory: Path, chunks: Sequence[Any], resume: bool) -> set[int]:
    """Create or check the checkpoint directory; returns the indices of chunks already finished.

    Without ``resume`` any previous content is discarded.  With ``resume`` the manifest must
    hold the fingerprint of the same sweep (same chunk functions and arguments).

    Parameters
    ----------
    directory : Path
        The checkpoint directory (created if missing).
    chunks : sequence of Chunk
        The whole sweep.
    resume : bool
        Keep the chunks of a previous run of the same sweep.

    Returns
    -------
    set of int
        Indices of the chunks whose files exist (they may still be unreadable; see
        :meth:`CheckpointStore.open`).

    Raises
    ------
    SweepError
        When the directory cannot be created, the path is not a directory, or (with ``resume``)
        the checkpoint holds a different sweep.
    """
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise SweepError(f"out: cannot create checkpoint directory {directory} ({e.strerror or e})") from None
    if not directory.is_dir():
        raise SweepError(f"out: checkpoint path {directory} exists and is not a directory")
    fp = fingerprint(chunks)
    man = directory / MANIFEST
    _clear_temporaries(directory)
    if directory.name.endswith(".chunks"):  # temporaries of the final output left by a killed process
        remove_stale(directory.with_name(directory.name[: -len(".chunks")]))
    old: dict[str, Any] = {}
    if man.exists():
        try:
            old = json.loads(man.read_text(encoding="utf-8"))
            if not isinstance(old, dict) or not isinstance(old.get("fingerprint"), str):
                raise ValueError("not a checkpoint manifest")
        except (OSError, ValueError, UnicodeDecodeError, RecursionError) as e:
            if resume:
                raise SweepError(
                    f"resume: the checkpoint manifest {man} cannot be read ({type(e).__name__}); its chunks cannot "
                    "be trusted: run without --resume to start over"
                ) from None
            old = {}
    elif resume:
        has_chunks = any(directory.glob("chunk-*.npz"))
        report(
            f"resume: nothing to resume in {directory} (no checkpoint manifest"
            + ("; its chunk files are not trusted" if has_chunks else "")
            + "); the whole sweep is run"
        )
    if resume and old and old.get("fingerprint") != fp:
        raise SweepError(
            f"resume: checkpoint {directory} holds a different sweep (parameters, options or chunk size differ); "
            "run without --resume to start over, or use another --out"
        )
    _OPEN[str(directory)] = fp
    if not resume or not old:
        for p in directory.glob("chunk-*.npz"):  # a fresh start, or chunks without a manifest: not trusted
            p.unlink(missing_ok=True)
        _clear_temporaries(directory)
        atomic_write_bytes(man, json.dumps({"fingerprint": fp, "chunks": len(chunks)}).encode())
        return set()
    done = {c.index for c in chunks if _chunk_path(directory, c.index).exists()}
    if not done:
        report(f"resume: no finished chunk in {directory}; the whole sweep is run")
    return done


class CheckpointStore:
    """A checkpoint directory: finished chunks saved durably as they complete, loaded on resume.

    Parameters
    ----------
    directory : path
        Where the manifest and the chunk files live (see :func:`checkpoint_dir`).
    resume : bool
        Keep (and load) the chunks of a previous run of the same sweep; without it any previous
        content is discarded when the sweep opens the store.
    """

    def __init__(self, directory: str | Path, *, resume: bool = False) -> None:
        self.directory = Path(directory)
        self.resume = bool(resume)
        self._queue: queue.Queue | None = None
        self._thread: threading.Thread | None = None
        self._error: BaseException | None = None

    def __repr__(self) -> str:
        return f"CheckpointStore({str(self.directory)!r}, resume={self.resume})"

    def open(self, chunks: Sequence[Any]) -> dict[int, dict[str, np.ndarray]]:
        """Prepare the directory for ``chunks`` and return the finished chunks it holds.

        Parameters
        ----------
        chunks : sequence of Chunk
            The whole sweep.

        Returns
        -------
        dict
            Chunk index → result of every readable finished chunk (empty without ``resume``).

        Raises
        ------
        SweepError
            See :func:`prepare_checkpoint`.
        """
        return dict(self.finished(chunks))

    def finished(self, chunks: Sequence[Any]) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        """:meth:`open`, one finished chunk at a time: (index, result) of each readable one, in index order."""
        for i in sorted(prepare_checkpoint(self.directory, chunks, self.resume)):
            r = _load_chunk(self.directory, i)
            if r is not None:
                yield i, r

    def save(self, index: int, result: dict[str, np.ndarray]) -> None:
        """Write one finished chunk durably.

        Parameters
        ----------
        index : int
            The chunk's index.
        result : dict of ndarray
            Its result (plain arrays).
        """
        _save_chunk(self.directory, index, result)

    def save_later(self, index: int, result: dict[str, np.ndarray]) -> None:
        """Queue one finished chunk for a durable write by the store's writer thread.

        The write (and its two fsyncs, which can take longer than a short chunk's integration on
        a slow disk) then overlaps the next chunks; :meth:`flush` waits for every queued write.  A
        process killed meanwhile loses the queued chunks, as it loses the chunks in flight.

        Parameters
        ----------
        index : int
            The chunk's index.
        result : dict of ndarray
            Its result (plain arrays; not modified afterwards).
        """
        if self._thread is None:
            self._queue = queue.Queue()
            self._thread = threading.Thread(target=self._write_queued, name="geardyn-checkpoint", daemon=True)
            self._thread.start()
        self._queue.put((index, result))

    def _write_queued(self) -> None:
        while (item := self._queue.get()) is not None:
            try:
                if self._error is None:
                    self.save(*item)
            except BaseException as e:  # reported by flush()
                self._error = e

    def flush(self) -> None:
        """Wait until every chunk queued by :meth:`save_later` is written; stop the writer thread.

        Raises
        ------
        OSError
            The first error of a queued write.
        """
        if self._thread is None:
            return
        self._queue.put(None)
        self._thread.join()
        self._thread = None
        self._queue = None
        err, self._error = self._error, None
        if err is not None:
            raise err

    def remove(self) -> None:
        """Delete the checkpoint (see :func:`remove_checkpoint`)."""
        remove_checkpoint(self.directory)
