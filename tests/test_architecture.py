"""``docs/architecture.md`` says what the code is: each claim that can be checked is checked here.

* The public API it lists is ``geardyn.__all__``, and ``import geardyn`` imports none of the heavy libraries.
* Every file and directory it names exists (the concepts' places and the recipes' file lists).
* No import cycle, counting imports inside functions (``../shared/tools/structure.py``, when the checkout has it).
* ``.ci/run`` runs the checks it says it runs.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

import geardyn

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "geardyn"
DOC = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
STRUCTURE = ROOT.parent / "shared" / "tools" / "structure.py"


def _section(title: str) -> str:
    start = DOC.index(f"## {title}")
    end = DOC.find("\n## ", start + 1)
    return DOC[start : end if end > 0 else len(DOC)]


def test_the_public_api_listed_is_geardyn_all():
    bullets = "\n".join(line for line in _section("The public API").splitlines() if line.startswith(("* ", "  ")))
    listed = set(re.findall(r"`([A-Za-z_][A-Za-z0-9_]*)`", bullets))
    assert listed == set(geardyn.__all__)


def test_import_geardyn_imports_no_heavy_library():
    code = (
        "import sys, geardyn\n"
        "print(sorted(m for m in ('numpy', 'xarray', 'numba', 'pint', 'matplotlib') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout


def _exists(token: str) -> bool:
    tok = token.rstrip("/")
    if tok.startswith("python "):
        tok = tok.split()[1]
    bases = (ROOT, PKG, PKG / "analysis", ROOT / "docs")
    if any((b / tok).exists() for b in bases):
        return True
    return "/" not in tok and any(PKG.rglob(tok))


PATHS = sorted(set(re.findall(r"`((?:python )?[\w./-]+(?:\.py|\.md|/))`", DOC)))


def test_the_page_names_files():
    assert "src/geardyn/config.py" in PATHS and "tests/test_conformance.py" in PATHS and len(PATHS) > 40


@pytest.mark.parametrize("token", PATHS)
def test_every_file_the_page_names_exists(token):
    assert _exists(token), token


def test_every_public_module_and_package_is_on_the_page():
    """The concepts' table says where everything is: each module and package of ``src/geardyn`` not private by
    its name (``_x``) is named on the page."""
    names = [p.name for p in PKG.glob("*.py") if not p.name.startswith("_")]
    names += [p.name + "/" for p in PKG.iterdir() if p.is_dir() and not p.name.startswith(("_", "."))]
    missing = [n for n in names if f"`{n}" not in DOC and f"{n}`" not in DOC]
    assert missing == [], missing


def test_the_recipes_name_existing_files_only():
    recipes = "\n".join(_section(t) for t in re.findall(r"^## (Recipe: [^\n]+)$", DOC, re.M))
    named = re.findall(r"`((?:python )?[\w./-]+(?:\.py|\.md|/))`", recipes)
    assert len(named) >= 15
    assert [t for t in named if not _exists(t)] == []


@pytest.mark.skipif(not STRUCTURE.is_file(), reason="the structure tool (../shared/tools) is not beside the checkout")
def test_no_import_cycle():
    out = subprocess.run([sys.executable, str(STRUCTURE), "src/geardyn"], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


def test_ci_runs_the_checks_the_page_names():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    for step in (
        "set -euo pipefail",
        "ruff check src tests",
        "ruff format --check src tests",
        "python ../shared/tools/structure.py src/geardyn",
        "tests/test_doctests.py",
        'pip install ".[test,dask]"',
        "python -m pytest -q",
    ):
        assert step in ci, step
    assert "ruff" in "".join(
        re.findall(r"^test = \[[^\]]*\]", (ROOT / "pyproject.toml").read_text(encoding="utf-8"), re.M)
    )
