"""Two structural facts that decide several claims, derived and checked numerically.

- **F1** The divergence of the vector field is −2c(θ), whatever the state, so the period map has
  Jacobian determinant exp(−4πξ0/ω) everywhere: it contracts every area, so for ξ0 > 0 there is no
  invariant closed curve and no quasi-periodic attractor; the paper's "quasi-n-periodic" can only
  be period-n.  Checked: the determinant of the computed period-map Jacobian (variational
  equations) at points on periodic and chaotic attractors against exp(−4πξ0/ω).
- **F2** Without back-flank contact (u ≥ −D throughout), f(u; D) = max(u − D, 0) and w = u − D
  obeys an equation free of D: the response does not depend on D (f_p and ε fixed).  Checked: one
  response (from the same state relative to D) at several D, with and without back-flank contact.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ...analysis.classify import IMPACT_LABELS, impact_states
from ...analysis.periodic.map import PeriodMap
from ...integrate import integrate_batch
from ...io import json_attr
from ...model import IntegrationOptions
from ..report import Section
from ..settings import Context
from ..verdicts import yes_no

__all__ = ["F1_TEXT", "F2_TEXT", "F2_D", "f1_check", "f2_check", "study_facts"]

F1_TEXT = (
    "F1 (area contraction). As a first-order system in x = (u, v), u' = v and v' = −2c(θ)v − k(θ)f(u) + F(θ), "
    "with c(θ) = ξ0 + ξ1 cos(θ + φ_c1). The divergence ∂u'/∂u + ∂v'/∂v = −2c(θ) does not depend on the state (f "
    "enters only through u in the v' equation). By Liouville's formula the Jacobian determinant of the period map "
    "P over one forcing period T = 2π/ω is exp(−∫₀ᵀ 2c dτ) = exp(−4πξ0/ω) at every point and in every contact "
    "state (the field is continuous, so no saltation term). For ξ0 > 0, P^n multiplies every area by "
    "exp(−4πnξ0/ω) < 1. An invariant closed curve of P^n would bound a disc that P^n maps onto itself with a smaller "
    "area: impossible. So there are no invariant closed curves, no quasi-periodic attractors, and no Neimark–Sacker "
    "(torus, 'Hopf') bifurcation of a periodic orbit (the product of its two multipliers is that determinant, so a "
    "complex pair lies strictly inside the unit circle). The paper's 'quasi-n-periodic' can only mean period-n; "
    "geardyn reads it so, and any label of closed curves or λ1 ≈ 0 is re-examined by a longer exponent run or shooting."
)
F2_TEXT = (
    "F2 (backlash without back-flank contact). When u ≥ −D throughout, f(u; D) = max(u − D, 0). With w = u − D the "
    "equation reads w'' + 2c(θ)w' + k(θ) max(w, 0) = f_p + f_e(θ), free of D. A response that never touches the "
    "back flank is therefore, translated by D, a response at every D with the same f_p and ε: the same motion, "
    "period, exponents and amplitude. With f_p and ε fixed, as Table 3 does (D = b/(2 mm)), the motion can change "
    "with b while the impacts stay single-sided only by switching between coexisting attractors, and the amplitude "
    "cannot grow with b: the claims that the motion goes quasi-1 → quasi-2 → chaotic with b, that the impacts stay "
    "single-sided, and that the amplitude grows with b cannot all hold."
)

#: F1: the (ξ0, ω, φ_c1) points checked.
F1_POINTS: tuple[tuple[float, float, float], ...] = (
    (0.03, 1.0, 0.0),
    (0.06, 1.0, 0.0),
    (0.1, 1.0, 0.0),
    (0.1, 0.6, 0.0),
    (0.1, 1.4, 0.5 * math.pi),
    (0.3, 1.0, math.pi),
)
#: F2: the D values of the response.
F2_D: tuple[float, ...] = (0.1, 0.35, 0.75, 1.5, 3.0, 7.0, 15.0)
#: F2: the ω of the response.
F2_OMEGA = 1.0


def f1_check(base, transient: int = 300) -> list[dict[str, float]]:
    """det of the period-map Jacobian at a point of the attractor against exp(−4πξ0/ω).

    Parameters
    ----------
    base : GearModel
    transient : int
        Periods integrated from rest to reach the attractor.

    Returns
    -------
    list of dict
        ``xi0``, ``omega``, ``phi_c1``, ``det``, ``theory``, ``rel`` (relative difference), ``u``, ``v``.
    """
    out = []
    for xi0, w, ph in F1_POINTS:
        m = base.replace(xi0=xi0, omega=w).with_param("phi_c1", ph)
        res = integrate_batch([m], (0.0, 0.0), IntegrationOptions(transient=transient, periods=1))
        x = res.end_state[0]
        J = PeriodMap(m, 1).jacobian(x)
        det, th = float(np.linalg.det(J)), math.exp(-4 * math.pi * xi0 / w)
        out.append(
            {
                "xi0": xi0,
                "omega": w,
                "phi_c1": ph,
                "det": det,
                "theory": th,
                "rel": abs(det - th) / th,
                "u": float(x[0]),
                "v": float(x[1]),
            }
        )
    return out


def f2_check(base, transient: int = 400, periods: int = 64) -> dict[str, np.ndarray]:
    """One response at every D of :data:`F2_D`, each from (u, u') = (D, 0): the same state relative to D.

    Parameters
    ----------
    base : GearModel
    transient, periods : int

    Returns
    -------
    dict of ndarray
        ``D``, ``amplitude``, ``u_min``, ``u_max_rel`` (u_max − D), ``impact`` codes, ``back`` (the back flank touched).
    """
    models = [base.replace(omega=F2_OMEGA, D=d) for d in F2_D]
    s0 = np.array([[d, 0.0] for d in F2_D])
    res = integrate_batch(models, s0, IntegrationOptions(transient=transient, periods=periods))
    D = np.asarray(F2_D)
    return {
        "D": D,
        "amplitude": res.amplitude,
        "u_min": res.u_min,
        "u_max_rel": res.u_max - D,
        "impact": impact_states(res.u_min, D),
        "back": res.u_min < -D,
    }


def study_facts(ctx: Context) -> list[Section]:
    """F1 and F2: the derivations and their numerical checks.

    Parameters
    ----------
    ctx : Context

    Returns
    -------
    list of Section
        F1, then F2, each with its table.
    """
    ctx.log("F1 and F2")
    f1 = f1_check(ctx.base)
    f2 = f2_check(ctx.base)
    ctx.save(
        "facts_f1",
        xr.Dataset(
            {k: ("point", np.array([r[k] for r in f1])) for k in f1[0]},
            attrs={"geardyn_kind": "facts_f1", "model": json_attr(ctx.base)},
        ),
        "F1: period-map Jacobian determinants",
        figures=False,
    )
    ctx.save(
        "facts_f2",
        xr.Dataset(
            {k: ("D", np.asarray(v, dtype=float)) for k, v in f2.items() if k != "D"},
            coords={"D": f2["D"]},
            attrs={"geardyn_kind": "facts_f2", "model": json_attr(ctx.base)},
        ),
        f"F2: one response at several D (ω = {F2_OMEGA:g})",
        figures=False,
    )
    worst = max(r["rel"] for r in f1)
    free = ~f2["back"]
    amp_free = f2["amplitude"][free]
    spread = float(np.ptp(amp_free)) if amp_free.size else float("nan")
    table = [["ξ0", "ω", "φ_c1", "det of the period-map Jacobian", "exp(−4πξ0/ω)", "relative difference"]] + [
        [
            f"{r['xi0']:g}",
            f"{r['omega']:g}",
            f"{r['phi_c1']:.3g}",
            f"{r['det']:.10f}",
            f"{r['theory']:.10f}",
            f"{r['rel']:.1e}",
        ]
        for r in f1
    ]
    t2 = [["D", "amplitude", "u_max − D", "u_min", "impact", "back flank touched"]] + [
        [
            f"{d:g}",
            f"{f2['amplitude'][i]:.12f}",
            f"{f2['u_max_rel'][i]:.12f}",
            f"{f2['u_min'][i]:.4f}",
            IMPACT_LABELS[int(f2["impact"][i])],
            yes_no(f2["back"][i]),
        ]
        for i, d in enumerate(f2["D"])
    ]
    text = [
        F1_TEXT,
        f"F1 checked: at {len(f1)} points on attractors (periodic and chaotic, several ξ0, ω and φ_c1) the determinant "
        f"of the period-map Jacobian from the variational equations equals exp(−4πξ0/ω) to a relative {worst:.1e} "
        "(RK4 with the paper's Δτ = 0.01).",
    ]
    text2 = [
        F2_TEXT,
        f"F2 checked at ω = {F2_OMEGA:g} (Table 1 otherwise), each D from (u, u') = (D, 0): the {int(free.sum())} "
        f"responses that never touch the back flank (D = {', '.join(f'{d:g}' for d in f2['D'][free])}) have the same "
        f"amplitude to {spread:.1e}; those that do (D = {', '.join(f'{d:g}' for d in f2['D'][~free]) or '–'}) differ.",
    ]
    return [
        Section("F1: the period map contracts every area", text, [], [], table),
        Section("F2: without back-flank contact the response does not depend on D", text2, [], [], t2),
    ]
