"""Keep numba's on-disk cache of a kernel package consistent with the package's sources.

numba keys a cached function on the source file it is defined in, so a worker compiled from
``lanes.py`` that inlines functions of ``core.py`` is not recompiled when only ``core.py``
changes.  :func:`refresh`, called by a kernel package before it imports its modules, hashes every
source file of the package and, when the hash differs from the one stamped next to the cache,
removes the package's cached machine code so that numba compiles it afresh.  An installed copy
never changes and pays only the hash (a few kilobytes read once per process).  :func:`fast_loads` also makes
each kernel's cache saves take a file lock (:func:`locked_saves`), so that processes compiling at once cannot
give two specializations the same cache file.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

__all__ = ["STAMP", "fast_loads", "locked_saves", "refresh"]

#: Name of the stamp file (in the package's ``__pycache__``) holding the hash of its sources.
STAMP = "geardyn-sources.sha256"


def refresh(package_file: str) -> bool:
    """Remove the stale numba cache of the package whose ``__init__`` is ``package_file``.

    Parameters
    ----------
    package_file : str
        ``__file__`` of the kernel package's ``__init__``.

    Returns
    -------
    bool
        True when cached code was found stale and removed.  Nothing is done (False) where numba
        keeps its cache elsewhere (``NUMBA_CACHE_DIR``) or the directory cannot be written.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return False
    pkg = Path(package_file).resolve().parent
    h = hashlib.sha256()
    for src in sorted(pkg.glob("*.py")):
        h.update(src.name.encode())
        h.update(src.read_bytes())
    digest = h.hexdigest()
    cache = pkg / "__pycache__"
    stamp = cache / STAMP
    try:
        if stamp.read_text() == digest:
            return False
    except OSError:
        pass
    removed = False
    try:
        for f in list(cache.glob("*.nbi")) + list(cache.glob("*.nbc")):
            try:
                f.unlink()
                removed = True
            except FileNotFoundError:
                pass
        cache.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # a read-only install: numba caches in the user's directory, keyed as before
        return False
    return removed


def fast_loads(*workers: object) -> None:
    """Let each numba dispatcher of ``workers`` load its compiled code from the cache without setting up
    numba's compiler first.

    Before reading a cached function, numba sets up its typing and lowering registries (imports a few
    hundred of its modules and, through them, ``scipy.linalg``: about half of a short command's time), which
    only compiling needs.  A worker's cached machine code (its callees linked in) is read and linked with
    numba's runtime started, nothing else; the same code runs, so the results are the same bits.  A worker
    that is not in the cache is compiled as before (numba's compiler sets itself up then), and any error
    of this load falls back to numba's own.  Other dispatchers, a user's own among them, are not touched.

    Parameters
    ----------
    *workers : numba dispatcher
        The kernel's entry points (those called from Python).  A second call for one is a no-op.
    """
    for worker in workers:
        cache = getattr(worker, "_cache", None)
        full = getattr(cache, "load_overload", None)
        if full is None or getattr(full, "fast", False) or not hasattr(cache, "_load_overload"):
            continue

        def load_overload(sig, target_context, cache=cache, full=full):  # type: ignore[no-untyped-def]
            try:
                from numba.core.runtime import rtsys

                rtsys.initialize(target_context)
                with cache._guard_against_spurious_io_errors():
                    return cache._load_overload(sig, target_context)
            except Exception:  # noqa: BLE001  (numba's own load, as if this had not been tried)
                return full(sig, target_context)

        load_overload.fast = True  # type: ignore[attr-defined]
        cache.load_overload = load_overload
        locked_saves(getattr(cache, "_cache_file", None))


def locked_saves(cache_file: object) -> None:
    """Make a numba cache file's ``save`` hold an exclusive lock on ``<index>.lock`` (POSIX ``flock``).

    numba's ``save`` reads the index, takes the first data-file number it does not list and writes both: two
    processes adding different specializations of one function at once (two sweep workers of a fresh install,
    test workers) can take the same number, and the index then names a file holding the other's machine code.
    Under the lock one save completes before the next reads the index.  Where no lock can be taken (no
    ``fcntl``, a read-only cache) the save runs as numba's own.

    Parameters
    ----------
    cache_file : numba.core.caching.IndexDataCacheFile or None
        A dispatcher's ``_cache._cache_file``; None or one already locked is left alone.
    """
    save = getattr(cache_file, "save", None)
    index = getattr(cache_file, "_index_path", None)
    if save is None or index is None or getattr(save, "locked", False):
        return

    def locked(key, data, save=save, lock=str(index) + ".lock"):  # type: ignore[no-untyped-def]
        try:
            import fcntl

            fh = open(lock, "a")
        except (ImportError, OSError):
            return save(key, data)
        with fh:
            fcntl.flock(fh, fcntl.LOCK_EX)
            try:
                return save(key, data)
            finally:
                fcntl.flock(fh, fcntl.LOCK_UN)

    locked.locked = True  # type: ignore[attr-defined]
    cache_file.save = locked  # type: ignore[attr-defined]
