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
    assert refresh(str(pkg / "__init__.py")) is True  # no stamp yet: the cache is not trusted
    assert not any(f.exists() for f in cached) and (pkg / "__pycache__" / STAMP).exists()
    for f in cached:
        f.write_bytes(b"fresh machine code")
    assert refresh(str(pkg / "__init__.py")) is False  # unchanged sources: the cache is kept
    assert all(f.exists() for f in cached)
    (pkg / "core.py").write_text("def f(): return 2\n")  # a change in a file the workers inline
    assert refresh(str(pkg / "__init__.py")) is True
    assert not any(f.exists() for f in cached)


def test_a_cache_kept_elsewhere_is_left_to_numba(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "elsewhere"))
    (tmp_path / "__init__.py").write_text("")
    assert refresh(str(tmp_path / "__init__.py")) is False
