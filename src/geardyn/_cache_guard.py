"""Keep numba's on-disk cache of a kernel package consistent with the package's sources.

numba keys a cached function on the source file it is defined in, so a worker compiled from
``lanes.py`` that inlines functions of ``core.py`` is not recompiled when only ``core.py``
changes.  :func:`refresh`, called by a kernel package before it imports its modules, hashes every
source file of the package and, when the hash differs from the one stamped next to the cache,
removes the package's cached machine code so that numba compiles it afresh.  An installed copy
never changes and pays only the hash (a few kilobytes read once per process).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

__all__ = ["STAMP", "fast_loads", "refresh"]

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
