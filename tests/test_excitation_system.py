"""A system file's mesh with an excitation table over one pinion revolution (a cracked pinion tooth):
the forcing period P·2π/ω in every periodic tool, ω the mesh frequency."""

import re
from pathlib import Path

import numpy as np
import pytest

from geardyn.analysis.hb import hb_solve
from geardyn.analysis.lyapunov import lyapunov_spectrum
from geardyn.analysis.periodic import continuation
from geardyn.analysis.periodic.orbit import shoot
from geardyn.integrate import trajectory
from geardyn.model import IntegrationOptions
from geardyn.systems import load_system
from geardyn.tooth import Crack, mesh_stiffness, pair_geometry, table_of, write_table

ROOT = Path(__file__).resolve().parents[1]
P = 16


@pytest.fixture(scope="module")
def system(tmp_path_factory):
    d = tmp_path_factory.mktemp("exc")
    geo = pair_geometry(16, 48, 3.175e-3, face_width=0.016)
    ms = mesh_stiffness(geo, 20.0, faults=[Crack(0, 0, 0.5)], cycles=P, points=8)
    write_table(table_of(ms), d / "crack.csv")
    text = (ROOT / "examples/systems/paper_torsional.toml").read_text()
    text = re.sub(r"^rpm = .*$", "omega = 0.8", text, flags=re.M)
    text = re.sub(r"^stiffness = .*\n(.*\n)*?phi_e = .*$", 'excitation = "crack.csv"\nxi = [0.05]', text, flags=re.M)
    text = re.sub(r"^xi = \[0.05\]\nphi_c = .*\n", "", text, flags=re.M)
    (d / "system.toml").write_text(text)
    return load_system(d / "system.toml")


def test_the_mesh_frequency_stays_omega_and_the_forcing_period_is_a_revolution(system):
    m = system.meshes[0]
    assert system.omega == 0.8 and system.period_multiple() == P
    assert m.ratio == 1.0 / P and m.cycles == P and len(m.kappa) == 8 * P // 2
    assert m.xi[P - 1] > 0 and not any(m.xi[: P - 1])  # the damping harmonic stays mesh order 1
    assert system.sampling_period == pytest.approx(P * 2 * np.pi / 0.8, rel=1e-14)


def test_poincare_section_shooting_and_lyapunov(system):
    orb = shoot(system, 1, dtau=0.02)
    assert orb.converged
    tr = trajectory(system, orb.state, IntegrationOptions(dtau=0.02, transient=0, periods=2), history_periods=1)
    np.testing.assert_allclose(tr.poincare[-1], orb.state, atol=1e-7)
    ly = lyapunov_spectrum(system, IntegrationOptions(dtau=0.02, transient=5, periods=20), orb.state)
    # the rigid rotation gives exponents 0; the orbit keeps contact, so the system is linear periodic and the
    # exponents add up to the mean trace (Liouville)
    assert sum(ly.exponents) == pytest.approx(system.mean_trace(), abs=1e-8)


def test_continuation_and_harmonic_balance(system):
    orb = shoot(system, 1, dtau=0.005)
    hb = hb_solve(system, harmonics=4 * P)  # the stiffness's 64 harmonics of omega/16 (mesh orders to 4)
    assert hb.converged
    # the mesh deflection and the velocities at theta = 0 agree with shooting's (the free rotation's angle is
    # arbitrary); HB truncates the response at mesh order 4, shooting resolves the steps
    a, b = hb.state(), orb.state
    scale = abs(b[0] - b[1])
    assert abs((a[0] - a[1]) - (b[0] - b[1])) < 2e-3 * scale
    np.testing.assert_allclose(a[2:], b[2:], rtol=0, atol=2e-3 * scale)
    br = continuation(system, "omega", 0.8, 0.805, 1, dtau=0.02, accurate=False, max_points=8).branches[0]
    w = br.values
    assert w.size >= 2 and w.min() >= 0.8 - 1e-12 and w.max() <= 0.805 + 1e-12


def test_the_example_system_with_a_cracked_pinion_tooth_loads():
    s = load_system(ROOT / "examples/systems/spur_crack50.toml")
    m = s.meshes[0]
    assert s.period_multiple() == 16 and m.cycles == 16 and m.ratio == 1.0 / 16 and len(m.kappa) == 16 * 32 // 2
    assert s.omega == pytest.approx(s.scaling.omega_from_rpm(1800.0), rel=1e-12)
