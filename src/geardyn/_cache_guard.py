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

__all__ = ["STAMP", "refresh"]

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
