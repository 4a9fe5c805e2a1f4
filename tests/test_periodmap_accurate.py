"""The accurate mode's period map of a mesh-vector system (steps split at the contact boundaries) and its monodromy
matrix, against an independent reference: scipy's DOP853 on the same equations (the system's assembled matrices,
:meth:`SystemModel.pack`), restarted at every contact-boundary crossing (events), the monodromy by central finite
differences of that flow.

The vector field is continuous at δ = ±D (the dead zone's force is), so the flow needs no saltation matrix and the
monodromy of a trajectory that crosses the boundaries transversally is a smooth function of the start: the period
map's multipliers must not move when the start moves by rounding.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn.analysis.periodic import PeriodMap, shoot
from geardyn.analysis.periodic.orbit import elastic_multipliers
from geardyn.systems import load_system
from geardyn.systems.assemble import SystemModel

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

#: A period-1 orbit at θ = 0 of the 2-stage chain (chain_toml(2, fp_torque=30 N·m, eps_um=10 µm), ω = 0.75), from
#: shooting in the accurate mode (Δτ = 0.002, residual 3e-11) started on the harmonic-balance orbit (H = 16).  Both
#: meshes lose contact over part of the period (δ_min = 0.989 D); the chain is symmetric, so the two meshes cross
#: their boundaries within 1e-8 of each other, inside one step.
CHAIN2_ORBIT = np.array(
    [
        -0.006255428266957641,
        -0.017186647912484396,
        1.292372621991699,
        0.006255428266957641,
        0.017186647912484396,
        -0.04215002015415622,
        -0.006255428232662717,
        -0.017186647818259772,
        0.04215002048158389,
        0.006255428232662717,
        0.017186647818259772,
        -1.2923726223191276,
        0.0039504873686748015,
        0.010853874841274697,
        0.017584615332502978,
        -0.0039504873686748015,
        -0.010853874841274697,
        0.013722621464839152,
        0.003950487262294201,
        0.010853874548996365,
        -0.013722621904848185,
        -0.003950487262294201,
        -0.010853874548996365,
        -0.017584614892494042,
    ]
)


#: Shooting's start for the pair (a point of its period-1 orbit at ω = 0.75, to 1e-10).
PAIR_GUESS = (0.330433390743612, -0.1622666806099843, 0.06513938153567211, -0.2564259953821277)


@pytest.fixture(scope="module")
def chain2(tmp_path_factory):
    from ndof_scaling import chain_toml

    path = chain_toml(2, tmp_path_factory.mktemp("chain") / "chain2.toml", fp_torque=30.0, eps_um=10.0)
    return load_system(path).with_param("omega", 0.75)


@pytest.fixture(scope="module")
def pair():
    """The paper's pair as two rotating bodies (the 1-DOF model's equations) at ω = 0.75."""
    return load_system(ROOT / "examples" / "systems" / "paper_torsional.toml").with_param("omega", 0.75)


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a multiplier of either set to the nearest of the other."""
    d = np.abs(a[:, None] - b[None, :])
    return float(max(d.min(axis=0).max(), d.min(axis=1).max()))


class Dop853Flow:
    """x(0) -> x(T) of the system's equations (geardyn._kernel_ndof.core's docstring) by DOP853, from the packed
    arrays: q'' = g − A q − B q' − Σ_m W[m] (C_m δ_m' + K_m f(δ_m; D_m)), δ_m = V[m]·q − E_m(θ), θ = ωτ.  The
    integration stops at every crossing of δ_m = ±D_m and restarts there, so that no step straddles a kink."""

    def __init__(self, model, rtol: float = 1e-12, atol: float = 1e-13):
        a = SystemModel.pack([model])
        assert a.Vc.shape[1] == 0 and a.Fo.shape[1] == 0 and a.bq.shape[1] == 0  # meshes only, constant loads
        Mi = a.Mi[0]
        self.A, self.B, self.g = Mi @ a.Kb[0], Mi @ a.Cb[0], Mi @ a.F[0]
        self.V, self.W = a.V[0], a.V[0] @ Mi.T
        self.coef, self.D, self.ratio, self.omega = a.coef[0], a.D[0], a.ratio[0], float(a.omega[0])
        self.n, self.T = Mi.shape[0], model.sampling_period
        self.rtol, self.atol = rtol, atol
        self.events = []
        for m in range(self.V.shape[0]):
            for side in (1.0, -1.0):
                ev = lambda t, x, m=m, side=side: self.deflection(t, x)[0][m] - side * self.D[m]  # noqa: E731
                ev.terminal = True
                self.events.append(ev)

    def series(self, theta: float) -> np.ndarray:
        """(C, K, E, dE/dθ) of every mesh at the base angle θ (the Fourier series of the packed coefficients)."""
        H = self.coef.shape[2] - 1
        j = np.arange(1, H + 1)
        out = np.empty((self.coef.shape[0], 4))
        for m, c in enumerate(self.coef):
            ph = self.ratio[m] * theta
            cj, sj = np.cos(j * ph), np.sin(j * ph)
            for k in range(3):
                out[m, k] = c[k, 0, 0] + c[k, 1:, 0] @ cj + c[k, 1:, 1] @ sj
            out[m, 3] = np.sum(j * self.ratio[m] * (c[2, 1:, 1] * cj - c[2, 1:, 0] * sj))
        return out

    def deflection(self, t: float, x: np.ndarray):
        cf = self.series(self.omega * t)
        q, v = x[: self.n], x[self.n :]
        return self.V @ q - cf[:, 2], self.V @ v - self.omega * cf[:, 3], cf

    def field(self, t: float, x: np.ndarray) -> np.ndarray:
        d, dv, cf = self.deflection(t, x)
        s = cf[:, 0] * dv + cf[:, 1] * (d - np.clip(d, -self.D, self.D))
        q, v = x[: self.n], x[self.n :]
        return np.concatenate([v, self.g - self.A @ q - self.B @ v - s @ self.W])

    def __call__(self, x0: np.ndarray) -> np.ndarray:
        t, x, T = 0.0, np.array(x0, dtype=float), self.T
        opts = dict(method="DOP853", rtol=self.rtol, atol=self.atol)
        while t < T:
            r = solve_ivp(self.field, (t, T), x, events=self.events, **opts)
            assert r.success
            t, x = r.t[-1], r.y[:, -1]
            if r.status == 1 and t < T:  # a crossing: step 1e-9 past it on one side, then go on with the events
                t1 = min(t + 1e-9, T)
                x = solve_ivp(self.field, (t, t1), x, **opts).y[:, -1]
                t = t1
        return x

    def jacobian(self, t: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """∂q''/∂q and ∂q''/∂q' at (t, x): the slope of the dead zone is 1 in contact, 0 in separation."""
        d, _dv, cf = self.deflection(t, x)
        k = cf[:, 1] * (np.abs(d) > self.D)
        return -self.A - (self.W.T * k) @ self.V, -self.B - (self.W.T * cf[:, 0]) @ self.V

    def variational(self, x0: np.ndarray) -> np.ndarray:
        """∂x(T)/∂x(0) by DOP853 on the state and its variational equation together (no saltation at a crossing:
        the field is continuous there), stopped and restarted at every crossing like the flow."""
        n, d = self.n, 2 * self.n

        def field(t, z):
            x, Phi = z[:d], z[d:].reshape(d, d)
            Jq, Jv = self.jacobian(t, x)
            return np.concatenate([self.field(t, x), Phi[n:].ravel(), (Jq @ Phi[:n] + Jv @ Phi[n:]).ravel()])

        events = []
        for ev in self.events:
            e = lambda t, z, ev=ev: ev(t, z[:d])  # noqa: E731
            e.terminal = True
            events.append(e)
        t, z, T = 0.0, np.concatenate([x0, np.eye(d).ravel()]), self.T
        opts = dict(method="DOP853", rtol=self.rtol, atol=self.atol)
        while t < T:
            r = solve_ivp(field, (t, T), z, events=events, **opts)
            assert r.success
            t, z = r.t[-1], r.y[:, -1]
            if r.status == 1 and t < T:
                t1 = min(t + 1e-9, T)
                z = solve_ivp(field, (t, t1), z, **opts).y[:, -1]
                t = t1
        return z[d:].reshape(d, d)

    def monodromy(self, x0: np.ndarray, eps: float) -> np.ndarray:
        """∂x(T)/∂x(0) by central differences of relative step eps."""
        M = np.empty((x0.size, x0.size))
        for j in range(x0.size):
            e = np.zeros(x0.size)
            e[j] = eps * max(1.0, abs(x0[j]))
            M[:, j] = (self(x0 + e) - self(x0 - e)) / (2.0 * e[j])
        return M


def test_chain_multipliers_do_not_move_with_the_step_or_the_start_bits(chain2):
    """On the symmetric 2-stage chain the two meshes cross their boundaries within 1e-8 of each other, inside one
    step.  The accurate map's elastic multipliers at the orbit and at three starts moved by 1e-13 relative, with
    Δτ = 0.004, 0.001 and 0.0005: measured all within 2e-12 of one another (RK4's error at these steps is below
    that).  Asserted 1e-9.  Before the accurate step left an element lying on its boundary out of its crossing
    search, the first mesh's split could leave it exactly on D; the search then ended on a split of rounding length,
    64 times over, and the step was finished unsplit past the second mesh's crossing: the multipliers were 2.6e-4
    off at Δτ = 0.004 and 4.8e-5 at Δτ = 0.0005, at every start tried."""
    rng = np.random.default_rng(7)
    starts = [CHAIN2_ORBIT] + [CHAIN2_ORBIT * (1.0 + 1e-13 * rng.standard_normal(CHAIN2_ORBIT.size)) for _ in range(3)]
    mus = []
    for dtau in (0.004, 0.001, 0.0005):
        pmap = PeriodMap(chain2, 1, dtau=dtau, accurate=True)
        for x in starts:
            ev = pmap.evaluate(x)
            assert ev.ok
            mu, r = elastic_multipliers(chain2, ev.monodromy)
            assert r == 1 and mu.size == 2 * (chain2.n - 1)
            mus.append(mu)
    spread = max(_distance(mus[0], mu) for mu in mus[1:])
    assert spread < 1e-9


def test_pair_multipliers_are_dop853s(pair):
    """The paper's pair as two rotating bodies at ω = 0.75: a period-1 orbit that crosses δ = D twice a period and
    stays 0.82 (above) and 0.87 (below, from −D) away from the boundaries at its extremes: no grazing.  The accurate
    map's elastic multipliers (Δτ = 0.002) against DOP853 (rtol 1e-12): the monodromy by central differences of the
    flow (relative step 1e-5: their rounding error about 1e-12/1e-5 = 1e-7, their truncation error below the 7e-7
    measured with step 1e-4), measured 1.2e-8, asserted 1e-6; and by the variational equation integrated with the
    flow, measured 7.2e-12, asserted 1e-9 (the two references agree: the flow needs no saltation matrix)."""
    orbit = shoot(pair, 1, guess=PAIR_GUESS, dtau=0.002, accurate=True)
    assert orbit.converged
    x = orbit.state
    flow = Dop853Flow(pair)
    assert np.abs(flow(x) - x).max() < 1e-8  # the same orbit for the reference
    mu_fd, _ = elastic_multipliers(pair, flow.monodromy(x, 1e-5))
    mu_var, _ = elastic_multipliers(pair, flow.variational(x))
    mu, _ = elastic_multipliers(pair, PeriodMap(pair, 1, dtau=0.002, accurate=True).jacobian(x))
    assert mu.size == mu_fd.size == mu_var.size == 2
    assert _distance(mu, mu_fd) < 1e-6
    assert _distance(mu, mu_var) < 1e-9


def test_chain_multipliers_are_dop853s_variational(chain2):
    """The 2-stage chain's orbit (CHAIN2_ORBIT; the two meshes cross within 1e-8 of each other, inside one step):
    the accurate map's elastic multipliers (Δτ = 0.002 and 0.0005) against DOP853's variational equation (rtol
    1e-12).  Measured 5.5e-12 and 9e-13; asserted 1e-9.  Before an element left on its boundary by a split was kept
    out of the next crossing search: 1.1e-4 and 4.8e-5."""
    flow = Dop853Flow(chain2)
    mu_ref, _ = elastic_multipliers(chain2, flow.variational(CHAIN2_ORBIT))
    for dtau in (0.002, 0.0005):
        mu, _ = elastic_multipliers(chain2, PeriodMap(chain2, 1, dtau=dtau, accurate=True).jacobian(CHAIN2_ORBIT))
        assert _distance(mu, mu_ref) < 1e-9


@pytest.mark.slow
def test_chain_multipliers_are_dop853s_finite_differences(chain2):
    """The 2-stage chain's orbit (CHAIN2_ORBIT): the accurate map's elastic multipliers (Δτ = 0.002 and 0.0005)
    against DOP853's monodromy by central differences of the flow (rtol 1e-12, relative step 1e-5).  Measured
    2.7e-7 at both steps (the differences' own error: the variational equation's monodromy is 1e-11 from the map);
    asserted 1e-6.  Before the fix of the accurate step 1.1e-4 at Δτ = 0.002 and 4.8e-5 at Δτ = 0.0005."""
    flow = Dop853Flow(chain2)
    assert np.abs(flow(CHAIN2_ORBIT) - CHAIN2_ORBIT).max() < 1e-8
    mu_ref, _ = elastic_multipliers(chain2, flow.monodromy(CHAIN2_ORBIT, 1e-5))
    for dtau in (0.002, 0.0005):
        mu, _ = elastic_multipliers(chain2, PeriodMap(chain2, 1, dtau=dtau, accurate=True).jacobian(CHAIN2_ORBIT))
        assert _distance(mu, mu_ref) < 1e-6
