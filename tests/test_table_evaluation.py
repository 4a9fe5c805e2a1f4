"""A mesh stiffness and STE table evaluated as given (piecewise linear with jumps) in the accurate mode.

References: SciPy DOP853 integrating the same piecewise-linear right-hand side segment by segment (restarted
at every node and at every contact-boundary crossing), and the closed-form Fourier series of a square wave.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn.integrate import integrate_batch
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.tooth.excitation import Excitation, excitation_model, piecewise_series

#: A table with two jumps of the stiffness, one of the STE, and kinks (phases in mesh cycles).
PHASE = (0.0, 0.1, 0.3183098861837907, 0.3183098861837907, 0.55, 0.7071067811865476, 0.7071067811865476, 0.9)
K_REL = (1.25, 1.2, 1.1, 0.7, 0.8, 0.75, 1.15, 1.3)
E_REL = (0.0, 0.02, 0.05, 0.05, 0.01, -0.03, 0.02, 0.01)


def _segments(phase, values, period):
    """Independent reading of the table: per distinct phase, its left/right value and the right segment's slope."""
    phase, values = np.asarray(phase, float), np.asarray(values, float)
    xs = sorted(set(phase))
    left = [values[np.flatnonzero(phase == x)[0]] for x in xs]
    right = [values[np.flatnonzero(phase == x)[-1]] for x in xs]
    slope = []
    for j, x in enumerate(xs):
        xn, vn = (xs[j + 1], left[j + 1]) if j + 1 < len(xs) else (xs[0] + period, left[0])
        slope.append((vn - right[j]) / (xn - x))
    return xs, left, right, slope


def reference(model: GearModel, state0, periods: int) -> np.ndarray:
    """Poincaré points (state at θ ≡ 0⁻) by DOP853, node by node, restarted at each contact crossing."""
    P = model.cycles
    w = model.forcing_omega
    phase, k, e = model.table
    e = e or (0.0,) * len(k)
    xs, kl, kr, ks = _segments(phase, k, P)
    _, el, er, es = _segments(phase, e, P)
    th = [2.0 * math.pi * x / P for x in xs]
    kss = [s * P / (2.0 * math.pi) for s in ks]  # slopes per radian of the forcing phase
    ess = [s * P / (2.0 * math.pi) for s in es]
    D, fp, c = model.D, model.fp, 2.0 * model.xi0
    m = len(th)

    def f(u):
        return u - min(max(u, -D), D)

    def run(t0, t1, y, K0, Ks, base):
        """From t0 to t1 on one segment K = K0 + Ks (ωt − base), restarted at each crossing of u = ±D."""

        def rhs(t, y):
            return [y[1], fp - c * y[1] - (K0 + Ks * (w * t - base)) * f(y[0])]

        events = [lambda t, y, b=b: y[0] - b for b in (D, -D)] if D > 0 else None
        for ev in events or ():
            ev.terminal = True
        while t0 < t1:
            sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-14, events=events)
            y, t0 = sol.y[:, -1], sol.t[-1]
            if sol.status == 1:  # on the boundary: a short step past it without the events, then on
                crossings.append(t0)
                step = min(t1, t0 + 1e-7)
                y = solve_ivp(rhs, (t0, step), y, method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
                t0 = step
        return np.asarray(y, float)

    T = 2.0 * math.pi / w
    y = np.asarray(state0, float)
    out = []
    crossings = reference.crossings = []
    for p in range(periods):
        t = p * T
        if th[0] > 0:  # the wrap segment from the last node, one period back
            y = run(t, t + th[0] / w, y, kr[-1], kss[-1], th[-1] - 2.0 * math.pi + 2.0 * math.pi * p)
        for j in range(m):
            y = y + np.array([-(er[j] - el[j]), -w * (ess[j] - ess[j - 1])])  # the STE's jump and kink
            t_end = (t + th[j + 1] / w) if j + 1 < m else (p + 1) * T
            y = run(t + th[j] / w, t_end, y, kr[j], kss[j], th[j] + 2.0 * math.pi * p)
        out.append(y)
    return np.array(out)


def _model(D=0.6, cycles=1, e=True, omega=0.8):
    base = GearModel(omega=omega, xi0=0.05, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=(), fp=0.3, D=D)
    ph = tuple(cycles * x for x in PHASE)
    k = np.asarray(K_REL) * 3.0e8
    exc = Excitation(k, np.asarray(E_REL) * 1e-5 if e else None, cycles, phase=np.asarray(ph))
    return excitation_model(base, exc, b_c=1e-5, evaluation="table", harmonics=3)


def _accurate(model, N, periods, state0=(0.9, 0.0)):
    return integrate_batch(
        [model], np.asarray(state0), IntegrationOptions(transient=0, periods=periods, accurate=True), steps=N
    ).poincare[0]


def test_constant_table_equals_plain_model():
    base = GearModel(omega=0.8, xi0=0.05, xi=(0.02,), phi_c=(0.3,), kappa=(), phi_k=(), eps=(), phi_e=(), fp=0.2, D=1.0)
    m = excitation_model(base, Excitation(np.full(64, 3.2e8), np.full(64, 2e-6)), b_c=1e-5, evaluation="table")
    assert m.evaluation == "table" and max(m.table[1]) == min(m.table[1]) == 1.0
    opts = IntegrationOptions(transient=10, periods=5, accurate=True)
    a = integrate_batch([base], None, opts).poincare[0]
    b = integrate_batch([m], None, opts).poincare[0]
    assert np.max(np.abs(a - b)) < 1e-12 * max(1.0, np.max(np.abs(a)))
    assert np.any(np.abs(a[:, 0]) > 1.0)  # the motion reaches contact


@pytest.mark.parametrize("cycles", [1, 3])
def test_piecewise_table_against_dop853(cycles):
    m = _model(cycles=cycles)
    ref = reference(m, (0.0, 0.0), 2)  # from rest in the dead zone
    got = _accurate(m, 1200 * cycles, 2, (0.0, 0.0))
    assert np.max(np.abs(got - ref)) < 1e-8
    assert len(reference.crossings) >= 2  # the motion leaves contact and comes back


def _rk4_through(model, N, periods, state0=(0.9, 0.0)):
    """Plain fixed-step RK4 evaluating the table as given at every stage, stepping straight through its jumps."""
    P, w = model.cycles, model.forcing_omega
    phase, k, _ = model.table
    xs, kl, kr, ks = _segments(phase, k, P)

    def K(theta):
        x = (theta * P / (2.0 * math.pi)) % P
        j = max(i for i in range(len(xs)) if xs[i] <= x) if x >= xs[0] else len(xs) - 1
        return kr[j] + ks[j] * ((x - xs[j]) % P)

    def acc(t, u, v):
        return model.fp - 2.0 * model.xi0 * v - K(w * t) * (u - min(max(u, -model.D), model.D))

    h = 2.0 * math.pi / w / N
    u, v = state0
    for n in range(N * periods):
        t = n * h
        k1 = acc(t, u, v)
        k2 = acc(t + h / 2, u + h / 2 * v, v + h / 2 * k1)
        k3 = acc(t + h / 2, u + h / 2 * (v + h / 2 * k1), v + h / 2 * k2)
        u3, v3 = u + h * (v + h / 2 * k2), v + h * k3
        k4 = acc(t + h, u3, v3)
        u, v = (
            u + h / 6 * (v + 2 * (v + h / 2 * k1) + 2 * (v + h / 2 * k2) + v3),
            v + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4),
        )
    return np.array([u, v])


def test_order_with_and_without_splits():
    """Two stiffness jumps at 1/3 and 2/3 of the period; N ≡ 1 (mod 3) puts them at the same place in a step for
    every N, so the leading error constant does not change with N and the observed order is clean."""
    base = GearModel(omega=0.8, xi0=0.05, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=(), fp=0.3, D=0.0)
    exc = Excitation(np.array([1.2, 1.1, 0.7, 0.8, 1.15]) * 3e8, None, 1, phase=np.array([0, 1, 1, 2, 2]) / 3.0)
    m = excitation_model(base, exc, evaluation="table", harmonics=2)  # D = 0: the jumps are the only non-smoothness
    ref = reference(m, (0.9, 0.0), 2)[-1]
    Ns = np.array([49, 100, 199, 400, 799])
    split = [np.max(np.abs(_accurate(m, N, 2)[-1] - ref)) for N in Ns]
    through = [np.max(np.abs(_rk4_through(m, N, 2) - ref)) for N in Ns]
    order_split = -np.diff(np.log(split)) / np.diff(np.log(Ns))
    order_through = -np.diff(np.log(through)) / np.diff(np.log(Ns))
    assert np.all(np.abs(order_split - 4.0) < 0.1), (split, order_split)
    assert np.all(np.abs(order_through - 1.0) < 0.1), (through, order_through)
    assert split[-1] < 1e-9 < 1e-4 < through[-1]


def test_spur_jumps_at_the_contact_ratio(tmp_path):
    """A healthy spur pair without modifications: the pair count changes at phase 0 (a pair enters) and at
    ε_α − 1 (a pair leaves); the table gives both twice, and its other rows are the grid's."""
    from geardyn.tooth.config import load_case
    from geardyn.tooth.faults import Modifications
    from geardyn.tooth.mesh import mesh_stiffness
    from geardyn.tooth.table import read_table, table_of, write_table

    case = load_case("examples/tooth_healthy_spur.toml")
    ms = mesh_stiffness(case.geometry, case.torque, modifications=Modifications(), points=16)
    exc = table_of(ms, jumps=True)
    x, n = np.unique(exc.phase, return_counts=True)
    jumps = x[n == 2]
    assert jumps.size == 2 and jumps[0] == 0.0
    assert abs(jumps[1] - (case.geometry.eps_alpha - 1.0)) < 1e-9
    assert set(ms.phase) <= set(exc.phase) and exc.stiffness.size == 16 + 3
    i = np.flatnonzero(exc.phase == jumps[1])
    assert exc.stiffness[i[0]] > 1.4 * exc.stiffness[i[1]]  # two pairs, then one
    assert np.array_equal(read_table(write_table(exc, tmp_path / "j.csv")).phase, exc.phase)


def test_piecewise_series_of_a_square_wave():
    mean, amp, ph = piecewise_series(np.array([0.0, 0.0, 0.5, 0.5]), np.array([-1.0, 1.0, 1.0, -1.0]), 9)
    j = np.arange(1, 10)
    assert abs(mean) < 1e-15
    expect = np.where(j % 2 == 1, 4.0 / (math.pi * j), 0.0)  # 1 on (0, ½), −1 on (½, 1): Σ 4/(πj) sin(2πjx), j odd
    assert np.max(np.abs(amp - expect)) < 1e-14
    assert np.max(np.abs(ph[::2] + math.pi / 2)) < 1e-12


def test_table_refused_outside_the_accurate_mode():
    m = _model()
    with pytest.raises(ModelError, match="accurate mode only"):
        integrate_batch([m], None, IntegrationOptions(transient=1, periods=1))
    with pytest.raises(ModelError, match="at most twice"):
        m.replace(table=((0.0, 0.5, 0.5, 0.5), (1.0,) * 4, ()))
    assert GearModel.from_dict(m.to_dict()) == m


def test_rhs_evaluates_the_table():
    m = _model(cycles=3)
    xs, kl, kr, ks = _segments(m.table[0], m.table[1], 3)
    rng = np.random.default_rng(1)
    for x in np.r_[rng.uniform(0, 3, 50), np.array(xs) + 1e-9, 2.9]:  # mesh cycles; just past a node: its right value
        j = max(i for i in range(len(xs)) if xs[i] <= x)
        K = kr[j] + ks[j] * (x - xs[j])
        tau = 2 * math.pi * x / m.omega  # the mesh phase 2π x
        assert abs(m.rhs(tau, (1.7, 0.1))[1] - (m.fp - 2 * m.xi0 * 0.1 - K * (1.7 - m.D))) < 1e-12
