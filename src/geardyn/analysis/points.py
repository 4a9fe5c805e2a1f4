"""What the sweeps over many points share: the initial state, the chunks, the rows, the Dataset.

A bifurcation diagram, a two-parameter map and a basin map all cut a :class:`~geardyn.grid.Grid`
into chunks for the sweep engine (:func:`geardyn.sweep.run_chunks`), concatenate the per-point
rows the chunks return and assemble them into one annotated :class:`xarray.Dataset`.  The pieces
here do that once for all of them.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from .._docfill import attributes
from ..io import annotate, result_attrs
from ..model import GearModel, IntegrationOptions, ModelError
from ..sweep import Chunk, SweepOptions, run_chunks
from ..system import element_names
from .classify import SETTLE_PERIODS

__all__ = [
    "SweepKeyword",
    "SWEEP_KEYWORDS",
    "sweep_function",
    "initial_state",
    "concat_rows",
    "RowSink",
    "run_slices",
    "result_dataset",
    "grid_variables",
]


@dataclass(frozen=True)
@attributes
class SweepKeyword:
    """A keyword parameter that several sweeps share: its annotation, default and documentation."""

    #: The keyword.
    name: str
    #: Its type, as written in the signature.
    annotation: str
    #: Its default value.
    default: Any
    #: Its entry in a numpydoc Parameters section (type line, then the description indented).
    doc: str


#: The keyword parameters the sweeps over points share (declared once: :func:`sweep_function`).
SWEEP_KEYWORDS: dict[str, SweepKeyword] = {
    k.name: k
    for k in (
        SweepKeyword(
            "state0",
            "Sequence[float]",
            (0.0, 0.0),
            """state0 : sequence of float
    Initial state (non-dimensional) at θ = 0 of every point (``fixed`` mode) or of the first point
    of each continuation run; one entry per state component (``model.state_dim``).""",
        ),
        SweepKeyword(
            "options",
            "IntegrationOptions",
            IntegrationOptions(),
            """options : IntegrationOptions
    Transient and recorded periods per point (in continuation runs a shorter transient is usually
    enough, since each point starts near its attractor); default ``IntegrationOptions()``.""",
        ),
        SweepKeyword(
            "lyapunov",
            "bool",
            False,
            """lyapunov : bool
    Compute the largest exponent (and λ2) of every point over its recorded periods.  Without it
    only non-periodic points get exponents (needed to tell quasi-periodic from chaotic).""",
        ),
        SweepKeyword(
            "settle_periods",
            "int",
            SETTLE_PERIODS,
            """settle_periods : int
    Further periods for points not periodic after the transient (see
    :func:`~geardyn.analysis.steady.classify_batch`); default
    :data:`~geardyn.analysis.classify.SETTLE_PERIODS`.""",
        ),
        SweepKeyword(
            "engine",
            "SweepOptions | None",
            None,
            """engine : SweepOptions, optional
    Where and how the sweep runs (:class:`geardyn.sweep.SweepOptions`); where the points are
    independent, its ``chunk_points`` is the number of points per chunk (default
    :data:`geardyn.sweep.DEFAULT_CHUNK_POINTS`).""",
        ),
        SweepKeyword(
            "engine_kw",
            "Any",
            inspect.Parameter.empty,
            """**engine_kw
    Fields of :class:`~geardyn.sweep.SweepOptions` given one by one (``workers``, ``scheduler``,
    ``executor``, ``checkpoint``, ``resume``, ``progress``, ``chunk_points``); any other keyword
    is refused with :class:`TypeError`.""",
        ),
    )
}


def _document(doc: str, entries: Sequence[SweepKeyword]) -> str:
    """``doc`` with the entries of the shared keywords it does not document inserted before ``Returns``."""
    marker = "\n    Returns\n"
    missing = [k for k in entries if f"\n    {k.name} :" not in doc and f"\n    **{k.name}" not in doc]
    if not missing or marker not in doc:
        return doc
    head, tail = doc.split(marker, 1)
    block = "\n".join("    " + line if line else line for k in missing for line in k.doc.splitlines())
    return f"{head.rstrip()}\n{block}\n{marker}{tail}"


def sweep_function(caller: str, **defaults: Any) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator: a sweep whose shared keywords are declared by :data:`SWEEP_KEYWORDS`.

    The decorated function lists the shared keywords it takes (``state0``, ``options``,
    ``lyapunov``, ``settle_periods``, ``engine``) as keyword-only parameters without default; the
    decorator gives them their annotation, default and documentation, adds ``**engine_kw`` (the
    engine options given one by one) and passes the function one merged
    :class:`~geardyn.sweep.SweepOptions` as ``engine``.

    Parameters
    ----------
    caller : str
        The function's name, for the message of an unknown keyword.
    **defaults
        Defaults that differ from those of :data:`SWEEP_KEYWORDS` (e.g. ``options=BASIN_OPTIONS``);
        only shared keywords.

    Returns
    -------
    callable
        The decorator.

    Raises
    ------
    TypeError
        For a default of a keyword that is not shared.
    """
    unknown = set(defaults) - set(SWEEP_KEYWORDS)
    if unknown:
        raise TypeError(f"sweep_function: not a shared keyword: {sorted(unknown)}")

    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        sig = inspect.signature(fn)
        params, shared = [], []
        for p in sig.parameters.values():
            k = SWEEP_KEYWORDS.get(p.name)
            if k is not None and p.default is p.empty:
                p = p.replace(annotation=k.annotation, default=defaults.get(p.name, k.default))
                shared.append(k)
            params.append(p)
        params.append(inspect.Parameter("engine_kw", inspect.Parameter.VAR_KEYWORD, annotation="Any"))
        shared.append(SWEEP_KEYWORDS["engine_kw"])
        public = sig.replace(parameters=params)
        own = set(sig.parameters)

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            engine_kw = {k: kwargs.pop(k) for k in list(kwargs) if k not in own}
            bound = public.bind(*args, **kwargs)
            bound.apply_defaults()
            call = dict(bound.arguments)
            call.pop("engine_kw", None)
            call["engine"] = SweepOptions.merge(call["engine"], caller, **engine_kw)
            return fn(**call)

        wrapper.__signature__ = public  # type: ignore[attr-defined]
        wrapper.__doc__ = _document(fn.__doc__ or "", shared)
        return wrapper

    return decorate


def initial_state(model: GearModel, state0: Sequence[float] | np.ndarray) -> tuple[float, ...]:
    """The initial state of a sweep as a tuple of floats, checked.

    Parameters
    ----------
    model : System
        The base model (its ``state_dim`` is the length the state must have).
    state0 : sequence of float
        The initial state at θ = 0: the full state, or (u0, v0) of a system's reference element
        (:meth:`~geardyn.system.System.initial_state`).

    Returns
    -------
    tuple of float
        One entry per state component (picklable, for the chunks of the sweep engine).

    Raises
    ------
    ModelError
        If a component is not finite.
    ValueError
        If the state does not have ``model.state_dim`` components.
    """
    s0 = np.asarray(state0, dtype=float)
    if s0.shape == (2,) and model.state_dim != 2:  # (u0, v0) of a system's reference element
        s0 = model.initial_state(float(s0[0]), float(s0[1]))
    s0 = s0.reshape(model.state_dim)
    if not np.all(np.isfinite(s0)):
        raise ModelError("initial state (u0, v0): must be finite")
    return tuple(float(x) for x in s0)


def concat_rows(results: Sequence[Mapping[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """The rows of consecutive chunks joined into one array per key (in chunk order).

    Parameters
    ----------
    results : sequence of dict of ndarray
        The chunk results, all with the keys of the first.

    Returns
    -------
    dict of ndarray
    """
    return {k: np.concatenate([r[k] for r in results]) for k in results[0]}


class RowSink:
    """The rows of consecutive chunks written into preallocated arrays as the chunks finish.

    The sink of :func:`geardyn.sweep.run_chunks`: chunk ``k`` holds the rows ``offsets[k]`` …
    ``offsets[k] + len``; each variable's array (``total`` rows, the dtype and trailing shape of
    the first chunk that has it) is allocated when a chunk first brings it, and the chunk's rows
    are copied in, so that only the chunks in flight are ever held besides the output.  The
    arrays equal :func:`concat_rows` of the results in chunk order.

    Parameters
    ----------
    offsets : sequence of int
        First row of each chunk, in chunk order.
    total : int
        Rows of the whole sweep.

    Attributes
    ----------
    arrays : dict of ndarray
        The output, one array per variable.
    """

    def __init__(self, offsets: Sequence[int], total: int) -> None:
        self.offsets = [int(o) for o in offsets]
        self.total = int(total)
        self.arrays: dict[str, np.ndarray] = {}
        self._rows = 0

    def __call__(self, position: int, result: Mapping[str, np.ndarray]) -> None:
        start = self.offsets[position]
        n = None
        for k, v in result.items():
            v = np.asarray(v)
            a = self.arrays.get(k)
            if a is None:
                a = self.arrays[k] = np.empty((self.total,) + v.shape[1:], dtype=v.dtype)
            a[start : start + v.shape[0]] = v
            n = v.shape[0]
        self._rows += int(n or 0)

    def result(self) -> dict[str, np.ndarray]:
        """The output arrays, once every chunk has arrived.

        Raises
        ------
        SweepError
            If the chunks delivered do not add up to ``total`` rows.
        """
        if self._rows != self.total:
            from ..errors import SweepError

            raise SweepError(f"sweep: {self._rows} rows delivered for {self.total} points")
        return self.arrays


def run_slices(
    function: Callable[..., dict[str, np.ndarray]],
    args_of: Callable[[slice], tuple[Any, ...]],
    slices: Sequence[slice],
    engine: SweepOptions,
    description: str,
) -> dict[str, np.ndarray]:
    """Run ``function`` on consecutive slices of a grid (independent points) and join the rows.

    Parameters
    ----------
    function : callable
        The chunk function (module-level, so that workers can import it).
    args_of : callable
        Its positional arguments for one slice of the flat point index.
    slices : sequence of slice
        The chunks: consecutive slices of the grid's flat point index covering it
        (:func:`geardyn.sweep.chunk_slices` sizes them by cost).
    engine : SweepOptions
        Where and how the sweep runs.
    description : str
        Name of the sweep in progress reports.

    Returns
    -------
    dict of ndarray
        One row per grid point, in the grid's flat order: each chunk's rows are written there as
        the chunk finishes (:class:`RowSink`), so the sweep holds no per-chunk copies.

    Raises
    ------
    SweepError
        When the sweep cannot run (see :func:`geardyn.sweep.run_chunks`).
    """
    chunks = [Chunk(i, function, args_of(sl)) for i, sl in enumerate(slices)]
    sink = RowSink([sl.start or 0 for sl in slices], slices[-1].stop if slices else 0)  # each chunk's rows in place
    run_chunks(chunks, engine, description=description, sink=sink)
    return sink.result()


def result_dataset(
    data: Mapping[str, Any], coords: Mapping[str, Any], kind: str, model: GearModel, options: Any, **extra: Any
) -> xr.Dataset:
    """A sweep's Dataset: its variables, the standard attributes and the registry's metadata.

    Parameters
    ----------
    data : mapping
        Variables as ``name -> (dims, values)``.
    coords : mapping
        Coordinates.
    kind : str
        The result's ``geardyn_kind``.
    model : GearModel
        The base model (stored as JSON).
    options : IntegrationOptions
        The integration options (stored as JSON).
    **extra
        Further global attributes (:func:`geardyn.io.result_attrs`).

    Returns
    -------
    xarray.Dataset
        With ``units``/``long_name`` (and flags) of every variable from :data:`geardyn.io.VARIABLES`.
    """
    ds = xr.Dataset(dict(data), coords=dict(coords), attrs=result_attrs(kind, model, options, **extra))
    return annotate(ds)


def grid_variables(
    rows: Mapping[str, np.ndarray], keys: Sequence[str], dims: tuple[str, ...], shape: tuple[int, ...], model: Any
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The variables of a sweep's Dataset from its rows: each of ``keys`` that ``rows`` holds, reshaped onto ``dims``.

    Parameters
    ----------
    rows : mapping of ndarray
        One row per grid point in the grid's flat order (a system's per-element variables (P, elements)).
    keys : sequence of str
        The variables kept, in this order.
    dims, shape : tuple
        The grid's dimensions and their sizes.
    model : System
        The base model: names the ``element`` coordinate.

    Returns
    -------
    data, coords : dict
        ``name -> (dims, values)``, a per-element variable over ``dims + ("element",)``; and the ``element``
        coordinate when there is such a variable.
    """
    data: dict[str, Any] = {}
    coords: dict[str, Any] = {}
    for k in keys:
        if k in rows:
            v = rows[k]
            data[k] = (dims + ("element",) if v.ndim > 1 else dims, v.reshape(shape + v.shape[1:]))
            if v.ndim > 1:
                coords["element"] = element_names(model, v.shape[-1])
    return data, coords
