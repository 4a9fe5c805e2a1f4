"""The figure registry: which figures each kind of result has, and one function that draws them.

Every way geardyn draws a result — the commands with ``--out``, ``geardyn plot FILE.nc``, the
``ds.geardyn.plot()`` accessor and the reproduction report — goes through :func:`save_figures`, so a
saved file redraws exactly the figures its command drew.  A figure is a :class:`FigureSpec`: a
file stem, a plot function ``fn(ds, ax=None, **kwargs) -> PlotArtists`` and a condition on the
Dataset.  :data:`FIGURES` lists them by ``geardyn_kind``; :data:`PHYSICAL_FIGURES` apply to any kind
that carries physical variables.  Context a figure needs beyond the main result (the brute-force
sweep under a continuation) is attached to the Dataset (:func:`geardyn.io.attach`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import xarray as xr

from .._docfill import RESULT, attributes, parameters
from ..errors import PlotError
from . import (
    basins,
    bifurcation,
    engineering,
    gearbox,
    lyapunov,
    maps,
    modes,
    periodic,
    physical,
    rattle,
    reproduce,
    response,
    runup,
    simulate,
    systems,
    tooth,
)
from .common import DPI, json_attr, save
from .hb import hb_figure

__all__ = ["FIGURES", "PHYSICAL_FIGURES", "FigureSpec", "draw", "figures_for", "register", "save_figures"]


def _always(ds: xr.Dataset) -> bool:
    """Every result has the figure (the default condition of a :class:`FigureSpec`)."""
    return True


@dataclass(frozen=True)
@attributes
class FigureSpec:
    """One figure of a kind of result: what to call its file, how to draw it and when a result has it."""

    #: File name without suffix: ``"time_history"`` gives ``time_history.png``.
    stem: str
    #: ``draw(ds, ax=None, **kwargs) -> PlotArtists``.
    draw: Callable[..., Any]
    #: ``when(ds) -> bool``: whether the Dataset has this figure (default: always).
    when: Callable[[xr.Dataset], bool] = _always
    #: Further keyword arguments of ``draw``.
    kwargs: Mapping[str, Any] = field(default_factory=dict)

    def __call__(self, ds: xr.Dataset, ax: Any = None) -> Any:
        """Draw the figure of ``ds`` (into ``ax`` if given); returns the plot function's artists."""
        return self.draw(ds, ax=ax, **dict(self.kwargs))


_STABILITY = (FigureSpec("stability_boundary", periodic.stability_figure),)

#: The figures of each kind of result, in the order they are drawn.
FIGURES: dict[str, tuple[FigureSpec, ...]] = {
    "simulate": (
        FigureSpec("time_history", simulate.time_history),
        FigureSpec("phase_portrait", simulate.phase_portrait),
        FigureSpec("spectrum", simulate.spectrum),
    ),
    "lyapunov": (FigureSpec("lyapunov", lyapunov.convergence),),
    "bifurcation": (FigureSpec("bifurcation", bifurcation.diagram),),
    "response": (FigureSpec("response", response.response), FigureSpec("response_bifurcation", bifurcation.diagram)),
    "map": (
        FigureSpec("map_motion", maps.motion_map),
        FigureSpec("map_impact", maps.impact_map),
        FigureSpec("map_amplitude", maps.continuous_map, kwargs={"var": "amplitude"}),
        FigureSpec("map_lle", maps.continuous_map, when=bifurcation._has_lle, kwargs={"var": "lle"}),
    ),
    "basins": (FigureSpec("basins", basins.basin_figure),),
    "orbit": (
        FigureSpec(
            "orbit", periodic.orbit_figure, when=lambda ds: bool(json_attr(ds, "summary").get("converged", True))
        ),
    ),
    "continuation": (FigureSpec("continuation", periodic.continuation_figure),),
    "hb": (FigureSpec("hb", hb_figure),),
    "stability_boundary": _STABILITY,
    "mathieu_boundary": _STABILITY,
    "stability_comparison": _STABILITY,
    "formula_fit": (FigureSpec("formula_fit", reproduce.formula_fit),),
    "search": (FigureSpec("search", reproduce.search_map),),
    "readings_map": (FigureSpec("readings", reproduce.readings_map),),
    "response_overlay": (FigureSpec("response_overlay", reproduce.response_overlay),),
}


def _has(*names: str) -> Callable[[xr.Dataset], bool]:
    return lambda ds: set(names) <= set(ds.variables)


#: Figures in physical units, drawn for a result of any kind that carries the variables they need.
PHYSICAL_FIGURES: tuple[FigureSpec, ...] = (
    FigureSpec("physical_time_history", physical.time_history, when=_has("time_s", "dte_um", "mesh_force_N")),
    FigureSpec("spectrum_hz", physical.spectrum_hz, when=_has("frequency_Hz", "spectrum_um")),
    FigureSpec("response_rpm", physical.response_rpm, when=physical._has_response_rpm),
    *(
        FigureSpec(
            f"{name}_vs_rpm",
            physical.rpm_curve,
            when=lambda ds, name=name: physical.rpm_curve_variable(ds) == name,
            kwargs={"name": name},
        )
        for name in physical.RPM_CURVE_VARIABLES
    ),
)


def register(kind: str, *specs: FigureSpec) -> None:
    """Add figures for results of ``kind`` (a new kind, or more figures for a known one).

    Parameters
    ----------
    kind : str
        The ``geardyn_kind`` of the results.
    *specs : FigureSpec
        The figures, drawn after those already registered.
    """
    FIGURES[kind] = FIGURES.get(kind, ()) + tuple(specs)


register("response", FigureSpec("response_iso_kv", engineering.kv_overlay, when=engineering.has_iso_kv))
register("runup", FigureSpec("runup", runup.runup_figure))
register("modes", FigureSpec("campbell", modes.campbell, when=modes.has_campbell))
register("modes", FigureSpec("mode_shapes", gearbox.mode_shapes, when=gearbox.has_shafts))
# the figures only a system's results have, each where the Dataset holds what it draws
register(  # beside the reference mesh's time history where there are several elements
    "simulate",
    FigureSpec("element_deflections", systems.element_deflections, when=lambda ds: ds.sizes.get("element", 0) > 1),
)
register(
    "lyapunov",
    FigureSpec("lyapunov_spectrum", systems.lyapunov_spectrum, when=lambda ds: ds.sizes.get("exponent", 0) > 2),
)
register("orbit", FigureSpec("multipliers", systems.multipliers, when=_has("points")))
for _k in ("bifurcation", "response"):
    register(_k, FigureSpec("mesh_amplitudes", systems.mesh_amplitudes, when=_has("element_u_min")))
# the kinds earlier versions wrote for systems
register(
    "system_simulate",
    FigureSpec("element_deflections", systems.element_deflections),
    FigureSpec("phase_portrait", systems.reference_phase),
)
register("system_lyapunov", FigureSpec("lyapunov_spectrum", systems.lyapunov_spectrum))
register("system_orbit", FigureSpec("multipliers", systems.multipliers))
register(
    "system_bifurcation",
    FigureSpec("bifurcation", bifurcation.diagram),
    FigureSpec("mesh_amplitudes", systems.mesh_amplitudes),
)
register(
    "system_response",
    FigureSpec("response", response.response),
    FigureSpec("mesh_amplitudes", systems.mesh_amplitudes),
)
# (their sweeps are laid out along the reference mesh: the 1-DOF figures draw them)
register("system_map", *FIGURES["map"][:3])
register("system_basins", *FIGURES["basins"])
register("system_continuation", FigureSpec("continuation", systems.continuation_branches))
register(
    "stiffness", FigureSpec("stiffness", tooth.stiffness_figure), FigureSpec("compliance", tooth.compliance_figure)
)
register(
    "signature",
    FigureSpec("order_spectrum", tooth.order_spectrum),
    FigureSpec("signature", tooth.signature_signals),
)
register("signature_sweep", FigureSpec("indicators", tooth.indicator_sweep))
register(
    "tooth_fe",
    FigureSpec("tooth_fe_compliance", tooth.fe_compliance_figure),
    FigureSpec("tooth_fe_crack", tooth.fe_crack_figure),
)
register("rattle", FigureSpec("rattle", rattle.rattle_history))
register("rattle_map", FigureSpec("rattle_map", rattle.rattle_map_figure))


def _kind(ds: Any) -> str:
    kind = ds.attrs.get("geardyn_kind") if hasattr(ds, "attrs") else None
    if not kind:
        raise PlotError("not a geardyn result: the Dataset has no 'geardyn_kind' attribute")
    if str(kind) not in FIGURES:
        raise PlotError(f"no figures for results of kind {kind!r}: known kinds are {', '.join(sorted(FIGURES))}")
    return str(kind)


@parameters(RESULT)
def figures_for(ds: xr.Dataset) -> list[FigureSpec]:
    """The figures a result has: those of its kind, then the physical ones, each where its condition holds.

    Returns
    -------
    list of FigureSpec

    Raises
    ------
    PlotError
        If ``ds`` is not a geardyn result or its kind has no figures, or a variable has another type or shape
        than geardyn writes (:func:`geardyn.io.result_variables`).
    """
    from ..io import result_variables

    kind = _kind(ds)
    result_variables(ds, error=PlotError)  # a variable of another type or shape is refused before drawing
    return [f for f in FIGURES[kind] + PHYSICAL_FIGURES if f.when(ds)]


def draw(ds: xr.Dataset, stem: str, ax: Any = None) -> Any:
    """Draw the figure ``stem`` of a result (into ``ax`` if given); returns its :class:`~.common.PlotArtists`.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.
    stem : str
        The figure's file stem (one of :func:`figures_for`).
    ax : Axes or sequence of Axes, optional
        Where to draw (as the figure's plot function takes it); a new figure if omitted.

    Returns
    -------
    PlotArtists

    Raises
    ------
    PlotError
        If the result has no figure of that name.
    """
    specs = {f.stem: f for f in figures_for(ds)}
    if stem not in specs:
        raise PlotError(f"figure: {stem!r} is not a figure of this {_kind(ds)} result; it has {', '.join(specs)}")
    return specs[stem](ds, ax=ax)


def save_figures(
    ds: xr.Dataset, directory: str | Path, *, fmt: str | Sequence[str] = "png", dpi: int = DPI
) -> list[Path]:
    """Draw every figure of a result into ``directory`` and return their paths.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result (its ``geardyn_kind`` selects the figures, see :func:`figures_for`).
    directory : str or Path
        Where the files go (created if needed), named ``<stem>.<fmt>``.
    fmt : str or sequence of str
        File formats (``png``, ``pdf``, ``svg``; several as ``"png,pdf"`` or a list): each figure is
        drawn once and saved in each; saving needs no display and switches no backend.
    dpi : int
        Resolution of raster formats (default :data:`~geardyn.plot.common.DPI`).

    Returns
    -------
    list of Path
        Figure by figure, one file per format.

    Raises
    ------
    PlotError
        As :func:`figures_for`.
    ModelError
        For an unknown format or a resolution out of range (:func:`geardyn.validate.figure_formats`,
        :func:`geardyn.validate.dpi`).
    """
    from .. import validate

    formats = validate.figure_formats(fmt)
    res = validate.dpi(dpi)
    d = Path(directory)
    paths: list[Path] = []
    for spec in figures_for(ds):
        art = spec(ds)
        paths += [save(art, d / f"{spec.stem}.{f}", dpi=res) for f in formats]
    return paths
