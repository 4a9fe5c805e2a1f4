"""Harmonic balance with alternating frequency/time evaluation and Hill stability (``docs/hb.md``).

Entry points
------------
:func:`hb_solve`
    One parameter point: Newton on the HB equations with the analytic Jacobian; an
    :class:`HBSolution` with a :class:`~geardyn.status.Status` and Hill's multipliers.
:func:`hb_continuation`
    Pseudo-arclength continuation in any model parameter with folds, period doublings,
    Neimark–Sacker points and grazing located; an :class:`HBContinuation` (``to_dataset()``,
    ``to_json()``).
:func:`hb_response`
    The up/down frequency response read off one branch in the format of ``geardyn response``
    (jumps at the folds, hysteresis between them).
:func:`hill_floquet`
    Hill's method for y'' + c(τ)y' + s(τ)y = 0 from the Fourier coefficients of c and s.
:func:`hb_system_solve`, :func:`hb_system_continuation`
    The same for a multi-DOF system (:mod:`geardyn.systems`): every DOF's harmonics, the elastic multipliers
    (:func:`system_hill_floquet`, the rigid-body modes left out); an :class:`HBSystemSolution` or
    :class:`HBSystemContinuation`.  :func:`hb_response` also takes a system.
"""

from .continuation import HBBifurcation, HBContinuation, hb_continuation
from .hill import HillResult, hill_floquet, hill_matrix
from .response import hb_response, response_from_branch
from .solve import DEFAULT_HARMONICS, HBSolution, HBSystem, hb_solve
from .system import HBSystemEquations, HBSystemSolution, hb_system_solve
from .system_continuation import SYSTEM_DS_MAX, HBSystemContinuation, hb_system_continuation
from .system_hill import system_hill_floquet

__all__ = [
    "DEFAULT_HARMONICS",
    "HBBifurcation",
    "HBContinuation",
    "HBSolution",
    "HBSystem",
    "HillResult",
    "hb_continuation",
    "hb_response",
    "hb_solve",
    "hill_floquet",
    "hill_matrix",
    "response_from_branch",
    "HBSystemContinuation",
    "HBSystemEquations",
    "HBSystemSolution",
    "SYSTEM_DS_MAX",
    "hb_system_continuation",
    "hb_system_solve",
    "system_hill_floquet",
]
