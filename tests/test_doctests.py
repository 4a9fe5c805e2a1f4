"""The public API's examples run: every callable in ``geardyn.__all__`` has a numpydoc ``Examples`` section, and
its doctests pass (run from the checkout's root, where the examples' files are)."""

from __future__ import annotations

import doctest
import inspect
import re
from pathlib import Path

import pytest

import geardyn

ROOT = Path(__file__).resolve().parents[1]
CALLABLES = [name for name in geardyn.__all__ if callable(getattr(geardyn, name))]
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def test_public_names_are_the_documented_ones():
    assert {"System", "SystemModel", "load_system", "Grid", "GearModel", "simulate", "bifurcation"} <= set(
        geardyn.__all__
    )
    assert {"continuation", "lyapunov_spectrum", "shoot", "hb_solve"} <= set(geardyn.__all__)
    assert sorted(dir(geardyn)) == sorted(geardyn.__all__)  # no stray names (modules, helpers, typing)
    for name in geardyn.__all__:
        assert getattr(geardyn, name) is not None


@pytest.mark.parametrize("name", CALLABLES)
def test_examples_run(name, monkeypatch):
    obj = getattr(geardyn, name)
    doc = inspect.getdoc(obj) or ""
    assert re.search(r"^Examples\n-{8}$", doc, re.M), f"geardyn.{name}: no numpydoc Examples section"
    monkeypatch.chdir(ROOT)
    tests = doctest.DocTestFinder(recurse=False).find(obj, f"geardyn.{name}", globs={})
    out: list[str] = []
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    for t in tests:
        runner.run(t, out=out.append)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0, f"geardyn.{name}: its Examples hold no doctest"
    assert result.failed == 0, "".join(out)
