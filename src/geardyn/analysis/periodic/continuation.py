"""Continuation of periodic orbits over a parameter interval, with branch switching.

:func:`continuation` shoots the first orbit, continues its branch (:mod:`.branch`) and, at every
period doubling, switches onto the period-2n branch (:func:`switch_at_period_doubling`) and
continues that too, up to a largest period.  :class:`ContinuationResult` holds the branches and
events and writes the ``continuation --json`` summary and the NetCDF Dataset.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from ...model import DEFAULT_DTAU, GearModel, IntegrationOptions, ModelError, canonical_param
from ...status import Status
from ...validate import number
from .arclength import MAX_BRANCH_POINTS, continue_branch, element_extrema
from .branch import Bifurcation, Branch
from .floquet import pairs
from .map import PeriodMap
from .orbit import (
    GUESS_TRANSIENT,
    SHOOT_MAX_ITER,
    SHOOT_TOL,
    PeriodicOrbit,
    _minimal_period,
    _newton,
    _orbit_from_eval,
    shoot,
)

__all__ = ["ContinuationResult", "continuation", "switch_at_period_doubling", "DEFAULT_MAX_PERIOD"]

#: Branch switching at a period doubling: parameter offset (relative to |stop − start|) at which the
#: period-2n orbit is sought, and the trial offsets along the critical eigenvector (times 1 + |x|).
SWITCH_PARAM_REL = 2.0e-3
SWITCH_AMPLITUDES = (3e-3, 1e-2, 3e-2, 1e-1, 3e-1)
#: Largest period reached by branch switching by default.
DEFAULT_MAX_PERIOD = 4
#: A period doubling counts as the end of an already traced period-2n branch when its parameter and
#: state lie this close (relative to |stop − start| and to 1 + |x|) to that branch's merge point.
SAME_EVENT_PARAM_REL = 1.0e-3
SAME_EVENT_STATE_REL = 1.0e-2


def switch_at_period_doubling(
    branch: Branch, bif: Bifurcation, model: GearModel, *, stop: float, start: float, dtau: float, accurate: bool
) -> PeriodicOrbit | None:
    """A period-2n orbit next to a period doubling of a period-n branch (branch switching).

    At the flip point x* the eigenvector e of the multiplier −1 gives the direction in which the
    period-2n orbit emanates (a pitchfork of P^{2n}).  Period-2n orbits are sought by shooting at
    the parameter p* ± δ from x* + a·e for a few offsets a, first on the side where the period-n
    orbit is unstable (supercritical case), then on the other; the first solution whose minimal
    period is 2n is returned (None if there is none).

    Parameters
    ----------
    branch : Branch
        The period-n branch.
    bif : Bifurcation
        Its period doubling.
    model : GearModel
        The model of the continuation (the parameter is set from ``bif``).
    stop, start : float
        The continuation interval (the period-2n orbit is sought inside it).
    dtau, accurate : float, bool
        The step Δτ and integration mode of the branch's period maps.

    Returns
    -------
    PeriodicOrbit or None
        A converged orbit of minimal period 2n.

    References
    ----------
    Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
    (branch switching at a flip point).
    """
    param = branch.param
    n2 = 2 * branch.n
    ev_star = PeriodMap(model.with_param(param, bif.value), branch.n, dtau=dtau, accurate=accurate).evaluate(bif.state)
    if not ev_star.ok:
        return None
    w, V = np.linalg.eig(ev_star.monodromy)
    k = int(np.argmin(np.abs(w + 1.0)))
    e = np.real(V[:, k])
    e = e / np.linalg.norm(e)
    delta = SWITCH_PARAM_REL * abs(stop - start)
    lo, hi = sorted((start, stop))
    first = 1.0
    if None not in (bif.stable_before, bif.stable_after) and bif.stable_before != bif.stable_after:
        # the side where the period-n orbit is unstable first
        first = (1.0 if stop >= start else -1.0) * (1.0 if bif.stable_before else -1.0)
    scale = 1.0 + float(np.linalg.norm(bif.state))
    for sgn in (first, -first):
        p = bif.value + sgn * delta
        if not (lo - 1e-12 <= p <= hi + 1e-12):
            continue
        try:
            pmap = PeriodMap(model.with_param(param, p), n2, dtau=dtau, accurate=accurate)
        except ModelError:
            continue
        for a in SWITCH_AMPLITUDES:
            for s_e in (1.0, -1.0):
                x0 = bif.state + s_e * a * scale * e
                ev, conv, its, res, _status = _newton(
                    pmap, x0, SHOOT_TOL, SHOOT_MAX_ITER, bool(model.rigid_basis().shape[1])
                )
                if not conv:
                    continue
                if _minimal_period(ev.points, n2) == n2:
                    return _orbit_from_eval(pmap, ev, True, Status.OK, its, res)
    return None


@dataclass
class ContinuationResult:
    """Branches and bifurcations of a continuation run (see :func:`continuation`).

    Parameters
    ----------
    model : GearModel
        The model of the run.
    param : str
        The continued parameter.
    start, stop : float
        The interval.
    branches : list of Branch
        The traced branches (0: the primary one).
    dtau : float
        Target step Δτ of the period maps.
    accurate : bool
        Integration mode of the period maps.
    notes : list of str
        Remarks of the run (orbits not found, minimal periods).
    """

    model: GearModel
    param: str
    start: float
    stop: float
    branches: list[Branch]
    dtau: float
    accurate: bool
    notes: list[str] = field(default_factory=list)

    @property
    def bifurcations(self) -> list[Bifurcation]:
        """All events, excluding a period-2n branch's return to the period-n branch (already listed as
        that branch's period doubling), sorted by branch then parameter."""
        return [x for b in self.branches for x in b.bifurcations if x.type != "merge"]

    def of_type(self, typ: str, n: int | None = None) -> list[Bifurcation]:
        """The events of type ``typ`` (on branches of period ``n`` if given)."""
        return [b for b in self.bifurcations if b.type == typ and (n is None or b.n == n)]

    def to_json(self) -> dict[str, Any]:
        """The ``continuation --json`` summary (DESIGN §5): ``branch`` points and ``bifurcations``."""
        pts = []
        for br in self.branches:
            mu = br.multipliers
            st = br.stable
            for i in range(len(br)):
                pts.append(
                    {
                        self.param: float(br.values[i]),
                        "amplitude": float(br.amplitude[i]),
                        "stable": bool(st[i]),
                        "multipliers": pairs(mu[i]),
                        "period": int(br.n),
                        "branch": int(br.index),
                        "state": br.states[i].tolist(),
                        "u_min": float(br.u_min[i]),
                        "u_max": float(br.u_max[i]),
                    }
                )
        return {
            "param": self.param,
            "start": self.start,
            "stop": self.stop,
            "branch": pts,
            "bifurcations": [b.to_json() for b in self.bifurcations],
            "branches": [
                {
                    "branch": b.index,
                    "period": b.n,
                    "points": len(b),
                    "end": b.end,
                    "from": None
                    if b.origin is None
                    else {"type": b.origin.type, self.param: b.origin.value, "branch": b.origin.branch},
                }
                for b in self.branches
            ],
            "notes": self.notes,
        }

    def to_dataset(self) -> xr.Dataset:
        """One Dataset: dimension ``point`` (all branches concatenated, ``branch`` says which),
        ``section`` (section points, NaN-padded to the longest period), ``bifurcation``."""
        from ...io import annotate, result_attrs

        m, P, bifs, brs = self.model, self.param, self.bifurcations, self.branches
        nmax = max([b.n for b in brs] + [1])
        dim = brs[0].multipliers.shape[1]  # (a run has its primary branch, of one point at least)
        n_points = sum(len(b) for b in brs)
        # the reference element's (δ, δ') at the section points, NaN-padded to nmax (at θ = 0, the 1-DOF model's
        # state (u, u'), the variables u and v)
        sec = np.concatenate(
            [
                np.pad(
                    m.element_series(b.points, 0.0)[..., m.reference, :],
                    ((0, 0), (0, nmax - b.n), (0, 0)),
                    constant_values=np.nan,
                )
                for b in brs
            ]
        )
        mu = np.concatenate([b.multipliers for b in brs])

        def cat(k: str, dtype: Any = float) -> tuple[str, np.ndarray]:  # a branch attribute at every point
            return "point", np.concatenate([np.broadcast_to(getattr(b, k), len(b)) for b in brs]).astype(dtype)

        def col(k: str, dtype: Any = float) -> tuple[str, np.ndarray]:  # an attribute of every event
            return "bifurcation", np.array([getattr(b, k) for b in bifs], dtype=dtype)

        bsec = np.array([m.element_series(b.state, 0.0)[m.reference] for b in bifs], dtype=float).reshape(-1, 2)
        ds = xr.Dataset(
            {
                P: cat("values"),
                "branch": cat("index", np.int64),
                "period": cat("n", np.int64),
                "u": ("point", sec[:, 0, 0]),
                "v": ("point", sec[:, 0, 1]),
                "amplitude": cat("amplitude"),
                "u_min": cat("u_min"),
                "u_max": cat("u_max"),
                "stable": cat("stable", np.int8),
                "multiplier_re": (("point", "multiplier"), mu.real),
                "multiplier_im": (("point", "multiplier"), mu.imag),
                "poincare_u": (("point", "section"), sec[..., 0]),
                "poincare_v": (("point", "section"), sec[..., 1]),
                "status": ("point", np.zeros(n_points, dtype=np.int64)),
                "bifurcation_type": col("type", object),
                f"bifurcation_{P}": col("value"),
                "bifurcation_period": col("n", np.int64),
                "bifurcation_branch": col("branch", np.int64),
                "bifurcation_u": ("bifurcation", bsec[:, 0]),
                "bifurcation_v": ("bifurcation", bsec[:, 1]),
                "bifurcation_amplitude": col("amplitude"),
                "bifurcation_detail": col("detail", object),
            },
            coords={
                "point": np.arange(n_points),
                "multiplier": np.arange(dim),
                "section": np.arange(nmax),
                "bifurcation": np.arange(len(bifs)),
            },
            attrs=result_attrs(
                "continuation",
                self.model,
                {"dtau": self.dtau, "accurate": self.accurate},
                param=P,
                start=str(self.start),
                stop=str(self.stop),
                branches=[{"branch": b.index, "period": b.n, "end": b.end} for b in self.branches],
                notes=self.notes,
            ),
        )
        return annotate(ds)


def continuation(
    model: GearModel,
    param: str,
    start: float,
    stop: float,
    n: int = 1,
    guess: Sequence[float] | None = None,
    *,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = True,
    switch: bool = True,
    max_period: int = DEFAULT_MAX_PERIOD,
    ds: float | None = None,
    ds_max: float | None = None,
    max_points: int = MAX_BRANCH_POINTS,
    locate: bool = True,
    state0: Sequence[float] | None = None,
    transient: int = GUESS_TRANSIENT,
    progress: Callable[[float, float], None] | None = None,
) -> ContinuationResult:
    """Pseudo-arclength continuation of period-n orbits in ``param`` from ``start`` to ``stop``.

    Parameters
    ----------
    model : GearModel
        The model; ``param`` is set to ``start`` for the first orbit.
    param : str
        Any model parameter name (``omega``, ``xi0``, ``xi1``, ``kappa1``, ``fp``, ``eps1``/``fe``,
        ``D``/``backlash``, phases ``phi_c1``…).
    start, stop : float
        The interval; ``stop`` may lie below ``start``.
    n : int
        Period of the first branch (forcing periods).
    guess : (u, u'), optional
        Shooting guess at ``start``; by default the attractor reached by simulation from
        ``state0`` (default (0, 0)).
    switch : bool
        Switch at every period doubling onto the period-2n branch (up to ``max_period``) and
        continue it too.
    ds, ds_max : float, optional
        Initial and largest arclength step in (u, u', p/|stop − start|), i.e. with the parameter
        interval scaled to length 1 (defaults DS_INIT and DS_MAX).  Smaller steps resolve closely
        spaced events better.
    locate : bool
        Locate events precisely (secant on test functions); otherwise report the nearer end of the
        step that brackets them.
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    accurate : bool
        Accurate integration mode (the default here: its multipliers vary smoothly along a branch).
    max_period : int
        Largest period reached by switching.
    max_points : int
        Largest number of points per branch.
    state0 : (u, u'), optional
        Start of the simulation that gives the first guess.
    transient : int
        Forcing periods of that simulation (without ``guess``).
    progress : callable, optional
        Called as ``progress(done, total)`` in parameter units while the branches are traced:
        ``total`` is the parameter distance the branches traced so far have to cover (|stop − start|
        for the primary branch, plus, for each switched branch, the distance from its start to its
        end of the interval) and ``done`` the distance covered (never decreasing; see
        :func:`~geardyn.analysis.periodic.continue_branch`).  The last call has ``done`` = ``total``.

    Returns
    -------
    ContinuationResult
        Branches (stable and unstable parts; ``Branch.stable``) and bifurcations: ``fold`` (a
        real multiplier through +1 at a turning point of the branch; the jump points of a
        hysteresis loop), ``period-doubling`` (a real multiplier through −1), ``neimark-sacker``
        (a complex pair through the unit circle; impossible here for ξ0 > 0 since
        |μ1 μ2| = det M = exp(−2ξ0 nT) < 1), ``grazing`` (u_min or u_max of the orbit crossing ±D:
        contact loss or back-side contact begins, the map changes form) and ``branch-point``
        (a multiplier through +1 without a turn; not generic here).

    Raises
    ------
    ModelError
        For a bad parameter name or interval, or when the first orbit cannot be found.

    References
    ----------
    R. Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., Springer, 2010;
    Yu. A. Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., Springer, 2004
    (numerical analysis of bifurcations).

    Examples
    --------
    >>> from geardyn import GearModel, continuation
    >>> res = continuation(GearModel(), "omega", 0.5, 0.6, 1)
    >>> [(b.type, round(b.value, 3)) for b in res.bifurcations]  # the drive side loses contact
    [('grazing', 0.565)]
    """
    param = canonical_param(param)
    number("start", start)
    number("stop", stop)
    if start == stop:
        raise ModelError("stop: must differ from start")
    max_period = max(max_period, n)
    m0 = model.with_param(param, start)
    model.with_param(param, stop)  # validates the far end too
    IntegrationOptions(dtau=dtau).check_for(m0.omega)
    if param == "omega":
        IntegrationOptions(dtau=dtau).check_for(max(start, stop))
    orbit = shoot(m0, n, guess, dtau=dtau, accurate=accurate, state0=state0, transient=transient)
    notes: list[str] = []
    if not orbit.converged:
        raise ModelError(
            f"guess: shooting for the period-{n} orbit at {param} = {start:g} did not converge "
            f"(status {orbit.status_label}); give a better --guess u,v"
        )
    if orbit.minimal_period < n:
        notes.append(f"the starting orbit has minimal period {orbit.minimal_period} < {n}")
    span_done = _SpanProgress(progress)

    def trace(orbit: PeriodicOrbit, stop: float, **kw: Any) -> Branch:
        return continue_branch(
            orbit,
            param,
            stop,
            ds=ds,
            ds_max=ds_max,
            max_points=max_points,
            locate=locate,
            progress=span_done.branch(),
            **kw,
        )

    branches = [trace(orbit, stop, start_bound=start, index=0)]
    span = abs(stop - start)
    lo, hi = sorted((start, stop))
    if switch:
        seen: list[tuple[int, float, np.ndarray]] = []  # (period, value, state) of merge points / sources
        for br in branches:  # (the branches switched to are appended, and visited in turn)
            if 2 * br.n > max_period:
                continue
            for b in br.bifurcations:
                if b.type != "period-doubling":
                    continue
                if any(
                    nn == 2 * br.n
                    and abs(v - b.value) <= SAME_EVENT_PARAM_REL * span
                    and np.linalg.norm(s - b.state) <= SAME_EVENT_STATE_REL * (1 + np.linalg.norm(s))
                    for nn, v, s in seen
                ):
                    continue  # the period-2n branch through this point is already traced
                new = switch_at_period_doubling(br, b, model, stop=stop, start=start, dtau=dtau, accurate=accurate)
                if new is None:
                    notes.append(
                        f"no period-{2 * br.n} orbit found next to the period doubling at {param} = {b.value:.6g}"
                    )
                    continue
                p_new = new.model.get(param)
                away = 1.0 if p_new >= b.value else -1.0
                far, near = (hi, lo) if away > 0 else (lo, hi)
                nb = trace(new, far, start_bound=near, index=len(branches), origin=b, direction=away)
                # the period-doubling point (the period-n orbit traversed twice) at the head of the switched
                # branch, so that the period-2n branch is drawn from where it is born
                _add_point(nb, b, model, dtau, accurate, end=False)
                nb = _append_merge(nb, br, model, dtau, accurate, span)
                branches.append(nb)
                seen.append((2 * br.n, b.value, b.state.copy()))
                for mb in nb.bifurcations:
                    if mb.type == "merge":
                        seen.append((nb.n, mb.value, mb.state.copy()))
    return ContinuationResult(model, param, float(start), float(stop), branches, dtau, accurate, notes)


class _SpanProgress:
    """Adds up the (done, total) reports of the branches of one run for one ``progress(done, total)``."""

    def __init__(self, progress: Callable[[float, float], None] | None) -> None:
        self.progress = progress
        self.done = 0.0
        self.total = 0.0

    def branch(self) -> Callable[[float, float], None] | None:
        """The callback of the next branch (None without ``progress``)."""
        if self.progress is None:
            return None
        base = self.done
        started = [False]

        def report(done: float, total: float) -> None:
            if not started[0]:
                started[0] = True
                self.total += total
            self.done = max(self.done, base + done)
            self.progress(self.done, self.total)

        return report


def _append_merge(br: Branch, parent: Branch, model: GearModel, dtau: float, accurate: bool, span: float) -> Branch:
    """A switched branch that ended by meeting its parent branch: replace the interpolated merge point
    by the parent's period doubling there (located precisely on the parent) and end the branch on it."""
    merges = [b for b in br.bifurcations if b.type == "merge"]
    if not merges:
        return br
    mb = merges[-1]
    pds = [b for b in parent.bifurcations if b.type == "period-doubling"]
    if not pds:
        return br
    pd = min(pds, key=lambda b: abs(b.value - mb.value))
    if abs(pd.value - mb.value) > SAME_EVENT_PARAM_REL * span + 1e-12:
        return br
    mb.value, mb.state, mb.u_min, mb.u_max, mb.located = pd.value, pd.state.copy(), pd.u_min, pd.u_max, pd.located
    M = _add_point(br, pd, model, dtau, accurate, end=True)
    if M is not None:
        Uc = br.elastic
        mb.multipliers = np.sort_complex(np.linalg.eigvals(M if Uc is None else Uc.T @ M @ Uc))[::-1]
    return br


def _add_point(
    br: Branch, b: Bifurcation, model: GearModel, dtau: float, accurate: bool, end: bool
) -> np.ndarray | None:
    """Add the orbit at an event (its value and state) to the branch's end (or head); its monodromy (None, and
    nothing added, where the map fails there)."""
    pmap = PeriodMap(model.with_param(br.param, b.value), br.n, dtau=dtau, accurate=accurate)
    ev = pmap.evaluate(b.state)
    if not ev.ok:
        return None
    new = {
        "values": [b.value],
        "states": b.state[None, :],
        "points": np.vstack([b.state[None, :], ev.points[:-1]])[None],
        "monodromy": ev.monodromy[None],
        "u_min": [b.u_min],
        "u_max": [b.u_max],
        "steps": [pmap.steps],
        "extrema": element_extrema(pmap, b.state)[None],
    }
    for k, v in new.items():
        old = getattr(br, k)
        setattr(br, k, np.concatenate([old, v] if end else [v, old]))
    return ev.monodromy
