"""Harmonic balance at one parameter value: :func:`hb_solve` on any system (the equations: :mod:`.equations`).

Newton on the HB equations with the analytic Jacobian gives an :class:`HBSolution` with a
:class:`~geardyn.status.Status` and, when converged, the elastic Floquet multipliers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ModelError
from ...status import Status
from .equations import NEWTON_MAX_ITER, NEWTON_TOL, HBEquations, single_thread_blas
from .hill import HillResult

__all__ = ["HBSolution", "hb_solve"]


@dataclass
class HBSolution:
    """A harmonic-balance solution at one parameter value (non-dimensional).

    Attributes
    ----------
    model : System
    harmonics, period, samples : int
        H, n and the number N of time samples per response period.
    coefficients : ndarray
        ``[a_0, a_1 … a_H, b_1 … b_H]`` of every coordinate q_i(φ), φ = ντ: (2H + 1,) for one coordinate (the pair's
        u), else (dofs, 2H + 1).
    status : Status
        Newton's outcome (``OK``, ``NOT_CONVERGED``, ``DIVERGED``).
    iterations : int
    residual : float
        ||R|| at the last iterate.
    u_min, u_max : float
        Extremes of the reference element's deflection (the pair's u) over the period (NaN unless converged).
    hill : HillResult or None
        The elastic Floquet multipliers (None unless converged and asked for); ``hill.status`` is ``UNRESOLVED``
        when they cannot be trusted.
    equations : HBEquations
        The equations solved.
    unknowns : ndarray
        The full unknown vector (coefficients, then the gauge multipliers of the rigid-body modes).
    element_extremes : ndarray (elements, 2)
        δ_min, δ_max of every element.
    rigid : int
        Rigid-body modes (their 2 multipliers each, exactly 1, are left out).
    """

    model: Any
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
    equations: Any = field(default=None, repr=False)
    unknowns: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    element_extremes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    rigid: int = 0

    @property
    def converged(self) -> bool:
        return self.status is Status.OK

    @property
    def amplitude(self) -> float:
        """Half peak-to-peak deflection (u_max − u_min)/2."""
        return 0.5 * (self.u_max - self.u_min)

    @property
    def multipliers(self) -> np.ndarray:
        if self.hill is not None:
            return self.hill.multipliers
        return np.full(2 * (self.equations.basis.dofs - self.rigid), complex(math.nan, math.nan))

    @property
    def stable(self) -> bool | None:
        """True/False when converged and resolved, None otherwise."""
        if not self.converged or self.hill is None or self.hill.status is not Status.OK:
            return None
        return self.hill.stable

    def signal(self, samples: int = 512) -> tuple[np.ndarray, np.ndarray]:
        """(τ, δ) of the reference element at ``samples`` equispaced instants over the response period from θ = 0."""
        eq = self.equations
        phi = 2.0 * np.pi * np.arange(samples) / samples
        return phi / eq.nu(), eq.dbasis.evaluate(eq.deflection(self.unknowns, eq.reference), phi)

    def state(self) -> np.ndarray:
        """(q, q') at θ = 0, comparable with a shooting orbit's ``state`` (up to the rigid-body position)."""
        return self.equations.state(self.unknowns)


def _start_coefficients(eq: HBEquations, guess: Any = None, state0: Any = None) -> np.ndarray:
    """The start (dofs, 2H + 1) of Newton: ``guess`` as coefficients, ``"linear"``, or ``"simulate"`` (the attractor
    reached by simulation from ``state0``; the linear response when that diverges).  None is ``"simulate"``, or
    ``"linear"`` for a system without damping (it has no attractor: a simulation keeps its transient for ever).

    Raises
    ------
    ModelError
        For another string, or coefficients of the wrong size.
    """
    nd, M = eq.basis.dofs, eq.M
    if guess is None:
        guess = "linear" if eq.form.mean_trace() == 0.0 else "simulate"
    if isinstance(guess, str):
        if guess not in ("simulate", "linear"):
            raise ModelError(f"guess: expected coefficients, 'simulate' or 'linear', got {guess!r}")
        Q0 = eq.simulated_guess(state0) if guess == "simulate" else None
        return eq.linear_guess() if Q0 is None else Q0
    Q0 = np.asarray(guess, dtype=float)
    if Q0.size != nd * M or Q0.ndim > 2 or (Q0.ndim == 2 and Q0.shape != (nd, M)):
        want = f"{M} coefficients" if nd == 1 else f"coefficients of shape ({nd}, {M})"
        raise ModelError(f"guess: expected {want} for H = {eq.H}, got shape {Q0.shape}")
    return Q0.reshape(nd, M)


def hb_solve(
    model: Any,
    harmonics: int | None = None,
    period: int = 1,
    guess: np.ndarray | str | None = None,
    *,
    samples: int | None = None,
    tol: float = NEWTON_TOL,
    max_iter: int = NEWTON_MAX_ITER,
    stability: bool = True,
    state0: Any = None,
    floquet: str = "monodromy",
) -> HBSolution:
    """Solve the harmonic-balance equations of a system at one parameter point.

    Parameters
    ----------
    model : System
        The pair (:class:`~geardyn.model.GearModel`) or a multi-DOF system (its forcing must be periodic).
    harmonics : int, optional
        H per coordinate (default :func:`~geardyn.analysis.hb.equations.default_harmonics`: 16 unless the
        forcing period spans several mesh cycles).
    period : int
        n: the response repeats after n forcing periods (n = 1 harmonic, n > 1 subharmonic).
    guess : ndarray, "simulate", "linear" or None
        Start: coefficients, the linearised permanently meshing response, or the attractor reached by simulation
        from ``state0`` (default ``"simulate"``; ``"linear"`` if the simulation diverges).
    samples : int, optional
        Time samples per response period.
    tol, max_iter : float, int
        Newton tolerance (||R|| <= tol·(1 + ||x||)) and iteration limit.
    stability : bool
        Compute the Floquet multipliers of a converged solution.
    state0 : (u0, v0) or a full state, optional
        Start of the simulation of the default guess (rest by default).
    floquet : str
        ``"monodromy"`` (default) or ``"hill"``.

    Returns
    -------
    HBSolution
        Check ``status``; values are NaN unless it is ``OK``.

    Raises
    ------
    ModelError
        For incommensurate meshes, bad ``harmonics``/``period`` or a guess of the wrong shape.

    Examples
    --------
    >>> from geardyn import GearModel, hb_solve
    >>> sol = hb_solve(GearModel(omega=0.8), 8)  # 8 harmonics
    >>> sol.converged, sol.period, round(sol.amplitude, 3)
    (True, 1, 0.927)
    """
    eq = HBEquations(model, harmonics, period, samples=samples, floquet=floquet)
    Q0 = _start_coefficients(eq, guess, state0)
    with single_thread_blas():
        x, status, its, r = eq.newton(eq.unknowns(Q0), None, tol=tol, max_iter=max_iter)
        Q = eq._split(x).copy()
        Q = Q[0] if eq.basis.dofs == 1 else Q
        sol = HBSolution(model, eq.H, eq.n, eq.N, Q, status, its, r, equations=eq, unknowns=x, rigid=eq.basis.rigid)
        if status is Status.OK:
            sol.element_extremes = eq.element_extremes(x)
            sol.u_min, sol.u_max = map(float, sol.element_extremes[eq.reference])
            if stability:
                sol.hill = eq.stability(x)
    return sol
