"""A tooth pair, its modifications, its faults and its run from a TOML file (``examples/tooth_*.toml``).

Sections and keys (units in the key names)::

    [tooth_pair]       z1, z2, z_virtual ([z_v1, z_v2] of a bevel pair's virtual cylindrical gears), m_n_mm,
                       alpha_n_deg (20), beta_deg (0), face_width_mm, x1, x2 (0), h_a (1), h_f (1.25),
                       E_GPa (206), nu (0.3), bore1_mm, bore2_mm (0.5 r_f), torque_Nm, name
    [modifications]    tip_relief_um, tip_length_mm, root_relief_um, root_length_mm (pairs: pinion, wheel),
                       shape ("linear" | "parabolic"), crowning_um
    [[fault]]          kind = "crack" | "spall" | "wear" | "broken" and the fields of that fault
                       (lengths in m as in :mod:`geardyn.tooth.faults`, or with _mm / _um suffixes)
    [mesh]             cycles, points, slices
    [signature]        rpm, revolutions, fs_Hz, noise, backlash_um, b_c_um, xi0

The file is read and checked by the one reader and validator of geardyn's TOML files
(:mod:`geardyn._config_values`): a missing, oversized or malformed file, an unknown section or key and a value of
the wrong type are refused in one line naming the file, the line and the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from .. import _config_values as cv
from .._config_values import _Key
from ..errors import ConfigError, ModelError
from .faults import FAULT_KINDS, Modifications, fault_from_dict
from .geometry import PairGeometry, pair_geometry

__all__ = ["ToothCase", "load_case"]

_N, _I = _Key(cv._NUMBER), _Key(cv._INT)
#: The sections of a tooth-pair file and their keys (plain numbers: the units are in the key names).
_SCHEMA: dict[str, dict[str, _Key]] = {
    "tooth_pair": {
        "name": _Key(cv._TEXT),
        "z1": _I,
        "z2": _I,
        "z_virtual": _Key(cv._NUMBER, True),
        **{k: _N for k in ("m_n_mm", "alpha_n_deg", "beta_deg", "face_width_mm", "x1", "x2", "h_a", "h_f")},
        **{k: _N for k in ("E_GPa", "nu", "bore1_mm", "bore2_mm", "torque_Nm")},
    },
    "modifications": {
        **{
            f"{k}{u}": _Key(cv._NUMBER, True)
            for k in ("tip_relief", "tip_length", "root_relief", "root_length")
            for u in ("", "_mm", "_um")
        },
        **{f"crowning{u}": _N for u in ("", "_mm", "_um")},
        "shape": _Key(cv._choice(("linear", "parabolic"))),
    },
    "mesh": {"cycles": _I, "points": _I, "slices": _I},
    "signature": {
        "rpm": _N,
        "revolutions": _I,
        "fs_Hz": _N,
        "noise": _N,
        "backlash_um": _N,
        "b_c_um": _N,
        "xi0": _N,
        "seed": _I,
    },
}
_REQUIRED = ("z1", "z2", "m_n_mm", "face_width_mm", "torque_Nm")
_TOP_TEXT = ("title", "description")
_SCALE = {"_mm": 1e-3, "_um": 1e-6}


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
        ``[signature]`` options in SI units.
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


def _si(d: dict[str, Any]) -> dict[str, Any]:
    out = {}
    for k, v in d.items():
        for suf, f in _SCALE.items():
            if k.endswith(suf):
                k, v = k[: -len(suf)], (v * f if not isinstance(v, list | tuple) else [x * f for x in v])
                break
        out[k] = v
    return out


def _section(ctx: cv._Ctx, doc: dict[str, Any], name: str) -> dict[str, Any]:
    """The checked values of ``[name]`` (an empty table when absent)."""
    raw = doc.get(name, {})
    if not isinstance(raw, dict):
        raise ctx.error(None, name, f"must be a table ([{name}])")
    schema, out = _SCHEMA[name], {}
    for key, val in raw.items():
        if key not in schema:
            raise ctx.error(name, key, f"unknown key; allowed: {', '.join(schema)}")
        out[key] = cv._parse_value(ctx, name, key, schema[key], val)[0]
    return out


def _faults(ctx: cv._Ctx, doc: dict[str, Any]) -> list:
    raw = doc.get("fault", [])
    if not isinstance(raw, list) or not all(isinstance(t, dict) for t in raw):
        raise ctx.error(None, "fault", "write each fault as a [[fault]] table")
    out = []
    for i, t in enumerate(raw):
        kind = t.get("kind") if isinstance(t.get("kind"), str) else None
        types = {f.name: str(f.type) for f in fields(FAULT_KINDS[kind])} if kind in FAULT_KINDS else {}
        for key, val in t.items():
            base = next((key[: -len(u)] for u in _SCALE if key.endswith(u)), key)
            if key == "kind" or base not in types:  # the fault's constructor names what it does not know
                continue
            typ = types[base]
            kind_of = cv._TEXT if typ.startswith("str") else cv._INT if typ.startswith("int") else cv._NUMBER
            cv._parse_value(ctx, "fault", key, _Key(kind_of), val, index=i, element=kind)
        try:
            out.append(fault_from_dict(_si(t)))
        except ModelError as e:
            raise ctx.error("fault", None, str(e), ModelError, index=i, element=kind) from None
    return out


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
        For a missing file, invalid TOML, an unknown section or key, a value of the wrong type or a missing
        required key (one line naming the file, the line and the key).
    ModelError
        For a pair or a fault the geometry refuses (one line naming the file).
    """
    p = Path(path)
    source, text = cv.read_toml(p, "tooth-pair file")
    ctx = cv._Ctx(source, text)
    doc = cv.parse_toml(text, source)
    for key, val in doc.items():
        if key in _TOP_TEXT:
            if not isinstance(val, str):
                raise ctx.error(None, key, f"expected a string, got {val!r}")
        elif key not in _SCHEMA and key != "fault":
            allowed = ", ".join([f"[{s}]" for s in _SCHEMA] + ["[[fault]]", *_TOP_TEXT])
            raise ctx.error(
                key if isinstance(val, dict) else None,
                None if isinstance(val, dict) else key,
                f"unknown section or key {key!r}; allowed: {allowed}",
            )
    if not isinstance(doc.get("tooth_pair"), dict):
        raise ConfigError(f"{source}: no [tooth_pair] section")
    tp = _section(ctx, doc, "tooth_pair")
    missing = [k for k in _REQUIRED if k not in tp]
    if missing:
        raise ctx.error("tooth_pair", None, f"needs the key(s) {', '.join(missing)}")
    zv = tp.get("z_virtual")
    if zv is not None and len(zv) != 2:
        raise ctx.error("tooth_pair", "z_virtual", f"expected two numbers [z_v1, z_v2], got {len(zv)}")
    md = _si(_section(ctx, doc, "modifications"))
    mesh, sig = _section(ctx, doc, "mesh"), _section(ctx, doc, "signature")
    try:
        geo = pair_geometry(
            *(zv if zv is not None else (tp["z1"], tp["z2"])),
            tp["m_n_mm"] * 1e-3,
            alpha_n=math.radians(tp.get("alpha_n_deg", 20.0)),
            beta=math.radians(tp.get("beta_deg", 0.0)),
            face_width=tp["face_width_mm"] * 1e-3,
            x1=tp.get("x1", 0.0),
            x2=tp.get("x2", 0.0),
            h_a=tp.get("h_a", 1.0),
            h_f=tp.get("h_f", 1.25),
            bore1=tp["bore1_mm"] * 1e-3 if "bore1_mm" in tp else None,
            bore2=tp["bore2_mm"] * 1e-3 if "bore2_mm" in tp else None,
            E=tp.get("E_GPa", 206.0) * 1e9,
            nu=tp.get("nu", 0.3),
            teeth=(tp["z1"], tp["z2"]) if zv is not None else None,
        )
    except (ModelError, TypeError) as exc:
        raise ctx.error("tooth_pair", None, str(exc), ModelError) from None
    try:
        mods = Modifications(**{k: tuple(v) if isinstance(v, tuple | list) else v for k, v in md.items()})
    except (ModelError, TypeError) as exc:
        raise ctx.error("modifications", None, str(exc), ModelError) from None
    faults = _faults(ctx, doc)
    return ToothCase(
        name=str(tp.get("name", p.stem)),
        geometry=geo,
        torque=float(tp["torque_Nm"]),
        modifications=mods,
        faults=faults,
        mesh=mesh,
        signature=_si(sig),
    )
