"""The ``geardyn`` accessor of :class:`xarray.Dataset`: ``ds.geardyn.plot()`` and friends.

Importing :mod:`geardyn` registers it::

    import geardyn, xarray as xr
    ds = geardyn.read_netcdf("results/simulate.nc")
    ds.geardyn.kind            # "simulate"
    ds.geardyn.model           # the System it was computed on (a GearModel, or a SystemModel)
    ds.geardyn.physical()      # a copy with rpm, µm, N variables (scales of the paper's pair by default)
    ds.geardyn.plot("figs")    # the figures of ``geardyn plot``, as PNG files
    ds.geardyn.figures         # their names, e.g. ["time_history", "phase_portrait", ...]
    ds.geardyn.figure("phase_portrait", ax=ax)   # one of them, into your own Axes

Nothing heavy is imported until a method is called (matplotlib only by :meth:`plot`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import xarray as xr

__all__ = ["GeardynAccessor"]


@xr.register_dataset_accessor("geardyn")
class GeardynAccessor:
    """geardyn methods on a result Dataset (``ds.geardyn``).

    Parameters
    ----------
    ds : xarray.Dataset
        A result written by geardyn (its ``geardyn_kind`` attribute names the kind); xarray
        passes it when ``ds.geardyn`` is first accessed.
    """

    def __init__(self, ds: xr.Dataset):
        self._ds = ds

    @property
    def kind(self) -> str | None:
        """The kind of result (``geardyn_kind`` attribute), e.g. ``"simulate"``; ``None`` if not a geardyn result."""
        return self._ds.attrs.get("geardyn_kind")

    @property
    def model(self):
        """The System the result was computed on, rebuilt from its attributes (:func:`geardyn.io.model_from_attrs`):
        a :class:`~geardyn.model.GearModel` for the pair's results, a :class:`~geardyn.systems.SystemModel` for a
        system's."""
        from .io import model_from_attrs

        return model_from_attrs(self._ds)

    @property
    def scales(self):
        """The :class:`~geardyn.geometry.scales.Scales` stored with the result, or ``None``."""
        from .units import PhysicalScales

        return PhysicalScales.from_attrs(self._ds.attrs)

    def physical(self, scales: Any = None) -> xr.Dataset:
        """A copy with physical coordinates and variables (see :func:`geardyn.analysis.physical.add_physical`).

        Parameters
        ----------
        scales : PhysicalScales, LoadedConfig, path of a configuration, or None
            The gear pair; ``None`` uses the scales stored in the result, else the paper's Table 1
            pair (k0 assumed).
        """
        from .analysis.physical import add_physical

        return add_physical(self._ds, scales)

    def plot(self, directory: str | Path | None = None) -> list[Path]:
        """Draw the result's figures as PNG files, like ``geardyn plot``; returns their paths.

        Parameters
        ----------
        directory : str or Path, optional
            Where to write them; default the directory of the file the Dataset was read from,
            else the current directory.

        Returns
        -------
        list of Path

        Raises
        ------
        geardyn.errors.PlotError
            If the Dataset is not a geardyn result or its kind has no figures.
        """
        from .plot import save_figures

        if directory is None:
            src = self._ds.encoding.get("source")
            directory = Path(src).parent if src else Path.cwd()
        return save_figures(self._ds, directory)

    @property
    def figures(self) -> list[str]:
        """Names (file stems) of the figures this result has (see :func:`geardyn.plot.figures_for`)."""
        from .plot import figures_for

        return [f.stem for f in figures_for(self._ds)]

    def figure(self, name: str, ax: Any = None):
        """Draw one figure of the result, into ``ax`` if given, else into a new figure.

        Parameters
        ----------
        name : str
            One of :attr:`figures`.
        ax : matplotlib.axes.Axes or sequence of Axes, optional
            Where to draw (one Axes: the figure's main panel).

        Returns
        -------
        geardyn.plot.PlotArtists
            The figure, its Axes and the artists drawn.

        Raises
        ------
        geardyn.errors.PlotError
            If the result has no figure of that name.
        """
        from .plot import draw

        return draw(self._ds, name, ax=ax)

    def to_netcdf(self, path: str | Path) -> Path:
        """Write the result atomically with geardyn's conventions (:func:`geardyn.io.write_netcdf`)."""
        from .io import write_netcdf

        return write_netcdf(self._ds, path)
