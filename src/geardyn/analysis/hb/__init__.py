"""Harmonic balance with alternating frequency/time evaluation and Floquet stability on any System, through its
:meth:`hb_form` (``docs/hb.md``): :func:`hb_solve` (one point), :func:`hb_continuation` (a branch with its folds,
period doublings, Neimark–Sacker points and grazing located), :func:`hb_response` (the up/down frequency response
read off one branch) and Hill's method (:func:`hill_floquet`, :func:`system_hill_floquet`).
"""

from .continuation import HBBifurcation, HBContinuation, hb_continuation
from .equations import DEFAULT_HARMONICS, HBEquations
from .form import HBForm
from .hill import HillResult, hill_floquet, system_hill_floquet
from .response import hb_response, response_from_branch
from .solve import HBSolution, hb_solve

__all__ = [
    "DEFAULT_HARMONICS",
    "HBBifurcation",
    "HBContinuation",
    "HBEquations",
    "HBForm",
    "HBSolution",
    "HillResult",
    "hb_continuation",
    "hb_response",
    "hb_solve",
    "hill_floquet",
    "response_from_branch",
    "system_hill_floquet",
]
