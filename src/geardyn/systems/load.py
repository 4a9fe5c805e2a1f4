"""System files: a multi-DOF gear system in TOML, with units written out.

A file has the top-level strings ``title`` and ``description`` and these tables (``[[x]]`` may repeat)::

    [system]                      # optional
    reference = "mesh"            # the mesh that sets the scales (default: the first)
    characteristic_length = "0.05 mm"   # b_c (default: half the reference mesh's backlash)
    equivalent_mass = "rotational"      # m_e of a mesh from its rotation entries (default) or "full"

    [operating]                   # optional: a pinion speed (needs the reference mesh's teeth) or ω
    rpm = "3000 rpm"              # or: omega = 0.8

    [[body]]
    name = "pinion"
    dofs = ["x", "y", "z", "theta"]   # translations (global frame) and the rotation about its axis
    mass = "225 kg"
    inertia = "1.772 kg*m^2"          # about its axis; or mass_matrix = [[...]] (SI, over dofs)

    [[connection]]                # a bearing to ground with springs on some DOFs of one body
    name = "pinion_bearing"
    body = "pinion"
    kx = "1e9 N/m"                # kx, ky, kz (N/m), ktheta (N*m/rad); cx, cy, cz, ctheta dampers
    [[connection]]                # or a spring along a coupling vector (one body: to ground)
    name = "shaft"
    kind = "torsional"            # "translational" (default: k in N/m, rotation entries lengths)
    vector = { motor = { theta = 1 }, pinion = { theta = -1 } }
    stiffness = "330 N*m/rad"
    damping = "23.1 N*m*s/rad"
    clearance = "1e-3 rad"        # optional: a dead zone |w·q| <= clearance (a nonlinear element)
    [[connection]]                # or a full matrix (SI) over listed DOFs
    dofs = ["a.x", "b.x"]
    stiffness_matrix = [[1e8, -1e8], [-1e8, 1e8]]

    [[mesh]]
    name = "mesh"
    pinion = "pinion"             # driver and driven body
    gear = "gear"
    type = "bevel"                # "bevel" (keys z1, z2, m_mn, beta_m, alpha_n, Sigma, r1, r2, hand,
                                  # drive_side: geardyn.geometry), "spur" (pressure_angle, base_radius1,
                                  # base_radius2, helix_angle, center_angle, pinion_rotation, hand) or
                                  # "vector" (vector = { pinion = { x = 0.34, theta = "96.6 mm" }, ... })
    stiffness = "2000 N/um"       # mean mesh stiffness k0
    backlash = "0.1 mm"           # normal backlash j (the dead zone is half of it)
    xi0 = 0.1                     # damping ratios (c = 2 ξ √(k0 m_e)); or c0 = "..N*s/m", c = [..]
    xi = [0.05]
    kappa = [0.2]                 # or k = ["400 N/um"]; phases phi_k = ["0 deg"]
    eps = [0.5]                   # STE / b_c; or e = ["25 um"]; phases phi_e
    ratio = 1                     # mesh frequency / base frequency
    teeth = 23                    # pinion teeth (rpm → mesh frequency); bevel: z1

    [[load]]
    body = "pinion"
    torque = "1932 N*m"           # on theta; or dof = "x" and force = "100 N"
    [[load]]
    mesh = "mesh"                 # or: f_p in units of k_ref b_c, applied as the balanced
    fp = 0.2                      # torques ±F_p R_l on the mesh's rotations

    [[bearing]]                   # a rolling-element bearing on a body's x and y (geardyn.systems.rolling)
    name = "brg"
    type = "ball"                 # or "roller" (exponent 10/9)
    body = "pinion"               # its inner ring (the cage turns with it); body2 = "housing" (default ground)
    elements = 8                  # Z
    pitch_diameter = "40 mm"
    element_diameter = "10 mm"
    contact_angle = "0 deg"
    radial_clearance = "5 um"
    load_deflection = "8e9 N/m^1.5"   # Hertzian K (N/m^n, n = 3/2 ball, 10/9 roller)
    cx = "200 N*s/m"              # dampers per direction

Any value may be written ``{ value = ..., assumed = "source" }``; every value geardyn assumes is listed
with its source in :attr:`SystemDescription.assumptions`.  A problem with the file (missing, TOML
syntax, unknown section or key, wrong type or unit) raises :class:`~geardyn.errors.ConfigError`; a
bad value (zero or negative mass, an unknown body, a singular mass matrix, a body with no connection)
raises :class:`~geardyn.errors.ModelError`.  Both messages are one line naming the file, the line and
the element.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from .. import _config_values as cv
from .._config_values import _Key
from ..errors import ConfigError, ModelError
from ..geometry import Assumption, SpiralBevelGearPair
from .description import DOFS, MESH_SERIES_KEYS, Body, Clearance, Connection, Load, Mesh, SystemDescription
from .vectors import bevel_mesh_vector, cylindrical_mesh_vector

__all__ = ["build"]

#: The value kinds of a system file (:mod:`geardyn._config_values`, the validator of every file): name -> kind.
_K = {
    "number": cv._NUMBER,
    "int": cv._INT,
    "text": cv._TEXT,
    "mass": cv._MASS,
    "inertia": cv._INERTIA,
    "length": cv._LENGTH,
    "angle": cv._ANGLE,
    "phase": cv._PHASE,
    "stiffness": cv._STIFF,
    "tstiffness": cv._TSTIFF,
    "damping": cv._DAMP,
    "tdamping": cv._TDAMP,
    "force": cv._FORCE,
    "torque": cv._TORQUE,
    "speed": cv._SPEED,
}

_NONNEGATIVE = frozenset({"mass", "inertia", "stiffness", "tstiffness", "damping", "tdamping"})

_BODY_KEYS = {"name": "text", "dofs": "list", "mass": "mass", "inertia": "inertia", "mass_matrix": "matrix"}
_BEARING_KEYS = {f"k{d}": ("tstiffness" if d == "theta" else "stiffness") for d in DOFS} | {
    f"c{d}": ("tdamping" if d == "theta" else "damping") for d in DOFS
}
_CONN_KEYS = {
    "name": "text",
    "body": "text",
    "kind": "text",
    "vector": "table",
    "stiffness": "any",
    "damping": "any",
    "clearance": "any",
    "dofs": "list",
    "stiffness_matrix": "matrix",
    "damping_matrix": "matrix",
} | _BEARING_KEYS
_MESH_COMMON = (
    {"name": "text", "pinion": "text", "gear": "text", "type": "text", "stiffness": "stiffness"}
    | MESH_SERIES_KEYS
    | {"teeth": "int", "vector": "table", "excitation": "text", "excitation_harmonics": "int"}
)
_MESH_SPUR = {
    "pressure_angle": "angle",
    "helix_angle": "angle",
    "base_radius1": "length",
    "base_radius2": "length",
    "center_angle": "angle",
    "pinion_rotation": "text",
    "hand": "text",
}
_MESH_BEVEL = {
    "z1": "int",
    "z2": "int",
    "m_mn": "length",
    "beta_m": "angle",
    "alpha_n": "angle",
    "Sigma": "angle",
    "r1": "length",
    "r2": "length",
    "hand": "text",
    "drive_side": "text",
}
_LOAD_KEYS = {
    "body": "text",
    "dof": "text",
    "force": "force",
    "torque": "torque",
    "mesh": "text",
    "fp": "number",
    "orders": "orders",
}
_SECTIONS = {
    "system": {"reference": "text", "characteristic_length": "length", "equivalent_mass": "text"},
    "operating": {"rpm": "speed", "omega": "number"},
}
#: The arrays of tables of a system file, in the order they are read.
_ARRAYS = ("body", "connection", "mesh", "load", "bearing")
_TOP_TEXT = ("title", "description")


class _Ctx(cv._Ctx):
    """The file's place finder (:class:`geardyn._config_values._Ctx`) with the assumptions made while reading."""

    def __init__(self, source: str, text: str):
        super().__init__(source, text)
        self.assumptions: list[Assumption] = []

    def assume(self, a: Assumption | str, *fields: Any) -> None:
        """Record an assumed input: an :class:`~geardyn.geometry.Assumption`, or its fields (name, value, unit,
        source), so that a reader elsewhere need not import the geometry package."""
        if isinstance(a, str):
            a = Assumption(a, *fields)
        if all(x.name != a.name for x in self.assumptions):
            self.assumptions.append(a)

    def line_containing(self, section: str, index: int, text: str) -> int | None:
        """First line of block ``index`` of ``[[section]]`` that contains ``text`` (quoted)."""
        start = self.line(section, index, None)
        if start is None:
            return None
        for i in range(start, len(self.lines)):
            line = self.lines[i]
            if line.lstrip().startswith("["):
                break
            if f'"{text}"' in line or f"'{text}'" in line or re.search(rf"\b{re.escape(text)}\s*=", line):
                return i + 1
        return None

    def config(self, section, problem, index=None, key=None, element=None, cls=ConfigError) -> ConfigError:
        """A file problem placed on its line: at ``key`` of block ``index`` of ``section``, else at the block."""
        return self.error(section, key, problem, cls, index=index, element=element, fallback=True)

    def model(self, section, problem, index=None, key=None, element=None) -> ModelError:
        """A bad value placed on its line, as :meth:`config`."""
        return self.config(section, problem, index, key, element, ModelError)


def _strip(msg: str) -> tuple[str | None, str]:
    """Split a ModelError message "kind 'name': key: problem" into (key, problem)."""
    m = re.match(r"^(?:body|connection|clearance|mesh|gear|load on \S+) ?(?:'[^']*')?: (.*)$", msg)
    rest = m.group(1) if m else msg
    km = re.match(r"^([A-Za-z_][\w]*): (.*)$", rest)
    return km.groups() if km else (None, rest)


class _Block:
    """One table of the file, with its place, for reading values (through the one validator,
    :func:`geardyn._config_values._parse_value`)."""

    def __init__(self, ctx: _Ctx, section: str, index: int | None, data: dict, schema: dict, element: str | None):
        self.ctx, self.section, self.index, self.data, self.schema = ctx, section, index, data, schema
        self.element = element
        if not isinstance(data, dict):
            raise ConfigError(f"{ctx.source}: [{section}] must be a table")
        for key in data:
            if key not in schema:
                raise self.cerr(key, f"unknown key; allowed: {', '.join(schema)}")

    def cerr(self, key, problem) -> ConfigError:
        return self.ctx.config(self.section, problem, self.index, key, self.element)

    def merr(self, key, problem) -> ModelError:
        return self.ctx.model(self.section, problem, self.index, key, self.element)

    def wrap(self, err: ModelError) -> ModelError:
        if str(err).startswith(f"{self.ctx.source}: "):  # already placed in the file
            return err
        key, problem = _strip(str(err))
        if key is not None and key not in self.data:  # a key of another table (a gear's module): keep it in the text
            key, problem = None, f"{key}: {problem}"
        return self.merr(key, problem)

    def has(self, key: str) -> bool:
        return key in self.data

    def need(self, *keys: str) -> None:
        """Refuse the table unless it has all ``keys``."""
        missing = [k for k in keys if not self.has(k)]
        if missing:
            raise self.cerr(None, f"missing key(s) {', '.join(missing)}")

    def _where(self, key: str, kind: str) -> dict[str, Any]:
        return {
            "index": self.index,
            "element": self.element,
            "nonnegative": kind in _NONNEGATIVE or key == "backlash",
        }

    def get(self, key: str, kind: str | None = None, default: Any = None, assumed: str | None = None) -> Any:
        """The value of ``key`` in SI (``default`` marked assumed with ``assumed`` when missing)."""
        kind = kind or self.schema[key]
        base = kind.rstrip("*")
        unit = _K[base].unit or "" if base in _K else ""
        raw = self.data.get(key)
        if key not in self.data:
            value, src = default, assumed
        elif base in _K:
            spec = _Key(_K[base], kind.endswith("*"))
            value, src = cv._parse_value(self.ctx, self.section, key, spec, raw, **self._where(key, base))
        elif isinstance(raw, dict) and kind != "table":
            value, src = self._parse(key, kind, self.inline_value(key)), raw.get("assumed")
        else:
            value, src = self._parse(key, kind, raw), None
        if src:
            shown = list(value) if isinstance(value, tuple) else value
            self.ctx.assume(Assumption(f"{self.element or self.section}.{key}", shown, unit, src))
        return value

    def inline_value(self, key: str) -> Any:
        """The value of ``key`` as written: the ``value`` of an inline table ``{ value = ..., assumed = ... }``."""
        raw = self.data.get(key)
        if not isinstance(raw, dict):
            return raw
        if set(raw) - {"value", "assumed"} or "value" not in raw:
            raise self.cerr(key, "an inline table must have the keys 'value' and optionally 'assumed'")
        return raw["value"]

    def _parse(self, key: str, kind: str, raw: Any) -> Any:
        if kind == "list":
            if not isinstance(raw, list) or not all(isinstance(x, str) for x in raw):
                raise self.cerr(key, f"expected a list of strings, got {raw!r}")
            return list(raw)
        if kind == "matrix":
            try:
                a = np.array(raw, dtype=float)
            except (TypeError, ValueError):
                a = None
            if a is None or a.ndim != 2 or isinstance(raw, str):
                raise self.cerr(key, "expected a matrix of plain numbers in SI units, e.g. [[1e8, -1e8], [-1e8, 1e8]]")
            return a
        if kind == "table":
            if not isinstance(raw, dict):
                raise self.cerr(key, f"expected a table, got {raw!r}")
            return raw
        return self._scalar(key, kind, raw)

    def _scalar(self, key: str, kind: str, raw: Any, item: int | None = None) -> Any:
        return cv._parse_scalar(self.ctx, self.section, key, _K[kind], raw, item, **self._where(key, kind))


# ---------------------------------------------------------------------------- elements
def _body(ctx: _Ctx, i: int, data: dict) -> Body:
    name = data.get("name") if isinstance(data.get("name"), str) else f"body{i + 1}"
    blk = _Block(ctx, "body", i, data, _BODY_KEYS, name)
    if not blk.has("dofs"):
        raise blk.cerr(None, f"missing key 'dofs' (a list from {', '.join(DOFS)})")
    try:
        return Body(name, tuple(blk.get("dofs")), blk.get("mass"), blk.get("inertia"), blk.get("mass_matrix"))
    except ModelError as e:
        raise blk.wrap(e) from None


def _dof_ref(blk: _Block, key: str, text: str) -> tuple[str, str]:
    if not isinstance(text, str) or text.count(".") != 1:
        raise blk.cerr(key, f"a DOF is written 'body.dof' (e.g. 'pinion.x'), got {text!r}")
    return tuple(text.split("."))


def springs(blk: _Block, dofs: tuple[str, ...]) -> tuple[dict[str, float], dict[str, float]]:
    """A bearing table's stiffnesses ``k<dof>`` and dampers ``c<dof>`` given on ``dofs``."""
    return tuple({d: blk.get(f"{x}{d}") for d in dofs if blk.has(f"{x}{d}")} for x in "kc")


def _vector(blk: _Block, table: dict, translational: bool) -> dict[tuple[str, str], float]:
    out: dict[tuple[str, str], float] = {}
    for body, comps in table.items():
        if not isinstance(comps, dict):
            raise blk.cerr("vector", f"body {body!r}: expected a table of DOF = coefficient, e.g. {{ x = 1 }}")
        for d, raw in comps.items():
            if d not in DOFS:
                raise blk.cerr("vector", f"body {body!r}: unknown DOF {d!r}; allowed: {', '.join(DOFS)}")
            if d != "theta" and not translational:
                raise blk.cerr("vector", f"body {body!r}: a torsional element has rotation entries only")
            # a translational element's rotation entry is a lever arm (a length); every other entry a number
            out[(body, d)] = blk._scalar("vector", "length" if d == "theta" and translational else "number", raw)
    return out


def _connection(ctx: _Ctx, i: int, data: dict):
    name = data.get("name") if isinstance(data.get("name"), str) else f"connection{i + 1}"
    blk = _Block(ctx, "connection", i, data, _CONN_KEYS, name)
    forms = [f for f in ("body", "vector", "stiffness_matrix") if blk.has(f)]
    if len(forms) != 1:
        raise blk.cerr(
            None, "give one of: body (a bearing with kx, ky, kz, ktheta), vector, or dofs + stiffness_matrix"
        )
    try:
        if forms[0] == "body":
            bad = [k for k in data if k not in _BEARING_KEYS and k not in ("name", "body")]
            if bad:
                raise blk.cerr(bad[0], "not allowed in a bearing given by body (use kx, ky, kz, ktheta, cx, ...)")
            body = blk.get("body")
            k, c = springs(blk, DOFS)
            if not k:
                raise blk.cerr(None, "a bearing needs at least one stiffness (kx, ky, kz or ktheta)")
            return Connection.diagonal(name, body, k, c)
        if forms[0] == "stiffness_matrix":
            if not blk.has("dofs"):
                raise blk.cerr("stiffness_matrix", "needs dofs = ['body.dof', ...] (its rows)")
            dofs = tuple(_dof_ref(blk, "dofs", t) for t in blk.get("dofs"))
            return Connection(name, dofs, blk.get("stiffness_matrix"), blk.get("damping_matrix"))
        kind = blk.get("kind", default="translational")
        if kind not in ("translational", "torsional"):
            raise blk.cerr("kind", f"must be 'translational' or 'torsional', got {kind!r}")
        tr = kind == "translational"
        vec = _vector(blk, blk.get("vector"), tr)
        if not blk.has("stiffness"):
            raise blk.cerr(None, "missing key 'stiffness'")
        k = blk.get("stiffness", "stiffness" if tr else "tstiffness")
        c = blk.get("damping", "damping" if tr else "tdamping", default=0.0, assumed="no damping given: 0")
        if blk.has("clearance"):
            gap = blk.get("clearance", "length" if tr else "angle")
            return Clearance(name, tuple(vec.items()), k, gap, c)
        return Connection.along(name, vec, k, c)
    except ModelError as e:
        raise blk.wrap(e) from None


def _mesh_block(ctx: _Ctx, i: int, data: Any) -> _Block:
    """A ``[[mesh]]`` table's block: the keys of every mesh and those of its type."""
    d = data if isinstance(data, dict) else {}
    name = d.get("name") if isinstance(d.get("name"), str) else f"mesh{i + 1}"
    return _Block(
        ctx, "mesh", i, data, _MESH_COMMON | {"spur": _MESH_SPUR, "bevel": _MESH_BEVEL}.get(d.get("type"), {}), name
    )


def _mesh(ctx: _Ctx, i: int, data: dict, bodies: dict[str, Body], b_c: float | None) -> Mesh:
    typ = data.get("type", "vector")
    blk = _mesh_block(ctx, i, data)
    name = blk.element
    if typ not in ("vector", "spur", "bevel"):
        raise blk.cerr("type", f"must be 'vector', 'spur' or 'bevel', got {typ!r}")
    if not (blk.has("stiffness") or blk.has("excitation")):
        raise blk.cerr(None, "missing key 'stiffness' (the mean mesh stiffness, e.g. \"2000 N/um\")")
    try:
        backlash = blk.get("backlash", default=0.0, assumed="no backlash given: 0 (a linear mesh)")
        teeth = blk.get("teeth")
        if typ == "vector":
            if not blk.has("vector"):
                raise blk.cerr(None, "a mesh of type 'vector' needs vector = { body = { dof = ... } }")
            vector = tuple(_vector(blk, blk.get("vector"), True).items())
        else:
            if blk.has("vector"):
                raise blk.cerr("vector", f"not allowed with type = {typ!r} (the vector comes from the geometry)")
            p, g = blk.get("pinion"), blk.get("gear")
            if p is None or g is None:
                raise blk.cerr(None, 'needs the bodies: pinion = "..." and gear = "..."')
            for key, b in (("pinion", p), ("gear", g)):
                if b not in bodies:
                    raise blk.merr(key, f"unknown body {b!r}; bodies: {', '.join(bodies)}")
            d1, d2 = bodies[p].dofs, bodies[g].dofs
            if typ == "spur":
                for key in ("pressure_angle", "base_radius1", "base_radius2"):
                    if not blk.has(key):
                        raise blk.cerr(None, f"missing key {key!r}")
                helix = blk.get("helix_angle", default=0.0)
                vector = cylindrical_mesh_vector(
                    p,
                    g,
                    d1,
                    d2,
                    **{k: blk.get(k) for k in ("pressure_angle", "base_radius1", "base_radius2")},
                    helix_angle=helix,
                    center_angle=blk.get(
                        "center_angle",
                        default=0.0,
                        assumed="not given: the line of centres from pinion to gear along +x",
                    ),
                    pinion_rotation=blk.get(
                        "pinion_rotation",
                        default="counterclockwise",
                        assumed="not given: the pinion runs counterclockwise seen from +z",
                    ),
                    hand=blk.get(
                        "hand", default="right", assumed="not given: right-hand pinion helix" if helix > 0 else None
                    ),
                )
            else:
                blk.need("z1", "z2", "m_mn", "beta_m", "alpha_n")
                keys = ("Sigma", "r1", "r2", "hand", "drive_side", "z1", "z2", "m_mn", "beta_m", "alpha_n")
                kw = {k: blk.get(k) for k in keys if blk.has(k)}
                pair = SpiralBevelGearPair(
                    j_n=backlash,
                    I1=bodies[p].inertia or 1.0,
                    I2=bodies[g].inertia or 1.0,
                    k0=blk.get("stiffness"),
                    **kw,
                )
                for a in pair.assumptions:
                    if a.name in ("r1", "r2", "hand", "drive_side"):
                        ctx.assume(Assumption(f"{name}.{a.name}", a.value, a.unit, a.source))
                vector = bevel_mesh_vector(pair, p, g, d1, d2)
                teeth = pair.z1 if teeth is None else teeth
        series = mesh_series(blk, b_c) | mesh_damping(blk)  # b_c is known: see build
        return Mesh(
            name=name,
            vector=vector,
            backlash=backlash,
            phi_c=blk.get("phi_c", default=()),
            ratio=blk.get("ratio", default=1.0),
            teeth=teeth,
            **series,
            **(excitation_table(blk) if blk.has("excitation") else {}),
        )
    except ModelError as err:
        raise blk.wrap(err) from None


def mesh_series(blk: _Block, b_c: float) -> dict[str, Any]:
    """The mean stiffness and the stiffness and STE harmonics of a ``[[mesh]]`` written out (kappa or k, eps or e)."""
    kappa = blk.get("kappa", default=())
    k0 = blk.get("stiffness")
    if blk.has("k"):
        if blk.has("kappa"):
            raise blk.cerr("k", "give kappa (relative) or k (N/m), not both")
        kappa = tuple(x / k0 for x in blk.get("k"))
    e = blk.get("e", default=())
    if blk.has("eps"):
        if blk.has("e"):
            raise blk.cerr("eps", "give eps (relative to b_c) or e (a length), not both")
        e = tuple(x * b_c for x in blk.get("eps"))
    return {
        "stiffness": k0,
        "kappa": kappa,
        "phi_k": blk.get("phi_k", default=()),
        "e": e,
        "phi_e": blk.get("phi_e", default=()),
    }


def excitation_table(blk: _Block) -> dict[str, Any]:
    """A ``[[mesh]]``'s excitation table (its path beside the file) and the harmonics kept of it."""
    return {
        "excitation": str(Path(blk.ctx.source).parent / blk.get("excitation")),
        "excitation_harmonics": blk.get("excitation_harmonics"),
    }


def mesh_damping(blk: _Block) -> dict[str, Any]:
    """A ``[[mesh]]``'s damping: c0 and c (N·s/m) when given, else the ratios xi0 (default 0.1) and xi."""
    if any(blk.has(k) for k in ("c0", "c")):
        return {"c0": blk.get("c0", default=0.0), "c": blk.get("c", default=())}
    return {
        "xi0": blk.get("xi0", default=0.1, assumed="not given: geardyn's default mean mesh damping ratio 0.1"),
        "xi": blk.get("xi", default=()),
    }


def _orders(blk: _Block) -> tuple:
    """``orders = [{ order = 2, amplitude = "40 N*m", phase = "0 deg" }, ...]`` of a load: (k, N·m, rad) tuples."""
    if not blk.has("orders"):
        return ()
    raw = blk.data["orders"]
    if not isinstance(raw, list) or not raw or not all(isinstance(e, dict) for e in raw):
        raise blk.cerr("orders", 'expected a list of tables { order = 2, amplitude = "40 N*m", phase = "0 deg" }')
    where = {"index": blk.index, "element": blk.element}
    return tuple(cv._order_tables(blk.ctx, blk.section, "orders", raw, cv._TORQUE, cv._ANGLE, **where))


def _body_speed(body: str, mesh_data: list, meshes: dict[str, Mesh]):
    """The shaft speed of ``body`` over the base frequency, from a mesh whose pinion or gear it is and whose
    teeth on that body are given (spur: ``teeth`` of the pinion; bevel: z1, z2): Ω/ω = ratio/z."""
    from fractions import Fraction

    from .assemble import MAX_RATIO_DENOMINATOR

    for i, t in enumerate(mesh_data):
        if not isinstance(t, dict):
            continue
        name = t.get("name", f"mesh{i + 1}")
        m = meshes.get(name)
        if m is None:
            continue
        teeth = {}
        if t.get("pinion") is not None:
            z1 = t.get("z1", t.get("teeth"))
            teeth[t["pinion"]] = z1.get("value") if isinstance(z1, dict) else z1
        if t.get("gear") is not None and t.get("z2") is not None:
            z2 = t["z2"]
            teeth[t["gear"]] = z2.get("value") if isinstance(z2, dict) else z2
        z = teeth.get(body)
        if isinstance(z, int) and not isinstance(z, bool) and z > 0:
            return Fraction(m.ratio).limit_denominator(MAX_RATIO_DENOMINATOR) / z
    raise ModelError(
        f"load on {body}.theta: orders: the speed of body {body!r} is unknown: give the teeth of a mesh on it "
        "(teeth of the pinion of a spur mesh, z1/z2 of a bevel mesh)"
    )


def _loads(
    ctx: _Ctx, i: int, data: dict, meshes: dict[str, Mesh], k_ref: float, b_c: float, mesh_data: list = ()
) -> list[Load]:
    where = data.get("body") or data.get("mesh")
    blk = _Block(ctx, "load", i, data, _LOAD_KEYS, where if isinstance(where, str) else None)
    if blk.has("mesh"):
        if not blk.has("fp") or any(blk.has(k) for k in ("body", "dof", "force", "torque", "orders")):
            raise blk.cerr(None, 'a load on a mesh is given as mesh = "..." and fp = <number> only')
        mname = blk.get("mesh")
        if mname not in meshes:
            raise blk.merr("mesh", f"unknown mesh {mname!r}; meshes: {', '.join(meshes)}")
        Fp = blk.get("fp") * k_ref * b_c
        # the balanced torques: T_l = ±F_p R_l on the rotations of the mesh's bodies
        return [Load(b, d, Fp * v) for (b, d), v in meshes[mname].vector if d == "theta"]
    if not blk.has("body") or blk.has("fp"):
        raise blk.cerr(None, 'a load needs body = "..." and torque = "... N*m" (or dof and force)')
    if blk.has("torque") == blk.has("force"):
        raise blk.cerr(None, 'give torque (on theta) or force (with dof = "x", "y" or "z")')
    if blk.has("orders") and not blk.has("torque"):
        raise blk.cerr("orders", 'torque orders act on a torque load: give torque = "... N*m" (its mean, may be 0)')
    if blk.has("torque"):
        if blk.get("dof", default="theta") != "theta":
            raise blk.cerr("dof", "a torque acts on theta")
        body = blk.get("body")
        orders = _orders(blk)
        try:
            speed = _body_speed(body, mesh_data, meshes) if orders else None
            return [Load(body, "theta", blk.get("torque"), orders, speed)]
        except ModelError as e:
            raise blk.merr("orders", str(e).split(": orders: ", 1)[-1]) from None
    dof = blk.get("dof")
    if dof not in ("x", "y", "z"):
        raise blk.cerr("dof", f"a force acts on x, y or z, got {dof!r}")
    return [Load(blk.get("body"), dof, blk.get("force"))]


def _rolling(ctx: _Ctx, i: int, data: dict, mesh_data: list, meshes: dict[str, Mesh]):
    """A ``[[bearing]]``: a rolling-element bearing on a body's x and y (:mod:`geardyn.systems.rolling`)."""
    from .rolling import ROLLING_KEYS, read_rolling, round_ball_pass

    name = data.get("name") if isinstance(data.get("name"), str) else f"bearing{i + 1}"
    blk = _Block(ctx, "bearing", i, data, ROLLING_KEYS | {"body": "text", "body2": "text"}, name)
    if not blk.has("body"):
        raise blk.cerr(None, 'a bearing needs body = "..." (the body on its inner ring, with x and y)')
    body = blk.get("body")
    try:
        speed = _body_speed(body, mesh_data, meshes)
    except ModelError:
        raise blk.merr(
            "body", f"the speed of body {body!r} is unknown: give the teeth of a mesh on it (the cage turns with it)"
        ) from None
    return read_rolling(blk, body, blk.get("body2"), speed, round_ball_pass)


# ---------------------------------------------------------------------------- the file
def _element_line(ctx: _Ctx, data: dict, err: ModelError) -> ModelError:
    """Place a system-level ModelError ("kind 'name': ...") on its element's block."""
    msg = str(err)
    m = re.match(r"^(body|connection|clearance|mesh|element) '([^']*)': (.*)$", msg)
    if m:
        kind, name, rest = m.groups()
        sections = {"clearance": "connection", "element": None}.get(kind, kind)
        for sec in [sections] if sections else ["connection", "mesh"]:
            for i, tbl in enumerate(data.get(sec, []) or []):
                if isinstance(tbl, dict) and tbl.get("name", f"{sec}{i + 1}") == name:
                    key, problem = _strip(rest)
                    key = key if key in tbl else None
                    um = re.search(r"unknown body '([^']*)'", rest)
                    ln = ctx.line_containing(sec, i, um.group(1)) if um and key is None else None
                    if key is None and (ln or "name" in tbl):  # the line of the unknown body, else of the name
                        ln = ln or ctx.line(sec, i, "name")
                        return ModelError(f"{ctx.source}: line {ln}: [[{sec}]] {name!r}: {rest}")
                    return ctx.model(sec, problem if key else rest, i, key, name)
    m = re.match(r"^(reference|characteristic_length): (.*)$", msg)
    if m:
        return ctx.model("system", m.group(2), key=m.group(1))
    return ModelError(f"{ctx.source}: {msg}")


def check_top(ctx: _Ctx, data: dict, sections: dict, arrays: tuple[str, ...], gearbox: bool = False) -> None:
    """Refuse a top-level key of a system (or ``gearbox``) file that is none of its sections, arrays of tables
    and texts, or of the wrong type."""
    for key, val in data.items():
        if key in _TOP_TEXT:
            if not isinstance(val, str):
                raise ctx.config(None, f"{key}: expected a string")
        elif key in arrays:
            if not isinstance(val, list):
                at = "" if gearbox else f"line {ctx.line(key, None, None) or '?'}: "
                raise ConfigError(f"{ctx.source}: {at}{key}: write [[{key}]] tables")
        elif key not in sections:
            allowed = ", ".join([f"[{s}]" for s in sections] + [f"[[{s}]]" for s in arrays] + list(_TOP_TEXT))
            if gearbox:
                raise ConfigError(f"{ctx.source}: unknown section or key {key!r} in a gearbox file; allowed: {allowed}")
            raise ConfigError(
                f"{ctx.source}: line {_top_line(ctx, key) or '?'}: unknown section or key {key!r}; allowed: {allowed}"
            )


def build(ctx: _Ctx, data: dict) -> SystemDescription:
    """The description of a parsed system file of bodies (a file with ``[[shaft]]`` tables is a gearbox:
    :func:`geardyn.systems.files.load_description` dispatches).

    Parameters
    ----------
    ctx : _Ctx
        The file's locator (its source and lines).
    data : dict
        The parsed file.

    Returns
    -------
    SystemDescription
    """
    check_top(ctx, data, _SECTIONS, _ARRAYS)
    sysb, opb = (_Block(ctx, s, None, data.get(s, {}), keys, None) for s, keys in _SECTIONS.items())
    bodies = [_body(ctx, i, t) for i, t in enumerate(data.get("body", []))]
    if not bodies:
        raise ConfigError(f"{ctx.source}: no [[body]]: a system needs bodies")
    _unique(ctx, "body", [b.name for b in bodies])
    bmap = {b.name: b for b in bodies}
    conns, clears = [], []
    for i, t in enumerate(data.get("connection", [])):
        c = _connection(ctx, i, t)
        (clears if isinstance(c, Clearance) else conns).append(c)
    mesh_data = data.get("mesh", [])
    if not mesh_data:
        raise ConfigError(f"{ctx.source}: no [[mesh]]: a system needs at least one gear mesh")
    ref = sysb.get("reference")
    b_c = sysb.get("characteristic_length")
    if b_c is None:  # half the reference mesh's backlash, read first so that eps can be converted
        names = [t.get("name", f"mesh{i + 1}") if isinstance(t, dict) else None for i, t in enumerate(mesh_data)]
        if ref is not None and ref not in names:
            raise ctx.model("system", f"unknown mesh {ref!r}; meshes: {', '.join(map(str, names))}", key="reference")
        j = names.index(ref) if ref is not None else 0
        rb = _mesh_block(ctx, j, mesh_data[j])
        b_c = half_backlash(
            rb, rb._parse("backlash", "length", rb.inline_value("backlash")) if rb.has("backlash") else 0.0
        )
    meshes = [_mesh(ctx, i, t, bmap, b_c) for i, t in enumerate(mesh_data)]
    _unique(ctx, "mesh", [m.name for m in meshes])
    _unique(ctx, "connection", [getattr(c, "name", None) for c in conns + clears])
    mmap = {m.name: m for m in meshes}
    k_ref = mmap[ref].stiffness if ref in mmap else meshes[0].stiffness
    loads = [ld for i, t in enumerate(data.get("load", [])) for ld in _loads(ctx, i, t, mmap, k_ref, b_c, mesh_data)]
    rolling = [_rolling(ctx, i, t, mesh_data, mmap) for i, t in enumerate(data.get("bearing", []))]
    _unique(ctx, "bearing", [b.name for b in rolling])
    common = described(ctx, data, sysb, opb, ref)
    try:
        return SystemDescription(
            bodies=tuple(bodies),
            meshes=tuple(meshes),
            connections=tuple(conns),
            clearances=tuple(clears),
            loads=tuple(loads),
            rolling_bearings=tuple(rolling),
            **common,
        )
    except ModelError as e:
        raise _element_line(ctx, data, e) from None


def half_backlash(blk: _Block, jn: float) -> float:
    """The default characteristic length: half the reference mesh's backlash ``jn`` (refused when it is 0)."""
    if not jn > 0:
        raise blk.merr("backlash", 'is 0: give [system] characteristic_length (e.g. "1 um") to scale lengths')
    return jn / 2.0


def described(ctx: _Ctx, data: dict, sysb: _Block, opb: _Block, ref: str | None) -> dict[str, Any]:
    """What every system file gives its description besides the elements: the [system] and [operating] values
    (a speed must be > 0; ω = 1 assumed when none is given), the title, the file and the assumptions made."""
    rpm, omega = opb.get("rpm"), opb.get("omega")
    if rpm is None and omega is None:
        ctx.assume(Assumption("operating.omega", 1.0, "", "no operating point given: ω = 1"))
    for key, v in (("rpm", rpm), ("omega", omega)):
        if v is not None and not v > 0:
            raise opb.merr(key, f"must be > 0, got {v:g}")
    return {
        "reference": ref,
        "characteristic_length": sysb.get("characteristic_length"),
        "rpm": rpm,
        "omega": omega,
        "equivalent_mass": sysb.get("equivalent_mass", default="rotational"),
        "title": str(data.get("title", "")),
        "source": ctx.source,
        "assumptions": tuple(ctx.assumptions),
    }


def _unique(ctx: _Ctx, section: str, names: list) -> None:
    """Refuse two [[section]] tables of the same name (the second would silently replace the first)."""
    seen: dict[str, int] = {}
    for i, n in enumerate(names):
        if n is not None and n in seen:
            at = f"line {ctx.line(section, seen[n], 'name')}"
            raise ctx.config(section, f"duplicate {section} name {n!r} (also at {at}); names must be unique", i, "name")
        seen[n] = i


def _top_line(ctx: _Ctx, key: str) -> int | None:
    pat = re.compile(rf"^\s*(\[\[?\s*{re.escape(key)}[\s.\]]|{re.escape(key)}\s*=)")
    for i, line in enumerate(ctx.lines, start=1):
        if pat.match(line):
            return i
    return None
