"""The paper's claims, each with its own numbers: what ``geardyn reproduce`` checks.

Every claim is a :class:`Claim`: an id, where the paper makes it (a table row or the study whose text
states it), the statement as the report quotes it, and the numbers the statement carries (parameter
ranges, jump frequencies, table values) as data.  The studies of :mod:`geardyn.paper.studies` read
the numbers from here, compute what geardyn finds, and judge the claim (:meth:`Claim.judge`).
Nothing here is computed.  The paper has no numbered sections or figures: its tables and the study
each sentence belongs to (damping, backlash, jumps, the amplitude formula, the stability condition)
are the sources.

The paper's words for motions are kept as words (``"quasi-4-periodic"``, ``"chaotic"``,
``"quasi-periodic"``); :func:`geardyn.paper.verdicts.motion_rule` says once how each is read.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from .report import Finding

__all__ = ["CLAIMS", "Claim", "TABLE3", "TABLE4", "TABLE_COLUMNS", "claim_ids"]


@dataclass(frozen=True)
class Claim:
    """One claim of the paper with the numbers it states.

    Parameters
    ----------
    id : str
        Short identifier used in the report (``"T2-1"`` is Table 2, row 1).
    source : str
        Where the paper makes the claim: a table row, or the study whose text states it.
    statement : str
        The claim as the report quotes it.
    numbers : mapping, optional
        The paper's numbers and words of the claim, by name: ``param`` with ``lo``/``hi`` (and
        ``lo_open``/``hi_open``) for a range (a missing end is unbounded), ``motion`` for the paper's
        word for a motion, ``omega`` for a jump frequency, ``b`` for a backlash in mm, table values
        by their column.  Stored read-only.
    """

    id: str
    source: str
    statement: str
    numbers: Mapping[str, Any] = field(default_factory=dict, hash=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "numbers", MappingProxyType(dict(self.numbers)))

    def judge(self, computed: str, verdict: str, evidence: Sequence[str]) -> Finding:
        """The report entry for this claim: what geardyn computed and the verdict.

        Parameters
        ----------
        computed : str
            What geardyn finds, in words and numbers.
        verdict : str
            One of :data:`geardyn.paper.report.VERDICTS`.
        evidence : sequence of str
            Paths of the data and figures that show it, relative to the report directory.

        Returns
        -------
        Finding

        Raises
        ------
        ValueError
            If ``verdict`` is not one of the allowed verdicts.
        """
        return Finding(self.id, self.source, self.statement, computed, verdict, list(evidence))


#: The columns of Tables 3 and 4: the names of the numbers of their rows' claims, in the tables' order.
TABLE_COLUMNS: Mapping[int, tuple[str, ...]] = MappingProxyType(
    {3: ("b", "D", "motion", "amplitude", "lyapunov"), 4: ("omega", "xi0", "b", "A", "jump")}
)


def _row(table: int, row: int, statement: str, *values: Any, **numbers: Any) -> Claim:
    """Row ``row`` of Table ``table``: its numbers by name, or as values in the order of :data:`TABLE_COLUMNS`."""
    return Claim(
        f"T{table}-{row}",
        f"Table {table}, row {row}",
        statement,
        dict(zip(TABLE_COLUMNS.get(table, ()), values), **numbers),
    )


_LIST: tuple[Claim, ...] = (
    # Table 2: dynamic states against the damping ratios
    _row(
        2, 1, "ξ0 < 0.064: chaotic motion (high nonlinearity).", param="xi0", hi=0.064, hi_open=True, motion="chaotic"
    ),
    _row(
        2,
        2,
        "0.064 ≤ ξ0 ≤ 0.1: quasi-4-periodic motion (medium nonlinearity).",
        param="xi0",
        lo=0.064,
        hi=0.1,
        motion="quasi-4-periodic",
    ),
    _row(
        2,
        3,
        "ξ0 > 0.1: quasi-2-periodic motion (low nonlinearity).",
        param="xi0",
        lo=0.1,
        lo_open=True,
        motion="quasi-2-periodic",
    ),
    _row(
        2,
        4,
        "ξ1 < 0.03: quasi-periodic motion (low nonlinearity).",
        param="xi1",
        hi=0.03,
        hi_open=True,
        motion="quasi-periodic",
    ),
    _row(2, 5, "ξ1 ≥ 0.05: chaotic motion (high nonlinearity).", param="xi1", lo=0.05, motion="chaotic"),
    Claim(
        "XI0-BIF",
        "text, damping study",
        "As ξ0 increases the motion goes chaos → quasi-4-periodic → quasi-2-periodic → chaos, with bifurcation "
        "points near ξ0 = 0.064 and ξ0 = 0.8.",
        {"param": "xi0", "points": (0.064, 0.8)},
    ),
    Claim(
        "XI1-CHAOS",
        "text, damping study",
        "Increasing ξ1 drives the system from quasi-periodic to chaotic motion.",
        {"param": "xi1"},
    ),
    # Table 3 and the backlash text
    _row(
        3,
        1,
        "b = 0.2 mm (D = 0.1): quasi-1-periodic motion, negative Lyapunov exponent.",
        0.2,
        0.1,
        "quasi-1-periodic",
        "increasing",
        "negative",
    ),
    _row(
        3,
        2,
        "b = 0.7 mm (D = 0.35): quasi-2-periodic motion, Lyapunov exponent near zero.",
        0.7,
        0.35,
        "quasi-2-periodic",
        "moderate",
        "near zero",
    ),
    _row(
        3,
        3,
        "b = 1.5 mm (D = 0.75): chaotic motion, positive Lyapunov exponent.",
        1.5,
        0.75,
        "chaotic",
        "high",
        "positive",
    ),
    Claim(
        "BL-IMPACT",
        "text, backlash study",
        "For b = 0.2, 0.7, 1.5 mm the gear pair always has single-sided impacts; the impact state does not change.",
        {"b": (0.2, 0.7, 1.5), "impact": "single-sided impact"},
    ),
    Claim("BL-AMP", "text and Table 3", "The vibration amplitude grows with backlash."),
    # Jumps
    Claim(
        "JUMP-LOW", "text, jump study", "Below ω = 0.5 the amplitude is steady whatever the damping.", {"omega": 0.5}
    ),
    Claim(
        "JUMP-XI0",
        "text, jump study",
        "Above ω = 0.5 upward jumps occur; their size decreases as ξ0 increases.",
        {"omega": 0.5, "direction": "up"},
    ),
    Claim("JUMP-XI1", "text, jump study", "The upward jump size increases with ξ1.", {"direction": "up"}),
    Claim(
        "JUMP-FLUCT",
        "text, jump study",
        "After the first jump the amplitude fluctuates; fluctuations weaken with higher ξ0 and intensify with higher "
        "ξ1.",
    ),
    Claim("JUMP-057", "text, backlash jumps", "Jumps occur near ω = 0.57 for all backlash values.", {"omega": 0.57}),
    Claim(
        "JUMP-082",
        "text, backlash jumps",
        "For b = 0.5 a downward jump appears at ω = 0.82.",
        {"b": 0.5, "omega": 0.82, "direction": "down"},
    ),
    Claim(
        "JUMP-095",
        "text, backlash jumps",
        "For b = 1.5 an upward jump occurs at ω = 0.95.",
        {"b": 1.5, "omega": 0.95, "direction": "up"},
    ),
    # Table 4: amplitude and jump type at five operating points
    _row(4, 1, "ω = 0.4, ξ0 = 0.08, b = 0.5: amplitude 0.15, no jump.", 0.4, 0.08, 0.5, 0.15, "none"),
    _row(4, 2, "ω = 0.6, ξ0 = 0.08, b = 0.5: amplitude 0.45, upward jump.", 0.6, 0.08, 0.5, 0.45, "upward"),
    _row(4, 3, "ω = 0.6, ξ0 = 0.15, b = 0.5: amplitude 0.30, upward jump.", 0.6, 0.15, 0.5, 0.30, "upward"),
    _row(4, 4, "ω = 0.8, ξ0 = 0.08, b = 0.5: amplitude 0.25, downward jump.", 0.8, 0.08, 0.5, 0.25, "downward"),
    _row(4, 5, "ω = 0.9, ξ0 = 0.08, b = 1.5: amplitude 0.60, upward jump.", 0.9, 0.08, 1.5, 0.60, "upward"),
    # The amplitude formula and the stability condition
    Claim("FORMULA", "amplitude formula", "A(ω, ξ0, b) = A0 + ΔA sin(πω) e^(−ξ0 ω) + β b² describes the amplitude."),
    Claim("STABILITY", "stability condition", "The Hopf bifurcation condition reduces to ξ0 = ½√(1 − κ1²)."),
)

#: Every claim of the paper by id, in the order of the paper.
CLAIMS: Mapping[str, Claim] = MappingProxyType({c.id: c for c in _LIST})


def claim_ids(prefix: str) -> list[str]:
    """Ids of the claims whose id starts with ``prefix`` (``"T3-"``: the rows of Table 3), in order.

    Parameters
    ----------
    prefix : str
        The start of the ids wanted.

    Returns
    -------
    list of str
    """
    return [cid for cid in CLAIMS if cid.startswith(prefix)]


#: Table 3 as rows: b (mm), D, dynamic state, amplitude trend, Lyapunov exponent (from the T3 claims).
TABLE3: tuple[tuple[float, float, str, str, str], ...] = tuple(
    tuple(CLAIMS[c].numbers[k] for k in TABLE_COLUMNS[3]) for c in claim_ids("T3-")
)

#: Table 4 as rows: ω, ξ0, b (mm), amplitude A, jump type (from the T4 claims).
TABLE4: tuple[tuple[float, float, float, float, str], ...] = tuple(
    tuple(CLAIMS[c].numbers[k] for k in TABLE_COLUMNS[4]) for c in claim_ids("T4-")
)
