"""``geardyn reproduce``: the driver of :mod:`geardyn.paper`, under its former name.

The studies, the claims and the report live in :mod:`geardyn.paper`; this module re-exports the
names its callers use.
"""

from __future__ import annotations

from .paper.run import run, run_studies, settings_section, write_outputs
from .paper.settings import Context, Settings
from .paper.studies.formula import fit_formula
from .paper.verdicts import MATCH_PARTLY, MATCH_REPRODUCED, VERDICT_RULES, describe_motion, quasi_n, verdict_of

__all__ = [
    "MATCH_PARTLY",
    "MATCH_REPRODUCED",
    "VERDICT_RULES",
    "Context",
    "Settings",
    "describe_motion",
    "fit_formula",
    "quasi_n",
    "run",
    "run_studies",
    "settings_section",
    "verdict_of",
    "write_outputs",
]
