"""Harmonic balance for one parameter value: the residual, its analytic Jacobian, Newton's method.

For a period-n response u(φ), φ = θ/n = ντ with ν = ω/(P n), the equation of motion
u'' + C(θ)u' + K(θ)f(u; D) = F(θ) (θ the phase of the forcing frequency ω/P: P = ``GearModel.cycles`` mesh
cycles a forcing period, 1 unless the excitation spans several; ω, the parameter, stays the mesh frequency,
and ∂R/∂ω = ∂R/∂(ω/P)/P) becomes, in the complex coefficients c_k (k = −H … H),

    R_k(c) = −ν²k² c_k + ν Σ_l Ĉ_{k−l} (il) c_l + [K f(u)]^_k − F̂_k = 0,

with the products of trigonometric polynomials exact and the dead-zone term from
:func:`~geardyn.analysis.hb.aft.dead_zone_terms` (contact switches located on a time grid of N
samples, then exact integration).  Its Jacobian is analytic:

    ∂R/∂c = −ν² diag(k²) + ν T(Ĉ) diag(ik) + T(Ŝ),        Ŝ = coefficients of K(θ)·χ_contact(φ),

and Newton is run on the real coefficient vector ``[a_0, a_1 … a_H, b_1 … b_H]``.

References
----------
T. M. Cameron and J. H. Griffin, "An alternating frequency/time domain method for calculating the
steady-state response of nonlinear dynamic systems", J. Appl. Mech. 56 (1989) 149–154.
G. W. Hill, Acta Math. 8 (1886) 1–36 (Hill's method for the stability, :mod:`.hill`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ...model import DEFAULT_DTAU, GearModel, IntegrationOptions, ModelError, canonical_param
from ...status import Status
from ._aftkernel import bordered_omega_kernel, dR_domega_kernel, forcing_kernel, residual_kernel
from ._blas import single_thread_blas, solve
from .aft import ROOT_MAX_ITER, ROOT_TOL, HarmonicBasis, dead_zone_terms, model_series, signal_extrema, time_samples
from .hill import HillResult, hill_floquet
from .monodromy import check_floquet, monodromy_floquet

__all__ = [
    "HBSystem",
    "HBSolution",
    "hb_solve",
    "guess_from_simulation",
    "default_harmonics",
    "DEFAULT_HARMONICS",
    "MAX_DEFAULT_HARMONICS",
    "NEWTON_TOL",
]

#: Default harmonics of ν = ω/n (see ``docs/hb.md`` for the convergence study behind it).
DEFAULT_HARMONICS = 16
#: The most harmonics the default of a multi-cycle excitation (P > 1) takes: the Jacobian is a dense matrix of
#: 2H + 1 rows (its LU costs about (2H + 1)³ flops a Newton step).
MAX_DEFAULT_HARMONICS = 1024
#: Newton converges when ||R|| <= NEWTON_TOL·(1 + ||a||) (real coefficients, Euclidean norm).
NEWTON_TOL = 1e-11
NEWTON_MAX_ITER = 40
NEWTON_MIN_DAMPING = 2.0**-12
#: Coefficient vectors larger than this count as diverged.
DIVERGED_NORM = 1e8
#: Relative step of the central difference for the derivative of R in a parameter other than ω.
FD_REL_STEP = 1e-6
#: Simulation used for a starting guess: forcing periods discarded and the step (the model's default step,
#: as in the guess of shooting).
GUESS_TRANSIENT = 400
GUESS_DTAU = DEFAULT_DTAU


def default_harmonics(model: GearModel, period: int = 1) -> int:
    """H when none is given: :data:`DEFAULT_HARMONICS` for a one-cycle model; for an excitation of P > 1 mesh
    cycles (harmonics of ν = ω/(P n)), the larger of P·:data:`DEFAULT_HARMONICS` (the mesh orders up to 16 of
    a one-cycle model's default) and n times the excitation's harmonics (every harmonic it carries).

    Parameters
    ----------
    model : GearModel
    period : int
        n, the response period in forcing periods.

    Returns
    -------
    int

    Raises
    ------
    ModelError
        When that is more than :data:`MAX_DEFAULT_HARMONICS` (give the harmonics explicitly).
    """
    P = int(model.period_multiple() or 1)  # mesh cycles of the forcing period (excitation, torque orders)
    if P == 1:
        return DEFAULT_HARMONICS
    H = max(P * DEFAULT_HARMONICS, int(period) * int(model.n_harmonics))
    if H > MAX_DEFAULT_HARMONICS:
        raise ModelError(
            f"harmonics: the excitation spans {P} mesh cycles (harmonics of ω/{P * int(period)}); the "
            f"default would take {H} ({P}·{DEFAULT_HARMONICS} for mesh orders up to {DEFAULT_HARMONICS}, "
            f"and the excitation's {model.n_harmonics} per forcing period), more than "
            f"{MAX_DEFAULT_HARMONICS}: give the harmonics explicitly (the cost grows as H³), or use "
            f"shooting"
        )
    return H


class _AtOmega(NamedTuple):
    """What the residual needs of the model at one value of ω (param ``omega``)."""

    omega: float
    D: float


class HBSystem:
    """The harmonic-balance equations of one model (optionally as a function of one parameter).

    Parameters
    ----------
    model : GearModel
        Base model; ``param`` values replace one of its parameters.
    harmonics : int, optional
        H, harmonics of ν = ω/(P n) retained (default :func:`default_harmonics`).
    period : int
        n, the response period in forcing periods (P mesh periods each).
    param : str, optional
        Parameter name (as :meth:`GearModel.with_param`) used by :meth:`residual` and :meth:`dR_dp`.
    samples : int, optional
        Time samples N per response period (default :func:`~geardyn.analysis.hb.aft.time_samples`).
    floquet : str
        How :meth:`stability` computes the Floquet multipliers: ``"monodromy"`` (default,
        :mod:`.monodromy`) or ``"hill"`` (Hill's method, :mod:`.hill`).
    """

    def __init__(
        self,
        model: GearModel,
        harmonics: int | None = None,
        period: int = 1,
        param: str | None = None,
        samples: int | None = None,
        *,
        floquet: str = "monodromy",
    ):
        if int(period) < 1:
            raise ModelError(f"period: must be an integer >= 1, got {period!r}")
        if harmonics is None:
            harmonics = default_harmonics(model, int(period))
        if int(harmonics) < 1:
            raise ModelError(f"harmonics: must be an integer >= 1, got {harmonics!r}")
        self.base = model
        self.P = int(model.period_multiple() or 1)  # mesh cycles of the forcing period (excitation, torque orders)
        self.n = int(period)
        self.H = int(harmonics)
        self.floquet = check_floquet(floquet)
        self.param = canonical_param(param) if param is not None else None
        # ω's fast path builds F from f_p and the STE alone; torque orders take the model's own series
        self._omega_fast = self.param == "omega" and not getattr(model, "torque_orders", ())
        N = samples or time_samples(self.H, self.n, model.n_harmonics + 2)
        self.basis = HarmonicBasis(self.H, N)
        self._cache: dict[float | None, tuple[GearModel, tuple[np.ndarray, ...]]] = {}
        self._cuts: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
        self._series: tuple[np.ndarray, ...] | None = None
        self._fargs: tuple[float, np.ndarray, np.ndarray, int, int] | None = None

    def model_at(self, p: float | None = None) -> GearModel:
        """The model at parameter value ``p`` (the base model when ``p`` is None)."""
        m = self._entry(p)[0]
        return m if isinstance(m, GearModel) else self.base.with_param("omega", m.omega)

    def check(self, p: float) -> None:
        """Raise :class:`ModelError` when ``p`` is not a valid value of the system's parameter."""
        self._at(p)

    def _entry(self, p: float | None) -> tuple[GearModel | _AtOmega, tuple[np.ndarray, ...]]:
        key = None if (p is None or self.param is None) else float(p)
        e = self._cache.get(key)
        if e is None:
            if len(self._cache) > 32:
                self._cache.clear()
            if key is not None and self._omega_fast and key > 0 and math.isfinite(2.0 * math.pi / key):
                # only the forcing depends on ω: skip building and validating a model per value
                C, K, _F = self._base_series()
                e = self._cache[key] = (_AtOmega(key, self.base.D), (C, K, self._forcing(self.forcing(key))))
                return e
            m = self.base if key is None else self.base.with_param(self.param, key)
            C, K, F = model_series(m, self.n)
            e = self._cache[key] = (m, (C, K, F))
        return e

    def _base_series(self) -> tuple[np.ndarray, ...]:
        if self._series is None:
            self._series = model_series(self.base, self.n)
        return self._series

    def _forcing(self, omega: float) -> np.ndarray:
        """The F series of :func:`model_series` at ω = ``omega`` (the same operations, so the same values)."""
        return forcing_kernel(float(omega), *self._forcing_args())

    def _forcing_args(self) -> tuple[float, np.ndarray, np.ndarray, int, int]:
        """(f_p, ε_l, φ_el, n, harmonics of the model's series) of the base model for :func:`forcing_kernel`."""
        if self._fargs is None:
            b = self.base
            self._fargs = (
                float(b.fp),
                np.array(b.eps, dtype=float).reshape(-1),
                np.array(b.phi_e, dtype=float).reshape(-1),
                self.n,
                int(b.n_harmonics),
            )
        return self._fargs

    def _at(self, p: float | None) -> tuple[float, float, np.ndarray, np.ndarray]:
        """ω, D and the C, K series at ``p`` (without building the forcing when only it depends on ω).

        Raises
        ------
        ModelError
            When ``p`` is not a valid value of the parameter.
        """
        if p is not None and self._omega_fast:
            w = float(p)
            if w > 0 and math.isfinite(2.0 * math.pi / w):
                C, K, _F = self._base_series()
                return w, float(self.base.D), C, K
        m, (C, K, _F) = self._entry(p)
        return m.omega, float(m.D), C, K

    def forcing(self, omega: float) -> float:
        """The forcing frequency ω/P of the mesh frequency ``omega`` (``omega`` itself when P = 1)."""
        return omega if self.P == 1 else omega / self.P

    def nu(self, p: float | None = None) -> float:
        """ν = ω/(P n), the fundamental frequency of the response at ``p``."""
        if p is not None and self._omega_fast:
            return self.forcing(float(p)) / self.n
        return self.forcing(self._entry(p)[0].omega) / self.n

    def _centred(self, z: np.ndarray, L: int) -> np.ndarray:
        """Centred coefficient array z padded or cut to half-length L."""
        Lz = (len(z) - 1) // 2
        out = np.zeros(2 * L + 1, dtype=complex)
        m = min(L, Lz)
        out[L - m : L + m + 1] = z[Lz - m : Lz + m + 1]
        return out

    def _cut(self, z: np.ndarray, L: int) -> np.ndarray:
        """:meth:`_centred` of ``z``, kept per array and L (the series of one parameter value are reused)."""
        key = (id(z), L)
        e = self._cuts.get(key)
        if e is None or e[0] is not z:
            if len(self._cuts) > 64:
                self._cuts.clear()
            e = self._cuts[key] = (z, self._centred(z, L))
        return e[1]

    def _f_centred(self, F: np.ndarray) -> np.ndarray:
        """F cut or padded to the harmonics |k| <= H (kept per F array)."""
        return self._cut(F, self.H)

    def residual(
        self, a: np.ndarray, p: float | None = None, jacobian: bool = True
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Residual R(a) (real, length 2H + 1) and, if asked, its analytic Jacobian ∂R/∂a.

        Parameters
        ----------
        a : ndarray
            Real coefficients of u.
        p : float, optional
            Parameter value (``param`` of the system).
        jacobian : bool
            Also return the Jacobian.

        Returns
        -------
        (R, J) : ndarray, ndarray or None
        """
        m, (C, K, F) = self._entry(p)
        b = self.basis
        R, J = residual_kernel(
            np.ascontiguousarray(a, dtype=float),
            self.forcing(m.omega) / self.n,
            C,
            K,
            self._f_centred(F),
            float(m.D),
            b.cos_table,
            b.sin_table,
            self.H,
            ROOT_MAX_ITER,
            ROOT_TOL,
            bool(jacobian),
        )
        return R, (J if jacobian else None)

    def dR_dp(self, a: np.ndarray, p: float) -> np.ndarray:
        """Derivative of R in the system's parameter at fixed coefficients (analytic for ω, else a
        central difference of the residual, which is exact to rounding for parameters entering it
        linearly: ξ_k, κ_r, ε_l, f_p)."""
        if self.param is None:
            raise ModelError("dR_dp: the system has no continuation parameter")
        if self._omega_fast:
            m, (C, K, F) = self._entry(p)
            w = self.forcing(m.omega)
            Rw = dR_domega_kernel(
                np.ascontiguousarray(a, dtype=float), w / self.n, w, self.n, C, self._f_centred(F), self.H
            )
            return Rw if self.P == 1 else Rw / self.P  # dR/dω = dR/d(ω/P) / P
        return self._dR_dp_fd(a, p)

    def bordered(self, a: np.ndarray, p: float, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """R and the bordered Jacobian of a continuation in the system's parameter.

        Parameters
        ----------
        a : ndarray
            Real coefficients of u.
        p : float
            Parameter value.
        scale : float
            Factor of the parameter column (the parameter's scaling in the continuation).

        Returns
        -------
        (R, A) : ndarray (2H + 1,), ndarray (2H + 2, 2H + 2)
            The residual and [[∂R/∂a, scale·∂R/∂p], [0 … 0]]: the last row is left zero for the
            caller's border (the arclength condition's normal).

        Raises
        ------
        ModelError
            When the system has no continuation parameter.
        """
        if self._omega_fast:
            w, D, C, K = self._at(p)
            b = self.basis
            fp, eps, phi_e, n, Hm = self._forcing_args()
            sc = float(scale) if self.P == 1 else float(scale) / self.P  # dR/dω = dR/d(ω/P) / P
            return bordered_omega_kernel(
                np.ascontiguousarray(a, dtype=float),
                self.forcing(w),
                n,
                C,
                K,
                fp,
                eps,
                phi_e,
                Hm,
                D,
                b.cos_table,
                b.sin_table,
                self.H,
                ROOT_MAX_ITER,
                ROOT_TOL,
                sc,
            )
        R, J = self.residual(a, p)
        Rp = self.dR_dp(a, p)
        M = self.basis.size
        A = np.zeros((M + 1, M + 1))
        A[:M, :M] = J
        A[:M, M] = Rp * scale
        return R, A

    def _dR_dp_fd(self, a: np.ndarray, p: float) -> np.ndarray:
        """Central difference of the residual in the parameter."""
        d = FD_REL_STEP * max(1.0, abs(p))
        vals = []
        for q in (p + d, p - d):
            try:
                vals.append((q, self.residual(a, q, jacobian=False)[0]))
            except ModelError:
                vals.append((p, self.residual(a, p, jacobian=False)[0]))
        (q1, r1), (q2, r2) = vals
        return (r1 - r2) / (q1 - q2)

    def stability(self, a: np.ndarray, p: float | None = None) -> HillResult:
        """Floquet exponents and multipliers of the solution ``a``: from the monodromy matrix along it
        (:mod:`.monodromy`) or by Hill's method (:mod:`.hill`), as ``floquet`` says."""
        w, D, C, K = self._at(p)
        w = self.forcing(w)
        if self.floquet == "hill":
            dz = dead_zone_terms(self.basis, a, K, D)
            return hill_floquet(self._cut(C, 2 * self.H), dz.S, w / self.n, self.H)
        H, nu = self.H, w / self.n
        x0 = np.array([a[0] + np.sum(a[1 : H + 1]), nu * (np.arange(1, H + 1) @ a[H + 1 :])])
        F = self._entry(p)[1][2]
        one, zero = np.ones((1, 1)), np.zeros((1, 1))
        return monodromy_floquet(nu, x0, zero, zero, one, one, [C], [K], [np.zeros(1, complex)], [F], [D])

    def newton(
        self, a0: np.ndarray, p: float | None = None, *, tol: float = NEWTON_TOL, max_iter: int = NEWTON_MAX_ITER
    ) -> tuple[np.ndarray, Status, int, float]:
        """Damped Newton on R(a) = 0 at fixed parameter.

        Returns
        -------
        (a, status, iterations, residual norm)
        """
        a = np.asarray(a0, dtype=float).copy()
        if a.shape != (self.basis.size,) or not np.all(np.isfinite(a)):
            return a, Status.DIVERGED, 0, math.inf
        R, J = self.residual(a, p)
        r = float(np.linalg.norm(R))
        for it in range(max_iter + 1):
            if r <= tol * (1.0 + float(np.linalg.norm(a))):
                return a, Status.OK, it, r
            if it == max_iter:
                break
            try:
                da = solve(J, -R)
            except np.linalg.LinAlgError:
                da = np.linalg.lstsq(J, -R, rcond=None)[0]
            lam = 1.0
            while lam >= NEWTON_MIN_DAMPING:
                trial = a + lam * da
                if not np.all(np.isfinite(trial)) or np.linalg.norm(trial) > DIVERGED_NORM:
                    lam *= 0.5
                    continue
                Rt, Jt = self.residual(trial, p)
                rt = float(np.linalg.norm(Rt))
                if rt < (1.0 - 1e-4 * lam) * r:
                    a, R, J, r = trial, Rt, Jt, rt
                    break
                lam *= 0.5
            else:
                return a, Status.NOT_CONVERGED, it + 1, r
        return a, Status.NOT_CONVERGED, max_iter, r


@dataclass
class HBSolution:
    """A harmonic-balance solution at one parameter value (non-dimensional).

    Attributes
    ----------
    model : GearModel
    harmonics, period, samples : int
        H, n and the number N of time samples per response period.
    coefficients : ndarray (2H + 1,)
        ``[a_0, a_1 … a_H, b_1 … b_H]`` of u(φ), φ = ωτ/n.
    status : Status
        Newton's outcome (``OK``, ``NOT_CONVERGED``, ``DIVERGED``).
    iterations : int
    residual : float
        ||R|| at the last iterate.
    u_min, u_max : float
        Extremes of the reconstructed u over the period (NaN unless converged).
    hill : HillResult or None
        Stability (None unless converged); ``hill.status`` is ``UNRESOLVED`` when the multipliers
        cannot be trusted at this H.
    """

    model: GearModel
    harmonics: int
    period: int
    samples: int
    coefficients: np.ndarray
    status: Status
    iterations: int
    residual: float
    u_min: float = math.nan
    u_max: float = math.nan
    hill: HillResult | None = field(default=None, repr=False)

    @property
    def converged(self) -> bool:
        return self.status is Status.OK

    @property
    def amplitude(self) -> float:
        """Half peak-to-peak displacement (u_max − u_min)/2."""
        return 0.5 * (self.u_max - self.u_min)

    @property
    def multipliers(self) -> np.ndarray:
        return self.hill.multipliers if self.hill is not None else np.full(2, complex(math.nan, math.nan))

    @property
    def stable(self) -> bool | None:
        """True/False when converged and resolved, None otherwise."""
        if not self.converged or self.hill is None or self.hill.status is not Status.OK:
            return None
        return self.hill.stable

    def signal(self, samples: int = 512) -> tuple[np.ndarray, np.ndarray]:
        """(τ, u) at ``samples`` equispaced instants over the n forcing periods, from τ = 0 (θ = 0)."""
        b = HarmonicBasis(self.harmonics, max(samples, 2 * self.harmonics + 2))
        phi = 2.0 * np.pi * np.arange(samples) / samples
        nu = self.model.forcing_omega / self.period
        return phi / nu, b.evaluate(self.coefficients, phi)

    def state(self) -> np.ndarray:
        """(u, u') at τ = 0 (θ = 0), comparable with a shooting orbit's ``state``."""
        a, H = self.coefficients, self.harmonics
        k = np.arange(1, H + 1)
        nu = self.model.forcing_omega / self.period
        return np.array([a[0] + a[1 : H + 1].sum(), nu * float(k @ a[H + 1 :])])


def guess_from_simulation(
    model: GearModel,
    harmonics: int,
    period: int = 1,
    state0: Sequence[float] = (0.0, 0.0),
    *,
    transient: int = GUESS_TRANSIENT,
    dtau: float = GUESS_DTAU,
) -> np.ndarray | None:
    """Fourier coefficients of the attractor reached by simulation from ``state0`` (n periods after
    ``transient`` forcing periods), truncated to H harmonics of ω/n; None if the simulation diverged.

    Parameters
    ----------
    model : GearModel
    harmonics, period : int
        H and n.
    state0 : (u, u')
    transient : int
    dtau : float

    Returns
    -------
    ndarray or None
    """
    from ...integrate import trajectory

    n, H = int(period), int(harmonics)
    P = int(model.period_multiple() or 1)  # mesh cycles of the forcing period (excitation, torque orders)
    if P > 1:  # the same settling time as a one-cycle model's: the transient counts forcing periods of P cycles
        transient = -(-int(transient) // P)
    opts = IntegrationOptions(dtau=dtau, transient=int(transient), periods=n)
    tr = trajectory(model, state0, opts, history_periods=n)
    u = tr.u[:-1]
    if not np.all(np.isfinite(u)):
        return None
    X = np.fft.rfft(u) / u.size
    a = np.zeros(2 * H + 1)
    a[0] = X[0].real
    m = min(H, X.size - 1)
    a[1 : m + 1] = 2.0 * X[1 : m + 1].real
    a[H + 1 : H + 1 + m] = -2.0 * X[1 : m + 1].imag
    return a


def linear_guess(model: GearModel, harmonics: int, period: int = 1) -> np.ndarray:
    """Coefficients of the response of the linearised, permanently meshing model (u > D), a guess
    for small-amplitude responses: u = f_p + D + Σ_l ω²l²ε_l cos(lθ + φ_el)/(1 − (lω)² + 2iξ0 lω)."""
    H, n = int(harmonics), int(period)
    model = model.forcing_model()  # harmonics of the forcing frequency ω/P
    a = np.zeros(2 * H + 1)
    a[0] = model.fp + model.D
    w = model.omega
    for j, (e, ph) in enumerate(zip(model.eps, model.phi_e), start=1):
        kk = n * j
        if kk > H:
            break
        z = w * w * j * j * e * np.exp(1j * ph) / (1.0 - (j * w) ** 2 + 2j * model.xi0 * j * w)
        a[kk] += z.real
        a[H + kk] += -z.imag
    return a


def hb_solve(
    model: GearModel,
    harmonics: int | None = None,
    period: int = 1,
    guess: np.ndarray | str | None = None,
    *,
    samples: int | None = None,
    tol: float = NEWTON_TOL,
    max_iter: int = NEWTON_MAX_ITER,
    stability: bool = True,
    floquet: str = "monodromy",
) -> HBSolution:
    """Solve the harmonic-balance equations of ``model`` at one parameter point.

    Parameters
    ----------
    model : GearModel
        Non-dimensional model.
    harmonics : int
        H, harmonics of ν = ω/(P n) (default :func:`default_harmonics`: :data:`DEFAULT_HARMONICS` for a one-cycle
        model).
    period : int
        n: the response repeats after n forcing periods (n = 1 harmonic, n > 1 subharmonic).
    guess : ndarray, "simulate", "linear" or None
        Starting coefficients (length 2H + 1), ``"linear"`` (the permanently meshing linear response) or
        ``"simulate"`` (the attractor reached by simulation from rest).  Default: ``"simulate"``.
    samples : int, optional
        Time samples per response period (default :func:`~geardyn.analysis.hb.aft.time_samples`).
    tol, max_iter : float, int
        Newton tolerance (||R|| <= tol·(1 + ||a||)) and iteration limit (defaults
        :data:`NEWTON_TOL` and :data:`NEWTON_MAX_ITER`).
    stability : bool
        Compute Hill's multipliers of a converged solution.
    floquet : str
        How the multipliers are computed: ``"monodromy"`` (default) or ``"hill"`` (see :class:`HBSystem`).

    Returns
    -------
    HBSolution
        Check ``status`` (a :class:`~geardyn.status.Status`); values are NaN unless it is ``OK``.

    Raises
    ------
    ModelError
        For a bad ``harmonics``, ``period`` or ``guess`` (not coefficients of length 2H + 1,
        ``"simulate"`` or ``"linear"``).

    References
    ----------
    T. M. Cameron and J. H. Griffin, "An alternating frequency/time domain method for calculating the
    steady-state response of nonlinear dynamic systems", J. Appl. Mech. 56 (1989) 149–154.
    A. Lazarus, O. Thomas, C. R. Mécanique 338 (2010) 510–517 (Hill's multipliers).

    Examples
    --------
    >>> from geardyn import GearModel, hb_solve
    >>> sol = hb_solve(GearModel(omega=0.8), 8)  # 8 harmonics
    >>> sol.converged, sol.period, round(sol.amplitude, 3)
    (True, 1, 0.927)
    """
    sysm = HBSystem(model, harmonics, period, samples=samples, floquet=floquet)
    H = sysm.H
    if guess is None or (isinstance(guess, str) and guess == "simulate"):
        a0 = guess_from_simulation(model, H, period)
        if a0 is None:
            a0 = linear_guess(model, H, period)
    elif isinstance(guess, str) and guess == "linear":
        a0 = linear_guess(model, H, period)
    elif isinstance(guess, str):
        raise ModelError(f"guess: expected coefficients, 'simulate' or 'linear', got {guess!r}")
    else:
        a0 = np.asarray(guess, dtype=float)
        if a0.shape != (2 * H + 1,):
            raise ModelError(f"guess: expected {2 * H + 1} coefficients for H = {H}, got shape {a0.shape}")
    with single_thread_blas():
        a, status, its, r = sysm.newton(a0, None, tol=tol, max_iter=max_iter)
        sol = HBSolution(model, H, sysm.n, sysm.basis.N, a, status, its, r)
        if status is Status.OK:
            sol.u_min, sol.u_max, _, _ = signal_extrema(sysm.basis, a)
            if stability:
                sol.hill = sysm.stability(a)
    return sol
