"""Shared figure helpers: what a plot function returns, figures without pyplot, axis labels, saving.

Every plot function has the form ``fn(ds, ax=None, ...) -> PlotArtists``: with ``ax`` it draws into
the given Axes (a sequence of Axes for figures of several panels, or one Axes for the main panel
only); without it, it creates a :class:`matplotlib.figure.Figure` of its own.  Such a figure is not
managed by :mod:`matplotlib.pyplot` and carries an Agg canvas, so it can be saved as PNG on any
machine without switching the backend (no ``matplotlib.use`` anywhere in geardyn).
"""

from __future__ import annotations

import functools
import inspect
import io as _io
import math
import re
import sys
import textwrap
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .._docfill import RESULT, parameters
from ..errors import GeardynError, PlotError
from ..params import FAMILIES, LISTING_ORDER, canonical_param, slot
from .mesh_names import MESH_VARIABLES, json_attr, json_list, mesh_labels, of_mesh, reference_mesh, system_info

__all__ = [
    "DPI",
    "IMAGE_CELLS",
    "MESH_VARIABLES",
    "NAN_COLOR",
    "PlotArtists",
    "cells",
    "contact_lines",
    "json_attr",
    "json_list",
    "label",
    "log_stems",
    "mesh_labels",
    "model_of",
    "new_figure",
    "of_mesh",
    "panels",
    "parameter_text",
    "place_labels",
    "plot_function",
    "reference_mesh",
    "save",
    "set_title",
    "symbol",
]

#: Resolution of saved PNG figures.
DPI = 120
#: Cells of a grid from which :func:`cells` draws an image instead of a mesh of quadrilaterals (when
#: both axes are evenly spaced): the same cells, in a third of the time and memory at 10⁶ cells.
IMAGE_CELLS = 40_000
#: Colour (with a hatch) of the cells of a map without a value (NaN), distinct from every colour scale.
NAN_COLOR = "#8c8c8c"
#: Hatch of those cells.
NAN_HATCH = "///"
#: Largest number of components of a spectrum drawn as stems (more: one line, :func:`log_stems`).
STEM_MAX = 80
#: Legend outside the axes, right of the curves it names (a time history's).
OUTSIDE_RIGHT = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
#: Offsets (points) tried in turn for a label beside its anchor, the first free of other labels is taken.
LABEL_OFFSETS = tuple((dx, dy) for dy in (0, 11, -11, 22, -22, 33, -33, 44, -44) for dx in (5, -5))


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
        """Save the figure (see :func:`save`; the figure stays open).

        Parameters
        ----------
        path : str or Path
            Output file; the format follows its suffix.
        **kwargs
            Keywords of :func:`save` (``dpi``).

        Returns
        -------
        Path
        """
        return save(self, path, close=False, **kwargs)

    def _repr_png_(self) -> bytes:  # shown inline by Jupyter
        buf = _io.BytesIO()
        self.figure.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
        return buf.getvalue()


def new_figure(**kwargs: Any) -> Figure:
    """A figure outside pyplot with an Agg canvas.

    Parameters
    ----------
    **kwargs
        Keywords of :class:`matplotlib.figure.Figure` (``figsize``, ``dpi``, ...), which refuses
        unknown ones.

    Returns
    -------
    matplotlib.figure.Figure
    """
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
    **subplots
        Keywords of :meth:`matplotlib.figure.Figure.subplots` for a new figure (``nrows``,
        ``ncols``, ``sharex``, ...; default ``n`` rows in one column); not used when ``ax`` is given.

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
        return fig, list(fig.subplots(**{"nrows": n, "ncols": 1, "squeeze": False, **subplots}).ravel()), True
    if isinstance(ax, Axes):
        return ax.figure, [ax] + [None] * (n - 1), False
    axes = list(np.asarray(ax, dtype=object).ravel())
    if len(axes) != n or not all(isinstance(a, Axes) for a in axes):
        raise PlotError(f"ax: this figure has {n} panels; give one Axes (main panel) or {n} Axes, got {len(axes)}")
    return axes[0].figure, axes, False


#: Non-dimensional displacements (u = u_n / b_c): their axes carry the unit b_c.
IN_B_C = tuple(
    (
        "u poincare_u amplitude rms mean u_min u_max amplitude_up "
        "amplitude_down delta element_u_min element_u_max element_mean element_rms"
    ).split()
)
_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def subscripts(text: str) -> str:
    """``ξ_1`` → ``ξ₁``: an index written after an underscore as subscript digits (a figure shows no literal
    underscore).

    Parameters
    ----------
    text : str
        A label.

    Returns
    -------
    str
    """
    return re.sub(r"_\{?(\d+)\}?", lambda m: m.group(1).translate(_SUB), text)


def label(da: xr.DataArray, fallback: str | None = None) -> str:
    """Axis label '<long_name> [units]' from a DataArray's attributes (no unit shown for "1").

    Parameters
    ----------
    da : xarray.DataArray
        The variable or coordinate on the axis.
    fallback : str, optional
        The name shown when it has no ``long_name`` (default its own name).

    Returns
    -------
    str
    """
    name = subscripts(str(da.attrs.get("long_name", fallback or str(da.name))))
    units = da.attrs.get("units")
    if units == "1" and str(da.name) in IN_B_C:  # a displacement of the non-dimensional model: in units of b_c
        return f"{name} [b_c]"
    return f"{name} [{units}]" if units and units != "1" else name


def save(fig: Any, path: str | Path, *, close: bool = True, dpi: int = DPI) -> Path:
    """Save a figure (a :class:`~matplotlib.figure.Figure` or :class:`PlotArtists`) atomically and return its path.

    The format follows the suffix of ``path`` (PNG for ``.png``).  A figure managed by pyplot is
    closed there when ``close`` is true; geardyn's own figures need no closing.

    Parameters
    ----------
    fig : Figure or PlotArtists
        What to save.
    path : str or Path
        Output file (its directory is created if missing).
    close : bool
        Close a pyplot-managed figure after saving.
    dpi : int
        Resolution (default :data:`DPI`).

    Returns
    -------
    Path
        ``path``.
    """
    from ..atomic import atomic_write_bytes

    figure = fig.figure if isinstance(fig, PlotArtists) else fig
    path = Path(path)
    buf = _io.BytesIO()  # drawn in memory, then written atomically: no truncated figure on a full disk
    figure.savefig(buf, dpi=dpi, bbox_inches="tight", format=path.suffix.lstrip(".").lower() or "png")
    atomic_write_bytes(path, buf.getbuffer())
    if close and getattr(figure.canvas, "manager", None) is not None and "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close(figure)
    return path


# ------------------------------------------------------------------------------------ parameters
@parameters(RESULT)
def model_of(ds: xr.Dataset) -> dict:
    """The model parameters stored with a result (its ``model`` attribute), empty if it has none.

    Returns
    -------
    dict
        ``GearModel.to_dict()`` of the result's model, or ``{}``.
    """
    return json_attr(ds, "model")


def symbol(name: str) -> str:
    """The symbol of a parameter for labels (``"xi0"`` → ``"ξ0"``, ``"kappa2"`` → ``"κ2"``); other names unchanged.

    Parameters
    ----------
    name : str
        A parameter name of the registry (:mod:`geardyn.params`), or any other name.

    Returns
    -------
    str
    """
    try:
        fam, idx = slot(name)
    except GeardynError:
        return str(name)
    sym = FAMILIES[fam].symbol
    return sym.replace("_{k}", "{k}").replace("{k}", str(idx + 1)) if idx is not None else sym


def _canonical(name: str) -> str:
    try:
        return canonical_param(name)
    except GeardynError:
        return str(name)


def parameter_text(ds: xr.Dataset, exclude: Iterable[str] = ()) -> str:
    """The model parameters of a result as ``"ω = 1.2, ξ0 = 0.1, ξ1 = 0.05, κ1 = 0.2, …"`` (phases only when
    nonzero), leaving out the parameters in ``exclude`` (swept or drawn on an axis); ``""`` without a model.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.
    exclude : iterable of str
        Parameter names (any alias) left out.

    Returns
    -------
    str
    """
    m = model_of(ds)
    skip = {_canonical(n) for n in exclude}
    parts = []
    for fam in LISTING_ORDER:
        value = m.get(fam)
        if value is None:
            continue
        f = FAMILIES[fam]
        if f.series:
            items = [(f"{fam}{k + 1}", v) for k, v in enumerate(value) if f.amplitude is None or v != 0]
        else:
            items = [(fam, value)]
        parts += [f"{symbol(n)} = {float(v):.4g}" for n, v in items if n not in skip]
    return ", ".join(parts)


def equal_steps(x: np.ndarray) -> bool:
    """Whether ``x`` holds at least two values, evenly spaced (steps equal to 1e-6 relative)."""
    d = np.diff(x)
    return x.size >= 2 and bool(np.allclose(d, d[0], rtol=1e-6, atol=0.0))


def cells(
    ax: Axes,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    *,
    cmap: Any = None,
    norm: Any = None,
    vmin: float | None = None,
    vmax: float | None = None,
) -> Any:
    """Draw ``z[j, i]`` as cells centred on ``(x[i], y[j])`` (``pcolormesh(..., shading="nearest")``).

    A grid of at least :data:`IMAGE_CELLS` cells on evenly spaced axes is drawn as an image of the same
    cells (``imshow``, nearest neighbour, the same extent); a mesh of quadrilaterals otherwise.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    x, y : ndarray
        Cell centres along the columns and the rows.
    z : ndarray (y.size, x.size)
        The values.
    cmap, norm, vmin, vmax
        The colour scale, as for ``imshow`` and ``pcolormesh``.

    Returns
    -------
    matplotlib.image.AxesImage or matplotlib.collections.QuadMesh
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    kw = {"cmap": cmap, "norm": norm, "vmin": vmin, "vmax": vmax}

    if z.size >= IMAGE_CELLS and equal_steps(x) and equal_steps(y) and x[1] > x[0] and y[1] > y[0]:
        dx, dy = (x[-1] - x[0]) / (x.size - 1), (y[-1] - y[0]) / (y.size - 1)
        return ax.imshow(
            z,
            origin="lower",
            aspect="auto",
            interpolation="nearest",
            extent=(x[0] - dx / 2, x[-1] + dx / 2, y[0] - dy / 2, y[-1] + dy / 2),
            **kw,
        )
    return ax.pcolormesh(x, y, z, shading="nearest", **kw)


def set_title(
    ax: Axes, text: str, ds: xr.Dataset, exclude: Iterable[str] = (), *, fontsize: float | str | None = None
) -> Any:
    """Title ``text`` with the result's parameters (:func:`parameter_text`) on a second line.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The Axes titled.
    text : str
        The first line.
    ds : xarray.Dataset
        The result whose parameters form the second line.
    exclude : iterable of str
        Parameters left out of the second line (swept or drawn on an axis).
    fontsize : float or str, optional
        Font size of the title; default matplotlib's ``axes.titlesize``.

    Returns
    -------
    matplotlib.text.Text
        The title.
    """
    params = parameter_text(ds, exclude)
    info = system_info(ds)
    if info:  # a system's figure says which mesh the reference variables are
        where = f"{info.get('title') or 'system'}: reference mesh '{info.get('reference_mesh')}'"
        params = f"{where}; {params}" if params else where
    size = {} if fontsize is None else {"fontsize": fontsize}
    return ax.set_title(f"{text}\n{params}" if params else text, **size)


def rpm_per_omega(ds: xr.Dataset) -> float | None:
    """Pinion speed (rpm) per unit ω of the gear pair stored with a result, or ``None`` without a physical pair."""
    from ..geometry.scales import PhysicalScales

    info = system_info(ds)
    if info:  # a system: its reference pinion's teeth and ω_n
        teeth, wn = info.get("teeth"), info.get("omega_n")
        return float(wn) * 60.0 / (2.0 * np.pi * float(teeth)) if teeth and wn else None
    try:
        sc = PhysicalScales.from_attrs(ds.attrs)
    except (GeardynError, ValueError, KeyError, TypeError):
        return None
    if sc is None or getattr(sc, "nondimensional", False):
        return None
    return float(sc.rpm_from_omega(1.0))


def rpm_axis(ax: Axes, ds: xr.Dataset, param: str) -> Any:
    """A top axis in pinion speed (rpm) over an ω axis, for a result with a physical gear pair.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The Axes whose x axis is ``param``.
    ds : xarray.Dataset
        The result (its ``physical_scales`` attribute gives rpm per unit ω).
    param : str
        The parameter on the x axis; nothing is drawn unless it is ``omega``.

    Returns
    -------
    matplotlib.axes.Axes or None
        The secondary axis, or ``None`` when none is drawn.
    """
    scale = rpm_per_omega(ds) if param == "omega" else None
    if not scale:
        return None
    sec = ax.secondary_xaxis("top", functions=(lambda w: w * scale, lambda r: r / scale))
    sec.set_xlabel(f"{of_mesh('pinion speed', ds)} [rpm]", fontsize=8)
    sec.tick_params(labelsize=8)
    return sec


def speed_text(ds: xr.Dataset) -> str:
    """``" (2400 rpm)"`` for a result at one ω with a physical gear pair, else ``""``."""
    scale = rpm_per_omega(ds)
    omega = model_of(ds).get("omega")
    return f" ({float(omega) * scale:.0f} rpm)" if scale and isinstance(omega, (int, float)) else ""


# ------------------------------------------------------------------------------------ drawing
def contact_lines(
    ax: Axes,
    ds: xr.Dataset,
    param: str | None = None,
    x: np.ndarray | None = None,
    *,
    lw: float = 0.8,
    ls: str | None = None,
) -> list[Artist]:
    """The contact boundaries u = ±D of a figure over ``x`` in grey: horizontal lines at the model's D, or, when the
    swept parameter ``param`` is D itself, the lines u = ±D following the plotted D (nothing where D = 0).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    ds : xarray.Dataset
        The result (its model gives D).
    param : str, optional
        The parameter on the horizontal axis.
    x : ndarray, optional
        Its plotted values (used when ``param`` is D).
    lw : float
        Line width.
    ls : str, optional
        Line style; default matplotlib's ``lines.linestyle``.

    Returns
    -------
    list of Artist
        The lines drawn (``gid`` ``"contact"``).
    """
    style = {"color": "0.6", "lw": lw, **({} if ls is None else {"ls": ls})}
    if param is not None and x is not None and _canonical(param) == "D":
        d = np.sort(np.asarray(x, dtype=float))
        return [ax.plot(d, s * d, gid="contact", **style)[0] for s in (1, -1)]
    D = model_of(ds).get("D")
    if D is None or not float(D) > 0:
        return []
    return [ax.axhline(s * float(D), gid="contact", **style) for s in (1, -1)]


def log_stems(ax: Axes, x: np.ndarray, amp: np.ndarray) -> None:
    """An amplitude spectrum on a log scale (the mean term left out): stems with a dot on each from the floor of the
    axis for a line spectrum, one line for a dense (broadband) one.

    The floor is the decade under that of the smallest amplitude within six decades of the peak (at lowest the
    decade six decades under the peak); components below it (the rounding between the harmonics of a periodic
    response) are not drawn.  A spectrum with more
    than :data:`STEM_MAX` components above the floor is drawn as a line: stems that close together would fill the
    axis down to the floor like bars.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw.
    x : ndarray
        Frequencies, the mean term first.
    amp : ndarray
        Amplitudes at ``x``.
    """
    ax.set_yscale("log")
    f, a = np.asarray(x[1:], dtype=float), np.asarray(amp[1:], dtype=float)
    ok = np.isfinite(a) & (a > 0)
    top = float(np.max(a[ok])) if np.any(ok) else 1.0
    big = a[ok & (a >= top * 1e-6)]
    lowest = 10.0 ** (math.floor(math.log10(float(np.min(big)))) - 1) if big.size else top * 1e-6
    floor = max(10.0 ** math.floor(math.log10(top * 1e-6)), lowest, 1e-300)
    shown = ok & (a >= floor)
    if int(np.count_nonzero(shown)) > STEM_MAX:
        ax.plot(f, np.where(ok, np.maximum(a, floor), np.nan), color="C0", lw=0.8, gid="spectrum")
    else:
        ax.vlines(f[shown], floor, a[shown], color="C0", lw=1.0, gid="spectrum")
        ax.plot(f[shown], a[shown], "o", color="C0", ms=3, gid="spectrum-peaks")
    ax.set_ylim(floor, top * 2)


def branch_lines(
    ax: Axes,
    x: np.ndarray,
    ys: list[np.ndarray],
    stable: np.ndarray,
    name: str,
    seen: set[str],
    widths=(1.7, 1.2),
    **style,
) -> None:
    """A branch of periodic solutions: stable runs solid, unstable dashed (runs overlap by one point so the line is
    unbroken), labelled ``name`` + "stable" / "unstable" once per Axes (``seen`` holds the labels given)."""
    i0 = 0
    for i in range(1, stable.size + 1):
        if i < stable.size and stable[i] == stable[i0]:
            continue
        st = bool(stable[i0])
        j = slice(i0, min(i, x.size - 1) + 1)
        lab = name + ("stable" if st else "unstable")
        for y in ys:
            kw = {"lw": widths[0] if st else widths[1], **style}
            ax.plot(x[j], y[j], ls="-" if st else "--", label=None if lab in seen else lab, **kw)
            seen.add(lab)
        i0 = i


def bifurcation_marker(ax: Axes, x: float, y: float, marker: str, color: str, name: str, seen: set[str]) -> None:
    """A located bifurcation as an open marker at (x, y), named ``name`` in the legend once per Axes (``seen`` holds
    the names given)."""
    ax.plot(
        [x],
        [y],
        ls="none",
        marker=marker,
        color=color,
        ms=7,
        mfc="white",
        mew=1.8,
        zorder=5,
        label=None if name in seen else name,
    )
    seen.add(name)


def spread(y: np.ndarray, gap: float, top: float) -> np.ndarray:
    """Positions as close to ``y`` (ascending) as possible, at least ``gap`` apart, within [0, top] (labels moved
    apart along an axis)."""
    out = np.array(y, dtype=float)
    for i in range(1, len(out)):
        out[i] = max(out[i], out[i - 1] + gap)
    if len(out) and out[-1] > top:
        out[-1] = top
        for i in range(len(out) - 2, -1, -1):
            out[i] = min(out[i], out[i + 1] - gap)
    return out


def cell_edges(x: np.ndarray, half: float = 0.005) -> np.ndarray:
    """Edges of cells centred on the ascending values ``x``: midway between neighbours, the end cells as wide as
    their neighbours' (``half`` either side of a single value)."""
    if x.size < 2:
        return np.array([x[0] - half, x[0] + half])
    return np.concatenate([[x[0] - (x[1] - x[0]) / 2], 0.5 * (x[1:] + x[:-1]), [x[-1] + (x[-1] - x[-2]) / 2]])


def place_labels(
    ax: Axes,
    labels: Sequence[tuple[float, float, str, str]],
    avoid: Sequence[Artist] = (),
) -> list[Artist]:
    """Labels (font size 7) beside anchor points, each at the first of :data:`LABEL_OFFSETS` where its box overlaps
    neither an earlier label nor an artist of ``avoid`` (arrows, say).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw (its data limits should be final).
    labels : sequence of (x, y, text, colour)
        Anchor in data coordinates, text and colour of each label.
    avoid : sequence of Artist
        Artists the labels must not cover.

    Returns
    -------
    list of Artist
        The labels.
    """
    ax.get_xlim(), ax.get_ylim()  # settle the autoscaled limits before measuring
    renderer = ax.figure._get_renderer()  # the canvas's, or the one a saved figure would use
    taken = [a.get_window_extent(renderer) for a in avoid]
    out = []
    for x, y, s, colour in labels:
        for dx, dy in LABEL_OFFSETS:
            t = ax.annotate(
                s,
                (x, y),
                xytext=(dx, dy),
                textcoords="offset points",
                color=colour,
                ha="left" if dx > 0 else "right",
                va="center",
                fontsize=7,
            )
            box = t.get_window_extent(renderer)
            if not any(box.overlaps(b) for b in taken) or (dx, dy) == LABEL_OFFSETS[-1]:
                break
            t.remove()
        taken.append(box)
        out.append(t)
    return out


# ------------------------------------------------------------------------------- plot functions
_RETURNS = "Returns\n-------\nPlotArtists\n    The figure, its Axes and the artists drawn.\n"
#: Documentation of ``ax`` for a one-panel figure.
ONE_AXES = "ax : matplotlib.axes.Axes, optional\n    Where to draw; a new figure if omitted."


def plot_function(
    kind: str,
    figsize: Any,
    *,
    n: Any = 1,
    subplots: Any = None,
    ax_doc: str = ONE_AXES,
    params: str = "",
    tight: bool = False,
    adjust: dict | None = None,
) -> Callable[[Callable[..., Any]], Callable[..., PlotArtists]]:
    """Make ``fn(ds, ..., ax)`` drawing into given Axes a plot function ``fn(ds, ..., ax=None) -> PlotArtists``.

    The wrapper finds or creates the Axes (:func:`panels`), records what ``fn`` adds and completes the
    docstring of ``fn`` (its summary) with the sections every plot function shares.

    Parameters
    ----------
    kind : str
        The kind of result drawn (for the docstring).
    figsize : (float, float) or callable
        Size of a new figure, or ``figsize(ds)``.
    n : int or callable
        Number of panels, or ``n(ds)``; ``fn`` receives one Axes when ``n`` is 1, else the list of panels
        (``None`` where not drawn; always the list when ``n`` is callable, even of one panel).
    subplots : dict or callable, optional
        Keywords of :meth:`~matplotlib.figure.Figure.subplots` for a new figure, or ``subplots(ds)``.
    ax_doc : str
        Documentation of ``ax`` (numpydoc, dedented; default :data:`ONE_AXES`).
    params : str
        Documentation of the parameters between ``ds`` and ``ax`` (numpydoc, dedented).
    tight : bool
        Apply :meth:`~matplotlib.figure.Figure.tight_layout` to a new figure.
    adjust : dict, optional
        Keywords of :meth:`~matplotlib.figure.Figure.subplots_adjust` applied to a new figure before drawing.

    Returns
    -------
    callable
        The decorator.
    """

    def wrap(fn: Callable[..., Any]) -> Callable[..., PlotArtists]:
        sig = inspect.signature(fn)

        @functools.wraps(fn)
        def plot(ds: xr.Dataset, *args: Any, **kwargs: Any) -> PlotArtists:
            ds = mesh_labels(ds)  # a system's labels name its reference mesh
            bound = sig.bind(ds, *args, **kwargs)
            bound.apply_defaults()

            def of_ds(value: Any) -> Any:  # a figure property, or a function of the Dataset giving it
                return value(ds) if callable(value) else value

            count = of_ds(n)
            fig, axes, new = panels(bound.arguments["ax"], count, of_ds(figsize), **(of_ds(subplots) or {}))
            if new and adjust:
                fig.subplots_adjust(**adjust)
            drawn = [a for a in axes if a is not None]
            before = [set(a.get_children()) for a in drawn]  # to return what fn adds
            bound.arguments["ax"] = axes if callable(n) or count > 1 else axes[0]
            fn(*bound.args, **bound.kwargs)
            if new and tight:
                fig.tight_layout()
            return PlotArtists(fig, drawn, [c for a, b in zip(drawn, before) for c in a.get_children() if c not in b])

        sections = ["Parameters", "----------", "ds : xarray.Dataset", f"    A ``{kind}`` result."]
        sections += [textwrap.dedent(t).strip("\n") for t in (params, ax_doc) if t]
        plot.__doc__ = inspect.cleandoc(fn.__doc__ or "") + "\n\n" + "\n".join(sections) + "\n\n" + _RETURNS
        return plot

    return wrap
