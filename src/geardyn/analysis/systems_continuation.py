"""The ``--system`` form of a continuation's results: per-mesh extremes beside the branches of the one
continuation algorithm.

Continuation, branch switching at period doublings and the events located by Newton are
:func:`geardyn.analysis.periodic.continuation` for any System (the rigid-body gauge rows and the elastic
multipliers come from the System's rigid basis).  :class:`SystemContinuation` holds its result with every
element's extremes along the branches and writes the ``system_continuation`` summary and Dataset.

References
----------
R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010;
Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import xarray as xr

from ..labels import IMPACT_LABELS, impact_state
from ..model import DEFAULT_DTAU
from .periodic.arclength import MAX_BRANCH_POINTS
from .periodic.continuation import DEFAULT_MAX_PERIOD, ContinuationResult, continuation

__all__ = ["SystemContinuation", "system_continuation"]


@dataclass
class SystemContinuation:
    """A continuation of a system's periodic orbits with every element's extremes (non-dimensional).

    Parameters
    ----------
    result : ContinuationResult
        The branches and bifurcations (:func:`~geardyn.analysis.periodic.continuation`).
    """

    result: ContinuationResult

    @property
    def model(self) -> Any:
        return self.result.model

    @property
    def param(self) -> str:
        return self.result.param

    def _cat(self, f) -> np.ndarray:
        return np.concatenate([f(b) for b in self.result.branches])

    @property
    def values(self) -> np.ndarray:
        """The parameter at every point of every branch."""
        return self._cat(lambda b: b.values)

    @property
    def extrema(self) -> np.ndarray:
        """(K, elements, 2): every element's δ_min, δ_max at every point."""
        return self._cat(lambda b: b.extrema)

    def to_json(self) -> dict[str, Any]:
        """Keys of ``continuation --json`` plus ``rigid_body_modes`` and ``meshes`` (per-mesh extremes per point)."""
        out = self.result.to_json()
        m = self.model
        r = m.rigid_basis().shape[1]
        p = m.period_multiple() or 1
        for pt in out["branch"]:
            pt["period"] *= p
        ext = self.extrema
        els = m.elements
        out["meshes"] = [{"name": e.name, "u_min": ext[:, i, 0].tolist(), "u_max": ext[:, i, 1].tolist(),
                          "amplitude": (0.5 * (ext[:, i, 1] - ext[:, i, 0])).tolist(),
                          "impact": [IMPACT_LABELS[impact_state(float(lo), e.gap)] for lo in ext[:, i, 0]],
                          "dynamic_factor": None} for i, e in enumerate(els) if e.kind == "mesh"]
        out["rigid_body_modes"] = r
        if r:
            out["notes"] = out["notes"] + [f"{2 * r} multipliers equal to 1 belong to the rigid-body mode(s) and "
                                           f"are left out; the multipliers listed are the elastic ones"]
        return out

    def to_dataset(self) -> xr.Dataset:
        """Dataset of kind ``system_continuation`` (point and bifurcation tables, per-element extremes)."""
        import json

        from ..io import annotate
        from ..io import system_attrs

        m, res = self.model, self.result
        names = [e.name for e in m.elements]
        ext = self.extrema
        bifs = res.bifurcations
        ds = xr.Dataset({
            "value": ("point", self.values),
            "amplitude": ("point", self._cat(lambda b: b.amplitude)),
            "stable": ("point", self._cat(lambda b: b.stable).astype(np.int64)),
            "branch": ("point", self._cat(lambda b: np.full(len(b), b.index)).astype(np.int64)),
            "state": (("point", "coordinate"), self._cat(lambda b: b.states)),
            "element_u_min": (("point", "element"), ext[:, :, 0]),
            "element_u_max": (("point", "element"), ext[:, :, 1]),
            "bifurcation_type": ("bifurcation", np.array([b.type for b in bifs], dtype=str) if bifs
                                 else np.zeros(0, dtype=str)),
            "bifurcation_value": ("bifurcation", np.array([b.value for b in bifs], float)),
            "bifurcation_amplitude": ("bifurcation", np.array([b.amplitude for b in bifs], float)),
        }, coords={"point": np.arange(self.values.size), "element": names,
                   "coordinate": [f"{lab}" for lab in m.labels] + [f"{lab}'" for lab in m.labels],
                   "bifurcation": np.arange(len(bifs))},
            attrs=system_attrs(m, "system_continuation", None, {"param": self.param}))
        ds.attrs["summary"] = json.dumps(self.to_json())
        return annotate(ds)


def system_continuation(model: Any, param: str, start: float, stop: float, n: int = 1,
                        guess: Sequence[float] | None = None, *, dtau: float = DEFAULT_DTAU, accurate: bool = True,
                        ds_max: float | None = None, max_points: int = MAX_BRANCH_POINTS,
                        state0: Sequence[float] | None = None, switch: bool = True,
                        max_period: int = DEFAULT_MAX_PERIOD) -> SystemContinuation:
    """:func:`geardyn.analysis.periodic.continuation` of a system, with its per-element extremes.

    Parameters
    ----------
    model : System
    param : str
        A system parameter (``omega``, ``<mesh>.xi0``, ``<mesh>.D``, ...).
    start, stop : float
        The interval (``stop`` may lie below ``start``).
    n : int
        Period of the first branch in forcing periods.
    guess : (d,) state, optional
        Shooting guess at ``start`` (default: the attractor reached by simulation from ``state0``).
    dtau, accurate, ds_max, max_points, switch, max_period
        As :func:`~geardyn.analysis.periodic.continuation`.
    state0 : (u0, v0) or (d,), optional
        Start of the simulation that gives the first guess.

    Returns
    -------
    SystemContinuation

    Raises
    ------
    ModelError
        For incommensurate meshes, a bad interval, or when the first orbit cannot be found.
    """
    return SystemContinuation(continuation(model, param, start, stop, n, guess, dtau=dtau, accurate=accurate,
                                           switch=switch, max_period=max_period, ds_max=ds_max, max_points=max_points, state0=state0))
