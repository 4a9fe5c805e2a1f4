"""The readings of the jump claims and Table 4: lockstep frequency responses under every reading.

Every reading (phases varied one at a time over {0, π/2, π, 3π/2} × the three backlash readings)
gets the responses its claims speak of: ξ0 ∈ {0.08, 0.1, 0.15} and ξ1 ∈ {0.03, 0.05, 0.08} at
b = 0.5 mm, and b ∈ {0.2, 0.7, 1.5} mm at ξ0 = 0.08; up and down sweeps over the ω grid of the jump
study (step 0.01), all in one call of the sweep engine (:func:`geardyn.paper.readings.lockstep_responses`).
Each claim is judged under each reading by the rules of :mod:`geardyn.paper.verdicts`, the default
reading (phases 0, D = b/(2 mm)) first.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from ...io import json_attr
from ..claims import CLAIMS, claim_ids
from ..readings import BACKLASH_READINGS, Reading, lockstep_responses, phase_pairs, response_jumps
from ..report import Finding
from ..settings import Context, ResponseKey
from ..table1 import TABLE1
from ..verdicts import (
    FORMULA_R2_REPRODUCED,
    distinct_text,
    fluctuation_trend,
    jump_holds,
    jump_type_at,
    strictly_monotone,
    yes_no,
)
from .formula import fit_responses
from .jumps import JUMP_NEAR, LOW_OMEGA, TABLE4_AMP_REL, TABLE4_NEAR, after_jump, first_up_jump

__all__ = ["JUMP_KEYS", "JumpReadings", "jump_readings", "run_lockstep"]

XI0_KEYS = ((0.08, 0.05, 0.5), (0.1, 0.05, 0.5), (0.15, 0.05, 0.5))
XI1_KEYS = ((0.08, 0.03, 0.5), (0.08, 0.05, 0.5), (0.08, 0.08, 0.5))
B_KEYS = ((0.08, 0.05, 0.2), (0.08, 0.05, 0.5), (0.08, 0.05, 0.7), (0.08, 0.05, 1.5))
#: The responses of each reading: (ξ0, ξ1, b in mm), those with ξ0, ξ1 and b varied, each once.
JUMP_KEYS: tuple[ResponseKey, ...] = tuple(dict.fromkeys(XI0_KEYS + XI1_KEYS + B_KEYS))


def _claim_keys() -> dict[str, set[int]]:
    xi1 = TABLE1["xi1"]

    def ix(*keys: ResponseKey) -> set[int]:
        return {JUMP_KEYS.index(k) for k in keys}

    out = {
        "JUMP-LOW": set(range(len(JUMP_KEYS))),
        "JUMP-XI0": ix(*XI0_KEYS),
        "JUMP-XI1": ix(*XI1_KEYS),
        "JUMP-FLUCT": ix(*XI0_KEYS, *XI1_KEYS),
        "JUMP-057": ix(*B_KEYS),
        "FORMULA": {i for i, k in enumerate(JUMP_KEYS) if k[1] == xi1},
    }
    for cid in ("JUMP-082", "JUMP-095", *claim_ids("T4-")):
        out[cid] = ix((CLAIMS[cid].numbers.get("xi0", 0.08), xi1, CLAIMS[cid].numbers["b"]))
    return out


#: Candidate readings confirmed for a claim judged on one or two responses (one for the others).
CONFIRM_SINGLE = 2
#: The responses each claim is judged on (indices of JUMP_KEYS).
CLAIM_KEYS: dict[str, set[int]] = _claim_keys()
#: A hysteresis below ω = 0.5 (JUMP-LOW): up and down amplitudes differing by this fraction of the response's range.
LOW_DISAGREE = 0.1


@dataclass
class JumpReadings:
    """The lockstep responses: readings, and per reading and key the amplitudes, spreads and jumps.

    Parameters
    ----------
    omega : ndarray (n,)
        The ω grid.
    readings : list of Reading
        The readings, the default among them.
    amplitude, spread : ndarray (reading, key, 2, n)
        Half peak-to-peak amplitude and spread of the Poincaré points, up and down sweeps.
    jumps : list
        Per reading and key (:data:`JUMP_KEYS`), the jumps of the response.
    """

    omega: np.ndarray
    readings: list[Reading]
    amplitude: np.ndarray  # (reading, key, 2, ω)
    spread: np.ndarray
    jumps: list[list[list[dict[str, Any]]]]  # [reading][key] -> jumps


def run_lockstep(
    ctx: Context,
    readings: list[Reading] | None = None,
    options: Any = None,
    name: str = "readings_responses",
    keys: list[set[int]] | None = None,
) -> JumpReadings:
    """Every reading's responses, in one call of the sweep engine.

    Parameters
    ----------
    ctx : Context
    readings : list of Reading, optional
        Default: every phase pair (one phase varied) under every backlash reading, the default first.
    options : IntegrationOptions, optional
        Periods per point (default the settings' ``readings_response_options``).
    name : str
        Name of the saved Dataset.
    keys : list of set of int, optional
        Per reading, the indices of :data:`JUMP_KEYS` to compute (default all); the others are NaN.

    Returns
    -------
    JumpReadings
    """
    s = ctx.settings
    if readings is None:
        readings = [Reading(a, b, key) for key in BACKLASH_READINGS for (a, b) in phase_pairs(False)]
    options = options or s.readings_response_options
    nR, nK = len(readings), len(JUMP_KEYS)
    pairs = [(i, k) for i in range(nR) for k in range(nK) if keys is None or k in keys[i]]
    pts = np.array(
        [[readings[i].phi_c, readings[i].phi_k, *JUMP_KEYS[k][:2], readings[i].D(JUMP_KEYS[k][2])] for i, k in pairs]
    )
    W = np.round(np.linspace(*s.response_omega, s.response_num), 6)
    ctx.log(f"readings responses: {pts.shape[0]} up/down sweeps of {W.size} ω each")
    r = lockstep_responses(ctx.base, ("phi_c1", "phi_k1", "xi0", "xi1", "D"), pts, W, options, ctx.executor)
    amp, spread = np.full((2, nR, nK, 2, W.size), np.nan)
    ii, kk = np.array(pairs).T
    amp[ii, kk], spread[ii, kk] = r["amplitude"], r["spread"]
    jumps = [
        [response_jumps(W, amp[i, k]) if np.isfinite(amp[i, k]).any() else [] for k in range(nK)] for i in range(nR)
    ]
    ctx.save(
        name,
        xr.Dataset(
            {k: (("reading", "key", "sweep", "omega"), v) for k, v in (("amplitude", amp), ("spread", spread))},
            coords={
                "reading": [rd.text for rd in readings],
                "key": [f"ξ0 = {a:g}, ξ1 = {b:g}, b = {c:g} mm" for a, b, c in JUMP_KEYS],
                "sweep": ["up", "down"],
                "omega": W,
            },
            attrs={"geardyn_kind": "readings_responses", "model": json_attr(ctx.base)},
        ),
        f"frequency responses under {nR} readings ({nR * nK} up/down sweeps, ω step {W[1] - W[0]:.2f}, "
        f"{options.transient} transient and {options.periods} recorded periods per point)",
        figures=False,
    )
    return JumpReadings(W, readings, amp, spread, jumps)


def _fluct(jr: JumpReadings, i: int, k: int) -> float:
    v = jr.spread[i, k, 0, jr.omega > after_jump(jr.jumps[i][k])]
    return float(np.nanmean(v)) if v.size else float("nan")


def _test(jr: JumpReadings, cid: str, i: int) -> tuple[bool, str]:
    """Claim ``cid`` under reading i of the lockstep responses: (holds, result)."""
    K, W, js, n = JUMP_KEYS.index, jr.omega, jr.jumps[i], CLAIMS[cid].numbers
    if cid == "JUMP-LOW":
        sel = W < LOW_OMEGA
        bad = sum(
            any(j["omega"] < LOW_OMEGA for j in jk)
            or bool(np.any(np.abs(a[0, sel] - a[1, sel]) > LOW_DISAGREE * (float(np.nanmax(a) - np.nanmin(a)) or 1.0)))
            for jk, a in zip(js, jr.amplitude[i])
        )
        return not bad, f"steady below ω = {LOW_OMEGA:g} in {len(JUMP_KEYS) - bad} of {len(JUMP_KEYS)} responses"
    if cid in ("JUMP-XI0", "JUMP-XI1"):
        keys, lab, pos = (XI0_KEYS, "ξ0", 0) if cid == "JUMP-XI0" else (XI1_KEYS, "ξ1", 1)
        first = [first_up_jump(js[K(k)]) for k in keys]
        if not all(first):
            return False, f"an upward jump above ω = {LOW_OMEGA:g} in {sum(map(bool, first))} of {len(first)} responses"
        sz = [j["size"] for j in first]  # type: ignore[index]
        return strictly_monotone(sz, pos == 0), "sizes " + ", ".join(
            f"{lab} = {k[pos]:g}: {v}" for k, v in zip(keys, distinct_text(sz))
        )
    if cid == "JUMP-FLUCT":
        f0, f1 = ([_fluct(jr, i, K(k)) for k in keys] for keys in (XI0_KEYS, XI1_KEYS))
        (ok0, why0), (ok1, why1) = fluctuation_trend(f0, True), fluctuation_trend(f1, False)
        return ok0 and ok1, (
            f"spread over ξ0 {', '.join(distinct_text(f0))} ({why0}); over ξ1 {', '.join(distinct_text(f1))} ({why1})"
        )
    if cid == "JUMP-057":
        first = [first_up_jump(js[K(k)]) for k in B_KEYS]
        ok = all(j is not None and abs(j["omega"] - n["omega"]) <= JUMP_NEAR for j in first)
        return ok, "first upward jumps at ω = " + ", ".join(f"{j['omega']:.3f}" if j else "–" for j in first)
    if cid == "FORMULA":
        _, fit = fit_responses((*key, W, jr.amplitude[i, k, 0]) for k, key in enumerate(JUMP_KEYS))
        return fit["r2"] >= FORMULA_R2_REPRODUCED, f"R² = {fit['r2']:.3f} ({jr.readings[i].backlash})"
    w = n["omega"]  # JUMP-082, JUMP-095 and Table 4: a jump (and an amplitude) at ω on one response
    (k,) = CLAIM_KEYS[cid]
    jk = js[k]
    if cid.startswith("JUMP-"):
        return jump_holds(
            jk, w, n["direction"], JUMP_NEAR
        ), f"jump at ω = {w:g} ± {JUMP_NEAR:g}: {jump_type_at(jk, w, JUMP_NEAR)}"
    a = jr.amplitude[i, k, :, int(np.argmin(np.abs(W - w)))]
    ok_a = bool(np.any(np.abs(a - n["A"]) <= TABLE4_AMP_REL * n["A"]))
    ok_j = jump_holds(jk, w, n["jump"], TABLE4_NEAR)
    return ok_a and ok_j, f"A = {a[0]:.3f} / {a[1]:.3f} (up / down), jump: {jump_type_at(jk, w, TABLE4_NEAR)}"


def jump_readings(ctx: Context, jr: JumpReadings, findings: dict[str, Finding]) -> dict[str, list[tuple[bool, str]]]:
    """Every jump claim, Table 4 row and the formula under every reading; verdicts set in ``findings``.

    A claim failing at the default reading (the study's full responses) is reproduced under the
    reading nearest the default where the lockstep responses show it, once the responses under that
    reading, recomputed with the study's transient and recorded periods, show it too.

    Parameters
    ----------
    ctx : Context
        Where the confirmations run.
    jr : JumpReadings
    findings : dict
        By claim id; changed in place (readings, verdict, reading, deciding).

    Returns
    -------
    dict
        Claim id → (holds, result) per reading (in the order of ``jr.readings``, default first).
    """
    out = {}
    need: dict[str, list[int]] = {}
    i_def = next(i for i, rd in enumerate(jr.readings) if rd.is_default)
    for cid in CLAIM_KEYS:
        res = [_test(jr, cid, i) for i in range(len(jr.readings))]
        out[cid] = res
        f = findings[cid]
        f.evidence.append(ctx.datasets["readings_responses"])
        f.readings = [["reading", "result", "holds"]] + [
            [rd.text + (" (default)" if rd.is_default else ""), txt, yes_no(ok)]
            for rd, (ok, txt) in zip(jr.readings, res)
        ]
        # at the default reading the study's full responses decide; the lockstep rows are the other readings
        holding = [i for i, (ok, _) in enumerate(res) if ok and i != i_def]
        if f.verdict == "reproduced":
            f.deciding = f"holds at the default reading (full responses); lockstep: {res[i_def][1]}"
        elif holding:
            need[cid] = holding[: CONFIRM_SINGLE if len(CLAIM_KEYS[cid]) <= 2 else 1]
            f.deciding = f"{len(holding)} of {len(res) - 1} other readings hold in the lockstep responses"
        else:
            f.verdict = "contradicted"
            f.deciding = (
                f"fails at the default reading and under all {len(res) - 1} other readings; lockstep default: "
                f"{res[i_def][1]}"
            )
    if not need:
        return out
    # recompute the responses under the candidate readings with the study's periods; set the verdicts
    uniq = sorted({i for c in need.values() for i in c})
    opts = ctx.settings.response_options
    keys = [set().union(*(CLAIM_KEYS[c] for c, idx in need.items() if u in idx)) for u in uniq]
    sub = run_lockstep(ctx, [jr.readings[i] for i in uniq], opts, name="readings_responses_confirmed", keys=keys)
    longer = f"{opts.transient} transient and {opts.periods} recorded periods per point"
    for cid, idx in need.items():
        f = findings[cid]
        tried = []
        for i in idx:
            ok, txt = _test(sub, cid, uniq.index(i))
            rd = jr.readings[i]
            f.readings.append([rd.text + " (confirmation)", txt, "confirmed" if ok else "not confirmed"])
            tried.append(f"{rd.text}: {txt}")
            if ok:
                f.verdict, f.reading = "reproduced under a reading", rd.text
                f.deciding = (
                    f"fails at the default reading; holds under {rd.text} ({rd.changes()}), confirmed with "
                    f"{longer}: {txt}; {f.deciding}"
                )
                break
        else:
            f.verdict = "contradicted"
            f.deciding = (
                f"fails at the default reading; the {len(idx)} reading(s) nearest the default where the lockstep "
                f"responses show it fail with {longer} ({'; '.join(tried)}); {f.deciding}"
            )
        f.evidence.append(ctx.datasets["readings_responses_confirmed"])
    return out
