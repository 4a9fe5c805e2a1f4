"""A tooth pair, its modifications, its faults and its run from a TOML file (``examples/tooth_*.toml``).

Values carry their units, as in every other file (``m_n = "3.2 mm"``), read by the configuration's value
parser (:mod:`geardyn._config_values`: one-line errors naming the file, line, section and key).  The
keys and their defaults are the table of ``docs/excitation.md`` (:data:`PAIR_KEYS`, :data:`MOD_KEYS`,
:data:`SIGNATURE_KEYS`, :data:`MESH_KEYS`, :data:`FAULT_KEYS`).  The earlier keys with the unit in their
name (``m_n_mm = 3.2``, ``face_width_mm``, ``torque_Nm``, ``tip_relief_um``, ``fs_Hz`` …) are still read,
as plain numbers in that unit; a key given both ways is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._config_values import (
    _ANGLE,
    _INT,
    _LENGTH,
    _NUMBER,
    _SPEED,
    _TEXT,
    _TORQUE,
    _choice,
    _Ctx,
    _Key,
    _Kind,
    _parse_value,
    parse_toml,
    read_toml,
)
from ..errors import ConfigError, ModelError
from .faults import Modifications, fault_from_dict
from .geometry import ISO53_RACKS, PairGeometry, pair_geometry
from .mesh import check_plausible

__all__ = ["FAULT_KEYS", "MESH_KEYS", "MOD_KEYS", "PAIR_KEYS", "SIGNATURE_KEYS", "ToothCase", "load_case"]

_MODULUS = _Kind("Young's modulus", "Pa", '"206 GPa"')
_FREQUENCY = _Kind("frequency", "Hz", '"40 kHz"')
#: A section's keys: name → (kind, old key with its unit in the name, factor of the old key's number to SI).
_Keys = dict[str, tuple[_Key, str | None, float]]


def _k(
    kind: _Kind, old: str | None = None, factor: float = 1.0, series: bool = False
) -> tuple[_Key, str | None, float]:
    return _Key(kind, series), old, factor


#: [tooth_pair] keys: (kind, old key with its unit in the name, factor of the old key's number to SI).
PAIR_KEYS: _Keys = {
    "name": _k(_TEXT),
    "z1": _k(_INT),
    "z2": _k(_INT),
    "z_virtual": _k(_NUMBER, series=True),
    "m_n": _k(_LENGTH, "m_n_mm", 1e-3),
    "alpha_n": _k(_ANGLE, "alpha_n_deg", math.pi / 180.0),
    "beta": _k(_ANGLE, "beta_deg", math.pi / 180.0),
    "face_width": _k(_LENGTH, "face_width_mm", 1e-3),
    "x1": _k(_NUMBER),
    "x2": _k(_NUMBER),
    "h_a": _k(_NUMBER),
    "h_f": _k(_NUMBER),
    "rack": _k(_choice(tuple(ISO53_RACKS))),
    "rho_f": _k(_NUMBER),
    "root": _k(_choice(("trochoid", "radial"))),
    "E": _k(_MODULUS, "E_GPa", 1e9),
    "nu": _k(_NUMBER),
    "bore1": _k(_LENGTH, "bore1_mm", 1e-3),
    "bore2": _k(_LENGTH, "bore2_mm", 1e-3),
    "rim1": _k(_LENGTH, "rim1_mm", 1e-3),
    "rim2": _k(_LENGTH, "rim2_mm", 1e-3),
    "torque": _k(_TORQUE, "torque_Nm"),
}
#: [modifications] keys.
MOD_KEYS: _Keys = {
    "tip_relief": _k(_LENGTH, "tip_relief_um", 1e-6, series=True),
    "tip_length": _k(_LENGTH, "tip_length_mm", 1e-3, series=True),
    "root_relief": _k(_LENGTH, "root_relief_um", 1e-6, series=True),
    "root_length": _k(_LENGTH, "root_length_mm", 1e-3, series=True),
    "shape": _k(_choice(("linear", "parabolic"))),
    "crowning": _k(_LENGTH, "crowning_um", 1e-6),
}
#: [mesh] keys.
MESH_KEYS: _Keys = {
    "cycles": _k(_INT),
    "points": _k(_INT),
    "slices": _k(_INT),
}
#: [signature] keys (``rpm`` also as a plain number in rpm).
SIGNATURE_KEYS: _Keys = {
    "rpm": _k(_SPEED),
    "revolutions": _k(_INT),
    "fs": _k(_FREQUENCY, "fs_Hz"),
    "noise": _k(_NUMBER),
    "backlash": _k(_LENGTH, "backlash_um", 1e-6),
    "b_c": _k(_LENGTH, "b_c_um", 1e-6),
    "xi0": _k(_NUMBER),
    "seed": _k(_INT),
}
#: [[fault]] keys: lengths of spalls and wear with units (or in m as plain numbers; or with _mm / _um).
FAULT_KEYS: _Keys = {
    "kind": _k(_choice(("crack", "spall", "wear", "broken"))),
    "gear": _k(_INT),
    "tooth": _k(_INT),
    "depth": _k(_NUMBER),
    "angle_deg": _k(_NUMBER),
    "length": _k(_NUMBER),
    "at": _k(_NUMBER),
    "width": _k(_LENGTH),
    "y0": _k(_NUMBER),
    "remaining": _k(_NUMBER),
}
_FAULT_LENGTHS = {"spall": ("length", "width", "depth"), "wear": ("depth",)}
#: Top-level text keys a tooth-pair file may hold beside its sections.
_TOP_TEXT = ("title", "description")
_SUFFIX = {"_mm": 1e-3, "_um": 1e-6}


@dataclass
class ToothCase:
    """Everything a ``geardyn stiffness`` / ``geardyn signature`` run of one file needs.

    Attributes
    ----------
    name : str
        Name of the case.
    geometry : PairGeometry
        The pair.
    torque : float
        Pinion torque (N·m).
    modifications : Modifications
        Profile and lead modifications.
    faults : list
        Tooth faults.
    mesh : dict
        ``[mesh]`` options (cycles, points, slices).
    signature : dict
        ``[signature]`` options in SI units (``fs`` also as ``fs_Hz``; rpm in rpm).
    """

    name: str
    geometry: PairGeometry
    torque: float
    modifications: Modifications
    faults: list = field(default_factory=list)
    mesh: dict[str, Any] = field(default_factory=dict)
    signature: dict[str, Any] = field(default_factory=dict)

    def mesh_stiffness(self, cycles: int | None = None, points: int | None = None) -> Any:
        """The pair's mesh stiffness and STE (:func:`geardyn.tooth.mesh.mesh_stiffness`) at its torque.

        Parameters
        ----------
        cycles, points : int, optional
            Mesh cycles and phases per cycle (default the file's ``[mesh]`` values, else the hunting
            period's cycles and 64 points).

        Returns
        -------
        MeshStiffness
        """
        from .mesh import mesh_stiffness

        return mesh_stiffness(
            self.geometry,
            self.torque,
            faults=self.faults,
            modifications=self.modifications,
            cycles=cycles if cycles is not None else self.mesh.get("cycles"),
            points=int(points if points is not None else self.mesh.get("points", 64)),
            slices=self.mesh.get("slices"),
        )


def _section(ctx: _Ctx, doc: dict[str, Any], name: str, keys: _Keys) -> dict:
    raw = doc.get(name, {})
    if not isinstance(raw, dict):
        raise ctx.error(name, "", "expected a table")
    old = {o: (k, f) for k, (_, o, f) in keys.items() if o}
    unknown = sorted(set(raw) - set(keys) - set(old))
    if unknown:
        raise ctx.error(name, unknown[0], f"unknown key; allowed: {', '.join(sorted(keys))}")
    out: dict[str, Any] = {}
    for k, v in raw.items():
        if k in old:
            new, factor = old[k]
            if new in raw:
                raise ctx.error(name, k, f"given twice, as {new} and {k}; keep {new} (with its unit)")
            series = keys[new][0].series
            val, _ = _parse_value(ctx, name, k, _Key(_NUMBER, series), v)
            out[new] = tuple(x * factor for x in val) if series else val * factor
        else:
            spec = keys[k][0]
            if spec.kind is _SPEED and isinstance(v, (int, float)) and not isinstance(v, bool):
                v = f"{v!r} rpm"
            out[k], _ = _parse_value(ctx, name, k, spec, v)
    return out


def _fault(ctx: _Ctx, i: int, raw: Any) -> Any:
    if not isinstance(raw, dict):
        raise ctx.error(None, "fault", "write each fault as a [[fault]] table")
    kind = raw.get("kind") if isinstance(raw.get("kind"), str) else None
    where = {"index": i, "element": kind}
    lengths = _FAULT_LENGTHS.get(kind, ())
    d: dict[str, Any] = {}
    for k, v in raw.items():
        base, factor = k, None
        for suf, f in _SUFFIX.items():
            if k.endswith(suf):
                base, factor = k[: -len(suf)], f
        if base == "kind":
            d[base] = v
        elif base in lengths:  # a length with its unit, or a plain number in m (or in the unit of the key's suffix)
            kind = _LENGTH if factor is None and isinstance(v, str) else _NUMBER
            val, _ = _parse_value(ctx, "fault", k, _Key(kind), v, **where)
            d[base] = val * (factor or 1.0)
        elif base in FAULT_KEYS and factor is None:
            spec = FAULT_KEYS[base][0]
            d[base], _ = _parse_value(ctx, "fault", k, _Key(_NUMBER) if spec.kind is _LENGTH else spec, v, **where)
        else:
            raise ctx.error("fault", k, f"unknown key; allowed: {', '.join(sorted(FAULT_KEYS))}", **where)
    try:
        return fault_from_dict(d)
    except ModelError as e:
        raise ctx.error("fault", None, str(e), ModelError, **where) from None


def load_case(path: str | Path) -> ToothCase:
    """Read a tooth-pair file.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    ToothCase

    Raises
    ------
    ConfigError
        For a missing file, invalid TOML, unknown keys, values without their unit or missing required keys
        (one line naming the file, line and key).
    ModelError
        For a physically impossible pair (one line naming the key and the bound).

    Examples
    --------
    >>> case = load_case("examples/tooth_19_48.toml")
    >>> case.geometry.gears[0].teeth, round(case.geometry.m_n * 1e3, 3)
    (19, 3.2)
    """
    source, text = read_toml(path, "tooth-pair file")
    doc = parse_toml(text, source)
    ctx = _Ctx(source, text)
    if not isinstance(doc.get("tooth_pair"), dict):
        raise ConfigError(f"{source}: no [tooth_pair] section")
    sections = ("tooth_pair", "modifications", "mesh", "signature")
    for key, val in doc.items():
        if key in _TOP_TEXT:
            if not isinstance(val, str):
                raise ctx.error(None, key, f"expected a string, got {val!r}")
        elif key not in sections and key != "fault":
            allowed = ", ".join([f"[{s}]" for s in sections] + ["[[fault]]", *_TOP_TEXT])
            raise ctx.error(
                key if isinstance(val, dict) else None,
                None if isinstance(val, dict) else key,
                f"unknown section or key {key!r}; allowed: {allowed}",
            )
    tp = _section(ctx, doc, "tooth_pair", PAIR_KEYS)
    for req in ("z1", "z2", "m_n", "face_width", "torque"):
        if req not in tp:
            raise ctx.error("tooth_pair", "", f"needs {req} (e.g. {PAIR_KEYS[req][0].kind.example})")
    md = _section(ctx, doc, "modifications", MOD_KEYS)
    mesh = _section(ctx, doc, "mesh", MESH_KEYS)
    sig = _section(ctx, doc, "signature", SIGNATURE_KEYS)
    if "fs" in sig:
        sig["fs_Hz"] = sig["fs"]
    faults_raw = doc.get("fault", [])
    if not isinstance(faults_raw, list):
        raise ctx.error(None, "fault", "write faults as [[fault]] tables")
    zv = tp.get("z_virtual")
    if zv is not None and len(zv) != 2:
        raise ctx.error("tooth_pair", "z_virtual", f"expected two numbers [z_v1, z_v2], got {len(zv)}")
    try:  # every other [tooth_pair] key is a keyword of pair_geometry, whose defaults are the file's
        geo = pair_geometry(
            *(zv or (tp["z1"], tp["z2"])),
            teeth=(tp["z1"], tp["z2"]) if zv else None,
            **{k: v for k, v in tp.items() if k not in ("name", "z1", "z2", "z_virtual", "torque")},
        )
    except (ModelError, TypeError) as exc:
        raise ctx.error("tooth_pair", None, str(exc), ModelError) from None
    try:
        mods = Modifications(**md)
    except (ModelError, TypeError) as exc:
        raise ctx.error("modifications", None, str(exc), ModelError) from None
    faults = [_fault(ctx, i, f) for i, f in enumerate(faults_raw)]
    try:
        check_plausible(geo, float(tp["torque"]), mods, faults)
    except ModelError as exc:
        raise ctx.error(None, None, str(exc), ModelError) from None
    return ToothCase(str(tp.get("name", Path(path).stem)), geo, float(tp["torque"]), mods, faults, mesh, sig)
