"""Run small dense linear algebra on one BLAS thread.

Harmonic balance factorises and diagonalises matrices of a few hundred rows thousands of times; a
multi-threaded BLAS spends more time waking its threads than computing (and on a loaded machine
much more).  :func:`solve` calls LAPACK's ``dgesv`` directly: for the matrices of a continuation
(a few dozen rows, between other compiled work) ``numpy.linalg.solve`` spends ten times as long in
its generic machinery as in the factorisation.  :func:`single_thread_blas` limits the BLAS loaded by NumPy and SciPy to one thread for
the duration of a block, through ``threadpoolctl`` when it is installed, else through the
``*_set_num_threads`` entry points of every OpenBLAS loaded; it does nothing when neither is
available.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np
from scipy.linalg.lapack import dgesv

__all__ = ["single_thread_blas", "solve"]

_SETTERS = (
    "scipy_openblas_set_num_threads64_",
    "scipy_openblas_set_num_threads",
    "openblas_set_num_threads64_",
    "openblas_set_num_threads",
)
_GETTERS = (
    "scipy_openblas_get_num_threads64_",
    "scipy_openblas_get_num_threads",
    "openblas_get_num_threads64_",
    "openblas_get_num_threads",
)
_found: list[tuple[Callable[[], int], Callable[[int], None]]] | None = None


def _openblas() -> list[tuple[Callable[[], int], Callable[[int], None]]]:
    """(get, set) thread-count entry points of every OpenBLAS loaded (NumPy's and SciPy's may differ)."""
    global _found
    if _found is not None:
        return _found
    _found = []
    try:
        with open("/proc/self/maps") as fh:
            paths = {ln.split()[-1] for ln in fh if "openblas" in ln.lower() and ln.split()[-1].startswith("/")}
    except OSError:
        return _found
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        get = next((getattr(lib, g) for g in _GETTERS if hasattr(lib, g)), None)
        put = next((getattr(lib, s) for s in _SETTERS if hasattr(lib, s)), None)
        if get is not None and put is not None:
            get.restype = ctypes.c_int
            put.argtypes = [ctypes.c_int]
            _found.append((lambda g=get: int(g()), lambda k, p=put: p(int(k))))
    return _found


_limits: Callable[..., object] | None | bool = False


def _threadpoolctl() -> Callable[..., object] | None:
    """``threadpoolctl.threadpool_limits`` if installed (looked up once)."""
    global _limits
    if _limits is False:
        try:
            from threadpoolctl import threadpool_limits  # type: ignore[import-not-found]
        except ImportError:
            threadpool_limits = None
        _limits = threadpool_limits
    return _limits  # type: ignore[return-value]


@contextmanager
def single_thread_blas() -> Iterator[None]:
    """Limit NumPy's BLAS to one thread inside the block (restored afterwards)."""
    threadpool_limits = _threadpoolctl()
    if threadpool_limits is not None:
        with threadpool_limits(limits=1, user_api="blas"):
            yield
        return
    libs = _openblas()
    old = [get() for get, _put in libs]
    for _get, put in libs:
        put(1)
    try:
        yield
    finally:
        for (_get, put), k in zip(libs, old):
            put(k)


def solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with A x = b (real square A, vector b) by LAPACK ``dgesv``.

    Parameters
    ----------
    A : ndarray (m, m)
    b : ndarray (m,)

    Returns
    -------
    ndarray (m,)

    Raises
    ------
    numpy.linalg.LinAlgError
        When A is exactly singular (as ``numpy.linalg.solve``).
    """
    _lu, _piv, x, info = dgesv(A, b)
    if info > 0:
        raise np.linalg.LinAlgError("Singular matrix")
    if info < 0:
        raise ValueError(f"dgesv: illegal argument {-info}")
    return x
