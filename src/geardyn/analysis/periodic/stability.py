"""The paper's stability condition and the Floquet stability boundaries it is compared with.

The paper states a "Hopf" condition ξ0 = ½√(1 − κ1²) for the stability of the gear pair's
response.  :func:`stability_boundary` gives the ξ0 below which the period-n response of the full
model loses stability (continuation in ξ0 with the first loss of stability located), and
:func:`mathieu_boundary` that of the linear contact model (the damped Mathieu–Hill equation), so
that :func:`compare_stability_condition` can say whether the paper's value is a boundary.  These
functions are about the 1-DOF model's physics (its ξ0, κ1 and contact limit D = 0).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np
import xarray as xr

from ...io import annotate, result_attrs
from ...model import DEFAULT_DTAU, GearModel, ModelError
from .arclength import continue_branch
from .branch import STABILITY_LOSSES
from .map import PeriodMap
from .orbit import shoot

__all__ = [
    "paper_stability_damping",
    "paper_stability_condition",
    "stability_boundary",
    "mathieu_boundary",
    "compare_stability_condition",
    "XI0_SCAN_HIGH",
    "XI0_SCAN_LOW",
]

#: Stability boundary scans in ξ0 start at XI0_SCAN_HIGH (a heavily damped, stable response) and
#: stop at XI0_SCAN_LOW (at ξ0 = 0 the mean damping vanishes, det M = 1, and every orbit is neutral).
XI0_SCAN_HIGH = 0.6
XI0_SCAN_LOW = 1.0e-3


def paper_stability_damping(kappa1: float) -> float:
    """The paper's "Hopf" stability condition ξ0 = ½√(1 − κ1²) (non-dimensional damping ratio).

    Parameters
    ----------
    kappa1 : float
        First stiffness harmonic κ1.

    Returns
    -------
    float
        The critical ξ0.

    Raises
    ------
    ModelError
        If |κ1| > 1.
    """
    k = float(kappa1)
    if not (abs(k) <= 1.0):
        raise ModelError(f"kappa1: the condition ½√(1 − κ1²) needs |κ1| <= 1, got {kappa1!r}")
    return 0.5 * math.sqrt(1.0 - k * k)


def paper_stability_condition(model: GearModel) -> dict[str, Any]:
    """Evaluate the paper's condition for a model: the critical ξ0 and whether ξ0 exceeds it.

    Parameters
    ----------
    model : GearModel
        The model (its κ1 and ξ0).

    Returns
    -------
    dict
        ``kappa1``, ``xi0_paper``, ``xi0``, ``above_paper_condition``.
    """
    crit = paper_stability_damping(model.get("kappa1"))
    return {
        "kappa1": model.get("kappa1"),
        "xi0_paper": crit,
        "xi0": model.get("xi0"),
        "above_paper_condition": bool(model.get("xi0") > crit),
    }


def stability_boundary(
    model: GearModel,
    omegas: Iterable[float],
    *,
    xi0_high: float = XI0_SCAN_HIGH,
    xi0_low: float = XI0_SCAN_LOW,
    n: int = 1,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = False,
) -> xr.Dataset:
    """Floquet stability boundary of the period-n response in ξ0, for each ω.

    At each ω the period-n orbit reached by simulation at ``xi0_high`` (heavily damped, stable) is
    continued in ξ0 down to ``xi0_low``; the first bifurcation at which it loses stability (fold,
    period doubling or Neimark–Sacker) gives the critical ξ0_c(ω): below it the orbit that is
    stable at high damping is no longer stable.  NaN when it stays stable down to ``xi0_low``.

    Parameters
    ----------
    model : GearModel
        The model (its ω and ξ0 are set per scan).
    omegas : iterable of float
        Mesh frequencies.
    xi0_high, xi0_low : float
        Start and end of the scan in ξ0.
    n : int
        Period of the response.
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    accurate : bool
        Split the steps at the contact boundaries u = ±D (``IntegrationOptions.accurate``); default False.

    Returns
    -------
    xarray.Dataset
        Over ``omega``: ``xi0_critical``, ``bifurcation_type`` and ``status`` (0 found, or stable
        throughout; 1 the start orbit was not found or the scan stopped early).
    """
    om = np.asarray(list(omegas), dtype=float)
    crit = np.full(om.size, np.nan)
    kinds = np.array([""] * om.size, dtype=object)
    status = np.zeros(om.size, dtype=np.int64)
    for i, w in enumerate(om):
        m = model.with_param("omega", float(w)).with_param("xi0", xi0_high)
        orb = shoot(m, n, dtau=dtau, accurate=accurate)
        if not orb.converged or not orb.stable:
            status[i] = 1
            kinds[i] = "start orbit not found" if not orb.converged else "start orbit unstable"
            continue
        br = continue_branch(orb, "xi0", xi0_low, start_bound=xi0_high, stop_on_instability=True)
        lost = [b for b in br.bifurcations if b.type in STABILITY_LOSSES and b.stable_before]
        if lost:
            crit[i] = lost[0].value
            kinds[i] = lost[0].type
        elif br.values.min() > xi0_low + 1e-9 * (xi0_high - xi0_low):
            status[i] = 1
            kinds[i] = f"scan incomplete ({br.end})"
        else:
            kinds[i] = "stable"

    ds = xr.Dataset(
        {"xi0_critical": ("omega", crit), "bifurcation_type": ("omega", kinds), "status": ("omega", status)},
        coords={"omega": om},
        attrs=result_attrs(
            "stability_boundary",
            model,
            {"dtau": dtau, "accurate": accurate, "n": n},
            xi0_high=str(xi0_high),
            xi0_low=str(xi0_low),
        ),
    )
    return annotate(ds, names=["xi0_critical", "bifurcation_type"])


def mathieu_boundary(
    model: GearModel, omegas: Iterable[float], *, dtau: float = DEFAULT_DTAU, xi0_max: float = 1.0, tol: float = 1e-8
) -> xr.Dataset:
    """Floquet stability boundary of the linear contact model (D = 0, no load, no STE; the damped
    Mathieu–Hill equation u'' + 2ξ(θ)u' + k(θ)u = 0 with the model's ξ_k, κ_r): for each ω the
    smallest ξ0 above which u = 0 is stable (bisection on max|μ| = 1; 0 where it is stable already at
    ξ0 = XI0_SCAN_LOW, i.e. outside the parametric instability tongues).

    Parameters
    ----------
    model : GearModel
        The model (its damping and stiffness harmonics are kept).
    omegas : iterable of float
        Mesh frequencies.
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    xi0_max : float
        Upper end of the bisection in ξ0 (NaN where it is still unstable there).
    tol : float
        Bisection tolerance in ξ0.

    Returns
    -------
    xarray.Dataset
        ``xi0_critical`` over ``omega``.

    References
    ----------
    A. H. Nayfeh and D. T. Mook, *Nonlinear Oscillations*, Wiley, 1979 (the damped Mathieu
    equation and its instability tongues).
    """
    om = np.asarray(list(omegas), dtype=float)
    crit = np.zeros(om.size)
    lin = model.replace(D=0.0, fp=0.0, eps=(), phi_e=())  # the 1-DOF model's linear contact limit
    for i, w in enumerate(om):

        def rho(xi0: float) -> float:
            pmap = PeriodMap(lin.with_param("omega", float(w)).with_param("xi0", xi0), 1, dtau=dtau)
            ev = pmap.evaluate(np.zeros(pmap.dim))
            return float(np.max(np.abs(np.linalg.eigvals(ev.monodromy)))) if ev.ok else math.inf

        if rho(XI0_SCAN_LOW) < 1.0:
            crit[i] = 0.0  # stable for every positive damping in the scan (outside the instability tongues)
            continue
        lo, hi = 0.0, xi0_max
        if rho(hi) >= 1.0:
            crit[i] = math.nan
            continue
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            if rho(mid) >= 1.0:
                lo = mid
            else:
                hi = mid
        crit[i] = 0.5 * (lo + hi)

    ds = xr.Dataset(
        {"xi0_critical": ("omega", crit)},
        coords={"omega": om},
        attrs=result_attrs("mathieu_boundary", lin, {"dtau": dtau}),
    )
    return annotate(ds, names=["xi0_critical"])


def compare_stability_condition(
    model: GearModel,
    omegas: Iterable[float],
    *,
    dtau: float = DEFAULT_DTAU,
    xi0_high: float = XI0_SCAN_HIGH,
    xi0_low: float = XI0_SCAN_LOW,
) -> xr.Dataset:
    """The paper's condition ξ0 = ½√(1 − κ1²) against the Floquet stability boundaries.

    Returns one Dataset over ``omega`` with ``xi0_critical`` (period-1 response of the full model,
    :func:`stability_boundary`), ``xi0_critical_linear`` (linear contact model, :func:`mathieu_boundary`)
    and, in the attributes, ``xi0_paper`` and the largest critical values over the ω grid with
    where they occur, so a report can say whether the paper's value is a stability boundary.

    Parameters
    ----------
    model : GearModel
        The model.
    omegas : iterable of float
        Mesh frequencies.
    dtau : float
        Target step Δτ; default :data:`~geardyn.model.DEFAULT_DTAU`.
    xi0_high, xi0_low : float
        The ξ0 scan of :func:`stability_boundary`.

    Returns
    -------
    xarray.Dataset
        ``xi0_critical``, ``xi0_critical_linear``, ``xi0_paper`` and the maxima in the attributes.
    """
    om = np.asarray(list(omegas), dtype=float)
    nl = stability_boundary(model, om, xi0_high=xi0_high, xi0_low=xi0_low, dtau=dtau)
    lin = mathieu_boundary(model, om, dtau=dtau)
    paper = paper_stability_damping(model.get("kappa1"))
    ds = nl
    ds["xi0_critical_linear"] = ("omega", lin["xi0_critical"].values)
    ds["xi0_paper"] = xr.DataArray(paper)

    ds.attrs["xi0_paper"] = str(paper)
    for key, crit in (("", nl["xi0_critical"].values), ("_linear", lin["xi0_critical"].values)):
        i = int(np.nanargmax(crit)) if np.any(np.isfinite(crit)) else None  # the largest critical value and its ω
        for k, v in ((key, crit), (key + "_at_omega", om)):
            ds.attrs["max_xi0_critical" + k] = "null" if i is None else str(float(v[i]))
    ds.attrs["geardyn_kind"] = "stability_comparison"
    return annotate(ds, names=["xi0_critical_linear", "xi0_paper"])
