"""The backlash study: Table 3 and the text on the impact state and the amplitude (BL-IMPACT, BL-AMP).

The paper gives backlash b in mm and pairs it with non-dimensional D = b/(2 mm) (Table 3); the
study takes those D at the ω of the damping study (the default reading); the other readings (ω,
phases, D = b or b/0.1 mm) are tried by :mod:`geardyn.paper.studies.readings`.
"""

from __future__ import annotations

import numpy as np

from ...analysis.classify import IMPACT_LABELS
from ...analysis.confirm import confirm_sweep
from ..claims import CLAIMS, TABLE3, claim_ids
from ..report import Section
from ..settings import Context, model_text
from ..verdicts import count_text, describe_motion, motion_fields, motion_rule, parts, yes_no
from .readings import lle_sign_holds

__all__ = ["study_backlash"]


def study_backlash(ctx: Context) -> Section:
    """Table 3 (motion and exponent sign at three backlash values), BL-IMPACT and BL-AMP.

    Parameters
    ----------
    ctx : Context
        Gives ``d_grid`` for the diagram and ``search_omegas`` for the search of the claimed sequence.

    Returns
    -------
    Section
        The claims T3-1 to T3-3, BL-IMPACT and BL-AMP, with Table 3 computed.
    """
    s = ctx.settings
    ctx.log("backlash study")
    Ds = [row[1] for row in TABLE3]
    where = model_text(ctx.base, skip=("D",))
    ds = ctx.bifurcation(ctx.base, "D", s.d_grid, lyapunov=True)
    rel = ctx.save("backlash_bifurcation", ds, f"bifurcation diagram over D ({where})")
    pts = confirm_sweep(
        ctx.bifurcation(
            ctx.base, "D", Ds, lyapunov=True, options=s.options.replace(periods=max(s.periods, 2 * s.settle))
        ),
        ctx.base,
        "D",
        long_periods=s.confirm_periods,
    )
    rel_pts = ctx.save("backlash_table3", pts, f"the Table 3 points D = {', '.join(f'{d:g}' for d in Ds)} ({where})")
    ev = [rel_pts, rel, ctx.figure("backlash_bifurcation"), ctx.figure("backlash_table3")]
    m, n, l = motion_fields(pts)
    lle, err, amp, imp = (pts[k].isel(sweep=0).values for k in ("lle", "lle_err", "amplitude", "impact"))
    claims = []
    table = [["b (mm)", "D", "paper", "geardyn motion", "λ1 (1/τ)", "amplitude", "impact"]]
    for i, (cid, (b, D, motion, _, sign)) in enumerate(zip(claim_ids("T3-"), TABLE3)):
        desc = describe_motion(int(m[i]), int(n[i]), int(l[i]))
        table.append(
            [
                f"{b:g}",
                f"{D:g}",
                motion,
                desc,
                f"{lle[i]:+.4f} ± {err[i]:.1e}",
                f"{amp[i]:.3f}",
                IMPACT_LABELS[int(imp[i])],
            ]
        )
        ok_state = motion_rule(motion)[0](int(m[i]), int(n[i]), int(l[i]))
        ok_sign = bool(lle_sign_holds(sign, lle[i], err[i]))
        claims.append(
            CLAIMS[cid].judge(
                f"at ω = {s.omega_damping:g}: {desc}, λ1 = {lle[i]:+.4f} ± {err[i]:.1e} (claimed {sign}); "
                f"parts holding: {count_text(ok_state + ok_sign, 2, '')}; motion: {yes_no(ok_state)}, "
                f"exponent sign: {yes_no(ok_sign)}.",
                parts(ok_state, ok_sign),
                ev,
            )
        )
    nD = len(Ds)
    claimed_impact = CLAIMS["BL-IMPACT"].numbers["impact"]
    n_single = sum(IMPACT_LABELS[int(x)] == claimed_impact for x in imp)
    text = (
        f"at ω = {s.omega_damping:g}: impacts "
        + ", ".join(f"{IMPACT_LABELS[int(x)]} (D = {d:g})" for x, d in zip(imp, Ds))
        + f"; {claimed_impact} at {count_text(n_single, nD, 'backlash values')}"
    )
    claims.append(CLAIMS["BL-IMPACT"].judge(text + ".", parts(n_single == nD), ev))
    grows = bool(np.all(np.diff(amp) > 0))
    text = (
        f"at ω = {s.omega_damping:g}: amplitudes "
        + ", ".join(f"{a:.3f}" for a in amp)
        + f" for D = {', '.join(f'{d:g}' for d in Ds)} ({'growing' if grows else 'not growing'} with D)"
    )
    claims.append(CLAIMS["BL-AMP"].judge(text + ".", parts(grows), ev))
    return Section(
        "Backlash (Table 3)",
        [
            f"The paper pairs b = {', '.join(f'{row[0]:g}' for row in TABLE3)} mm with "
            f"D = {', '.join(f'{d:g}' for d in Ds)}, "
            "i.e. D = b/(2 mm) with f_p and ε1 fixed (a fixed length scale b_c = 1 mm, not b_c = b_n); this study uses "
            f"that reading at ω = {s.omega_damping:g}. Amplitude = half peak-to-peak of u over the recorded periods."
        ],
        [
            (ev[2], f"Bifurcation diagram over the backlash D with the largest Lyapunov exponent, {where}"),
            (
                ev[3],
                f"The Table 3 points D = {', '.join(f'{d:g}' for d in Ds)} with their Lyapunov exponents "
                f"({max(s.periods, 2 * s.settle)} recorded periods), {where}",
            ),
        ],
        claims,
        table,
    )
