"""Refactorings keep every computed number bit-identical.

``tests/data/regression_values.json`` holds, as ``float.hex`` strings, a bifurcation sweep, a shot
period-2 orbit (state, monodromy, extremes), a Lyapunov spectrum, a steady response and a short
continuation, recorded by ``tests/data/record_regression.py`` on the commit named in the file
(before the redesign of the package's periphery).  The same computations today must give the same bits.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
sys.path.insert(0, str(DATA))

from record_regression import compute  # noqa: E402

RECORDED = json.loads((DATA / "regression_values.json").read_text())


@pytest.fixture(scope="module")
def today() -> dict:
    return compute()


@pytest.mark.parametrize("study", ["bifurcation", "orbit", "lyapunov", "simulate", "continuation"])
def test_bit_identical_to_recorded(today: dict, study: str) -> None:
    for key, values in RECORDED[study].items():
        assert today[study][key] == values, f"{study}.{key} changed"
