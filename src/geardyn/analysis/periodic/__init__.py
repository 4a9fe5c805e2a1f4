"""Periodic orbits: the period map, shooting, Floquet analysis, continuation, bifurcations.

A period-n orbit of the forced gear pair is a fixed point of the n-period stroboscopic map
P^n (section θ ≡ 0 mod 2π).  Everything here works on that map, :class:`PeriodMap`, which
evaluates P^n through the one kernel (:mod:`geardyn.integrate`) together with its Jacobian, the
monodromy matrix M, by tangent propagation.  In the default integration mode M is the exact
Jacobian of the discrete map, so Newton's method converges quadratically; in the accurate mode
(steps split at u = ±D) it is the Jacobian of the split steps with the crossing times frozen,
which is accurate to the integration error.

Modules
-------
:mod:`.map`
    :class:`PeriodMap` (P^n, its Jacobian, its parameter derivative, ``with_param``) and
    :class:`MapEvaluation`.
:mod:`.floquet`
    :func:`floquet`: multipliers μ (eigenvalues of M), Floquet exponents ln|μ|/(nT) per unit τ,
    stability and the type of instability (:class:`Floquet`).
:mod:`.orbit`
    :func:`shoot`: Newton on P^n(x) − x = 0 (damped by backtracking), with a guess from
    simulation when none is given; returns a :class:`PeriodicOrbit`.  :func:`orbit_extrema`.
:mod:`.branch`, :mod:`.arclength`, :mod:`.continuation`
    :func:`continuation`: pseudo-arclength continuation of a branch of period-n orbits in any
    model parameter (``omega``, ``xi0``, ``kappa1``, ``fp``, ``D``, ...), around folds, with
    detection and location of folds (a multiplier through +1), period doublings (through −1),
    Neimark–Sacker points (a complex pair through the unit circle) and grazing (min or max of u
    over the orbit touching ±D); branch switching at period doublings onto the period-2n branch.
:mod:`.stability`
    The paper's stability condition ξ0 = ½√(1 − κ1²) (:func:`paper_stability_damping`) and the
    stability boundaries Floquet analysis gives (:func:`stability_boundary`,
    :func:`mathieu_boundary`, :func:`compare_stability_condition`), for comparison.

All quantities are non-dimensional (displacements in units of the characteristic length b_c,
time τ in units of 1/ω_n).  No function here changes numba's thread setting: every map
evaluation asks :mod:`geardyn.integrate` for one thread for that call only.
"""

from __future__ import annotations

from .arclength import continue_branch
from .branch import BIFURCATION_TYPES, Bifurcation, Branch
from .continuation import ContinuationResult, continuation, switch_at_period_doubling
from .floquet import INSTABILITY_TYPES, Floquet, floquet
from .map import MapEvaluation, PeriodMap
from .orbit import PeriodicOrbit, guess_from_simulation, orbit_extrema, orbit_status_label, shoot
from .stability import (
    compare_stability_condition,
    mathieu_boundary,
    paper_stability_condition,
    paper_stability_damping,
    stability_boundary,
)

__all__ = [
    "PeriodMap",
    "MapEvaluation",
    "PeriodicOrbit",
    "Floquet",
    "Bifurcation",
    "Branch",
    "ContinuationResult",
    "shoot",
    "guess_from_simulation",
    "floquet",
    "continuation",
    "continue_branch",
    "switch_at_period_doubling",
    "orbit_extrema",
    "orbit_status_label",
    "paper_stability_damping",
    "paper_stability_condition",
    "stability_boundary",
    "mathieu_boundary",
    "compare_stability_condition",
    "BIFURCATION_TYPES",
    "INSTABILITY_TYPES",
]
