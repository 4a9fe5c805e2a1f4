"""Torque orders on a multi-DOF system through the mesh-vector kernel and harmonic balance.

A linear system (the mesh never leaves contact: no backlash) forced by torque orders has the steady state
q(t) = K⁻¹F + Re Σ_o (K − Ω_o²M + iΩ_o C)⁻¹ F_o e^{iφ_o} e^{iΩ_o t}: solved here in SI units from the file's
values, independently of the kernel, and compared with the simulation's Poincaré state (θ = 0).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from geardyn import IntegrationOptions, hb_solve, simulate
from geardyn.systems import load_description, load_system

R1, R2, I1, I2, K_MESH, XI = 23.8682e-3, 71.6047e-3, 1.751e-4, 6.828e-3, 3.2e8, 0.07
RPM = 12000.0
B_C = 0.05e-3
#: (order of the pinion's speed, amplitude N·m, phase deg)
ORDERS = ((8, 5.0, 30.0), (16, 2.0, -50.0))


def _file(tmp_path, *, sparse=False, backlash="0 mm", ground=True, orders=ORDERS):
    """A spur pair on bearings (the spur example's values), held in torsion by springs to ground, the pinion's
    torque with two orders; ``sparse`` adds the z translations and two coupled bodies (10 DOFs: the kernel's
    sparse step; 6 DOFs take its dense step)."""
    dofs = '["x", "y", "z", "theta"]' if sparse else '["x", "y", "theta"]'
    kz = 'kz = "5e7 N/m"\ncz = "1e4 N*s/m"\n' if sparse else ""
    orders = ", ".join(f'{{ order = {o}, amplitude = "{a} N*m", phase = "{p} deg" }}' for o, a, p in orders)
    text = f"""
title = "linear spur pair with torque orders"
[system]
reference = "mesh"
characteristic_length = "{B_C * 1e3} mm"
[operating]
rpm = "{RPM} rpm"
[[body]]
name = "pinion"
dofs = {dofs}
mass = "1.2728 kg"
inertia = "{I1} kg*m^2"
[[body]]
name = "gear"
dofs = {dofs}
mass = "3.5367 kg"
inertia = "{I2} kg*m^2"
[[connection]]
name = "pinion_bearing"
body = "pinion"
kx = "8.5364e7 N/m"
ky = "8.5364e7 N/m"
cx = "2.134e4 N*s/m"
cy = "2.134e4 N*s/m"
{kz}{'ktheta = "2e4 N*m/rad"' if ground else ""}
{'ctheta = "2 N*m*s/rad"' if ground else ""}
[[connection]]
name = "gear_bearing"
body = "gear"
kx = "8.5364e7 N/m"
ky = "8.5364e7 N/m"
cx = "2.134e4 N*s/m"
cy = "2.134e4 N*s/m"
{kz}ktheta = "1e5 N*m/rad"
ctheta = "20 N*m*s/rad"
[[mesh]]
name = "mesh"
type = "spur"
pinion = "pinion"
gear = "gear"
teeth = 16
pressure_angle = "20 deg"
base_radius1 = "{R1 * 1e3} mm"
base_radius2 = "{R2 * 1e3} mm"
center_angle = "0 deg"
pinion_rotation = "counterclockwise"
stiffness = "{K_MESH} N/m"
xi0 = {XI}
backlash = "{backlash}"
[[load]]
body = "pinion"
torque = "20 N*m"
orders = [{orders}]
[[load]]
body = "gear"
torque = "-60 N*m"
"""
    if sparse:
        text += """
[[body]]
name = "motor"
dofs = ["theta"]
inertia = "2e-3 kg*m^2"
[[body]]
name = "brake"
dofs = ["theta"]
inertia = "5e-2 kg*m^2"
[[connection]]
name = "input_coupling"
kind = "torsional"
vector = { motor = { theta = 1.0 }, pinion = { theta = -1.0 } }
stiffness = "3e4 N*m/rad"
damping = "20 N*m*s/rad"
[[connection]]
name = "output_coupling"
kind = "torsional"
vector = { gear = { theta = 1.0 }, brake = { theta = -1.0 } }
stiffness = "2e5 N*m/rad"
damping = "200 N*m*s/rad"
"""
    p = tmp_path / ("sparse.toml" if sparse else "dense.toml")
    p.write_text(text)
    return p


def _exact_state(path) -> np.ndarray:
    """The steady state (q̃, q̃') at t = 0 from the SI matrices: the mean load's static deflection plus every
    order's harmonic response, scaled by the file's b_c, base radii and ω_n."""
    desc = load_description(path)
    M = desc.mass_matrix()
    Kb, Cb = desc.bearing_matrices()
    (mesh,) = desc.meshes
    v = desc.vector(mesh)
    m_e = 1.0 / (R1**2 / I1 + R2**2 / I2)
    K = Kb + K_MESH * np.outer(v, v)
    C = Cb + XI * 2.0 * math.sqrt(K_MESH * m_e) * np.outer(v, v)
    labels = desc.labels
    F = np.zeros(len(labels))
    F[labels.index("pinion.theta")] = 20.0
    F[labels.index("gear.theta")] = -60.0
    q = np.linalg.solve(K, F).astype(complex)
    qd = np.zeros(len(labels), complex)
    speed = 2.0 * math.pi * RPM / 60.0
    for order, amp, ph in ORDERS:
        W = order * speed
        Fo = np.zeros(len(labels))
        Fo[labels.index("pinion.theta")] = amp
        X = np.linalg.solve(K - W**2 * M + 1j * W * C, Fo * np.exp(1j * math.radians(ph)))
        q += X
        qd += 1j * W * X
    radius = {"pinion": R1, "gear": R2}
    s = np.array([B_C / radius.get(lb.split(".")[0], 1.0) if lb.endswith("theta") else B_C for lb in labels])
    w_n = math.sqrt(K_MESH / m_e)
    return np.concatenate([q.real / s, qd.real / s / w_n])


@pytest.mark.parametrize("sparse", [False, True])
@pytest.mark.parametrize("accurate", [False, True])
def test_linear_system_with_orders_is_its_exact_steady_state(tmp_path, sparse, accurate):
    """RK4 at Δτ = 0.02 against the exact steady state: measured 1.0e-11 of the largest coordinate (6 DOFs,
    the default mode; 4.0e-10 at Δτ = 0.05, the fourth order's ratio) and 1.8e-9 (10 DOFs, whose couplings'
    modes decay slowest)."""
    path = _file(tmp_path, sparse=sparse)
    s = load_system(path)
    assert s.n == (10 if sparse else 6) and s.period_multiple() == 2  # orders 8 and 16 of 16 teeth: 1/2 and 1
    exact = _exact_state(path)
    res = simulate(s, IntegrationOptions(dtau=0.02, transient=100, periods=1, accurate=accurate))
    got = np.asarray(res.to_json()["poincare_state"][0])
    assert np.max(np.abs(got - exact)) < 1e-8 * np.max(np.abs(exact))
    # the orders matter: without them the state is the static deflection, far from the exact one
    quiet = simulate(replace(s, orders=()), IntegrationOptions(dtau=0.02, transient=2))
    assert np.max(np.abs(np.asarray(quiet.to_json()["poincare_state"][0]) - exact)) > 1e-3 * np.max(np.abs(exact))


def test_harmonic_balance_of_the_linear_system_is_exact(tmp_path):
    """HB places each order at its harmonic of the response period (r_o times the base periods of the forcing
    period): its state at θ = 0 is the exact steady state."""
    path = _file(tmp_path)
    sol = hb_solve(load_system(path), 8, guess="linear")
    assert sol.converged
    exact = _exact_state(path)
    assert np.max(np.abs(sol.state() - exact)) < 1e-9 * np.max(np.abs(exact))


def test_harmonic_balance_equals_simulation_with_contact_loss(tmp_path):
    """The pinion free in torsion (its torque reaches ground through the mesh), backlash 0.1 mm and an 8th order
    of 30 N·m: the mesh leaves contact once a period.  HB's state at θ = 0 against the simulation's (accurate
    mode, Δτ = 0.02): measured 3.1e-5 (H = 16), 5.8e-6 (H = 32), 1.3e-7 (H = 64), the dead zone's algebraic
    convergence."""
    path = _file(tmp_path, backlash="0.1 mm", ground=False, orders=((8, 30.0, 30.0), (16, 2.0, -50.0)))
    s = load_system(path)
    res = simulate(s, IntegrationOptions(dtau=0.02, transient=30, periods=4, accurate=True))
    out = res.to_json()
    assert out["motion"] == "period-1" and out["u_min"] < s.meshes[0].D < out["u_max"]  # contact lost
    x = np.asarray(out["poincare_state"][-1])
    errs = []
    for H in (16, 64):
        sol = hb_solve(s, H, guess="simulate")
        assert sol.converged
        errs.append(np.max(np.abs(sol.state() - x)))
    assert errs[1] < 1e-6 and errs[1] < errs[0] / 10, errs


def test_orders_survive_a_result_attribute(tmp_path):
    from fractions import Fraction

    from geardyn.systems import SystemModel

    s = load_system(_file(tmp_path))
    back = SystemModel.from_attrs(s.to_attrs())
    assert [(r, ph) for r, _, ph in back.orders] == [
        (Fraction(1, 2), math.radians(30)),
        (Fraction(1), -math.radians(50)),
    ]
    for (_, a, _), (_, b, _) in zip(back.orders, s.orders):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("accurate", [False, True])
def test_two_gear_rattle_system_through_the_kernel_is_its_pair(accurate):
    """The idle-rattle example (two gears, one mesh, an engine order) integrated by the mesh-vector kernel and, as
    its 1-DOF pair (:func:`~geardyn.analysis.rattle.pair_of_system`), by the pair's kernel: the same relative
    coordinate at every Poincaré point of two forcing periods (29 mesh cycles each), the gears flying through the
    backlash (measured 2e-13 in the default mode)."""
    from geardyn import integrate_batch
    from geardyn.analysis.rattle import pair_of_system

    s = load_system("examples/gearbox/rattle_idle.toml")
    m = pair_of_system(s)
    assert s.period_multiple() == m.period_multiple() == 29
    opts = IntegrationOptions(dtau=0.05, transient=0, periods=2, accurate=accurate)
    a = integrate_batch([s], s.initial_state(1.5, 0.0)[None, :], opts)
    b = integrate_batch([m], np.array([[1.5, 0.0]]), opts)
    v = s.V[0]
    u = a.poincare[0, :, : s.n] @ v
    du = a.poincare[0, :, s.n :] @ v
    np.testing.assert_allclose(u, b.poincare[0, :, 0], rtol=0, atol=1e-10)
    np.testing.assert_allclose(du, b.poincare[0, :, 1], rtol=0, atol=1e-10)
    assert np.max(a.contact_fractions) < 1.0  # the flight through the backlash is part of it
