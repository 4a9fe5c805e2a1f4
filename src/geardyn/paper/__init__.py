"""The paper geardyn reproduces, as data and as studies.

``geardyn reproduce`` reruns every study of "Nonlinear Dynamic Response of Spiral Bevel Gear Pairs
with Time-Varying Backlash" and judges each of its claims:

- :mod:`~geardyn.paper.claims`: every claim with its source, statement and numbers (:data:`CLAIMS`);
- :mod:`~geardyn.paper.table1`: the paper's Table 1 (the model defaults and the packaged gear pair);
- :mod:`~geardyn.paper.verdicts`: how the paper's words are read and verdicts are given;
- :mod:`~geardyn.paper.settings`: the choices the paper leaves open, and the studies' context;
- :mod:`~geardyn.paper.studies`: one module per study (damping, backlash, jumps, formula, stability);
- :mod:`~geardyn.paper.run`: the driver (:func:`geardyn.paper.run.run`);
- :mod:`~geardyn.paper.report`: the report (Markdown, self-contained HTML, JSON).

Importing this package loads only the claims and Table 1; the driver imports the analyses.
"""

from __future__ import annotations

from .claims import CLAIMS, TABLE3, TABLE4, Claim
from .table1 import TABLE1, TABLE1_MODEL

__all__ = ["CLAIMS", "Claim", "TABLE1", "TABLE1_MODEL", "TABLE3", "TABLE4"]
