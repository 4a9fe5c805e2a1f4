"""The public API's examples run: every callable in ``geardyn.__all__`` has a numpydoc ``Examples`` section, and
its doctests pass (run from the checkout's root, where the examples' files are); so do the examples of the
library's run inputs (:mod:`geardyn.inputs`, :mod:`geardyn.analysis.context`)."""

from __future__ import annotations

import doctest
import importlib
import inspect
import re
from pathlib import Path

import pytest

import geardyn

ROOT = Path(__file__).resolve().parents[1]
CALLABLES = [name for name in geardyn.__all__ if callable(getattr(geardyn, name))]
#: Examples beyond the public API kept true: module -> names.
MORE = {"geardyn.inputs": ("PairInputs",), "geardyn.analysis.context": ("continuation_context",)}
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def test_public_names_are_the_documented_ones():
    assert {"System", "SystemModel", "load_system", "Grid", "GearModel", "simulate", "bifurcation"} <= set(
        geardyn.__all__
    )
    assert {"continuation", "lyapunov_spectrum", "shoot", "hb_solve"} <= set(geardyn.__all__)
    assert sorted(dir(geardyn)) == sorted(geardyn.__all__)  # no stray names (modules, helpers, typing)
    for name in geardyn.__all__:
        assert getattr(geardyn, name) is not None


def _run_examples(obj, name: str, monkeypatch) -> None:
    doc = inspect.getdoc(obj) or ""
    assert re.search(r"^Examples\n-{8}$", doc, re.M), f"{name}: no numpydoc Examples section"
    monkeypatch.chdir(ROOT)
    tests = doctest.DocTestFinder(recurse=False).find(obj, name, globs={})
    out: list[str] = []
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    for t in tests:
        runner.run(t, out=out.append)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0, f"{name}: its Examples hold no doctest"
    assert result.failed == 0, "".join(out)


@pytest.mark.parametrize("name", CALLABLES)
def test_examples_run(name, monkeypatch):
    _run_examples(getattr(geardyn, name), f"geardyn.{name}", monkeypatch)


@pytest.mark.parametrize("path", [f"{m}.{n}" for m, names in MORE.items() for n in names])
def test_examples_of_the_run_inputs_run(path, monkeypatch):
    module, name = path.rsplit(".", 1)
    _run_examples(getattr(importlib.import_module(module), name), path, monkeypatch)
