"""The defaults of a run whose forcing period spans several reference mesh cycles
(``geardyn.analysis.settle.long_run``): the transient from the least damped mode's decay, the record in mesh
cycles, the classification's budget, the notes before the run; and the pair's defaults unchanged."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from geardyn import GearModel
from geardyn.analysis.settle import (
    CLASSIFY_CYCLES,
    CLASSIFY_SECTION,
    DECAY_EFOLDS,
    RECORD_FLOOR,
    classify_budget,
    decay_rate,
    long_run,
)
from geardyn.model import DEFAULT_PERIODS, DEFAULT_TRANSIENT
from geardyn.systems import Body, Connection, Mesh, SystemDescription, assemble

ROOT = Path(__file__).resolve().parents[1]
TWO_STAGE = ROOT / "tests" / "data" / "two_stage_12dof.toml"

# A linear 2-DOF torsional system: two wheels on torsional springs to ground, one mesh without backlash, damping
# proportional to stiffness (C = βK), and a forcing period of 64 mesh cycles (a table period, no harmonics: nothing
# varies, the system is linear and time-invariant).
I_A, I_B = 0.01, 0.04  # kg m^2
R_A, R_B = 0.05, 0.1  # m
K_M = 1e8  # N/m
K_A, K_B = 1e4, 4e4  # N m/rad
BETA = 8.5e-5  # s
OMEGA = 0.5
P = 64


def _linear_two_dof() -> SystemDescription:
    bodies = (Body("a", ("theta",), inertia=I_A), Body("b", ("theta",), inertia=I_B))
    conns = (
        Connection("ground_a", (("a", "theta"),), ((K_A,),), ((BETA * K_A,),)),
        Connection("ground_b", (("b", "theta"),), ((K_B,),), ((BETA * K_B,),)),
    )
    mesh = Mesh("m", ((("a", "theta"), R_A), (("b", "theta"), -R_B)), K_M, c0=BETA * K_M, cycles=P)
    return SystemDescription(bodies=bodies, meshes=(mesh,), connections=conns, characteristic_length=1e-5, omega=OMEGA)


def _hand_decay() -> float:
    """σ_min per unit τ by hand: with C = βK the modes decouple; ω_i² are the roots of
    det(K − ω² M) = 0 (a quadratic) and each underdamped mode decays at β ω_i² / 2 (1/s); τ = ω_n t with
    ω_n² = k_m / m_e, m_e = 1/(R_a²/I_a + R_b²/I_b) (the reference mesh's rotational equivalent mass)."""
    k11, k22, k12 = K_A + K_M * R_A**2, K_B + K_M * R_B**2, -K_M * R_A * R_B
    tr = k11 / I_A + k22 / I_B
    det = (k11 * k22 - k12**2) / (I_A * I_B)
    w1sq = 0.5 * (tr - math.sqrt(tr * tr - 4.0 * det))
    w2sq = 0.5 * (tr + math.sqrt(tr * tr - 4.0 * det))
    assert BETA * math.sqrt(w2sq) / 2 < 1.0  # both modes underdamped: σ_i = β ω_i² / 2
    m_e = 1.0 / (R_A**2 / I_A + R_B**2 / I_B)
    return BETA * w1sq / 2.0 / math.sqrt(K_M / m_e)


def test_transient_from_the_least_damped_mode_of_a_linear_two_dof_system():
    s = assemble(_linear_two_dof())
    assert s.period_multiple() == P and s.n == 2
    sigma = _hand_decay()
    assert decay_rate(s) == pytest.approx(sigma, rel=1e-10)
    T_f = P * 2.0 * math.pi / OMEGA  # the forcing period in τ
    want = math.ceil(DECAY_EFOLDS / sigma / T_f)  # 12/σ = 1996 τ over T_f = 804.2 τ: 3
    assert want == 3
    plan = long_run(s, 0.01)
    assert plan.transient == want and plan.cycles == P
    assert plan.steps == math.ceil(T_f / 0.01)
    # the record: the default's 200 mesh cycles in forcing periods, at least the floor
    assert plan.periods == max(RECORD_FLOOR, math.ceil(DEFAULT_PERIODS / P)) == 4
    # what is given stays as given
    given = long_run(s, 0.01, transient=7, periods=9)
    assert (given.transient, given.periods) == (7, 9)


def test_a_mode_without_decay_falls_back_to_the_fixed_count_in_mesh_cycles():
    d = _linear_two_dof()
    undamped = SystemDescription(
        bodies=d.bodies,
        meshes=(Mesh("m", d.meshes[0].vector, K_M, c0=0.0, cycles=P),),
        connections=tuple(Connection(c.name, c.dofs, c.stiffness) for c in d.connections),
        characteristic_length=1e-5,
        omega=OMEGA,
    )
    plan = long_run(assemble(undamped), 0.01)
    assert plan.transient == math.ceil(DEFAULT_TRANSIENT / P)  # 300 mesh cycles: 5 forcing periods
    assert "no decay time" in plan.transient_why


def test_one_mesh_cycle_keeps_the_fixed_defaults():
    assert long_run(GearModel(omega=0.8), 0.01) is None
    assert classify_budget(GearModel(omega=0.8)) == (1000, 4)


@pytest.mark.parametrize(("p", "budget"), [(2, (500, 4)), (64, (16, 3)), (1472, (16, 1))])
def test_classification_budget_in_mesh_cycles(p, budget):
    n, rounds = classify_budget(GearModel(omega=0.8, cycles=p))
    assert (n, rounds) == budget
    assert n >= CLASSIFY_SECTION and (n * rounds * p <= CLASSIFY_CYCLES or rounds == 1)


def _cli(*args, timeout=1800):
    return subprocess.run(
        [sys.executable, "-m", "geardyn.cli", *args], capture_output=True, text=True, cwd=ROOT, timeout=timeout
    )


def test_pair_default_simulate_is_unchanged_and_says_no_plan():
    """The pair's forcing period is one mesh cycle: no long-run note, and the JSON that of the explicit fixed
    defaults (300 + 200 forcing periods)."""
    default = _cli("simulate", "--omega", "0.8", "--json")
    assert default.returncode == 0, default.stderr
    assert "forcing period" not in default.stderr and "estimate" not in default.stderr
    fixed = _cli("simulate", "--omega", "0.8", "--json", "--transient", "300", "--periods", "200")
    assert json.loads(default.stdout) == json.loads(fixed.stdout)


def test_two_stage_default_simulate_completes_and_says_its_forcing_period_and_estimate_first():
    """The 12-DOF 23/64-19/56 file: 64 stage-1 mesh cycles per forcing period.  The fixed defaults took 500
    forcing periods (204,946,000 steps) and, not found periodic, 1000 more per classification pass; the default
    now settles by the physics and records the default's mesh cycles: 15 s with the kernel compiled (the N-DOF kernel
    every system test compiles)."""
    r = _cli("simulate", "--system", str(TWO_STAGE), "--json")
    assert r.returncode == 0, r.stderr
    err = r.stderr
    assert "forcing period: 64 cycles of mesh 'stage1'" in err
    assert "409,892 RK4 steps per forcing period" in err
    # the counts chosen and why, and the estimate, before the run
    assert "transient: 2 forcing periods (128 mesh cycles): the least damped mode decays" in err
    assert "record: 4 forcing periods (256 mesh cycles)" in err
    assert "estimate: 2,459,352 RK4 steps (6 forcing periods of 409,892)" in err
    out = json.loads(r.stdout)
    assert out["status"] == "ok" and out["motion"] != "not periodic"
    if out["motion"].startswith("period-"):  # checked over the record: period in mesh cycles
        assert out["period"] % 64 == 0
    assert np.isfinite(out["amplitude"])


def test_history_of_a_long_forcing_period_is_bounded_in_memory():
    """32 forcing periods of the 12-DOF file's history would be 13.1e6 steps of 24 states and 2 meshes' δ, δ'
    (2.9 GB); simulate keeps the last whole stage-1 mesh cycles within HISTORY_BYTES."""
    from geardyn.analysis.steady import HISTORY_BYTES, HISTORY_PERIODS, history_budget
    from geardyn.integrate import natural_steps
    from geardyn.model import IntegrationOptions
    from geardyn.systems import load_system

    s = load_system(TWO_STAGE)
    p = s.period_multiple()
    opts = IntegrationOptions(transient=2, periods=40)
    N = natural_steps(s, opts.dtau)
    per_sample = 8 * (s.state_dim + 2 * len(s.elements))
    steps, cycles = history_budget(s, opts, HISTORY_PERIODS)
    assert steps * per_sample <= HISTORY_BYTES + per_sample  # within the budget (to the rounding of one step)
    assert (steps + N / p) * per_sample > HISTORY_BYTES - per_sample  # and the most whole mesh cycles that fit
    assert abs(cycles - round(cycles)) <= p / N  # whole mesh cycles, to one step
    assert history_budget(s, IntegrationOptions(transient=2, periods=1, dtau=0.5), HISTORY_PERIODS) == (None, None)
    assert history_budget(GearModel(omega=0.8, cycles=1000), opts, HISTORY_PERIODS) == (None, None)  # the pair


def test_partial_history_is_the_end_of_the_full_one(monkeypatch):
    """With a small memory budget simulate keeps the last whole mesh cycles: the same samples as the end of the full
    history (the same trajectory, bit for bit), and a spectrum in mesh orders whose stage-1 mesh line (order 1) is
    that of the full history's to 2 %."""
    from geardyn.analysis import steady
    from geardyn.model import IntegrationOptions
    from geardyn.systems import load_system

    s = load_system(TWO_STAGE)
    opts = IntegrationOptions(transient=2, periods=4)
    full = steady.simulate(s, opts, history_periods=1)
    monkeypatch.setattr(steady, "HISTORY_BYTES", 2 * 2**20)
    part = steady.simulate(s, opts, history_periods=1)
    L = part.traj.u.size
    assert part.history_cycles is not None and L < full.traj.u.size
    assert np.array_equal(part.traj.u, full.traj.u[-L:])
    assert any("time history: the last" in n for n in part.summary["notes"]) and "notes" not in full.summary
    assert part.summary["amplitude"] == full.summary["amplitude"]  # the statistics stream over the whole record
    dp, df = part.to_dataset(), full.to_dataset()
    assert float(dp.attrs["history_cycles"]) == pytest.approx(part.history_cycles, rel=1e-5)
    a_part = float(dp["spectrum"].sel(order=1.0, method="nearest"))
    a_full = float(df["spectrum"].sel(order=1.0, method="nearest"))
    assert a_part == pytest.approx(a_full, rel=0.02)


def test_budget_ending_before_a_class_is_said_and_nothing_unchecked_is_periodic(monkeypatch):
    """A pair with a forcing period of 2 mesh cycles, no transient and 4 recorded periods: still decaying
    (e^(-ξ0 τ), e^-1.57 per forcing period at ω = 0.8), so not periodic; one classification pass of 4 forcing
    periods (a budget made small here) cannot settle it either: the motion is 'unresolved' and a note says the
    budget ended; no period is claimed."""
    from geardyn.analysis import steady
    from geardyn.model import IntegrationOptions

    monkeypatch.setattr(steady, "classify_budget", lambda model: (4, 1))
    res = steady.simulate(GearModel(omega=0.8, cycles=2), IntegrationOptions(transient=0, periods=4))
    s = res.summary
    assert s["motion"] == "unresolved" and s["period"] is None
    assert s["lle"] is not None and s["lle"] < 0  # the decay: significantly negative, no class
    (note,) = s["notes"]
    assert note.startswith("unresolved: the classification's budget ended before a class was found (1 pass(es) of 4")
    assert "notes" in res.to_json()
    # the pair's own budget (P = 1) says nothing of the kind
    one = steady.simulate(GearModel(omega=0.8), IntegrationOptions(transient=300, periods=8))
    assert one.summary["motion"] == "period-2" and "notes" not in one.summary


def test_a_sweeps_default_settling_pass_follows_the_forcing_period():
    """``--settle`` not given: 1000 forcing periods of one mesh cycle (the pair: unchanged), max(16, ⌈1000/P⌉) of
    P > 1 mesh cycles (the 12-DOF two-stage file: P = 64, 16 forcing periods = 1024 mesh cycles, where 1000 were
    64 000); a value given is taken as given."""
    from geardyn import GearModel, load_system
    from geardyn.cli.sweeps import _engine

    class _Inputs:  # the sweep command's inputs: only the engine's keywords are asked for
        def engine(self, stem):
            return {}

    def _settle(settle, model):
        return _engine(_Inputs(), "bifurcation", model, settle)["settle_periods"]

    two_stage = load_system(str(TWO_STAGE))
    assert two_stage.period_multiple() == 64
    assert (_settle(None, GearModel()), _settle(None, two_stage)) == (1000, 16)
    assert (_settle(None, GearModel(cycles=8)), _settle(None, GearModel(cycles=1472))) == (125, 16)
    assert _settle(500, two_stage) == 500


def test_the_time_budget_counts_steps_per_forcing_period_and_the_system_size():
    """The estimate before a run: N = ceil(P·2π/(ω Δτ)) steps per forcing period of P mesh cycles, each costing
    in proportion to the DOFs; the same run counted per mesh cycle of the pair (the old estimate) passes."""
    from geardyn.cli.output import SYSTEM_STEP_SECONDS_PER_DOF, check_budget
    from geardyn.errors import ModelError
    from geardyn.integrate import IntegrationOptions

    opts = IntegrationOptions(dtau=0.05, transient=1, periods=1)
    w, points, p, dofs = 0.1, 400, 1472, 110
    steps = math.ceil(p * 2 * math.pi / w / 0.05)
    check_budget(opts, [w], points)  # one mesh cycle of the 1-DOF pair's lanes: seconds
    with pytest.raises(ModelError) as err:
        check_budget(opts, [w], points, cycles=p, dofs=dofs)
    msg = str(err.value)
    assert f"{steps:.3g} steps per forcing period (110 DOF)" in msg
    assert f"{points * 2 * steps:.3g} RK4 steps" in msg
    import numba

    seconds = points * 2 * steps * SYSTEM_STEP_SECONDS_PER_DOF * dofs / max(1, numba.config.NUMBA_NUM_THREADS)
    assert seconds > 3600  # the default budget: refused before computing
