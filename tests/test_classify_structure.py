"""The classifier never emits a label the model's structure forbids, and a converging orbit is not a longer cycle.

* The 1-DOF pair's period map contracts every area by det = exp(−4πξ0/ω) (Liouville: the mean trace of the
  Jacobian is −2ξ0), so for ξ0 > 0 no invariant closed curve, and no quasi-periodic attractor, exists.
* A period-2 orbit converging with a multiplier near −1 repeats after 4 periods to within the tolerance long
  before it repeats after 2: it is not a period-4 orbit.  The independent reference is shooting (Newton on the
  period map) for a stable period-2 orbit.
"""

from __future__ import annotations

import numpy as np

from geardyn.analysis.classify import (
    MOTION_PERIODIC,
    MOTION_QUASIPERIODIC,
    MOTION_UNRESOLVED,
    classify_motion,
    converging_to_divisor,
    detect_period,
    detect_periods,
    quasi_periodic_allowed,
    quasi_periodic_allowed_batch,
)
from geardyn.analysis.periodic import shoot
from geardyn.analysis.steady import simulate
from geardyn.model import GearModel
from geardyn.pairpack import PointModels


def test_structure_forbids_quasi_periodicity_of_the_damped_pair():
    assert not quasi_periodic_allowed(GearModel())  # ξ0 = 0.1: area contracting
    assert quasi_periodic_allowed(GearModel(xi0=0.0))  # conservative in the mean: a torus is possible
    assert quasi_periodic_allowed(GearModel(xi0=-0.1))
    pm = PointModels(GearModel(), ("omega", "xi0"), np.array([[1.0, 0.1], [1.0, 0.0], [1.2, 0.05]]))
    assert quasi_periodic_allowed_batch(pm).tolist() == [False, True, False]
    pm = PointModels(GearModel(), ("omega",), np.array([[1.0], [1.3]]))
    assert quasi_periodic_allowed_batch(pm).tolist() == [False, False]


def test_a_forbidden_quasi_periodic_label_is_unresolved():
    # |λ1| inside the band, a stationary closed curve: quasi-periodic where allowed, unresolved where forbidden
    args = ([0, 0], [0.0, 0.0], [1e-4, 1e-4], [True, True], [1.0, 1.0], [1.0, 1.0])
    assert classify_motion(*args).tolist() == [MOTION_QUASIPERIODIC] * 2
    assert classify_motion(*args, quasi_allowed=[True, False]).tolist() == [MOTION_QUASIPERIODIC, MOTION_UNRESOLVED]
    # a periodic point stays periodic whatever the structure
    assert classify_motion([2], [-0.1], [1e-4], quasi_allowed=False).tolist() == [MOTION_PERIODIC]


def test_converging_period_two_is_not_period_four():
    """A period-2 cycle approached with the multiplier μ = −0.96 of the doubled map: differences over 4
    periods fall below the tolerance long before those over 2 do."""
    k = np.arange(200)
    cycle = np.where(k % 2 == 0, 0.85, -1.0)
    dev = 2e-5 * (-0.96) ** (k // 2)  # the deviation from the cycle, multiplied by μ every two periods
    pts = np.column_stack([cycle + dev, 0.3 + 0.5 * dev])
    d2 = np.max(np.abs(pts[-100 + 2 :] - pts[-100:-2]))
    d4 = np.max(np.abs(pts[-100 + 4 :] - pts[-100:-4]))
    assert d4 <= 1e-6 < d2  # the bare test would call it period-4
    assert converging_to_divisor(pts, 4, 100)
    assert detect_period(pts) == 0
    assert detect_periods(pts[None]).tolist() == [0]
    # a true period-4 cycle (stationary differences over 2 periods) keeps its period
    true4 = np.column_stack([np.tile([0.1, 0.5, 0.2, 0.7], 50), np.tile([0.0, 0.3, 0.1, 0.2], 50)])
    assert detect_period(true4) == 4 and detect_periods(true4[None]).tolist() == [4]


def test_simulate_at_omega_1_15_backlash_0_7_is_period_two():
    """The slowly converging orbit at ω = 1.15, D = 0.7 (paper defaults otherwise) is a stable period-2 orbit,
    confirmed by shooting from its last Poincaré point."""
    m = GearModel(omega=1.15, D=0.7)
    s = simulate(m)
    assert s.summary["motion"] == "period-2" and s.summary["period"] == 2
    orb = shoot(m, 2, guess=np.asarray(s.poincare[-1], dtype=float))
    assert orb.converged and orb.stable and orb.minimal_period == 2


def test_a_signal_while_the_program_imports_leaves_with_130():
    """The ``geardyn`` program leaves with 130 and one line on a SIGINT that arrives while its modules are
    still being imported (before the command's own handlers run)."""
    import os
    import subprocess
    import sys

    code = (
        "import os, signal, sys; sys.argv[0] = 'geardyn'; import geardyn.cli; "
        "os.kill(os.getpid(), signal.SIGINT); import time; time.sleep(5); print('lost')"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=env)
    assert r.returncode == 130 and r.stdout == "" and r.stderr == "interrupted\n"


_THREE_INERTIAS = """
title = "Three inertias: a lightly damped shaft on the paper's torsional pair, never in contact loss"
[system]
reference = "mesh"
[[body]]
name = "pinion"
dofs = ["theta"]
inertia = "1.772 kg*m^2"
[[body]]
name = "gear"
dofs = ["theta"]
inertia = "1.873 kg*m^2"
[[body]]
name = "motor"
dofs = ["theta"]
inertia = "0.5 kg*m^2"
[[mesh]]
name = "mesh"
type = "bevel"
pinion = "pinion"
gear = "gear"
z1 = 23
z2 = 47
m_mn = "7.28 mm"
beta_m = "35 deg"
alpha_n = "20 deg"
Sigma = "90 deg"
r1 = "125.5 mm"
r2 = "256 mm"
hand = "left"
drive_side = "concave"
backlash = "0.1 mm"
stiffness = "2000 N/um"
xi0 = 0.1
kappa = [0.2]
eps = [0.5]
[[load]]
mesh = "mesh"
fp = 3.0
[[connection]]
name = "shaft"
vector = { motor = { theta = 1.0 }, pinion = { theta = -1.0 } }
kind = "torsional"
stiffness = "2e5 N*m/rad"
damping = "0.001 N*m*s/rad"
"""


def test_a_slowly_decaying_mode_is_not_a_torus(tmp_path):
    """A linear, periodically forced, stable system has one periodic steady state (Floquet): its response is
    never quasi-periodic.  With the mesh always in contact (f_p = 3, no impact) the three-inertia system is linear
    with periodic coefficients; its shaft mode is damped at σ_min ≈ 6e-7 per τ, far inside the band within which a
    Lyapunov exponent counts as zero (LLE_FLOOR = 1e-4).  After a short transient the shaft mode still rings at its
    own frequency, so the Poincaré points lie on a closed curve and λ1 is zero within the band: the old rule
    called this quasi-periodic.  The slow decay makes it unresolved."""
    from geardyn.analysis.classify import LLE_FLOOR, classify_motion, decay_hides_torus
    from geardyn.analysis.settle import decay_rate
    from geardyn.model import IntegrationOptions
    from geardyn.systems import load_system

    f = tmp_path / "three.toml"
    f.write_text(_THREE_INERTIAS)
    s = load_system(f).with_param("omega", 0.8)
    sigma = decay_rate(s)
    assert 0.0 < sigma < 1e-2 * LLE_FLOOR
    r = simulate(s, options=IntegrationOptions(transient=5, periods=100)).summary
    assert r["impact"] == "no impact"
    assert r["motion"] == "unresolved"
    lle, err = r["lle"], r["lle_err"]
    assert abs(lle) <= 3 * err + LLE_FLOOR  # neutral within the band: what made it look like a torus
    # the same exponent on a model without the slow mode's σ (unknown) is labelled quasi-periodic by the band alone
    assert classify_motion(0, lle, err, True, 1.0, 1.0) == MOTION_QUASIPERIODIC
    assert decay_hides_torus(sigma, LLE_FLOOR)


def test_a_short_transient_on_a_slow_mode_is_said_before_the_run(tmp_path):
    """The CLI says, before the run, that the transient leaves the least damped mode undecayed: σ_min · T_f · N
    e-folds (T_f = 2π/ω, one mesh cycle), and the count ``auto`` needs for e^-12."""
    import math

    from cli_run import run_cli

    from geardyn.analysis.settle import decay_rate
    from geardyn.systems import load_system

    f = tmp_path / "three.toml"
    f.write_text(_THREE_INERTIAS)
    sigma = decay_rate(load_system(f).with_param("omega", 0.8))
    code, _out, err = run_cli(["simulate", "--system", str(f), "--omega", "0.8", "--transient", "5", "--periods", "4"])
    assert code == 0
    folds = sigma * 5 * 2.0 * math.pi / 0.8
    need = math.ceil(12.0 / (sigma * 2.0 * math.pi / 0.8))
    assert f"5 forcing periods decay the least damped mode (e^(-{sigma:.3g} τ)) to e^-{folds:.3g} only" in err
    assert f"e^-12 needs {need} (--transient auto)" in err
