"""The jump study: up and down frequency responses, the jump claims of the text, and Table 4.

The paper's 'b' (mm) is read as in its Table 3, D = b/2 (the default reading); the other readings
are judged by :mod:`geardyn.paper.studies.readings_jumps`.  Jumps and hysteresis come from
:func:`geardyn.analysis.response.frequency_response`.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from ...analysis.response import frequency_response
from ..claims import CLAIMS, TABLE4, claim_ids
from ..report import Finding, Section
from ..settings import SYMBOLS, Context, ResponseKey, model_text
from ..table1 import TABLE1
from ..verdicts import (
    count_text,
    distinct_text,
    fluctuation_trend,
    jump_holds,
    jump_type_at,
    parts,
    section_spread,
    strictly_monotone,
    yes_no,
)

__all__ = [
    "JUMP_NEAR",
    "JumpData",
    "LOW_OMEGA",
    "TABLE4_AMP_REL",
    "TABLE4_NEAR",
    "compute_responses",
    "first_up_jump",
    "fluctuation",
    "hysteresis_of",
    "response_overlay",
    "study_jumps",
    "study_table4",
]

#: A jump "near" a claimed ω: within this distance (about three grid steps of the default response grid).
JUMP_NEAR = 0.03
#: Table 4: a jump of the claimed kind counts at a row's ω when within this distance of it.
TABLE4_NEAR = 0.05
#: Table 4: a computed amplitude matches the paper's when within this relative difference.
TABLE4_AMP_REL = 0.25
#: "Steady below ω = 0.5" (JUMP-LOW): no jump and no hysteresis below this ω; the first jump is sought above it.
LOW_OMEGA: float = CLAIMS["JUMP-LOW"].numbers["omega"]
#: The fluctuation "after the first jump" is measured from this far (in ω) above the jump.
FLUCT_AFTER = 0.02


def response_key(xi0: float, xi1: float, D: float) -> str:
    """The name of the saved frequency response at (ξ0, ξ1, D).

    Parameters
    ----------
    xi0, xi1, D : float
        Mean damping, damping modulation and backlash of the response.
    """
    return f"response_xi0_{xi0:g}_xi1_{xi1:g}_D_{D:g}"


def jumps_of(ds: xr.Dataset) -> list[dict[str, Any]]:
    """The jumps a frequency response found (``omega``, ``direction``, ``size``, ``sweep`` each).

    Parameters
    ----------
    ds : xarray.Dataset
        A frequency response with its ``jumps`` attribute.
    """
    return json.loads(ds.attrs["jumps"])


def hysteresis_of(ds: xr.Dataset) -> list[list[float]]:
    """The ω intervals where the up and down sweeps of a frequency response disagree.

    Parameters
    ----------
    ds : xarray.Dataset
        A frequency response (kind ``response``) with its ``hysteresis`` attribute.

    Returns
    -------
    list of [float, float]
        The (ω_low, ω_high) intervals.
    """
    return json.loads(ds.attrs["hysteresis"])


def first_up_jump(ds: xr.Dataset | list[dict[str, Any]], above: float = LOW_OMEGA) -> dict[str, Any] | None:
    """The first upward jump above ``above`` in the up sweep, or ``None``.

    Parameters
    ----------
    ds : xarray.Dataset or list of dict
        A frequency response, or its jumps (:func:`jumps_of`).
    above : float
        The ω above which to look.

    Returns
    -------
    dict or None
    """
    js = jumps_of(ds) if isinstance(ds, xr.Dataset) else ds
    js = [j for j in js if j["sweep"] == "up" and j["direction"] == "up" and j["omega"] > above]
    return min(js, key=lambda j: j["omega"]) if js else None


def after_jump(jumps: list[dict[str, Any]]) -> float:
    """Where the fluctuation "after the first jump" is measured from: :data:`FLUCT_AFTER` above the first upward
    jump (:func:`first_up_jump`), or above :data:`LOW_OMEGA` when there is none.

    Parameters
    ----------
    jumps : list of dict
        The jumps of a response (:func:`jumps_of`).

    Returns
    -------
    float
    """
    j = first_up_jump(jumps)
    return (j["omega"] if j else LOW_OMEGA) + FLUCT_AFTER


def fluctuation(ds: xr.Dataset, after: float) -> float:
    """Mean spread of the Poincaré points (:func:`geardyn.paper.verdicts.section_spread`) over the up sweep above
    ``after``.

    Zero where every point is period-1; it measures fluctuation (multi-periodic or irregular motion),
    not the height of the resonance peak.

    Parameters
    ----------
    ds : xarray.Dataset
        A frequency response (with its Poincaré points).
    after : float
        The ω above which to measure.

    Returns
    -------
    float
        NaN if no grid point lies above ``after``.
    """
    sel = np.flatnonzero(ds["omega"].values > after)
    if sel.size == 0:
        return float("nan")
    return float(np.nanmean(_up_spread(ds, sel)))


def _up_spread(ds: xr.Dataset, idx: Sequence[int]) -> list[float]:
    """The spread of the up sweep's Poincaré points (:func:`geardyn.paper.verdicts.section_spread`) at the grid
    points ``idx``."""
    up = ds.sel(sweep="up")
    pu, pv = up["poincare_u"].values, up["poincare_v"].values
    return [section_spread(np.column_stack([pu[i], pv[i]])) for i in idx]


@dataclass
class JumpData:
    """The frequency responses of the jump study, keyed by (ξ0, ξ1, D).

    Parameters
    ----------
    responses : dict
        (ξ0, ξ1, D) → frequency response Dataset.
    evidence : dict
        (ξ0, ξ1, D) → its data path and figure reference.
    overlays : dict
        Claim id → the figure references of the overlays it compares responses on
        (:func:`save_overlays`).
    overlay_figures : list of (str, str)
        The overlays' figure references with their captions, for the jump study's section.
    """

    responses: dict[ResponseKey, xr.Dataset]
    evidence: dict[ResponseKey, list[str]]
    overlays: dict[str, list[str]] = field(default_factory=dict)
    overlay_figures: list[tuple[str, str]] = field(default_factory=list)

    def with_overlays(self, claims: Sequence[Finding]) -> None:
        """Put the overlays each claim compares responses on first in its evidence (in place)."""
        for c in claims:
            c.evidence = list(dict.fromkeys(self.overlays.get(c.id, []) + list(c.evidence)))

    def ev(self, *keys: ResponseKey) -> list[str]:
        """The evidence of the responses at ``keys``, in order."""
        return list(dict.fromkeys(e for k in keys for e in self.evidence[k]))


def compute_responses(ctx: Context) -> JumpData:
    """Up and down frequency responses at every (ξ0, ξ1, D) of :attr:`Settings.response_sets`.

    Parameters
    ----------
    ctx : Context
        The run: the responses use its ω range, number of points and periods.

    Returns
    -------
    JumpData
        Every response with its evidence.
    """
    s = ctx.settings
    jd = JumpData({}, {})
    for key in s.response_sets:
        ctx.log(f"frequency response {_key_text(key)}")
        model = ctx.model_at(key)
        ds = frequency_response(
            model,
            *s.response_omega,
            s.response_num,
            options=s.response_options,
            settle_periods=s.settle,
            executor=ctx.executor,
        )
        name = response_key(*key)
        rel = ctx.save(name, ds, f"frequency response at {model_text(model, skip=('omega',))}")
        jd.responses[key], jd.evidence[key] = ds, [rel, ctx.figure(name)]
    save_overlays(ctx, jd)
    return jd


#: What each overlay of the jump study compares: the varied parameter, its index in (ξ0, ξ1, D) and the
#: claims that compare the responses over it.
OVERLAYS = (
    ("xi0", 0, "xi0_set", ("JUMP-XI0", "JUMP-FLUCT", "T4-2", "T4-3")),
    ("xi1", 1, "xi1_set", ("JUMP-XI1", "JUMP-FLUCT")),
    ("D", 2, "d_set", ("JUMP-057", "JUMP-082", "JUMP-095", "T4-4", "T4-5")),
)


def response_overlay(jd: JumpData, keys: Sequence[ResponseKey], param: str) -> xr.Dataset:
    """The frequency responses at ``keys`` (one parameter varied) on one ω grid, for one figure that
    compares them (kind ``response_overlay``): amplitude of both sweeps, fluctuation of the up sweep,
    each response's jumps and hysteresis, and the ω and amplitudes the paper's claims name.

    Parameters
    ----------
    jd : JumpData
        The responses (all on one ω grid).
    keys : sequence of (ξ0, ξ1, D)
        The responses compared, in order.
    param : str
        The parameter varied: ``"xi0"``, ``"xi1"`` or ``"D"``.

    Returns
    -------
    xarray.Dataset
        ``amplitude`` (case, sweep, omega), ``fluctuation`` (case, omega: the spread of the Poincaré
        points of the up sweep, :func:`geardyn.paper.verdicts.section_spread`), ``value`` (case: the
        varied parameter); attributes ``param``, ``model`` (the first response's), ``jumps`` and
        ``hysteresis`` (a list per case), ``marks`` (the claimed ω: [ω, text]) and ``table4`` (the
        paper's Table 4 amplitudes at these responses: [case, ω, A, text]).
    """
    index = ("xi0", "xi1", "D").index(param)
    first = jd.responses[keys[0]]
    omega = first["omega"].values
    amp = np.stack([jd.responses[k]["amplitude"].sel(sweep=["up", "down"]).values for k in keys])
    spread = [_up_spread(jd.responses[k], range(omega.size)) for k in keys]
    marks = [[LOW_OMEGA, f"ω = {LOW_OMEGA:g}: steady below, upward jumps above (paper)"]]
    if param == "D":
        for cid in ("JUMP-057", "JUMP-082", "JUMP-095"):
            n = CLAIMS[cid].numbers
            if cid == "JUMP-057" or any(k[2] == n["b"] / 2 for k in keys):
                what = "jumps" if cid == "JUMP-057" else f"{n['direction']}ward jump at b = {n['b']:g} mm"
                marks.append([n["omega"], f"ω = {n['omega']:g}: {what} (paper)"])
    table4 = [
        [i, omega4, A, cid]
        for cid, (omega4, xi0, b, A, _) in zip(claim_ids("T4-"), TABLE4)
        for i, k in enumerate(keys)
        if k == (xi0, TABLE1["xi1"], b / 2)
    ]
    return xr.Dataset(
        {
            "amplitude": (("case", "sweep", "omega"), amp),
            "fluctuation": (("case", "omega"), np.asarray(spread)),
            "value": ("case", np.array([k[index] for k in keys], dtype=float)),
        },
        coords={"case": np.arange(len(keys)), "sweep": ["up", "down"], "omega": omega},
        attrs={
            "geardyn_kind": "response_overlay",
            "param": param,
            "model": first.attrs["model"],
            "jumps": json.dumps([jumps_of(jd.responses[k]) for k in keys]),
            "hysteresis": json.dumps([hysteresis_of(jd.responses[k]) for k in keys]),
            "marks": json.dumps(marks),
            "table4": json.dumps(table4),
        },
    )


def save_overlays(ctx: Context, jd: JumpData) -> None:
    """Save the overlay of each comparison of the jump study (:data:`OVERLAYS`) and note them in ``jd``: per
    claim in :attr:`JumpData.overlays` the figure reference (:meth:`Context.figure`) and data path of each
    overlay it compares responses on (in the order of :data:`OVERLAYS`), and their captions in
    :attr:`JumpData.overlay_figures`.

    Parameters
    ----------
    ctx : Context
    jd : JumpData
        Changed in place.
    """
    s = ctx.settings
    for param, index, attr, cids in OVERLAYS:
        keys = list(getattr(s, attr))
        if len(keys) < 2:
            continue
        name = f"responses_over_{param}"
        fixed = model_text(ctx.model_at(keys[0]), skip=("omega", param))
        values = ", ".join(f"{k[index]:g}" for k in keys)
        rel = ctx.save(
            name,
            response_overlay(jd, keys, param),
            f"frequency responses at {SYMBOLS[param]} = {values} overlaid ({fixed})",
        )
        for cid in cids + ("JUMP-LOW",):
            jd.overlays.setdefault(cid, []).extend([ctx.figure(name), rel])
        up = any(j["sweep"] == "up" and j["direction"] == "up" for k in keys for j in jumps_of(jd.responses[k]))
        jd.overlay_figures.append(
            (
                ctx.figure(name),
                f"Overlay of the up and down sweeps at {SYMBOLS[param]} = {values} ({fixed}): amplitude (top; up sweep "
                "thick with small filled markers, down sweep thin with large open markers, first upward jump "
                f"starred{', zoomed on in the middle panel' if up else ''}) and "
                "fluctuation, the spread of the Poincaré points of the up sweep (bottom); the ω the paper names "
                "dotted, the paper's Table 4 amplitudes at these responses as black-edged crosses.",
            )
        )


def _key_text(key: ResponseKey) -> str:
    return f"ξ0 = {key[0]:g}, ξ1 = {key[1]:g}, D = {key[2]:g}"


def study_jumps(ctx: Context, jd: JumpData) -> Section:
    """The jump claims: steady below ω = 0.5, jump size against ξ0 and ξ1, fluctuations, jumps near
    0.57, 0.82 and 0.95 (JUMP-LOW … JUMP-095).

    Parameters
    ----------
    ctx : Context
    jd : JumpData
        The frequency responses (:func:`compute_responses`).

    Returns
    -------
    Section
    """
    s = ctx.settings
    R = jd.responses
    claims: list[Finding] = []
    table = [["ξ0", "ξ1", "D", "jumps (ω, direction, size, sweep)", "hysteresis intervals"]]
    for key, ds in R.items():
        js = (
            "; ".join(f"{j['omega']:.3f} {j['direction']} {j['size']:.3f} ({j['sweep']})" for j in jumps_of(ds))
            or "none"
        )
        hs = ", ".join(f"[{a:.3f}, {b:.3f}]" for a, b in hysteresis_of(ds)) or "none"  # as the jumps
        table.append([*(f"{v:g}" for v in key), js, hs])

    # steady below ω = 0.5
    low = [(k, j) for k, ds in R.items() for j in jumps_of(ds) if j["omega"] < LOW_OMEGA]
    low_h = [(k, h) for k, ds in R.items() for h in hysteresis_of(ds) if h[0] < LOW_OMEGA]
    n_steady = len(R) - len({k for k, _ in low + low_h})
    claims.append(
        CLAIMS["JUMP-LOW"].judge(
            f"over {len(R)} responses (ξ0, ξ1, D varied): {len(low)} jumps and {len(low_h)} hysteresis intervals below "
            f"ω = {LOW_OMEGA:g}"
            + (": " + ", ".join(f"ω = {j['omega']:.2f} at {_key_text(k)}" for k, j in low) if low else "")
            + f"; steady below ω = {LOW_OMEGA:g} in {count_text(n_steady, len(R), 'responses')}.",
            parts(n_steady == len(R)),
            jd.ev(*R),
        )
    )

    above = CLAIMS["JUMP-XI0"].numbers["omega"]
    for cid, keys, lab, i, dec in (("JUMP-XI0", s.xi0_set, "ξ0", 0, True), ("JUMP-XI1", s.xi1_set, "ξ1", 1, False)):
        locs = [first_up_jump(R[k]) for k in keys]
        sizes = [j["size"] if j else float("nan") for j in locs]
        txt = f"first upward jump above ω = {above:g} (up sweep): " + ", ".join(
            f"{lab} = {k[i]:g}: " + (f"size {sz:.3f} at ω = {j['omega']:.3f}" if j else "none")
            for k, sz, j in zip(keys, sizes, locs)
        )
        ok = strictly_monotone(sizes, dec)
        n_found = sum(j is not None for j in locs)
        exists = n_found == len(locs)
        claims.append(
            CLAIMS[cid].judge(
                txt + f"; parts holding: {count_text(exists + ok, 2, '')}; an upward jump in each response: "
                f"{yes_no(exists)} ({n_found} of {len(locs)}), sizes {'decrease' if dec else 'increase'} with "
                f"{lab}: {yes_no(ok)}.",
                parts(exists, ok),
                jd.ev(*keys),
            )
        )

    fl0, fl1 = ([fluctuation(R[k], after_jump(jumps_of(R[k]))) for k in keys] for keys in (s.xi0_set, s.xi1_set))
    (ok0, why0), (ok1, why1) = fluctuation_trend(fl0, True), fluctuation_trend(fl1, False)
    claims.append(
        CLAIMS["JUMP-FLUCT"].judge(
            "fluctuation after the first jump (mean spread of the Poincaré points over the up sweep): ξ0 = "
            + ", ".join(f"{k[0]:g}: {f}" for k, f in zip(s.xi0_set, distinct_text(fl0, 4)))
            + f" ({why0}); ξ1 = "
            + ", ".join(f"{k[1]:g}: {f}" for k, f in zip(s.xi1_set, distinct_text(fl1, 4)))
            + f" ({why1}); both parts required.",
            parts(ok0, ok1),
            jd.ev(*s.xi0_set, *s.xi1_set),
        )
    )

    firsts = {k: first_up_jump(R[k]) for k in s.d_set}
    at = CLAIMS["JUMP-057"].numbers["omega"]
    near = [k for k, j in firsts.items() if j and abs(j["omega"] - at) <= JUMP_NEAR]
    locs = np.array([j["omega"] for j in firsts.values() if j])
    common = ""
    if locs.size >= 2 and float(np.ptp(locs)) <= 2 * JUMP_NEAR:
        shared = f"{locs.min():.3f}" if np.ptp(locs) == 0 else f"{locs.min():.3f}–{locs.max():.3f}"
        common = f"; the {locs.size} jumps found share one location, ω = {shared}"
    claims.append(
        CLAIMS["JUMP-057"].judge(
            "first upward jump (up sweep) for D = "
            + ", ".join(f"{k[2]:g}: " + (f"ω = {j['omega']:.3f}" if j else "none") for k, j in firsts.items())
            + f"; within ±{JUMP_NEAR:g} of ω = {at:g} for {count_text(len(near), len(firsts), 'backlash values')}"
            + common
            + ".",
            parts(len(near) == len(firsts)),
            jd.ev(*s.d_set),
        )
    )

    base_xi0 = s.d_set[0][0]  # the ξ0 of the backlash responses
    for cid in ("JUMP-082", "JUMP-095"):
        b, omega, direction = (CLAIMS[cid].numbers[k] for k in ("b", "omega", "direction"))
        keys = [k for k in ((base_xi0, TABLE1["xi1"], b / 2), (base_xi0, TABLE1["xi1"], b)) if k in R]
        txt = "; ".join(
            f"D = {k[2]:g}: jump at ω = {omega:g} ± {JUMP_NEAR:g}: {jump_type_at(jumps_of(R[k]), omega, JUMP_NEAR)}"
            for k in keys
        )
        ok = jump_holds(jumps_of(R[keys[0]]), omega, direction, JUMP_NEAR)
        claims.append(
            CLAIMS[cid].judge(
                f"b = {b:g} read as D = b/2 (the default reading): {txt} (the nearest jump must be "
                f"{direction}ward; the opposite jump fails).",
                parts(ok),
                jd.ev(*keys),
            )
        )

    jd.with_overlays(claims)

    return Section(
        "Jumps and fluctuations of the amplitude-frequency response",
        [
            f"Up and down sweeps over ω ∈ [{s.response_omega[0]:g}, {s.response_omega[1]:g}] ({s.response_num} points, "
            f"each starting from the previous end state, {s.response_options.transient} transient and "
            f"{s.response_options.periods} recorded periods). Amplitude = half peak-to-peak of u. A jump is a step "
            "of the amplitude of at least 10 % of the response's range and 5 times the neighbouring step changes (see "
            "geardyn.analysis.response). The paper's 'b' is read as in its Table 3 (D = b/2, b in mm), the default "
            f"reading; the other readings are in each claim's readings table. ξ1 = {TABLE1['xi1']:g} and ξ0 = "
            f"{base_xi0:g} unless varied."
        ],
        jd.overlay_figures
        + [
            (
                jd.evidence[k][1],
                f"Frequency response at {_key_text(k)}: up and down sweeps over ω ∈ "
                f"[{s.response_omega[0]:g}, {s.response_omega[1]:g}]",
            )
            for k in R
        ],
        claims,
        table,
    )


def _read_at(ds: xr.Dataset, omega: float) -> tuple[float, float, float, list[str]]:
    """A response read at the grid ω nearest ``omega``: that ω, the up and down amplitudes there, and the
    directions of the jumps within :data:`TABLE4_NEAR` of ``omega``."""
    x = ds["omega"].values
    k = int(np.argmin(np.abs(x - omega)))
    amp = ds["amplitude"]
    kinds = sorted({j["direction"] + "ward" for j in jumps_of(ds) if abs(j["omega"] - omega) <= TABLE4_NEAR})
    return x[k], float(amp.sel(sweep="up").values[k]), float(amp.sel(sweep="down").values[k]), kinds


def study_table4(ctx: Context, jd: JumpData) -> Section:
    """Table 4: amplitude and jump type at five operating points, read from the jump study's responses.

    Parameters
    ----------
    ctx : Context
        Unused (the common signature of the jump studies).
    jd : JumpData
        Must hold the D = b/2 response of every row (and the D = b one where computed).

    Returns
    -------
    Section
        T4-1 to T4-5 and Table 4 computed beside the paper's.
    """
    R = jd.responses
    claims = []
    table = [["ω", "ξ0", "b", "paper A", "paper jump", "geardyn A (up / down)", f"jumps within ±{TABLE4_NEAR:g}"]]
    for cid, (omega, xi0, b, A, kind) in zip(claim_ids("T4-"), TABLE4):
        key, alt = (xi0, TABLE1["xi1"], b / 2), (xi0, TABLE1["xi1"], b)
        ds = R[key]
        w, a_up, a_dn, kinds = _read_at(ds, omega)
        kind_ok = jump_holds(jumps_of(ds), omega, kind, TABLE4_NEAR)
        amp_ok = any(abs(a - A) <= TABLE4_AMP_REL * A for a in (a_up, a_dn))
        txt = (
            f"D = {b / 2:g} (b/2): A = {a_up:.3f} (up) / {a_dn:.3f} (down) at ω = {w:.3f}; jumps within "
            f"±{TABLE4_NEAR:g}: {', '.join(kinds) or 'none'} (nearest: "
            f"{jump_type_at(jumps_of(ds), omega, TABLE4_NEAR)}); parts holding: {count_text(amp_ok + kind_ok, 2, '')}; "
            f"amplitude {A:g} within {100 * TABLE4_AMP_REL:.0f} %: {yes_no(amp_ok)}, jump type "
            f"'{kind}': {yes_no(kind_ok)}"
        )
        ev = list(jd.evidence[key])
        if alt in R:
            _, a_alt, _, ja = _read_at(R[alt], omega)
            txt += f". Read as D = b = {b:g}: A = {a_alt:.3f} (up), jumps: {', '.join(ja) or 'none'}"
            ev += jd.evidence[alt]
        claims.append(CLAIMS[cid].judge(txt + ".", parts(amp_ok, kind_ok), ev))
        table.append(
            [f"{omega:g}", f"{xi0:g}", f"{b:g}", f"{A:g}", kind, f"{a_up:.3f} / {a_dn:.3f}", ", ".join(kinds) or "none"]
        )
    jd.with_overlays(claims)
    return Section(
        "Table 4: amplitude and jump type at five operating points",
        [
            f"Read from the frequency responses of the jump study at the grid ω nearest each row. Amplitude counts as "
            f"matching within {100 * TABLE4_AMP_REL:.0f} % (either sweep); the jump type when a jump of that "
            f"direction lies within ±{TABLE4_NEAR:g} in ω ('none': no jump there)."
        ],
        [],
        claims,
        table,
    )
