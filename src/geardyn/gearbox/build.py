"""Gearbox files: shafts, gears, meshes, bearings and couplings read into a :class:`GearboxDescription`.

A system file with ``[[shaft]]`` tables is a gearbox (``geardyn.systems.load`` hands it here).  Its tables::

    [gearbox]                     # optional
    max_period = 1000             # bound on the forcing period, in reference mesh cycles (default 1000)
    round_ratios = false          # true: round the mesh ratios to that denominator instead of refusing
    input_rotation = "counterclockwise"   # running sense of the reference shaft seen from +z

    [[shaft]]
    name = "input"
    material = { E = "210 GPa", nu = 0.3, rho = "7850 kg/m^3" }   # default steel
    segments = [{ length = "60 mm", outer = "40 mm" }, { length = "80 mm", outer = "50 mm", inner = "10 mm" }]
    elements_per_segment = 2      # elements between two neighbouring nodes of interest (default 2)
    rayleigh_beta = "2e-6 s"      # stiffness-proportional damping β K of the shaft (default 2e-6 s, assumed)

    [[gear]]
    name = "pinion1"
    shaft = "input"
    position = "70 mm"            # along the shaft from its start
    teeth = 23
    module = "3 mm"               # normal module
    pressure_angle = "20 deg"     # normal (default 20 deg)
    helix_angle = "15 deg"        # default 0 (spur)
    hand = "right"                # of the helix (a helical pair has opposite hands)
    face_width = "30 mm"
    profile_shift = 0.0
    # mass, inertia (polar), diametral_inertia: from the blank unless given; web_width + rim_inner_diameter

    [[mesh]]
    name = "stage1"
    pinion = "pinion1"            # driving gear
    gear = "wheel1"
    center_angle = "0 deg"        # direction of the line of centres, pinion to gear, from +x
    backlash = "0.1 mm"
    # stiffness = "400 N/um" (mean, along the line of action) with kappa/k, eps/e, phases; or an
    # excitation table; else the tooth model at the pinion torque `torque` (default: from the loads)
    # ratio, base_radius1, base_radius2: optional, checked against the teeth
    xi0 = 0.05

    [[bearing]]
    name = "in_A"
    shaft = "input"
    position = "0 mm"
    kx = "2e8 N/m"                # kx, ky, kz (N/m), krx, kry (N*m/rad); cx ... cry dampers
    # or dofs = ["x", "y"] with stiffness_matrix / damping_matrix (SI)

    [[body]]                      # rigid bodies as in any system file (a motor rotor, a load inertia)
    name = "motor"
    dofs = ["theta"]
    inertia = "0.05 kg*m^2"

    [[coupling]]                  # torsional coupling of a body to a shaft node
    name = "motor_coupling"
    shaft = "input"
    position = "0 mm"
    body = "motor"
    ktheta = "5e4 N*m/rad"
    ctheta = "5 N*m*s/rad"

    [[load]]
    body = "motor"                # or gear = "..."
    torque = "100 N*m"            # or "balance": the torque that balances the others at the exact speeds

Every shaft gets a node at each segment end and at every gear, bearing and coupling; each interval between
neighbouring nodes is cut into ``elements_per_segment`` Timoshenko elements (:mod:`.shaft`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from .._config_values import _Kind, _parse_scalar
from ..errors import ConfigError, ModelError
from ..geometry import Assumption
from ..systems.description import Connection, Load, Mesh
from .gear import Gear
from .kinematics import DEFAULT_MAX_PERIOD, forcing_period, round_ratio, solve_speeds
from .mesh import mesh_vector, pair_geometry_of, tooth_excitation
from .model import GearboxDescription, NodeBody, ShaftModel
from .shaft import NODE_DOFS, STEEL, Material, Section, ShaftMesh, shaft_matrices

__all__ = ["build_description", "is_gearbox"]

_ARRAYS = ("shaft", "gear", "mesh", "bearing", "coupling", "body", "load")
_TOP_TEXT = ("title", "description")
_SECTIONS = {
    "system": {"reference": "text", "characteristic_length": "length", "equivalent_mass": "text"},
    "operating": {"rpm": "speed", "omega": "number"},
    "gearbox": {"max_period": "int", "round_ratios": "bool", "input_rotation": "text"},
}
_SHAFT = {
    "name": "text",
    "material": "table",
    "segments": "any",
    "elements_per_segment": "int",
    "rayleigh_beta": "time",
}
_GEAR = {
    "name": "text",
    "shaft": "text",
    "position": "length",
    "teeth": "int",
    "module": "length",
    "pressure_angle": "angle",
    "helix_angle": "angle",
    "hand": "text",
    "face_width": "length",
    "profile_shift": "number",
    "mass": "mass",
    "inertia": "inertia",
    "diametral_inertia": "inertia",
    "web_width": "length",
    "rim_inner_diameter": "length",
    "reference_radius": "length",
    "base_radius": "length",
}
_MESH = {
    "name": "text",
    "pinion": "text",
    "gear": "text",
    "center_angle": "angle",
    "stiffness": "stiffness",
    "torque": "torque",
    "harmonics": "int",
    "backlash": "length",
    "kappa": "number*",
    "k": "stiffness*",
    "phi_k": "phase*",
    "xi0": "number",
    "xi": "number*",
    "c0": "damping",
    "c": "damping*",
    "phi_c": "phase*",
    "eps": "number*",
    "e": "length*",
    "phi_e": "phase*",
    "ratio": "number",
    "base_radius1": "length",
    "base_radius2": "length",
    "excitation": "text",
    "excitation_harmonics": "int",
}
_TRANS = ("x", "y", "z")
_TILT = ("rx", "ry")
_BEARING = (
    {"name": "text", "shaft": "text", "position": "length", "dofs": "list", "stiffness_matrix": "matrix"}
    | {"damping_matrix": "matrix"}
    | {f"k{d}": "stiffness" for d in _TRANS}
    | {f"k{d}": "tstiffness" for d in _TILT}
    | {f"c{d}": "damping" for d in _TRANS}
    | {f"c{d}": "tdamping" for d in _TILT}
)
_COUPLING = {
    "name": "text",
    "shaft": "text",
    "position": "length",
    "body": "text",
    "ktheta": "tstiffness",
    "ctheta": "tdamping",
}
_LOAD = {"body": "text", "gear": "text", "torque": "any"}
_EXTRA_UNITS = {"pressure": ("Pa", '"210 GPa"'), "density": ("kg/m^3", '"7850 kg/m^3"'), "time": ("s", '"2e-6 s"')}
#: Default stiffness-proportional damping of a shaft (s): ζ = β ω/2, 0.6 % at 1 kHz.
DEFAULT_RAYLEIGH_BETA = 2e-6
#: Relative tolerance for a given ratio and for given radii to agree with the teeth.
RATIO_RTOL = 1e-9
RADIUS_RTOL = 1e-4
#: An equivalent STE below this (m) from the tooth model is round-off (perfect involutes have none).
STE_FLOOR = 1e-12


def is_gearbox(data: dict) -> bool:
    """Whether a parsed system file describes a gearbox (it has ``[[shaft]]`` tables)."""
    return isinstance(data, dict) and "shaft" in data


def _classes(ctx_cls: type, block_cls: type) -> tuple[type, type]:
    """The file reader's context and block classes, extended for a gearbox (more sections and value kinds)."""

    class GCtx(ctx_cls):  # the one locator (geardyn._config_values._Ctx) places [[shaft]] ... as any array
        pass

    class GBlock(block_cls):
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

        def need(self, *keys: str) -> None:
            missing = [k for k in keys if not self.has(k)]
            if missing:
                raise self.cerr(None, f"missing key(s) {', '.join(missing)}")

    return GCtx, GBlock


def _blocks(ctx, data: dict, section: str, schema: dict) -> list:
    out = []
    for i, t in enumerate(data.get(section, []) or []):
        if not isinstance(t, dict):
            raise ConfigError(f"{ctx.source}: [[{section}]] {i + 1}: must be a table")
        name = t.get("name") if isinstance(t.get("name"), str) else f"{section}{i + 1}"
        out.append(ctx.Block(ctx, section, i, t, schema, name))
    names = [b.element for b in out]
    for i, n in enumerate(names):
        if n in names[:i]:
            raise ctx.config(section, i, "name", None, f"duplicate {section} name {n!r}; names must be unique")
    return out


# ---------------------------------------------------------------------------- shafts
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
    try:
        return Material(
            E=blk._scalar("material", "pressure", tbl["E"]) if "E" in tbl else STEEL.E,
            nu=blk._scalar("material", "number", tbl["nu"]) if "nu" in tbl else STEEL.nu,
            rho=blk._scalar("material", "density", tbl["rho"]) if "rho" in tbl else STEEL.rho,
        )
    except ModelError as e:
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
        length = blk._scalar("segments", "length", s["length"], k)
        outer = blk._scalar("segments", "length", s["outer"], k)
        inner = blk._scalar("segments", "length", s.get("inner", "0 m"), k)
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


# ---------------------------------------------------------------------------- the file
def build_description(ctx, data: dict, block: type, body, place) -> GearboxDescription:
    """The :class:`GearboxDescription` of a parsed gearbox file (see the module docstring).

    ``ctx`` is the system-file reader's context (file name and text), ``block`` its class reading one table
    with units, ``body`` its reader of a ``[[body]]`` and ``place`` the function that puts a system-level
    error on its element's line (:mod:`geardyn.systems.load` passes them, so both formats read values alike).
    """
    ctx_cls, block_cls = _classes(type(ctx), block)
    gctx = ctx_cls(ctx.source, "\n".join(ctx.lines))
    gctx.Block, gctx.body = block_cls, body
    try:
        return _build(gctx, data)
    except ModelError as e:
        if str(e).startswith(f"{ctx.source}: "):
            raise
        raise place(gctx, data, e) from None


def _build(ctx, data: dict) -> GearboxDescription:
    for key, val in data.items():
        if key in _TOP_TEXT:
            if not isinstance(val, str):
                raise ctx.config(None, None, None, None, f"{key}: expected a string")
        elif key in _ARRAYS:
            if not isinstance(val, list):
                raise ConfigError(f"{ctx.source}: {key}: write [[{key}]] tables")
        elif key not in _SECTIONS:
            allowed = ", ".join([f"[{s}]" for s in _SECTIONS] + [f"[[{s}]]" for s in _ARRAYS] + list(_TOP_TEXT))
            raise ConfigError(f"{ctx.source}: unknown section or key {key!r} in a gearbox file; allowed: {allowed}")
    sysb = ctx.Block(ctx, "system", None, data.get("system", {}), _SECTIONS["system"], None)
    opb = ctx.Block(ctx, "operating", None, data.get("operating", {}), _SECTIONS["operating"], None)
    gbb = ctx.Block(ctx, "gearbox", None, data.get("gearbox", {}), _SECTIONS["gearbox"], None)
    sblocks = _blocks(ctx, data, "shaft", _SHAFT)
    gblocks = _blocks(ctx, data, "gear", _GEAR)
    mblocks = _blocks(ctx, data, "mesh", _MESH)
    bblocks = _blocks(ctx, data, "bearing", _BEARING)
    cblocks = _blocks(ctx, data, "coupling", _COUPLING)
    if not mblocks:
        raise ConfigError(f"{ctx.source}: no [[mesh]]: a gearbox needs at least one mesh")
    rigid = [ctx.body(ctx, i, t) for i, t in enumerate(data.get("body", []) or [])]
    rmap = {b.name: b for b in rigid}

    # gears
    shaft_names = [b.element for b in sblocks]
    gears: dict[str, Gear] = {}
    for blk in gblocks:
        blk.need("shaft", "position", "teeth", "module", "face_width")
        sh = blk.get("shaft")
        if sh not in shaft_names:
            raise blk.merr("shaft", f"unknown shaft {sh!r}; shafts: {', '.join(shaft_names)}")
        helix = blk.get("helix_angle", default=0.0)
        try:
            g = Gear(
                name=blk.element,
                shaft=sh,
                position=blk.get("position"),
                teeth=blk.get("teeth"),
                module=blk.get("module"),
                face_width=blk.get("face_width"),
                pressure_angle=blk.get("pressure_angle", default=math.radians(20.0)),
                helix_angle=helix,
                profile_shift=blk.get("profile_shift", default=0.0),
                hand=blk.get("hand", default="right", assumed="not given: right hand" if helix > 0 else None),
                mass=blk.get("mass"),
                inertia=blk.get("inertia"),
                diametral_inertia=blk.get("diametral_inertia"),
                web_width=blk.get("web_width"),
                rim_inner_diameter=blk.get("rim_inner_diameter"),
            )
        except ModelError as e:
            raise blk.wrap(e) from None
        for key, exact in (("reference_radius", g.reference_radius), ("base_radius", g.base_radius)):
            if blk.has(key):
                _check_radius(blk, key, blk.get(key), exact, g)
        gears[g.name] = g

    # kinematics, exact
    pairs = []
    for blk in mblocks:
        blk.need("pinion", "gear")
        for key in ("pinion", "gear"):
            if blk.get(key) not in gears:
                raise blk.merr(key, f"unknown gear {blk.get(key)!r}; gears: {', '.join(gears)}")
        gp, gg = gears[blk.get("pinion")], gears[blk.get("gear")]
        pairs.append((blk.element, gp.shaft, gg.shaft, gp.teeth, gg.teeth))
    ref = sysb.get("reference", default=mblocks[0].element)
    names = [b.element for b in mblocks]
    if ref not in names:
        raise sysb.merr("reference", f"unknown mesh {ref!r}; meshes: {', '.join(names)}")
    ref_i = names.index(ref)
    rot = gbb.get("input_rotation", default="counterclockwise")
    if rot not in ("counterclockwise", "clockwise"):
        raise gbb.cerr("input_rotation", f"must be 'counterclockwise' or 'clockwise', got {rot!r}")
    try:
        speeds, senses = solve_speeds(shaft_names, pairs, pairs[ref_i][1], 1 if rot == "counterclockwise" else -1)
    except ModelError as e:
        raise ctx.model("mesh", None, None, None, str(e)) from None
    zref = pairs[ref_i][3] * speeds[pairs[ref_i][1]]
    ratios = {nm: sp_z * speeds[sp] / zref for (nm, sp, _, sp_z, _) in pairs}
    bound = gbb.get("max_period", default=DEFAULT_MAX_PERIOD)
    if not 1 <= bound <= 10**6:
        raise gbb.merr("max_period", f"must be from 1 to 1000000 reference mesh cycles, got {bound}")
    period = forcing_period(ratios.values())
    rounded = False
    if period > bound:
        if not gbb.get("round_ratios", default=False):
            worst = max(ratios, key=lambda k: ratios[k].denominator)
            raise ctx.model(
                "gearbox" if "gearbox" in data else "mesh",
                None,
                None,
                None,
                f"the forcing period (the meshes' hunting period) is {period} cycles of mesh {ref!r}, above the "
                f"bound max_period = {bound} (mesh {worst!r} runs at {ratios[worst]} of it); raise [gearbox] "
                "max_period or set round_ratios = true",
            )
        ratios = {k: round_ratio(v, bound) for k, v in ratios.items()}
        period = forcing_period(ratios.values())
        rounded = True
        ctx.assume(Assumption("gearbox.round_ratios", True, "", f"mesh ratios rounded to the denominator {bound}"))

    # shafts and their nodes
    feats: dict[str, dict[float, list[str]]] = {s: {} for s in shaft_names}
    where: dict[str, tuple[str, float]] = {}
    for blks in (gblocks, bblocks, cblocks):
        for blk in blks:
            blk.need("shaft", "position")
            sh = blk.get("shaft")
            if sh not in feats:
                raise blk.merr("shaft", f"unknown shaft {sh!r}; shafts: {', '.join(shaft_names)}")
            pos = blk.get("position")
            feats[sh].setdefault(pos, []).append(blk.element)
            where[blk.element] = (sh, pos)
    shafts: list[ShaftModel] = []
    bodies: list = []
    conns: list[Connection] = []
    node_at: dict[tuple[str, float], str] = {}
    body_names = set(rmap)
    for blk in sblocks:
        name = blk.element
        mat = _material(blk)
        segs = _segments(blk)
        total = sum(s[0] for s in segs)
        for pos, items in feats[name].items():
            if not -1e-12 <= pos <= total + 1e-12:
                raise blk.merr(
                    None, f"{items[0]!r} at {pos * 1e3:g} mm is outside the shaft (length {total * 1e3:g} mm)"
                )
        per = blk.get("elements_per_segment", default=2)
        if not 1 <= per <= 100:
            raise blk.merr("elements_per_segment", f"must be from 1 to 100, got {per}")
        beta = blk.get(
            "rayleigh_beta",
            default=DEFAULT_RAYLEIGH_BETA,
            assumed="not given: stiffness-proportional shaft damping beta = 2e-6 s (0.6 % of critical at 1 kHz)",
        )
        pos_list, secs = _discretise(segs, feats[name], per)
        K, M, G = shaft_matrices(ShaftMesh(tuple(pos_list), tuple(secs)), mat)
        K = 0.5 * (K + K.T)
        M = 0.5 * (M + M.T)
        node_names, node_feats = [], []
        for k, p in enumerate(pos_list):
            here = next((items for q, items in feats[name].items() if abs(q - p) < 1e-9), [])
            gear_here = [n for n in here if n in gears]
            nn = (gear_here or here or [f"{name}_{k}"])[0]
            if nn in body_names:
                nn = f"{name}_{k}"
            body_names.add(nn)
            node_names.append(nn)
            node_feats.append(tuple(here))
            for q in feats[name]:
                if abs(q - p) < 1e-9:
                    node_at[(name, q)] = nn
        for k, nn in enumerate(node_names):
            blockm = np.diag(np.diag(M[6 * k : 6 * k + 6, 6 * k : 6 * k + 6])).copy()
            for g in (gears[n] for n in node_feats[k] if n in gears):
                m, ip, idia = g.blank(mat.rho, _section_at(segs, g.position).outer)
                blockm += np.diag([m, m, m, idia, idia, ip])
            bodies.append(NodeBody(nn, NODE_DOFS, mass_matrix=tuple(map(tuple, blockm))))
        dofs = tuple((nn, d) for nn in node_names for d in NODE_DOFS)
        conns.append(Connection(name, dofs, K, beta * K))
        shafts.append(
            ShaftModel(
                name,
                tuple(pos_list),
                tuple(node_names),
                tuple(secs),
                mat,
                M,
                K,
                G,
                speeds[name],
                senses[name],
                tuple(node_feats),
            )
        )

    # bearings and couplings
    for blk in bblocks:
        node = node_at[where[blk.element]]
        try:
            conns.append(_bearing(blk, node))
        except ModelError as e:
            raise blk.wrap(e) from None
    body_speed: dict[str, Fraction] = {}
    for blk in cblocks:
        node = node_at[where[blk.element]]
        blk.need("body", "ktheta")
        b = blk.get("body")
        if b not in rmap:
            raise blk.merr("body", f"unknown body {b!r}; bodies: {', '.join(rmap) or '(none)'}")
        if "theta" not in rmap[b].dofs:
            raise blk.merr("body", f"body {b!r} has no theta DOF to couple")
        k, c = blk.get("ktheta"), blk.get("ctheta", default=0.0)
        conns.append(Connection.along(blk.element, {(node, "theta"): 1.0, (b, "theta"): -1.0}, k, c))
        body_speed[b] = speeds[where[blk.element][0]]

    # meshes
    b_c = sysb.get("characteristic_length")
    if b_c is None:
        blk = mblocks[ref_i]
        jn = blk.get("backlash", default=0.0)
        if not jn > 0:
            raise blk.merr("backlash", 'is 0: give [system] characteristic_length (e.g. "1 um") to scale lengths')
        b_c = jn / 2.0
    loads_raw = list(enumerate(data.get("load", []) or []))
    power = _drive_power(ctx, loads_raw, gears, speeds, body_speed)
    meshes = []
    for blk, (nm, sp, *_) in zip(mblocks, pairs):
        gp, gg = gears[blk.get("pinion")], gears[blk.get("gear")]
        try:
            meshes.append(
                _mesh(
                    blk,
                    gp,
                    gg,
                    node_at,
                    where,
                    senses,
                    ratios[nm],
                    rounded,
                    b_c,
                    power / float(speeds[sp]) if power else None,
                    shafts,
                )
            )
        except ModelError as e:
            raise blk.wrap(e) from None
    loads = _loads(ctx, loads_raw, gears, node_at, where, speeds, body_speed, rmap)
    rpm, omega = opb.get("rpm"), opb.get("omega")
    if rpm is None and omega is None:
        ctx.assume(Assumption("operating.omega", 1.0, "", "no operating point given: ω = 1"))
    for key, v in (("rpm", rpm), ("omega", omega)):
        if v is not None and not v > 0:
            raise opb.merr(key, f"must be > 0, got {v:g}")
    kin = {
        "reference_mesh": ref,
        "reference_shaft": pairs[ref_i][1],
        "shaft_speed_ratios": {s: str(v) for s, v in speeds.items()},
        "mesh_ratios": {k: str(v) for k, v in ratios.items()},
        "forcing_period_mesh_cycles": period,
        "rounded": rounded,
    }
    return GearboxDescription(
        bodies=tuple(bodies) + tuple(rigid),
        meshes=tuple(meshes),
        connections=tuple(conns),
        loads=tuple(loads),
        reference=ref,
        characteristic_length=sysb.get("characteristic_length"),
        rpm=rpm,
        omega=omega,
        equivalent_mass=sysb.get("equivalent_mass", default="rotational"),
        title=str(data.get("title", "")),
        source=ctx.source,
        assumptions=tuple(ctx.assumptions),
        shafts=tuple(shafts),
        kinematics=kin,
    )


def _check_radius(blk, key: str, given: float, exact: float, g: Gear) -> None:
    if abs(given - exact) > RADIUS_RTOL * exact:
        raise blk.merr(
            key,
            f"{given * 1e3:.6g} mm given, but {g.teeth} teeth of module {g.module * 1e3:g} mm "
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
    k = {d: blk.get(f"k{d}") for d in NODE_DOFS[:5] if blk.has(f"k{d}")}
    c = {d: blk.get(f"c{d}") for d in NODE_DOFS[:5] if blk.has(f"c{d}")}
    if not k:
        raise blk.cerr(None, "a bearing needs a stiffness (kx, ky, kz, krx, kry) or a stiffness_matrix")
    dofs = [d for d in NODE_DOFS[:5] if d in k or d in c]
    return Connection(
        blk.element,
        tuple((node, d) for d in dofs),
        np.diag([k.get(d, 0.0) for d in dofs]),
        np.diag([c.get(d, 0.0) for d in dofs]),
    )


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


def _drive_power(ctx, loads_raw, gears, speeds, body_speed) -> float:
    """Σ T n over the loads with a positive torque given (in N·m × the reference shaft's speed)."""
    p = 0.0
    for i, t in loads_raw:
        if not isinstance(t, dict):
            continue
        tq = t.get("torque")
        if tq == "balance" or tq is None:
            continue
        blk = ctx.Block(ctx, "load", i, t, _LOAD, t.get("body") or t.get("gear"))
        T = blk._scalar("torque", "torque", tq)
        if T > 0:
            if "gear" in t and t["gear"] in gears:
                p += T * float(speeds[gears[t["gear"]].shaft])
            elif "body" in t and t["body"] in body_speed:
                p += T * float(body_speed[t["body"]])
    return p


def _loads(ctx, loads_raw, gears, node_at, where, speeds, body_speed, rmap) -> list[Load]:
    out: list[tuple[str, Fraction, float | None, Any]] = []
    for i, t in loads_raw:
        if not isinstance(t, dict):
            raise ConfigError(f"{ctx.source}: [[load]] {i + 1}: must be a table")
        blk = ctx.Block(ctx, "load", i, t, _LOAD, t.get("body") or t.get("gear"))
        blk.need("torque")
        target, n = _load_target(blk, gears, node_at, where, speeds, body_speed, rmap)
        raw = t["torque"]
        T = None if raw == "balance" else blk.get("torque", "torque")
        out.append((target, n, T, blk))
    free = [x for x in out if x[2] is None]
    if len(free) > 1:
        raise free[1][3].cerr("torque", 'only one load may be "balance"')
    if free:
        target, n, _, blk = free[0]
        P = sum(T * Fraction(nn) for _, nn, T, _ in out if T is not None)
        Tb = -float(P) / float(n)
        ctx.assume(Assumption(f"load.{target}.torque", Tb, "N*m", "balances the other loads at the exact speeds"))
        out = [(a, b, Tb if T is None else T, c) for a, b, T, c in out]
    return [Load(target, "theta", T) for target, _, T, _ in out]


def _mesh(blk, gp, gg, node_at, where, senses, ratio, rounded, b_c, torque_default, shafts) -> Mesh:
    name = blk.element
    geo = pair_geometry_of(name, gp, gg)
    for key, g, rb in (("base_radius1", gp, geo["rb1"]), ("base_radius2", gg, geo["rb2"])):
        if blk.has(key):
            _check_radius(blk, key, blk.get(key), rb, g)
    if blk.has("ratio"):
        given = blk.get("ratio")
        if rounded or abs(given - float(ratio)) > RATIO_RTOL * float(ratio):
            raise blk.merr(
                "ratio",
                f"{given:.12g} given, but the teeth give {ratio} = {float(ratio):.12g} of the reference mesh "
                "frequency (omit ratio: it follows from the teeth)",
            )
    s1, s2 = senses[gp.shaft], senses[gg.shaft]
    psi = blk.get("center_angle", default=0.0, assumed="not given: the line of centres from pinion to gear along +x")
    v1, v2 = mesh_vector(geo, psi, s1, s2, gp.hand)
    n1, n2 = node_at[where[gp.name]], node_at[where[gg.name]]
    vector = tuple(((n1, d), float(c)) for d, c in zip(NODE_DOFS, v1) if c != 0.0) + tuple(
        ((n2, d), float(c)) for d, c in zip(NODE_DOFS, v2) if c != 0.0
    )
    backlash = blk.get("backlash", default=0.0, assumed="no backlash given: 0 (a linear mesh)")
    series: dict[str, Any] = {}
    if blk.has("excitation"):
        if blk.has("stiffness"):
            raise blk.cerr("excitation", "give the table or stiffness, not both")
        series = {
            "stiffness": None,
            "excitation": str(Path(blk.ctx.source).parent / blk.get("excitation")),
            "excitation_harmonics": blk.get("excitation_harmonics"),
        }
    elif blk.has("stiffness"):
        k0 = blk.get("stiffness")
        kappa = blk.get("kappa", default=())
        if blk.has("k"):
            if blk.has("kappa"):
                raise blk.cerr("k", "give kappa (relative) or k (N/m), not both")
            kappa = tuple(x / k0 for x in blk.get("k"))
        e = blk.get("e", default=())
        if blk.has("eps"):
            if blk.has("e"):
                raise blk.cerr("eps", "give eps (relative to b_c) or e (a length), not both")
            e = tuple(x * b_c for x in blk.get("eps"))
        series = {
            "stiffness": k0,
            "kappa": kappa,
            "phi_k": blk.get("phi_k", default=()),
            "e": e,
            "phi_e": blk.get("phi_e", default=()),
        }
    else:
        for key in ("kappa", "k", "eps", "e", "phi_k", "phi_e"):
            if blk.has(key):
                raise blk.cerr(key, "harmonics need the mean stiffness (the tooth model gives both otherwise)")
        torque = blk.get("torque", default=torque_default)
        if torque is None:
            raise blk.cerr(
                None, "the tooth model needs the pinion torque: give torque, a driving [[load]], or stiffness"
            )
        if not blk.has("torque"):
            blk.ctx.assume(Assumption(f"{name}.torque", torque, "N*m", "the pinion torque of the drive loads"))
        H = blk.get("harmonics", default=3)
        mat = next(s.material for s in shafts if s.name == gp.shaft)
        te = tooth_excitation(gp, gg, geo, torque, H, mat.E, mat.nu)
        series = {k: te[k] for k in ("stiffness", "kappa", "phi_k", "e", "phi_e")}
        if max(map(abs, series["e"]), default=0.0) < STE_FLOOR:  # unmodified involutes: e_eq is round-off
            series["e"], series["phi_e"] = (), ()
    if any(blk.has(k) for k in ("c0", "c")):
        damping = {"c0": blk.get("c0", default=0.0), "c": blk.get("c", default=())}
    else:
        damping = {
            "xi0": blk.get("xi0", default=0.1, assumed="not given: geardyn's default mean mesh damping ratio 0.1"),
            "xi": blk.get("xi", default=()),
        }
    return Mesh(
        name=name,
        vector=vector,
        backlash=backlash,
        phi_c=blk.get("phi_c", default=()),
        ratio=float(ratio),
        teeth=gp.teeth,
        **series,
        **damping,
    )
