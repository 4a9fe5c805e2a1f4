"""A system whose mean loads drive a free rigid-body rotation has no steady state: it is refused when it is
assembled, in one line naming the load that would balance it (it used to "diverge" with exit code 0)."""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import pytest

from geardyn.cli import main
from geardyn.errors import ModelError
from geardyn.systems import load_system
from geardyn.systems.assemble import assemble
from geardyn.systems.description import Body, Load, Mesh, SystemDescription

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "systems"


def _pair(loads, I1=1.5e-3, I2=4.0e-2, R1=0.03, R2=0.09):
    bodies = (Body("pinion", ("theta",), inertia=I1), Body("gear", ("theta",), inertia=I2))
    mesh = Mesh("mesh", ((("pinion", "theta"), R1), (("gear", "theta"), -R2)), 3e8, backlash=1e-4, teeth=20, xi0=0.1)
    return SystemDescription(bodies=bodies, meshes=(mesh,), loads=tuple(Load(b, "theta", t) for b, t in loads))


def test_pair_with_a_torque_on_one_gear_is_refused_with_the_output_torque_named():
    # the mesh deflection R1 θ1 − R2 θ2 is zero on the free rotation (θ1, θ2) = (R2, R1): the loads do the work
    # T1 R2 + T2 R1 on it, balanced by T2 = −T1 R2/R1
    with pytest.raises(ModelError) as e:
        assemble(_pair([("pinion", 20.0)]))
    msg = str(e.value)
    assert msg.startswith("the loads drive the free rotation of pinion, gear (no stiffness holds it")
    assert msg.endswith(f"a torque of {-20.0 * 0.09 / 0.03:.6g} N·m on gear.theta would balance them")
    assemble(_pair([("pinion", 20.0), ("gear", -60.0)]))  # balanced: T2 = −20 · 0.09/0.03 N·m
    with pytest.raises(ModelError, match="the loads drive the free rotation"):
        assemble(_pair([("pinion", 20.0), ("gear", 60.0)]))


def test_unbalanced_planetary_names_the_carrier_torque(tmp_path):
    """Lin & Parker's planetary (ring held, sun and carrier free) with a sun torque only.  Its free rotation, from
    the example's vectors: the planet bearings move the planet centres by r_c θ_c along the tangent, both lines of
    action make the angle α with it, so the sun mesh gives r_s θ_s + r_p θ_p = r_c cos α θ_c and the ring mesh
    r_p θ_p = −r_c cos α θ_c: θ_s/θ_c = 2 r_c cos α / r_s, and T_c = −T_s θ_s/θ_c balances."""
    r_s, r_c, alpha = 0.0387, 0.0884, math.radians(24.6)
    t_c = -1.0 * 2.0 * r_c * math.cos(alpha) / r_s
    text = (EXAMPLES / "planetary_lin_parker_1999.toml").read_text()
    f = tmp_path / "unbalanced.toml"
    f.write_text(text + '\n[[load]]\nbody = "sun"\ntorque = "1 N*m"\n')
    with pytest.raises(ModelError, match=f"a torque of {t_c:.6g} N·m on carrier.theta would balance them$"):
        load_system(f)
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err), pytest.raises(SystemExit) as ex:
        main(["simulate", "--system", str(f), "--omega", "0.8"])
    lines = err.getvalue().strip().splitlines()
    assert ex.value.code == 2 and len(lines) == 1
    assert lines[0].startswith(f"error: {f}: the loads drive the free rotation of carrier, sun, planet1")
    assert f"{t_c:.6g} N·m on carrier.theta" in lines[0]
    f.write_text(
        text + f'\n[[load]]\nbody = "sun"\ntorque = "1 N*m"\n[[load]]\nbody = "carrier"\ntorque = "{t_c!r} N*m"\n'
    )
    load_system(f)  # balanced to rounding


@pytest.mark.parametrize(
    "name", ["paper_torsional", "paper_bevel_8dof", "spur_bending_torsional", "planetary_lin_parker_1999"]
)
def test_the_examples_are_balanced(name):
    load_system(EXAMPLES / f"{name}.toml")
