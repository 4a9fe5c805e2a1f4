"""TOML configuration files with units written out.

A configuration describes a gear pair, its mesh and an operating point::

    [gear_pair]
    z1 = 23
    z2 = 47
    m_mn = "7.28 mm"
    beta_m = "35 deg"
    alpha_n = "20 deg"
    Sigma = "90 deg"
    j_n = "0.1 mm"
    I1 = "1.772 kg*m^2"
    I2 = "1.873 kg*m^2"
    r1 = "125.5 mm"
    r2 = "256 mm"
    face_width = { value = "100 mm", assumed = "typical value: about 0.3 x outer cone distance" }

    [mesh]              # non-dimensional (xi0, xi, kappa, eps, fp) or dimensional (c0, c, k, e)
    xi0 = 0.1
    xi = [0.05]
    kappa = [0.2]
    eps = [0.5]
    phi_e = ["0 deg"]
    fp = 0.2

    [operating]
    rpm = "3000 rpm"
    torque = "1500 N*m"

    [model]             # direct overrides of GearModel fields (non-dimensional)
    omega = 0.8

Every dimensional value is a string "number unit" parsed with pint; plain numbers are accepted
only for non-dimensional values and for phases (radians).  Any value may instead be written
``{ value = ..., assumed = "source or reason" }`` to mark it as an assumption; it is then listed
in the ``assumed`` output.  A missing or unreadable file, TOML syntax errors, unknown or missing
sections and keys, and values of the wrong kind or unit (or not finite) raise
:class:`~geardyn.errors.ConfigError`; values out of range for the gear pair or the model raise
:class:`~geardyn.model.ModelError`.  Both carry a one-line message naming the file, the line when
known, the section and the key.

Precedence of the non-dimensional model values: ``[model]`` overrides ``[mesh]``, which overrides
values derived from ``[operating]`` (ω from ``rpm``, f_p from ``torque``).  The reported speed and
torque are always those of the final model.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, replace
from functools import lru_cache
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping, NamedTuple

from .errors import ConfigError, GeardynError
from .geometry import (
    HANDS,
    ROTATIONS,
    SIDES,
    Assumption,
    MeshHarmonics,
    PhysicalScales,
    SpiralBevelGearPair,
    drive_side_from_rotation,
    geometry_summary,
)
from .model import GearModel, ModelError

__all__ = ["LoadedConfig", "PAPER_CONFIG", "load_config", "packaged_config_path", "parse_quantity"]

#: File name of the packaged configuration of the paper's Table 1 pair (used when no file is given).
PAPER_CONFIG = "paper_table1.toml"
#: Characteristic length of the paper's Table 3 reading of backlash, D = j_n/(2·1 mm) (m).
TABLE3_LENGTH = 1e-3
#: Relative difference above which two values are reported as different in the notes.
NOTE_RTOL = 1e-9

_ANGLE_UNITS = frozenset({"degree", "radian", "arcminute", "arcsecond", "turn", "revolution", "gradian"})
_SPEED_UNIT_WORDS = ("revolution", "radian", "turn", "degree", "rpm")


class _Kind(NamedTuple):
    label: str  # what is expected, for messages
    unit: str | None  # SI (or rpm) target unit; None for plain numbers
    example: str


_NUMBER = _Kind("non-dimensional number", None, "0.1")
_INT = _Kind("integer", None, "23")
_TEXT = _Kind("string", None, '"paper pair"')
_LENGTH = _Kind("length", "m", '"7.28 mm"')
_ANGLE = _Kind("angle", "radian", '"20 deg"')
_PHASE = _Kind("phase (angle, or a number in rad)", "radian", '"30 deg" or 0.5')
_INERTIA = _Kind("moment of inertia", "kg*m^2", '"1.772 kg*m^2"')
_STIFF = _Kind("stiffness", "N/m", '"2000 N/um"')
_STIFF_W = _Kind("stiffness per unit face width", "N/m^2", '"20 N/(mm*um)"')
_DAMP = _Kind("damping coefficient", "N*s/m", '"5e4 N*s/m"')
_SPEED = _Kind("rotational speed", "rpm", '"3000 rpm" or "314 rad/s"')
_TORQUE = _Kind("torque", "N*m", '"1500 N*m"')


def _choice(options: tuple[str, ...]) -> _Kind:
    return _Kind("one of " + ", ".join(repr(o) for o in options), None, repr(options[0]))


class _Key(NamedTuple):
    kind: _Kind
    series: bool = False


_SCHEMA: Mapping[str, Mapping[str, _Key]] = MappingProxyType(
    {
        "gear_pair": MappingProxyType(
            {
                "name": _Key(_TEXT),
                "z1": _Key(_INT),
                "z2": _Key(_INT),
                "m_mn": _Key(_LENGTH),
                "beta_m": _Key(_ANGLE),
                "alpha_n": _Key(_ANGLE),
                "Sigma": _Key(_ANGLE),
                "j_n": _Key(_LENGTH),
                "I1": _Key(_INERTIA),
                "I2": _Key(_INERTIA),
                "r1": _Key(_LENGTH),
                "r2": _Key(_LENGTH),
                "hand": _Key(_choice(HANDS)),
                "drive_side": _Key(_choice(SIDES)),
                "pinion_rotation": _Key(_choice(ROTATIONS)),
                "face_width": _Key(_LENGTH),
                "c_gamma": _Key(_STIFF_W),
                "k0": _Key(_STIFF),
            }
        ),
        "mesh": MappingProxyType(
            {
                "xi0": _Key(_NUMBER),
                "c0": _Key(_DAMP),
                "xi": _Key(_NUMBER, True),
                "c": _Key(_DAMP, True),
                "phi_c": _Key(_PHASE, True),
                "kappa": _Key(_NUMBER, True),
                "k": _Key(_STIFF, True),
                "phi_k": _Key(_PHASE, True),
                "eps": _Key(_NUMBER, True),
                "e": _Key(_LENGTH, True),
                "phi_e": _Key(_PHASE, True),
                "fp": _Key(_NUMBER),
                "characteristic_length": _Key(_LENGTH),
            }
        ),
        "operating": MappingProxyType(
            {
                "rpm": _Key(_SPEED),
                "torque": _Key(_TORQUE),
                "torque2": _Key(_TORQUE),
            }
        ),
        "model": MappingProxyType(
            {
                "omega": _Key(_NUMBER),
                "xi0": _Key(_NUMBER),
                "xi": _Key(_NUMBER, True),
                "phi_c": _Key(_PHASE, True),
                "kappa": _Key(_NUMBER, True),
                "phi_k": _Key(_PHASE, True),
                "eps": _Key(_NUMBER, True),
                "phi_e": _Key(_PHASE, True),
                "fp": _Key(_NUMBER),
                "D": _Key(_NUMBER),
            }
        ),
    }
)
_TOP_LEVEL_TEXT = ("title", "description")
_REQUIRED_PAIR = ("z1", "z2", "m_mn", "beta_m", "alpha_n", "j_n", "I1", "I2")


@lru_cache(maxsize=1)
def _ureg():
    import pint

    ureg = pint.UnitRegistry()
    ureg.define("rev = revolution")
    return ureg


def parse_quantity(text: str, unit: str) -> float:
    """Parse ``"number unit"`` and return its magnitude in ``unit`` (raises ``ValueError``).

    Parameters
    ----------
    text : str
        A quantity such as ``"7.28 mm"``.
    unit : str
        Target unit understood by pint, e.g. ``"m"``.
    """
    q = _ureg().Quantity(text)
    return float(q.to(unit).magnitude)


# ---------------------------------------------------------------------------- error context
class _Ctx:
    """Where a value comes from, to build one-line error messages."""

    def __init__(self, source: str, text: str):
        self.source = source
        self.lines = text.splitlines()

    def line_of(self, section: str | None, key: str) -> int | None:
        current: str | None = None
        key_re = re.compile(rf"^\s*(?:{re.escape(key)}|\"{re.escape(key)}\"|'{re.escape(key)}')\s*=")
        header = re.compile(r"^\s*\[\s*([^\[\]]+?)\s*\]\s*(#.*)?$")
        for i, line in enumerate(self.lines, start=1):
            m = header.match(line)
            if m:
                current = m.group(1)
                if section is not None and key == "" and current == section:
                    return i
                continue
            if current == section and key and key_re.match(line):
                return i
        return None

    def error(
        self, section: str | None, key: str, problem: str, cls: type[GeardynError] = ConfigError
    ) -> GeardynError:
        """The error ``cls`` (a file problem by default) with the file, line, section and key in its message."""
        line = self.line_of(section, key)
        where = f"{self.source}: " + (f"line {line}: " if line else "")
        what = (f"[{section}] " if section else "") + (f"{key}: " if key else "")
        return cls(f"{where}{what}{problem}")


# ---------------------------------------------------------------------------- value parsing
def _parse_scalar(ctx: _Ctx, section: str, key: str, kind: _Kind, raw: Any, index: int | None = None) -> Any:
    def bad(problem: str) -> GeardynError:
        return ctx.error(section, key, (f"element {index}: " if index is not None else "") + problem)

    if kind is _TEXT:
        if not isinstance(raw, str):
            raise bad(f"expected a string, got {raw!r}")
        return raw
    if kind.label.startswith("one of"):
        if not isinstance(raw, str) or kind.label.find(repr(raw)) < 0:
            raise bad(f"expected {kind.label}, got {raw!r}")
        return raw
    if isinstance(raw, bool) or isinstance(raw, (dict, list)):
        raise bad(f"expected a {kind.label} (e.g. {kind.example}), got {raw!r}")
    if kind is _INT:
        if isinstance(raw, float) and raw.is_integer():
            raw = int(raw)
        if not isinstance(raw, int):
            raise bad(f"expected an integer, got {raw!r}")
        return raw
    if kind.unit is None or (kind is _PHASE and isinstance(raw, (int, float))):
        # plain (non-dimensional) number; phases may be plain numbers in radians
        if isinstance(raw, str):
            try:
                q = _ureg().Quantity(raw)
            except Exception:
                raise bad(f"expected a {kind.label} (e.g. {kind.example}), got {raw!r}") from None
            if not q.unitless:
                raise bad(f"expected a {kind.label} without unit (e.g. {kind.example}), got {raw!r}")
            raw = float(q.to("").magnitude)
        x = float(raw)
        if not math.isfinite(x):
            raise bad(f"must be a finite number, got {raw!r}")
        return x
    if not isinstance(raw, str):
        raise bad(f"expected a {kind.label} with its unit, as a string (e.g. {kind.example}), got {raw!r}")
    try:
        q = _ureg().Quantity(raw)
    except Exception as e:  # pint raises several error types for bad unit strings
        raise bad(f"cannot read {raw!r} as a {kind.label} ({type(e).__name__}); write e.g. {kind.example}") from None
    units = str(q.units)
    if kind in (_ANGLE, _PHASE):
        if units not in _ANGLE_UNITS:
            raise bad(f"expected an angle with its unit (deg or rad; e.g. {kind.example}), got {raw!r}")
    elif kind is _SPEED:
        if not any(w in units for w in _SPEED_UNIT_WORDS):
            raise bad(f"expected a rotational speed in rpm, rev/s or rad/s (e.g. {kind.example}), got {raw!r}")
    if not q.is_compatible_with(kind.unit):
        raise bad(
            f"expected a {kind.label} (unit compatible with {kind.unit}, e.g. {kind.example}), "
            f"got {raw!r} with dimension {q.dimensionality}"
        )
    x = float(q.to(kind.unit).magnitude)
    if not math.isfinite(x):
        raise bad(f"must be finite, got {raw!r}")
    return x


def _parse_value(ctx: _Ctx, section: str, key: str, spec: _Key, raw: Any) -> tuple[Any, str | None]:
    """Return (value in SI, assumed-source or None)."""
    assumed = None
    if isinstance(raw, dict):
        extra = set(raw) - {"value", "assumed"}
        if "value" not in raw or extra:
            raise ctx.error(
                section,
                key,
                "an inline table must have the keys 'value' and optionally 'assumed' "
                f"(e.g. {{ value = {spec.kind.example}, assumed = \"typical value\" }}), got keys {sorted(raw)}",
            )
        assumed = raw.get("assumed")
        if assumed is not None and (not isinstance(assumed, str) or not assumed.strip()):
            raise ctx.error(section, key, "'assumed' must be a non-empty string giving the source or reason")
        raw = raw["value"]
    if spec.series:
        if not isinstance(raw, list):
            raw = [raw]
        if not raw:
            return (), assumed
        return tuple(_parse_scalar(ctx, section, key, spec.kind, r, i + 1) for i, r in enumerate(raw)), assumed
    return _parse_scalar(ctx, section, key, spec.kind, raw), assumed


def _read_section(ctx: _Ctx, data: Mapping[str, Any], section: str) -> tuple[dict[str, Any], dict[str, str]]:
    raw = data.get(section, {})
    if not isinstance(raw, dict):
        raise ctx.error(None, section, "must be a table ([" + section + "])")
    schema = _SCHEMA[section]
    values: dict[str, Any] = {}
    assumed: dict[str, str] = {}
    for key, val in raw.items():
        if key not in schema:
            raise ctx.error(section, key, f"unknown key; allowed: {', '.join(schema)}")
        values[key], src = _parse_value(ctx, section, key, schema[key], val)
        if src:
            assumed[key] = src
    return values, assumed


def _key_of_message(msg: str) -> str:
    return msg.split(":", 1)[0].strip()


def _wrap(ctx: _Ctx, section: str, err: ModelError, keymap: Mapping[str, str] | None = None) -> ModelError:
    msg = str(err)
    key = _key_of_message(msg)
    key = (keymap or {}).get(key, key)
    key = re.sub(r"\d+$", "", key) if key not in _SCHEMA.get(section, {}) else key
    line = ctx.line_of(section, key)
    return ModelError(f"{ctx.source}: " + (f"line {line}: " if line else "") + f"[{section}] {msg}")


# ---------------------------------------------------------------------------- loaded config
@dataclass(frozen=True)
class LoadedConfig:
    """A configuration file turned into a gear pair, an operating point and a :class:`GearModel`.

    Attributes
    ----------
    source : str
        The file the configuration came from.
    title : str
        The file's ``title`` (or the pair's name).
    pair : SpiralBevelGearPair
        The gear pair (SI units).
    mesh : MeshHarmonics
        Mesh harmonics as given (dimensional or non-dimensional).
    b_c : float
        Characteristic length (m).
    model : GearModel
        The non-dimensional model, with every override applied.
    rpm : float
        Pinion speed of the model (rpm), ``ω ω_n 60/(2π z1)``.
    torque : float
        Pinion torque T1 of the model (N·m): the given torque when the model's f_p comes from it,
        otherwise the balanced torque giving the model's f_p.
    torque2 : float or None
        Gear torque T2 (N·m) when given and used; ``None`` means balanced (T1 R2/R1).
    assumptions : tuple of Assumption
        Every assumed value (pair, mesh and operating point) with its source.
    notes : tuple of str
        Where values were derived or overridden.
    backlash_reading : str
        Which characteristic length was used (b_c = b_n, or the Table 3 reading b_c = 1 mm).
    """

    source: str
    title: str
    pair: SpiralBevelGearPair
    mesh: MeshHarmonics
    b_c: float
    model: GearModel
    rpm: float
    torque: float
    torque2: float | None
    assumptions: tuple[Assumption, ...]
    notes: tuple[str, ...]
    backlash_reading: str

    @property
    def scales(self) -> PhysicalScales:
        """Conversions between physical and non-dimensional quantities (:meth:`PhysicalScales.from_config`)."""
        return PhysicalScales.from_config(self)

    @property
    def assumed(self) -> list[str]:
        """Names of the assumed inputs."""
        return [a.name for a in self.assumptions]

    def at(self, rpm: float | None = None, torque: float | None = None) -> "LoadedConfig":
        """The same configuration at another operating point.

        Parameters
        ----------
        rpm : float, optional
            Pinion speed (rpm); sets ω.
        torque : float, optional
            Pinion torque T1 (N·m), balanced; sets f_p.
        """
        changes: dict[str, Any] = {}
        out: dict[str, Any] = {}
        sc = self.scales
        if rpm is not None:
            self.pair.mesh_frequency(rpm)  # validates rpm > 0
            changes["omega"] = float(sc.omega_from_rpm(rpm))
            out["rpm"] = float(rpm)
        if torque is not None:
            changes["fp"] = self.pair.fp_from_torques(torque, None, self.b_c)
            out["torque"] = float(torque)
            out["torque2"] = None
        # a speed or torque given here is no longer the configuration's assumed operating point
        dropped = {k for k in ("rpm", "torque", "torque2") if k in out}
        assumptions = tuple(a for a in self.assumptions if a.name not in dropped)
        return replace(self, model=self.model.replace(**changes), assumptions=assumptions, **out)

    def geometry_summary(self) -> dict[str, Any]:
        """:func:`~geardyn.geometry.geometry_summary` at this configuration's operating point.

        Adds ``source``, ``title``, ``backlash_reading``, ``model`` (the non-dimensional model) and
        the operating-point assumptions to ``assumed``/``assumptions``.
        """
        s = geometry_summary(self.pair, rpm=self.rpm, torque=self.torque, torque2=self.torque2, b_c=self.b_c)
        s["source"] = self.source
        s["title"] = self.title
        s["backlash_reading"] = self.backlash_reading
        s["assumed"] = self.assumed
        s["assumptions"] = [a.to_dict() for a in self.assumptions]
        s["notes"] = list(s.get("notes", [])) + list(self.notes)
        s["model"] = self.model.to_dict()
        return s


def packaged_config_path(name: str = PAPER_CONFIG):
    """A traversable for a configuration shipped with geardyn (``geardyn/data/<name>``).

    Parameters
    ----------
    name : str
        File name in the package's data directory; default :data:`PAPER_CONFIG`.

    Returns
    -------
    importlib.resources.abc.Traversable
    """
    return resources.files("geardyn").joinpath("data", name)


def load_config(path: str | Path | None = None) -> LoadedConfig:
    """Read, validate and convert a configuration file.

    Parameters
    ----------
    path : str or Path, optional
        The TOML file; ``None`` loads the packaged paper pair (:data:`PAPER_CONFIG`).

    Returns
    -------
    LoadedConfig

    Raises
    ------
    ConfigError
        For a missing or unreadable file, a TOML syntax error (with its line), an unknown or
        missing section or key, a value of the wrong kind or unit; the one-line message names the
        file, the line when known and the key.
    ModelError
        For a value out of range for the gear pair or the model, with the same kind of message.
    """
    if path is None:
        res = packaged_config_path()
        source = f"{PAPER_CONFIG} (packaged)"
        text = res.read_text(encoding="utf-8")
    else:
        p = Path(path)
        source = str(path)
        if not p.is_file():
            raise ConfigError(f"{source}: configuration file not found" + (" (it is a directory)" if p.is_dir() else ""))
        try:
            text = p.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as e:
            raise ConfigError(f"{source}: cannot read configuration file ({e})") from None
    return _load_text(text, source)


def _load_text(text: str, source: str) -> LoadedConfig:
    ctx = _Ctx(source, text)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        if m:
            msg = msg[: m.start()].strip()
            raise ConfigError(f"{source}: line {m.group(1)}: TOML syntax error: {msg} (column {m.group(2)})") from None
        raise ConfigError(f"{source}: TOML syntax error: {msg}") from None

    for key, val in data.items():
        if key in _SCHEMA:
            continue
        if key in _TOP_LEVEL_TEXT:
            if not isinstance(val, str):
                raise ctx.error(None, key, f"expected a string, got {val!r}")
            continue
        allowed = ", ".join([f"[{s}]" for s in _SCHEMA] + list(_TOP_LEVEL_TEXT))
        raise ConfigError(f"{source}: unknown section or key {key!r}; allowed: {allowed}")
    if "gear_pair" not in data:
        raise ConfigError(f"{source}: missing section [gear_pair]; it must give {', '.join(_REQUIRED_PAIR)}")

    gp, gp_assumed = _read_section(ctx, data, "gear_pair")
    mesh, mesh_assumed = _read_section(ctx, data, "mesh")
    op, op_assumed = _read_section(ctx, data, "operating")
    mo, mo_assumed = _read_section(ctx, data, "model")
    mesh_given = dict(mesh)
    notes: list[str] = []

    missing = [k for k in _REQUIRED_PAIR if k not in gp]
    if missing:
        line = ctx.line_of("gear_pair", "")
        raise ConfigError(
            f"{source}: " + (f"line {line}: " if line else "") + f"[gear_pair] missing key(s) {', '.join(missing)}"
        )

    # ---- the pair
    rotation = gp.pop("pinion_rotation", None)
    if rotation is not None:
        if "drive_side" in gp:
            raise ctx.error("gear_pair", "pinion_rotation", "give drive_side or pinion_rotation, not both", ModelError)
        if "hand" not in gp:
            raise ctx.error("gear_pair", "pinion_rotation", "needs the pinion hand of spiral (key 'hand')", ModelError)
        gp["drive_side"] = drive_side_from_rotation(gp["hand"], rotation)
        if "pinion_rotation" in gp_assumed:
            gp_assumed["drive_side"] = gp_assumed.pop("pinion_rotation")
        notes.append(f"drive_side = {gp['drive_side']} follows from hand = {gp['hand']} and pinion_rotation = {rotation}")
    for k in ("xi0", "c0"):
        if k in mesh:
            gp[k] = mesh.pop(k)
            if k in mesh_assumed:
                gp_assumed[k] = mesh_assumed.pop(k)
    title = data.get("title") or gp.get("name", "")
    try:
        pair = SpiralBevelGearPair(**gp, assumed=tuple(gp_assumed.items()))
        pair.resolved  # applies defaults and validates them
    except ModelError as e:
        section = "mesh" if _key_of_message(str(e)) in ("xi0", "c0", "xi0/c0") else "gear_pair"
        raise _wrap(ctx, section, e) from None

    # ---- characteristic length
    b_c = mesh.pop("characteristic_length", None)
    if b_c is not None and b_c <= 0:
        raise ctx.error("mesh", "characteristic_length", f"must be > 0 m, got {b_c:g} m", ModelError)
    if b_c is None and pair.b_n <= 0:
        raise ctx.error(
            "gear_pair",
            "j_n",
            "is 0 (no backlash): give [mesh] characteristic_length (e.g. \"1 um\") to scale lengths",
            ModelError,
        )
    b_c_used = pair.b_n if b_c is None else b_c
    sc = pair.scales(b_c_used)
    if b_c is None:
        reading = "b_c = b_n (half the normal backlash), so D = 1"
    else:
        reading = f"b_c = {b_c * 1e3:.6g} mm, so D = b_n/b_c = {pair.b_n / b_c:.6g}"
        if abs(b_c - TABLE3_LENGTH) <= NOTE_RTOL * TABLE3_LENGTH:
            reading += " (the paper's Table 3 reading, D = j_n/(2·1 mm))"

    # ---- mesh harmonics
    fp_mesh = mesh.pop("fp", None)
    try:
        harmonics = MeshHarmonics(**mesh)
        nd = harmonics.nondimensional(pair.m_e, pair.omega_n, pair.k0_mean, b_c_used)
    except ModelError as e:
        raise _wrap(ctx, "mesh", e) from None

    # ---- operating point
    rpm = op.get("rpm")
    torque = op.get("torque")
    torque2 = op.get("torque2")
    if rpm is not None and rpm <= 0:
        raise ctx.error("operating", "rpm", f"must be > 0 rpm, got {rpm:g} rpm", ModelError)
    if torque2 is not None and torque is None:
        raise ctx.error("operating", "torque2", "needs the pinion torque (key 'torque') too", ModelError)
    if rpm is not None:
        omega = float(sc.omega_from_rpm(rpm))
    else:
        omega = GearModel().omega
        notes.append(f"no [operating] rpm: ω = {omega:g} (GearModel default)")
    fp_torque = pair.fp_from_torques(torque, torque2, b_c_used) if torque is not None else None
    if fp_mesh is not None:
        fp = fp_mesh
        if fp_torque is not None and not math.isclose(fp_torque, fp_mesh, rel_tol=NOTE_RTOL):
            notes.append(
                f"[mesh] fp = {fp_mesh:g} overrides f_p = {fp_torque:.6g} from [operating] torque = {torque:g} N·m"
            )
    elif fp_torque is not None:
        fp = fp_torque
    else:
        fp = GearModel().fp
        notes.append(f"no [operating] torque and no [mesh] fp: f_p = {fp:g} (GearModel default)")

    try:
        model = GearModel(omega=omega, xi0=pair.xi0_mean, fp=fp, D=pair.b_n / b_c_used, **nd)
    except ModelError as e:
        raise _wrap(ctx, "mesh", e) from None
    if mo:
        try:
            model = model.replace(**mo)
        except ModelError as e:
            raise _wrap(ctx, "model", e) from None
        notes.append("[model] overrides: " + ", ".join(f"{k} = {v}" for k, v in mo.items()))

    # ---- the operating point of the final model
    rpm_final = float(sc.rpm_from_omega(model.omega))
    if torque is not None and fp_torque is not None and math.isclose(model.fp, fp_torque, rel_tol=NOTE_RTOL):
        torque_final, torque2_final = float(torque), torque2
    else:
        torque_final, torque2_final = float(sc.torque_from_fp(model.fp)), None
        notes.append(f"pinion torque T1 = {torque_final:.6g} N·m follows from f_p = {model.fp:g} (balanced torques)")
    if rpm is None or not math.isclose(rpm_final, rpm, rel_tol=NOTE_RTOL):
        notes.append(f"pinion speed {rpm_final:.6g} rpm follows from ω = {model.omega:g}")

    assumptions = list(pair.assumptions)
    units = {"rpm": "rpm", "torque": "N*m", "torque2": "N*m"}
    for key, src in op_assumed.items():
        assumptions.append(Assumption(key, op[key], units[key], src))
    for section, declared, values in (("mesh", mesh_assumed, mesh_given), ("model", mo_assumed, mo)):
        for key, src in declared.items():
            v = values[key]
            v = list(v) if isinstance(v, tuple) else v
            unit = _SCHEMA[section][key].kind.unit or ""
            assumptions.append(Assumption(f"model.{key}" if section == "model" else key, v, unit, src))

    return LoadedConfig(
        source=source,
        title=str(title),
        pair=pair,
        mesh=harmonics,
        b_c=b_c_used,
        model=model,
        rpm=rpm_final,
        torque=torque_final,
        torque2=torque2_final,
        assumptions=tuple(assumptions),
        notes=tuple(notes),
        backlash_reading=reading,
    )
