"""Shared figure helpers: what a plot function returns, figures without pyplot, axis labels, saving.

Every plot function has the form ``fn(ds, ax=None, ...) -> PlotArtists``: with ``ax`` it draws into
the given Axes (a sequence of Axes for figures of several panels, or one Axes for the main panel
only); without it, it creates a :class:`matplotlib.figure.Figure` of its own.  Such a figure is not
managed by :mod:`matplotlib.pyplot` and carries an Agg canvas, so it can be saved as PNG on any
machine without switching the backend (no ``matplotlib.use`` anywhere in geardyn).
"""

from __future__ import annotations

import io as _io
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import xarray as xr
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..errors import PlotError

__all__ = ["DPI", "PlotArtists", "label", "new_figure", "panels", "save"]

#: Resolution of saved PNG figures.
DPI = 120


@dataclass
class PlotArtists:
    """What a plot function drew: its figure, its Axes and the artists it added.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
        The figure drawn into (the caller's when ``ax`` was given).
    axes : list of matplotlib.axes.Axes
        The Axes drawn into, main panel first.
    artists : list of matplotlib.artist.Artist
        The lines, collections, patches and texts the function added (not the axis labels).
    """

    figure: Figure
    axes: list[Axes]
    artists: list[Artist] = field(default_factory=list)

    def savefig(self, path: str | Path, **kwargs: Any) -> Path:
        """Save the figure (see :func:`save`; the figure stays open)."""
        return save(self, path, close=False, **kwargs)

    def _repr_png_(self) -> bytes:  # shown inline by Jupyter
        buf = _io.BytesIO()
        self.figure.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
        return buf.getvalue()


def new_figure(**kwargs: Any) -> Figure:
    """A figure outside pyplot with an Agg canvas (``kwargs`` as for :class:`~matplotlib.figure.Figure`)."""
    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


def panels(ax: Any, n: int, figsize: tuple[float, float], **subplots: Any) -> tuple[Figure, list[Axes | None], bool]:
    """The Axes of a figure of ``n`` panels.

    Parameters
    ----------
    ax : None, Axes or sequence of Axes
        ``None``: a new figure of size ``figsize`` with ``n`` panels laid out by ``subplots``
        (keywords of :meth:`matplotlib.figure.Figure.subplots`, default one column); one Axes: the
        main panel only (the others are ``None`` and not drawn); ``n`` Axes: one per panel.
    n : int
        Number of panels of the full figure.
    figsize : (float, float)
        Size of a new figure in inches.

    Returns
    -------
    figure, list of Axes or None, bool
        The figure, the ``n`` panels (``None`` where not drawn) and whether the figure is new.

    Raises
    ------
    PlotError
        If a sequence of Axes of another length than ``n`` is given.
    """
    if ax is None:
        fig = new_figure(figsize=figsize)
        kw = {"nrows": n, "ncols": 1, "squeeze": False}
        kw.update(subplots)
        axes = list(np.asarray(fig.subplots(**kw)).ravel())
        return fig, axes, True
    if isinstance(ax, Axes):
        return ax.figure, [ax] + [None] * (n - 1), False
    axes = list(np.asarray(ax, dtype=object).ravel())
    if len(axes) != n or not all(isinstance(a, Axes) for a in axes):
        raise PlotError(f"ax: this figure has {n} panels; give one Axes (main panel) or {n} Axes, got {len(axes)}")
    return axes[0].figure, axes, False


def one_axes(ax: Any, figsize: tuple[float, float]) -> tuple[Figure, Axes, bool]:
    """(figure, Axes, new) of a one-panel figure: ``ax`` itself, or a new figure of ``figsize``."""
    fig, axes, new = panels(ax, 1, figsize)
    return fig, axes[0], new  # type: ignore[return-value]


def snapshot(axes: Sequence[Axes | None]) -> dict[int, set[Artist]]:
    """The children of each Axes now, to find later what a function added (see :func:`result`)."""
    return {id(a): set(a.get_children()) for a in axes if a is not None}


def result(fig: Figure, axes: Sequence[Axes | None], before: dict[int, set[Artist]]) -> PlotArtists:
    """The :class:`PlotArtists` of what was drawn into ``axes`` since the :func:`snapshot` ``before``."""
    drawn = [a for a in axes if a is not None]
    artists = [c for a in drawn for c in a.get_children() if c not in before.get(id(a), set())]
    return PlotArtists(fig, drawn, artists)


def label(da: xr.DataArray, fallback: str | None = None) -> str:
    """Axis label '<long_name> [units]' from a DataArray's attributes (no unit shown for "1")."""
    name = da.attrs.get("long_name", fallback or str(da.name))
    units = da.attrs.get("units")
    return f"{name} [{units}]" if units and units != "1" else name


def save(fig: Any, path: str | Path, *, close: bool = True, dpi: int = DPI) -> Path:
    """Save a figure (a :class:`~matplotlib.figure.Figure` or :class:`PlotArtists`) and return its path.

    The format follows the suffix of ``path`` (PNG for ``.png``).  A figure managed by pyplot is
    closed there when ``close`` is true; geardyn's own figures need no closing.
    """
    figure = fig.figure if isinstance(fig, PlotArtists) else fig
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=dpi, bbox_inches="tight")
    if close and getattr(figure.canvas, "manager", None) is not None and "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close(figure)
    return path
