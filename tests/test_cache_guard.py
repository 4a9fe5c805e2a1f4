"""numba's cache of geardyn's functions: keyed on the sources of their directory, kept where it can be written.

Each test compiles a one-line function in a package laid out in a temporary directory that stands for geardyn's
(``ROOT`` monkeypatched), in a fresh interpreter, and reads numba's own counters of cache hits and misses.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import geardyn._cache_guard as guard

PROBE = textwrap.dedent(
    """
    import json, sys
    from pathlib import Path
    import geardyn._cache_guard as guard
    guard.ROOT = Path(sys.argv[1]).resolve()
    if len(sys.argv) > 2:
        guard._writable = lambda d: False
    guard.WHAT = (("kern", "the test kernel"),)
    guard.install()
    seen = []
    guard.on_compile(seen.append)
    sys.path.insert(0, str(guard.ROOT.parent))
    from kern.work import f
    assert f(2.0) == 3.0
    stats = f.stats
    print(json.dumps({"hits": sum(stats.cache_hits.values()), "misses": sum(stats.cache_misses.values()),
                      "announced": seen, "compile_s": guard.compile_seconds()}))
    """
)


def _package(tmp_path: Path) -> Path:
    pkg = tmp_path / "src" / "kern"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "helpers.py").write_text("ONE = 1.0\n")
    (pkg / "work.py").write_text(
        "from numba import njit\n\n\n@njit(cache=True)\ndef f(x):\n    return x + 1.0\n",
    )
    return pkg


def _probe(pkg: Path, env: dict[str, str], readonly: bool = False) -> dict:
    args = [sys.executable, "-c", PROBE, str(pkg)] + (["ro"] if readonly else [])
    out = subprocess.run(args, env=env, capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def _env(tmp_path: Path) -> dict[str, str]:
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "usercache"))
    env.pop("NUMBA_CACHE_DIR", None)
    return env


def test_compiled_once_then_read_from_the_cache_and_recompiled_when_any_sibling_source_changes(tmp_path):
    pkg, env = _package(tmp_path), _env(tmp_path)
    first = _probe(pkg, env)
    assert first["misses"] == 1 and first["hits"] == 0
    assert first["announced"] == ["the test kernel"]  # named by its module's prefix
    assert first["compile_s"] > 0.0
    assert list((pkg / "__pycache__").glob("work.f-*.nbi"))
    second = _probe(pkg, env)
    assert second == {**second, "hits": 1, "misses": 0, "announced": [], "compile_s": 0.0}
    (pkg / "helpers.py").write_text("ONE = 2.0\n")  # a file the function does not even import
    third = _probe(pkg, env)
    assert third["misses"] == 1 and third["hits"] == 0


def test_a_byte_identical_copy_reads_the_cache_compiled_for_the_original(tmp_path):
    import shutil

    pkg, env = _package(tmp_path), _env(tmp_path)
    assert _probe(pkg, env)["misses"] == 1
    copy = tmp_path / "installed" / "kern"
    shutil.copytree(pkg, copy)  # new modification times, same contents: what an install of the wheel does
    os.utime(copy / "work.py", (1.0, 1.0))
    assert _probe(copy, env)["hits"] == 1


def test_a_read_only_install_keeps_its_cache_under_the_user_cache_home_seeded_from_the_shipped_one(tmp_path):
    pkg, env = _package(tmp_path), _env(tmp_path)
    assert _probe(pkg, env)["misses"] == 1  # the "shipped" cache, written at install
    ro = _probe(pkg, env, readonly=True)
    assert ro["hits"] == 1 and ro["misses"] == 0  # read from the seeded copy
    user = list((tmp_path / "usercache" / "geardyn" / "numba").rglob("work.f-*.nbi"))
    assert len(user) == 1
    for f in (pkg / "__pycache__").glob("*.nb*"):
        f.unlink()  # nothing shipped: compiled once, saved in the user's cache, read from there next time
    for f in user[0].parent.glob("*.nb*"):
        f.unlink()
    assert _probe(pkg, env, readonly=True)["misses"] == 1
    assert _probe(pkg, env, readonly=True)["hits"] == 1


def test_the_user_cache_root_names_this_copy_of_the_package(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    root = guard.user_cache_root()
    assert root.parent == tmp_path / "geardyn" / "numba" and len(root.name) == 12
    monkeypatch.setattr(guard, "ROOT", tmp_path / "another")
    assert guard.user_cache_root() != root


def test_functions_outside_geardyn_keep_numbas_own_locator(tmp_path):
    guard.install()
    from numba.core import caching

    ours = caching.CacheImpl._locator_classes[0]
    assert ours.__name__ == "PackageCacheLocator"
    (tmp_path / "m.py").write_text("def g():\n    return 1\n")
    ns: dict = {}
    exec(compile((tmp_path / "m.py").read_text(), str(tmp_path / "m.py"), "exec"), ns)
    assert ours.from_function(ns["g"], str(tmp_path / "m.py")) is None


def test_the_install_time_compile_has_every_runtime_dependency():
    """setup.py runs the commands of geardyn._precompile in pip's build environment: a runtime dependency
    missing there makes a command fail, and its kernels compile at the user's first run instead."""
    import tomllib

    meta = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    assert set(meta["project"]["dependencies"]) <= set(meta["build-system"]["requires"])


def _save_many(args):
    """One of several processes saving 60 entries into one cache directory at once."""
    path, who = args
    from numba.core import caching

    guard.install()
    guard._SAFE_PATHS.add(path)
    f = caching.IndexDataCacheFile(cache_path=path, filename_base="f-1.py311", source_stamp="s")
    for i in range(60):
        f.save((who, i), ("data", who, i))


def test_processes_saving_at_once_lose_no_entry_and_no_file_holds_another_keys_data(tmp_path):
    """numba's counter names let two processes take one file name for two keys, and its unlocked index loses
    the entries of one of them (184 of 240 were kept in a run of this test on numba's own files)."""
    import multiprocessing

    from numba.core import caching

    path = str(tmp_path)
    with multiprocessing.get_context("spawn").Pool(4) as pool:
        pool.map(_save_many, [(path, w) for w in range(4)])
    guard.install()
    guard._SAFE_PATHS.add(path)
    f = caching.IndexDataCacheFile(cache_path=path, filename_base="f-1.py311", source_stamp="s")
    index = f._load_index()
    assert sorted(index) == [(w, i) for w in range(4) for i in range(60)]
    assert all(f.load(k) == ("data", *k) for k in index)
    # an entry naming another key's file (as numba's counter can leave it) is a miss, not that key's code
    index[(0, 0)] = index[(1, 1)]
    f._save_index(index)
    assert f.load((0, 0)) is None and f.load((1, 1)) == ("data", 1, 1)


def test_every_compiled_function_of_geardyn_has_a_name_of_its_own():
    """numba names a compiled function's symbol by its qualified name, a per-process counter and its argument
    types: two closures of one factory with one name, compiled in two processes, can get the same symbol, and a
    cached caller then runs the other's code (the lanes worker of the general kind ran the first-harmonic
    chunk kernel: tests/test_simd.py failed once the kernels were compiled by several test workers)."""
    import gc
    import importlib

    from numba.core.registry import CPUDispatcher

    src = Path(guard.ROOT)
    for f in sorted(src.rglob("*.py")):  # every module that compiles (some are imported lazily by their package)
        if "njit" in f.read_text() and f.name != "_cache_guard.py":
            importlib.import_module(".".join(("geardyn", *f.relative_to(src).with_suffix("").parts)))

    names: dict[tuple[str, str], object] = {}
    for obj in gc.get_objects():
        if isinstance(obj, CPUDispatcher) and obj.py_func.__module__.startswith("geardyn"):
            key = (obj.py_func.__module__, obj.py_func.__qualname__)
            assert names.setdefault(key, obj.py_func) is obj.py_func, f"two compiled functions named {key}"
    assert len(names) > 40
    assert ("geardyn._kernel.lanes", "_make_chunk.chunk_kind_2_mode_1") in names


@pytest.mark.slow
def test_kernels_compiled_by_two_processes_run_their_own_code(tmp_path):
    """The failure itself: one process compiles the cosine kind's lanes worker at width 0, another at the same
    time the general kind's at width 512, into one cache; a third loads both and must match the scalar
    worker (before each closure had a name of its own, the general kind was wrong by 0.97)."""
    probe = textwrap.dedent(
        """
        import json, sys
        import numpy as np
        sys.path.insert(0, sys.argv[1])
        from test_simd import _batch, _run, _run_scalar, MODES
        n_tr, n_rec, tan, _ = MODES["statistics"]
        out = {}
        for step in sys.argv[2].split(","):
            kind, width = step.split(":")
            arrays = _batch(kind)
            got = _run(int(width), arrays, n_tr, n_rec, tan)["poincare"]
            ref = _run_scalar(arrays, n_tr, n_rec, tan)["poincare"]
            ok = np.arange(len(arrays[0])) != 11
            out[step] = float(np.max(np.abs(got[ok] - ref[ok])))
        print(json.dumps(out))
        """
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    tests = str(Path(__file__).resolve().parent)
    run = [sys.executable, "-c", probe, tests]
    first = [subprocess.Popen([*run, s], env=env, stdout=subprocess.PIPE) for s in ("cos:0", "gen:512")]
    assert all(p.wait() == 0 for p in first)
    out = subprocess.run([*run, "cos:0,gen:512"], env=env, capture_output=True, text=True, check=True).stdout
    assert json.loads(out.strip().splitlines()[-1]) == {"cos:0": 0.0, "gen:512": 0.0}
