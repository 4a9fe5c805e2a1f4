"""The paper's claims, as data: what ``geardyn reproduce`` checks.

Each entry is (id, source, statement).  The studies in :mod:`geardyn.reproduce` compute what
geardyn finds for each and give a verdict.  Nothing here is computed.
"""

from __future__ import annotations

#: The paper's Table 1 mesh values (non-dimensional; ω is not given there).
TABLE1 = {"xi0": 0.1, "xi1": 0.05, "kappa1": 0.2, "fp": 0.2, "eps1": 0.5, "D": 1.0}

#: Table 3: backlash in mm and the non-dimensional values the paper pairs with them (D = b/2 mm).
TABLE3 = [
    # b (mm), D, dynamic state, amplitude trend, Lyapunov exponent
    (0.2, 0.1, "quasi-1-periodic", "increasing", "negative"),
    (0.7, 0.35, "quasi-2-periodic", "moderate", "near zero"),
    (1.5, 0.75, "chaotic", "high", "positive"),
]

#: Table 4: ω, ξ0, b (mm), amplitude A, jump type.
TABLE4 = [
    (0.4, 0.08, 0.5, 0.15, "none"),
    (0.6, 0.08, 0.5, 0.45, "upward"),
    (0.6, 0.15, 0.5, 0.30, "upward"),
    (0.8, 0.08, 0.5, 0.25, "downward"),
    (0.9, 0.08, 1.5, 0.60, "upward"),
]

CLAIMS: dict[str, tuple[str, str]] = {
    # Table 2
    "T2-1": ("Table 2, row 1", "ξ0 < 0.064: chaotic motion (high nonlinearity)."),
    "T2-2": ("Table 2, row 2", "0.064 ≤ ξ0 ≤ 0.1: quasi-4-periodic motion (medium nonlinearity)."),
    "T2-3": ("Table 2, row 3", "ξ0 > 0.1: quasi-2-periodic motion (low nonlinearity)."),
    "T2-4": ("Table 2, row 4", "ξ1 < 0.03: quasi-periodic motion (low nonlinearity)."),
    "T2-5": ("Table 2, row 5", "ξ1 ≥ 0.05: chaotic motion (high nonlinearity)."),
    "XI0-BIF": (
        "text, damping study",
        "As ξ0 increases the motion goes chaos → quasi-4-periodic → quasi-2-periodic → chaos, with bifurcation "
        "points near ξ0 = 0.064 and ξ0 = 0.8.",
    ),
    "XI1-CHAOS": ("text, damping study", "Increasing ξ1 drives the system from quasi-periodic to chaotic motion."),
    # Table 3 and the backlash text
    "T3-1": ("Table 3, row 1", "b = 0.2 mm (D = 0.1): quasi-1-periodic motion, negative Lyapunov exponent."),
    "T3-2": ("Table 3, row 2", "b = 0.7 mm (D = 0.35): quasi-2-periodic motion, Lyapunov exponent near zero."),
    "T3-3": ("Table 3, row 3", "b = 1.5 mm (D = 0.75): chaotic motion, positive Lyapunov exponent."),
    "BL-IMPACT": (
        "text, backlash study",
        "For b = 0.2, 0.7, 1.5 mm the gear pair always has single-sided impacts; the impact state does not change.",
    ),
    "BL-AMP": ("text and Table 3", "The vibration amplitude grows with backlash."),
    # Jumps
    "JUMP-LOW": ("text, jump study", "Below ω = 0.5 the amplitude is steady whatever the damping."),
    "JUMP-XI0": ("text, jump study", "Above ω = 0.5 upward jumps occur; their size decreases as ξ0 increases."),
    "JUMP-XI1": ("text, jump study", "The upward jump size increases with ξ1."),
    "JUMP-FLUCT": (
        "text, jump study",
        "After the first jump the amplitude fluctuates; fluctuations weaken with higher ξ0 and intensify with higher ξ1.",
    ),
    "JUMP-057": ("text, backlash jumps", "Jumps occur near ω = 0.57 for all backlash values."),
    "JUMP-082": ("text, backlash jumps", "For b = 0.5 a downward jump appears at ω = 0.82."),
    "JUMP-095": ("text, backlash jumps", "For b = 1.5 an upward jump occurs at ω = 0.95."),
    # Table 4
    "T4-1": ("Table 4, row 1", "ω = 0.4, ξ0 = 0.08, b = 0.5: amplitude 0.15, no jump."),
    "T4-2": ("Table 4, row 2", "ω = 0.6, ξ0 = 0.08, b = 0.5: amplitude 0.45, upward jump."),
    "T4-3": ("Table 4, row 3", "ω = 0.6, ξ0 = 0.15, b = 0.5: amplitude 0.30, upward jump."),
    "T4-4": ("Table 4, row 4", "ω = 0.8, ξ0 = 0.08, b = 0.5: amplitude 0.25, downward jump."),
    "T4-5": ("Table 4, row 5", "ω = 0.9, ξ0 = 0.08, b = 1.5: amplitude 0.60, upward jump."),
    # Formula and stability condition
    "FORMULA": (
        "amplitude formula",
        "A(ω, ξ0, b) = A0 + ΔA sin(πω) e^(−ξ0 ω) + β b² describes the amplitude.",
    ),
    "STABILITY": (
        "stability condition",
        "The Hopf bifurcation condition reduces to ξ0 = ½√(1 − κ1²).",
    ),
}
