"""Matplotlib figures drawn from result Datasets only (no numerics here).

:func:`save_figures` redraws every figure of a saved result, choosing the plot module by the
Dataset's ``geardyn_kind`` attribute (:data:`KIND_MODULES`), and adds the physical-unit figures of
:mod:`geardyn.plot.physical` when the result carries physical variables.  Importing this package
does not import matplotlib; the plot modules do.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

from ..errors import PlotError

__all__ = ["KIND_MODULES", "PlotUnavailable", "plot_module", "save_figures"]

#: Plot module (``geardyn.plot.<module>``) of each kind of result.  Kinds not listed use the
#: module of their own name.
KIND_MODULES: dict[str, str] = {
    "simulate": "simulate",
    "lyapunov": "lyapunov",
    "bifurcation": "bifurcation",
    "response": "response",
    "map": "maps",
    "basins": "basins",
    "orbit": "periodic",
    "continuation": "periodic",
    "stability_boundary": "periodic",
    "mathieu_boundary": "periodic",
    "stability_comparison": "periodic",
    "formula_fit": "reproduce",
    "search": "reproduce",
}


class PlotUnavailable(PlotError):
    """A Dataset that geardyn cannot draw (not a geardyn result, or no plot module for its kind)."""


def plot_module(kind: str) -> Any:
    """The plot module for results of ``kind``; raises :class:`PlotUnavailable` if there is none."""
    name = KIND_MODULES.get(kind, kind)
    full = f"{__name__}.{name}"
    try:
        return importlib.import_module(full)
    except ModuleNotFoundError as e:
        if e.name != full:
            raise
        raise PlotUnavailable(f"no figures for results of kind {kind!r}: plot module {full} is not available") from None


def _drawer(module: Any, kind: str):
    for name in (f"save_{kind}", "save_all"):
        fn = getattr(module, name, None)
        if callable(fn):
            return fn
    raise PlotUnavailable(f"no figures for results of kind {kind!r}: {module.__name__} has no save_{kind} or save_all")


def save_figures(ds: Any, directory: str | Path) -> list[Path]:
    """Draw every figure of a result Dataset into ``directory`` (PNG) and return their paths.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result (its ``geardyn_kind`` attribute selects the figures).
    directory : str or Path
        Where the PNG files go (created if needed).

    Raises
    ------
    PlotUnavailable
        If ``ds`` is not a geardyn result or no plot module exists for its kind.
    """
    kind = ds.attrs.get("geardyn_kind") if hasattr(ds, "attrs") else None
    if not kind:
        raise PlotUnavailable("not a geardyn result: the Dataset has no 'geardyn_kind' attribute")
    fn = _drawer(plot_module(str(kind)), str(kind))
    paths = [Path(p) for p in fn(ds, directory)]
    from .physical import save_physical

    return paths + save_physical(ds, directory)
