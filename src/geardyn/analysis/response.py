"""Amplitude-frequency response: up and down sweeps with state continuation, jumps, hysteresis.

The response is a continuation bifurcation sweep over ω in both directions
(:func:`geardyn.analysis.bifurcation.bifurcation` with ``mode='continue'``, ``sweep='both'``).
From its Dataset:

- a **jump** is a step between neighbouring ω of one sweep where the amplitude changes abruptly:
  by at least :data:`JUMP_MIN_FRACTION` of the amplitude range of the whole response and by at
  least :data:`JUMP_RATIO` times the typical step change next to it (the larger of the median
  step changes over :data:`JUMP_WINDOW` steps before and after), so that smooth resonance flanks
  and the point-to-point scatter of chaotic amplitudes (also where such scatter begins) are not
  taken for jumps.  Each jump is
  reported at the midpoint ω of its step, with its direction (``up``: the amplitude increases),
  its size (|ΔA|) and the sweep in which it occurs.
- a **hysteresis interval** [ω_a, ω_b] covers a maximal run of grid points where the up and down
  sweeps end on different attractors (:func:`same_attractor`, the test of
  :mod:`geardyn.analysis.attractors` that the basins use too) and the sweep that leaves its
  attractor at an end of the run jumps there: coexisting attractors, whose basins
  :mod:`geardyn.analysis.basins` can map.  Its bounds are the midpoints of the grid steps of those
  jumps (so it is never zero-width); runs of differing attractors that no jump bounds, and any part
  of a run beyond its jump, are listed apart as **coexistence** (:func:`coexistence_intervals`).

All amplitudes are non-dimensional (units of b_c), frequencies ω = ω_e/ω_n.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from .._docfill import parameters, result_of
from ..io import json_values
from ..model import GearModel, ModelError
from .attractors import CYCLE_TOL, NONPERIODIC_TOL, Attractor, attractor_of
from .attractors import same_attractor as _same_attractor
from .bifurcation import bifurcation, point_labels, sweep_values
from .points import sweep_function

__all__ = [
    "JUMP_MIN_FRACTION",
    "JUMP_RATIO",
    "JUMP_WINDOW",
    "ATTRACTOR_TOL",
    "NONPERIODIC_TOL",
    "MEASURES",
    "frequency_response",
    "detect_jumps",
    "coexistence_intervals",
    "hysteresis_intervals",
    "same_attractor",
    "response_json",
]

#: A jump changes the amplitude by at least this fraction of the response's amplitude range …
JUMP_MIN_FRACTION = 0.1
#: … and by at least this many times the typical neighbouring step change.
JUMP_RATIO = 5.0
#: Steps on each side over which the typical step change is taken (median).
JUMP_WINDOW = 3
#: Two periodic attractors are the same when each point of one cycle lies within this distance
#: (relative to max(1, the cycle's largest |coordinate|)) of a point of the other
#: (:data:`geardyn.analysis.attractors.CYCLE_TOL`).  Two non-periodic attractors are taken as the
#: same when their amplitudes and means agree to NONPERIODIC_TOL of the response's amplitude range.
ATTRACTOR_TOL = CYCLE_TOL
#: Amplitude measures a response can be built on (variables of the bifurcation Dataset).
MEASURES = ("amplitude", "rms", "u_max", "u_min", "mean")


@sweep_function("frequency_response")
def frequency_response(
    model: GearModel,
    omega_start: float,
    omega_stop: float,
    num: int,
    *,
    measure: str = "amplitude",
    options,
    state0,
    lyapunov,
    settle_periods,
    engine,  # shared sweep keywords (SWEEP_KEYWORDS)
) -> xr.Dataset:
    """Up and down frequency sweeps with state continuation, with jumps and hysteresis detected.

    Parameters
    ----------
    model : GearModel
        The model; ω is swept.
    omega_start, omega_stop : float
        Ends of the ω grid (non-dimensional, > 0).
    num : int
        Points of the grid; choose the step small enough to resolve the jumps (they are located to
        within one step).
    measure : str
        Amplitude measure used for jumps: one of :data:`MEASURES` (default: half peak-to-peak).
    options : IntegrationOptions
        Transient and recorded periods per point (each point starts from the previous end state,
        so a moderate transient suffices away from bifurcations).
    state0 : sequence of float
        Initial state of the first point of each sweep (the lowest ω for up, the highest for down).
    engine : SweepOptions, optional
        Where and how the sweep runs (one chunk per sweep direction: ``chunk_points`` is not used).

    Returns
    -------
    xarray.Dataset
        The bifurcation Dataset (dims ``sweep`` = up, down and ``omega``) with the attributes
        ``jumps`` and ``hysteresis`` (JSON) and ``measure``.

    Raises
    ------
    ModelError
        For an unknown measure, an invalid or non-positive ω grid, or as
        :func:`~geardyn.analysis.bifurcation.bifurcation`.
    SweepError
        When the sweep cannot run (see :func:`geardyn.sweep.run_chunks`).
    TypeError
        For a keyword that is not an engine option.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, frequency_response
    >>> ds = frequency_response(GearModel(), 0.6, 0.8, 3, options=IntegrationOptions(transient=50, periods=8),
    ...                         progress=False)
    >>> ds.sizes["sweep"], ds.sizes["omega"], ds.sizes["section"]  # up and down, 3 speeds, 8 periods
    (2, 3, 8)
    """
    if measure not in MEASURES:
        raise ModelError(f"measure: must be one of {', '.join(MEASURES)}, got {measure!r}")
    vals = sweep_values(omega_start, omega_stop, num)
    if np.any(vals <= 0):
        raise ModelError(
            f"omega: must be > 0 (mesh frequency ω_e/ω_n), got a grid from {omega_start!r} to {omega_stop!r}"
        )
    ds = bifurcation(
        model,
        "omega",
        vals,
        mode="continue",
        sweep="both",
        state0=state0,
        options=options,
        lyapunov=lyapunov,
        settle_periods=settle_periods,
        engine=engine,
        description="response ω",
    )
    return annotate_response(ds, measure)


def annotate_response(ds: xr.Dataset, measure: str = "amplitude") -> xr.Dataset:
    """Detect jumps and hysteresis in a two-sweep ω Dataset and store them as attributes."""
    jumps = detect_jumps(ds, measure)
    hyst, coexist = coexistence_intervals(ds, jumps=jumps)
    ds.attrs.update(
        geardyn_kind="response",
        measure=measure,
        jumps=json.dumps(jumps),
        hysteresis=json.dumps(hyst),
        coexistence=json.dumps(coexist),
    )
    return ds


def _param(ds: xr.Dataset) -> str:
    return str(ds.attrs.get("param", "omega"))


def detect_jumps(
    ds: xr.Dataset,
    measure: str = "amplitude",
    *,
    min_fraction: float = JUMP_MIN_FRACTION,
    ratio: float = JUMP_RATIO,
    window: int = JUMP_WINDOW,
) -> list[dict[str, Any]]:
    """Jumps of ``measure`` along each sweep of a continuation Dataset (see the module docstring).

    Returns a list of ``{"omega", "direction", "size", "sweep", "omega_from", "omega_to",
    "amplitude_from", "amplitude_to"}`` in sweep order (up first, then down), where
    ``omega_from`` → ``omega_to`` is the grid step in the order the sweep runs and ``omega`` its
    midpoint (the parameter's value if the sweep is not over ω).

    Parameters
    ----------
    ds : xarray.Dataset
        A continuation bifurcation Dataset (one or two sweeps).
    measure : str
        Amplitude measure, one of :data:`MEASURES`.
    min_fraction : float
        Smallest jump as a fraction of the amplitude range; default :data:`JUMP_MIN_FRACTION`.
    ratio : float
        Smallest jump relative to the typical neighbouring step; default :data:`JUMP_RATIO`.
    window : int
        Steps on each side for the typical step; default :data:`JUMP_WINDOW`.

    Returns
    -------
    list of dict
    """
    name = _param(ds)
    x = ds[name].values
    scale = _amplitude_range(ds, measure)
    if scale == 0.0:
        return []
    jumps = []
    for lab in [str(s) for s in ds["sweep"].values]:
        a = ds[measure].sel(sweep=lab).values
        step = -1 if lab == "down" else 1
        xs, As = x[::step], a[::step]
        d = np.diff(As)
        ad = np.abs(d)
        for i in range(d.size):
            if not np.isfinite(d[i]) or ad[i] < min_fraction * scale:
                continue
            near = (ad[max(0, i - window) : i], ad[i + 1 : i + 1 + window])  # the steps before and after
            if sum(int(np.isfinite(s).sum()) for s in near) < 2:  # one neighbouring step measures no typical step
                continue
            sides = [float(np.median(s[np.isfinite(s)])) for s in near if np.any(np.isfinite(s))]
            typical = max(sides) if sides else 0.0
            if ad[i] < ratio * typical:
                continue
            jumps.append(
                {
                    name: float(0.5 * (xs[i] + xs[i + 1])),
                    "direction": "up" if d[i] > 0 else "down",
                    "size": float(ad[i]),
                    "sweep": lab,
                    f"{name}_from": float(xs[i]),
                    f"{name}_to": float(xs[i + 1]),
                    "amplitude_from": float(As[i]),
                    "amplitude_to": float(As[i + 1]),
                }
            )
    return jumps


def _amplitude_range(ds: xr.Dataset, measure: str = "amplitude") -> float:
    amp = ds[measure].values
    return float(np.ptp(amp[np.isfinite(amp)])) if np.any(np.isfinite(amp)) else 0.0


def _attractors(ds: xr.Dataset, lab: str) -> list[Attractor | None]:
    """The attractor each point of one sweep reached: its cycle, or its amplitude and mean (None: diverged)."""
    s = {k: ds[k].sel(sweep=lab).values for k in ("status", "period", "motion", "amplitude", "mean")}
    section = np.stack([ds[k].sel(sweep=lab).values for k in ("poincare_u", "poincare_v")], axis=-1)
    return [
        attractor_of(s["period"][k], s["motion"][k], section[k], np.array([s["amplitude"][k], s["mean"][k]]))
        if int(s["status"][k]) == 0
        else None
        for k in range(section.shape[0])
    ]


def _same(
    a: Attractor | None, b: Attractor | None, amp_range: float, tol: float, nonperiodic_tol: float
) -> bool | None:
    if a is None or b is None:
        return None
    sig_tol = nonperiodic_tol * max(amp_range, 1e-12)
    return _same_attractor(a, b, tol=tol, signature_tol=sig_tol, match_motion=False)


def same_attractor(
    ds: xr.Dataset,
    k: int,
    a: str = "up",
    b: str = "down",
    *,
    tol: float = ATTRACTOR_TOL,
    nonperiodic_tol: float = NONPERIODIC_TOL,
) -> bool | None:
    """Whether sweeps ``a`` and ``b`` reached the same attractor at grid index ``k``.

    Periodic attractors are compared by their Poincaré cycles (same period, each point of one
    cycle within ``tol`` of a point of the other); non-periodic ones by amplitude and mean (to
    ``nonperiodic_tol`` of the amplitude range); a periodic and a non-periodic one differ.

    Parameters
    ----------
    ds : xarray.Dataset
        A two-sweep continuation Dataset.
    k : int
        Grid index.
    a, b : str
        The sweep labels compared.
    tol : float
        Cycle tolerance; default :data:`ATTRACTOR_TOL`.
    nonperiodic_tol : float
        Tolerance of non-periodic attractors (fraction of the amplitude range); default
        :data:`NONPERIODIC_TOL`.

    Returns
    -------
    bool or None
        None where either point diverged.
    """
    return _same(_attractors(ds, a)[k], _attractors(ds, b)[k], _amplitude_range(ds), tol, nonperiodic_tol)


def _disagreeing_runs(ds: xr.Dataset, a: str, b: str) -> list[tuple[int, int]]:
    """Maximal runs (first, last grid index) where sweeps ``a`` and ``b`` end on different attractors."""
    rng = _amplitude_range(ds)
    differ = [
        _same(p, q, rng, ATTRACTOR_TOL, NONPERIODIC_TOL) is False
        for p, q in zip(_attractors(ds, a), _attractors(ds, b))
    ]
    edges = np.diff(np.concatenate([[0], np.asarray(differ, dtype=int), [0]]))
    return [(int(k), int(j) - 1) for k, j in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))]


def _leaving_jumps(
    jumps: list[dict[str, Any]], name: str, x: np.ndarray, sweep: str, rising: bool, k: int, j: int
) -> list[int]:
    """Grid steps (index m of the step x_m → x_{m+1}) where ``sweep`` jumps in the span of the run k … j.

    The span is the run and its two bounding steps (m from k − 1 to j); ``rising`` picks the sweep's
    direction of travel (the up sweep leaves its attractor at the run's upper end, the down sweep at
    its lower end).
    """
    index = {float(v): i for i, v in enumerate(x)}
    steps = []
    for jp in jumps:
        if jp.get("sweep") != sweep:
            continue
        a, b = index.get(float(jp[f"{name}_from"])), index.get(float(jp[f"{name}_to"]))
        if a is None or b is None or abs(a - b) != 1 or (b > a) != rising:
            continue
        m = min(a, b)
        if k - 1 <= m <= j:
            steps.append(m)
    return sorted(steps)


def coexistence_intervals(
    ds: xr.Dataset, a: str = "up", b: str = "down", jumps: list[dict[str, Any]] | None = None
) -> tuple[list[list[float]], list[list[float]]]:
    """The intervals where sweeps ``a`` and ``b`` end on different attractors, split by whether a jump bounds them.

    A maximal run of grid points x_k … x_j where the sweeps disagree is bounded by the grid steps
    (x_{k−1}, x_k) and (x_j, x_{j+1}); the folds where one attractor is born and the other dies lie
    inside those steps.  Its interval is reported from the midpoint of the first step to the midpoint
    of the last — the same midpoints at which :func:`detect_jumps` reports the jumps, so an interval
    and its jumps agree, and a run of one grid point gives an interval one grid step wide (not a
    zero-width one); at an end of the grid the interval ends at that grid point.

    The run is a **hysteresis** loop when the sweep that leaves its attractor at one of its ends
    jumps there: sweep ``a`` (rising) in a step at the run's upper end, or sweep ``b`` (falling)
    at its lower end.  Such a jump is taken in the run's bounding step or in a step inside the run
    (the point a sweep reaches just after its jump may not have settled on the attractor it jumped
    to, and so still differ from the other sweep there); the loop then runs from the down jump's
    midpoint to the up jump's (the run's bound where that end has no such jump), and any part of the
    run beyond a jump is listed as coexistence.  A run with a jump of either sweep in a bounding
    step is hysteresis too.

    Parameters
    ----------
    ds : xarray.Dataset
        A continuation Dataset with both sweeps.
    a, b : str
        The sweep labels compared: ``a`` runs with rising parameter (``up``), ``b`` falling (``down``).
    jumps : list of dict, optional
        The jumps of the Dataset (default: :func:`detect_jumps` on its ``measure``).

    Returns
    -------
    (hysteresis, coexistence) : two lists of [float, float]
        ``hysteresis``: the loops bounded by a jump (an amplitude jump where a sweep leaves its
        attractor).  ``coexistence``: attractors that differ with no jump in the measure at either
        bound (for example two period-n orbits of equal amplitude, or a point still settling); they
        are coexisting attractors, but no jump shows them.
    """
    labels = [str(s) for s in ds["sweep"].values]
    if a not in labels or b not in labels:
        return [], []
    name = _param(ds)
    x = ds[name].values
    if jumps is None:
        jumps = detect_jumps(ds, str(ds.attrs.get("measure", "amplitude")))
    steps = {frozenset((j[f"{name}_from"], j[f"{name}_to"])) for j in jumps}

    def mid(m: int) -> float:  # midpoint of the step x_m → x_{m+1}, or the grid's end
        return float(0.5 * (x[m] + x[m + 1])) if 0 <= m < x.size - 1 else float(x[min(max(m, 0), x.size - 1)])

    hysteresis: list[list[float]] = []
    coexistence: list[list[float]] = []
    for k, j in _disagreeing_runs(ds, a, b):
        lo, hi = mid(k - 1), mid(j)
        ups = _leaving_jumps(jumps, name, x, a, True, k, j)
        downs = _leaving_jumps(jumps, name, x, b, False, k, j)
        m_hi = ups[-1] if ups else j
        m_lo = downs[0] if downs else k - 1
        if (ups or downs) and m_lo < m_hi:
            if m_lo > k - 1:
                coexistence.append([lo, mid(m_lo)])
            hysteresis.append([mid(m_lo), mid(m_hi)])
            if m_hi < j:
                coexistence.append([mid(m_hi), hi])
            continue
        jumped = (k > 0 and frozenset((float(x[k - 1]), float(x[k]))) in steps) or (
            j + 1 < x.size and frozenset((float(x[j]), float(x[j + 1]))) in steps
        )
        (hysteresis if jumped else coexistence).append([lo, hi])
    return hysteresis, coexistence


def hysteresis_intervals(ds: xr.Dataset, a: str = "up", b: str = "down") -> list[list[float]]:
    """Intervals [ω_a, ω_b] of coexisting attractors bounded by a jump (see :func:`coexistence_intervals`).

    Parameters
    ----------
    ds : xarray.Dataset
        A continuation Dataset.
    a, b : str
        The sweep labels compared.

    Returns
    -------
    list of [float, float]
        Empty when the Dataset does not hold both sweeps.
    """
    return coexistence_intervals(ds, a, b)[0]


@parameters(result_of("frequency_response"))
def response_json(ds: xr.Dataset) -> dict[str, Any]:
    """The ``response --json`` summary: jumps, hysteresis, the grid and each sweep's labels.

    Returns
    -------
    dict
        ``jumps`` [{omega, direction, size, sweep, …}], ``hysteresis`` [[ω_a, ω_b], …],
        ``measure``, the grid under the parameter's name and, per sweep, its amplitudes,
        ``motion``, ``impact`` and ``period``.
    """
    name = _param(ds)
    measure = str(ds.attrs.get("measure", "amplitude"))
    labels = [str(s) for s in ds["sweep"].values]
    out: dict[str, Any] = {
        "jumps": json.loads(ds.attrs.get("jumps", "[]")),
        "hysteresis": json.loads(ds.attrs.get("hysteresis", "[]")),
        "coexistence": json.loads(ds.attrs.get("coexistence", "[]")),
        "measure": measure,
        name: json_values(ds[name]),
    }
    for lab in labels:
        pl = point_labels(ds, lab)
        out[lab] = {
            measure: json_values(ds[measure].sel(sweep=lab)),
            **{k: pl[k] for k in ("motion", "impact", "period")},
        }
    return out
