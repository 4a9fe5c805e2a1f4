"""The harmonic-balance equations of any system: residual, analytic Jacobian, Newton, Floquet multipliers.

The system is given by its :class:`~geardyn.analysis.hb.form.HBForm` (``model.hb_form(n)``)::

    q'' + B q' + A q + Σ_e W_e s_e = G0 + ν² G2,      s_e = C_e δ_e' + K_e f_e(δ_e),      δ_e = V_e·q − E_e,

a period-n response sought as H harmonics of ν = ω/periods in φ = ντ for every coordinate: the unknown is the
(dofs, 2H + 1) array of real coefficients ``[a_0, a_1 … a_H, b_1 … b_H]`` per coordinate, flattened coordinate by
coordinate, then one gauge multiplier per rigid-body mode.

How each term is evaluated
--------------------------
Every element's deflection δ_e is a trigonometric polynomial (E_e with its own harmonics when they exceed H).
Its force K_e f_e(δ_e) is projected by the element's law (:data:`LAW_TERMS`; the dead zone by
:func:`~geardyn.analysis.hb.aft.dead_zone_terms`' kernel: the contact switches located on a time grid and refined
by Newton, the interval integrals in closed form — exact for the truncated δ_e, no aliasing, a C¹ residual whose
Jacobian is the multiplication operator of K_e f_e'(δ_e), the operator Hill's matrix needs; a rolling bearing's
two rows by the System's law sampled on the time grid, :func:`~geardyn.analysis.hb.aft.sampled_terms`, with the
cross blocks of its 2×2 stiffness).  A law is one function returning the projections G and the series S_ij.  The
damping products and linear terms are exact convolutions.  The Jacobian is analytic::

    J = −ν² I⊗D₂ + A⊗I + ν B⊗D₁ + Σ_e (W_e V_eᵀ) ⊗ Re[ν T(Ĉ_e) diag(ik) + T(Ŝ_e)] + Σ_{i≠j} (W_i V_jᵀ) ⊗ T(Ŝ_ij),

D₁, D₂ the derivative operators in real coefficients, T(·) the Toeplitz (multiplication) matrix.  A form with one
coordinate and one dead-zone element without linear terms (:attr:`HBForm.scalar <.form.HBForm.scalar>`: the 1-DOF
pair) is evaluated by compiled kernels of the same equations (``benchmarks/hb_speed.py --general`` times both).

A free rigid-body mode R (no stiffness, damping or load along it) leaves the mean of the rigid coordinate undetermined:
the gauge Rᵀa_0 = 0 is imposed with one Lagrange multiplier per mode (``docs/hb.md``, "Rigid-body modes").

References
----------
T. M. Cameron and J. H. Griffin, J. Appl. Mech. 56 (1989) 149–154 (AFT); G. W. Hill, Acta Math. 8 (1886) 1–36.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any, NamedTuple

import numpy as np
from scipy import sparse
from scipy.linalg.lapack import dgesv
from scipy.sparse.linalg import splu
from threadpoolctl import threadpool_limits

from ...errors import ModelError
from ...grid import param_name
from ...integrate import start_state
from ...model import DEFAULT_DTAU, IntegrationOptions
from ...status import Status
from ...systems.rolling import static_deflection
from ._aftkernel import bordered_nu_kernel, centred, real_operator_kernel, residual_kernel
from .aft import (
    ROOT_MAX_ITER,
    ROOT_TOL,
    HarmonicBasis,
    dead_zone_terms,
    sampled_terms,
    signal_extrema,
    time_samples,
    toeplitz,
)
from .form import LAWS, HBForm, mean
from .hill import HillResult, system_hill_floquet
from .monodromy import _check_floquet, bearing_rows, monodromy_floquet

__all__ = ["HBEquations", "default_harmonics", "single_thread_blas", "solve", "DEFAULT_HARMONICS", "NEWTON_TOL"]

#: Default harmonics of ν (see ``docs/hb.md`` for the convergence study behind it).
DEFAULT_HARMONICS = 16
#: The most harmonics the default of a multi-cycle excitation takes (the Jacobian's LU costs about (2H + 1)³).
MAX_DEFAULT_HARMONICS = 1024
#: Newton converges when ||R|| <= NEWTON_TOL·(1 + ||a||).
NEWTON_TOL = 1e-11
NEWTON_MAX_ITER = 40
NEWTON_MIN_DAMPING = 2.0**-12
#: Unknown vectors larger than this count as diverged.
DIVERGED_NORM = 1e8
#: Relative step of the central difference for the derivative of R in a parameter other than ω.
FD_REL_STEP = 1e-6
#: Start simulation: forcing periods discarded and the step.
GUESS_TRANSIENT = 400
GUESS_DTAU = DEFAULT_DTAU
#: Samples per response period of the mesh forces for the dynamic factor (times the HB samples N).
FORCE_OVERSAMPLE = 4
#: Forms of more coordinates assemble the Jacobian sparse (:class:`SparseJacobian`; ``benchmarks/hb_scaling.py``).
SPARSE_DOFS = 8
#: SuperLU's pivot threshold: a diagonal pivot is kept while at least this times the column's largest entry.
PIVOT_THRESH = 0.01
#: SuperLU's column ordering of the lifted matrix (:class:`SparseJacobian`; the 48-DOF chain's at H = 16, ω = 0.75:
#: 76 500 entries in L + U, 2.5 ms a factorisation, against 4.8 ms with MMD_AT_PLUS_A and 8.2 ms for J itself).
PERMC_SPEC = "COLAMD"
#: Use the compiled kernels of a scalar form (``benchmarks/hb_speed.py --general`` switches them off).
SPECIALISE = True


def single_thread_blas() -> threadpool_limits:
    """Limit the BLAS of NumPy and SciPy to one thread inside a ``with`` block: the matrices are small and many."""
    return threadpool_limits(limits=1, user_api="blas")


def _slots(rows: np.ndarray, cols: np.ndarray, n: int) -> tuple:
    """The compressed-column slot of each entry (rows[i], cols[i]) of an n×n matrix (duplicates summed), the row
    indices and the column pointers: (slot, indices, indptr, n)."""
    uniq, slot = np.unique(np.asarray(cols, dtype=np.int64) * n + rows, return_inverse=True)
    return slot, (uniq % n).astype(np.int32), np.searchsorted(uniq // n, np.arange(n + 1)).astype(np.int32), n


class SparseJacobian:
    """A Jacobian J = L + Σ_(i,j) (W_i V_jᵀ) ⊗ op_ij of more than :data:`SPARSE_DOFS` coordinates (L: the linear
    parts, the gauge rows and columns) held as the values at ``pattern`` (:meth:`HBEquations._pattern`) of the lifted
    matrix of the unknowns z_j = (V_jᵀ ⊗ I) x (every element's deflection) and y_i = Σ_j op_ij z_j::

        [ L    0   U ] [x]   [b]
        [ Vᵀ  −I   0 ] [z] = [0]        U: the columns W_i ⊗ I,  Vᵀ: the rows V_jᵀ ⊗ I,  Op: the blocks op_ij,
        [ 0   Op  −I ] [y]   [0]

    whose Schur complement onto x is J (each element's dense M×M operator stored once, not once per pair of its
    coordinates).  A border (last column ``col`` and row, ``A[-1] = row``) lies on x only.  SuperLU factorises it
    (:data:`PERMC_SPEC`, :data:`PIVOT_THRESH`, one refinement step); :meth:`tocsc` and ``numpy.asarray`` give J."""

    def __init__(self, pattern: tuple, values: np.ndarray, col: np.ndarray | None = None):
        self.pattern, self.values, self.col = pattern, values, col
        self.row = None if col is None else np.zeros(col.size + 1)

    def __setitem__(self, index: int, row: np.ndarray) -> None:
        self.row[:] = row

    def lifted(self) -> sparse.csc_matrix:
        """The lifted matrix (the class docstring), bordered when :attr:`col` is given."""
        (slot, indices, indptr, n), v = self.pattern[self.col is not None], self.values
        v = v if self.col is None else np.concatenate([v, self.col, self.row])
        return sparse.csc_matrix((np.bincount(slot, v, indices.size), indices, indptr), (n, n))

    def tocsc(self) -> sparse.csc_matrix:
        """J (bordered when :attr:`col` is given): the Schur complement L + U Op Vᵀ of the lifted matrix."""
        m, k = self.lifted(), self.pattern[2] + (self.col is not None)
        z = k + self.pattern[3]
        J = (m[:k, :k] + m[:k, z:] @ (m[z:, k:z] @ m[k:z, :k])).tocsc()
        J.eliminate_zeros()
        return J

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self.tocsc().toarray()

    def solve(self, b: np.ndarray, lu: Any = None) -> np.ndarray:
        """x with A x = b (the lifted system's with [b, 0, 0]); ``lu``: another lifted matrix's factors of this pattern,
        used instead (a chord step, refined once with this matrix's residual); the factors used are left in :attr:`lu`
        (None after the least-squares answer of a matrix that is not finite)."""
        m = self.lifted()
        self.lu = None
        if not np.all(np.isfinite(m.data)):
            return np.linalg.lstsq(np.asarray(self), b, rcond=None)[0]
        if lu is None:
            try:
                lu = splu(m, permc_spec=PERMC_SPEC, diag_pivot_thresh=PIVOT_THRESH)
            except RuntimeError as err:  # "Factor is exactly singular"
                raise np.linalg.LinAlgError(str(err)) from None
        self.lu = lu
        rhs = np.zeros(m.shape[0])
        rhs[: b.size] = b
        x = lu.solve(rhs)
        return (x + lu.solve(rhs - m @ x))[: b.size]


def solve(A: np.ndarray | SparseJacobian, b: np.ndarray, robust: bool = False, lu: Any = None) -> np.ndarray:
    """x with A x = b by LAPACK ``dgesv`` (``numpy.linalg.solve`` costs ten times the factorisation here), or a
    :class:`SparseJacobian`'s SuperLU (always robust).

    Parameters
    ----------
    A : ndarray (m, m) or SparseJacobian
    b : ndarray (m,)
    robust : bool
        When True, a dense A that is not finite gives the least-squares answer instead of an error.
    lu : optional
        A sparse A's factors of a nearby matrix of the same pattern, used as in a chord step
        (:meth:`SparseJacobian.solve`).

    Raises
    ------
    numpy.linalg.LinAlgError
        When A is exactly singular.
    """
    if isinstance(A, SparseJacobian):
        return A.solve(b, lu)
    if robust and not np.all(np.isfinite(A)):  # the least-squares answer of a matrix that is not finite
        return np.linalg.lstsq(A, b, rcond=None)[0]
    _lu, _piv, x, info = dgesv(A, b)
    if info != 0:
        raise np.linalg.LinAlgError("Singular matrix" if info > 0 else f"dgesv: illegal argument {-info}")
    return x


#: Element law → the projections G_i of its rows' forces K f_i(δ) and the series S_ij of K ∂f_i/∂δ_j (local row
#: indices; any shapes that reshape to (rows, 2Hd + 1) and (rows, rows, 4Hd + 1)), whose Toeplitz matrices are the
#: Jacobian's blocks, of its rows' deflections ``ds`` and elements ``els``: a new law is one such function (its rows:
#: ``LAWS``).  The dead zone's K f(δ; D) and the series S of K f'(δ)
#: (:func:`.aft.dead_zone_terms`); a law sampled on the time grid (its ``rule``, :func:`.aft.sampled_terms`).
LAW_TERMS = {
    "dead_zone": lambda ds, els, basis, periods: dead_zone_terms(basis, ds[0], els[0].K, els[0].gap)[:2],
    "rolling_bearing": lambda ds, els, basis, periods: sampled_terms(basis, ds, els[0].rule, els[0].K[0].real, periods),
}


def default_harmonics(model: Any, period: int = 1) -> int:
    """H when none is given: :data:`DEFAULT_HARMONICS`, or for a forcing period of P > 1 mesh cycles (harmonics of
    ω/(P n): a pair's excitation of several cycles or torque orders; a system's mesh ratios, orders or rolling
    bearings) the larger of P·:data:`DEFAULT_HARMONICS` and n times the excitation's harmonics.

    Parameters
    ----------
    model : System
    period : int
        n, forcing periods per response period.

    Raises
    ------
    ModelError
        When that is more than :data:`MAX_DEFAULT_HARMONICS` (give the harmonics explicitly).
    """
    n = int(period)
    f = model.hb_form(n)
    P = f.periods // n  # mesh cycles per forcing period: the (reference) mesh frequency is harmonic P·j of ω/(P n)
    if P == 1:
        return DEFAULT_HARMONICS
    mh = f.span // n - 2
    H = max(P * DEFAULT_HARMONICS, n * mh)
    if H > MAX_DEFAULT_HARMONICS:
        raise ModelError(
            f"harmonics: the forcing period spans {P} mesh cycles (harmonics of ω/{P * n}); the default would take {H} "
            f"({P}·{DEFAULT_HARMONICS} for mesh orders up to {DEFAULT_HARMONICS}, and the excitation's {mh} per "
            f"forcing period), more than {MAX_DEFAULT_HARMONICS}: give the harmonics explicitly (the cost grows as "
            f"H³), or use shooting"
        )
    return H


class Layout(NamedTuple):
    """The unknown vector, ``size`` long: ``dofs`` blocks of 2H + 1 real coefficients, then ``rigid`` multipliers."""

    size: int
    dofs: int
    rigid: int


class _Point(NamedTuple):
    model: Any
    form: HBForm
    E: tuple[np.ndarray, ...]  # every element's E on the δ basis (real coefficients)
    G0: np.ndarray  # (dofs, 2H + 1) real coefficients of the forcing
    G2: np.ndarray
    pattern: tuple | None  # of the sparse Jacobian and the bordered one (None: dense)


class HBEquations:
    """Residual, Jacobian, Newton and Floquet multipliers of the HB equations of a system (module docstring).

    Parameters
    ----------
    model : System
        The system at its base point (a value of ``param`` given to a method replaces that parameter).
    harmonics : int, optional
        H per coordinate (default :func:`default_harmonics`).
    period : int
        n forcing periods per response period.
    param : str, optional
        A parameter of the system (``omega``, ``xi0``, ``<mesh>.xi0``, ``<clearance>.D`` ...) for :meth:`residual`
        and :meth:`dR_dp`.
    samples : int, optional
        Time samples N per response period (default :func:`~geardyn.analysis.hb.aft.time_samples`).
    floquet : str
        ``"monodromy"`` (default, :mod:`.monodromy`) or ``"hill"`` (Hill's method, :mod:`.hill`).

    Raises
    ------
    ModelError
        For incommensurate mesh frequencies, a bad H or n.
    """

    def __init__(
        self,
        model: Any,
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
        self.base, self.n, self.H = model, int(period), int(harmonics)
        self.param = None if param is None else param_name(param)
        self.floquet = _check_floquet(floquet)
        form = self.form = model.hb_form(self.n)
        self.periods = form.periods
        H, R, nd = self.H, form.rigid, form.dofs
        M = self.M = 2 * H + 1
        r = R.shape[1]
        self.elastic = np.linalg.svd(R.T)[2][r:].T if r else np.eye(nd)  # orthonormal complement (n, n − r)
        self.basis = Layout(nd * M + r, nd, r)
        left = np.linalg.inv(form.Mi) @ R
        self.gauge, self.left = np.zeros((2, nd * M, r))  # the gauge rows Rᵀa_0 and the multipliers' columns
        self.gauge[::M], self.left[::M] = R, left / np.maximum(np.linalg.norm(left, axis=0), 1e-300)
        self.Hd = max(H, self._ste_harmonics(form))
        self.N = int(samples) if samples else time_samples(self.Hd, form.span)
        self.dbasis = HarmonicBasis(self.Hd, self.N)
        self.hbasis = HarmonicBasis(H, 2 * H + 2)
        self._pad = np.concatenate([np.arange(H + 1), self.Hd + 1 + np.arange(H)])
        self._k = kk = np.arange(1, H + 1, dtype=float)
        self._k2 = np.concatenate([[0.0], kk**2, kk**2])
        self.D1, i = np.zeros((M, M)), np.arange(1, H + 1)
        self.D1[i, H + i], self.D1[H + i, i] = kk, -kk
        self._ik = 1j * np.arange(-H, H + 1)
        self._ikd = 1j * np.arange(-self.Hd, self.Hd + 1)
        self.reference, self._scalar, self._cache = form.reference, form.scalar, {}

    @property
    def scalar(self) -> bool:
        """Whether the compiled kernels of the 1-DOF equation evaluate the residual (:attr:`HBForm.scalar`)."""
        return SPECIALISE and self._scalar

    @property
    def elements(self) -> tuple[str, ...]:
        """Element names (the form's order: meshes, then clearances)."""
        return tuple(e.name for e in self.form.elements)

    @staticmethod
    def _ste_harmonics(form: HBForm) -> int:
        """Largest harmonic of φ with a nonzero coefficient in the elements' E series."""
        hs = (np.abs(np.flatnonzero(e.E) - (len(e.E) - 1) // 2).max(initial=0) for e in form.elements)
        return int(max(hs, default=0))

    def model_at(self, p: float | None = None) -> Any:
        """The system at parameter value ``p`` (the base system when ``p`` is None)."""
        m = self._entry(p).model
        return self.base.with_param(self.param, float(p)) if m is None else m

    def _pattern(self, f: HBForm) -> tuple:
        """The lifted Jacobian's entries (:class:`SparseJacobian`) in :meth:`_jacobian`'s order: I⊗D₂, A⊗I, B⊗D₁, the
        gauge, W_e ⊗ I, V_eᵀ ⊗ I, the two −I, every op_ij; as (plain and bordered slots, n, the z unknowns, the values
        of I⊗diag(k²), A⊗I and B⊗D₁, the fixed values of the gauge's and auxiliary blocks)."""
        M, N0, els = self.M, f.dofs * self.M, f.elements
        c, (di, dj), (ei, ej) = np.arange(M), np.nonzero(self.D1), np.divmod(np.arange(M * M), M)
        lin = ((np.eye(f.dofs), c, c, self._k2), (f.A, c, c, np.ones(M)), (f.B, di, dj, self.D1[di, dj]))
        parts = [_kron_index(m, bi, bj, M) for m, bi, bj, _ in lin]
        (gi, gk), (hi, hk) = np.nonzero(self.left), np.nonzero(self.gauge)
        parts += [(gi, N0 + gk), (N0 + hk, hi)]
        n, nz = self.basis.size, len(els) * M
        const = [np.repeat(v[v != 0], M) for v in [el.W for el in els] + [el.V for el in els]]
        const = [self.left[np.nonzero(self.left)], self.gauge[np.nonzero(self.gauge)], *const, -np.ones(2 * nz)]
        linear = tuple((m[np.nonzero(m)][:, None] * b).ravel() for m, _, _, b in lin)  # (m ⊗ b at those entries)

        def block(v: np.ndarray, at: int) -> tuple:  # the entries of v ⊗ I: rows of x, columns of the auxiliary at
            i = np.flatnonzero(v)
            return (i[:, None] * M + c).ravel(), at + np.tile(c, i.size)

        def lifted(k: int) -> tuple:  # the auxiliaries after the k unknowns x (and p): z at k, y at k + nz
            aux = [block(el.W, k + nz + e * M) for e, el in enumerate(els)]
            aux += [block(el.V, k + e * M)[::-1] for e, el in enumerate(els)]
            aux += [(k + np.arange(nz),) * 2, (k + nz + np.arange(nz),) * 2]
            aux += [(k + nz + i * M + ei, k + j * M + ej) for i, j in _couplings(f)]
            return [np.concatenate(x) for x in zip(*parts, *aux)]

        rows, cols = lifted(n)
        brows, bcols = lifted(n + 1)
        full = np.arange(n + 1)
        border = np.concatenate([brows, full[:-1], np.full(n + 1, n)]), np.concatenate([bcols, np.full(n, n), full])
        return _slots(rows, cols, n + 2 * nz), _slots(*border, n + 1 + 2 * nz), n, nz, linear, np.concatenate(const)

    def _entry(self, p: float | None) -> _Point:
        key = None if (p is None or self.param is None) else float(p)
        if key not in self._cache:
            if len(self._cache) > 32:  # (the base point kept: its Jacobian's pattern)
                self._cache = {k: v for k, v in self._cache.items() if k is None}
            self._cache[key] = self._point(key)
        return self._cache[key]

    def _point(self, key: float | None) -> _Point:
        """The system, its form and their coefficients at the parameter value ``key`` (None: the base point)."""
        if key is not None and self.param == "omega" and key > 0 and math.isfinite(2.0 * math.pi / key):
            # the form does not depend on ω (the forcing's ω² is ν²·periods²): no model is built per value
            return self._entry(None)._replace(model=None)
        m = self.base if key is None else self.base.with_param(self.param, key)
        f = self.form if key is None else m.hb_form(self.n)
        if (h := self._ste_harmonics(f)) > self.Hd:
            raise ModelError(
                f"{self.param}: the STE reaches harmonic {h} of ν, above the {self.Hd} this "
                f"harmonic balance was set up with"
            )
        E = tuple(self.dbasis.to_real(centred(e.E, self.Hd)) for e in f.elements)
        G0, G2 = (np.array([self.hbasis.to_real(centred(g, self.H)) for g in G]) for G in (f.G0, f.G2))
        return _Point(m, f, E, G0, G2, self._pattern(f) if f.dofs > SPARSE_DOFS else None)

    def nu(self, p: float | None = None) -> float:
        """ν = ω/periods at ``p``."""
        return (float(p) if p is not None and self.param == "omega" else self.model_at(p).omega) / self.periods

    def _split(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(x, dtype=float)[: self.basis.dofs * self.M].reshape(self.basis.dofs, self.M)

    def deflection(self, x: np.ndarray, e: int, p: float | None = None) -> np.ndarray:
        """Real coefficients (δ basis of ``Hd`` harmonics) of element e's deflection δ_e = V_e·q − E_e."""
        return self._delta(self._entry(p), e, self._split(x))

    def _delta(self, pt: _Point, e: int, Q: np.ndarray) -> np.ndarray:
        d = np.zeros(2 * self.Hd + 1)
        d[self._pad] = pt.form.elements[e].V @ Q
        return d - pt.E[e]

    def _kernel_args(self, p: float | None) -> tuple:
        """The arguments after (a, ν) of the compiled kernels of a scalar form."""
        f, b = self._entry(p).form, self.dbasis
        el = f.elements[0]
        return (el.C, el.K, f.G0[0], f.G2[0], el.gap, b.cos_table, b.sin_table, self.H, ROOT_MAX_ITER, ROOT_TOL)

    def _core(self, x: np.ndarray, p: float | None, jacobian: bool):
        """R and the Jacobian (or None) with the gauge rows and columns of the rigid-body modes, ν, the parts R2, R1
        (dofs, M) of R = ν² R2 + ν R1 + R0 and every element's S series."""
        pt, nu, Q = self._entry(p), self.nu(p), self._split(x)
        H, Hd = self.H, self.Hd
        R2 = -self._k2 * Q - pt.G2
        R1 = pt.form.B @ (Q @ self.D1.T)  # the φ-derivative of every row
        R0 = pt.form.A @ Q - pt.G0
        Ss, els = {}, pt.form.elements
        for e0, r in _units(pt.form):
            ds = [self._delta(pt, e, Q) for e in range(e0, e0 + r)]
            Gs, S = LAW_TERMS[els[e0].law](ds, els[e0 : e0 + r], self.dbasis, self.periods)
            S = np.reshape(S, (r, r, -1))
            for el, d, G in zip(els[e0 : e0 + r], ds, np.reshape(Gs, (r, -1))):
                Lc = (len(el.C) - 1) // 2
                damp = np.convolve(el.C, self._ikd * self.dbasis.to_complex(d))[Lc + Hd - H : Lc + Hd + H + 1]
                R1 += np.outer(el.W, self.hbasis.to_real(damp))
                R0 += np.outer(el.W, self.hbasis.to_real(G[Hd - H : Hd + H + 1]))
            Ss.update({(e0 + i, e0 + j): S[i, j] for i in range(r) for j in range(r)})
        J = self._jacobian(pt, nu, Ss) if jacobian else None
        N0, r = self.basis.size - self.basis.rigid, self.basis.rigid
        R = (nu * nu * R2 + nu * R1 + R0).ravel()
        if r:
            R = np.concatenate([R + self.left @ x[N0:], self.gauge.T @ x[:N0]])
            if J is not None and not isinstance(J, SparseJacobian):  # (the sparse pattern has them)
                J = np.block([[J, self.left], [self.gauge.T, np.zeros((r, r))]])
        return R, J, nu, (R2, R1), Ss

    def _jacobian(self, pt: _Point, nu: float, Ss: dict) -> np.ndarray | SparseJacobian:
        """Its blocks: every element's own (damping and S_ee), then the cross blocks S_ij of a law on several rows."""
        H, M, nd, f = self.H, self.M, self.basis.dofs, pt.form
        ops = []
        for i, j in _couplings(f):
            T = toeplitz(Ss[i, j], H)
            ops.append(real_operator_kernel(T + nu * toeplitz(f.elements[i].C, H) * self._ik if i == j else T, H))
        if pt.pattern is not None:
            (k2, a, b), const = pt.pattern[4:]
            return SparseJacobian(pt.pattern, np.concatenate([-(nu**2) * k2, a, nu * b, const, *map(np.ravel, ops)]))
        J = np.kron(np.eye(nd), np.diag(-(nu**2) * self._k2)) + np.kron(f.A, np.eye(M)) + nu * np.kron(f.B, self.D1)
        for (i, j), op in zip(_couplings(f), ops):
            J += np.kron(np.outer(f.elements[i].W, f.elements[j].V), op)
        return J

    def residual(self, x: np.ndarray, p: float | None = None, jacobian: bool = True):
        """Residual (length ``basis.size``: the HB equations, then the gauge rows) of the unknowns ``x`` at parameter
        value ``p`` and, if ``jacobian``, its (bordered) Jacobian, else None."""
        x = np.asarray(x, dtype=float)
        if self.scalar:
            R, J = residual_kernel(np.ascontiguousarray(x), self.nu(p), *self._kernel_args(p), bool(jacobian))
            return R, (J if jacobian else None)
        return self._core(x, p, jacobian)[:2]

    def dR_dp(self, x: np.ndarray, p: float) -> np.ndarray:
        """Derivative of the residual in the parameter at fixed unknowns (analytic for ω, else a central
        difference, exact to rounding for parameters entering linearly)."""
        if self.param is None:
            raise ModelError("dR_dp: the system has no continuation parameter")
        if self.param != "omega":
            d = FD_REL_STEP * max(1.0, abs(p))

            def at(q: float) -> tuple:  # (a value outside the parameter's range: p itself, a one-sided difference)
                try:
                    return q, self.residual(x, q, jacobian=False)[0]
                except ModelError:
                    return p, self.residual(x, p, jacobian=False)[0]

            (q1, r1), (q2, r2) = at(p + d), at(p - d)
            return (r1 - r2) / (q1 - q2)
        A = self.bordered(x, p)[1]
        return A.col if isinstance(A, SparseJacobian) else A[:-1, -1]

    def bordered(self, x: np.ndarray, p: float, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """R and [[∂R/∂x, scale·∂R/∂p], [0 … 0]] for the continuation (the last row left for the caller)."""
        if self.param == "omega" and self.scalar:
            a = np.ascontiguousarray(x, dtype=float)
            return bordered_nu_kernel(a, self.nu(p), *self._kernel_args(p), float(scale) / self.periods)
        if self.param == "omega":
            R, J, nu, (R2, R1), _ = self._core(x, p, True)
            d = ((2.0 * nu * R2 + R1) / self.periods).ravel()
        else:
            (R, J), d = self.residual(x, p), self.dR_dp(x, p)
        col = np.zeros(R.size)
        col[: d.size] = scale * d
        if isinstance(J, SparseJacobian):
            return R, SparseJacobian(J.pattern, J.values, col)
        A = np.pad(J, ((0, 1), (0, 1)))
        A[:-1, -1] = col
        return R, A

    def newton(
        self, x0: np.ndarray, p: float | None = None, *, tol: float = NEWTON_TOL, max_iter: int = NEWTON_MAX_ITER
    ):
        """Damped Newton on R(x) = 0 at fixed parameter: (x, status, iterations, residual norm)."""
        a = np.asarray(x0, dtype=float).copy()
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
                if np.all(np.isfinite(trial)) and np.linalg.norm(trial) <= DIVERGED_NORM:
                    Rt, Jt = self.residual(trial, p)
                    rt = float(np.linalg.norm(Rt))
                    if rt < (1.0 - 1e-4 * lam) * r:
                        a, R, J, r = trial, Rt, Jt, rt
                        break
                lam *= 0.5
            else:
                return a, Status.NOT_CONVERGED, it + 1, r
        return a, Status.NOT_CONVERGED, max_iter, r

    def stability(self, x: np.ndarray, p: float | None = None) -> HillResult:
        """The elastic Floquet multipliers of the solution ``x`` (rigid-body modes left out): from the monodromy
        matrix of one period started on it (:mod:`.monodromy`) or by Hill's method (:mod:`.hill`)."""
        f, nu = self._entry(p).form, self.nu(p)
        if self.floquet == "hill":
            nd, M = self.basis.dofs, self.M
            J = np.asarray(self._core(x, p, True)[1])[: nd * M, : nd * M]
            Cop = np.kron(f.B, np.eye(M))
            for el in f.elements:
                Cop += np.kron(np.outer(el.W, el.V), real_operator_kernel(toeplitz(el.C, self.H), self.H))
            K1 = 2.0 * nu * np.kron(np.eye(nd), self.D1) + Cop
            return system_hill_floquet(J, K1, self.elastic, nu, self.H, -f.mean_trace())
        bx = bearing_rows(f)[1]  # a bound of a sampled law's stiffness: its trace's
        Ss = self._core(x, p, False)[4] if bx.size else {}
        stiff = {e: float(np.abs(Ss[e, e]).sum() + np.abs(Ss[e + 1, e + 1]).sum()) for e in bx}
        return monodromy_floquet(f, nu, self.state(x, p), self.elastic, stiff)

    def element_extremes(self, x: np.ndarray, p: float | None = None) -> np.ndarray:
        """(elements, 2): δ_min, δ_max of every element."""
        return np.array(
            [signal_extrema(self.dbasis, self.deflection(x, e, p))[:2] for e in range(len(self.form.elements))]
        )

    def dynamic_factors(self, x: np.ndarray, p: float | None = None) -> np.ndarray:
        """Largest mesh force C δ' + K f(δ) over the period (from FORCE_OVERSAMPLE·N samples) over the static
        force, per mesh element (NaN where the static force is 0 or unknown)."""
        nu, Ns, out = self.nu(p), FORCE_OVERSAMPLE * self.N, []
        for e, el in enumerate(self._entry(p).form.elements):
            if el.kind == "mesh":
                c = self.dbasis.to_complex(self.deflection(x, e, p))
                u, v = _samples(c, Ns), _samples(nu * self._ikd * c, Ns)
                fm = float(np.max(_samples(el.C, Ns) * v + _samples(el.K, Ns) * (u - np.clip(u, -el.gap, el.gap))))
                s = el.static_force
                out.append(fm / s if s > 0 and math.isfinite(fm) else math.nan)
        return np.array(out)

    def state(self, x: np.ndarray, p: float | None = None) -> np.ndarray:
        """(q, q') at θ = 0, comparable with a shooting orbit's state (up to the rigid-body position)."""
        Q, H = self._split(x), self.H
        return np.concatenate([Q[:, 0] + Q[:, 1 : H + 1].sum(axis=1), self.nu(p) * (Q[:, H + 1 :] @ self._k)])

    def project(self, Q: np.ndarray) -> np.ndarray:
        """Coefficients with the rigid-body part removed (the gauge Rᵀa_0 = 0, no rigid momentum elsewhere)."""
        Q, R = np.array(Q, dtype=float), self.form.rigid
        if R.shape[1] == 0:
            return Q
        Mt = np.linalg.inv(self.form.Mi)
        Pm = R @ np.linalg.solve(R.T @ Mt @ R, R.T @ Mt)
        Q[:, 1:] -= Pm @ Q[:, 1:]
        Q[:, 0] -= R @ (R.T @ Q[:, 0])
        return Q

    def unknowns(self, Q: np.ndarray) -> np.ndarray:
        """The unknown vector of coefficients Q (dofs, 2H + 1), gauge multipliers zero."""
        return np.concatenate([np.asarray(Q, dtype=float).ravel(), np.zeros(self.basis.rigid)])

    def linear_guess(self, p: float | None = None) -> np.ndarray:
        """Coefficients (dofs, 2H + 1) of the linearised, permanently meshing response (meshes in drive contact
        at their mean stiffness and damping, clearances closed only without gap): K̄ a_0 = F̃ + Σ k_m D_m V_m and
        (K̄ − (νk)²M̃ + iνk C̄) ĉ_k = M̃ Ĝ_k + Σ_m V_m (k_m + iνk c_m) Ê_m,k; a rolling bearing at its static
        deflection (:func:`geardyn.systems.rolling.static_deflection`, a_0) and its tangent stiffness there (in K̄)."""
        f = self._entry(p).form
        Mt = np.linalg.inv(f.Mi)
        Kt, Ct = Mt @ f.A, Mt @ f.B
        H, nu, nd = self.H, self.nu(p), f.dofs
        G = f.G0 + nu**2 * f.G2
        L = (G.shape[1] - 1) // 2
        rhs0 = (Mt @ G[:, L]).real
        meshes, items = [], []
        for e, el in enumerate(f.elements):
            k0, c0, vv = mean(el.K), mean(el.C), np.outer(el.V, el.V)
            if el.rule is not None:  # a rolling bearing: its dampers, and its stiffness at the static deflection
                Ct = Ct + c0 * vv
                if el.name.endswith(".x"):
                    Z, n, cl, _, phase = el.rule.params()
                    items.append((np.array([el.V, f.elements[e + 1].V]), int(Z), k0, n, cl, phase))
            elif el.kind == "mesh" or el.gap <= 0:
                Kt, Ct = Kt + k0 * vv, Ct + c0 * vv
                rhs0 = rhs0 + k0 * el.gap * el.V
            if el.kind == "mesh":
                meshes.append((el, k0, c0, centred(el.E, self.Hd)))
        c = np.zeros((nd, 2 * H + 1), dtype=complex)
        if items:
            q0, mats = static_deflection(Kt, rhs0, items)
            c[:, H], Kt = q0, Kt + sum(mats)
        else:
            c[:, H] = np.linalg.lstsq(Kt, rhs0, rcond=1e-12)[0]
        for k in range(1, H + 1):
            rhs = Mt @ G[:, L + k] if k <= L else np.zeros(nd, dtype=complex)
            for el, k0, c0, E in meshes:
                rhs = rhs + el.V * (k0 + 1j * nu * k * c0) * E[self.Hd + k]
            if np.any(rhs != 0):
                c[:, H + k] = np.linalg.solve(Kt - (nu * k) ** 2 * Mt + 1j * nu * k * Ct, rhs)
                c[:, H - k] = np.conj(c[:, H + k])
        return self.project(np.array([self.hbasis.to_real(row) for row in c]))

    def simulated_guess(self, state0: Any = None, *, transient: int = GUESS_TRANSIENT, dtau: float = GUESS_DTAU):
        """Coefficients (dofs, 2H + 1) of the attractor reached by simulation from ``state0`` (n forcing periods
        after ``transient``, counted in one-cycle periods), the rigid-body part removed; None if it diverged."""
        from ...integrate import trajectory

        m, n, H = self.base, self.n, self.H
        opts = IntegrationOptions(dtau=dtau, transient=-(-int(transient) // self.form.cycles), periods=n)
        tr = trajectory(m, start_state(m, state0), opts, history_periods=n)
        q = tr.x[:-1, : self.form.dofs]
        if not np.all(np.isfinite(q)):
            return None
        X = np.fft.rfft(q, axis=0) / q.shape[0]
        a = np.zeros((q.shape[1], 2 * H + 1))
        a[:, 0] = X[0].real
        k = min(H, X.shape[0] - 1)
        a[:, 1 : k + 1] = 2.0 * X[1 : k + 1].real.T
        a[:, H + 1 : H + 1 + k] = -2.0 * X[1 : k + 1].imag.T
        return self.project(a)


def _units(f: HBForm) -> Iterator[tuple[int, int]]:
    """(first row, rows) of every law of the form: a dead zone one row, a rolling bearing its x and y rows."""
    e = 0
    while e < len(f.elements):
        r = LAWS[f.elements[e].law]
        yield e, r
        e += r


def _couplings(f: HBForm) -> list[tuple[int, int]]:
    """The element pairs (i, j) of the Jacobian's blocks (W_i V_jᵀ) ⊗ op_ij: every element's own, then the cross
    pairs i ≠ j of a law on several rows."""
    own = [(e, e) for e in range(len(f.elements))]
    return own + [(e + i, e + j) for e, r in _units(f) for i in range(r) for j in range(r) if i != j]


def _kron_index(m: np.ndarray, bi: np.ndarray, bj: np.ndarray, M: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the entries (bi, bj) of an M×M block at each nonzero of ``m`` (of m ⊗ block)."""
    i, j = np.nonzero(m)
    return (i[:, None] * M + bi).ravel(), (j[:, None] * M + bj).ravel()


def _samples(z: np.ndarray, Ns: int) -> np.ndarray:
    """Values at φ_j = 2πj/Ns of the real trigonometric polynomial with centred coefficients z (L < Ns/2)."""
    L = (len(z) - 1) // 2
    arr = np.zeros(Ns, dtype=complex)
    arr[np.arange(-L, L + 1) % Ns] = z
    return (np.fft.ifft(arr) * Ns).real
