"""Validation of user input (command line, configuration values, Python callers).

Every function here either returns the value in its checked form or raises
:class:`~geardyn.model.ModelError` with a one-line message that starts with the name of the
parameter and says what is allowed, e.g. ``"omega: must be > 0 (mesh frequency ω_e/ω_n), got -1.0"``.
Nothing else is raised, whatever the type of the value (this is tested with random input).
The CLI turns these errors into one line on stderr and exit code 2.

The model's own invariants (ω > 0, D >= 0, Σ|κ_r| < 1, phases per harmonic) are checked by
:class:`~geardyn.model.GearModel`; this module adds the checks of the raw values (type,
finiteness, integer-ness) in front of it and the limits that only make sense for a run (step
count per period, grid size, workers, scheduler address).
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from .grid import Grid, param_name
from .model import (
    DEFAULT_DTAU,
    DEFAULT_PERIODS,
    DEFAULT_TRANSIENT,
    GearModel,
    IntegrationOptions,
    ModelError,
    _check_finite,
    canonical_param,
)

__all__ = [
    "MAX_GRID_POINTS",
    "MAX_PERIOD_CONTRACTION",
    "MAX_PERIODS",
    "MAX_STEPS_PER_PERIOD",
    "axis",
    "chunk_points",
    "counts",
    "dpi",
    "exponents_computable",
    "figure_formats",
    "grid",
    "initial_state",
    "integer",
    "number",
    "options",
    "positive",
    "recorded",
    "scheduler",
    "workers",
]

#: Largest number of RK4 steps per forcing period, ceil(T/Δτ): a smaller ω or Δτ is refused
#: (10⁷ steps per period is already hours per point).
MAX_STEPS_PER_PERIOD = 10_000_000
#: Largest number of transient or recorded periods.
MAX_PERIODS = 100_000_000
#: Largest number of points of a sweep grid (product over its axes).
MAX_GRID_POINTS = 100_000_000
#: Largest number of local worker processes.
MAX_WORKERS = 4096
#: Largest number of RK4 steps of one point, steps per period × (transient + recorded periods):
#: 10¹² steps is about an hour of one core per point.
MAX_TOTAL_STEPS = 10**12
#: Largest number of recorded values of a result (Poincaré points × 2 coordinates over all points):
#: 5·10⁸ float64 values are 4 GB, a sixth of a 24 GB machine.
MAX_RECORDED_VALUES = 500_000_000

#: File formats a figure can be saved in (``--format``).
FIGURE_FORMATS = ("png", "pdf", "svg")
#: Range of ``--dpi``.
DPI_RANGE = (10, 2400)

_SCHEDULER = re.compile(r"^(?:(tcp|tls|inproc|ucx|ws|wss)://)?(\[[0-9a-fA-F:.]+\]|[A-Za-z0-9_.\-]+)(?::(\d{1,5}))?/?$")


def _describe(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def number(name: str, value: Any) -> float:
    """A finite real number (bool, strings, complex, None and non-finite values refused).

    Parameters
    ----------
    name, value
        The parameter's name (it starts the message) and what was given for it.

    Returns
    -------
    float
        The number; anything else raises :class:`ModelError`.
    """
    return _check_finite(name, value, real_only=True, describe=_describe)


def positive(name: str, value: Any, what: str = "") -> float:
    """A finite number > 0.

    Parameters
    ----------
    name : str
        The parameter's name, for the message.
    value : object
        The raw value.
    what : str
        Appended to "must be > 0" in the message (e.g. " (mesh frequency ω_e/ω_n)").

    Returns
    -------
    float
        The number, > 0.

    Raises
    ------
    ModelError
        For anything but a finite number > 0.
    """
    x = number(name, value)
    if x <= 0:
        raise ModelError(f"{name}: must be > 0{what}, got {_describe(value)}")
    return x


def integer(name: str, value: Any, lo: int, hi: int | None = None) -> int:
    """An integer in [lo, hi] (an integral float such as 3.0 is accepted).

    Parameters
    ----------
    name : str
        The parameter's name, for the message.
    value : object
        The raw value (bool refused).
    lo : int
        Smallest value allowed.
    hi : int, optional
        Largest value allowed (no limit by default).

    Returns
    -------
    int
        The value as an ``int``.

    Raises
    ------
    ModelError
        For a value that is not an integer in range.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ModelError(f"{name}: expected an integer >= {lo}, got {_describe(value)}")
    if isinstance(value, numbers.Integral):
        n = int(value)
    else:
        try:
            x = float(value)
        except (OverflowError, ValueError, TypeError):
            x = math.nan
        if not (math.isfinite(x) and x.is_integer()):
            raise ModelError(f"{name}: must be an integer >= {lo}, got {_describe(value)}")
        n = int(x)
    if n < lo or (hi is not None and n > hi):
        allowed = f">= {lo}" if hi is None else f">= {lo} and <= {hi}"
        raise ModelError(f"{name}: must be an integer {allowed}, got {_describe(value)}")
    return n


def counts(dtau: Any = None, transient: Any = None, periods: Any = None) -> tuple[Any, Any, Any]:
    """The step and the period counts of a run, each checked when given: Δτ > 0, ``transient`` >= 0 and
    ``periods`` >= 1 whole periods, at most :data:`MAX_PERIODS` each (the bounds of :func:`options`, for a caller
    that has only some of them yet).

    Parameters
    ----------
    dtau : float, optional
        Target step Δτ.
    transient : int, optional
        Periods discarded.
    periods : int, optional
        Periods recorded.

    Returns
    -------
    (float or None, int or None, int or None)
        The values as ``float`` and ``int``; None where not given.

    Raises
    ------
    ModelError
        For a value out of range.

    Examples
    --------
    >>> from geardyn import validate
    >>> validate.counts(transient=3.0)
    (None, 3, None)
    >>> validate.counts(periods=0)
    Traceback (most recent call last):
    ...
    geardyn.errors.ModelError: periods: must be an integer >= 1 and <= 100000000, got 0
    """
    return (
        None if dtau is None else positive("dtau", dtau, " and smaller than the forcing period 2π/ω"),
        None if transient is None else integer("transient", transient, 0, MAX_PERIODS),
        None if periods is None else integer("periods", periods, 1, MAX_PERIODS),
    )


def options(
    dtau: Any = DEFAULT_DTAU,
    transient: Any = DEFAULT_TRANSIENT,
    periods: Any = DEFAULT_PERIODS,
    accurate: Any = False,
    omegas: Iterable[float] = (),
) -> IntegrationOptions:
    """Integration options, checked against every mesh frequency ``omegas`` they will be used with.

    Δτ must be > 0 and smaller than every forcing period T = 2π/ω, with at most
    :data:`MAX_STEPS_PER_PERIOD` steps per period; ``transient`` >= 0 and ``periods`` >= 1 whole
    periods, at most :data:`MAX_PERIODS` each.

    Parameters
    ----------
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    transient : int
        Periods discarded; default :data:`~geardyn.model.DEFAULT_TRANSIENT`.
    periods : int
        Periods recorded; default :data:`~geardyn.model.DEFAULT_PERIODS`.
    accurate : bool
        Split the steps at the contact boundaries (``IntegrationOptions.accurate``).
    omegas : iterable of float
        The mesh frequencies of the run (none: no check against the forcing period).

    Returns
    -------
    IntegrationOptions

    Raises
    ------
    ModelError
        For a value out of range, a step not below a forcing period, too many steps per period or
        too many steps per point (:data:`MAX_TOTAL_STEPS`).
    """
    dt, tr, pe = counts(dtau, transient, periods)
    if not isinstance(accurate, (bool, np.bool_)):
        raise ModelError(f"accurate: expected true or false, got {_describe(accurate)}")
    opts = IntegrationOptions(dtau=dt, transient=tr, periods=pe, accurate=bool(accurate))
    ws = np.asarray(list(omegas), dtype=float).ravel() if not isinstance(omegas, np.ndarray) else omegas.ravel()
    if ws.size:
        w_max, w_min = float(np.max(ws)), float(np.min(ws))
        if not (math.isfinite(w_min) and w_min > 0):
            raise ModelError(f"omega: must be a finite number > 0, got {w_min!r}")
        opts.check_for(w_max)
        steps = 2.0 * math.pi / w_min / dt
        if not steps <= MAX_STEPS_PER_PERIOD:
            raise ModelError(
                f"dtau: ω = {w_min:.6g} with Δτ = {dt:g} needs {steps:.3g} steps per forcing period; "
                f"at most {MAX_STEPS_PER_PERIOD:.0e} allowed (increase dtau or omega)"
            )
        total = math.ceil(steps) * (tr + pe)
        if total > MAX_TOTAL_STEPS:
            raise ModelError(
                f"transient/periods: {tr} + {pe} periods of {math.ceil(steps)} steps are {total:.3g} RK4 steps per "
                f"point; at most {MAX_TOTAL_STEPS:.0e} allowed (fewer periods or a larger dtau)"
            )
    return opts


def recorded(points: int, periods: int) -> None:
    """Refuse a result whose recorded Poincaré points would not fit in memory (:data:`MAX_RECORDED_VALUES`).

    Parameters
    ----------
    points : int
        Points of the sweep.
    periods : int
        Recorded periods per point.

    Raises
    ------
    ModelError
        If points × periods × 2 exceeds :data:`MAX_RECORDED_VALUES`.
    """
    n = int(points) * int(periods) * 2
    if n > MAX_RECORDED_VALUES:
        raise ModelError(
            f"periods: {points} points × {periods} recorded periods × 2 coordinates = {n:.3g} values; at most "
            f"{MAX_RECORDED_VALUES:.0e} fit in memory (fewer points or recorded periods)"
        )


def initial_state(u0: Any, v0: Any) -> tuple[float, float]:
    """The initial state (u0, v0) at θ = 0 of the 1-DOF model: two finite numbers.

    Parameters
    ----------
    u0, v0 : float
        Initial displacement and velocity (non-dimensional).

    Returns
    -------
    tuple of float

    Raises
    ------
    ModelError
        If either is not a finite number.
    """
    return number("u0", u0), number("v0", v0)


def axis(param: Any, start: Any, stop: Any, num: Any) -> tuple[str, np.ndarray]:
    """One swept parameter: its canonical name and ``num`` evenly spaced values from start to stop.

    Parameters
    ----------
    param : str
        Parameter name or alias.
    start, stop : float
        Ends of the range.
    num : int
        Number of values, 1 … :data:`MAX_GRID_POINTS`.

    Returns
    -------
    name : str
    values : ndarray

    Raises
    ------
    ModelError
        For an unknown name, a non-finite end, a bad count or values that overflow.
    """
    if not isinstance(param, str) or not param:
        raise ModelError(f"param: expected a parameter name, got {_describe(param)}")
    name = param_name(param)
    a = number("start", start)
    b = number("stop", stop)
    n = integer("num", num, 1, MAX_GRID_POINTS)
    values = np.linspace(a, b, n)
    if not np.all(np.isfinite(values)):
        raise ModelError(f"start/stop: the values from {a!r} to {b!r} overflow; use a smaller range")
    return name, values


def grid(
    base: GearModel, axes: Sequence[tuple[str, Sequence[float]]], opts: IntegrationOptions | None = None
) -> Sequence[GearModel]:
    """The models of the Cartesian grid over ``axes`` (last axis fastest), each validated.

    Refuses an empty grid, one larger than :data:`MAX_GRID_POINTS`, any grid point the model
    refuses (e.g. ω <= 0 or Σ|κ| >= 1, named with its value) and, with ``opts``, a step Δτ not
    smaller than the forcing period of every point.

    Parameters
    ----------
    base : GearModel
        The model every point starts from.
    axes : sequence of (str, sequence of float)
        The swept parameters and their values.
    opts : IntegrationOptions, optional
        Options to check against every point (:func:`options`).

    Returns
    -------
    sequence of GearModel
        One per grid point, in row-major order (:meth:`geardyn.grid.Grid.lazy_models` of a product
        grid: each model is built when it is used).

    Raises
    ------
    ModelError
        For a malformed axis, an empty or too large grid, a point the model refuses or options
        that do not fit.
    """
    if not axes:
        raise ModelError("grid: empty parameter grid; give at least one parameter to sweep")
    names, values = [], []
    total = 1
    for i, ax in enumerate(axes):
        if not (isinstance(ax, (tuple, list)) and len(ax) == 2):
            raise ModelError(f"grid: axis {i + 1} must be (parameter, values), got {_describe(ax)}")
        p, v = ax
        name = param_name(p) if isinstance(p, str) else canonical_param(repr(p))
        try:
            arr = np.asarray(v, dtype=float).ravel()
        except (TypeError, ValueError, OverflowError):
            raise ModelError(f"{name}: grid values must be finite numbers, got {_describe(v)}") from None
        if arr.size == 0:
            raise ModelError(f"{name}: empty grid; give at least one value (num >= 1)")
        if not np.all(np.isfinite(arr)):
            raise ModelError(f"{name}: grid values must be finite numbers")
        total *= arr.size
        if total > MAX_GRID_POINTS:
            raise ModelError(f"grid: {total} points or more; at most {MAX_GRID_POINTS:.0e} allowed")
        names.append(name)
        values.append(arr)
    g = Grid("product", names, values)
    models = g.lazy_models(base)  # every point validated; a model is built only where one is used
    if opts is not None:
        options(opts.dtau, opts.transient, opts.periods, opts.accurate, g.omegas(base))
    return models


def figure_formats(value: Any) -> tuple[str, ...]:
    """The file formats of saved figures: ``"png,pdf"`` or a sequence of names, each in :data:`FIGURE_FORMATS`.

    Parameters
    ----------
    value : str or sequence of str
        The formats (``--format``), comma-separated in a string; case and spaces are ignored, a repeat
        is dropped.

    Returns
    -------
    tuple of str
        The formats in the order given.

    Raises
    ------
    ModelError
        For an empty list or an unknown format.
    """
    items = value.split(",") if isinstance(value, str) else list(value)
    names = tuple(dict.fromkeys(str(v).strip().lower().lstrip(".") for v in items))
    bad = [n for n in names if n not in FIGURE_FORMATS]
    if not names or bad:  # (an empty name is one of the bad)
        raise ModelError(f"format: expected {', '.join(FIGURE_FORMATS)} (comma-separated), got {value!r}")
    return names


def dpi(value: Any) -> int:
    """The resolution of raster figures (``--dpi``), an integer in :data:`DPI_RANGE`.

    Parameters
    ----------
    value : int
        Dots per inch.

    Returns
    -------
    int

    Raises
    ------
    ModelError
        Outside :data:`DPI_RANGE`.
    """
    return integer("dpi", value, *DPI_RANGE)


def workers(n: Any) -> int:
    """Number of local worker processes, 1 … :data:`MAX_WORKERS`.

    Parameters
    ----------
    n : int
        The requested count (``--workers``).

    Returns
    -------
    int
        The count, checked.

    Raises
    ------
    ModelError
        Unless ``n`` is an integer from 1 to :data:`MAX_WORKERS`.
    """
    return integer("workers", n, 1, MAX_WORKERS)


def chunk_points(n: Any) -> int:
    """Parameter points per chunk, >= 1 (the engine's ``chunk_points``).

    Parameters
    ----------
    n : int
        Points per chunk as given (``--chunk-points``); at most :data:`MAX_GRID_POINTS`.

    Returns
    -------
    int
        The size, checked; it raises :class:`ModelError` for anything else.
    """
    return integer("chunk size", n, 1, MAX_GRID_POINTS)


def scheduler(address: Any) -> str | None:
    """A Dask scheduler address such as ``tcp://HOST:PORT`` (None: no scheduler).

    Parameters
    ----------
    address : str or None
        The raw address.

    Returns
    -------
    str or None
        The address, stripped.

    Raises
    ------
    ModelError
        For anything that is not an address (scheme, host, optional port 1 … 65535).
    """
    if address is None:
        return None
    a = address.strip() if isinstance(address, str) else ""  # (an empty address matches nothing)
    m = _SCHEDULER.match(a)
    if m is None or (m.group(3) is not None and not 0 < int(m.group(3)) < 65536):
        raise ModelError(f"scheduler: expected an address like tcp://HOST:PORT, got {_describe(address)}")
    return a


#: Largest contraction (as a power of e) of the perturbations over one forcing period for which
#: Lyapunov exponents are computed: e^-700 is still a normal double (the smallest is e^-708).
MAX_PERIOD_CONTRACTION = 700.0


def exponents_computable(model: Any, omegas: Any) -> None:
    """Refuse Lyapunov exponents where the damping contracts the perturbations below double precision within one
    forcing period (e^(-2 ξ0 T) < e^-:data:`MAX_PERIOD_CONTRACTION`, T = 2π/ω): their Gram–Schmidt
    normalisation would divide by zero.

    Parameters
    ----------
    model : System
        The system (its mean damping is −mean trace / state dimension: the pair's ξ0).
    omegas : sequence of float
        Every forcing frequency the exponents are computed at.

    Raises
    ------
    ModelError
        Naming ω and the smallest ω allowed.
    """
    xi = -float(model.mean_trace()) / model.state_dim  # the mean damping (the pair's ξ0): harmonics average out
    ws = np.asarray(omegas, dtype=float).ravel()
    if xi <= 0 or not ws.size:
        return
    w_min = 4.0 * math.pi * xi / MAX_PERIOD_CONTRACTION
    w = float(np.min(ws))
    if w < w_min:
        raise ModelError(
            f"omega: Lyapunov exponents need ω >= {w_min:.4g} with this damping (ξ0 = {xi:g}): at ω = {w:.4g} the "
            f"perturbations shrink by e^-{4 * math.pi * xi / w:.0f} in one forcing period, below double precision"
        )
