"""The optimised kernel path against plain references, and its invariances.

The kernel advances parameter points in lock-step SIMD lanes (batches), or one at a time (single
points, histories); these tests check that both paths compute classic RK4 exactly as a plain loop
does (to rounding), agree with each other bit for bit, do not depend on the thread count or on
the batch a point is in, flag divergence, handle any number of harmonics, and keep the Liouville
identity λ1 + λ2 = −2ξ0.  No timing is asserted here (see ``benchmarks/``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn import _kernel as K
from geardyn import integrate as I
from geardyn.model import GearModel, IntegrationOptions
from geardyn.pairpack import steps_per_period

#: ω of the W1 grid (numpy.linspace(0.5, 1.5, 200)) whose steady motion is periodic (period 1 or 2).
W1_GRID = np.linspace(0.5, 1.5, 200)
PERIODIC_W1 = W1_GRID[[0, 20, 45, 62, 90, 100]]

#: Agreement demanded between the optimised path and the plain reference loop.
REF_TOL = 1e-12


# --------------------------------------------------------------------------- plain references
def reference_rk4(
    model: GearModel, n_transient: int, n_record: int, dtau: float = 0.01, state0: tuple[float, float] = (0.0, 0.0)
) -> np.ndarray:
    """Poincaré points from a plain classic-RK4 loop written from the model equation.

    u'' + 2[ξ0 + Σ ξ_k cos(kθ + φ_ck)] u' + [1 + Σ κ_r cos(rθ + φ_kr)] f(u) = f_p + ω² Σ l² ε_l cos(lθ + φ_el),
    θ = ωτ, h = T/ceil(T/Δτ); the coefficients are evaluated with math.cos at each stage angle.
    """
    w = model.omega
    T = 2.0 * math.pi / w
    N = math.ceil(T / dtau)
    h = T / N
    D = model.D

    def coefficients(theta: float) -> tuple[float, float, float]:
        C = 2.0 * model.xi0
        for k, (a, ph) in enumerate(zip(model.xi, model.phi_c), start=1):
            C += 2.0 * a * math.cos(k * theta + ph)
        Kc = 1.0
        for r, (a, ph) in enumerate(zip(model.kappa, model.phi_k), start=1):
            Kc += a * math.cos(r * theta + ph)
        F = model.fp
        for l_, (a, ph) in enumerate(zip(model.eps, model.phi_e), start=1):
            F += w * w * l_ * l_ * a * math.cos(l_ * theta + ph)
        return C, Kc, F

    def accel(u: float, v: float, coef: tuple[float, float, float]) -> float:
        C, Kc, F = coef
        dead = u - D if u > D else (u + D if u < -D else 0.0)
        return F - C * v - Kc * dead

    u, v = state0
    out = []
    for per in range(n_transient + n_record):
        for k in range(N):
            c0 = coefficients(2.0 * math.pi * k / N)
            c1 = coefficients(2.0 * math.pi * (k + 0.5) / N)
            c2 = coefficients(2.0 * math.pi * (k + 1) / N)
            k1u, k1v = v, accel(u, v, c0)
            k2u, k2v = v + 0.5 * h * k1v, accel(u + 0.5 * h * k1u, v + 0.5 * h * k1v, c1)
            k3u, k3v = v + 0.5 * h * k2v, accel(u + 0.5 * h * k2u, v + 0.5 * h * k2v, c1)
            k4u, k4v = v + h * k3v, accel(u + h * k3u, v + h * k3v, c2)
            u = u + h / 6.0 * (k1u + 2.0 * k2u + 2.0 * k3u + k4u)
            v = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        if per >= n_transient:
            out.append((u, v))
    return np.array(out)


@pytest.fixture
def threads():
    """Set the kernel thread count for a test and restore numba's setting afterwards."""
    import numba

    old = numba.get_num_threads()
    yield I.set_threads
    numba.set_num_threads(old)


def _assert_same(a: I.BatchResult, b: I.BatchResult, rows: slice | list | None = None) -> None:
    """Bit-identical results (NaN where NaN)."""
    sel = slice(None) if rows is None else rows
    for name in ("poincare", "end_state", "status", "stats"):
        np.testing.assert_array_equal(getattr(a, name)[sel], getattr(b, name)[sel], err_msg=name)
    if a.lyapunov_log is not None:
        np.testing.assert_array_equal(a.lyapunov_log[sel], b.lyapunov_log[sel], err_msg="lyapunov_log")
        np.testing.assert_array_equal(a.tangent[sel], b.tangent[sel], err_msg="tangent")


# --------------------------------------------------------------------------- against the plain loop
def test_batch_matches_plain_rk4_on_periodic_w1(threads):
    """The lane path (a batch of W1 ω) gives the plain loop's Poincaré points to 1e-12."""
    threads(1)
    opts = IntegrationOptions(transient=20, periods=6)
    models = [GearModel(omega=w) for w in PERIODIC_W1]
    res = I.integrate_batch(models, options=opts)
    assert np.all(res.status == I.ST_OK)
    for i, m in enumerate(models):
        ref = reference_rk4(m, opts.transient, opts.periods)
        np.testing.assert_allclose(res.poincare[i], ref, rtol=0, atol=REF_TOL, err_msg=f"omega={m.omega}")


def test_single_point_matches_plain_rk4():
    """The scalar path (one point) gives the plain loop's Poincaré points to 1e-12."""
    m = GearModel(omega=float(PERIODIC_W1[3]))
    opts = IntegrationOptions(transient=20, periods=6)
    res = I.integrate_batch([m], options=opts)
    np.testing.assert_allclose(res.poincare[0], reference_rk4(m, 20, 6), rtol=0, atol=REF_TOL)


def test_harmonics_and_phases_match_plain_rk4(threads):
    """Several harmonics per series, with phases, in a batch and alone, against the plain loop."""
    threads(1)
    opts = IntegrationOptions(transient=15, periods=5)
    base = dict(
        xi=(0.05, 0.01, 0.005),
        phi_c=(0.3, -0.2, 0.0),
        kappa=(0.2, 0.05),
        phi_k=(0.0, 1.1),
        eps=(0.5, 0.1, 0.0, 0.02),
        phi_e=(-0.4, 0.2, 0.0, 0.7),
    )
    models = [GearModel(omega=w, **base) for w in (0.55, 0.62, 0.7)]
    batch = I.integrate_batch(models, options=opts)
    for i, m in enumerate(models):
        ref = reference_rk4(m, opts.transient, opts.periods)
        np.testing.assert_allclose(batch.poincare[i], ref, rtol=0, atol=REF_TOL)
        alone = I.integrate_batch([m], options=opts)
        np.testing.assert_array_equal(batch.poincare[i], alone.poincare[0])
        np.testing.assert_array_equal(batch.stats[i], alone.stats[0])


@pytest.mark.slow
def test_w1_full_length_matches_plain_rk4(threads):
    """W1's full 300 + 200 periods on periodic ω against the plain loop (slow: pure Python)."""
    threads(1)
    opts = IntegrationOptions(transient=300, periods=200)
    models = [GearModel(omega=w) for w in PERIODIC_W1[:4]]
    res = I.integrate_batch(models, options=opts)
    for i, m in enumerate(models):
        np.testing.assert_allclose(res.poincare[i], reference_rk4(m, 300, 200), rtol=0, atol=REF_TOL)


# --------------------------------------------------------------------------- invariances
def test_lanes_and_scalar_paths_are_bit_identical(threads):
    """A point gives the same bits alone (scalar path) and inside a batch (lanes), every output."""
    threads(1)
    opts = IntegrationOptions(transient=8, periods=5)
    models = [GearModel(omega=w) for w in W1_GRID[::25]]
    models += [
        GearModel(omega=0.8, phi_c=(0.4,), phi_e=(1.0,)),
        GearModel(omega=1.3, D=0.0),
        GearModel(omega=1.1, kappa=(0.2, 0.0, 0.03)),
    ]
    for lyap in (False, True):
        batch = I.integrate_batch(models, options=opts, lyapunov=lyap)
        for i, m in enumerate(models):
            alone = I.integrate_batch([m], options=opts, lyapunov=lyap)
            for name in ("poincare", "end_state", "stats"):
                np.testing.assert_array_equal(getattr(batch, name)[i], getattr(alone, name)[0], err_msg=name)
            if lyap:
                np.testing.assert_array_equal(batch.lyapunov_log[i], alone.lyapunov_log[0])


def test_one_and_two_threads_identical(threads):
    """Dealing the points to 1, 2 or 3 workers changes nothing, bit for bit."""
    opts = IntegrationOptions(transient=20, periods=10)
    models = [GearModel(omega=w) for w in W1_GRID[::8]]
    assert int(sum(steps_per_period(m.omega, opts.dtau) for m in models)) * 30 >= K.THREAD_MIN_STEPS
    threads(1)
    one = I.integrate_batch(models, options=opts, lyapunov=True)
    threads(2)
    two = I.integrate_batch(models, options=opts, lyapunov=True)
    _assert_same(one, two)


def test_uneven_worker_split_identical(monkeypatch):
    """Three workers sharing the queue of an uneven batch give the same bits as one."""
    opts = IntegrationOptions(transient=20, periods=10)
    models = [GearModel(omega=w) for w in np.linspace(0.5, 1.5, 7)]
    monkeypatch.setattr(K, "n_threads", lambda: 1)
    ref = I.integrate_batch(models, options=opts)
    monkeypatch.setattr(K, "n_threads", lambda: 3)
    monkeypatch.setattr(K, "THREAD_MIN_STEPS", 0)
    _assert_same(ref, I.integrate_batch(models, options=opts))


def test_queue_longest_first():
    """The batch's queue holds every point once, by decreasing cost (steps per period)."""
    rng = np.random.default_rng(1)
    nsteps = rng.integers(400, 1300, size=101)
    order = K._queue_order(nsteps)
    assert sorted(order.tolist()) == list(range(101))
    assert np.all(np.diff(nsteps[order]) <= 0)


# --------------------------------------------------------------------------- Lyapunov, monodromy, histories
def test_liouville_sum_of_exponents(threads):
    """λ1 + λ2 = −2ξ0 on W3-style points (ω = linspace(0.5, 1.5, 50), reduced length)."""
    threads(1)
    opts = IntegrationOptions(transient=30, periods=60)
    ws = np.linspace(0.5, 1.5, 50)[::6]
    models = [GearModel(omega=w) for w in ws]
    res = I.integrate_batch(models, options=opts, lyapunov=True, record_poincare=False)
    assert res.poincare.shape == (len(models), 0, 2)
    T = 2.0 * np.pi / ws
    lam = res.lyapunov_log.sum(axis=1) / (opts.periods * T)[:, None]
    np.testing.assert_allclose(lam.sum(axis=1), -2.0 * 0.1, rtol=0, atol=1e-9)


def test_batched_monodromy_equals_period_map(threads):
    """The monodromy computed in lanes equals the one-point period map, bit for bit."""
    threads(1)
    models = [GearModel(omega=w) for w in (0.6, 0.75, 0.9, 1.05)]
    opts = IntegrationOptions(transient=0, periods=2)
    res = I.integrate_batch(models, (0.3, -0.1), opts, monodromy=True)
    for i, m in enumerate(models):
        points, mono, st, ok = I.period_map(m, (0.3, -0.1), n=2)
        assert ok
        np.testing.assert_array_equal(res.poincare[i], points)
        np.testing.assert_array_equal(res.tangent[i], mono)
        np.testing.assert_array_equal(res.stats[i], st)


def test_time_history_consistent_with_batch():
    """The time-history path ends its periods on the batch's Poincaré points, bit for bit."""
    m = GearModel(omega=0.9)
    opts = IntegrationOptions(transient=10, periods=4)
    tr = I.trajectory(m, options=opts, history_periods=2)
    batch = I.integrate_batch([m, m.replace(omega=1.0), m.replace(omega=1.1)], options=opts)
    np.testing.assert_array_equal(tr.summary.poincare[0], batch.poincare[0])
    N = int(batch.nsteps[0])
    np.testing.assert_array_equal(np.c_[tr.u[N::N], tr.v[N::N]], batch.poincare[0, -2:])


# --------------------------------------------------------------------------- faults
@pytest.mark.parametrize("record_poincare", [True, False])
def test_divergence_flagged_and_isolated(threads, record_poincare):
    """Diverging points are flagged, NaN-filled, and leave their batch neighbours untouched."""
    threads(1)
    opts = IntegrationOptions(transient=5, periods=30)
    good = [GearModel(omega=w) for w in (0.7, 0.9, 1.1, 1.3)]
    bad = [GearModel(omega=w, xi0=-0.3) for w in (0.8, 1.0)]
    models = [good[0], bad[0], good[1], good[2], bad[1], good[3]]
    res = I.integrate_batch(models, options=opts, lyapunov=True, record_poincare=record_poincare)
    diverged = np.array([1, 4])
    assert np.all(res.status[diverged] == I.ST_DIVERGED)
    assert np.all(res.status[[0, 2, 3, 5]] == I.ST_OK)
    assert np.all(np.isnan(res.end_state[diverged]))
    if record_poincare:
        assert np.all(np.isnan(res.poincare[diverged]))
    assert np.all(np.isnan(res.amplitude[diverged]))
    ref = I.integrate_batch(good, options=opts, lyapunov=True, record_poincare=record_poincare)
    for i, j in zip([0, 2, 3, 5], range(4)):
        np.testing.assert_array_equal(res.poincare[i], ref.poincare[j])
        np.testing.assert_array_equal(res.stats[i], ref.stats[j])
        np.testing.assert_array_equal(res.lyapunov_log[i], ref.lyapunov_log[j])
    # the scalar path flags it the same way
    alone = I.integrate_batch([bad[0]], options=opts, record_poincare=record_poincare)
    assert alone.status[0] == I.ST_DIVERGED and np.all(np.isnan(alone.end_state[0]))
    np.testing.assert_array_equal(alone.stats[0], res.stats[1])


def test_no_backlash_and_accurate_mode_still_served():
    """D = 0 (linear mesh) in lanes, and the accurate mode on a batch, agree with the default path."""
    opts = IntegrationOptions(transient=30, periods=3)
    lin = [GearModel(omega=w, D=0.0, fp=2.0) for w in (0.8, 0.9, 1.0)]
    res = I.integrate_batch(lin, options=opts)
    assert np.all(res.contact_fractions[:, 0] == 1.0)
    acc = I.integrate_batch(lin, options=opts.replace(accurate=True))
    np.testing.assert_allclose(acc.poincare, res.poincare, rtol=0, atol=1e-9)


# --------------------------------------------------------------------------- geardyn bench
def test_bench_json_structure():
    """``geardyn bench --workload W2 --json`` reports wall time, steps and ns per step (no timing asserted)."""
    import json

    from typer.testing import CliRunner

    from geardyn.cli import app

    r = CliRunner().invoke(app, ["bench", "--workload", "W2", "--repeats", "1", "--threads", "1", "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    w2 = out["workloads"]["W2"]
    assert w2["steps"] == 5_240_000
    assert w2["wall_s"] > 0 and w2["ns_per_step"] == pytest.approx(1e9 * w2["wall_s"] / w2["steps"])
    assert out["threads"] == 1


def test_bench_workload_sizes_and_bad_name():
    from geardyn import bench
    from geardyn.model import ModelError

    assert bench.workload("W1").steps == 69_152_500
    assert bench.workload("w3").steps == 79_782_400  # as counted by the C reference
    with pytest.raises(ModelError, match="W1, W2, W3"):
        bench.workload("W4")
