"""Steady response of one parameter point: Poincaré points, period, amplitudes, contact and impact.

:func:`summarize_batch` turns a :class:`~geardyn.integrate.BatchResult` into per-point arrays (used
by every sweep); :func:`simulate` runs one point with its time history and returns a
:class:`SteadyState` whose :meth:`~SteadyState.to_dataset` is the ``simulate`` result.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import xarray as xr

from ..integrate import ST_OK, BatchResult, Trajectory, trajectory
from ..io import result_attrs
from ..model import GearModel, IntegrationOptions
from .classify import IMPACT_LABELS, classify_batch, detect_period, impact_state, motion_label, period_label

#: Periods of time history kept by :func:`simulate` (also the spectrum's length: resolution 1/32 order).
HISTORY_PERIODS = 32
#: Highest mesh order kept in the spectrum.
SPECTRUM_MAX_ORDER = 10.0


def summarize_batch(res: BatchResult) -> dict[str, np.ndarray]:
    """Per-point summary arrays of a batch: period, impact, amplitude measures, contact fractions, status."""
    P = res.poincare.shape[0]
    period = np.array(
        [detect_period(res.poincare[i]) if res.status[i] == ST_OK else -1 for i in range(P)], dtype=np.int64
    )
    u_min = res.u_min
    impact = np.array([impact_state(u_min[i], res.models[i].D) for i in range(P)], dtype=np.int64)
    fr = res.contact_fractions
    return {
        "period": period,
        "impact": impact,
        "amplitude": res.amplitude,
        "rms": res.rms,
        "mean": res.mean,
        "u_min": u_min,
        "u_max": res.u_max,
        "fraction_drive": fr[:, 0],
        "fraction_separation": fr[:, 1],
        "fraction_back": fr[:, 2],
        "status": res.status.astype(np.int64),
    }


def amplitude_spectrum(u: np.ndarray, periods: int) -> tuple[np.ndarray, np.ndarray]:
    """Single-sided amplitude spectrum of u sampled uniformly over a whole number of forcing periods.

    Returns ``(order, amplitude)``: frequencies in orders of the mesh frequency (resolution
    1/``periods``) and the amplitude of each cosine component (the mean at order 0).
    """
    x = np.asarray(u, dtype=float)
    if x.size > 1 and np.isfinite(x[0]) and x.size % periods == 1:
        x = x[:-1]  # drop the closing sample that repeats the first period boundary
    n = x.size
    spec = np.abs(np.fft.rfft(x)) / n
    spec[1:] *= 2.0
    if n % 2 == 0:
        spec[-1] /= 2.0
    order = np.arange(spec.size) / periods
    keep = order <= SPECTRUM_MAX_ORDER
    return order[keep], spec[keep]


@dataclass
class SteadyState:
    """Steady response of one point (non-dimensional); see :func:`simulate`."""

    model: GearModel
    options: IntegrationOptions
    state0: tuple[float, float]
    traj: Trajectory
    summary: dict[str, Any]

    @property
    def poincare(self) -> np.ndarray:
        return self.traj.poincare

    def to_json(self) -> dict[str, Any]:
        """The ``simulate --json`` summary (DESIGN §5 keys)."""
        s = self.summary
        return {
            "omega": self.model.omega,
            "poincare": self.poincare.tolist(),
            "motion": s["motion"],
            "lle": s.get("lle"),
            "period": s["period"],
            "impact": s["impact"],
            "amplitude": s["amplitude"],
            "rms": s["rms"],
            "mean": s["mean"],
            "u_min": s["u_min"],
            "u_max": s["u_max"],
            "contact_fractions": s["contact_fractions"],
            "status": s["status"],
        }

    def to_dataset(self) -> xr.Dataset:
        """Time history (last periods), Poincaré points and spectrum with the model and options as attributes."""
        t = self.traj
        order, spec = amplitude_spectrum(t.u, t.history_periods)
        pc = self.poincare
        ds = xr.Dataset(
            {
                "u": ("tau", t.u),
                "v": ("tau", t.v),
                "poincare_u": ("section", pc[:, 0]),
                "poincare_v": ("section", pc[:, 1]),
                "spectrum": ("order", spec),
            },
            coords={"tau": t.tau, "section": np.arange(pc.shape[0]), "order": order},
            attrs=result_attrs(
                "simulate", self.model, self.options, state0=list(self.state0), summary=_jsonable(self.summary),
                history_periods=str(t.history_periods),
            ),
        )
        ds["section"].attrs.update(units="1", long_name="index of the recorded forcing period")
        return ds


def _jsonable(d: dict[str, Any]) -> dict[str, Any]:
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in d.items()}


def simulate(
    model: GearModel,
    options: IntegrationOptions = IntegrationOptions(),
    state0: Sequence[float] = (0.0, 0.0),
    *,
    history_periods: int = HISTORY_PERIODS,
) -> SteadyState:
    """Integrate one point and summarise its steady response.

    Parameters
    ----------
    model : GearModel
        Non-dimensional model.
    options : IntegrationOptions
        ``transient`` periods are discarded, ``periods`` Poincaré points recorded.
    state0 : (u0, v0)
        Initial state at θ = 0 (non-dimensional).
    history_periods : int
        How many of the last recorded periods keep the full time history (for plots and the spectrum).
    """
    t = trajectory(model, state0, options, history_periods=history_periods)
    arr = summarize_batch(t.summary)
    period = int(arr["period"][0])
    ok = int(arr["status"][0]) == ST_OK
    # Full motion classification; the Lyapunov spectrum is computed (by integrating on from the
    # end state) only when no period was found.
    cls = classify_batch(t.summary) if ok and period == 0 else None
    if cls is not None:
        period = int(cls["period"][0])
    motion = motion_label(int(cls["motion"][0]), period) if cls is not None else (
        period_label(period) if ok else "diverged")

    def f(key: str) -> float | None:
        x = float(arr[key][0])
        return x if np.isfinite(x) else None

    summary = {
        "period": period if period > 0 else None,
        "motion": motion,
        "impact": IMPACT_LABELS[int(arr["impact"][0])],
        "amplitude": f("amplitude"),
        "rms": f("rms"),
        "mean": f("mean"),
        "u_min": f("u_min"),
        "u_max": f("u_max"),
        "contact_fractions": {
            "drive": f("fraction_drive"), "separation": f("fraction_separation"), "back": f("fraction_back"),
        },
        "status": "ok" if ok else "diverged",
        "lle": float(cls["lle"][0]) if cls is not None and np.isfinite(cls["lle"][0]) else None,
        "lle_err": float(cls["lle_err"][0]) if cls is not None and np.isfinite(cls["lle_err"][0]) else None,
    }
    return SteadyState(model, options, (float(state0[0]), float(state0[1])), t, summary)
