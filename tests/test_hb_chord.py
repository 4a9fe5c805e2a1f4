"""The corrector's chord steps on a sparse Jacobian (``CHORD_RATE``: SuperLU's factors kept while the residual falls
fourfold an iteration, and used again for the new point's tangent) give the branch Newton with a fresh factorisation
every iteration gives: on the 48-DOF chain of ``benchmarks/hb_scaling.py`` over ω ∈ [0.64, 0.65], the same points
and the same grazings of its meshes (the reference is the same continuation with every Jacobian factorised)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.hb import equations
from geardyn.analysis.hb.continuation import hb_continuation
from geardyn.systems import load_system

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

pytestmark = pytest.mark.slow


def test_chord_steps_give_the_newton_branch_and_events(tmp_path, monkeypatch):
    from ndof_scaling import chain_toml

    model = load_system(chain_toml(8, tmp_path / "chain8.toml", fp_torque=30.0, eps_um=10.0))
    factorised = {"count": 0}
    solve = equations.SparseJacobian.solve

    def counted(self, b, lu=None):
        factorised["count"] += lu is None
        return solve(self, b, lu)

    monkeypatch.setattr(equations.SparseJacobian, "solve", counted)
    chord = hb_continuation(model, "omega", 0.64, 0.65, harmonics=16)
    with_chord = factorised["count"]
    factorised["count"] = 0
    monkeypatch.setattr(equations.SparseJacobian, "solve", lambda self, b, lu=None: counted(self, b, None))
    newton = hb_continuation(model, "omega", 0.64, 0.65, harmonics=16)
    assert isinstance(chord.equations.residual(chord.equations.unknowns(chord.equations.linear_guess()))[1],
                      equations.SparseJacobian)  # fmt: skip
    assert with_chord < factorised["count"]  # the chord steps saved factorisations
    events = [(b.type, b.value) for b in chord.bifurcations]
    reference = [(b.type, b.value) for b in newton.bifurcations]
    assert [t for t, _ in events] == [t for t, _ in reference] and any(t == "grazing" for t, _ in events)
    np.testing.assert_allclose([v for _, v in events], [v for _, v in reference], rtol=0, atol=1e-8)
    # the points lie on the same branch: each chord point's amplitude is the Newton branch's at its ω (to the
    # corrector's tolerance, interpolation aside: the points are compared where the two branches share a value)
    assert chord.values.size == newton.values.size
    np.testing.assert_allclose(chord.values, newton.values, rtol=0, atol=1e-8)
    np.testing.assert_allclose(chord.amplitude, newton.amplitude, rtol=1e-8, atol=0)
