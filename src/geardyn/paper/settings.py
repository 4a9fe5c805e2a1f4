"""The settings of a reproduction run, and the context every study runs in.

Settings the paper leaves unstated are chosen here, once, with the reason written into the report
(:class:`Settings`); the paper's own numbers are in :mod:`geardyn.paper.claims` and
:mod:`geardyn.paper.table1`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ..analysis.bifurcation import bifurcation
from ..model import GearModel, IntegrationOptions
from .table1 import TABLE1_MODEL

__all__ = ["FIGURE_REF", "RUN_FULL", "RUN_QUICK", "RUN_CHANGED", "Context", "Settings", "model_text"]

#: Prefix of a figure reference (:meth:`Context.figure`) until the figure is drawn.
FIGURE_REF = "figure:"
#: What a run is (:meth:`Settings.run_kind`): the full reproduction, ``--quick``, or other settings.
RUN_FULL, RUN_QUICK, RUN_CHANGED = "full", "quick", "changed"

#: The (ξ0, ξ1, D) of a frequency response of the jump study.
ResponseKey = tuple[float, float, float]

#: What each setting is, as a reduced run's report lists what it changed (``workers`` changes no result).
SETTING_TEXT = {
    "omega_damping": "ω of the damping and backlash studies",
    "transient": "transient periods of the bifurcation diagrams",
    "periods": "recorded periods of the bifurcation diagrams",
    "settle": "settling periods of non-periodic points",
    "xi0_grid": "ξ0 grid of the ξ0 bifurcation diagram",
    "xi1_grid": "ξ1 grid of the ξ1 bifurcation diagram",
    "d_grid": "D grid of the backlash bifurcation diagram",
    "readings_omegas": "ω grid of the readings",
    "readings_transient": "transient periods of each screened reading",
    "readings_periods": "recorded periods of each screened reading",
    "readings_settle": "settling periods of each screened reading",
    "readings_response_transient": "transient periods per point of the readings' responses",
    "readings_response_periods": "recorded periods per point of the readings' responses",
    "confirm_periods": "periods of the exponent run that re-examines doubtful labels",
    "response_omega": "ω range of the frequency responses",
    "response_num": "points of each frequency response",
    "response_transient": "transient periods per point of the frequency responses",
    "response_periods": "recorded periods per point of the frequency responses",
    "xi0_set": "responses with ξ0 varied",
    "xi1_set": "responses with ξ1 varied",
    "d_set": "responses with D varied",
    "alt_set": "further responses",
    "stability_omegas": "ω grid of the stability condition",
    "continuation_omega": "ω interval of the continuation",
    "continuation_sweep_num": "points of the sweep under the continuation",
    "continuation_sweep_periods": "recorded periods of the sweep under the continuation",
    "xi0_zoom": "ξ0 interval of the zoomed ξ0 diagram",
}


def _setting_value(name: str, value: Any) -> str:
    """A setting's value in a few words: a number, an interval, a grid by its size and ends, a set of responses."""
    if name.endswith(("_grid", "_omegas")):
        return (
            f"{len(value)} points over [{min(value):g}, {max(value):g}]"
            if len(value) > 3
            else f"{len(value)} points ({', '.join(f'{v:g}' for v in value)})"
        )
    if name.endswith("_set"):
        return f"{len(value)} responses"
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:g}" for v in value) + "]"
    return f"{value:g}"


@dataclass(frozen=True)
class Settings:
    """Settings of a reproduction run; ``quick()`` gives a reduced version for tests.

    Attributes
    ----------
    omega_damping : float
        ω of the damping and backlash studies at the default reading (not stated in the paper).
        ω = 1, the mesh frequency at the linear natural frequency, is the reference point of the
        non-dimensional model; the readings study tries every ω of ``readings_omegas``.
    transient, periods : int
        Periods discarded and recorded per point (the paper's Δτ = 0.01 is kept).
    settle : int
        Further periods with exponents for points not periodic after the transient.
    xi0_grid, xi1_grid : arrays
        Damping grids of the bifurcation diagrams.
    readings_omegas : array
        The ω grid (step 0.01) of the readings of the damping and backlash claims.
    readings_transient, readings_periods, readings_settle : int
        Periods of each screened reading (transient, recorded, settling of non-periodic points).
    readings_response_transient, readings_response_periods : int
        Periods per point of the lockstep frequency responses of the readings (each point continues
        from the previous end state, so a short transient suffices).
    confirm_periods : int
        Periods of the longer exponent run that re-examines doubtful labels (:mod:`geardyn.analysis.confirm`).
    d_grid : array
        Backlash grid of the backlash bifurcation diagram.
    response_omega, response_num : (float, float), int
        ω range and number of points of the frequency responses.
    response_transient, response_periods : int
        Periods discarded and recorded per point of a frequency response.
    xi0_set, xi1_set, d_set, alt_set : tuples of (ξ0, ξ1, D)
        Frequency responses of the jump study: ξ0 varied, ξ1 varied, D varied, and any further
        ones (none by default: the other backlash readings are judged by the readings study).
    stability_omegas : array
        ω grid of the stability-condition study.
    continuation_omega : (float, float)
        ω interval of the continuation through the first jump.
    continuation_sweep_num, continuation_sweep_periods : int
        Points and recorded periods of the brute-force up/down sweep drawn under the continuation
        (the sweep's transient is ``response_transient``), as ``geardyn continuation`` draws it.
    xi0_zoom : (float, float)
        ξ0 interval of the zoomed ξ0 bifurcation diagram: the fine part of ``xi0_grid``, where the
        paper's first bifurcation point and the Table 2 rows lie.
    workers : int
        Worker processes when :func:`geardyn.paper.run.run` makes its own pool.
    """

    omega_damping: float = 1.0
    transient: int = 300
    periods: int = 200
    settle: int = 400
    xi0_grid: tuple[float, ...] = tuple(
        np.round(np.concatenate([np.arange(0.02, 0.2, 0.004), np.arange(0.2, 0.951, 0.05)]), 4)
    )
    xi1_grid: tuple[float, ...] = tuple(np.round(np.arange(0.0, 0.1501, 0.005), 4))
    d_grid: tuple[float, ...] = tuple(np.round(np.arange(0.05, 1.0001, 0.025), 4))
    readings_omegas: tuple[float, ...] = tuple(np.round(np.arange(0.5, 1.6001, 0.01), 2))
    readings_transient: int = 80
    readings_periods: int = 24
    readings_settle: int = 40
    readings_response_transient: int = 40
    readings_response_periods: int = 24
    confirm_periods: int = 3000
    response_omega: tuple[float, float] = (0.3, 1.2)
    response_num: int = 91
    response_transient: int = 120
    response_periods: int = 100
    xi0_set: tuple[ResponseKey, ...] = ((0.08, 0.05, 0.25), (0.1, 0.05, 0.25), (0.15, 0.05, 0.25))
    xi1_set: tuple[ResponseKey, ...] = ((0.08, 0.03, 0.25), (0.08, 0.05, 0.25), (0.08, 0.08, 0.25))
    d_set: tuple[ResponseKey, ...] = (
        (0.08, 0.05, 0.1),
        (0.08, 0.05, 0.25),
        (0.08, 0.05, 0.35),
        (0.08, 0.05, 0.75),
    )
    alt_set: tuple[ResponseKey, ...] = ()
    stability_omegas: tuple[float, ...] = tuple(np.round(np.arange(0.4, 2.41, 0.1), 3))
    continuation_omega: tuple[float, float] = (0.5, 0.7)
    continuation_sweep_num: int = 101
    continuation_sweep_periods: int = 32
    xi0_zoom: tuple[float, float] = (0.02, 0.2)
    workers: int = 2

    @property
    def response_sets(self) -> list[ResponseKey]:
        """Every (ξ0, ξ1, D) of the jump study, each once, in the order of the sets."""
        return list(dict.fromkeys(self.xi0_set + self.xi1_set + self.d_set + self.alt_set))

    @property
    def response_options(self) -> IntegrationOptions:
        """Transient and recorded periods of the frequency responses."""
        return IntegrationOptions(transient=self.response_transient, periods=self.response_periods)

    @classmethod
    def quick(cls) -> Settings:
        """A reduced run (coarse grids, short runs) that exercises every study end to end."""
        return cls(
            transient=60,
            periods=40,
            settle=60,
            xi0_grid=(0.03, 0.07, 0.09, 0.15, 0.5),
            xi1_grid=(0.0, 0.02, 0.06),
            d_grid=(0.1, 0.35, 0.75),
            readings_omegas=(0.9, 1.0, 1.3),
            readings_transient=30,
            readings_periods=16,
            readings_settle=20,
            readings_response_transient=20,
            readings_response_periods=16,
            confirm_periods=200,
            workers=1,
            response_num=12,
            response_transient=40,
            response_periods=30,
            stability_omegas=(0.8, 1.6),
            continuation_omega=(0.61, 0.63),
            continuation_sweep_num=11,
            continuation_sweep_periods=16,
        )

    def changes(self) -> list[str]:
        """What this run changes from the full reproduction (:class:`Settings` as defined), one line per
        setting: ``"points of each frequency response: 12 (full run: 91)"``; empty for the full run.

        ``workers`` is left out: it changes the time, not the results.

        Returns
        -------
        list of str
        """
        full = Settings()
        return [
            f"{text}: {_setting_value(k, getattr(self, k))} (full run: {_setting_value(k, getattr(full, k))})"
            for k, text in SETTING_TEXT.items()
            if getattr(self, k) != getattr(full, k)
        ]

    def run_kind(self) -> str:
        """:data:`RUN_FULL` (the settings of the full reproduction), :data:`RUN_QUICK` (those of
        :meth:`quick`) or :data:`RUN_CHANGED` (any other), whatever the number of workers.

        Returns
        -------
        str
        """
        if not self.changes():
            return RUN_FULL
        return RUN_QUICK if replace(self, workers=1) == replace(Settings.quick(), workers=1) else RUN_CHANGED

    @property
    def readings_options(self) -> IntegrationOptions:
        """Transient and recorded periods of each screened reading."""
        return IntegrationOptions(transient=self.readings_transient, periods=self.readings_periods)

    @property
    def readings_response_options(self) -> IntegrationOptions:
        """Transient and recorded periods per point of the lockstep responses of the readings."""
        return IntegrationOptions(transient=self.readings_response_transient, periods=self.readings_response_periods)

    @property
    def options(self) -> IntegrationOptions:
        """Transient and recorded periods of the bifurcation diagrams."""
        return IntegrationOptions(transient=self.transient, periods=self.periods)


#: The model's parameters as the report names them, in the order it gives them.
SYMBOLS = {"omega": "ω", "xi0": "ξ0", "xi1": "ξ1", "D": "D", "fp": "f_p", "kappa1": "κ1", "eps1": "ε1"}


def model_text(model: GearModel, *, skip: Sequence[str] = (), only: Sequence[str] | None = None) -> str:
    """A model's parameters as the report writes them: ``"ω = 1, ξ0 = 0.08, ξ1 = 0.05, D = 0.25"``.

    Parameters
    ----------
    model : GearModel
    skip : sequence of str
        Parameters left out (the swept one), by canonical name (``"xi0"``, ``"omega"``…).
    only : sequence of str, optional
        The parameters given (default ω, ξ0, ξ1, D).

    Returns
    -------
    str
    """
    only = ("omega", "xi0", "xi1", "D") if only is None else only
    return ", ".join(f"{sym} = {model.get(k):g}" for k, sym in SYMBOLS.items() if k in only and k not in skip)


@dataclass
class Context:
    """What every study needs: the output directory, settings, the executor, and a log.

    Parameters
    ----------
    out : Path
        The report directory.
    settings : Settings
    executor : concurrent.futures.Executor, optional
        Where the sweeps run (``None``: in this process).
    log : callable, optional
        Receives one progress line per step.
    datasets : dict
        Name → data path (relative) of every saved Dataset.
    pending : dict
        Name → Dataset not yet written.
    labels : dict
        Name → what the Dataset is, with its parameters, as the report shows its evidence.
    data_only : set
        Names of the Datasets saved without figures (kinds that have none).
    """

    out: Path
    settings: Settings
    executor: Executor | None = None
    log: Callable[[str], None] = lambda s: None
    datasets: dict[str, str] = field(default_factory=dict)  # name -> relative path of its NetCDF
    pending: dict[str, xr.Dataset] = field(default_factory=dict)  # saved at the end, in parallel
    labels: dict[str, str] = field(default_factory=dict)  # name -> what it is, with its parameters
    data_only: set[str] = field(default_factory=set)  # names saved without figures

    @property
    def base(self) -> GearModel:
        """The Table 1 model at the ω of the damping and backlash studies."""
        return TABLE1_MODEL.replace(omega=self.settings.omega_damping)

    def model_at(self, key: ResponseKey) -> GearModel:
        """The base model (:attr:`base`) at one (ξ0, ξ1, D) of the jump study's sets.

        Parameters
        ----------
        key : (float, float, float)
            ξ0, ξ1 and D.

        Returns
        -------
        GearModel
        """
        return self.base.replace(xi0=key[0], xi=(key[1],), D=key[2])

    def save(self, name: str, ds: xr.Dataset, label: str | None = None, *, figures: bool = True) -> str:
        """Register a Dataset for ``data/<name>.nc`` and its figures; written by
        :func:`geardyn.paper.run.write_outputs`.

        Parameters
        ----------
        name : str
            File stem of the data; its figures go to ``figures/<name>/``.
        ds : xarray.Dataset
            A geardyn result (its ``geardyn_kind`` selects the figures).
        label : str, optional
            What the Dataset is, with its parameters (``"frequency response at ξ0 = 0.08, …"``): the
            report's name for its data and figures (default ``name``).
        figures : bool
            Draw its figures (False: data only, for kinds that have none).

        Returns
        -------
        str
            The data path relative to the report directory.
        """
        rel = f"data/{name}.nc"
        self.pending[name] = ds
        self.datasets[name] = rel
        self.labels[name] = label or name
        if not figures:
            self.data_only.add(name)
        return rel

    @staticmethod
    def figure(name: str) -> str:
        """A reference to the main figure of the Dataset saved as ``name``, for evidence and sections.

        The figure's file is known only once it is drawn (:func:`geardyn.plot.save_figures` names
        it); :func:`geardyn.paper.run.link_figures` replaces the reference by its path.

        Parameters
        ----------
        name : str
            The name given to :meth:`save`.

        Returns
        -------
        str
        """
        return FIGURE_REF + name

    def bifurcation(self, model: GearModel, param: str, values: Sequence[float], **kw: Any) -> xr.Dataset:
        """A bifurcation diagram with the run's integration settings and executor.

        Parameters
        ----------
        model : GearModel
        param : str
            The swept parameter.
        values : sequence of float
            Its grid.
        **kw
            Passed on to :func:`geardyn.analysis.bifurcation.bifurcation` (``options`` replaces the
            run's integration options).

        Returns
        -------
        xarray.Dataset
        """
        s = self.settings
        return bifurcation(
            model,
            param,
            values,
            options=kw.pop("options", s.options),
            settle_periods=s.settle,
            executor=self.executor,
            **kw,
        )
