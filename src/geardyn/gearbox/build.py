"""Gearbox files: shafts, gears, meshes, bearings and couplings read into a :class:`GearboxDescription`.

A system file with ``[[shaft]]`` tables is a gearbox (``geardyn.systems.load`` hands it here).  Its tables::

    [gearbox]                     # optional
    max_period = 1000             # bound on the forcing period, in reference mesh cycles (default 1000)
    round_ratios = false          # true: round the mesh ratios to that denominator instead of refusing
    input_rotation = "counterclockwise"   # running sense of the reference shaft seen from +z
    gyroscopic = false            # true: the shafts' and gears' gyroscopic terms (each shaft at its own speed)

    [[shaft]]
    name = "input"
    material = { E = "210 GPa", nu = 0.3, rho = "7850 kg/m^3" }   # default steel
    segments = [{ length = "60 mm", outer = "40 mm" }, { length = "80 mm", outer = "50 mm", inner = "10 mm" }]
    elements_per_segment = 2      # elements between two neighbouring nodes of interest (default 2)
    rayleigh_beta = "1e-7 s"      # stiffness-proportional damping β K of the shaft (default 1e-7 s, assumed)

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
    orders = [{ order = 6, amplitude = "3 N*m", phase = "0 deg" }]   # torque orders of the body's shaft speed

Every shaft gets a node at each segment end and at every gear, bearing and coupling; each interval between
neighbouring nodes is cut into ``elements_per_segment`` Timoshenko elements (:mod:`.shaft`).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..errors import ConfigError, ModelError
from ..geometry import Assumption
from ..systems.description import MESH_SERIES_KEYS, Connection, Mesh
from ..systems.load import _SECTIONS as SYSTEM_SECTIONS
from ..systems.load import (
    _body,
    _element_line,
    check_top,
    described,
    excitation_table,
    half_backlash,
    mesh_damping,
    mesh_series,
)
from ..systems.rolling import ROLLING_KEYS, read_rolling
from .gear import Gear, disc_gyroscopic
from .kinematics import DEFAULT_MAX_PERIOD, forcing_period, round_ratio, solve_speeds
from .mesh import mesh_vector, pair_geometry_of, tooth_excitation
from .model import GearboxDescription, NodeBody, ShaftModel
from .reading import (
    Block,
    _bearing,
    _check_radius,
    _discretise,
    _drive_power,
    _loads,
    _material,
    _order_ratios,
    _section_at,
    _segments,
)
from .shaft import NODE_DOFS, ShaftMesh, shaft_matrices

__all__ = ["build_description"]

_ARRAYS = ("shaft", "gear", "mesh", "bearing", "coupling", "body", "load")
_SECTIONS = SYSTEM_SECTIONS | {
    "gearbox": {"max_period": "int", "round_ratios": "bool", "input_rotation": "text", "gyroscopic": "bool"},
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
#: The keys of a ``[[gear]]`` that are not :class:`Gear` fields given as they are: checked against the teeth or
#: read with a default.
_GEAR_CHECKED = ("name", "shaft", "helix_angle", "hand", "reference_radius", "base_radius")
_MESH = (
    {"name": "text", "pinion": "text", "gear": "text", "center_angle": "angle", "stiffness": "stiffness"}
    | {"torque": "torque", "harmonics": "int"}
    | MESH_SERIES_KEYS
    | {"base_radius1": "length", "base_radius2": "length", "excitation": "text", "excitation_harmonics": "int"}
)
_TRANS = ("x", "y", "z")
_TILT = ("rx", "ry")
_BEARING = (
    {"name": "text", "shaft": "text", "position": "length", "dofs": "list", "stiffness_matrix": "matrix"}
    | {"damping_matrix": "matrix"}
    | {f"k{d}": "stiffness" for d in _TRANS}
    | {f"k{d}": "tstiffness" for d in _TILT}
    | {f"c{d}": "damping" for d in _TRANS}
    | {f"c{d}": "tdamping" for d in _TILT}
    | ROLLING_KEYS
)
_COUPLING = {
    "name": "text",
    "shaft": "text",
    "position": "length",
    "body": "text",
    "ktheta": "tstiffness",
    "ctheta": "tdamping",
}
#: Default stiffness-proportional damping of a shaft (s): ζ = β ω/2, 0.03 % at 1 kHz, 3 % at 100 kHz (the high
#: element modes stay underdamped, so that the explicit RK4 step is not limited by them).
DEFAULT_RAYLEIGH_BETA = 1e-7
#: Relative tolerance for a given ratio to agree with the teeth.
RATIO_RTOL = 1e-9
#: An equivalent STE below this (m) from the tooth model is round-off (perfect involutes have none).
STE_FLOOR = 1e-12


def _blocks(ctx, data: dict, section: str, schema: dict) -> list:
    out = []
    for i, t in enumerate(data.get(section, []) or []):
        if not isinstance(t, dict):
            raise ConfigError(f"{ctx.source}: [[{section}]] {i + 1}: must be a table")
        name = t.get("name") if isinstance(t.get("name"), str) else f"{section}{i + 1}"
        out.append(Block(ctx, section, i, t, schema, name))
    names = [b.element for b in out]
    for i, n in enumerate(names):
        if n in names[:i]:
            raise ctx.config(section, f"duplicate {section} name {n!r}; names must be unique", i, "name")
    return out


# ---------------------------------------------------------------------------- the file
def build_description(ctx, data: dict) -> GearboxDescription:
    """The :class:`GearboxDescription` of a parsed gearbox file (see the module docstring).

    Its tables are read as a system file's (:mod:`geardyn.systems.load`: its bodies, its blocks extended by
    :class:`geardyn.gearbox.reading.Block`, its placing of a system-level error on its element's line), so that
    both formats read values alike.

    Parameters
    ----------
    ctx
        The system-file reader's context (its ``source`` file name and ``lines`` of text).
    data : dict
        The parsed TOML of the gearbox file.
    """
    try:
        return _build(ctx, data)
    except ModelError as e:
        if str(e).startswith(f"{ctx.source}: "):
            raise
        raise _element_line(ctx, data, e) from None


def _build(ctx, data: dict) -> GearboxDescription:
    check_top(ctx, data, _SECTIONS, _ARRAYS, gearbox=True)
    sysb, opb, gbb = (
        Block(ctx, s, None, data.get(s, {}), _SECTIONS[s], None) for s in ("system", "operating", "gearbox")
    )
    sblocks, gblocks, mblocks, bblocks, cblocks = (
        _blocks(ctx, data, section, schema)
        for section, schema in (
            ("shaft", _SHAFT),
            ("gear", _GEAR),
            ("mesh", _MESH),
            ("bearing", _BEARING),
            ("coupling", _COUPLING),
        )
    )
    if not mblocks:
        raise ConfigError(f"{ctx.source}: no [[mesh]]: a gearbox needs at least one mesh")
    rigid = [_body(ctx, i, t) for i, t in enumerate(data.get("body", []) or [])]
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
            g = Gear(  # a key not given takes the Gear's default
                name=blk.element,
                shaft=sh,
                helix_angle=helix,
                **{k: blk.get(k) for k in _GEAR if blk.has(k) and k not in _GEAR_CHECKED},
                hand=blk.get("hand", default="right", assumed="not given: right hand" if helix > 0 else None),
            )
        except ModelError as e:
            raise blk.wrap(e) from None
        for key in ("reference_radius", "base_radius"):
            _check_radius(blk, key, getattr(g, key), g)
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
        raise ctx.model("mesh", str(e)) from None
    zref = pairs[ref_i][3] * speeds[pairs[ref_i][1]]
    ratios = {nm: sp_z * speeds[sp] / zref for (nm, sp, _, sp_z, _) in pairs}
    body_speed: dict[str, Fraction] = {  # a body coupled to a shaft turns with it
        blk.get("body"): speeds[blk.get("shaft")] for blk in cblocks if blk.has("body") and blk.get("shaft") in speeds
    }
    loads_raw = list(enumerate(data.get("load", []) or []))
    order_ratios = _order_ratios(ctx, loads_raw, gears, speeds, body_speed, zref)
    bound = gbb.get("max_period", default=DEFAULT_MAX_PERIOD)
    if not 1 <= bound <= 10**6:
        raise gbb.merr("max_period", f"must be from 1 to 1000000 reference mesh cycles, got {bound}")
    period = forcing_period([*ratios.values(), *order_ratios.values()])
    rounded = False
    if period > bound:
        if not gbb.get("round_ratios", default=False):
            every = {**{f"mesh {k!r}": v for k, v in ratios.items()}, **order_ratios}
            causes = ", ".join(f"{k} at {v}" for k, v in every.items() if v.denominator > 1)
            raise ctx.model(
                "gearbox" if "gearbox" in data else "mesh",
                f"the forcing period (the meshes' hunting period) is {period} cycles of mesh {ref!r}, above the "
                f"bound max_period = {bound} ({causes} of its frequency); raise [gearbox] "
                "max_period or set round_ratios = true",
            )
        if order_ratios and forcing_period(order_ratios.values()) > bound:
            raise ctx.model(
                "load",
                f"the torque orders alone repeat only after {forcing_period(order_ratios.values())} cycles of mesh "
                f"{ref!r}, above max_period = {bound}; rounding changes mesh ratios, not orders: raise max_period",
            )
        ratios = {k: round_ratio(v, bound) for k, v in ratios.items()}
        period = forcing_period([*ratios.values(), *order_ratios.values()])
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
            assumed="not given: stiffness-proportional shaft damping beta = 1e-7 s (0.03 % of critical at 1 kHz)",
        )
        pos_list, secs = _discretise(segs, feats[name], per)
        K, M, G = shaft_matrices(ShaftMesh(tuple(pos_list), tuple(secs)), mat)
        K = 0.5 * (K + K.T)
        M = 0.5 * (M + M.T)
        node_names, node_feats, radii = [], [], []
        for k, p in enumerate(pos_list):
            here = next((items for q, items in feats[name].items() if abs(q - p) < 1e-9), [])
            gs = [gears[n] for n in here if n in gears]
            nn = ([g.name for g in gs] or here or [f"{name}_{k}"])[0]
            if nn in body_names:
                nn = f"{name}_{k}"
            body_names.add(nn)
            node_names.append(nn)
            node_feats.append(tuple(here))
            for q in feats[name]:
                if abs(q - p) < 1e-9:
                    node_at[(name, q)] = nn
            blockm = np.diag(np.diag(M[6 * k : 6 * k + 6, 6 * k : 6 * k + 6]))
            for g in gs:
                m, ip, idia = g.blank(mat.rho, _section_at(segs, g.position).outer)
                blockm += np.diag([m, m, m, idia, idia, ip])
                G[6 * k : 6 * k + 6, 6 * k : 6 * k + 6] += disc_gyroscopic(ip)
            bodies.append(NodeBody(nn, NODE_DOFS, mass_matrix=tuple(map(tuple, blockm))))
            # the node's radius: its gear's reference radius, else the shaft's outer radius beside it
            radii.append(max([g.reference_radius for g in gs] or [s.outer / 2 for s in secs[max(k - 1, 0) : k + 1]]))
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
                tuple(radii),
            )
        )

    # bearings and couplings
    rolling = []
    # a rolling bearing's ball-pass ratio: the nearest multiple of 1/L, L the largest multiple of the forcing
    # period of the meshes and orders within max_period, so the forcing period stays within max_period
    grain = period * max(1, bound // period)
    for blk in bblocks:
        node = node_at[where[blk.element]]
        if blk.has("type"):
            linear = [k for k in blk.data if k not in ROLLING_KEYS and k not in ("shaft", "position")]
            if linear:
                raise blk.cerr(linear[0], "not allowed in a rolling bearing (type = 'ball' or 'roller')")
            sp = speeds[where[blk.element][0]] / zref
            rolling.append(read_rolling(blk, node, None, sp, lambda x: round_ratio(Fraction(x), grain)))
            continue
        extra = [k for k in ROLLING_KEYS if blk.has(k) and k not in ("name", "cx", "cy")]
        if extra:
            raise blk.cerr(extra[0], 'a rolling-bearing key: give type = "ball" or "roller"')
        try:
            conns.append(_bearing(blk, node))
        except ModelError as e:
            raise blk.wrap(e) from None
    if rolling:
        period = forcing_period([*ratios.values(), *order_ratios.values(), *(b.ratio for b in rolling)])
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

    # meshes
    b_c = sysb.get("characteristic_length")
    if b_c is None:
        b_c = half_backlash(mblocks[ref_i], mblocks[ref_i].get("backlash", default=0.0))
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
    loads = _loads(ctx, loads_raw, gears, node_at, where, speeds, body_speed, rmap, zref)
    common = described(ctx, data, sysb, opb, ref)
    kin = {
        "reference_mesh": ref,
        "reference_shaft": pairs[ref_i][1],
        "shaft_speed_ratios": {s: str(v) for s, v in speeds.items()},
        "mesh_ratios": {k: str(v) for k, v in ratios.items()},
        "order_ratios": {k: str(v) for k, v in order_ratios.items()},
        "ball_pass_ratios": {b.name: str(b.ratio) for b in rolling},
        "forcing_period_mesh_cycles": period,
        "rounded": rounded,
    }
    kinds = {s.name: "shaft" for s in shafts} | {b.element: "bearing" for b in bblocks}
    kinds |= {b.element: "coupling" for b in cblocks} | {m.name: "mesh" for m in meshes}
    return GearboxDescription(
        bodies=tuple(bodies) + tuple(rigid),
        meshes=tuple(meshes),
        connections=tuple(conns),
        loads=tuple(loads),
        shafts=tuple(shafts),
        kinematics=kin,
        element_kinds=kinds,
        rolling_bearings=tuple(rolling),
        gyroscopic=gbb.get("gyroscopic", default=False),
        **common,
    )


def _mesh(blk, gp, gg, node_at, where, senses, ratio, rounded, b_c, torque_default, shafts) -> Mesh:
    name = blk.element
    geo = pair_geometry_of(name, gp, gg)
    _check_radius(blk, "base_radius1", geo["rb1"], gp)
    _check_radius(blk, "base_radius2", geo["rb2"], gg)
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
    vector = tuple(((n, d), float(c)) for n, v in ((n1, v1), (n2, v2)) for d, c in zip(NODE_DOFS, v) if c != 0.0)
    backlash = blk.get("backlash", default=0.0, assumed="no backlash given: 0 (a linear mesh)")
    if backlash >= 0.5 * np.pi * gp.module:  # the normal tooth thickness at the reference circle
        raise blk.merr(
            "backlash",
            f"{backlash * 1e3:g} mm is not below the tooth thickness π m_n/2 = {0.5e3 * np.pi * gp.module:.3g} mm "
            '(a backlash is tens of µm: e.g. "0.08 mm")',
        )
    if blk.has("excitation"):
        if blk.has("stiffness"):
            raise blk.cerr("excitation", "give the table or stiffness, not both")
        series = {"stiffness": None} | excitation_table(blk)
    elif blk.has("stiffness"):
        series = mesh_series(blk, b_c)
    else:
        for key in ("kappa", "k", "eps", "e", "phi_k", "phi_e"):
            if blk.has(key):
                raise blk.cerr(key, "harmonics need the mean stiffness (the tooth model gives both otherwise)")
        torque = blk.get("torque", default=torque_default)
        if torque is None:
            raise blk.cerr(
                None,
                "the tooth model needs the pinion torque: give torque, a driving [[load]] (a positive torque), "
                "or stiffness",
            )
        if not blk.has("torque"):
            blk.ctx.assume(Assumption(f"{name}.torque", torque, "N*m", "the pinion torque of the drive loads"))
        H = blk.get("harmonics", default=3)
        mat = next(s.material for s in shafts if s.name == gp.shaft)
        te = tooth_excitation(gp, gg, geo, torque, H, mat.E, mat.nu)
        series = {k: te[k] for k in ("stiffness", "kappa", "phi_k", "e", "phi_e")}
        if max(map(abs, series["e"]), default=0.0) < STE_FLOOR:  # unmodified involutes: e_eq is round-off
            series["e"], series["phi_e"] = (), ()
    damping = mesh_damping(blk)
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
