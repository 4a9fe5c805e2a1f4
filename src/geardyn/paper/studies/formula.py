"""The amplitude formula A(ω, ξ0, b) = A0 + ΔA sin(πω) e^(−ξ0 ω) + β b², fitted to computed amplitudes."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import xarray as xr

from ...io import json_attr
from ..claims import CLAIMS
from ..report import Section
from ..settings import Context
from ..table1 import TABLE1
from ..verdicts import FORMULA_R2_PARTLY, FORMULA_R2_REPRODUCED, parts
from .jumps import JumpData

__all__ = ["FORMULA_R2_PARTLY", "FORMULA_R2_REPRODUCED", "fit_formula", "fit_responses", "study_formula"]


def fit_formula(omega: np.ndarray, xi0: np.ndarray, b: np.ndarray, A: np.ndarray) -> dict[str, float]:
    """Least-squares fit of A = A0 + ΔA sin(πω) e^(−ξ0 ω) + β b² (linear in A0, ΔA, β).

    Parameters
    ----------
    omega, xi0, b, A : numpy.ndarray
        Frequency, mean damping, backlash (mm) and amplitude of each point; points with a
        non-finite value are left out.

    Returns
    -------
    dict
        ``A0``, ``dA``, ``beta`` (per mm²), ``r2`` (coefficient of determination), ``rmse`` and
        ``n`` (points used).
    """
    X = np.column_stack([np.ones_like(omega), np.sin(np.pi * omega) * np.exp(-xi0 * omega), b**2])
    ok = np.all(np.isfinite(X), axis=1) & np.isfinite(A)
    X, A = X[ok], A[ok]
    coef, *_ = np.linalg.lstsq(X, A, rcond=None)
    res = A - X @ coef
    ss_tot = float(np.sum((A - A.mean()) ** 2))
    r2 = 1.0 - float(np.sum(res**2)) / ss_tot if ss_tot > 0 else float("nan")
    return {
        "A0": float(coef[0]),
        "dA": float(coef[1]),
        "beta": float(coef[2]),
        "r2": r2,
        "rmse": float(np.sqrt(np.mean(res**2))),
        "n": int(ok.sum()),
    }


def fit_responses(
    curves: Iterable[tuple[float, float, float, np.ndarray, np.ndarray]],
) -> tuple[np.ndarray, dict[str, float]]:
    """The formula fitted (:func:`fit_formula`) to the amplitude curves at the Table 1 ξ1.

    Parameters
    ----------
    curves : iterable of (float, float, float, ndarray, ndarray)
        ξ0, ξ1, backlash b (mm), ω grid and amplitude of each curve; those at another ξ1 are left out.

    Returns
    -------
    (ndarray, dict)
        The points fitted (ω, ξ0, b, A per row) and the fit.
    """
    data = np.vstack(
        [
            np.column_stack([w, np.full_like(w, xi0), np.full_like(w, b), a])
            for xi0, xi1, b, w, a in curves
            if xi1 == TABLE1["xi1"]
        ]
    )
    return data, fit_formula(*data.T)


def study_formula(ctx: Context, jd: JumpData) -> Section:
    """The amplitude formula (FORMULA), fitted to the up sweeps of the jump study at the Table 1 ξ1.

    Parameters
    ----------
    ctx : Context
        Where the fitted data is saved.
    jd : JumpData
        The responses fitted (those at the Table 1 ξ1, up sweeps).

    Returns
    -------
    Section
        The FORMULA claim, with the fitted coefficients and R².
    """
    data, fit = fit_responses(
        (xi0, xi1, 2 * D, ds["omega"].values, ds["amplitude"].sel(sweep="up").values)
        for (xi0, xi1, D), ds in jd.responses.items()
    )
    omega, xi0, b_mm, amp = data.T
    ds = xr.Dataset(
        {
            "amplitude": ("point", amp),
            "omega": ("point", omega),
            "xi0": ("point", xi0),
            "b_mm": ("point", b_mm),
        },
        attrs={
            "geardyn_kind": "formula_fit",
            "model": json_attr(ctx.base.replace(xi=(TABLE1["xi1"],))),
            **{k: str(v) for k, v in fit.items()},
        },
    )
    groups = sorted({(float(x), float(b)) for x, b in zip(xi0, b_mm)})
    where = f"ξ1 = {TABLE1['xi1']:g}; (ξ0, b in mm) = " + ", ".join(f"({x:g}, {b:g})" for x, b in groups)
    rel = ctx.save("formula_fit", ds, f"formula fit to the up sweeps ({where})")
    r2 = fit["r2"]
    ev = [rel, ctx.figure("formula_fit")]
    c = CLAIMS["FORMULA"].judge(
        f"least-squares fit to {fit['n']} computed amplitudes (up sweeps, ξ1 = {TABLE1['xi1']:g}, b = 2D mm): "
        f"A0 = {fit['A0']:.3f}, ΔA = {fit['dA']:.3f}, β = {fit['beta']:.3f} per mm²; R² = {r2:.3f}, "
        f"RMS error {fit['rmse']:.3f} (holds from R² ≥ {FORMULA_R2_REPRODUCED:g}).",
        parts(r2 >= FORMULA_R2_REPRODUCED),
        ev,
    )
    return Section(
        "The amplitude formula",
        [
            "The formula is linear in A0, ΔA and β, so they are fitted by linear least squares to the amplitudes of "
            "the up sweeps of the jump study (b = 2D mm); the verdict follows the R² rule of the Settings."
        ],
        [
            (
                ev[1],
                f"Computed amplitudes (markers) against the fitted formula (line) over ω ∈ "
                f"[{ctx.settings.response_omega[0]:g}, {ctx.settings.response_omega[1]:g}], one panel per (ξ0, b) on "
                f"shared axes, each in its own colour, line style and marker; {where}",
            )
        ],
        [c],
    )
