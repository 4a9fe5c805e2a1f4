"""numba's on-disk cache of geardyn's kernels: keyed on their sources, safe between processes, kept where it can
be written, and announced.

**Keyed on the sources.**  numba keys a cached function on the modification time of the file it is defined in,
so a worker compiled from ``lanes.py`` that inlines functions of ``core.py`` would not be recompiled when only
``core.py`` changes, and a copy of the package (an install) would never find the code compiled for it.
:func:`install` puts :class:`PackageCacheLocator` in front of numba's own locators for every function defined
in geardyn: its source stamp is the SHA-256 of every source file of the function's directory and of the
directories whose compiled functions it calls (:data:`DEPENDS`), so a change to any of them makes numba compile
afresh (a stale index is ignored), and code compiled for one copy of the sources is valid for any
byte-identical copy.  That is what lets ``pip install`` compile the kernels once, at install time
(``setup.py``: the wheel ships the cache; :mod:`geardyn._precompile`).

**Safe between processes.**  Two processes compiling at once (two test workers, two commands, a dask
cluster) write one cache.  numba names a function's data files by a counter (``f.1.nbc``, ``f.2.nbc``, ...)
chosen from the index it has just read, and rewrites the index unlocked: two processes can take one number
for two signatures (the index then names one and the file holds the other's code), and one loses the other's
entries.  :class:`SafeIndexFile` names each file by a hash of its key (signature, target, the function's
bytecode) and of the source stamp, so a file only ever holds the code of the key it is named for; it updates
the index under a lock of the directory, and reads no file it did not name that way.  numba also names a
compiled function's symbol by its qualified name, a per-process counter and its argument types, so closures
of one factory compiled in two processes can share a symbol, and a cached caller then links to the other's
code: :func:`own_name` gives each such closure a name of its own.

**Kept where it can be written.**  The cache lives in the ``__pycache__`` beside the sources, or under numba's
``NUMBA_CACHE_DIR`` when that is set.  Where the ``__pycache__`` cannot be written (a package installed
read-only, in a user's site-packages), it lives under the user's cache home (``$XDG_CACHE_HOME/geardyn/numba``,
``~/.cache/geardyn/numba``), seeded from the cache shipped with the package.  A cache that can be kept nowhere
costs a compile, never a failure.

**Announced.**  A compile of a geardyn function (the cache missed) is reported to the callbacks of
:func:`on_compile` ("compiling the integrator, first run only": progress bars print it), and
:func:`compile_seconds` counts the time spent compiling, which progress ETAs leave out.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import pickle
import shutil
import threading
import time
from collections.abc import Callable
from pathlib import Path

__all__ = ["compile_seconds", "fast_loads", "install", "on_compile", "own_name", "refresh", "user_cache_root"]

#: The geardyn package directory: functions defined below it use :class:`PackageCacheLocator`.
ROOT = Path(__file__).resolve().parent

#: What is being compiled, by the module prefix of the function (the first match names it).
WHAT = (
    ("geardyn._kernel_ndof", "the N-DOF integrator"),
    ("geardyn._kernel", "the integrator"),
    ("geardyn.analysis.hb", "the harmonic-balance kernels"),
    ("geardyn", "geardyn's kernels"),
)

#: Directories (relative to :data:`ROOT`) whose compiled functions call those of other directories: their
#: cache is stamped with the sources of both.
DEPENDS = {"_kernel_ndof": ("_kernel",), "analysis/hb": ("_kernel_ndof",)}

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


def _stamp(directory: Path) -> str:
    """The source stamp of the functions of ``directory``: its sources and those of the directories it calls."""
    try:
        rel = directory.relative_to(ROOT).as_posix()
    except ValueError:
        rel = ""
    parts = [_digest(str(directory))] + [_digest(str(ROOT / dep)) for dep in DEPENDS.get(rel, ())]
    return parts[0] if len(parts) == 1 else hashlib.sha256("".join(parts).encode()).hexdigest()


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


#: Cache directories of geardyn's functions (their index files are :class:`SafeIndexFile`).
_SAFE_PATHS: set[str] = set()
#: The lock file of a cache directory, held while its index files are updated.
LOCK_NAME = "geardyn-cache.lock"


def _locator_class():
    from numba.core import caching, config

    class PackageCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
        """numba's locator for a function defined in geardyn: stamped by its directory's sources."""

        def __init__(self, py_func, py_file):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            here = Path(py_file).resolve().parent
            shipped = here / "__pycache__"
            if config.CACHE_DIR:
                sub = caching.UserProvidedCacheLocator.get_suitable_cache_subpath(py_file)
                self._cache_path = os.path.join(config.CACHE_DIR, sub)
            elif _writable(shipped):
                self._cache_path = str(shipped)
            else:
                target = user_cache_root() / here.relative_to(ROOT)
                _seed(shipped, target)
                self._cache_path = str(target)
            _SAFE_PATHS.add(self._cache_path)

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):
            return _stamp(Path(self._py_file).resolve().parent)

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


def _index_file_class():
    from numba.core import caching

    class SafeIndexFile(caching.IndexDataCacheFile):
        """numba's index and data files of one function, with each data file named by its key.

        The name is a hash of the key (signature, target, bytecode) and of the source stamp, so a data file
        only ever holds the code compiled for the key it is named for, whatever other processes write at the
        same time; the index is updated under a lock of the directory (where the platform has one), after
        the data file is in place; a key whose index entry names another file is a miss.
        """

        def __init__(self, cache_path, filename_base, source_stamp):
            super().__init__(cache_path, filename_base, source_stamp)
            self._base = filename_base

        def name_for(self, key) -> str:
            digest = hashlib.sha256(repr((key, self._source_stamp)).encode()).hexdigest()[:24]
            return f"{self._base}.{digest}.nbc"

        @contextlib.contextmanager
        def _locked(self):
            try:
                handle = open(os.path.join(self._cache_path, LOCK_NAME), "ab")  # noqa: SIM115
            except OSError:
                yield
                return
            with handle:
                try:
                    import fcntl

                    fcntl.flock(handle, fcntl.LOCK_EX)
                except (ImportError, OSError):  # no lock here: names alone keep the code right
                    pass
                yield

        def _stale_files(self) -> list[str]:
            """The data files named by an index written for other sources (none if it is for these)."""
            try:
                with open(self._index_path, "rb") as f:
                    pickle.load(f)
                    stamp, overloads = pickle.loads(f.read())
            except Exception:  # noqa: BLE001  (no index, another numba's, unreadable: nothing to remove)
                return []
            return [] if stamp == self._source_stamp else list(overloads.values())

        def save(self, key, data):
            name = self.name_for(key)
            self._save_data(name, data)
            with self._locked():
                for stale in self._stale_files():
                    if stale != name:
                        with contextlib.suppress(OSError):
                            os.remove(self._data_path(stale))
                overloads = self._load_index()
                foreign = [k for k, n in overloads.items() if n != self.name_for(k)]  # numba's counter names
                for k in foreign:
                    with contextlib.suppress(OSError):
                        os.remove(self._data_path(overloads.pop(k)))
                if foreign or overloads.get(key) != name:
                    overloads[key] = name
                    self._save_index(overloads)

        def load(self, key):
            name = self._load_index().get(key)
            if name is None or name != self.name_for(key):
                return None
            try:
                return self._load_data(name)
            except OSError:
                return None

    return SafeIndexFile


def own_name(*tags: object) -> Callable[[Callable], Callable]:
    """Give a function built by a factory a qualified name of its own; apply it under ``@njit``.

    numba names a compiled function's symbol by its qualified name, a counter of the compiling process and
    its argument types.  Closures built by one factory share the qualified name; compiled in two processes
    (two test workers, two commands) they can get the same counter, and a cached caller compiled in one
    process then links to the other's code once both are loaded: the lanes worker of the general kind ran
    the first-harmonic chunk kernel, with no error.  A name of its own per closure (the factory's arguments
    in ``tags``) makes the symbols differ.

    Parameters
    ----------
    *tags : object
        What distinguishes this closure from the factory's others (kind, mode, width), joined into the name.

    Examples
    --------
    >>> def make(k):
    ...     @own_name("kind", k)
    ...     def f(x):
    ...         return x + k
    ...     return f
    >>> make(2).__qualname__
    'make.f_kind_2'
    """
    suffix = "_".join(str(t) for t in tags)

    def rename(fn: Callable) -> Callable:
        fn.__qualname__ = f"{fn.__qualname__.replace('<locals>.', '')}_{suffix}"
        fn.__name__ = f"{fn.__name__}_{suffix}"
        return fn

    return rename


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
    is kept elsewhere (``NUMBA_CACHE_DIR``) geardyn's functions are cached there, keyed and named the same way.

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
        locators.insert(0, _locator_class())  # NUMBA_CACHE_DIR is honoured by the locator itself
        numbas, safe = caching.IndexDataCacheFile, _index_file_class()

        def index_file(cache_path, filename_base, source_stamp):
            cls = safe if cache_path in _SAFE_PATHS else numbas
            return cls(cache_path=cache_path, filename_base=filename_base, source_stamp=source_stamp)

        caching.IndexDataCacheFile = index_file
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
