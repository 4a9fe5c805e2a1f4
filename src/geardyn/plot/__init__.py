"""Matplotlib figures drawn from result Datasets only (no numerics here).

Every plot function has the form ``fn(ds, ax=None, ...) -> PlotArtists`` (see
:mod:`geardyn.plot.common`); :mod:`geardyn.plot.registry` lists the figures of each kind of result
and :func:`save_figures` draws them into a directory — the one entry point of the commands,
``geardyn plot``, the ``ds.geardyn`` accessor and the report.  No backend is chosen or switched:
figures to files are drawn on their own Agg canvas, outside pyplot.
"""

from __future__ import annotations

from ..errors import PlotError
from .common import PlotArtists
from .registry import FIGURES, PHYSICAL_FIGURES, FigureSpec, draw, figures_for, register, save_figures

__all__ = [
    "FIGURES",
    "PHYSICAL_FIGURES",
    "FigureSpec",
    "PlotArtists",
    "PlotError",
    "PlotUnavailable",
    "draw",
    "figures_for",
    "register",
    "save_figures",
]

#: Former name of :class:`geardyn.errors.PlotError` (a Dataset geardyn cannot draw).
PlotUnavailable = PlotError
