"""The system protocol, implemented by the gear model."""

from __future__ import annotations

import numpy as np

from geardyn.integrate import state_dim
from geardyn.model import Boundary, GearModel
from geardyn.system import System


def test_gear_model_is_a_system() -> None:
    m = GearModel(omega=1.2)
    assert isinstance(m, System)
    assert m.state_dim == 2 and state_dim(m) == m.state_dim
    assert np.isclose(m.period, 2 * np.pi / 1.2)
    assert m.with_param("kappa1", 0.1).get("kappa1") == 0.1
    assert "omega" in m.parameters()


def test_contact_boundaries_of_the_mesh() -> None:
    m = GearModel(D=0.5)
    (b,) = m.contact_boundaries()
    assert isinstance(b, Boundary)
    assert len(b.vector) == m.state_dim and b.gap == 0.5


def test_pack_gives_the_kernel_arrays() -> None:
    coef, D, omega = GearModel.pack([GearModel(omega=0.8), GearModel(omega=1.1, D=0.3)])
    assert coef.shape[0] == 2 and list(D) == [1.0, 0.3] and list(omega) == [0.8, 1.1]
