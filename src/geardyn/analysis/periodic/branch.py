"""A branch of periodic orbits and the events located on it (results of a continuation)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .floquet import pairs

__all__ = ["Bifurcation", "Branch", "BIFURCATION_TYPES"]

#: Bifurcation (event) types reported by :func:`~geardyn.analysis.periodic.continuation`.
BIFURCATION_TYPES = ("fold", "period-doubling", "neimark-sacker", "grazing", "branch-point")
#: The events at which a stable orbit can lose its stability.
STABILITY_LOSSES = ("fold", "period-doubling", "neimark-sacker", "branch-point")


@dataclass
class Bifurcation:
    """A located event on a branch (non-dimensional).

    ``type`` is one of :data:`BIFURCATION_TYPES`; ``value`` the parameter value; ``state`` the orbit's
    (u, u') at θ = 0; ``n`` the period of the branch it lies on; ``detail`` says which multiplier or
    which boundary (e.g. ``u_min = +D``); ``located`` is False when the location did not converge
    (the value is then the better end of the bracketing step).

    Parameters
    ----------
    type : str
        One of :data:`BIFURCATION_TYPES` (or ``merge``: a switched branch meeting its parent).
    param : str
        The continued parameter.
    value : float
        Its value at the event.
    state : ndarray (d,)
        The orbit's state at θ = 0 there.
    n : int
        Period of the branch.
    branch : int
        Index of the branch.
    multipliers : ndarray (d,) complex
        Floquet multipliers at the event.
    u_min, u_max : float
        Extremes of u over the orbit.
    detail : str
        Which multiplier or boundary.
    located : bool
        Whether the location converged.
    stable_before, stable_after : bool or None
        Stability of the branch on either side (None where unknown).
    test : str
        Name of the test function that changed sign.

    References
    ----------
    Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004 (test
    functions of codimension-one bifurcations of maps).
    """

    type: str
    param: str
    value: float
    state: np.ndarray
    n: int
    branch: int
    multipliers: np.ndarray
    u_min: float
    u_max: float
    detail: str = ""
    located: bool = True
    stable_before: bool | None = None
    stable_after: bool | None = None
    test: str = ""

    @property
    def amplitude(self) -> float:
        """Half peak-to-peak displacement of the orbit there."""
        return 0.5 * (self.u_max - self.u_min)

    def to_json(self) -> dict[str, Any]:
        """The JSON form (an element of ``bifurcations`` in ``continuation --json``)."""
        return {
            "type": self.type,
            self.param: float(self.value),
            "period": int(self.n),
            "branch": int(self.branch),
            "state": self.state.tolist(),
            "amplitude": float(self.amplitude),
            "u_min": float(self.u_min),
            "u_max": float(self.u_max),
            "multipliers": pairs(self.multipliers),
            "detail": self.detail,
            "located": bool(self.located),
        }


@dataclass
class Branch:
    """A continued branch of period-n orbits (arrays over its K points, non-dimensional).

    ``values`` the parameter, ``states`` (K, 2) the orbit at θ = 0, ``points`` (K, n, 2) all section
    points, ``multipliers`` (K, 2) complex, ``u_min``/``u_max`` (K,), ``stable`` (K,).  ``origin`` is
    the bifurcation it was switched from (None for a primary branch); ``end`` says why it stopped.

    Parameters
    ----------
    index : int
        Branch number in its continuation.
    param : str
        The continued parameter.
    n : int
        Period of the orbits (forcing periods).
    values : ndarray (K,)
        Parameter values.
    states : ndarray (K, d)
        Orbits at θ = 0.
    points : ndarray (K, n, d)
        Section points of each orbit.
    monodromy : ndarray (K, d, d)
        Monodromy matrices.
    u_min, u_max : ndarray (K,)
        Extremes of u over each orbit.
    steps : ndarray (K,)
        RK4 steps per period of each point's map.
    end : str
        Why the branch stopped.
    origin : Bifurcation, optional
        The event it was switched from.
    bifurcations : list of Bifurcation
        Events located on it.
    elastic : ndarray (d, d − 2r), optional
        The complement of the system's rigid-body subspace (:func:`~geardyn.analysis.periodic.orbit.elastic_basis`):
        the multipliers are then those of ``elasticᵀ M elastic``, the 2r rigid-body ones (exactly 1) left out.
    extrema : ndarray (K, elements, 2), optional
        Every element's extremes of δ over each orbit (the reference element's are ``u_min``, ``u_max``).
    """

    index: int
    param: str
    n: int
    values: np.ndarray
    states: np.ndarray
    points: np.ndarray
    monodromy: np.ndarray
    u_min: np.ndarray
    u_max: np.ndarray
    steps: np.ndarray
    end: str
    origin: Bifurcation | None = None
    bifurcations: list[Bifurcation] = field(default_factory=list)
    elastic: np.ndarray | None = None
    extrema: np.ndarray | None = None

    @property
    def multipliers(self) -> np.ndarray:
        """(K, d − 2r) complex (elastic) multipliers per point, largest modulus first."""
        M = self.monodromy
        if self.elastic is not None:
            M = np.einsum("ji,kjl,lm->kim", self.elastic, M, self.elastic)
        mu = np.linalg.eigvals(M)
        order = np.argsort(-np.abs(mu), axis=1, kind="stable")
        return np.take_along_axis(mu, order, axis=1)

    @property
    def stable(self) -> np.ndarray:
        """(K,) all multipliers inside the unit circle."""
        return np.max(np.abs(self.multipliers), axis=1) < 1.0

    @property
    def amplitude(self) -> np.ndarray:
        """(K,) half peak-to-peak displacement."""
        return 0.5 * (self.u_max - self.u_min)

    def __len__(self) -> int:
        return len(self.values)
