"""The public period map: evaluation, Jacobian, parameter derivative, with_param, steps and threads."""

from __future__ import annotations

import inspect
import math
import pathlib

import numba
import numpy as np
import pytest

from geardyn import integrate as I
from geardyn.analysis import periodic as P
from geardyn.analysis.periodic import PeriodMap
from geardyn.model import GearModel, IntegrationOptions, ModelError
from geardyn.status import Status

#: The linear limit: no backlash (D = 0: always in contact), constant coefficients.
LINEAR = dict(D=0.0, xi=(), kappa=(), fp=0.2, eps=(0.5,))


def central_jacobian(pmap: PeriodMap, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    J = np.zeros((x.size, x.size))
    for j in range(x.size):
        e = np.zeros(x.size)
        e[j] = h
        J[:, j] = (pmap(x + e) - pmap(x - e)) / (2 * h)
    return J


# ------------------------------------------------------------------------------ evaluation
def test_fixed_point_of_the_linear_map_is_the_closed_form_response():
    """u'' + 2ξ0 u' + u = f_p + ε ω² cos ωτ has the periodic response u = f_p + A cos(ωτ − φ)."""
    w, xi0, fp, eps = 0.7, 0.1, 0.2, 0.5
    pmap = PeriodMap(GearModel(omega=w, xi0=xi0, **LINEAR), 1)
    c = pmap(np.zeros(2))  # the map is affine: P(x) = M x + c
    M = pmap.jacobian(np.zeros(2))
    x_star = np.linalg.solve(np.eye(2) - M, c)
    A = eps * w**2 / math.hypot(1.0 - w**2, 2.0 * xi0 * w)
    phi = math.atan2(2.0 * xi0 * w, 1.0 - w**2)
    exact = np.array([fp + A * math.cos(phi), A * w * math.sin(phi)])
    assert np.allclose(x_star, exact, rtol=0, atol=1e-8)
    ev = pmap.evaluate(x_star)
    assert ev.ok and ev.steps == pmap.steps
    assert np.allclose(ev.residual, 0.0, atol=1e-12)
    assert np.allclose(P.shoot(pmap.model, 1, guess=(0.0, 0.0)).state, exact, rtol=0, atol=1e-8)


def test_evaluate_returns_all_section_points_and_the_step():
    pmap = PeriodMap(GearModel(omega=0.8), 3)
    ev = pmap.evaluate([0.5, 0.1])
    assert ev.points.shape == (3, 2) and ev.monodromy.shape == (2, 2) and ev.ok
    assert np.array_equal(ev.value, pmap([0.5, 0.1]))
    one = PeriodMap(GearModel(omega=0.8), 1)
    x = np.array([0.5, 0.1])
    for k in range(3):
        x = one(x)
        assert np.array_equal(x, ev.points[k])
    assert pmap.steps == math.ceil(pmap.period / pmap.dtau) and pmap.step == pmap.period / pmap.steps
    tau, u, v = pmap.history([0.5, 0.1])
    assert u.size == 3 * pmap.steps + 1 and u[-1] == ev.value[0] and v[-1] == ev.value[1]


def test_evaluate_of_a_non_finite_or_diverging_state_is_not_ok():
    pmap = PeriodMap(GearModel(), 1)
    ev = pmap.evaluate([math.nan, 0.0])
    assert not ev.ok and np.all(np.isnan(ev.points)) and np.all(np.isnan(ev.monodromy))
    assert not PeriodMap(GearModel(xi0=-0.5), 50).evaluate([0.0, 0.0]).ok


# ------------------------------------------------------------------------------ derivatives
@pytest.mark.parametrize(
    "model, x, accurate",
    [
        (GearModel(omega=1.3), (1.2, -0.3), False),  # contact loss on the way: the discrete map's exact Jacobian
        (GearModel(omega=0.6, xi0=0.05), (0.4, 0.2), False),
        (GearModel(omega=0.7, **LINEAR), (0.3, 0.1), False),
    ],
)
def test_jacobian_equals_central_finite_differences(model, x, accurate):
    pmap = PeriodMap(model, 2, accurate=accurate)
    x = np.asarray(x, float)
    J = pmap.jacobian(x)
    assert np.allclose(J, central_jacobian(pmap, x), rtol=1e-5, atol=1e-7 * np.max(np.abs(J)))


@pytest.mark.parametrize("name", ["xi0", "kappa1", "fp", "eps1", "omega", "D", "phi_k1"])
def test_parameter_derivative_equals_finite_differences(name):
    pmap = PeriodMap(GearModel(omega=1.1), 1)
    x = np.array([1.1, -0.2])
    g = pmap.param_derivative(x, name)
    p = pmap.get(name)
    d = 1e-4 * max(1.0, abs(p))
    fixed = pmap.with_steps(pmap.steps)  # the derivative holds the steps per period fixed
    fd = (fixed.with_param(name, p + d)(x) - fixed.with_param(name, p - d)(x)) / (2 * d)
    assert g.shape == (2,) and np.all(np.isfinite(g))
    assert np.allclose(g, fd, rtol=1e-5, atol=1e-8 * max(1.0, np.max(np.abs(fd))))


def test_parameter_derivative_is_one_sided_at_the_edge_of_the_domain():
    pmap = PeriodMap(GearModel(omega=0.7, **LINEAR), 1)  # D = 0: D − δ is not a model
    x = np.array([0.3, 0.1])
    g = pmap.param_derivative(x, "backlash")
    d = 1e-6
    one_sided = (pmap.with_steps(pmap.steps).with_param("D", d)(x) - pmap(x)) / d
    assert np.array_equal(g, one_sided)
    with pytest.raises(ModelError, match="unknown parameter"):
        pmap.param_derivative(x, "nope")


# ------------------------------------------------------------------------------ new maps
def test_with_param_returns_a_new_map():
    pmap = PeriodMap(GearModel(omega=1.0), 2, dtau=0.02, accurate=True)
    other = pmap.with_param("omega", 0.5)
    assert other is not pmap and pmap.model.omega == 1.0 and other.get("omega") == 0.5
    assert (other.n, other.dtau, other.accurate) == (2, 0.02, True)
    assert other.steps == math.ceil(2 * math.pi / 0.5 / 0.02) and other.steps != pmap.steps
    fixed = PeriodMap(GearModel(omega=1.0), 1, steps=500)
    assert fixed.with_param("omega", 0.5).steps == 500  # an explicit step count is kept
    assert fixed.with_steps(500) is fixed and fixed.with_steps(None).steps == math.ceil(2 * math.pi / 0.01)
    assert np.array_equal(pmap.with_param("fe", 0.3).model.eps, (0.3,))
    with pytest.raises(ModelError, match="unknown parameter"):
        pmap.with_param("nope", 1.0)
    with pytest.raises(ModelError, match="backlash|D"):
        pmap.with_param("D", -1.0)


@pytest.mark.parametrize("bad", [dict(n=0), dict(n=1.5), dict(steps=0), dict(steps=2.5), dict(dtau=-1.0)])
def test_bad_settings_are_refused(bad):
    kw = dict(n=1) | bad
    with pytest.raises(ModelError):
        PeriodMap(GearModel(), kw.pop("n"), **kw)


# ------------------------------------------------------------------------------ steps in integrate
def test_steps_option_gives_the_same_bits_as_the_step_it_stands_for():
    m = GearModel(omega=1.3)
    N = 700
    opts = IntegrationOptions(transient=3, periods=4)
    a = I.integrate_batch([m], (0.1, 0.0), opts, steps=N)
    b = I.integrate_batch([m], (0.1, 0.0), opts.replace(dtau=m.period / (N - 0.5)))
    assert int(a.nsteps[0]) == int(b.nsteps[0]) == N
    assert np.array_equal(a.poincare, b.poincare) and np.array_equal(a.stats, b.stats)
    pts, M, _st, ok = I.period_map(m, (0.1, 0.0), 2, steps=N)
    pts2, M2, _st2, ok2 = I.period_map(m, (0.1, 0.0), 2, dtau=m.period / (N - 0.5))
    assert ok and ok2 and np.array_equal(pts, pts2) and np.array_equal(M, M2)
    tr = I.trajectory(m, (0.1, 0.0), opts, history_periods=2, steps=N)
    assert tr.u.size == 2 * N + 1 and tr.tau[1] == m.period / N


@pytest.mark.parametrize("steps", [0, -3, 2.5, True, [10, 20]])
def test_bad_steps_are_refused(steps):
    with pytest.raises(ModelError, match="steps"):
        I.integrate_batch([GearModel()], None, IntegrationOptions(transient=0, periods=1), steps=steps)


# ------------------------------------------------------------------------------ threads
@pytest.fixture
def thread_setting():
    old = numba.get_num_threads()
    yield min(2, numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(old)


def test_shooting_and_continuation_leave_the_thread_count_alone(thread_setting, monkeypatch):
    numba.set_num_threads(thread_setting)
    calls = []
    real = numba.set_num_threads
    monkeypatch.setattr(numba, "set_num_threads", lambda n: (calls.append(n), real(n))[1])
    orbit = P.shoot(GearModel(omega=1.3), 1)
    assert orbit.converged and numba.get_num_threads() == thread_setting
    res = P.continuation(GearModel(omega=1.3), "xi0", 0.1, 0.09, 1, switch=False, accurate=False)
    assert len(res.branches[0]) > 2 and numba.get_num_threads() == thread_setting
    if thread_setting == 1:
        assert calls == []  # one thread already: nothing to change
    else:
        assert calls and calls[-1] == thread_setting  # every change was undone


def test_using_threads_restores_the_setting_even_on_error(thread_setting):
    numba.set_num_threads(thread_setting)
    with pytest.raises(RuntimeError):
        with I.using_threads(1):
            assert numba.get_num_threads() == 1
            raise RuntimeError("boom")
    assert numba.get_num_threads() == thread_setting
    with I.using_threads(None):
        assert numba.get_num_threads() == thread_setting
    with pytest.raises(ModelError, match="threads"):
        with I.using_threads(0):
            pass


def test_no_periodic_module_touches_numba_threads():
    pkg = pathlib.Path(inspect.getfile(P)).parent
    for f in pkg.glob("*.py"):
        text = f.read_text(encoding="utf-8")
        assert "set_num_threads" not in text and "import numba" not in text, f.name


# ------------------------------------------------------------------------------ orbit status
def test_orbit_status_is_a_status_written_as_before():
    orbit = P.shoot(GearModel(omega=1.3), 1)
    assert orbit.status is Status.OK and orbit.to_json()["status"] == "converged"
    failed = P.shoot(GearModel(xi0=-0.5), 1)
    assert failed.status is Status.DIVERGED and failed.to_json()["status"] == "diverged"
    stuck = P.shoot(GearModel(omega=1.3), 1, guess=(3.0, 0.0), max_iter=1)
    assert stuck.status is Status.NOT_CONVERGED and stuck.to_json()["status"] == "not converged"
    assert orbit.to_dataset().attrs["status"] == "converged"
    assert orbit.period_map.steps == orbit.steps
