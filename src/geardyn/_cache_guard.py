"""numba's on-disk cache of geardyn's kernels: keyed on their sources, kept where it can be written, and announced.

**Keyed on the sources.**  numba keys a cached function on the modification time of the file it is defined in,
so a worker compiled from ``lanes.py`` that inlines functions of ``core.py`` would not be recompiled when only
``core.py`` changes, and a copy of the package (an install) would never find the code compiled for it.
:func:`install` puts :class:`PackageCacheLocator` in front of numba's own locators for every function defined
in geardyn: its source stamp is the SHA-256 of every source file of the function's directory, so a change to
any of them makes numba compile afresh (a stale index is ignored and its data files overwritten), and code
compiled for one copy of the sources is valid for any byte-identical copy.  That is what lets ``pip install``
compile the kernels once, at install time (``setup.py``: the wheel ships the cache; :mod:`geardyn._precompile`).

**Kept where it can be written.**  The cache lives in the ``__pycache__`` beside the sources.  Where that cannot
be written (a package installed read-only, in a user's site-packages), it lives under the user's cache home
(``$XDG_CACHE_HOME/geardyn/numba``, ``~/.cache/geardyn/numba``), seeded from the cache shipped with the
package; numba's ``NUMBA_CACHE_DIR`` still takes precedence.  A cache that can be kept nowhere costs a compile,
never a failure.

**Announced.**  A compile of a geardyn function (the cache missed) is reported to the callbacks of
:func:`on_compile` ("compiling the integrator, first run only": progress bars print it), and
:func:`compile_seconds` counts the time spent compiling, which progress ETAs leave out.
"""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import threading
import time
from collections.abc import Callable
from pathlib import Path

__all__ = ["compile_seconds", "fast_loads", "install", "on_compile", "refresh", "user_cache_root"]

#: The geardyn package directory: functions defined below it use :class:`PackageCacheLocator`.
ROOT = Path(__file__).resolve().parent

#: What is being compiled, by the module prefix of the function (the first match names it).
WHAT = (
    ("geardyn._kernel_ndof", "the N-DOF integrator"),
    ("geardyn._kernel", "the integrator"),
    ("geardyn.analysis.hb", "the harmonic-balance kernels"),
    ("geardyn", "geardyn's kernels"),
)

_lock = threading.RLock()
_installed = False
_callbacks: list[Callable[[str], None]] = []
_depth = 0
_t_start = 0.0
_total = 0.0


@functools.cache
def _digest(directory: str) -> str:
    """SHA-256 of the names and contents of the ``*.py`` files of ``directory`` (once per process)."""
    h = hashlib.sha256()
    for src in sorted(Path(directory).glob("*.py")):
        h.update(src.name.encode())
        h.update(src.read_bytes())
    return h.hexdigest()


def _writable(directory: Path) -> bool:
    """Whether ``directory`` (or, if it does not exist yet, its parent) can be written."""
    target = directory if directory.exists() else directory.parent
    return os.access(target, os.W_OK | os.X_OK)


def user_cache_root() -> Path:
    """The user's cache directory for a copy of geardyn installed where it cannot write.

    Returns
    -------
    pathlib.Path
        ``$XDG_CACHE_HOME/geardyn/numba/<tag>`` (``~/.cache`` without it), ``tag`` naming this copy of the
        package, so that two installs never share compiled code.

    Examples
    --------
    >>> user_cache_root().parts[-3:-1]
    ('geardyn', 'numba')
    """
    home = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    tag = hashlib.sha1(str(ROOT).encode()).hexdigest()[:12]
    return Path(home) / "geardyn" / "numba" / tag


def _seed(shipped: Path, target: Path) -> None:
    """Copy the cache shipped with the package into ``target`` once (files it already has are kept)."""
    try:
        target.mkdir(parents=True, exist_ok=True)
        for f in list(shipped.glob("*.nbi")) + list(shipped.glob("*.nbc")):
            dest = target / f.name
            if not dest.exists():
                shutil.copyfile(f, dest)
    except OSError:
        pass


def _locator_class():
    from numba.core import caching

    class PackageCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
        """numba's locator for a function defined in geardyn: stamped by its directory's sources."""

        def __init__(self, py_func, py_file):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            here = Path(py_file).resolve().parent
            shipped = here / "__pycache__"
            if _writable(shipped):
                self._cache_path = str(shipped)
            else:
                target = user_cache_root() / here.relative_to(ROOT)
                _seed(shipped, target)
                self._cache_path = str(target)

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):
            return _digest(str(Path(self._py_file).resolve().parent))

        @classmethod
        def from_function(cls, py_func, py_file):
            try:
                Path(py_file).resolve().relative_to(ROOT)
            except (ValueError, OSError):
                return None
            if not os.path.exists(py_file):
                return None
            self = cls(py_func, py_file)
            try:
                self.ensure_cache_path()
            except OSError:
                return None
            return self

    return PackageCacheLocator


def _what(module: str) -> str | None:
    for prefix, what in WHAT:
        if module == prefix or module.startswith(prefix + "."):
            return what
    return None


def _watcher():
    from numba.core import event

    class CompileWatch(event.Listener):
        """Counts the time numba spends compiling geardyn's functions and announces the first of a batch."""

        def on_start(self, ev):
            global _depth, _t_start
            disp = (ev.data or {}).get("dispatcher")
            what = _what(getattr(getattr(disp, "py_func", None), "__module__", "") or "")
            with _lock:
                _depth += 1
                if _depth > 1:
                    return
                _t_start = time.monotonic()
                callbacks = list(_callbacks)
            if what is not None:
                for cb in callbacks:
                    try:
                        cb(what)
                    except Exception:  # noqa: BLE001  (an announcement is not worth failing for)
                        pass

        def on_end(self, ev):
            global _depth, _total
            with _lock:
                _depth = max(0, _depth - 1)
                if _depth == 0:
                    _total += time.monotonic() - _t_start

    return CompileWatch()


def install() -> None:
    """Key numba's cache of geardyn's functions on their sources, and watch their compiles (once per process).

    Called by every module that defines cached numba functions, before it defines them.  Where numba's cache
    is kept elsewhere (``NUMBA_CACHE_DIR``) numba's own locator is used.

    Examples
    --------
    >>> install()  # a second call does nothing
    >>> install()
    """
    global _installed
    with _lock:
        if _installed:
            return
        from numba.core import caching, event

        locators = caching.CacheImpl._locator_classes
        # after numba's NUMBA_CACHE_DIR locator, in front of its in-tree one
        pos = 1 if locators and locators[0] is caching.UserProvidedCacheLocator else 0
        locators.insert(pos, _locator_class())
        event.register("numba:compile", _watcher())
        _installed = True


def refresh(package_file: str) -> None:
    """Make the cache of a kernel package follow all its sources (:func:`install`); called before its workers.

    Parameters
    ----------
    package_file : str
        The ``__file__`` of the kernel package asking.  Every geardyn function is keyed on the sources of its
        own directory once :func:`install` has run, so the file only names the caller; it selects nothing.
    """
    install()


def on_compile(callback: Callable[[str], None]) -> Callable[[], None]:
    """Call ``callback(what)`` when a compile of a geardyn function starts (its cache missed).

    Parameters
    ----------
    callback : callable
        Called with a phrase naming what compiles ("the integrator"), once per outermost compile.

    Returns
    -------
    callable
        Removes the callback.

    Examples
    --------
    >>> seen = []
    >>> remove = on_compile(seen.append)
    >>> remove()
    """
    with _lock:
        _callbacks.append(callback)

    def remove() -> None:
        with _lock:
            if callback in _callbacks:
                _callbacks.remove(callback)

    return remove


def compile_seconds() -> float:
    """Seconds this process has spent compiling geardyn's functions so far (a compile under way counts).

    Examples
    --------
    >>> compile_seconds() >= 0.0
    True
    """
    with _lock:
        running = time.monotonic() - _t_start if _depth > 0 else 0.0
        return _total + running


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
