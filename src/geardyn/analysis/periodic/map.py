"""The n-period stroboscopic map of a system, with its Jacobian and parameter derivative.

:class:`PeriodMap` is the derived system every orbit tool stands on: shooting solves
P^n(x) = x, Floquet analysis reads the eigenvalues of its Jacobian, continuation follows its
fixed points in a parameter.  It is built from what every system has — its state dimension, its
forcing period, its parameters by name (``get``/``with_param``) — and reaches the kernel only
through :mod:`geardyn.integrate`.

The section is θ ≡ 0 mod 2π.  In the default integration mode the map is the discrete RK4 map
with N steps per forcing period (h = T/N, N = ceil(T/Δτ) unless given), and the Jacobian comes
from tangent propagation of the same steps, so it is the exact derivative of the discrete map; in
the accurate mode (steps split at u = ±D) it is the Jacobian of the split steps with the crossing
times frozen, accurate to the integration error (the vector field is continuous, so the flow needs
no saltation correction).

Every call integrates on one thread (``threads=1``): a map evaluation is one trajectory, and the
orbit tools evaluate it thousands of times, where starting a thread team would cost more than the
integration.  numba's thread setting of the caller is left as it was.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...integrate import forcing_period, integrate_batch, natural_steps, period_map, state_dim, trajectory
from ...model import DEFAULT_DTAU, IntegrationOptions, ModelError, canonical_param

__all__ = ["PeriodMap", "MapEvaluation", "FD_REL_STEP", "MAP_THREADS"]

#: Relative step of the central finite difference for ∂P^n/∂p: δ = FD_REL_STEP·max(1, |p|).
FD_REL_STEP = 1.0e-6
#: Threads of every map evaluation (one trajectory each; see the module notes).
MAP_THREADS = 1


def _is_count(v: object) -> bool:
    """v is an integer >= 1 (an int or an integral float, not a bool)."""
    try:
        return not isinstance(v, bool) and float(v).is_integer() and v >= 1
    except (TypeError, ValueError, OverflowError):
        return False


@dataclass(frozen=True)
class MapEvaluation:
    """One evaluation of P^n at a state (non-dimensional).

    Attributes
    ----------
    x : ndarray (d,)
        The state the map was evaluated at.
    points : ndarray (n, d)
        P(x), P²(x), ..., P^n(x); NaN when the trajectory diverged.
    monodromy : ndarray (d, d)
        The Jacobian of P^n at x.
    ok : bool
        The trajectory stayed bounded and the Jacobian is finite.
    steps : int
        RK4 steps per forcing period used.
    """

    x: np.ndarray
    points: np.ndarray
    monodromy: np.ndarray
    ok: bool
    steps: int

    @property
    def value(self) -> np.ndarray:
        """P^n(x)."""
        return self.points[-1]

    @property
    def residual(self) -> np.ndarray:
        """P^n(x) − x (zero at a period-n orbit)."""
        return self.points[-1] - self.x


class PeriodMap:
    """The n-period stroboscopic map P^n of a system at the section θ ≡ 0 mod 2π.

    Parameters
    ----------
    model : System
        The system (:class:`geardyn.system.System`: any model the door :mod:`geardyn.integrate` integrates).
    n : int
        Forcing periods per map iteration (P^n).
    dtau : float
        Target step Δτ: N = ceil(T/Δτ) RK4 steps per forcing period unless ``steps`` is given.
    accurate : bool
        Integrate in the accurate mode (steps split at the contact boundaries).
    steps : int, optional
        RK4 steps per forcing period N, held whatever the parameters (the step is h = T/N).

    Raises
    ------
    ModelError
        If ``n`` or ``steps`` is not an integer >= 1, or ``dtau`` is not a positive number.

    Notes
    -----
    Treat a map as immutable: :meth:`with_param` and :meth:`with_steps` return new maps.

    References
    ----------
    T. S. Parker and L. O. Chua, *Practical Numerical Algorithms for Chaotic Systems*, Springer,
    1989 (the Poincaré map of a periodically forced system and its Jacobian by variational
    equations).

    Examples
    --------
    >>> import numpy as np
    >>> from geardyn import GearModel, PeriodMap
    >>> P = PeriodMap(GearModel(omega=0.8), 1)
    >>> e = P.evaluate(np.zeros(2))  # one forcing period from (u, u') = (0, 0)
    >>> e.points.shape, e.monodromy.shape, e.ok
    ((1, 2), (2, 2), True)
    """

    __slots__ = ("model", "n", "dtau", "accurate", "_steps", "_fixed")

    def __init__(
        self, model: Any, n: int = 1, *, dtau: float = DEFAULT_DTAU, accurate: bool = False, steps: int | None = None
    ):
        if not _is_count(n):
            raise ModelError(f"period: must be an integer >= 1, got {n!r}")
        if steps is not None and not _is_count(steps):
            raise ModelError(f"steps: RK4 steps per period must be an integer >= 1, got {steps!r}")
        self.model = model
        self.n = int(n)
        self.dtau = IntegrationOptions(dtau=dtau).dtau
        self.accurate = bool(accurate)
        self._fixed = steps is not None
        self._steps = int(steps) if steps is not None else natural_steps(model, self.dtau)

    # ------------------------------------------------------------------ description
    @property
    def steps(self) -> int:
        """RK4 steps per forcing period N (h = T/N)."""
        return self._steps

    @property
    def natural_steps(self) -> int:
        """ceil(T/Δτ): the steps per period this map's Δτ gives at its parameters."""
        return natural_steps(self.model, self.dtau)

    @property
    def dim(self) -> int:
        """Dimension d of the state."""
        return state_dim(self.model)

    @property
    def period(self) -> float:
        """Forcing period T of the system (non-dimensional time); one map iteration spans n·T."""
        return forcing_period(self.model)

    @property
    def step(self) -> float:
        """The RK4 step h = T/N."""
        return forcing_period(self.model) / self._steps

    def get(self, name: str) -> float:
        """Value of the system parameter ``name``."""
        return self.model.get(name)

    def __repr__(self) -> str:
        return (
            f"PeriodMap(n={self.n}, steps={self._steps}{'' if self._fixed else ' (natural)'}, "
            f"accurate={self.accurate}, model={self.model!r})"
        )

    # ------------------------------------------------------------------ new maps
    def with_param(self, name: str, value: float) -> PeriodMap:
        """The same map for the system with parameter ``name`` set to ``value``.

        Parameters
        ----------
        name : str
            Parameter name (``omega``, ``xi0``, ``kappa1``, ``D``, ...; aliases accepted).
        value : float
            New value.

        Returns
        -------
        PeriodMap
            Same n, Δτ and mode; a step count given explicitly is kept, otherwise it is ceil(T/Δτ)
            at the new parameters.

        Raises
        ------
        ModelError
            For an unknown name or a value the system refuses.
        """
        return PeriodMap(
            self.model.with_param(name, value),
            self.n,
            dtau=self.dtau,
            accurate=self.accurate,
            steps=self._steps if self._fixed else None,
        )

    def with_steps(self, steps: int | None) -> PeriodMap:
        """The same map with ``steps`` RK4 steps per forcing period (None: ceil(T/Δτ)).

        Parameters
        ----------
        steps : int or None
            Steps per period.

        Returns
        -------
        PeriodMap
            ``self`` when nothing changes.

        Raises
        ------
        ModelError
            If ``steps`` is not an integer >= 1.
        """
        if (steps is None and not self._fixed) or (steps is not None and self._fixed and steps == self._steps):
            return self
        return PeriodMap(self.model, self.n, dtau=self.dtau, accurate=self.accurate, steps=steps)

    # ------------------------------------------------------------------ evaluation
    def _options(self) -> IntegrationOptions:
        return IntegrationOptions(transient=0, periods=self.n, accurate=self.accurate)

    def evaluate(self, x: Sequence[float] | np.ndarray) -> MapEvaluation:
        """P^n(x), the intermediate section points and the Jacobian, in one integration.

        Parameters
        ----------
        x : (d,) array
            State at θ = 0.

        Returns
        -------
        MapEvaluation
            ``ok`` False (and NaN results) if x is not finite or the trajectory diverged.
        """
        x = np.asarray(x, dtype=float)
        d = self.dim
        if not np.all(np.isfinite(x)):
            return MapEvaluation(x, np.full((self.n, d), np.nan), np.full((d, d), np.nan), False, self._steps)
        pts, M, _st, ok = period_map(
            self.model, x, self.n, accurate=self.accurate, steps=self._steps, threads=MAP_THREADS
        )
        ok = ok and bool(np.all(np.isfinite(M)))
        return MapEvaluation(x.copy(), pts, M, ok, self._steps)

    def __call__(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """P^n(x) (NaN if the trajectory diverged)."""
        return self.evaluate(x).value

    def jacobian(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """The Jacobian of P^n at x: the monodromy matrix when x lies on a period-n orbit.

        Parameters
        ----------
        x : (d,) array
            The point of the section θ ≡ 0 where the derivative is taken.

        Returns
        -------
        ndarray (d, d)
            ∂P^n/∂x (:attr:`MapEvaluation.monodromy`); NaN if the trajectory diverged.
        """
        return self.evaluate(x).monodromy

    def param_derivative(self, x: Sequence[float] | np.ndarray, name: str) -> np.ndarray:
        """∂P^n/∂p at fixed x and fixed steps per period, by a central difference.

        The difference step is δ = FD_REL_STEP·max(1, |p|); at the edge of the parameter's domain
        (such as D = 0) the difference is one-sided.  The points p ± δ are integrated in one batch.

        Parameters
        ----------
        x : (d,) array
            State at θ = 0.
        name : str
            Parameter name.

        Returns
        -------
        ndarray (d,)
            The derivative; NaN if it cannot be formed (the system is undefined on both sides, or
            a trajectory diverged).

        Raises
        ------
        ModelError
            For an unknown parameter name.
        """
        name = canonical_param(name)
        p = self.model.get(name)
        d = FD_REL_STEP * max(1.0, abs(p))
        x = np.asarray(x, dtype=float)
        nan = np.full(self.dim, np.nan)
        models, values = [], []
        for q in (p + d, p - d, p):
            try:
                models.append(self.model if q == p else self.model.with_param(name, q))
                values.append(q)
            except ModelError:
                continue
        if len(values) < 2:
            return nan
        # p ± δ where both are valid, else the valid one and p
        res = integrate_batch(models[:2], x, self._options(), steps=self._steps, threads=MAP_THREADS)
        if not np.all(res.ok):
            return nan
        ends = res.poincare[:, -1, :]
        return (ends[0] - ends[1]) / (values[0] - values[1])

    def trajectory(self, x: Sequence[float] | np.ndarray):
        """The trajectory over the n periods of one map iteration, at every RK4 step.

        Parameters
        ----------
        x : (d,) array
            State at θ = 0.

        Returns
        -------
        geardyn.integrate.Trajectory
            The full state and every element's (δ, δ') (NaN if the trajectory diverged).
        """
        return trajectory(
            self.model, x, self._options(), history_periods=self.n, steps=self._steps, threads=MAP_THREADS
        )

    def history(self, x: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The trajectory over the n periods of one map iteration, at every RK4 step.

        Parameters
        ----------
        x : (2,) array
            State at θ = 0.

        Returns
        -------
        tau, u, v : ndarray (n·N + 1,)
            Time from x and the state (NaN if the trajectory diverged).
        """
        tr = self.trajectory(x)
        return tr.tau, tr.u, tr.v
