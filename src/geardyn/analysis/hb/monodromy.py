"""Floquet multipliers of a harmonic-balance solution from the monodromy matrix of one period (``docs/hb.md``,
"Floquet multipliers from the monodromy matrix").

The equation of the form (:mod:`.form`) is integrated over the response period from the state of the HB solution at
φ = 0 together with the columns of a fundamental matrix of its variational equation
(:func:`~._monodromykernel.monodromy_kernel`: classic RK4 with every element locked to its contact region on a step,
the steps cut at the contact switches located on the trajectory, steps of at most :data:`STEP_ANGLE`/ρ in τ,
ρ = √ρ(K) + ‖C‖₂ of the largest stiffness and damping, a bound of the fastest rate of the linearised motion). The
period is integrated twice: from the HB state (the state in the second period's steps, the fundamental matrix a step
per :data:`FIRST_STRIDE` of them), then from the state corrected by one Newton step of shooting on the elastic part,
x₀ + Q (QᵀΦQ − I)⁻¹ Qᵀ(x₀ − x(T)) (skipped when it is more than :data:`REFINE_GAIN` times the gap it closes, next to a
fold). The multipliers are the eigenvalues of QᵀΦQ, Q = diag(P, P) an orthonormal basis of the complement of the
rigid-body modes, so the rigid modes' multipliers 1 are left out; the exponents their principal logarithms over T.
``UNRESOLVED`` when Liouville's formula fails by more than :data:`~.hill.LIOUVILLE_TOL` or the first period does not
return to within :data:`CLOSURE_TOL` of its start.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ...errors import ModelError
from ...status import Status
from ..periodic.floquet import largest_first
from ._monodromykernel import monodromy_kernel
from .hill import LIOUVILLE_TOL, NO_MULTIPLIERS, HillResult

__all__ = [
    "CLOSURE_TOL",
    "FIRST_STRIDE",
    "FLOQUET_METHODS",
    "REFINE_GAIN",
    "STEP_ANGLE",
    "SWITCH_TOL",
    "monodromy_floquet",
]

#: The ways of computing Floquet multipliers of an HB solution: ``"monodromy"`` (this module, the default)
#: and ``"hill"`` (Hill's method, :mod:`.hill`).
FLOQUET_METHODS = ("monodromy", "hill")
#: Largest RK4 step times the fastest rate ρ of the linearised motion.
STEP_ANGLE = 0.03
#: Contact switches are located to this relative tolerance in φ.
SWITCH_TOL = 1e-14
#: The period started on the HB solution must return to within this of its start (relative, elastic part);
#: farther, the HB solution is too far from an orbit for its multipliers to mean anything: ``UNRESOLVED``.
#: (Paper defaults at ω = 0.58, 0.7, 0.9: 0.02–0.05 at H = 2, below 1e-2 from H = 4, about 6e-5 at H = 16.)
CLOSURE_TOL = 1e-2
#: The period is started again from the state corrected by one Newton step of shooting (module notes), unless the
#: step is more than REFINE_GAIN times the closure gap (QᵀΦQ − I nearly singular: a multiplier within about
#: 1/REFINE_GAIN of 1, next to a fold, where the step would leave for another orbit).
REFINE_GAIN = 20.0
#: The first period (the Newton step's) takes the state in the second period's steps, so the step aims at the orbit
#: the second one integrates, and Φ in steps of this many of them (1 with a rolling bearing: it needs the stages).
FIRST_STRIDE = 4


def _check_floquet(floquet: str) -> str:
    """``floquet`` if it names a method of :data:`FLOQUET_METHODS`; else a one-line :class:`ModelError`."""
    if floquet not in FLOQUET_METHODS:
        raise ModelError(f"floquet: expected one of {', '.join(FLOQUET_METHODS)}, got {floquet!r}")
    return floquet


def _pack(series: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Centred series of different lengths as rows (each centred at its own half-length) and the half-lengths."""
    L = np.array([(len(z) - 1) // 2 for z in series], dtype=np.int64)
    out = np.zeros((len(series), 2 * int(L.max(initial=0)) + 1), dtype=complex)
    for i, z in enumerate(series):
        out[i, : len(z)] = z
    return out, L


def _rows(nz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row pointers and column indices of the True entries of ``nz`` (compressed sparse rows)."""
    return np.concatenate([[0], np.cumsum(nz.sum(axis=1))]).astype(np.int64), np.nonzero(nz)[1].astype(np.int64)


def bearing_rows(form: Any) -> tuple[np.ndarray, np.ndarray]:
    """The rolling bearings of a form as the N-DOF kernel's parameter rows (:data:`geardyn._kernel_ndof.core.BQ_Z`
    …; the cage's radians per radian of φ in ``BQ_RHO``) and the index of each one's x row."""
    els = form.elements
    bx = [e for e, el in enumerate(els) if el.law == "rolling_bearing" and el.name.endswith(".x")]
    # (the rule's parameters: Z, n, c, ratio, phase)
    rows = [[Z, els[e].K[0].real, n, c, els[e].C[0].real, els[e + 1].C[0].real, r / Z * form.periods, ph]
            for e in bx for Z, n, c, r, ph in [els[e].rule.params()]]  # fmt: skip
    return np.reshape(np.array(rows, dtype=float), (len(bx), 8)), np.array(bx, dtype=np.int64)


def monodromy_floquet(
    form: Any, nu: float, x0: np.ndarray, P: np.ndarray | None = None, stiff: dict | None = None
) -> HillResult:
    """Floquet exponents and multipliers from the monodromy matrix of one period started on the HB solution.

    Parameters
    ----------
    form : HBForm
        The system's equation (:class:`~geardyn.analysis.hb.form.HBForm`).
    nu : float
        Fundamental frequency of the solution (period T = 2π/ν), φ = ντ.
    x0 : ndarray (2n,)
        The solution's state (q, q') at φ = 0 (τ-derivatives).
    P : ndarray (n, n − r), optional
        Orthonormal basis of the complement of the rigid-body modes (default: none, the identity).
    stiff : dict, optional
        A bound of the stiffness of each rolling bearing's x row over the period (for the step; its rows' own
        series are the kernel's bearing law, :func:`bearing_rows`).

    Returns
    -------
    HillResult
        2(n − r) exponents and multipliers (largest modulus first), centralities 0 (no eigenvectors are
        sorted), Liouville's error and the status (``DIVERGED`` if the period could not be integrated).
    """
    els, n = form.elements, form.dofs
    A, B = (np.ascontiguousarray(z, dtype=float) for z in (form.A, form.B))
    W, V = (np.array([getattr(e, k) for e in els], dtype=float).reshape(len(els), n) for k in "WV")
    bq, bx = bearing_rows(form)
    C, K, E, D = ([getattr(e, k) for e in els] for k in ("C", "K", "E", "gap"))
    for e in bx:  # its rows are the kernel's law: no series of their own, no switch
        C[e] = C[e + 1] = K[e] = K[e + 1] = np.zeros(1, complex)
        D[e] = D[e + 1] = 0.0
    G = [g0 + nu * nu * g2 for g0, g2 in zip(form.G0, form.G2)]
    P = np.eye(n) if P is None else np.asarray(P, dtype=float)
    count = 2 * P.shape[1]
    nan = np.full(count, complex(math.nan, math.nan))
    diverged = HillResult(nan, nan, np.zeros(count), math.nan, Status.DIVERGED)
    if count == 0:
        return NO_MULTIPLIERS
    (Cz, Lc), (Kz, Lk), (Ez, Le), (Gz, Lg) = map(_pack, (C, K, E, G))
    dEz = Ez * (1j * (np.arange(Ez.shape[1])[None, :] - Le[:, None]))
    x_start = np.array(x0, dtype=float)
    if not (math.isfinite(nu) and nu > 0 and all(np.all(np.isfinite(z)) for z in (Cz, Kz, Ez, Gz, x_start))):
        return diverged
    kb, cb = np.abs(Kz).sum(axis=1), np.abs(Cz).sum(axis=1)
    for i, e in enumerate(bx):
        kb[e] = kb[e + 1] = (stiff or {}).get(e, 0.0)
        cb[e], cb[e + 1] = bq[i, 4:6]
    kmax, cmax = (X + (b[:, None] * W).T @ V for X, b in ((A, kb), (B, cb)))  # the largest stiffness, damping (bounds)
    krad, crad = (abs(float(kmax[0, 0])), abs(float(cmax[0, 0]))) if n == 1 else (
        float(np.max(np.abs(np.linalg.eigvals(kmax)))), float(np.linalg.norm(cmax, 2)))  # fmt: skip
    rate = math.sqrt(krad) + crad
    hmax = STEP_ANGLE * nu / max(rate, 1e-12)  # in φ
    Q = np.zeros((2 * n, count))  # diag(P, P) (scipy's block_diag costs 30 times this)
    Q[:n, : count // 2] = Q[n:, count // 2 :] = P
    sp = (*_rows(np.logical_or(A != 0, B != 0)), *_rows(V != 0), *_rows(W != 0))  # the nonzeros the kernel sums
    args = (A, B, W, V, sp, Cz, Lc, Kz, Lk, Ez, dEz, Le, Gz, Lg, np.asarray(D, dtype=float), hmax, float(nu))

    def period(start: np.ndarray, stride: int = 1) -> tuple[np.ndarray, np.ndarray] | None:
        """(end state, QᵀΦQ) of the period from ``start`` (a step of Φ per ``stride`` of the state's), or None if
        it could not be integrated."""
        xe, Y = start.copy(), Q.copy()
        steps, _switches = monodromy_kernel(xe, Y, *args, SWITCH_TOL, bq, bx, stride)
        Phi = Q.T @ Y
        return None if steps < 0 or not (np.all(np.isfinite(Phi)) and np.all(np.isfinite(xe))) else (xe, Phi)

    first = period(x_start, 1 if bx.size else FIRST_STRIDE)
    if first is None:
        return diverged
    x, Phi = first
    # one Newton step of shooting on the elastic part (the HB state's error moves the switch instants, and with them
    # the multipliers, to first order); without it (a step over REFINE_GAIN times the gap) the HB state again
    gap = Q.T @ (x - x_start)
    closure = float(np.linalg.norm(gap)) / (1.0 + float(np.linalg.norm(Q.T @ x_start)))
    start = x_start
    if closure <= CLOSURE_TOL:
        try:
            dz = np.linalg.solve(Phi - np.eye(count), -gap)
        except np.linalg.LinAlgError:
            dz = np.full(count, math.nan)
        if np.all(np.isfinite(dz)) and float(np.linalg.norm(dz)) <= REFINE_GAIN * float(np.linalg.norm(gap)):
            start = x_start + Q @ dz
    again = period(start)
    if again is None and start is not x_start:
        again = period(x_start)
    if again is None:
        return diverged
    Phi = again[1]
    T = 2.0 * math.pi / nu
    mu = largest_first(np.linalg.eigvals(Phi).astype(complex))
    with np.errstate(divide="ignore"):
        ex = np.log(mu) / T
    ref = math.exp(form.mean_trace() * T)
    liou = float(abs(np.prod(mu) / ref - 1.0))
    status = Status.OK if liou <= LIOUVILLE_TOL and closure <= CLOSURE_TOL else Status.UNRESOLVED
    return HillResult(ex, mu, np.zeros(count), liou, status)
