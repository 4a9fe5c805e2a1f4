"""Harmonic balance of multi-DOF systems (a system of meshes, :mod:`geardyn.systems`): residual, Jacobian, Newton.

The system (non-dimensional, :mod:`geardyn.systems.assemble`; the kernel's form)::

    q'' = g − A q − B q' − Σ_e W[e] s_e,      s_e = C_e(θ) δ_e' + K_e(θ) f(δ_e; D_e),
    δ_e = V[e]·q − E_e(θ)   (meshes; clearances: C_e = cc, K_e = kc, E_e = 0),

with A = M̃⁻¹K̃_b, B = M̃⁻¹C̃_b, W[e] = M̃⁻¹V[e], g = M̃⁻¹F̃.  A period-n response (n forcing periods of
p base periods each, p = :meth:`System.period_multiple`) is sought as H harmonics of ν = ω/(n p) in
the slow angle φ = θ/(n p) for every DOF: the unknown is the (n_dof, 2H + 1) array of real coefficients
``[a_0, a_1 … a_H, b_1 … b_H]`` per DOF, flattened DOF by DOF (n_dof(2H + 1) reals).  Mesh e runs at
θ_e = r_e θ, so its harmonic j is harmonic j r_e n p of φ (an integer: the forcing is periodic).

How each term is evaluated
--------------------------
Every element's deflection δ_e(φ) is a trigonometric polynomial (the STE E_e exactly, with its own
harmonics when they exceed H).  Its dead-zone term K_e f(δ_e; D_e) is projected by the 1-DOF routine
:func:`~geardyn.analysis.hb.aft.dead_zone_terms` (its compiled kernel): the contact switches located
on a time grid and refined by Newton, the interval integrals in closed form.  That routine is used
rather than a sampled AFT because it is exact for the truncated δ_e (no aliasing, no quadrature error
at the kink of f), the residual is continuously differentiable and its Jacobian is the multiplication
operator of K_e χ_e (χ_e = 1 in contact) — the operator Hill's matrix needs — and because it makes the
system of the paper's torsional pair reproduce the 1-DOF harmonic balance to rounding.  The damping
products C_e δ_e' and the linear terms are exact convolutions.  The Jacobian is analytic::

    J = ν² I⊗D₂ + A⊗I + ν B⊗D₁ + Σ_e (W[e] V[e]ᵀ) ⊗ Re[ν T(Ĉ_e) diag(ik) + T(Ŝ_e)],

D₁, D₂ the derivative operators in real coefficients, T(·) the Toeplitz (multiplication) matrix and
Ŝ_e the coefficients of K_e(θ)·χ_e(φ).

Rigid-body modes
----------------
A free rigid-body mode R (:func:`~geardyn.systems.elements.rigid_modes`: K̄R = 0, C̃_bR = 0,
F̃·R = 0) leaves the mean of the rigid coordinate undetermined: adding R c to the harmonic 0 of every
DOF maps a solution to a solution, so J has the right null vectors (R in the harmonic-0 slots) and the
left null vectors (M̃R there: the harmonic-0 momentum balance along R holds identically).  The gauge
Rᵀ a_0 = 0 fixes it in a bordered system with one Lagrange multiplier λ per rigid mode,

    [ J    L ] [Δa]     [ R(a) + L λ ]
    [ Nᵀ   0 ] [Δλ] = − [ Nᵀ a       ],        N = R in harmonic 0,  L = M̃R in harmonic 0,

which is square and nonsingular (λ converges to zero, the residual being consistent); the unknown
vector is (a, λ).  The rigid mode's Floquet multipliers (exactly 1) are left out of the stability
test (:mod:`.system_hill`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ...errors import ModelError
from ...integrate import start_state
from ...status import Status
from ...systems.elements import rigid_modes
from ...systems.report import static_mesh_forces
from ..periodic.orbit import require_periodic
from ._aftkernel import dead_zone_kernel, real_operator_kernel
from ._blas import single_thread_blas
from .aft import ROOT_MAX_ITER, ROOT_TOL, HarmonicBasis, signal_extrema, time_samples, toeplitz
from .hill import HillResult
from .monodromy import check_floquet, monodromy_floquet
from .solve import DEFAULT_HARMONICS, GUESS_DTAU, GUESS_TRANSIENT, NEWTON_MAX_ITER, NEWTON_TOL, HBSolution, HBSystem
from .system_hill import system_hill_floquet

__all__ = [
    "HBSystemEquations",
    "HBSystemSolution",
    "hb_system_solve",
    "system_linear_guess",
    "system_guess_from_simulation",
    "dynamic_factors",
]

#: A harmonic j r_e n p of a mesh series counts as an integer within this (relative) tolerance.
HARMONIC_RTOL = 1e-9
#: Samples per response period of the mesh forces for the dynamic factor (times the HB samples N).
FORCE_OVERSAMPLE = 4


class Layout(NamedTuple):
    """Layout of the unknown vector: ``dofs`` blocks of 2H + 1 real coefficients, then ``rigid`` multipliers.

    ``size`` is its length (what :meth:`HBSystem.newton` and the continuation read as ``basis.size``).
    """

    size: int
    dofs: int
    H: int
    rigid: int


class _Element(NamedTuple):
    name: str
    W: np.ndarray  # (n,) M̃⁻¹ V[e]
    V: np.ndarray  # (n,)
    C: np.ndarray  # centred complex series in φ of the damping
    K: np.ndarray  # of the stiffness
    E: np.ndarray  # real coefficients of the STE on the δ basis
    D: float


class _Point(NamedTuple):
    model: Any
    omega: float
    elements: tuple[_Element, ...]
    A: np.ndarray
    B: np.ndarray
    g: np.ndarray


def _phi_series(row: np.ndarray, ratio: float, periods: int) -> np.ndarray:
    """Centred complex coefficients in φ = θ/periods of Σ_j row[j, 0] cos(j r θ) + row[j, 1] sin(j r θ)."""
    j = np.arange(row.shape[0])
    qf = j * ratio * periods
    q = np.rint(qf).astype(int)
    if np.any(np.abs(qf - q) > HARMONIC_RTOL * np.maximum(1.0, qf)):
        raise ModelError(f"ratio: mesh ratio {ratio!r} times {periods} periods is not an integer harmonic")
    L = int(q[-1]) if q.size else 0
    z = np.zeros(2 * L + 1, dtype=complex)
    z[L] = row[0, 0]
    half = 0.5 * (row[1:, 0] - 1j * row[1:, 1])
    np.add.at(z, L + q[1:], half)
    np.add.at(z, L - q[1:], np.conj(half))
    return z


def _samples(z: np.ndarray, Ns: int) -> np.ndarray:
    """Values at φ_j = 2πj/Ns of the real trigonometric polynomial with centred coefficients z (L < Ns/2)."""
    L = (len(z) - 1) // 2
    arr = np.zeros(Ns, dtype=complex)
    arr[np.arange(-L, L + 1) % Ns] = z
    return (np.fft.ifft(arr) * Ns).real


def _centred(z: np.ndarray, L: int) -> np.ndarray:
    """Centred coefficients cut or zero-padded to half-length L."""
    Lz = (len(z) - 1) // 2
    m = min(L, Lz)
    out = np.zeros(2 * L + 1, dtype=complex)
    out[L - m : L + m + 1] = z[Lz - m : Lz + m + 1]
    return out


class HBSystemEquations:
    """Residual, Jacobian, Newton and Hill's matrix of a system's HB equations (see the module docstring).

    Parameters
    ----------
    model : System
        The system at its base point (a value of ``param`` given to a method replaces that parameter).
    harmonics : int
        H per DOF: harmonics of ν = ω/(n p) (default :data:`~geardyn.analysis.hb.solve.DEFAULT_HARMONICS`).
    period : int
        n forcing periods per response period.
    param : str, optional
        A system parameter (``omega``, ``<mesh>.xi0``, ``<clearance>.D`` ...) for :meth:`residual` and
        :meth:`dR_dp`.
    samples : int, optional
        Time samples N per response period (default :func:`~geardyn.analysis.hb.aft.time_samples`).
    floquet : str
        How :meth:`stability` computes the multipliers: ``"monodromy"`` (default, :mod:`.monodromy`) or
        ``"hill"`` (Hill's method, :mod:`.system_hill`).

    Raises
    ------
    ModelError
        For incommensurate mesh frequencies, a bad H or n.
    """

    def __init__(
        self,
        model: Any,
        harmonics: int = DEFAULT_HARMONICS,
        period: int = 1,
        param: str | None = None,
        samples: int | None = None,
        *,
        floquet: str = "monodromy",
    ):
        if int(period) < 1:
            raise ModelError(f"period: must be an integer >= 1, got {period!r}")
        if int(harmonics) < 1:
            raise ModelError(f"harmonics: must be an integer >= 1, got {harmonics!r}")
        p = require_periodic(model, "harmonic balance")
        self.base, self.n, self.H, self.param = model, int(period), int(harmonics), param
        self.floquet = check_floquet(floquet)
        self.periods = self.n * p  # base periods per response period
        H = self.H
        self.M = 2 * H + 1
        R = rigid_modes(model)
        nd, r = model.n, R.shape[1]
        self.rigid = R
        self.elastic = np.linalg.svd(R.T)[2][r:].T if r else np.eye(nd)  # orthonormal complement (n, n − r)
        self.basis = Layout(nd * self.M + r, nd, H, r)
        N0 = nd * self.M
        self.gauge = np.zeros((N0, r))  # right null vectors: R in the harmonic-0 slots
        self.gauge[np.arange(nd) * self.M, :] = R
        left = np.linalg.inv(np.asarray(model.Mi)) @ R
        self.left = np.zeros((N0, r))
        self.left[np.arange(nd) * self.M, :] = left / np.maximum(np.linalg.norm(left, axis=0), 1e-300)
        self._cache: dict[float | None, _Point] = {}
        self.Hd = max(H, self._ste_harmonics(model))
        mh = max((m.n_harmonics * m.ratio for m in model.meshes), default=0.0)
        self.N = int(samples) if samples else time_samples(self.Hd, self.periods, int(math.ceil(mh)) + 2)
        self.dbasis = HarmonicBasis(self.Hd, self.N)
        self.hbasis = HarmonicBasis(H, 2 * H + 2)
        Hd = self.Hd
        self._pad = np.concatenate([np.arange(H + 1), Hd + 1 + np.arange(H)])
        kk = np.arange(1, H + 1, dtype=float)
        self._k = kk
        self._k2 = np.concatenate([[0.0], kk**2, kk**2])
        D1 = np.zeros((self.M, self.M))
        D1[np.arange(1, H + 1), H + 1 + np.arange(H)] = kk
        D1[H + 1 + np.arange(H), np.arange(1, H + 1)] = -kk
        self.D1 = D1
        self._ik = 1j * np.arange(-H, H + 1)
        self._ikd = 1j * np.arange(-Hd, Hd + 1)
        names = [m.name for m in model.meshes]
        self.reference = names.index(model.scaling.reference) if model.scaling.reference in names else 0

    # ------------------------------------------------------------------ the system at one parameter value
    def _ste_harmonics(self, model: Any) -> int:
        """Largest harmonic of φ in the meshes' STE series."""
        out = 0
        for m in model.meshes:
            nz = [j + 1 for j, e in enumerate(m.eps) if e != 0.0]
            if nz:
                out = max(out, int(round(max(nz) * m.ratio * self.periods)))
        return out

    def model_at(self, p: float | None = None) -> Any:
        """The system at parameter value ``p`` (the base system when ``p`` is None)."""
        return self._entry(p).model

    def check(self, p: float) -> None:
        """Raise :class:`ModelError` when ``p`` is not a valid value of the parameter."""
        self._entry(p)

    def _entry(self, p: float | None) -> _Point:
        key = None if (p is None or self.param is None) else float(p)
        e = self._cache.get(key)
        if e is not None:
            return e
        if len(self._cache) > 32:
            self._cache.clear()
        if key is not None and self.param == "omega" and None in self._cache:
            b = self._cache[None]  # the series do not depend on ω: only ν changes
            m = self.base.with_param("omega", key)
            e = self._cache[key] = _Point(m, m.omega, b.elements, b.A, b.B, b.g)
            return e
        m = self.base if key is None else self.base.with_param(self.param, key)
        if key is not None and self.param != "omega":
            require_periodic(m, "harmonic balance")
        if self._ste_harmonics(m) > self.Hd:
            raise ModelError(
                f"{self.param}: the STE reaches harmonic {self._ste_harmonics(m)} of ν, above the "
                f"{self.Hd} this harmonic balance was set up with"
            )
        Mi = np.asarray(m.Mi)
        els = []
        for i, mesh in enumerate(m.meshes):
            cf = mesh.coefficients()
            C = _phi_series(cf[0], mesh.ratio, self.periods)
            K = _phi_series(cf[1], mesh.ratio, self.periods)
            E = self.dbasis.to_real(_centred(_phi_series(cf[2], mesh.ratio, self.periods), self.Hd))
            els.append(_Element(mesh.name, Mi @ m.V[i], np.asarray(m.V[i]), C, K, E, float(mesh.D)))
        for i, nm in enumerate(m.clearance_names):
            els.append(
                _Element(
                    nm,
                    Mi @ m.Vc[i],
                    np.asarray(m.Vc[i]),
                    np.array([m.cc[i]], dtype=complex),
                    np.array([m.kc[i]], dtype=complex),
                    np.zeros(2 * self.Hd + 1),
                    float(m.Dc[i]),
                )
            )
        e = _Point(m, m.omega, tuple(els), Mi @ np.asarray(m.Kb), Mi @ np.asarray(m.Cb), Mi @ np.asarray(m.F))
        self._cache[key] = e
        if key is not None and self.param == "omega" and None not in self._cache:
            self._cache[None] = _Point(self.base, self.base.omega, e.elements, e.A, e.B, e.g)
        return e

    def nu(self, p: float | None = None) -> float:
        return self._entry(p).omega / self.periods

    @property
    def elements(self) -> tuple[str, ...]:
        """Element names: the meshes, then the clearances."""
        return tuple(e.name for e in self._entry(None).elements)

    # ------------------------------------------------------------------ evaluation
    def _split(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(x, dtype=float)[: self.basis.dofs * self.M].reshape(self.basis.dofs, self.M)

    def _d1(self, Q: np.ndarray) -> np.ndarray:
        """φ-derivative of real coefficient rows."""
        H = self.H
        out = np.zeros_like(Q)
        out[..., 1 : H + 1] = self._k * Q[..., H + 1 :]
        out[..., H + 1 :] = -self._k * Q[..., 1 : H + 1]
        return out

    def deflection(self, x: np.ndarray, e: int, p: float | None = None) -> np.ndarray:
        """Real coefficients (on the δ basis of ``Hd`` harmonics) of element e's deflection δ_e = V[e]·q − E_e."""
        el = self._entry(p).elements[e]
        d = np.zeros(2 * self.Hd + 1)
        d[self._pad] = el.V @ self._split(x)
        return d - el.E

    def _element_terms(self, el: _Element, Q: np.ndarray, nu: float):
        """(damping term without ν, dead-zone term) in real coefficients, and the S series of K χ."""
        H, Hd = self.H, self.Hd
        d = np.zeros(2 * Hd + 1)
        d[self._pad] = el.V @ Q
        d -= el.E
        G, S, _ = dead_zone_kernel(
            d, el.K, el.D, self.dbasis.cos_table, self.dbasis.sin_table, Hd, ROOT_MAX_ITER, ROOT_TOL
        )
        Lc = (len(el.C) - 1) // 2
        damp = np.convolve(el.C, self._ikd * self.dbasis.to_complex(d))[Lc + Hd - H : Lc + Hd + H + 1]
        hb = self.hbasis
        return hb.to_real(damp), hb.to_real(G[Hd - H : Hd + H + 1]), S

    def _core(self, x: np.ndarray, p: float | None, jacobian: bool):
        """R (n, M) split as ν² R2 + ν R1 + R0, the Jacobian (or None) and the per-element S series."""
        pt = self._entry(p)
        nu = pt.omega / self.periods
        Q = self._split(x)
        R2 = -self._k2 * Q
        R1 = pt.B @ self._d1(Q)
        R0 = pt.A @ Q
        R0[:, 0] -= pt.g
        Ss = []
        for el in pt.elements:
            dmp, dz, S = self._element_terms(el, Q, nu)
            R1 += np.outer(el.W, dmp)
            R0 += np.outer(el.W, dz)
            Ss.append(S)
        J = self._jacobian(pt, nu, Ss) if jacobian else None
        return (R2, R1, R0), nu, J, Ss, pt

    def _damping_ops(self, pt: _Point) -> list[np.ndarray]:
        """Real multiplication operators of every element's damping series C_e."""
        H = self.H
        return [real_operator_kernel(toeplitz(el.C, H), H) for el in pt.elements]

    def _jacobian(self, pt: _Point, nu: float, Ss: list[np.ndarray]) -> np.ndarray:
        H, M, nd = self.H, self.M, self.basis.dofs
        I = np.eye(M)
        J = np.kron(np.eye(nd), np.diag(-(nu**2) * self._k2)) + np.kron(pt.A, I) + nu * np.kron(pt.B, self.D1)
        for el, S in zip(pt.elements, Ss):
            op = real_operator_kernel(nu * toeplitz(el.C, H) * self._ik[None, :] + toeplitz(S, H), H)
            J += np.kron(np.outer(el.W, el.V), op)
        return J

    def residual(
        self, a: np.ndarray, p: float | None = None, jacobian: bool = True
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Residual (length ``basis.size``: the HB equations, then the gauge rows) and its Jacobian.

        Parameters
        ----------
        a : ndarray
            The unknown vector (coefficients DOF by DOF, then the gauge multipliers).
        p : float, optional
            Parameter value.
        jacobian : bool
            Also return the (bordered) Jacobian.

        Returns
        -------
        (R, J) : ndarray, ndarray or None
        """
        a = np.asarray(a, dtype=float)
        (R2, R1, R0), nu, J, _, _ = self._core(a, p, jacobian)
        N0, r = self.basis.size - self.basis.rigid, self.basis.rigid
        R = (nu * nu * R2 + nu * R1 + R0).ravel()
        if r:
            R = np.concatenate([R + self.left @ a[N0:], self.gauge.T @ a[:N0]])
        if not jacobian:
            return R, None
        if r:
            J = np.block([[J, self.left], [self.gauge.T, np.zeros((r, r))]])
        return R, J

    def dR_dp(self, a: np.ndarray, p: float) -> np.ndarray:
        """Derivative of the residual in the parameter at fixed unknowns (analytic for ω, else a central
        difference, exact to rounding for parameters entering linearly)."""
        if self.param is None:
            raise ModelError("dR_dp: the system has no continuation parameter")
        if self.param != "omega":
            return self._dR_dp_fd(a, p)
        (R2, R1, _R0), nu, _, _, _ = self._core(a, p, False)
        d = ((2.0 * nu * R2 + R1) / self.periods).ravel()
        return np.concatenate([d, np.zeros(self.basis.rigid)])

    _dR_dp_fd = HBSystem._dR_dp_fd
    newton = HBSystem.newton

    def bordered(self, a: np.ndarray, p: float, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """R and [[∂R/∂a, scale·∂R/∂p], [0 … 0]] for the continuation (as :meth:`HBSystem.bordered`).

        Parameters
        ----------
        a : ndarray
            The unknown vector.
        p : float
            Parameter value.
        scale : float
            Factor of the parameter column.

        Returns
        -------
        (R, A) : ndarray, ndarray
            The residual and the bordered matrix, its last row zero for the caller's border.
        """
        R, J = self.residual(a, p)
        A = np.pad(J, ((0, 1), (0, 1)))
        A[:-1, -1] = scale * self.dR_dp(a, p)
        return R, A

    def hill_operators(self, a: np.ndarray, p: float | None = None) -> tuple[np.ndarray, np.ndarray, float, float]:
        """K0 (the HB Jacobian), K1 (= 2ν I⊗D₁ + damping operator), ν and the mean trace of the damping.

        The variational equation y'' + 𝒞(τ) y' + 𝒦(τ) y = 0 with the Floquet ansatz gives the pencil
        λ² + λ K1 + K0 in real coefficients (see :mod:`.system_hill`).
        """
        _, nu, J, _, pt = self._core(a, p, True)
        nd, M = self.basis.dofs, self.M
        Cop = np.kron(pt.B, np.eye(M))
        trace = float(np.trace(pt.B))
        for el, op in zip(pt.elements, self._damping_ops(pt)):
            Cop += np.kron(np.outer(el.W, el.V), op)
            trace += float(el.V @ el.W) * float(el.C[(len(el.C) - 1) // 2].real)
        K1 = 2.0 * nu * np.kron(np.eye(nd), self.D1) + Cop
        return J, K1, nu, trace

    def stability(self, a: np.ndarray, p: float | None = None) -> HillResult:
        """The elastic multipliers of the solution ``a`` (the rigid-body modes left out): from the monodromy
        matrix of one period started on it (:mod:`.monodromy`) or by Hill's method (:mod:`.system_hill`), as
        ``floquet`` says."""
        if self.floquet == "hill":
            K0, K1, nu, trace = self.hill_operators(a, p)
            return system_hill_floquet(K0, K1, self.elastic, nu, self.H, trace)
        pt = self._entry(p)
        els = pt.elements
        E = [self.dbasis.to_complex(el.E) for el in els]
        return monodromy_floquet(
            pt.omega / self.periods,
            self.state(a, p),
            pt.A,
            pt.B,
            np.array([el.W for el in els]),
            np.array([el.V for el in els]),
            [el.C for el in els],
            [el.K for el in els],
            E,
            [np.array([gi], dtype=complex) for gi in pt.g],
            [el.D for el in els],
            P=self.elastic,
        )

    # ------------------------------------------------------------------ measures
    def extremes(self, a: np.ndarray, p: float | None = None, e: int | None = None) -> tuple[float, float]:
        """(δ_min, δ_max) over the period of element ``e`` (default the reference mesh)."""
        lo, hi, _, _ = signal_extrema(self.dbasis, self.deflection(a, self.reference if e is None else e, p))
        return lo, hi

    def element_extremes(self, a: np.ndarray, p: float | None = None) -> np.ndarray:
        """(elements, 2): δ_min, δ_max of every element (meshes, then clearances)."""
        return np.array([self.extremes(a, p, e) for e in range(len(self._entry(p).elements))])

    def mesh_force_max(self, a: np.ndarray, p: float | None = None) -> np.ndarray:
        """Largest mesh force s_m = C_m δ_m' + K_m f(δ_m) of every mesh over the period, from
        :data:`FORCE_OVERSAMPLE`·N samples (units k_ref b_c)."""
        pt = self._entry(p)
        nu = pt.omega / self.periods
        Ns = FORCE_OVERSAMPLE * self.N
        out = []
        for e in range(len(pt.model.meshes)):
            el = pt.elements[e]
            c = self.dbasis.to_complex(self.deflection(a, e, p))
            u, v = _samples(c, Ns), _samples(nu * self._ikd * c, Ns)
            out.append(float(np.max(_samples(el.C, Ns) * v + _samples(el.K, Ns) * (u - np.clip(u, -el.D, el.D)))))
        return np.array(out)

    def state(self, a: np.ndarray, p: float | None = None) -> np.ndarray:
        """(q̃, q̃') at θ = 0, comparable with a shooting orbit's state (up to the rigid-body position)."""
        Q = self._split(a)
        H = self.H
        return np.concatenate([Q[:, 0] + Q[:, 1 : H + 1].sum(axis=1), self.nu(p) * (Q[:, H + 1 :] @ self._k)])

    def project(self, Q: np.ndarray) -> np.ndarray:
        """Coefficients with the rigid-body part removed: the harmonic-0 rigid coordinate set to the gauge
        (Rᵀ a_0 = 0) and the rigid momentum (M̃R)ᵀ a_k of every other harmonic to zero, as on a solution."""
        Q = np.array(Q, dtype=float)
        R = self.rigid
        if R.shape[1] == 0:
            return Q
        Mt = np.linalg.inv(np.asarray(self.base.Mi))
        Pm = R @ np.linalg.solve(R.T @ Mt @ R, R.T @ Mt)
        Q[:, 1:] -= Pm @ Q[:, 1:]
        Q[:, 0] -= R @ (R.T @ Q[:, 0])
        return Q

    def unknowns(self, Q: np.ndarray) -> np.ndarray:
        """The unknown vector of coefficients Q (n_dof, 2H + 1), gauge multipliers zero."""
        return np.concatenate([np.asarray(Q, dtype=float).ravel(), np.zeros(self.basis.rigid)])


def system_linear_guess(eq: HBSystemEquations, p: float | None = None) -> np.ndarray:
    """Coefficients (n_dof, 2H + 1) of the response of the linearised, permanently meshing system (drive
    contact, mean mesh stiffness and damping, clearances closed only if their gap is zero), forced by the
    STE: K̄ a_0 = F̃ + Σ k_m D_m V_m, and per harmonic (K̄ − (νk)²M̃ + iνk C̄) ĉ_k = Σ_m V_m (k_m + iνk c_m) Ê_m,k.

    Parameters
    ----------
    eq : HBSystemEquations
    p : float, optional
        Parameter value.

    Returns
    -------
    ndarray (n_dof, 2H + 1)
    """
    pt = eq._entry(p)
    m = pt.model
    Mt = np.linalg.inv(np.asarray(m.Mi))
    Kt, Ct = np.asarray(m.Kb, float).copy(), np.asarray(m.Cb, float).copy()
    rhs0 = np.asarray(m.F, float).copy()
    nm = len(m.meshes)
    for i, el in enumerate(pt.elements):
        Lk, Lc = (len(el.K) - 1) // 2, (len(el.C) - 1) // 2
        k0, c0 = el.K[Lk].real, el.C[Lc].real
        if i >= nm and el.D > 0:
            continue
        Kt += k0 * np.outer(el.V, el.V)
        Ct += c0 * np.outer(el.V, el.V)
        rhs0 += k0 * el.D * el.V
    H, nu = eq.H, pt.omega / eq.periods
    c = np.zeros((m.n, 2 * H + 1), dtype=complex)
    c[:, H] = np.linalg.lstsq(Kt, rhs0, rcond=1e-12)[0]
    for k in range(1, H + 1):
        f = np.zeros(m.n, dtype=complex)
        for el in pt.elements[:nm]:
            Ek = eq.dbasis.to_complex(el.E)[eq.Hd + k]
            f += el.V * (el.K[(len(el.K) - 1) // 2].real + 1j * nu * k * el.C[(len(el.C) - 1) // 2].real) * Ek
        if np.any(f != 0):
            c[:, H + k] = np.linalg.solve(Kt - (nu * k) ** 2 * Mt + 1j * nu * k * Ct, f)
            c[:, H - k] = np.conj(c[:, H + k])
    return eq.project(np.array([eq.hbasis.to_real(row) for row in c]))


def system_guess_from_simulation(
    eq: HBSystemEquations,
    state0: Sequence[float] | None = None,
    *,
    transient: int = GUESS_TRANSIENT,
    dtau: float = GUESS_DTAU,
) -> np.ndarray | None:
    """Coefficients (n_dof, 2H + 1) of the attractor reached by simulation from ``state0`` (n forcing periods
    after ``transient``), the rigid-body part removed (:meth:`HBSystemEquations.project`); None if the
    simulation diverged.

    Parameters
    ----------
    eq : HBSystemEquations
    state0 : (u0, v0) of the reference mesh or a full (2n,) state, optional
    transient : int
        Forcing periods discarded (default :data:`~geardyn.analysis.hb.solve.GUESS_TRANSIENT`).
    dtau : float
        Step (default :data:`~geardyn.analysis.hb.solve.GUESS_DTAU`).

    Returns
    -------
    ndarray or None
    """
    from ...integrate import trajectory
    from ...model import IntegrationOptions

    m, n, H = eq.base, eq.n, eq.H
    opts = IntegrationOptions(dtau=dtau, transient=int(transient), periods=n)
    tr = trajectory(m, start_state(m, state0), opts, history_periods=n)
    q = tr.x[:-1, : m.n]
    if not np.all(np.isfinite(q)):
        return None
    X = np.fft.rfft(q, axis=0) / q.shape[0]
    a = np.zeros((m.n, 2 * H + 1))
    a[:, 0] = X[0].real
    k = min(H, X.shape[0] - 1)
    a[:, 1 : k + 1] = 2.0 * X[1 : k + 1].real.T
    a[:, H + 1 : H + 1 + k] = -2.0 * X[1 : k + 1].imag.T
    return eq.project(a)


@dataclass
class HBSystemSolution(HBSolution):
    """A harmonic-balance solution of a system at one parameter value (non-dimensional); the fields of
    :class:`~geardyn.analysis.hb.solve.HBSolution`, for the system.

    Attributes
    ----------
    model : System
        The system point.
    harmonics, period, samples : int
        H per DOF, n and the time samples N per response period.
    coefficients : ndarray (n_dof, 2H + 1)
        ``[a_0, a_1 … a_H, b_1 … b_H]`` of every DOF q̃_i(φ), φ = θ/(n p).
    status : Status
        Newton's outcome.
    iterations : int
    residual : float
        Norm of the residual at the last iterate.
    u_min, u_max : float
        Extremes of the reference mesh's δ (NaN unless converged).
    hill : HillResult or None
        The elastic multipliers (rigid-body modes left out; None unless converged).
    equations : HBSystemEquations
        The equations solved (for :meth:`state`, deflections and mesh forces).
    unknowns : ndarray
        The full unknown vector (coefficients, then the gauge multipliers).
    element_extremes : ndarray (elements, 2)
        δ_min, δ_max of every element (meshes, then clearances).
    rigid : int
        Rigid-body modes (their 2 multipliers each, exactly 1, are left out).
    """

    equations: Any = field(default=None, repr=False)
    unknowns: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    element_extremes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    rigid: int = 0

    def state(self) -> np.ndarray:
        """(q̃, q̃') at θ = 0."""
        return self.equations.state(self.unknowns)

    def signal(self, samples: int = 512) -> tuple[np.ndarray, np.ndarray]:
        """(τ, δ) of the reference mesh at ``samples`` equispaced instants over the response period."""
        eq = self.equations
        phi = 2.0 * np.pi * np.arange(samples) / samples
        return phi / eq.nu(), eq.dbasis.evaluate(eq.deflection(self.unknowns, eq.reference), phi)


def hb_system_solve(
    model: Any,
    harmonics: int = DEFAULT_HARMONICS,
    period: int = 1,
    guess: np.ndarray | str | None = None,
    *,
    samples: int | None = None,
    tol: float = NEWTON_TOL,
    max_iter: int = NEWTON_MAX_ITER,
    stability: bool = True,
    state0: Sequence[float] | None = None,
    floquet: str = "monodromy",
) -> HBSystemSolution:
    """Solve the harmonic-balance equations of a multi-DOF system at one parameter point.

    Parameters
    ----------
    model : System
        The system (its forcing must be periodic).
    harmonics : int
        H per DOF (default :data:`~geardyn.analysis.hb.solve.DEFAULT_HARMONICS`).
    period : int
        n: the response repeats after n forcing periods.
    guess : ndarray (n_dof, 2H + 1), "simulate", "linear" or None
        Start: coefficients, the linearised permanently meshing response, or the attractor reached by
        simulation from ``state0`` (default ``"simulate"``; ``"linear"`` if the simulation diverges).
    samples : int, optional
        Time samples per response period.
    tol, max_iter : float, int
        Newton tolerance and iteration limit (defaults :data:`~geardyn.analysis.hb.solve.NEWTON_TOL`,
        :data:`~geardyn.analysis.hb.solve.NEWTON_MAX_ITER`).
    stability : bool
        Compute Hill's multipliers of a converged solution.
    state0 : (u0, v0) or (2n,), optional
        Start of the simulation of the default guess.
    floquet : str
        How the multipliers are computed: ``"monodromy"`` (default) or ``"hill"`` (see
        :class:`HBSystemEquations`).

    Returns
    -------
    HBSystemSolution
        Check ``status``; values are NaN unless it is ``OK``.

    Raises
    ------
    ModelError
        For incommensurate meshes, bad ``harmonics``/``period`` or a guess of the wrong shape.
    """
    eq = HBSystemEquations(model, harmonics, period, samples=samples, floquet=floquet)
    H, nd = eq.H, model.n
    if guess is None or (isinstance(guess, str) and guess == "simulate"):
        Q0 = system_guess_from_simulation(eq, state0)
        if Q0 is None:
            Q0 = system_linear_guess(eq)
    elif isinstance(guess, str) and guess == "linear":
        Q0 = system_linear_guess(eq)
    elif isinstance(guess, str):
        raise ModelError(f"guess: expected coefficients, 'simulate' or 'linear', got {guess!r}")
    else:
        Q0 = np.asarray(guess, dtype=float)
        if Q0.shape != (nd, 2 * H + 1):
            raise ModelError(f"guess: expected coefficients of shape ({nd}, {2 * H + 1}), got {Q0.shape}")
    with single_thread_blas():
        x, status, its, r = eq.newton(eq.unknowns(Q0), None, tol=tol, max_iter=max_iter)
        sol = HBSystemSolution(
            model, H, eq.n, eq.N, eq._split(x).copy(), status, its, r, equations=eq, unknowns=x, rigid=eq.basis.rigid
        )
        if status is Status.OK:
            sol.u_min, sol.u_max = eq.extremes(x)
            sol.element_extremes = eq.element_extremes(x)
            if stability:
                sol.hill = eq.stability(x)
    return sol


def dynamic_factors(eq: HBSystemEquations, a: np.ndarray, p: float | None = None) -> list[float | None]:
    """Largest mesh force over the period divided by the static mesh force, per mesh.

    Parameters
    ----------
    eq : HBSystemEquations
    a : ndarray
        The unknown vector of a solution.
    p : float, optional
        Parameter value.

    Returns
    -------
    list of float or None
        One per mesh; None where the static mesh force is 0.
    """
    fs = static_mesh_forces(eq.model_at(p))
    fm = eq.mesh_force_max(a, p)
    return [float(f / s) if s > 0 and math.isfinite(f) else None for f, s in zip(fm, fs)]
