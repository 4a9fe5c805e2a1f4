"""The frequency response of an HB branch in the format of ``geardyn response``: up and down sweeps, jumps at
the folds, hysteresis between them (``docs/hb.md``).

The paths of a brute-force response are read off one branch continued in ω from the lowest to the highest ω: the
branch is cut into its **stable segments** (each extended to the located fold, period doubling or Neimark–Sacker
point that ends it, monotone in ω); the **up sweep** starts on the segment the branch starts on and, at a fold,
**jumps** to the stable segment continuing beyond it with the nearest amplitude; at a period doubling or
Neimark–Sacker point it leaves the period-n solutions until the next segment begins; the **down sweep** likewise
from the top.  Where no segment covers an ω the points are ``Status.UNRESOLVED`` with NaN values.  The jumps are at
the exact fold values, the **hysteresis** intervals where the two sweeps are on different stable segments.  Every
grid point is solved by Newton at its ω from the segment's interpolated coefficients.
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ModelError
from ...status import Status
from .aft import signal_extrema
from .continuation import HBBifurcation, HBContinuation, hb_continuation
from .equations import HBEquations, single_thread_blas

__all__ = [
    "MEASURES",
    "STABILITY_EVENTS",
    "decided_stability",
    "hb_response",
    "response_from_branch",
    "stable_segments",
]

#: Response measures (as :data:`geardyn.analysis.response.MEASURES`).
MEASURES = ("amplitude", "rms", "u_max", "u_min", "mean")
#: Events at which a branch changes stability (the ends of its stable segments).
STABILITY_EVENTS = ("fold", "period-doubling", "neimark-sacker")
#: Steps of ω in which a grid point is reached from the nearest branch point when Newton from the interpolated
#: coefficients fails.
WALK_STEPS = 8
#: A sweep's path: its pieces (ω_a, ω_b, the stable segment's index or None), in sweep order.
Pieces = list[tuple[float, float, int | None]]


@dataclass
class Segment:
    """A stable part of an HB branch, monotone in ω (increasing), with its end events."""

    index: int
    omega: np.ndarray
    coefficients: np.ndarray
    amplitude: np.ndarray
    ends: tuple[HBBifurcation | None, HBBifurcation | None]

    def guess(self, w: float) -> np.ndarray:
        """Coefficients interpolated linearly in ω."""
        if self.omega.size == 1:
            return self.coefficients[0].copy()
        j = int(np.clip(np.searchsorted(self.omega, w) - 1, 0, self.omega.size - 2))
        w0, w1 = self.omega[j], self.omega[j + 1]
        t = 0.0 if w1 == w0 else (w - w0) / (w1 - w0)
        return (1 - t) * self.coefficients[j] + t * self.coefficients[j + 1]

    def amplitude_at(self, w: float) -> float:
        return float(np.interp(w, self.omega, self.amplitude))


def _event_between(res: HBContinuation, i: int, j: int) -> HBBifurcation | None:
    """The located stability event on the branch between points i and j (nearest in coefficients)."""
    ai, aj = res.coefficients[i], res.coefficients[j]
    chord = float(np.linalg.norm(aj - ai))
    best, dbest = None, math.inf
    for b in res.bifurcations:
        if b.type in STABILITY_EVENTS and b.coefficients.size >= ai.size:
            bc = b.coefficients[: ai.size]  # a system's event also carries the gauge multipliers
            d = float(np.linalg.norm(bc - ai) + np.linalg.norm(bc - aj))
            best, dbest = (b, d) if d < dbest else (best, dbest)
    return best if dbest <= 1.5 * chord + 1e-12 else None


def _resolved_next(resolved: np.ndarray, i: int, step: int) -> int:
    """The nearest point past i in the direction ``step`` (±1) whose stability is decided (i + step if none is)."""
    j = i + step
    while 0 < j < resolved.size - 1 and not resolved[j]:
        j += step
    return j if resolved[j] else i + step


def decided_stability(res: HBContinuation) -> np.ndarray:
    """Stability per branch point, a point whose multipliers were not resolved taking its neighbours' when they are
    both stable and no stability event is located between them (stability changes only at a fold, a period
    doubling or a Neimark–Sacker point); elsewhere such a point counts as unstable.

    Parameters
    ----------
    res : HBContinuation
    """
    st = np.array(res.stable, dtype=bool)
    for i, j in _runs(res.status != int(Status.OK)):
        if i > 0 and j + 1 < st.size and st[i - 1] and st[j + 1] and _event_between(res, i - 1, j + 1) is None:
            st[i : j + 1] = True
    return st


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of every maximal run of True in ``mask``."""
    d = np.diff(np.concatenate([[0], np.asarray(mask, dtype=int), [0]]))
    return [(int(i), int(j) - 1) for i, j in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1))]


def stable_segments(res: HBContinuation) -> list[Segment]:
    """The stable segments (:class:`Segment`) of a branch in ω (see the module docstring), in branch order.

    Parameters
    ----------
    res : HBContinuation
    """
    if res.param != "omega":
        raise ModelError(f"param: a frequency response needs a branch in omega, got {res.param}")
    st = decided_stability(res)
    P = res.values.size
    resolved = res.status == int(Status.OK)
    runs, dv = [], np.diff(res.values)
    turns = np.flatnonzero(dv[:-1] * dv[1:] < 0) + 1  # split where the branch turns in ω (a stable segment does not)
    for i, j in _runs(st):
        cuts = [i, *turns[(turns > i) & (turns < j)].tolist(), j]
        runs += zip(cuts, cuts[1:])
    out = []
    for i0, i1 in runs:
        w = list(res.values[i0 : i1 + 1])
        a = list(res.coefficients[i0 : i1 + 1])
        amp = list(res.amplitude[i0 : i1 + 1])
        first = _event_between(res, _resolved_next(resolved, i0, -1), i0) if i0 > 0 and not st[i0 - 1] else None
        last = _event_between(res, i1, _resolved_next(resolved, i1, 1)) if i1 + 1 < P and not st[i1 + 1] else None
        rising = w[-1] >= w[0]
        for b, at_start in ((first, True), (last, False)):
            edge = w[0] if at_start else w[-1]
            if b is None or not ((b.value <= edge) if (at_start == rising) else (b.value >= edge)):
                continue  # (an event beyond the segment's end extends it)
            k = 0 if at_start else len(w)
            w.insert(k, b.value), a.insert(k, b.coefficients[: res.coefficients.shape[1]])
            amp.insert(k, 0.5 * (b.u_max - b.u_min))
        W, A, M = np.array(w), np.array(a), np.array(amp)
        ends = (first, last)
        if W[-1] < W[0]:
            W, A, M, ends = W[::-1], A[::-1], M[::-1], (last, first)
        out.append(Segment(len(out), W, A, M, ends))
    return out


def _sweep_paths(segments: list[Segment], lo: float, hi: float) -> dict[str, Pieces]:
    """``{"up": [...], "down": [...]}``: the pieces (ω_a, ω_b, segment index or None) the sweeps over [lo, hi]
    follow, in sweep order; consecutive pieces on two segments are a jump at their common end, a piece with None
    has no stable solution."""
    out = {}
    for lab, d in (("up", 1.0), ("down", -1.0)):
        # in the sweep's coordinate d·ω, increasing along the sweep: every segment spans [a, b)
        span = {s.index: sorted((d * float(s.omega[0]), d * float(s.omega[-1]))) for s in segments}
        x, stop = sorted((d * lo, d * hi))

        def ahead(x: float, exclude: int | None = None) -> list[Segment]:
            """Segments that continue from x in the sweep direction."""
            return [s for s in segments if s.index != exclude and span[s.index][0] <= x < span[s.index][1]]

        pieces: Pieces = []
        cands = ahead(x)
        cur = (min if d > 0 else max)(cands, key=lambda s: s.index) if cands else None
        while x < stop:
            if cur is None:  # on no segment until the next one starts
                e = min([a for a, _ in span.values() if x < a < stop], default=stop)
                nxt = next((s for s in ahead(e) if span[s.index][0] == e), None)
            else:  # to the segment's end, then a jump to the segment beyond it with the nearest amplitude
                e, end = min(span[cur.index][1], stop), cur.ends[d > 0]
                amp = cur.amplitude_at(d * e)
                # after a period doubling or torus the attractor goes on nearby, not period-n; after no located event
                # (the branch's end, or a change of stability that was not located) where it goes is not known: a
                # jump is placed only at a fold
                fold = end is not None and end.type == "fold"
                nxt = min(
                    ahead(e, cur.index) if fold else [], key=lambda s: abs(s.amplitude_at(d * e) - amp), default=None
                )
            pieces.append((d * x, d * e, None if cur is None else cur.index))
            x, cur = e, nxt
        out[lab] = pieces
    return out


def _on(pieces: Pieces, w: float) -> int | None:
    """The segment a sweep is on at ω = w (the first piece containing it, in sweep order)."""
    for a, b, s in pieces:
        if min(a, b) <= w <= max(a, b):
            return s
    return None


def _solution(rd: HBEquations, seg: Segment, x: float) -> tuple[np.ndarray, Status]:
    """The segment's solution at ω = x: Newton from its coefficients interpolated at x or, when that fails (too far
    from it), natural continuation from its nearest point in WALK_STEPS equal steps of ω (then four times as many),
    each Newton started from the previous solution."""
    k, ncoef = int(np.argmin(np.abs(seg.omega - x))), seg.coefficients.shape[1]
    walks = [
        (seg.coefficients[k], np.linspace(float(seg.omega[k]), x, s + 1)[1:]) for s in (WALK_STEPS, 4 * WALK_STEPS)
    ]
    for a, ws in [(seg.guess(x), [x]), *walks]:
        for w in ws:
            a, st = rd.newton(rd.unknowns(a[:ncoef]), float(w))[:2]  # (the gauge multipliers appended)
            if st is not Status.OK:
                break
        if st is Status.OK:
            break
    return a, st


def _measures(basis: Any, a: np.ndarray) -> dict[str, float]:
    H = basis.H
    umin, umax, _, _ = signal_extrema(basis, a)
    rms = math.sqrt(0.5 * float(np.sum(a[1 : H + 1] ** 2 + a[H + 1 :] ** 2)))
    return {"amplitude": 0.5 * (umax - umin), "rms": rms, "mean": float(a[0]), "u_min": umin, "u_max": umax}


def _minimal_period(pu: np.ndarray, pv: np.ndarray, n: int) -> int:
    p = np.array([pu, pv])
    scale = 1.0 + float(np.max(np.abs(p)))
    periods = (d for d in range(1, n + 1) if n % d == 0 and np.all(np.abs(np.roll(p, -d, 1) - p) <= 1e-8 * scale))
    return next(periods, n)


def response_from_branch(res: HBContinuation, omegas: Any, measure: str = "amplitude"):
    """The response Dataset (``geardyn_kind`` ``response``) of an HB branch in ω on the grid ``omegas``.

    Parameters
    ----------
    res : HBContinuation
        A branch continued in ω over (at least) the grid's interval (a system's: the reference mesh's δ).
    omegas : array_like
        Increasing ω grid.
    measure : str
        Amplitude measure of the jumps: one of :data:`MEASURES`.

    Returns
    -------
    xarray.Dataset
        Dims ``sweep`` (up, down), ``omega`` and ``section`` (the n section points); the variables of a
        brute-force response that HB determines (``period``, ``motion``, ``impact``, ``status``,
        ``amplitude``, ``rms``, ``mean``, ``u_min``, ``u_max``, ``poincare_u``, ``poincare_v``; ``lle``
        NaN) and the attributes ``jumps``, ``hysteresis`` (JSON, exact fold values), ``measure``,
        ``method`` = ``hb`` and ``bifurcations`` (the branch's, JSON).

    Raises
    ------
    ModelError
        For an unknown measure or a branch not in ω.
    """
    import xarray as xr

    from ...io import annotate
    from ..classify import MOTION_PERIODIC, MOTION_UNRESOLVED, impact_state

    if measure not in MEASURES:
        raise ModelError(f"measure: must be one of {', '.join(MEASURES)}, got {measure!r}")
    w = np.asarray(omegas, dtype=float)
    segs = stable_segments(res)
    lo, hi = float(w[0]), float(w[-1])
    for seg in segs:  # a branch's first value is start/p_s·p_s: within rounding of the grid's end, it is that end
        for k in (0, -1):
            for x in (lo, hi):
                if abs(seg.omega[k] - x) <= 8.0 * math.ulp(x):
                    seg.omega[k] = x
    paths = _sweep_paths(segs, lo, hi)
    n, H = res.period, res.harmonics
    rd = HBEquations(res.model, H, n, param="omega", samples=res.samples)
    D, basis = float(res.gaps[res.reference]), rd.dbasis
    phis = 2.0 * np.pi * np.arange(n) / n
    shape = (2, w.size)
    f = {k: np.full(shape, np.nan) for k in MEASURES}
    pu, pv = np.full((2, *shape, n), np.nan)
    period, impact, status = (np.full(shape, v, dtype=np.int64) for v in (0, -1, int(Status.UNRESOLVED)))

    @functools.cache
    def solve(s: int, x: float) -> tuple[np.ndarray, Status]:  # (each point once: the sweeps and jumps share it)
        return _solution(rd, segs[s], x)

    with single_thread_blas():
        for r, lab in enumerate(("up", "down")):
            for k, x in enumerate(w.tolist()):
                s = _on(paths[lab], x)
                if s is None:
                    continue
                a, st = solve(s, x)
                status[r, k] = int(st)
                if st is not Status.OK:
                    continue
                u = rd.deflection(a, rd.reference, x)
                vals = _measures(basis, u)
                for key, v in vals.items():
                    f[key][r, k] = v
                pu[r, k] = basis.evaluate(u, phis)
                pv[r, k] = rd.nu(x) * basis.evaluate(u, phis, 1)
                period[r, k] = _minimal_period(pu[r, k], pv[r, k], n)
                impact[r, k] = impact_state(vals["u_min"], D)
        jumps = []
        for lab, d in (("up", 1.0), ("down", -1.0)):  # (d: the sweep's direction)
            pieces = paths[lab]
            for (_a0, x, s0), (_a1, _b1, s1) in zip(pieces, pieces[1:]):
                a_to, st = (None, None) if s0 is None or s1 is None else solve(s1, x)
                if st is not Status.OK:
                    continue
                end = segs[s0].coefficients[-1 if d > 0 else 0]
                m_from, m_to = (_measures(basis, rd.deflection(a, rd.reference, x))[measure] for a in (end, a_to))
                before, after = w[d * w <= d * x], w[d * w > d * x]  # the grid points on either side
                g_from = float(before[np.argmax(d * before)]) if before.size else x
                g_to = float(after[np.argmin(d * after)]) if after.size else x
                jumps.append(
                    dict(omega=x, direction="up" if m_to > m_from else "down", size=abs(m_to - m_from), sweep=lab,
                         omega_from=g_from, omega_to=g_to, amplitude_from=m_from, amplitude_to=m_to)
                )  # fmt: skip
    attrs = dict(param="omega", mode="harmonic balance", sweep="both", method="hb", measure=measure)
    attrs.update(jumps=json.dumps(jumps), hysteresis=json.dumps(_hysteresis(paths)))
    bif = json.dumps(res.bifurcations_json())
    motion = np.where(status == int(Status.OK), MOTION_PERIODIC, MOTION_UNRESOLVED).astype(np.int64)
    sw, ss = ("sweep", "omega"), ("sweep", "omega", "section")
    ds = xr.Dataset(
        {
            "period": (sw, period),
            "motion": (sw, motion),
            "impact": (sw, impact),
            "status": (sw, status),
            **{k: (sw, f[k]) for k in MEASURES},
            "lle": (sw, np.full(shape, np.nan)),
            "poincare_u": (ss, pu),
            "poincare_v": (ss, pv),
        },
        coords={"sweep": ["up", "down"], "omega": w, "section": np.arange(n)},
        attrs=res.attrs(
            "response", {"method": "hb", "harmonics": H, "period": n, "samples": res.samples}, **attrs, bifurcations=bif
        ),
    )
    return annotate(ds)


def _hysteresis(paths: dict[str, Pieces]) -> list[list[float]]:
    """Maximal ω intervals where the sweeps are on different stable segments, or one on a stable segment and
    the other on none (then its attractor is not that period-n solution either)."""
    cuts = sorted({float(v) for lab in paths for a, b, _s in paths[lab] for v in (a, b)})
    out: list[list[float]] = []
    for a, b in zip(cuts, cuts[1:]):
        m = 0.5 * (a + b)
        su, sd = _on(paths["up"], m), _on(paths["down"], m)
        if su != sd:  # on different stable solutions, or on one and not on any period-n solution
            if out and out[-1][1] == a:
                out[-1][1] = b
            else:
                out.append([a, b])
    return out


def hb_response(
    model: Any,
    omega_start: float,
    omega_stop: float,
    num: int,
    *,
    harmonics: int | None = None,
    period: int = 1,
    measure: str = "amplitude",
    guess: Any = None,
    state0: Any = None,
    progress: bool = False,
) -> Any:
    """Up and down frequency response by harmonic balance, in the format of
    :func:`geardyn.analysis.response.frequency_response`.

    Parameters
    ----------
    model : System
        The pair or a multi-DOF system (then the response is its reference mesh's); ω is varied.
    omega_start, omega_stop : float
        The ω interval (> 0); the branch is continued from the lower end.
    num : int
        Grid points of the sweeps (the jumps and hysteresis bounds are exact, not on the grid).
    harmonics, period : int
        H and n of the HB solutions (H default: :func:`~geardyn.analysis.hb.equations.default_harmonics`, 16 for a
        one-cycle model and for a system).
    measure : str
        Amplitude measure: one of :data:`MEASURES`.
    guess : optional
        Start guess at the lower end (as :func:`~geardyn.analysis.hb.continuation.hb_continuation`).
    state0 : optional
        Start of the simulation of the default guess (as :func:`~geardyn.analysis.hb.continuation.hb_continuation`).
    progress : bool
        Show the progress of the continuation on stderr (:func:`geardyn.sweep.progress.task_progress`).

    Returns
    -------
    xarray.Dataset
        See :func:`response_from_branch`.

    Raises
    ------
    ModelError
        For invalid input, a model without damping (no stability can be decided), or when HB does not converge
        at the lower end of the interval.
    """
    from ...sweep.progress import task_progress

    lo, hi = sorted((float(omega_start), float(omega_stop)))
    if not lo > 0:
        raise ModelError(
            f"omega: must be > 0 (mesh frequency ω_e/ω_n), got a range from {omega_start!r} to {omega_stop!r}"
        )
    if measure not in MEASURES:
        raise ModelError(f"measure: must be one of {', '.join(MEASURES)}, got {measure!r}")
    with task_progress("response ω (HB)", unit="Δω traced", enabled=progress) as bar:
        res = hb_continuation(
            model, "omega", lo, hi, harmonics=harmonics, period=period, guess=guess, state0=state0, progress=bar
        )
    if not res.converged:
        raise ModelError(f"omega_start: harmonic balance at omega = {lo:g} did not converge ({res.end})")
    return response_from_branch(res, np.linspace(lo, hi, int(num)), measure)
