"""Mesh stiffness, load sharing and static transmission error over a mesh cycle or the hunting period.

The mesh phase θ is counted in mesh cycles: at θ = m the pair m (pinion tooth m mod z1, wheel tooth
m mod z2) enters contact at the start A of the path of contact on the face y = 0.  Along the line of
action, measured from the pinion's tangent point T1, pair m sits at

    s_m(θ, y) = s_A + (θ − m) p_bt − y tan β_b

in the slice at y across the face, in contact while s_A ≤ s ≤ s_E.  The face is cut into slices of
width Δb; each slice of each pair in contact is a spring along the transverse line of action

    k_i = Δb cos β_b / (c_1 + c_2 + c_h)

(c the compliances per unit width of :mod:`geardyn.tooth.energy` at the contact radii on the two
teeth; cos β_b turns the normal stiffness of a contact line Δb / cos β_b long into the transverse one)
with an initial separation e_i ≥ 0 (profile and lead modifications, wear, spalls).  Under the force
F along the line of action the teeth approach by δ (the loaded static transmission error) such that
deflections are compatible (every loaded slice deflects δ − e_i) and the loads add up:

    F = Σ_i k_i max(0, δ − e_i)

(Tavakoli & Houser 1986; Velex & Maatar 1996, the "linear" Hertzian compliance of Yang & Sun).  It is
solved exactly per phase by sorting the e_i.  The mesh stiffness the dynamic model uses is the
tangent stiffness k_m = Σ_{loaded} k_i, and the equivalent STE e_eq = δ − F / k_m makes
F = k_m (δ − e_eq) hold at that phase (for a pair without modifications e_eq = 0 and δ = F/k_m).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ModelError
from ..model import _whole_number
from ..plausible import budget
from .energy import hertz_compliance, tooth_compliance
from .faults import Broken, Crack, Modifications, Spall, Wear, fault_to_dict
from .geometry import PairGeometry

__all__ = ["MeshStiffness", "check_plausible", "default_cycles", "mesh_stiffness", "share_load"]


def share_load(k: np.ndarray, e: np.ndarray, F: float) -> np.ndarray:
    """The approach δ with Σ k_i max(0, δ − e_i) = F, per row (rows: phases; columns: springs).

    Parameters
    ----------
    k : ndarray (M, Q)
        Spring stiffnesses (0 for springs not in contact).
    e : ndarray (M, Q)
        Initial separations.
    F : float
        Force (> 0).

    Returns
    -------
    ndarray (M,)
        δ per phase (inf where no spring is in contact).
    """
    e = np.where(k > 0, e, np.inf)
    order = np.argsort(e, axis=1)
    es = np.take_along_axis(e, order, axis=1)
    ks = np.take_along_axis(k, order, axis=1)
    ks = np.where(np.isfinite(es), ks, 0.0)
    K = np.cumsum(ks, axis=1)
    KE = np.cumsum(ks * np.where(np.isfinite(es), es, 0.0), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = (F + KE) / K
    nxt = np.concatenate([es[:, 1:], np.full((es.shape[0], 1), np.inf)], axis=1)
    ok = (K > 0) & (delta <= nxt) & (delta >= es)
    first = np.argmax(ok, axis=1)
    out = delta[np.arange(len(first)), first]
    return np.where(ok.any(axis=1), out, np.inf)


def default_cycles(z1: int, z2: int, faults: Sequence[Any]) -> int:
    """Mesh cycles of the excitation's period: 1 healthy, z1 (z2) with faults on the pinion (wheel)
    only, lcm(z1, z2) — the hunting period — with faults on both.

    Parameters
    ----------
    z1, z2 : int
        Teeth of pinion and wheel.
    faults : sequence
        The faults.

    Returns
    -------
    int
    """
    gears = {f.gear for f in faults if not (isinstance(f, Wear) and f.tooth is None)}
    return math.lcm(*(z for g, z in enumerate((z1, z2)) if g in gears))  # lcm() = 1


@dataclass
class MeshStiffness:
    """The mesh of a pair over ``cycles`` mesh cycles (SI units: N/m, m, N).

    Attributes
    ----------
    geometry : PairGeometry
        The pair.
    force : float
        Force along the transverse line of action (N).
    phase : ndarray
        Mesh phases (mesh cycles).
    stiffness : ndarray
        Tangent mesh stiffness k_m (N/m).
    stiffness_unmodified : ndarray
        Σ k_i of the pairs in geometric contact (N/m).
    ste, ste_noload, ste_equivalent : ndarray
        Loaded STE δ, no-load TE min e_i and e_eq = δ − F/k_m (m).
    share : ndarray (M, P)
        Load share of the pairs m = ⌊θ⌋ − j.
    pairs_in_contact : ndarray
        Pairs carrying load.
    cycles, slices : int
        Mesh cycles computed, slices across the face.
    faults : tuple
        The faults.
    modifications : Modifications
        The modifications.
    components : dict
        A healthy single pair's compliances by term along the path (``s``, ``hertz``, ``bending``,
        ``shear``, ``axial``, ``fillet``, ``pair``).
    """

    geometry: PairGeometry
    force: float
    phase: np.ndarray  # mesh cycles, M points
    stiffness: np.ndarray  # tangent mesh stiffness k_m (N/m)
    stiffness_unmodified: np.ndarray  # Σ k_i over the pairs geometrically in contact (no separations)
    ste: np.ndarray  # loaded STE δ (m)
    ste_noload: np.ndarray  # no-load TE: min e_i (m)
    ste_equivalent: np.ndarray  # e_eq = δ − F / k_m (m)
    share: np.ndarray  # (M, P) load share of the pairs m = floor(θ) − j, j = 0 … P−1
    pairs_in_contact: np.ndarray  # (M,) number of pairs carrying load
    cycles: int
    slices: int
    faults: tuple = ()
    modifications: Modifications = field(default_factory=Modifications)
    components: dict[str, np.ndarray] = field(default_factory=dict)  # single healthy pair along s

    @property
    def mean_stiffness(self) -> float:
        return float(np.mean(self.stiffness))


#: Largest memory a mesh computation may plan for (bytes); larger requests are refused before computing.
MAX_MESH_BYTES = 2_000_000_000
#: Arrays of the (phase, pair, slice) size a mesh computation holds at once (an upper estimate).
_MESH_ARRAYS = 24

#: Largest line load F_bt / b a pair may carry (N/m): 100 000 N/mm, some 30 times what case-hardened steel
#: teeth carry at their bending and pitting limits.
MAX_LINE_LOAD = 1e8


def check_plausible(
    geo: PairGeometry, torque1: float, modifications: Modifications | None = None, faults: Sequence[Any] = ()
) -> None:
    """Refuse a load, modification or fault the pair cannot have, in one line naming the key and the bound.

    The torque's line load at most :data:`MAX_LINE_LOAD`; reliefs no deeper than the tooth's half thickness
    at its tip and no longer than the path of contact; crowning at most m_n / 2; spalls within the active
    profile and the face and shallower than the half tooth at the tip; wear shallower than that.

    Parameters
    ----------
    geo : PairGeometry
    torque1 : float
        Pinion torque (N·m).
    modifications : Modifications, optional
    faults : sequence

    Raises
    ------
    ModelError
    """
    if not (math.isfinite(torque1) and torque1 > 0):
        raise ModelError(f"torque: must be > 0 N·m, got {torque1!r}")
    w = torque1 / geo.r_b[0] / geo.face_width
    if w > MAX_LINE_LOAD:
        raise ModelError(
            f"torque: {torque1:g} N·m gives a line load of {w / 1e3:.4g} N/mm; at most {MAX_LINE_LOAD / 1e3:g} N/mm"
        )
    path = geo.s_E - geo.s_A
    half_tip = [float(sec.h[-1]) for sec in geo.sections]
    mods = modifications or Modifications()
    for name in ("tip_relief", "root_relief"):
        for g, c in enumerate(getattr(mods, name)):
            if c > half_tip[g]:
                raise ModelError(
                    f"{name}: {c * 1e6:g} um on gear {g}; at most the half tooth thickness at the tip, "
                    f"{half_tip[g] * 1e6:.4g} um"
                )
    for name in ("tip_length", "root_length"):
        for g, length in enumerate(getattr(mods, name)):
            if length > path * (1 + 1e-12):
                raise ModelError(
                    f"{name}: {length * 1e3:g} mm on gear {g}; at most the path of contact, {path * 1e3:.4g} mm"
                )
    if mods.crowning > 0.5 * geo.m_n:
        raise ModelError(f"crowning: {mods.crowning * 1e6:g} um; at most m_n / 2 = {0.5 * geo.m_n * 1e6:.4g} um")
    for f in faults:
        if isinstance(f, Spall):
            room = (1.0 - f.y0) * geo.face_width
            if f.length > path * (1 + 1e-12):
                raise ModelError(
                    f"spall: length {f.length * 1e3:g} mm; at most the path of contact, {path * 1e3:.4g} mm"
                )
            if f.width > room * (1 + 1e-12):
                raise ModelError(
                    f"spall: width {f.width * 1e3:g} mm from y0 = {f.y0:g}; at most the face left, {room * 1e3:.4g} mm"
                )
        if isinstance(f, (Spall, Wear)) and f.depth > half_tip[f.gear]:
            kind = "spall" if isinstance(f, Spall) else "wear"
            raise ModelError(
                f"{kind}: depth {f.depth * 1e6:g} um on gear {f.gear}; less than the half tooth thickness at the "
                f"tip, {half_tip[f.gear] * 1e6:.4g} um"
            )


def _relief(mods: Modifications, geo: PairGeometry, s: np.ndarray, y: np.ndarray) -> np.ndarray:
    n = mods.exponent
    e = np.zeros_like(s)
    zones = (  # (amount, length, start of the zone, direction: +1 grows with s)
        (mods.tip_relief[0], mods.tip_length[0], geo.s_E - mods.tip_length[0], 1.0),
        (mods.tip_relief[1], mods.tip_length[1], geo.s_A + mods.tip_length[1], -1.0),
        (mods.root_relief[0], mods.root_length[0], geo.s_A + mods.root_length[0], -1.0),
        (mods.root_relief[1], mods.root_length[1], geo.s_E - mods.root_length[1], 1.0),
    )
    for c, length, start, sign in zones:
        if c > 0:
            x = np.clip(sign * (s - start) / length, 0.0, None)
            e += c * np.minimum(x, 1.0) ** n
    if mods.crowning > 0:
        e += 4.0 * mods.crowning * (y / geo.face_width - 0.5) ** 2
    return e


def _profile_fraction(geo: PairGeometry, gear: int, s: np.ndarray) -> np.ndarray:
    f = (s - geo.s_A) / (geo.s_E - geo.s_A)
    return f if gear == 0 else 1.0 - f


def mesh_stiffness(
    geo: PairGeometry,
    torque1: float,
    *,
    faults: Sequence[Any] = (),
    modifications: Modifications | None = None,
    cycles: int | None = None,
    points: int = 64,
    slices: int | None = None,
    phases: np.ndarray | None = None,
) -> MeshStiffness:
    """Mesh stiffness, load sharing and STE of a pair over ``cycles`` mesh cycles.

    Parameters
    ----------
    geo : PairGeometry
        The pair (:func:`geardyn.tooth.geometry.pair_geometry`).
    torque1 : float
        Pinion torque (N·m, > 0); the force along the transverse line of action is T1 / r_b1.
    faults : sequence
        :class:`~geardyn.tooth.faults.Crack`, :class:`Spall`, :class:`Wear`, :class:`Broken`.
    modifications : Modifications, optional
        Tip/root relief and crowning.
    cycles : int, optional
        Mesh cycles computed (default :func:`default_cycles`).
    points : int
        Phases per mesh cycle.
    slices : int, optional
        Slices across the face (default 1 for a spur pair without crowning or partial faults, else 40).
    phases : ndarray, optional
        Mesh phases (in mesh cycles) to evaluate instead of the grid of ``cycles`` × ``points``.

    Returns
    -------
    MeshStiffness
    """
    mods = modifications or Modifications()
    z1, z2 = geo.gears[0].teeth, geo.gears[1].teeth
    for f in faults:
        z = (z1, z2)[f.gear]
        if getattr(f, "tooth", None) is not None and f.tooth >= z:
            raise ModelError(f"fault: tooth {f.tooth} of gear {f.gear} does not exist (z = {z})")
    check_plausible(geo, torque1, mods, faults)
    P = default_cycles(z1, z2, faults) if cycles is None else int(cycles)
    if P < 1:
        raise ModelError(f"cycles: at least 1, got {P}")
    if not _whole_number(points, 4):
        raise ModelError(f"points: a whole number of at least 4 per mesh cycle, got {points!r}")
    if slices is not None and not _whole_number(slices, 1):
        raise ModelError(f"slices: a whole number of at least 1, got {slices!r}")
    partial = any(isinstance(f, Spall) or (isinstance(f, Crack) and f.length < 1.0) for f in faults)
    S = int(slices) if slices else (40 if (geo.beta > 0 or mods.crowning > 0 or partial) else 1)
    b = geo.face_width
    tanb = math.tan(geo.beta_b)
    J = int(math.ceil(geo.eps_alpha + b * tanb / geo.p_bt)) + 1  # pairs that can be in contact at once
    M_est = P * int(points) if phases is None else int(np.size(phases))
    need = _MESH_ARRAYS * 8.0 * M_est * J * S
    budget(f"memory of {M_est} phases x {J} pairs x {S} slices", need, MAX_MESH_BYTES, key="points x cycles x slices")
    F = torque1 / geo.r_b[0]
    theta = np.arange(P * points) / points if phases is None else np.atleast_1d(np.asarray(phases, dtype=float))
    M = theta.size
    y = (np.arange(S) + 0.5) * b / S
    base = np.floor(theta).astype(np.int64)
    m = base[:, None, None] - np.arange(J)[None, :, None]  # (M, J, 1) pair index
    s = geo.s_A + (theta[:, None, None] - m) * geo.p_bt - y[None, None, :] * tanb  # (M, J, S)
    m = np.broadcast_to(m, s.shape)
    yy = np.broadcast_to(y[None, None, :], s.shape)
    inside = (s >= geo.s_A - 1e-12) & (s <= geo.s_E + 1e-12)
    sc = np.clip(s, geo.s_A, geo.s_E)
    ch = hertz_compliance(geo.gears[0].E, geo.gears[0].nu, geo.gears[1].E, geo.gears[1].nu)
    comp = [tooth_compliance(geo, g, geo.contact_radius(g, sc)).total for g in (0, 1)]
    tooth = (np.mod(m, z1), np.mod(m, z2))
    gap = _relief(mods, geo, sc, yy)
    contact = inside.copy()
    sliding = np.abs(sc - geo.s_pitch) / max(abs(geo.s_A - geo.s_pitch), abs(geo.s_E - geo.s_pitch))
    for f in faults:
        g = f.gear
        on = tooth[g] == f.tooth if getattr(f, "tooth", None) is not None else np.ones_like(inside)
        if isinstance(f, Crack):
            sel = on & inside & (yy <= f.length * b + 1e-12)
            if sel.any():
                rho = geo.contact_radius(g, sc[sel])
                comp[g][sel] = tooth_compliance(geo, g, rho, crack_depth=f.depth).total
        elif isinstance(f, Spall) and not f.empty:
            frac = _profile_fraction(geo, g, sc) * (geo.s_E - geo.s_A)
            centre = f.at * (geo.s_E - geo.s_A)
            y0 = f.y0 * b
            sel = on & (np.abs(frac - centre) <= 0.5 * f.length) & (yy >= y0) & (yy <= y0 + f.width)
            gap = gap + np.where(sel, f.depth, 0.0)
        elif isinstance(f, Wear):
            depth = f.depth * (1.0 if f.kind == "uniform" else sliding)
            gap = gap + np.where(on, depth, 0.0)
        elif isinstance(f, Broken):
            contact &= ~(on & (_profile_fraction(geo, g, sc) > f.remaining + 1e-12))
    k = np.where(contact, (b / S) * math.cos(geo.beta_b) / (comp[0] + comp[1] + ch), 0.0)
    kf, ef = k.reshape(M, -1), gap.reshape(M, -1)
    delta = share_load(kf, ef, F)
    if not np.all(np.isfinite(delta)):
        raise ModelError(
            "mesh: no tooth pair in contact at some phase (a missing or broken tooth where the contact ratio "
            "leaves it alone in mesh); the static mesh is undefined there"
        )
    load = kf * np.clip(delta[:, None] - ef, 0.0, None)
    km = np.where(delta[:, None] > ef, kf, 0.0).sum(axis=1)
    share = (load.reshape(M, J, S).sum(axis=2)) / F
    pairs = (share > 1e-9).sum(axis=1)
    noload = np.where(kf > 0, ef, np.inf).min(axis=1)
    # a single healthy pair along the path, by term (for the record and the figure)
    sp = np.linspace(geo.s_A, geo.s_E, 201)
    t1, t2 = (tooth_compliance(geo, g, geo.contact_radius(g, sp)) for g in (0, 1))
    comps = {"s": sp, "hertz": np.full_like(sp, ch)}
    for name in ("bending", "shear", "axial", "fillet"):
        comps[name] = getattr(t1, name) + getattr(t2, name)
    comps["pair"] = b * math.cos(geo.beta_b) / (t1.total + t2.total + ch)
    return MeshStiffness(
        geo, F, theta, km, kf.sum(1), delta, noload, delta - F / km, share, pairs, P, S, tuple(faults), mods, comps
    )


def faults_json(faults: Sequence[Any]) -> list[dict[str, Any]]:
    """The faults in their dict form."""
    return [fault_to_dict(f) for f in faults]
