"""The standard workloads written with the Python tools a user would otherwise pick.

* ``pynamicalsys`` (``ContinuousDynamicalSystem`` with its fixed-step ``rk4`` integrator at the
  same step h = T/ceil(T/0.01) as geardyn; ``stroboscopic_map`` for the Poincaré points,
  ``lyapunov`` for the exponents, which re-orthonormalises after every step);
* SciPy ``solve_ivp`` with RK45 (adaptive; tolerances below), Poincaré points from ``t_eval``,
  exponents from the variational equations restarted each period with Gram–Schmidt.

They run on reduced grids; :func:`extrapolate` scales the measured time to the full workload
(pynamicalsys by RK4 steps, which it shares with geardyn; SciPy by integrated time τ, since its
adaptive step does not depend on the grid).  Used by ``benchmarks/compare.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np

#: The paper's defaults used by every workload.
XI0, XI1, KAPPA1, FP, EPS1, D = 0.1, 0.05, 0.2, 0.2, 0.5, 1.0
#: SciPy RK45 tolerances: tight enough that its Poincaré points agree with RK4 at Δτ = 0.01
#: (≈ 1e-7) on periodic ω.
SCIPY_RTOL, SCIPY_ATOL = 1e-8, 1e-10


def steps(omega: float, dtau: float = 0.01) -> int:
    return math.ceil(2.0 * math.pi / omega / dtau)


# ----------------------------------------------------------------------------------- pynamicalsys
def _pyn_system():
    from numba import njit
    from pynamicalsys import ContinuousDynamicalSystem

    @njit
    def rhs(t, u, p):
        w = p[0]
        c = math.cos(w * t)
        x = u[0]
        f = x - min(max(x, -p[6]), p[6])
        return np.array([u[1], p[4] + p[5] * w * w * c - 2.0 * (p[1] + p[2] * c) * u[1] - (1.0 + p[3] * c) * f])

    @njit
    def jac(t, u, p):
        w = p[0]
        c = math.cos(w * t)
        g = (1.0 + p[3] * c) if abs(u[0]) > p[6] else 0.0
        J = np.zeros((2, 2))
        J[0, 1] = 1.0
        J[1, 0] = -g
        J[1, 1] = -2.0 * (p[1] + p[2] * c)
        return J

    return ContinuousDynamicalSystem(equations_of_motion=rhs, jacobian=jac, system_dimension=2, number_of_parameters=7)


def _params(w: float) -> np.ndarray:
    return np.array([w, XI0, XI1, KAPPA1, FP, EPS1, D])


def pynamicalsys_poincare(omegas, transient: int, periods: int) -> tuple[float, int, list[np.ndarray]]:
    """Stroboscopic (Poincaré) points per ω with pynamicalsys RK4; returns (seconds, RK4 steps, points)."""
    ds = _pyn_system()
    w0 = float(omegas[0])
    ds.integrator("rk4", time_step=2 * math.pi / w0 / steps(w0))
    ds.stroboscopic_map(
        [0.0, 0.0],
        num_samples=1,
        sampling_time=2 * math.pi / w0,
        parameters=_params(w0),
        transient_time=2 * math.pi / w0,
    )  # JIT warm-up
    out = []
    n = 0
    t0 = time.perf_counter()
    for w in omegas:
        T = 2 * math.pi / w
        N = steps(w)
        ds.integrator("rk4", time_step=T / N)
        r = ds.stroboscopic_map(
            [0.0, 0.0],
            num_samples=periods,
            sampling_time=T,
            parameters=_params(w),
            transient_time=transient * T if transient else None,
        )
        out.append(r[:, 1:])
        n += N * (transient + periods)
    return time.perf_counter() - t0, n, out


def pynamicalsys_lyapunov(omegas, transient: int, periods: int) -> tuple[float, int, np.ndarray]:
    """Both exponents per ω with pynamicalsys RK4 + tangent equations; returns (seconds, steps, exponents)."""
    ds = _pyn_system()
    w0 = float(omegas[0])
    ds.integrator("rk4", time_step=2 * math.pi / w0 / steps(w0))
    ds.lyapunov([0.0, 0.0], 4 * math.pi / w0, parameters=_params(w0), transient_time=2 * math.pi / w0)  # warm-up
    lam = []
    n = 0
    t0 = time.perf_counter()
    for w in omegas:
        T = 2 * math.pi / w
        N = steps(w)
        ds.integrator("rk4", time_step=T / N)
        # pynamicalsys's total_time includes the transient
        lam.append(
            ds.lyapunov(
                [0.0, 0.0],
                (transient + periods) * T,
                parameters=_params(w),
                transient_time=transient * T,
                endpoint=False,
            )
        )
        n += N * (transient + periods)
    return time.perf_counter() - t0, n, np.array(lam)


# ----------------------------------------------------------------------------------- SciPy
def _scipy_rhs(w: float):
    def f(t, y):
        c = math.cos(w * t)
        x = y[0]
        fz = x - min(max(x, -D), D)
        return [y[1], FP + EPS1 * w * w * c - 2.0 * (XI0 + XI1 * c) * y[1] - (1.0 + KAPPA1 * c) * fz]

    return f


def scipy_poincare(omegas, transient: int, periods: int) -> tuple[float, float, list[np.ndarray]]:
    """Poincaré points per ω with solve_ivp RK45; returns (seconds, integrated time τ, points)."""
    from scipy.integrate import solve_ivp

    out = []
    tau = 0.0
    t0 = time.perf_counter()
    for w in omegas:
        T = 2 * math.pi / w
        te = T * np.arange(transient + 1, transient + periods + 1)
        sol = solve_ivp(
            _scipy_rhs(w), (0.0, te[-1]), [0.0, 0.0], method="RK45", t_eval=te, rtol=SCIPY_RTOL, atol=SCIPY_ATOL
        )
        out.append(sol.y.T)
        tau += te[-1]
    return time.perf_counter() - t0, tau, out


def scipy_lyapunov(omegas, transient: int, periods: int) -> tuple[float, float, np.ndarray]:
    """Both exponents per ω: RK45 on state + tangent matrix, restarted each period after Gram–Schmidt."""
    from scipy.integrate import solve_ivp

    lam = []
    tau = 0.0
    t0 = time.perf_counter()
    for w in omegas:
        T = 2 * math.pi / w
        f = _scipy_rhs(w)

        def fv(t, y, f=f, w=w):
            c = math.cos(w * t)
            du = f(t, y[:2])
            g = (1.0 + KAPPA1 * c) if abs(y[0]) > D else 0.0
            C = 2.0 * (XI0 + XI1 * c)
            a1, b1, a2, b2 = y[2], y[3], y[4], y[5]
            return [du[0], du[1], b1, -g * a1 - C * b1, b2, -g * a2 - C * b2]

        y = solve_ivp(f, (0.0, transient * T), [0.0, 0.0], method="RK45", rtol=SCIPY_RTOL, atol=SCIPY_ATOL).y[:, -1]
        Y = np.eye(2)
        s = np.zeros(2)
        for k in range(periods):
            y0 = np.r_[y, Y[:, 0], Y[:, 1]]
            sol = solve_ivp(fv, (0.0, T), y0, method="RK45", rtol=SCIPY_RTOL, atol=SCIPY_ATOL)
            z = sol.y[:, -1]
            y = z[:2]
            Q, R = np.linalg.qr(np.c_[z[2:4], z[4:6]])
            Y = Q * np.sign(np.diag(R))
            s += np.log(np.abs(np.diag(R)))
        lam.append(s / (periods * T))
        tau += (transient + periods) * T
    return time.perf_counter() - t0, tau, np.array(lam)


def extrapolate(seconds: float, measured: float, full: float) -> float:
    """Time of the full workload from a reduced run: seconds × full / measured (steps or τ)."""
    return seconds * full / measured
