"""Events of an HB branch located once when they coincide (``SHARED_REL_TOL``): on the 48-DOF chain of
``benchmarks/hb_scaling.py`` two meshes under the same loads lose contact at the same ω (0.646994); each grazing is
reported, at the value its own secant location gives (the reference: the same continuation with every event
located separately), for one location's Jacobians."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.hb import continuation, equations
from geardyn.systems import load_system

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

pytestmark = pytest.mark.slow


def test_coinciding_grazings_are_located_once(tmp_path, monkeypatch):
    from ndof_scaling import chain_toml

    model = load_system(chain_toml(8, tmp_path / "chain8.toml", fp_torque=30.0, eps_um=10.0))
    calls = {"jacobians": 0}
    jacobian = equations.HBEquations._jacobian

    def counted(*a, **k):
        calls["jacobians"] += 1
        return jacobian(*a, **k)

    monkeypatch.setattr(equations.HBEquations, "_jacobian", counted)
    shared = continuation.hb_continuation(model, "omega", 0.64, 0.65, harmonics=16)
    with_sharing, calls["jacobians"] = calls["jacobians"], 0
    monkeypatch.setattr(continuation, "SHARED_REL_TOL", -1.0)  # every event located by its own secant
    alone = continuation.hb_continuation(model, "omega", 0.64, 0.65, harmonics=16)
    grazings = sorted((b.detail, b.value) for b in shared.of_type("grazing"))
    reference = sorted((b.detail, b.value) for b in alone.of_type("grazing"))
    assert len(grazings) == 2 and [d for d, _ in grazings] == [d for d, _ in reference]
    assert grazings[0][1] == grazings[1][1]  # one location for both
    np.testing.assert_allclose([v for _, v in grazings], [v for _, v in reference], rtol=0, atol=1e-9)
    assert [b.located for b in shared.bifurcations] == [True] * len(shared.bifurcations)
    np.testing.assert_array_equal(shared.values, alone.values)  # the branch itself is the same
    assert with_sharing < calls["jacobians"]
