"""Harmonic balance with alternating frequency/time evaluation and Floquet stability (``docs/hb.md``), on any
system through its :meth:`hb_form <geardyn.analysis.hb.form.HBForm>` (the pair, multi-DOF systems).

Entry points
------------
:func:`hb_solve`
    One parameter point: Newton on the HB equations with the analytic Jacobian; an :class:`HBSolution` with a
    :class:`~geardyn.status.Status` and the elastic Floquet multipliers.
:func:`hb_continuation`
    Pseudo-arclength continuation in any parameter with folds, period doublings, Neimark–Sacker points and
    grazing located; an :class:`HBContinuation` (``to_dataset()``, ``to_json()``).
:func:`hb_response`
    The up/down frequency response read off one branch in the format of ``geardyn response``.
:func:`hill_floquet`, :func:`system_hill_floquet`
    Hill's method for y'' + c(τ)y' + s(τ)y = 0 from the Fourier coefficients of c and s, and for n coordinates.
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
