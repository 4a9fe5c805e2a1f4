"""A tooth pair, its modifications, its faults and its run from a TOML file (``examples/tooth_*.toml``).

Sections and keys (units in the key names)::

    [tooth_pair]       z1, z2, z_virtual ([z_v1, z_v2] of a bevel pair's virtual cylindrical gears), m_n_mm,
                       alpha_n_deg (20), beta_deg (0), face_width_mm, x1, x2 (0),
                       h_a (1), h_f (1.25), E_GPa (206), nu (0.3), bore1_mm, bore2_mm (0.5 r_f), torque_Nm
    [modifications]    tip_relief_um, tip_length_mm, root_relief_um, root_length_mm (pairs: pinion, wheel),
                       shape ("linear" | "parabolic"), crowning_um
    [[fault]]          kind = "crack" | "spall" | "wear" | "broken" and the fields of that fault
                       (lengths in m as in :mod:`geardyn.tooth.faults`, or with _mm / _um suffixes)
    [mesh]             cycles, points, slices
    [signature]        rpm, revolutions, fs_Hz, noise, backlash_um, b_c_um, xi0
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError, ModelError
from .faults import Modifications, fault_from_dict
from .geometry import PairGeometry, pair_geometry

__all__ = ["ToothCase", "load_case"]

_PAIR_KEYS = {
    "z1",
    "z2",
    "z_virtual",
    "m_n_mm",
    "alpha_n_deg",
    "beta_deg",
    "face_width_mm",
    "x1",
    "x2",
    "h_a",
    "h_f",
    "E_GPa",
    "nu",
    "bore1_mm",
    "bore2_mm",
    "torque_Nm",
    "name",
}
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
                k, v = k[: -len(suf)], (v * f if not isinstance(v, list) else [x * f for x in v])
                break
        out[k] = v
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
        For a missing file, invalid TOML, unknown keys or missing required keys (one line naming the file).
    """
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{p}: {exc}") from None
    tp = doc.get("tooth_pair")
    if not isinstance(tp, dict):
        raise ConfigError(f"{p}: no [tooth_pair] section")
    unknown = set(tp) - _PAIR_KEYS
    if unknown:
        raise ConfigError(f"{p}: [tooth_pair] unknown keys {sorted(unknown)}; allowed: {sorted(_PAIR_KEYS)}")
    for req in ("z1", "z2", "m_n_mm", "face_width_mm", "torque_Nm"):
        if req not in tp:
            raise ConfigError(f"{p}: [tooth_pair] needs {req}")
    zv = tp.get("z_virtual")
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
        md = _si(doc.get("modifications", {}))
        mods = Modifications(**{k: tuple(v) if isinstance(v, list) else v for k, v in md.items()})
        faults = [fault_from_dict(_si(f)) for f in doc.get("fault", [])]
    except (ModelError, TypeError) as exc:
        raise ConfigError(f"{p}: {exc}") from None
    return ToothCase(
        name=str(tp.get("name", p.stem)),
        geometry=geo,
        torque=float(tp["torque_Nm"]),
        modifications=mods,
        faults=faults,
        mesh=dict(doc.get("mesh", {})),
        signature=_si(doc.get("signature", {})),
    )
