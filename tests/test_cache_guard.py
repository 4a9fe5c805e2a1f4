"""The kernel packages' numba cache follows every source file of the package, not only the worker's."""

from __future__ import annotations

from geardyn._cache_guard import STAMP, refresh


def test_stale_cache_is_removed_when_any_source_changes(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    pkg = tmp_path / "kern"
    (pkg / "__pycache__").mkdir(parents=True)
    (pkg / "__init__.py").write_text("x = 1\n")
    (pkg / "core.py").write_text("def f(): return 1\n")
    cached = [pkg / "__pycache__" / "worker.w-10.py311.nbi", pkg / "__pycache__" / "worker.w-10.py311.1.nbc"]
    for f in cached:
        f.write_bytes(b"machine code")
    assert refresh(str(pkg / "__init__.py")) is True          # no stamp yet: the cache is not trusted
    assert not any(f.exists() for f in cached) and (pkg / "__pycache__" / STAMP).exists()
    for f in cached:
        f.write_bytes(b"fresh machine code")
    assert refresh(str(pkg / "__init__.py")) is False         # unchanged sources: the cache is kept
    assert all(f.exists() for f in cached)
    (pkg / "core.py").write_text("def f(): return 2\n")       # a change in a file the workers inline
    assert refresh(str(pkg / "__init__.py")) is True
    assert not any(f.exists() for f in cached)


def test_a_cache_kept_elsewhere_is_left_to_numba(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "elsewhere"))
    (tmp_path / "__init__.py").write_text("")
    assert refresh(str(tmp_path / "__init__.py")) is False


def test_a_cache_save_waits_for_the_lock_another_holds(tmp_path):
    """Two processes adding specializations of one kernel at once must not both take the same data file: a save
    holds ``<index>.lock`` (here held by another open file, as another process would)."""
    import fcntl
    import threading

    from geardyn._cache_guard import locked_saves

    class File:
        _index_path = tmp_path / "kernel.nbi"

        def __init__(self):
            self.saved = []

        def save(self, key, data):
            self.saved.append((key, data))

    f = File()
    locked_saves(f)
    with open(str(f._index_path) + ".lock", "a") as other:
        fcntl.flock(other, fcntl.LOCK_EX)
        t = threading.Thread(target=f.save, args=("sig", b"code"))
        t.start()
        t.join(0.3)
        assert t.is_alive() and f.saved == []  # waits while the lock is held
        fcntl.flock(other, fcntl.LOCK_UN)
    t.join(10)
    assert f.saved == [("sig", b"code")]
    wrapped = f.save
    locked_saves(f)  # a second call leaves it as it is
    assert f.save is wrapped and f.save.locked


def test_the_kernels_cache_saves_are_locked():
    from geardyn._kernel.scalar import _scalar_worker
    from geardyn._kernel_ndof import ndof_worker

    import geardyn.integrate  # noqa: F401  (imports the kernel packages, which set their loads and saves up)

    for worker in (_scalar_worker, ndof_worker):
        assert worker._cache._cache_file.save.locked
