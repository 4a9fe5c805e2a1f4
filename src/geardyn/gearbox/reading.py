"""Reading a gearbox file's tables: shaft segments and material, bearings, radii checks, loads and torque orders.

Helpers of :mod:`geardyn.gearbox.build`; each takes the table being read (its ``blk``: values with units, errors
placed on the file's line).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np

from .._config_values import _Kind, _parse_scalar
from ..errors import ConfigError, ModelError
from ..geometry import Assumption
from ..systems.description import Connection, Load
from ..systems.load import _Block, _orders, springs
from .gear import Gear
from .shaft import NODE_DOFS, STEEL, Material, Section

__all__ = ["Block", "LOAD_KEYS", "RADIUS_RTOL"]

#: Keys of a ``[[load]]`` of a gearbox.
LOAD_KEYS = {"body": "text", "gear": "text", "torque": "any", "orders": "any"}
#: Relative tolerance for given radii to agree with the teeth.
RADIUS_RTOL = 1e-4
_EXTRA_UNITS = {"pressure": ("Pa", '"210 GPa"'), "density": ("kg/m^3", '"7850 kg/m^3"'), "time": ("s", '"2e-6 s"')}


class Block(_Block):
    """A table of a gearbox file: a system file's block (:mod:`geardyn.systems.load`) with more value kinds
    (``bool``, ``any``, a pressure, a density, a time).

    Parameters
    ----------
    ctx : geardyn.systems.load._Ctx
        The file's locator (its source and lines).
    section : str
        The table's section (``shaft``, ``gear``, ...).
    index : int or None
        Its place in an array of tables (None for a single table).
    data : dict
        The table as parsed.
    schema : dict
        Its keys and their value kinds.
    element : str or None
        The element's name, for messages.
    """

    def _scalar(self, key: str, kind: str, raw: Any, index_: int | None = None) -> Any:
        if kind == "bool":
            if not isinstance(raw, bool):
                raise self.cerr(key, f"expected true or false, got {raw!r}")
            return raw
        if kind == "any":
            return raw
        if kind not in _EXTRA_UNITS:
            return super()._scalar(key, kind, raw, index_)
        unit, example = _EXTRA_UNITS[kind]  # through the one validator of every file
        where = {"index": self.index, "element": self.element, "nonnegative": True}
        return _parse_scalar(self.ctx, self.section, key, _Kind(kind, unit, example), raw, index_, **where)


def _load_block(ctx, i: int, t: dict) -> Block:
    return Block(ctx, "load", i, t, LOAD_KEYS, t.get("body") or t.get("gear"))


def _material(blk) -> Material:
    tbl = blk.get("material", default=None)
    if tbl is None:
        blk.ctx.assume(
            Assumption(f"{blk.element}.material", "steel", "", "not given: E 210 GPa, nu 0.3, rho 7850 kg/m^3")
        )
        return STEEL
    extra = set(tbl) - {"E", "nu", "rho"}
    if extra:
        raise blk.cerr("material", f"unknown key {sorted(extra)[0]!r}; allowed: E, nu, rho")
    kinds = {"E": "pressure", "nu": "number", "rho": "density"}  # a key not given: steel's (Material's default)
    values = {k: blk._scalar("material", kinds[k], tbl[k]) for k in kinds if k in tbl}  # (placed errors pass)
    try:
        return Material(**values)
    except ModelError as e:  # Material's own bounds, placed here
        raise blk.merr("material", str(e).split(": ", 1)[-1]) from None


def _segments(blk) -> list[tuple[float, Section]]:
    segs = blk.get("segments", default=None)
    if not isinstance(segs, list) or not segs or not all(isinstance(s, dict) for s in segs):
        raise blk.cerr("segments", 'expected a list of tables, e.g. [{ length = "100 mm", outer = "40 mm" }]')
    out = []
    for k, s in enumerate(segs, start=1):
        extra = set(s) - {"length", "outer", "inner"}
        if extra or "length" not in s or "outer" not in s:
            raise blk.cerr("segments", f"segment {k}: needs length and outer (inner optional), got keys {sorted(s)}")
        length, outer, inner = (
            blk._scalar("segments", "length", s.get(x, "0 m"), k) for x in ("length", "outer", "inner")
        )
        if not length > 0:
            raise blk.merr("segments", f"segment {k}: length must be > 0, got {s['length']!r}")
        try:
            out.append((length, Section(outer, inner)))
        except ModelError as e:
            raise blk.merr("segments", f"segment {k}: {e}") from None
    return out


def _discretise(segs, features: dict[float, list[str]], per: int):
    """Node positions and element sections: nodes at segment ends and features, ``per`` elements between."""
    ends = np.concatenate([[0.0], np.cumsum([s[0] for s in segs])])
    pts = sorted(set(ends.tolist()) | set(features))
    merged: list[float] = []
    for p in pts:
        if merged and p - merged[-1] < 1e-9:
            continue
        merged.append(p)
    nodes, secs = [merged[0]], []
    for a, b in zip(merged[:-1], merged[1:]):
        mid = 0.5 * (a + b)
        seg = min(int(np.searchsorted(ends, mid)) - 1, len(segs) - 1)
        for j in range(1, per + 1):
            nodes.append(a + (b - a) * j / per)
            secs.append(segs[seg][1])
    return nodes, secs


def _section_at(segs, x: float) -> Section:
    ends = np.cumsum([s[0] for s in segs])
    i = min(int(np.searchsorted(ends, x - 1e-12)), len(segs) - 1)
    return segs[i][1]


def _check_radius(blk, key: str, exact: float, g: Gear) -> None:
    """Refuse a radius ``key`` the table gives that is not the ``exact`` one of gear ``g``'s teeth."""
    if blk.has(key) and abs(blk.get(key) - exact) > RADIUS_RTOL * exact:
        raise blk.merr(
            key,
            f"{blk.get(key) * 1e3:.6g} mm given, but {g.teeth} teeth of module {g.module * 1e3:g} mm "
            f"(helix {math.degrees(g.helix_angle):g} deg) give {exact * 1e3:.6g} mm",
        )


def _bearing(blk, node: str) -> Connection:
    if blk.has("stiffness_matrix"):
        blk.need("dofs")
        dofs = blk.get("dofs")
        bad = [d for d in dofs if d not in NODE_DOFS[:5]]
        if bad:
            raise blk.cerr("dofs", f"unknown DOF {bad[0]!r}; a bearing acts on x, y, z, rx, ry")
        return Connection(
            blk.element, tuple((node, d) for d in dofs), blk.get("stiffness_matrix"), blk.get("damping_matrix")
        )
    k, c = springs(blk, NODE_DOFS[:5])
    if not k:
        raise blk.cerr(None, "a bearing needs a stiffness (kx, ky, kz, krx, kry) or a stiffness_matrix")
    return Connection.diagonal(blk.element, node, k, c, NODE_DOFS)


def _load_target(blk, gears, node_at, where, speeds, body_speed, rmap):
    if blk.has("gear") == blk.has("body"):
        raise blk.cerr(None, 'a load acts on one gear = "..." or one body = "..."')
    if blk.has("gear"):
        g = blk.get("gear")
        if g not in gears:
            raise blk.merr("gear", f"unknown gear {g!r}; gears: {', '.join(gears)}")
        return node_at[where[g]], speeds[gears[g].shaft]
    b = blk.get("body")
    if b not in rmap:
        raise blk.merr("body", f"unknown body {b!r}; bodies: {', '.join(rmap) or '(none)'}")
    if b not in body_speed:
        raise blk.merr("body", f"body {b!r} is coupled to no shaft ([[coupling]]): its speed is unknown")
    return b, body_speed[b]


def _load_tables(ctx, loads_raw, gears, speeds, body_speed):
    """Each ``[[load]]`` table (a table only), its block and the shaft speed of its gear or body (None when it is
    unknown: refused with its message when the loads are read)."""
    for i, t in loads_raw:
        if isinstance(t, dict):
            blk, b = _load_block(ctx, i, t), t.get("body")
            if isinstance(b, str) and b in gears and b not in body_speed:
                raise blk.merr("body", f"unknown body {b!r}: {b!r} is a gear; a torque on a gear is gear = {b!r}")
            n = speeds[gears[t["gear"]].shaft] if t.get("gear") in gears else body_speed.get(t.get("body"))
            yield t, blk, n


def _drive_power(ctx, loads_raw, gears, speeds, body_speed) -> float:
    """Σ T n over the loads with a positive torque given (in N·m × the reference shaft's speed)."""
    p = 0.0
    for t, blk, n in _load_tables(ctx, loads_raw, gears, speeds, body_speed):
        tq = t.get("torque")
        if tq == "balance" or tq is None:
            continue
        T = blk._scalar("torque", "torque", tq)
        if T > 0 and n is not None:
            p += T * float(n)
    return p


def _order_ratios(ctx, loads_raw, gears, speeds, body_speed, zref) -> dict[str, Fraction]:
    """The frequency of every torque order of the loads over the reference mesh frequency (exact)."""
    return {
        f"order {k} of {blk.element}": k * n / zref
        for t, blk, n in _load_tables(ctx, loads_raw, gears, speeds, body_speed)
        if "orders" in t and n is not None
        for k, _, _ in _orders(blk)
    }


def _loads(ctx, loads_raw, gears, node_at, where, speeds, body_speed, rmap, zref) -> list[Load]:
    out: list[tuple[str, Fraction, float | None, Any, tuple]] = []
    for i, t in loads_raw:
        if not isinstance(t, dict):
            raise ConfigError(f"{ctx.source}: [[load]] {i + 1}: must be a table")
        blk = _load_block(ctx, i, t)
        blk.need("torque")
        target, n = _load_target(blk, gears, node_at, where, speeds, body_speed, rmap)
        T = None if t["torque"] == "balance" else blk.get("torque", "torque")
        out.append((target, n, T, blk, _orders(blk)))
    free = [x for x in out if x[2] is None]
    if len(free) > 1:
        raise free[1][3].cerr("torque", 'only one load may be "balance"')
    if free:
        target, n, _, blk, _ = free[0]
        P = sum(T * Fraction(nn) for _, nn, T, _, _ in out if T is not None)
        Tb = -float(P) / float(n)
        ctx.assume(Assumption(f"load.{target}.torque", Tb, "N*m", "balances the other loads at the exact speeds"))
        out = [(a, b, Tb if T is None else T, c, o) for a, b, T, c, o in out]
    loads = []
    for target, n, T, blk, orders in out:
        try:  # the body's shaft speed over the base (reference mesh) frequency: its order k runs at k n/z_ref
            loads.append(Load(target, "theta", T, orders, (n / zref) if orders else None))
        except ModelError as e:
            raise blk.wrap(e) from None
    return loads
