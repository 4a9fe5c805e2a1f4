"""The report's section on the readings: what was tried for each claim, and how the verdicts came out."""

from __future__ import annotations

from collections.abc import Mapping

from ..readings import BACKLASH_READINGS, PHASES, phase_text
from ..report import Finding, Section, verdict_counts
from ..settings import Context
from ..verdicts import yes_no

__all__ = ["fixed_readings", "readings_section"]


def fixed_readings(findings: Mapping[str, Finding]) -> None:
    """Claims no reading changes (the stability condition): one row, the verdict as computed, the deciding line.

    Parameters
    ----------
    findings : mapping
        By claim id; changed in place where a claim has no readings table yet.
    """
    for f in findings.values():
        if f.readings:
            continue
        f.readings = [
            ["reading", "result", "holds"],
            [
                "the paper's κ1 = 0.2 (no phase, backlash or ω enters the closed form)",
                f.computed,
                yes_no(f.verdict == "reproduced"),
            ],
        ]
        f.deciding = f.deciding or (
            ("holds" if f.verdict == "reproduced" else "fails")
            + " against Floquet multipliers of the full model and of the linear contact model"
        )


def readings_section(ctx: Context, findings: Mapping[str, Finding]) -> Section:
    """What the readings study tried, and per claim how many readings hold and the verdict kind.

    Parameters
    ----------
    ctx : Context
    findings : mapping
        By claim id, with their readings tables.

    Returns
    -------
    Section
    """
    s = ctx.settings
    w = s.readings_omegas
    text = [
        "The paper leaves open the phases of the stiffness and damping variation, how its backlash b in mm becomes "
        "D (f_p, ε1 and b_n of Table 1 kept), and the ω of its damping and backlash studies. Every claim is judged "
        "under the readings it depends on: φ_c1 and φ_k1 over {" + ", ".join(phase_text(p) for p in PHASES) + "} "
        "(each varied alone: 7 pairs), D = "
        + ", ".join(f"b/({v:g} mm)" for v in BACKLASH_READINGS.values())
        + f", and ω over [{w[0]:.2f}, {w[-1]:.2f}] in steps of 0.01 (the jump claims over the responses' ω grid of "
        f"step {(s.response_omega[1] - s.response_omega[0]) / (s.response_num - 1):.2g}).",
        f"The damping and backlash readings are screened in one sweep ({s.readings_transient} transient and "
        f"{s.readings_periods} recorded periods per point, exponents for the points not periodic); the candidates "
        "nearest the default are confirmed by a full computation under the rule applied at the default reading "
        "(whole intervals judged by length, long exponent runs, labels re-examined by a longer run or shooting). The "
        "jump claims and Table 4 are judged on up and down frequency responses under every reading, run in lockstep "
        f"({s.readings_response_transient} transient and {s.readings_response_periods} recorded periods per point, "
        "each point from the previous end state). Each claim's readings table is shown with it.",
    ]
    table = [["claim", "readings (rows)", "holding rows", "verdict", "reading"]]
    for cid, f in findings.items():
        rows = f.readings[1:]
        hold = sum(r[2] in ("yes", "confirmed") for r in rows)
        table.append([cid, str(len(rows)), str(hold), f.verdict, f.reading or "–"])
    text.append("Verdicts: " + verdict_counts(findings.values()) + ".")
    figs = []
    if "readings_damping" in ctx.datasets:
        figs.append(
            (
                ctx.figure("readings_damping"),
                f"Fraction of the readings where each damping and backlash claim holds on the screen, over ω ∈ "
                f"[{w[0]:.2f}, {w[-1]:.2f}] (step 0.01; ξ0 = 0.1, ξ1 = 0.05 unless the claim varies them); the "
                "candidates nearest the default are then confirmed in full",
            )
        )
    return Section("Readings", text, figs, [], table)
