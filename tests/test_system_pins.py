"""Numbers of multi-DOF systems pinned across the refactoring onto one analysis stack.

Every literal below was recorded from the previous implementation (the ``systems_*`` analysis modules and
``integrate_ndof``, before the analyses were written once against :class:`geardyn.system.System`).  The same
kernel calls must give the same numbers, to 1e-12.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from geardyn.model import IntegrationOptions
from geardyn.systems import load_system

EX = Path(__file__).resolve().parents[1] / "examples" / "systems"
TOL = dict(rtol=1e-12, atol=1e-15)


def _h(*xs: str) -> np.ndarray:
    return np.array([float.fromhex(x) for x in xs])


@pytest.fixture(scope="module")
def torsional():
    return load_system(EX / "paper_torsional.toml").with_param("omega", 0.8)


@pytest.fixture(scope="module")
def spur6():
    return load_system(EX / "spur_bending_torsional.toml")


@pytest.mark.slow  # the stiff bearings take small steps
def test_simulate_of_the_six_dof_spur_pair(spur6):
    from geardyn.analysis.steady import simulate

    r = simulate(spur6, IntegrationOptions(transient=50, periods=16))
    np.testing.assert_allclose(
        [r.summary["amplitude"], r.summary["u_min"]], _h("0x1.68ae935646840p-7", "0x1.0b29337c59bccp+0"), **TOL
    )
    np.testing.assert_allclose(
        r.poincare[-1],
        _h(
            "-0x1.12c837610c242p-4",
            "-0x1.797a92ae31dfep-3",
            "0x1.4d346e3e1d76bp+0",
            "0x1.12bb0adf7d46bp-4",
            "0x1.796879bd00852p-3",
            "-0x1.12fbce4c38584p-3",
            "0x1.d54a356e97445p-20",
            "0x1.42574100af31ep-18",
            "0x1.39b8595babed4p-15",
            "-0x1.e4599b7876cf6p-19",
            "-0x1.4caf68b80767dp-17",
            "0x1.ede1036d036d7p-15",
        ),
        **TOL,
    )


def test_lyapunov_spectrum_of_the_torsional_pair(torsional):
    from geardyn.analysis.lyapunov import lyapunov_spectrum

    ly = lyapunov_spectrum(torsional, IntegrationOptions(transient=50, periods=200))
    np.testing.assert_allclose(
        ly.exponents,
        _h("0x1.941005e51ee39p-15", "-0x1.30dfb99b4d757p-20", "-0x1.5704906659f72p-6", "-0x1.6ed1b01d4516dp-3"),
        **TOL,
    )


def test_shooting_on_the_torsional_pair(torsional):
    from geardyn.analysis.periodic import shoot

    o = shoot(torsional, 1)
    assert o.iterations == 3
    np.testing.assert_allclose(
        o.state,
        _h("0x1.89ff552194481p-2", "-0x1.4fefab1a41916p-3", "0x1.e621e651acf17p-5", "-0x1.de6c8f476c0a3p-3"),
        **TOL,
    )
    mu = np.sort_complex(np.asarray(o.multipliers))
    np.testing.assert_allclose(
        mu,
        np.sort_complex(
            np.array([-1.0622375380559457, 1.00000001094273, 0.9999999890572707, -0.1956997083097751], complex)
        ),
        rtol=1e-9,
    )


def test_period_map_of_the_bevel_pair():
    from geardyn.integrate import period_map

    b8 = load_system(EX / "paper_bevel_8dof.toml")
    pts, M, _st, ok = period_map(b8, np.zeros(b8.state_dim), 1)
    assert ok
    np.testing.assert_allclose(
        pts[-1][:4],
        _h("-0x1.bd27e806c78cbp-7", "0x1.f639fb241a1ddp-4", "-0x1.30a8cab413898p-3", "0x1.f26395bf69f72p-2"),
        **TOL,
    )
    np.testing.assert_allclose(
        [M[0, 0], M[3, 5], np.linalg.det(M)],
        _h("-0x1.f46ca43c2e8c9p-3", "0x1.a845f2322f906p-4", "0x1.ca228385b2af8p-5"),
        **TOL,
    )


def test_batch_of_the_six_dof_spur_pair(spur6):
    from geardyn.integrate import integrate_batch

    res = integrate_batch(
        [spur6.with_param("omega", w) for w in (0.6, 0.9)], None, IntegrationOptions(transient=20, periods=4)
    )
    np.testing.assert_allclose(res.amplitude, _h("0x1.1809cd2b75ac0p-6", "0x1.c7187dad785c0p-6"), **TOL)
    np.testing.assert_allclose(res.element_rms().ravel(), _h("0x1.6791a1fd46cddp-7", "0x1.4141bd7331f6fp-6"), **TOL)


def test_bifurcation_sweep_of_the_six_dof_spur_pair(spur6):
    from geardyn.analysis.bifurcation import bifurcation

    # no settling pass (settle_periods=0): the kernel call of the previous system sweep
    ds = bifurcation(
        spur6, "omega", [0.07, 0.09], options=IntegrationOptions(transient=20, periods=8), settle_periods=0
    )
    np.testing.assert_allclose(
        ds["amplitude"].values.ravel(), _h("0x1.67b0b14774cc0p-7", "0x1.69226f29e57c0p-7"), **TOL
    )
    np.testing.assert_allclose(
        ds["poincare_u"].values.ravel()[:3],
        _h("0x1.0b2a2cce4aa40p+0", "0x1.0b2a2cce4aa40p+0", "0x1.0b2a2cce4aa4ap+0"),
        **TOL,
    )
