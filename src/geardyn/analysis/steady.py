"""Steady response of one parameter point: Poincaré points, period, amplitudes, contact and impact.

:func:`summarize_batch` turns a :class:`~geardyn.integrate.BatchResult` into per-point arrays (used
by every sweep); :func:`classify_batch` settles the points that are not yet periodic (further
integration with the tangent equations) and classifies them (:mod:`geardyn.analysis.classify`);
:func:`simulate` runs one point with its time history and returns a :class:`SteadyState` whose
:meth:`~SteadyState.to_dataset` is the ``simulate`` result.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._lazy import lazy_module
from ..integrate import ST_OK, BatchResult, Trajectory, integrate_batch, natural_steps, start_state, trajectory
from ..io import annotate, json_number, result_attrs
from ..model import IntegrationOptions
from ..system import state_names
from .classify import (
    IMPACT_LABELS,
    LLE_FLOOR,
    LLE_SIGMAS,
    MOTION_UNRESOLVED,
    SETTLE_PERIODS,
    SETTLE_ROUNDS,
    SETTLING_RATIO,
    classify_points,
    detect_periods,
    impact_states,
    motion_label,
    period_label,
    quasi_periodic_allowed_batch,
    settling_ratios,
)
from .lyapunov import DEFAULT_BLOCKS, spectrum_from_log
from .settle import classify_budget, decay_rates

xr = lazy_module("xarray")

#: Periods of time history kept by :func:`simulate` (also the spectrum's length: resolution 1/32 order).
HISTORY_PERIODS = 32
#: Tangent vectors of the settling passes: the motion class needs the largest exponent only (a system's λ2 is then
#: not computed, NaN; ``lyapunov`` gives the spectrum; the pair's kernel always propagates both of its two).
CLASSIFY_TANGENTS = 1
#: Highest mesh order kept in the spectrum.
SPECTRUM_MAX_ORDER = 10.0
#: Memory the time history of a mesh-vector system's :func:`simulate` may take (its states and element deflections,
#: bytes): a longer history keeps its last whole reference mesh cycles that fit (a long forcing period's
#: :data:`HISTORY_PERIODS` would take hundreds of GB).
HISTORY_BYTES = 256 * 2**20
#: The reference element's measures of a steady response in its summary.
_MEASURES = ("amplitude", "rms", "mean", "u_min", "u_max")


def history_budget(model: Any, options: IntegrationOptions, history_periods: int) -> tuple[int | None, float | None]:
    """The steps of history :func:`simulate` keeps when ``history_periods`` forcing periods exceed
    :data:`HISTORY_BYTES`: the last whole reference mesh cycles that fit (at least one).

    Parameters
    ----------
    model : System
    options : IntegrationOptions
    history_periods : int
        Forcing periods of history asked for.

    Returns
    -------
    (steps, cycles) : tuple
        ``(None, None)`` when the whole periods fit (or for the pair, whose state is two numbers); else the steps
        kept and the reference mesh cycles they span (steps × P / N, N the steps per forcing period).

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions
    >>> history_budget(GearModel(), IntegrationOptions(), HISTORY_PERIODS)
    (None, None)
    """
    if int(model.state_dim) <= 2:
        return None, None
    hp = int(min(max(history_periods, 1), options.periods))
    N = natural_steps(model, options.dtau)
    per_sample = 8 * (int(model.state_dim) + 2 * len(model.elements))
    if hp * N * per_sample <= HISTORY_BYTES:
        return None, None
    P = int(model.period_multiple() or 1)
    cycles = max(1, int(HISTORY_BYTES // per_sample * P // N))
    steps = min(hp * N - 1, max(1, round(cycles * N / P)))
    return steps, steps * P / N


def summarize_batch(res: BatchResult) -> dict[str, np.ndarray]:
    """Per-point summary arrays of a batch: period, impact, amplitude measures, contact fractions, status.

    Parameters
    ----------
    res : geardyn.integrate.BatchResult
        The batch.

    Returns
    -------
    dict of ndarray
        ``period`` (:func:`~geardyn.analysis.classify.detect_period`, -1 where not ok), ``impact``,
        ``amplitude``, ``rms``, ``mean``, ``u_min``, ``u_max``, ``fraction_<counter>`` for each counter of its
        law (the dead zone's ``fraction_drive``, ``fraction_separation``, ``fraction_back``), ``status`` (all of
        the reference element); for a system of several elements also ``element_u_min``, ``element_u_max``,
        ``element_mean``, ``element_rms`` and ``element_impact`` (P, elements).
    """
    period = np.where(res.status == ST_OK, detect_periods(res.poincare), -1).astype(np.int64)
    u_min = res.u_min
    impact = impact_states(u_min, res.models.reference_gaps())
    out = {
        "period": period,
        "impact": impact,
        "amplitude": res.amplitude,
        "rms": res.rms,
        "mean": res.mean,
        "u_min": u_min,
        "u_max": res.u_max,
        **{f"fraction_{name}": f for name, f in res.law_fractions().items()},
        "status": res.status.astype(np.int64),
    }
    if res.stats.shape[1] > 1:  # every element of a system with several
        lo = res.element_u_min()
        gaps = res.models.element_gaps()
        out.update(
            element_u_min=lo,
            element_u_max=res.element_u_max(),
            element_mean=res.element_mean(),
            element_rms=res.element_rms(),
            element_impact=impact_states(lo, gaps),
        )
    return out


def classify_batch(
    res: Any,
    *,
    settle_periods: int = SETTLE_PERIODS,
    blocks: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    rounds: int = SETTLE_ROUNDS,
) -> dict[str, np.ndarray]:
    """Full per-point classification of a batch: period, motion, impact, amplitudes, exponents.

    Parameters
    ----------
    res : geardyn.integrate.BatchResult
        A batch integrated with or without ``lyapunov=True``.  With it, every point gets its
        exponents from the recorded periods.
    settle_periods : int
        Points whose Poincaré sequence is not periodic are integrated this many further periods
        from their end state with the tangent equations (repeated, up to
        :data:`~geardyn.analysis.classify.SETTLE_ROUNDS` passes, while the sequence still contracts onto a cycle,
        :func:`~geardyn.analysis.classify.settling_ratio` <= :data:`~geardyn.analysis.classify.SETTLING_RATIO`);
        their period, amplitudes, Poincaré points, end state and exponents are then those of the last pass
        (0: no such pass; the motion of a non-periodic point without exponents is then 'unresolved').
    blocks : int, optional
        Blocks for the exponents' uncertainty (default :data:`geardyn.analysis.lyapunov.DEFAULT_BLOCKS`).
    progress : callable, optional
        Called as ``progress(done, total)`` in periods (per point) of the settling passes while they run,
        ``total`` being the periods of the passes begun so far (it grows as a pass begins); the numbers are
        those of a call without it, bit for bit (:func:`~geardyn.integrate.integrate_batch`).
    rounds : int
        The most settling passes (default :data:`~geardyn.analysis.classify.SETTLE_ROUNDS`; a long forcing period's
        budget: :func:`geardyn.analysis.settle.classify_budget`).

    Returns
    -------
    dict of ndarray
        The keys of :func:`summarize_batch` plus ``motion`` (codes),
        ``lle``, ``lle_err``, ``lambda2`` (NaN where not computed), ``curve_dim`` (correlation
        dimension of the section of non-periodic points, else NaN), ``settle_ratio``
        (:func:`~geardyn.analysis.classify.settling_ratio` of non-periodic points, else NaN), ``loops`` (closed
        curves of a quasi-periodic section, else 0), ``settled`` (number of settling passes run),
        ``unsettled`` (bool: the passes ran out while the section still contracted onto a cycle),
        ``poincare`` (P, n, 2) and ``end_state`` (P, 2).
    """
    nb = DEFAULT_BLOCKS if blocks is None else blocks
    models = res.models
    P = len(models)
    T = models.sampling_periods()
    out = summarize_batch(res)
    out["poincare"] = res.poincare.copy()
    out["end_state"] = res.end_state.copy()
    d = res.end_state.shape[1]
    lam = np.full((P, d), np.nan)
    err = np.full((P, d), np.nan)
    if res.lyapunov_log is not None and res.lyapunov_log.shape[1] > 0:
        lam, err = spectrum_from_log(res.lyapunov_log, T, blocks=nb)
    settled = np.zeros(P, dtype=np.int64)
    sections = list(out["poincare"])  # the section of point i: that of its last settling pass, else its recorded one
    need = np.flatnonzero((out["status"] == ST_OK) & (out["period"] == 0))
    n_rec = res.poincare.shape[1]
    max_rounds = int(rounds)
    rounds = 0
    while settle_periods > 0 and need.size and rounds < max_rounds:
        opts = res.options.replace(transient=0, periods=max(int(settle_periods), n_rec))
        ran = rounds * opts.periods
        r2 = integrate_batch(
            models[need],
            out["end_state"][need],
            opts,
            lyapunov=True,
            progress=None if progress is None else (lambda d, n, ran=ran: progress(ran + d, ran + n)),
            tangents=CLASSIFY_TANGENTS,
        )
        s2 = summarize_batch(r2)
        for k, v in s2.items():
            out[k][need] = v
        if n_rec:
            out["poincare"][need] = r2.poincare[:, -n_rec:, :]
        out["end_state"][need] = r2.end_state
        l2, e2 = spectrum_from_log(r2.lyapunov_log, T[need], blocks=nb)
        for a, new in ((lam, l2), (err, e2)):
            a[need] = np.nan  # the leading exponent(s) only (CLASSIFY_TANGENTS; the pair: both)
            a[need, : new.shape[1]] = new
        settled[need] += 1
        rounds += 1
        for i, sec in zip(need, r2.poincare):
            sections[i] = sec
        chaotic = l2[:, 0] > LLE_SIGMAS * e2[:, 0] + LLE_FLOOR  # nothing to settle
        again = (s2["status"] == ST_OK) & (s2["period"] == 0) & ~chaotic
        need = need[again & (settling_ratios(r2.poincare) <= SETTLING_RATIO)]  # still contracting onto a cycle
    unsettled = np.zeros(P, dtype=bool)
    if rounds:  # still contracting onto a cycle when the passes ran out
        unsettled[need] = True
    bad = out["status"] != ST_OK
    lam[bad] = err[bad] = np.nan
    allowed = quasi_periodic_allowed_batch(models)
    with np.errstate(invalid="ignore"):  # a neutral λ1 where a torus is allowed: is it the slowest mode's decay?
        neutral = ~bad & (out["period"] == 0) & allowed & (np.abs(lam[:, 0]) <= LLE_SIGMAS * err[:, 0] + LLE_FLOOR)
    decay = decay_rates(models, np.flatnonzero(neutral))
    cls = classify_points(out["period"], lam[:, 0], err[:, 0], ~bad, sections, allowed, decay)
    out.update(
        motion=cls["motion"],
        lle=lam[:, 0].copy(),
        lle_err=err[:, 0].copy(),
        lambda2=lam[:, 1].copy(),
        curve_dim=cls["curve_dim"],
        settle_ratio=cls["settle_ratio"],
        loops=cls["loops"],
        settled=settled,
        unsettled=unsettled,
    )
    return out


def amplitude_spectrum(u: np.ndarray, periods: float, closed: bool | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Single-sided amplitude spectrum of u sampled uniformly over a whole number of forcing periods.

    Returns ``(order, amplitude)``: frequencies in orders of the mesh frequency (resolution
    1/``periods``) and the amplitude of each cosine component (the mean at order 0).  ``closed``: whether the
    last sample repeats the first (dropped); by default when the length is one more than a multiple of ``periods``.
    """
    x = np.asarray(u, dtype=float)
    drop = x.size % periods == 1 if closed is None else closed
    if x.size > 1 and np.isfinite(x[0]) and drop:
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
    """Steady response of one point of any System (non-dimensional); see :func:`simulate`.

    Attributes
    ----------
    model : System
        The point.
    options : IntegrationOptions
        The options it was integrated with.
    state0 : tuple of float
        The initial state (the full state).
    traj : Trajectory
        The integrated trajectory with its time history.
    summary : dict
        The classification and the reference element's measures.
    extra : dict
        What the system adds (``System.report``: per-mesh entries of a mesh-vector system; empty for the pair).
    history_cycles : float, optional
        The reference mesh cycles the kept history spans when it is shorter than whole forcing periods
        (:func:`history_budget`); None: ``traj.history_periods`` forcing periods.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, SteadyState, simulate
    >>> res = simulate(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=8))
    >>> isinstance(res, SteadyState), res.summary["period"], sorted(res.to_dataset().data_vars)[:2]
    (True, 2, ['delta', 'delta_rate'])
    """

    model: Any
    options: IntegrationOptions
    state0: tuple[float, ...]
    traj: Trajectory
    summary: dict[str, Any]
    extra: dict[str, Any] = field(default_factory=dict)
    history_cycles: float | None = None

    @property
    def poincare(self) -> np.ndarray:
        """Poincaré points of the trajectory (periods, state dimension)."""
        return self.traj.poincare

    def to_json(self) -> dict[str, Any]:
        """The ``simulate --json`` summary (DESIGN §5 keys)."""
        s = self.summary
        pc, m = self.poincare, self.model
        state = {}
        if pc.shape[1] != 2:  # a system: the reference element's (δ, δ') as the pair's (u, u'), the full states beside
            state = {"poincare_state": pc.tolist()}
            pc = m.element_series(pc, 0.0)[:, m.reference, :]
        return {
            "omega": self.model.omega,
            "poincare": pc.tolist(),
            **state,
            **{k: s.get(k) for k in ("motion", "lle", "period", "impact", *_MEASURES, "contact_fractions", "status")},
            **({"notes": s["notes"]} if s.get("notes") else {}),
            **self.extra,
        }

    def to_dataset(self) -> xr.Dataset:
        """Time history (last periods), Poincaré points and spectrum with the model and options as attributes."""
        t = self.traj
        m = self.model
        if self.history_cycles is None:
            order, spec = amplitude_spectrum(t.u, t.history_periods * (m.period_multiple() or 1))
        else:
            order, spec = amplitude_spectrum(t.u, self.history_cycles, closed=True)
        pc = self.poincare
        sec = m.element_series(pc, 0.0)[:, m.reference, :]  # the reference element's (δ, δ') (the pair's (u, u'))
        ds = xr.Dataset(
            {
                "u": ("tau", t.u),
                "v": ("tau", t.v),
                "poincare_u": ("section", sec[:, 0]),
                "poincare_v": ("section", sec[:, 1]),
                "spectrum": ("order", spec),
                # every element's δ, δ' and the full states, for every System (the pair's: its mesh's (u, u'))
                "delta": (("tau", "element"), t.deltas[:, :, 0]),
                "delta_rate": (("tau", "element"), t.deltas[:, :, 1]),
                "poincare": (("section", "state"), pc),
            },
            coords={
                "tau": t.tau,
                "section": np.arange(pc.shape[0]),
                "order": order,
                "element": [e.name for e in m.elements],
                "state": state_names(m, pc.shape[1]),
            },
            attrs=result_attrs(
                "simulate",
                self.model,
                self.options,
                state0=list(self.state0),
                summary=_jsonable(self.summary),
                history_periods=str(t.history_periods),
                **({} if self.history_cycles is None else {"history_cycles": f"{self.history_cycles:.6g}"}),
            ),
        )
        return annotate(ds, names=["section", "element", "state", "delta", "delta_rate", "poincare"])


def _jsonable(d: dict[str, Any]) -> dict[str, Any]:
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in d.items()}


def simulate(
    model: Any,
    options: IntegrationOptions = IntegrationOptions(),
    state0: Sequence[float] | None = None,
    *,
    history_periods: int = HISTORY_PERIODS,
    progress: Callable[[int, int], None] | None = None,
    classify: bool = True,
) -> SteadyState:
    """Integrate one point of any System and summarise its steady response.

    Parameters
    ----------
    model : System
        Non-dimensional model.
    options : IntegrationOptions
        ``transient`` periods are discarded, ``periods`` Poincaré points recorded.
    state0 : (u0, v0) of the reference element, or a full state, optional
        Initial state at θ = 0 (non-dimensional; :func:`geardyn.integrate.start_state`); default
        ``model.initial_state()`` ((0, 0) for the pair).
    history_periods : int
        How many of the last recorded periods keep the full time history (for plots and the spectrum).
    progress : callable, optional
        Called as ``progress(done, total)`` in forcing periods while the point runs: ``total`` is the transient
        plus the recorded periods, and grows by a settling pass's periods when the response is not periodic and
        :func:`classify_batch` integrates on (:func:`~geardyn.integrate.trajectory`); the result is that of a call
        without it, bit for bit.
    classify : bool
        Whether a response found not periodic is classified (:func:`classify_batch`: further periods with the
        leading tangent vector); False leaves its motion 'not periodic' (a plain run).

    Returns
    -------
    SteadyState
        Its ``to_json`` has the keys of ``geardyn simulate --json`` (the reference element's measures; the
        period in forcing periods of the base frequency) plus what ``model.report`` adds.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, simulate
    >>> res = simulate(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=8))
    >>> res.summary["motion"], res.summary["impact"]
    ('period-2', 'single-sided impact')
    """
    s0 = start_state(model, state0)
    hist_steps, hist_cycles = history_budget(model, options, history_periods)
    t = trajectory(model, s0, options, history_periods=history_periods, progress=progress, history_steps=hist_steps)
    arr = summarize_batch(t.summary)
    period = int(arr["period"][0])
    ok = int(arr["status"][0]) == ST_OK
    # Full motion classification; the Lyapunov spectrum is computed (by integrating on from the
    # end state) only when no period was found.
    base = int(options.transient) + int(options.periods)
    n_pass, rounds = classify_budget(model)  # the pair's 4 × 1000 periods; a long forcing period's in mesh cycles
    cls = (
        classify_batch(
            t.summary,
            settle_periods=n_pass,
            rounds=rounds,
            progress=None if progress is None else (lambda d, n: progress(base + d, base + n)),
        )
        if ok and period == 0 and classify
        else None
    )
    if cls is not None:
        period = int(cls["period"][0])
    motion = (
        motion_label(int(cls["motion"][0]), period) if cls is not None else (period_label(period) if ok else "diverged")
    )

    def f(key: str, d: dict[str, np.ndarray] = arr) -> float | None:
        return json_number(d[key][0])

    P = int(model.period_multiple() or 1)  # mesh cycles of the forcing period
    summary = {
        "period": period * P if period > 0 else None,
        "motion": motion,
        "impact": IMPACT_LABELS[int(arr["impact"][0])],
        **{k: f(k) for k in _MEASURES},
        "contact_fractions": {name: f(f"fraction_{name}") for name in model.elements[model.reference].law.counters},
        "status": "ok" if ok else "diverged",
        **{k: None if cls is None else f(k, cls) for k in ("lle", "lle_err")},
    }
    notes = []
    if cls is not None and P > 1 and summary["motion"] == motion_label(MOTION_UNRESOLVED, 0):
        passes = int(cls["settled"][0])
        notes.append(
            f"unresolved: the classification's budget ended before a class was found ({passes} pass(es) of {n_pass} "
            f"forcing periods, {passes * n_pass * P:,} mesh cycles, at most {rounds})"
            + (": the section still contracted onto a cycle" if bool(cls["unsettled"][0]) else "")
            + "; a longer --transient or --periods settles it further"
        )
    if hist_cycles is not None:
        notes.append(
            f"time history: the last {hist_cycles:.6g} reference mesh cycles ({hist_steps:,} steps; "
            f"{HISTORY_BYTES // 2**20} MB at most), not {t.history_periods} forcing periods"
        )
    if notes:
        summary["notes"] = notes
    extra = model.report(t.summary, 0, t.tau, t.deltas)
    return SteadyState(model, options, tuple(float(x) for x in s0), t, summary, extra, hist_cycles)
