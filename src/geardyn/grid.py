"""Grids of a sweep: the parameter points (or initial states) a sweep runs over.

One concept for every sweep (after Attractors.jl, where a sweep is a curve or a product of
parameter points):

- a **range**: one parameter, its values sorted (:meth:`Grid.range`, :meth:`Grid.linspace`);
- a **product** of axes: every combination, the last axis fastest (:meth:`Grid.product`);
- a **curve**: parameter points listed together, one value of each parameter per point
  (:meth:`Grid.curve`);
- a grid of **initial states** (u0, v0) at θ = 0 (:meth:`Grid.states`).

A grid knows its axes (canonical parameter names of any System, :func:`param_name`: the pair's names,
and a system's ``<element>.<name>`` such as ``m2.kappa2``, the stiffness harmonic of mesh ``m2``, and
values), its shape and size, yields the compact parameter array of a slice of its points
(:meth:`Grid.points`: what a sweep's workers receive instead of lists of model objects) and
builds the models of a slice (:meth:`Grid.models`), inside the worker.
"""

from __future__ import annotations

from collections import abc
from collections.abc import Sequence
from typing import Any

import numpy as np

from ._docfill import fill
from .model import GearModel, ModelError, canonical_param
from .system import Batch, build_models

__all__ = [
    "GRID_KINDS",
    "Grid",
    "GridModels",
    "build_models",
    "chunked",
    "linspace_values",
    "param_name",
    "point_models",
]

#: Docstring entries of the functions and classes that build the models of parameter points.
_BASE = """base : System
    The model every point starts from (a :class:`GearModel` or a system)."""

#: The kinds of grid.
GRID_KINDS = ("range", "product", "curve", "states")


def linspace_values(start: float, stop: float, num: int, label: str = "") -> np.ndarray:
    """Evenly spaced values ``start`` … ``stop`` (``num`` >= 1), validated.

    Parameters
    ----------
    start, stop : float
        Ends of the range (finite).
    num : int
        Number of values (>= 1).
    label : str
        Prefix of the names in the messages (``"u0"`` → ``"u0 start: …"``).

    Returns
    -------
    ndarray

    Raises
    ------
    ModelError
        For a non-finite end or ``num`` not an integer >= 1.
    """
    pre = f"{label} " if label else ""
    for name, v in (("start", start), ("stop", stop)):
        if not np.isfinite(v):
            raise ModelError(f"{pre}{name}: must be a finite number, got {v!r}")
    if isinstance(num, bool) or int(num) != num or num < 1:
        raise ModelError(f"{pre}num: must be an integer >= 1, got {num!r}")
    return np.linspace(float(start), float(stop), int(num))


def chunked(n: int, size: int) -> list[slice]:
    """Slices cutting range(n) into consecutive chunks of at most ``size`` points.

    Parameters
    ----------
    n : int
        Number of points.
    size : int
        Points per chunk (>= 1).

    Returns
    -------
    list of slice

    Raises
    ------
    ModelError
        For ``size`` < 1.
    """
    if size < 1:
        raise ModelError(f"chunk size: must be >= 1, got {size}")
    return [slice(i, min(i + size, n)) for i in range(0, n, size)]


def param_name(name: str) -> str:
    """Canonical spelling of a parameter name of any System.

    Parameters
    ----------
    name : str
        A name of the pair (:func:`geardyn.model.canonical_param`), or a system's ``<element>.<name>``
        (``m2.kappa2``, ``gap.D``, ``m1.k``; the part after the dot spelled as the pair's where it is one).

    Returns
    -------
    str

    Raises
    ------
    ModelError
        For an unqualified name outside the pair's grammar, or a qualified one with an empty part or spaces.
    """
    if isinstance(name, str) and "." in name:
        elem, p = name.rsplit(".", 1)
        if not (elem.strip() and p.strip()) or not all(c.isprintable() and not c.isspace() for c in name):
            raise ModelError(
                f"param: {name!r} is not <element>.<name>: give a mesh or clearance and one of its parameters "
                "(e.g. m2.kappa2), without spaces"
            )
        try:
            p = canonical_param(p)
        except ModelError:
            pass  # a system's own mesh parameter (k, ratio): its with_param judges it
        return f"{elem}.{p}"
    return canonical_param(name)


def _axis_values(name: str, values: Sequence[float] | np.ndarray, unique: bool) -> np.ndarray:
    a = np.asarray(values, dtype=float).ravel()
    if unique:
        a = np.unique(a)
    if a.size == 0:
        raise ModelError(f"{name}: empty grid (num must be >= 1)")
    if not np.all(np.isfinite(a)):
        raise ModelError(f"{name}: values must be finite numbers")
    return a


@fill(_BASE)
def point_models(base: Any, names: Sequence[str], points: np.ndarray) -> Batch:
    """The :class:`~geardyn.system.Batch` of parameter points that ``base``'s backend supplies
    (:meth:`geardyn.backend.Backend.points`): the pair's points packed straight from the array, bit for bit the
    models' kernel arrays without a model object per point; a :class:`~geardyn.system.ModelList` otherwise.

    Parameters
    ----------
    {{base}}
    names : sequence of str
        Parameter names, one per column of ``points``.
    points : ndarray (P, len(names))
        The parameter values of each point.

    Returns
    -------
    Batch

    Raises
    ------
    ModelError
        For no point or a point the model refuses.

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> b = point_models(GearModel(), ["omega"], [[0.5], [0.9]])
    >>> len(b), b[1].omega
    (2, 0.9)
    """
    return base.backend.points(base, names, points)


class Grid:
    """The points of a sweep: a range, a product of axes, a curve, or a grid of initial states.

    Build one with :meth:`range`, :meth:`linspace`, :meth:`product`, :meth:`curve` or
    :meth:`states`; the constructor takes already validated axes.

    Parameters
    ----------
    kind : {'range', 'product', 'curve', 'states'}
        The kind of grid.
    names : sequence of str
        Axis names: canonical parameter names, or ``v0``, ``u0`` for a state grid.
    axes : sequence of ndarray
        Values of each axis (a curve: the value of each parameter at each point, equal lengths).

    Attributes
    ----------
    kind : str
    names : tuple of str
    axes : tuple of ndarray

    Examples
    --------
    >>> from geardyn import Grid
    >>> g = Grid.linspace("omega", 0.5, 1.5, 3)
    >>> g, g.values("omega").tolist()
    (Grid.range(omega[3]), [0.5, 1.0, 1.5])
    >>> Grid.product(("omega", [0.6, 0.8]), ("xi0", [0.05, 0.1])).points().tolist()
    [[0.6, 0.05], [0.6, 0.1], [0.8, 0.05], [0.8, 0.1]]
    """

    def __init__(self, kind: str, names: Sequence[str], axes: Sequence[np.ndarray]) -> None:
        if kind not in GRID_KINDS:
            raise ModelError(f"grid: kind must be one of {', '.join(GRID_KINDS)}, got {kind!r}")
        if len(names) != len(axes) or not names:
            raise ModelError(f"grid: {len(names)} names but {len(axes)} axes")
        self.kind = kind
        self.names = tuple(str(n) for n in names)
        self.axes = tuple(np.asarray(a, dtype=float) for a in axes)
        if kind == "curve" and len({a.size for a in self.axes}) != 1:
            raise ModelError("curve: every parameter needs one value per point")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def range(cls, param: str, values: Sequence[float] | np.ndarray) -> Grid:
        """One parameter over ``values`` (sorted, duplicates dropped).

        Parameters
        ----------
        param : str
            Any parameter name of a System (:func:`param_name`).
        values : sequence of float
            Its values (finite, at least one).

        Returns
        -------
        Grid
            Of kind ``'range'``, one axis.

        Raises
        ------
        ModelError
            For an unknown parameter, no values or a non-finite value.
        """
        name = param_name(param)
        return cls("range", [name], [_axis_values(name, values, True)])

    @classmethod
    def linspace(cls, param: str, start: float, stop: float, num: int) -> Grid:
        """One parameter over ``num`` evenly spaced values ``start`` … ``stop``.

        Parameters
        ----------
        param : str
            Any parameter name.
        start, stop : float
            Ends of the range.
        num : int
            Number of values (>= 1).

        Returns
        -------
        Grid
            Of kind ``'range'``, values evenly spaced.

        Raises
        ------
        ModelError
            See :func:`linspace_values` and :meth:`range`.
        """
        return cls.range(param, linspace_values(start, stop, num))

    @classmethod
    def product(cls, *axes: tuple[str, Sequence[float]], unique: bool = True) -> Grid:
        """Every combination of the axes' values, the last axis fastest.

        Parameters
        ----------
        *axes : (str, sequence of float)
            Parameter name and values of each axis (different parameters).
        unique : bool
            Sort each axis and drop duplicate values (as every sweep does); False keeps them as given.

        Returns
        -------
        Grid
            Of kind ``'product'``, shape (len(values) of each axis).

        Raises
        ------
        ModelError
            For no axis, a parameter given twice, an unknown name, or an empty or non-finite axis.
        """
        if not axes:
            raise ModelError("empty parameter grid: give at least one parameter")
        names = [param_name(p) for p, _ in axes]
        if len(set(names)) != len(names):
            raise ModelError(f"grid: each parameter at most once, got {', '.join(names)}")
        return cls("product", names, [_axis_values(n, v, unique) for n, (_, v) in zip(names, axes)])

    @classmethod
    def curve(cls, points: dict[str, Sequence[float]]) -> Grid:
        """Parameter points listed together: point i sets every parameter to its i-th value.

        Parameters
        ----------
        points : dict of str to sequence of float
            Parameter name → its value at each point (equal lengths, in the order of the sweep).

        Returns
        -------
        Grid
            Of kind ``'curve'``, shape (points,).

        Raises
        ------
        ModelError
            For no parameter, unequal lengths, an unknown name or a non-finite value.
        """
        if not points:
            raise ModelError("empty parameter grid: give at least one parameter")
        names = [param_name(p) for p in points]
        return cls("curve", names, [_axis_values(n, v, False) for n, v in zip(names, points.values())])

    @classmethod
    def states(cls, u0: Sequence[float] | np.ndarray, v0: Sequence[float] | np.ndarray) -> Grid:
        """Initial states (u0, v0) at θ = 0: rows of v0, u0 fastest (dimensions ``v0``, ``u0``).

        Parameters
        ----------
        u0, v0 : sequence of float
            Initial displacements and velocities (non-dimensional), kept as given.

        Returns
        -------
        Grid
            Of kind ``'states'``, shape (len(v0), len(u0)).

        Raises
        ------
        ModelError
            For an empty or non-finite axis.
        """
        return cls("states", ["v0", "u0"], [_axis_values("v0", v0, False), _axis_values("u0", u0, False)])

    # ------------------------------------------------------------------ shape
    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of the grid's result arrays (one entry per axis; a range or curve: (n,))."""
        if self.kind == "curve":
            return (int(self.axes[0].size),)
        return tuple(int(a.size) for a in self.axes)

    @property
    def size(self) -> int:
        """Number of points."""
        return int(np.prod(self.shape))

    def __len__(self) -> int:
        return self.size

    def __repr__(self) -> str:
        axes = ", ".join(f"{n}[{a.size}]" for n, a in zip(self.names, self.axes))
        return f"Grid.{self.kind}({axes})"

    def values(self, name: str) -> np.ndarray:
        """The values of one axis (the coordinate of the result's dimension ``name``)."""
        return self.axes[self.names.index(name)]

    # ------------------------------------------------------------------ points
    def points(self, sl: slice = slice(None)) -> np.ndarray:
        """Parameter values of the points in ``sl`` (flat, row-major order): array (n, len(names)).

        Parameters
        ----------
        sl : slice
            A slice of the flat point index (see :meth:`slices`).

        Returns
        -------
        ndarray (n, len(names))
            Column j holds ``names[j]``.
        """
        if self.kind == "curve":
            return np.column_stack(self.axes)[sl]
        idx = np.unravel_index(np.arange(*sl.indices(self.size)), self.shape)
        return np.column_stack([a[i] for a, i in zip(self.axes, idx)])

    def state_points(self, sl: slice = slice(None)) -> np.ndarray:
        """Initial states (u0, v0) of the points in ``sl`` of a state grid: array (n, 2).

        Raises
        ------
        ModelError
            For a grid that is not a grid of initial states.
        """
        if self.kind != "states":
            raise ModelError(f"grid: a {self.kind} grid holds parameter points, not initial states")
        p = self.points(sl)
        return np.column_stack([p[:, 1], p[:, 0]])

    @fill(_BASE)
    def models(self, base: Any, sl: slice = slice(None)) -> list[Any]:
        """The models of the points in ``sl``: ``base`` with each axis parameter set, in axis order.

        Parameters
        ----------
        {{base}}
        sl : slice
            A slice of the flat point index.

        Returns
        -------
        list of System

        Raises
        ------
        ModelError
            For a state grid, or a point the model refuses.
        """
        if self.kind == "states":
            raise ModelError("grid: a grid of initial states has no parameter points")
        return build_models(base, self.names, self.points(sl))

    @fill(_BASE)
    def check(self, base: Any, block: int = 1 << 16) -> None:
        """Validate every point as its model would be validated, without keeping a model.

        Parameters
        ----------
        {{base}}
        block : int
            Points checked at a time (the batch of :func:`point_models`: the pair's packed arrays).

        Raises
        ------
        ModelError
            For a state grid, or the model's error for the first point it refuses.
        """
        if self.kind == "states":
            raise ModelError("grid: a grid of initial states has no parameter points")
        for sl in chunked(self.size, block):
            point_models(base, self.names, self.points(sl))

    @fill(_BASE)
    def lazy_models(self, base: Any) -> GridModels:
        """The models of every point, validated now (:meth:`check`) and each built only when it is used.

        Parameters
        ----------
        {{base}}

        Returns
        -------
        GridModels
            A sequence of :class:`GearModel` in flat order (equal to :meth:`models`).

        Raises
        ------
        ModelError
            As :meth:`check`.
        """
        self.check(base)
        return GridModels(self, base)

    @fill(_BASE)
    def omegas(self, base: Any) -> np.ndarray:
        """The mesh frequency ω of every point (flat order): its ω axis, else ``base.omega``.

        Parameters
        ----------
        {{base}}

        Returns
        -------
        ndarray (size,)
        """
        if "omega" in self.names and self.kind != "states":
            j = self.names.index("omega")
            if self.kind == "curve":
                return np.asarray(self.axes[j], dtype=float)
            shape = [1] * len(self.axes)
            shape[j] = self.axes[j].size
            return np.broadcast_to(self.axes[j].reshape(shape), self.shape).ravel()
        return np.full(self.size, float(base.omega))

    def steps_per_period(self, base: GearModel, dtau: float) -> np.ndarray:
        """RK4 steps per forcing period of every point (flat order): N = ceil(T/Δτ) of its ω.

        Parameters
        ----------
        base : GearModel
            The model every point starts from (its ω where ω is not an axis).
        dtau : float
            Target step Δτ.

        Returns
        -------
        ndarray of int64 (size,)
        """
        from .pairpack import steps_per_period

        return steps_per_period(self.omegas(base) / (base.period_multiple() or 1), dtau)

    def cost_slices(self, costs: np.ndarray, target: float, min_points: int = 1, min_chunks: int = 1) -> list[slice]:
        """Consecutive slices whose summed ``costs`` are about ``target`` each.

        A chunk ends at the first point where the running cost reaches the next multiple of
        ``target``; chunks hold at least ``min_points`` points, and the grid is cut into at least
        ``min_chunks`` chunks when it has enough points.  The cut depends only on the costs (not on
        the worker count), so a sweep resumed with other workers finds its chunks again.

        Parameters
        ----------
        costs : ndarray (size,)
            Estimated cost of every point (flat order), e.g. its RK4 steps.
        target : float
            Cost of one chunk (> 0).
        min_points, min_chunks : int
            Lower bounds on the points per chunk and on the number of chunks.

        Returns
        -------
        list of slice
        """
        n = self.size
        c = np.asarray(costs, dtype=float).ravel()
        total = float(np.sum(c))
        chunks = max(1, int(np.ceil(total / max(float(target), 1e-300))), min(int(min_chunks), n))
        chunks = min(chunks, max(1, n // max(int(min_points), 1)))
        if chunks <= 1:
            return [slice(0, n)]
        cum = np.cumsum(c)
        cuts = np.searchsorted(cum, total * np.arange(1, chunks) / chunks, side="left") + 1
        edges = np.unique(np.concatenate([[0], np.clip(cuts, 1, n), [n]]))
        return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]

    def slices(self, chunk_points: int) -> list[slice]:
        """Consecutive slices of at most ``chunk_points`` points covering the grid.

        Raises
        ------
        ModelError
            For ``chunk_points`` < 1.
        """
        return chunked(self.size, chunk_points)


@fill(_BASE)
class GridModels(abc.Sequence):
    """The models of a grid's points in flat order, each built when it is indexed (:meth:`Grid.lazy_models`).

    Parameters
    ----------
    grid : Grid
        The grid (parameter points).
    {{base}}
    """

    def __init__(self, grid: Grid, base: Any) -> None:
        self.grid, self.base = grid, base

    def __len__(self) -> int:
        return self.grid.size

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return self.grid.models(self.base, i)
        k = int(i) + (self.grid.size if int(i) < 0 else 0)
        if not 0 <= k < self.grid.size:
            raise IndexError("grid model index out of range")
        return self.grid.models(self.base, slice(k, k + 1))[0]

    def __repr__(self) -> str:
        return f"GridModels({self.grid!r})"
