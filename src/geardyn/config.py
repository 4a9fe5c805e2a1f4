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
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ._config_values import (
    _ANGLE,
    _DAMP,
    _DENSITY,
    _INERTIA,
    _INT,
    _LENGTH,
    _NUMBER,
    _PHASE,
    _SPEED,
    _STIFF,
    _STIFF_W,
    _TEXT,
    _TORQUE,
    _choice,
    _Ctx,
    _Key,
    _order_tables,
    _parse_value,
    parse_quantity,
    parse_toml,
    read_toml,
)
from .errors import ConfigError
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
from .geometry.iso import ISO_KEYS, ISO_ONLY_KEYS, K0_METHODS, iso_k0, iso_summary, pair_iso_mesh
from .model import GearModel, ModelError
from .params import FAMILIES

__all__ = ["LoadedConfig", "PAPER_CONFIG", "load_config", "packaged_config_path", "parse_quantity"]

#: File name of the packaged configuration of the paper's Table 1 pair (used when no file is given).
PAPER_CONFIG = "paper_table1.toml"
#: Characteristic length of the paper's Table 3 reading of backlash, D = j_n/(2·1 mm) (m).
TABLE3_LENGTH = 1e-3
#: Relative difference above which two values are reported as different in the notes.
NOTE_RTOL = 1e-9

#: ``[mesh] kappa`` written as this word takes κ_r and φ_k from the contact ratios (ISO 10300-1).
KAPPA_FROM_GEOMETRY = "geometry"


def _keys(series: tuple[str, ...] = (), **kinds: Any) -> Mapping[str, _Key]:
    """A section's keys and their kinds (those in ``series`` take a list of values), read-only."""
    return MappingProxyType({k: _Key(kind, k in series) for k, kind in kinds.items()})


_SCHEMA: Mapping[str, Mapping[str, _Key]] = MappingProxyType(
    {
        "gear_pair": _keys(
            name=_TEXT,
            z1=_INT,
            z2=_INT,
            m_mn=_LENGTH,
            beta_m=_ANGLE,
            alpha_n=_ANGLE,
            Sigma=_ANGLE,
            j_n=_LENGTH,
            I1=_INERTIA,
            I2=_INERTIA,
            r1=_LENGTH,
            r2=_LENGTH,
            hand=_choice(HANDS),
            drive_side=_choice(SIDES),
            pinion_rotation=_choice(ROTATIONS),
            face_width=_LENGTH,
            c_gamma=_STIFF_W,
            k0=_STIFF,
            k0_method=_choice(K0_METHODS),
            # ISO 23509 mean-point data and rating inputs read by geardyn.geometry.iso (ISO 10300-1)
            beta_m2=_ANGLE,
            alpha_lim=_ANGLE,
            d_m1=_LENGTH,
            d_m2=_LENGTH,
            delta1=_ANGLE,
            delta2=_ANGLE,
            h_am1=_LENGTH,
            h_am2=_LENGTH,
            x_hm1=_NUMBER,
            offset=_LENGTH,
            zeta_mp=_ANGLE,
            zeta_m=_ANGLE,
            b2_eff=_LENGTH,
            K_A=_NUMBER,
            f_pt=_LENGTH,
            density=_DENSITY,
        ),
        "mesh": _keys(
            ("xi", "c", "phi_c", "kappa", "k", "phi_k", "eps", "e", "phi_e"),
            xi0=_NUMBER,
            c0=_DAMP,
            xi=_NUMBER,
            c=_DAMP,
            phi_c=_PHASE,
            kappa=_NUMBER,
            k=_STIFF,
            phi_k=_PHASE,
            eps=_NUMBER,
            e=_LENGTH,
            phi_e=_PHASE,
            fp=_NUMBER,
            characteristic_length=_LENGTH,
        ),
        "operating": _keys(
            rpm=_SPEED,
            torque=_TORQUE,
            torque2=_TORQUE,
            omega=_NUMBER,
        ),
        "model": MappingProxyType(
            {f.name: _Key(_PHASE if f.units == "rad" else _NUMBER, f.series) for f in FAMILIES.values()}
        ),
        "excitation": _keys(file=_TEXT, b_c=_LENGTH, harmonics=_INT, evaluation=_TEXT),
    }
)
_TOP_LEVEL_TEXT = ("title", "description")
_REQUIRED_PAIR = ("z1", "z2", "m_mn", "beta_m", "alpha_n", "j_n", "I1", "I2")
#: Keys that need a gear pair: refused in a non-dimensional configuration (no ``[gear_pair]``).
_PHYSICAL_KEYS = {"mesh": ("c0", "c", "k", "e", "characteristic_length"), "operating": ("rpm", "torque", "torque2")}


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


def _wrap(ctx: _Ctx, section: str, err: ModelError) -> ModelError:
    msg = str(err)
    key = _key_of_message(msg)
    key = re.sub(r"\d+$", "", key) if key not in _SCHEMA.get(section, {}) else key
    return ModelError(ctx.head(ctx.line(section, None, key or None, fallback=False)) + f"[{section}] {msg}")


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
    pair : SpiralBevelGearPair or None
        The gear pair (SI units); ``None`` for a non-dimensional configuration (no ``[gear_pair]``).
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
    iso_inputs : mapping
        The ISO 10300-1 inputs of ``[gear_pair]`` (:data:`~geardyn.geometry.iso.ISO_KEYS`, SI units).
    k0_method : str
        How k0 was obtained: ``"given"``, ``"iso"`` (c_γ b_v,eff) or ``"face_width"`` (c_γ × b).

    Examples
    --------
    >>> from geardyn import load_config
    >>> cfg = load_config()
    >>> slower = cfg.at(rpm=2000, torque=1000)
    >>> slower.rpm, round(slower.model.omega, 4), round(slower.model.fp, 4)
    (2000.0, 0.668, 0.1035)
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
    iso_inputs: Mapping[str, float] = field(default_factory=dict)
    k0_method: str = "face_width"

    @property
    def scales(self) -> PhysicalScales:
        """Conversions between physical and non-dimensional quantities (:meth:`PhysicalScales.from_config`)."""
        return PhysicalScales.from_config(self)

    @property
    def assumed(self) -> list[str]:
        """Names of the assumed inputs."""
        return [a.name for a in self.assumptions]

    def at(self, rpm: float | None = None, torque: float | None = None) -> LoadedConfig:
        """The same configuration at another operating point.

        Parameters
        ----------
        rpm : float, optional
            Pinion speed (rpm); sets ω.
        torque : float, optional
            Pinion torque T1 (N·m), balanced; sets f_p.
        """
        if self.pair is None and (rpm is not None or torque is not None):
            raise ConfigError(
                f"{self.source}: no [gear_pair], so a pinion speed or torque has no meaning; give ω and f_p instead"
            )
        changes: dict[str, Any] = {}
        out: dict[str, Any] = {}
        notes = list(self.notes)  # the notes on how the configuration's own speed or torque came about go
        if rpm is not None:
            self.pair.mesh_frequency(rpm)  # validates rpm > 0
            changes["omega"] = float(self.scales.omega_from_rpm(rpm))
            out["rpm"] = float(rpm)
            notes = [n for n in notes if not n.startswith(("pinion speed", "no [operating] rpm"))]
            notes.append(f"pinion speed {float(rpm):.6g} rpm given for this run sets ω = {changes['omega']:.6g}")
        if torque is not None:
            changes["fp"] = self.pair.fp_from_torques(torque, None, self.b_c)
            out.update(torque=float(torque), torque2=None)
            notes = [n for n in notes if not n.startswith(("pinion torque T1", "no [operating] torque", "[mesh] fp ="))]
            notes.append(
                f"pinion torque T1 = {float(torque):.6g} N·m given for this run sets f_p = {changes['fp']:.6g}"
                " (balanced torques)"
            )
        # a speed or torque given here is no longer the configuration's assumed operating point
        assumptions = tuple(a for a in self.assumptions if a.name not in out)
        return replace(self, model=self.model.replace(**changes), assumptions=assumptions, notes=tuple(notes), **out)

    def geometry_summary(self) -> dict[str, Any]:
        """:func:`~geardyn.geometry.geometry_summary` at this configuration's operating point.

        Adds ``source``, ``title``, ``backlash_reading``, ``model`` (the non-dimensional model) and
        the operating-point assumptions to ``assumed``/``assumptions``.
        """
        if self.pair is None:
            raise ConfigError(f"{self.source}: no [gear_pair]: a non-dimensional configuration has no geometry")
        s = geometry_summary(self.pair, rpm=self.rpm, torque=self.torque, torque2=self.torque2, b_c=self.b_c)
        iso_notes: list[str] = []
        try:
            mesh = pair_iso_mesh(self.pair, self.iso_inputs, rpm=self.rpm, torque=self.torque)
        except ModelError as e:
            s["iso10300"] = None
            iso_notes.append(f"ISO 10300-1 mesh data not computed: {e}")
        else:
            block = iso_summary(
                mesh,
                k0_method=self.k0_method,
                k0_used=self.pair.k0_mean,
                c_gamma_given=self.pair.c_gamma,
                hypoid=bool(self.iso_inputs.get("offset")),
            )
            iso_notes = block.pop("iso_notes")
            s.update(block)
            s["iso10300"] = "ISO 10300-1:2014 Annex A (Method B1 virtual cylindrical gears), clause 6"
            k_geo, k_model = mesh.kappa.kappa[0], (self.model.kappa or (0.0,))[0]
            if k_model > 0 and k_geo > 0 and abs(k_model / k_geo - 1.0) > 0.1:
                iso_notes.append(
                    f"the model's κ1 = {k_model:.4g} is {k_model / k_geo:.3g} × the κ1 = {k_geo:.4g} "
                    "the contact ratios imply"
                )
        s.update(
            source=self.source,
            title=self.title,
            backlash_reading=self.backlash_reading,
            assumed=self.assumed,
            assumptions=[a.to_dict() for a in self.assumptions],
            notes=list(s.get("notes", [])) + list(self.notes) + iso_notes,
            model=self.model.to_dict(),
        )
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

    Examples
    --------
    >>> from geardyn import load_config
    >>> cfg = load_config()  # the paper's Table 1 pair, packaged with geardyn
    >>> cfg.pair.z1, cfg.pair.z2, cfg.rpm, round(cfg.model.omega, 4)
    (23, 47, 3000.0, 1.002)
    """
    if path is None:
        res = packaged_config_path()
        source = f"{PAPER_CONFIG} (packaged)"
        text = res.read_text(encoding="utf-8")
    else:
        source, text = read_toml(path, "configuration file")
    return _load_text(text, source)


def _load_text(text: str, source: str) -> LoadedConfig:
    ctx = _Ctx(source, text)
    data = parse_toml(text, source)

    for key, val in data.items():
        if key in _SCHEMA:
            continue
        if key in _TOP_LEVEL_TEXT:
            if not isinstance(val, str):
                raise ctx.error(None, key, f"expected a string, got {val!r}")
            continue
        allowed = ", ".join([f"[{s}]" for s in _SCHEMA] + list(_TOP_LEVEL_TEXT))
        if isinstance(val, dict):
            raise ConfigError(
                ctx.head(ctx.line(key, fallback=False))
                + f"unknown section or key {key!r} (a section [{key}]); allowed: {allowed}"
            )
        raise ConfigError(f"{source}: unknown section or key {key!r}; allowed: {allowed}")
    exc = _read_section(ctx, data, "excitation")[0]  # {} without [excitation]
    data, orders = _pop_orders(data)
    cfg = _load_sections(ctx, data)
    cfg = _with_excitation(ctx, cfg, exc) if exc else cfg
    return _with_orders(ctx, cfg, orders) if orders is not None else cfg


def _pop_orders(data: dict[str, Any]) -> tuple[dict[str, Any], Any]:
    """``data`` without ``[model] torque_orders``, and that key's value (None when absent)."""
    mo = data.get("model")
    if not isinstance(mo, dict) or "torque_orders" not in mo:
        return data, None
    return {**data, "model": {k: v for k, v in mo.items() if k != "torque_orders"}}, mo["torque_orders"]


def _with_orders(ctx: _Ctx, cfg: LoadedConfig, raw: Any) -> LoadedConfig:
    """``cfg`` with ``[model] torque_orders`` (:mod:`geardyn.torque_orders`): with a gear pair, orders of the
    pinion's speed and amplitudes of a pinion torque (N·m); without one, mesh orders and non-dimensional amplitudes."""
    if not isinstance(raw, list) or not all(isinstance(e, dict) for e in raw):
        raise ctx.error("model", "torque_orders", "expected a list of tables {order, amplitude, phase}")
    physical = cfg.pair is not None
    out = _order_tables(ctx, "model", "torque_orders", raw, _TORQUE if physical else _NUMBER, _PHASE)
    if physical:
        out = pinion_orders(cfg, out)
    try:
        model = cfg.model.replace(torque_orders=cfg.model.torque_orders + tuple(out))
    except ModelError as e:
        raise ctx.error("model", "torque_orders", str(e), ModelError) from None
    what = "orders of the pinion speed, pinion torque amplitudes" if physical else "mesh orders"
    return replace(cfg, model=model, notes=cfg.notes + (f"[model] torque_orders: {len(out)} {what}",))


def pinion_orders(cfg: LoadedConfig, orders: list[tuple[Any, float, float]]) -> list[tuple[Any, float, float]]:
    """Torque orders of the pinion's speed with amplitudes of a pinion torque (N·m) as the model's: orders of the
    mesh frequency (k/z1) and non-dimensional amplitudes (the torque on the pinion alone, T2 = 0)."""
    return [(q / cfg.pair.z1, cfg.pair.fp_from_torques(a, 0.0, cfg.b_c), p) for q, a, p in orders]


def _with_excitation(ctx: _Ctx, cfg: LoadedConfig, exc: dict[str, Any]) -> LoadedConfig:
    """``cfg`` with the ``[excitation]`` table's stiffness and STE (``file`` relative to the configuration)."""
    from .tooth.table import apply_excitation

    if "file" not in exc:
        raise ctx.error(
            "excitation",
            "file",
            "missing: the table file (.nc of geardyn stiffness, .csv, .json, or a tooth-pair .toml)",
        )
    path = Path(exc["file"])
    if not path.is_absolute() and Path(ctx.source).is_file():
        path = Path(ctx.source).parent / path
    try:
        model = apply_excitation(
            cfg.model,
            path,
            b_c=exc.get("b_c", cfg.b_c),
            harmonics=exc.get("harmonics"),
            evaluation=exc.get("evaluation", "series"),
        )
    except (ModelError, ConfigError) as e:
        raise ctx.error("excitation", "file", str(e), type(e)) from None
    note = (
        f"[excitation] {exc['file']}: stiffness and STE over {model.cycles} mesh cycle(s), "
        f"{len(model.kappa)} harmonics of ω/{model.cycles} (they replace kappa, eps and their phases)"
    )
    return replace(cfg, model=model, notes=cfg.notes + (note,))


def _load_sections(ctx: _Ctx, data: dict[str, Any]) -> LoadedConfig:
    data, kappa_geometry = _kappa_word(ctx, data)
    if "gear_pair" not in data:
        if kappa_geometry:
            raise ctx.error("mesh", "kappa", f'"{KAPPA_FROM_GEOMETRY}" needs the gear pair ([gear_pair])')
        return _load_nondimensional(ctx, data)

    gp, gp_assumed = _read_section(ctx, data, "gear_pair")
    mesh, mesh_assumed = _read_section(ctx, data, "mesh")
    op, op_assumed = _read_section(ctx, data, "operating")
    mo, mo_assumed = _read_section(ctx, data, "model")
    mesh_given = dict(mesh)
    notes: list[str] = []

    missing = [k for k in _REQUIRED_PAIR if k not in gp]
    if missing:
        raise ConfigError(
            ctx.head(ctx.line("gear_pair", fallback=False)) + f"[gear_pair] missing key(s) {', '.join(missing)}"
        )

    # ---- the ISO 10300-1 inputs and the way to k0
    k0_method = gp.pop("k0_method", None)
    iso_in = {k: gp.pop(k) for k in ISO_KEYS if k in gp}
    iso_declared = {k: gp_assumed.pop(k) for k in list(gp_assumed) if k in ISO_KEYS or k == "k0_method"}
    if "k0" in gp and k0_method is not None:
        raise ctx.error("gear_pair", "k0_method", "give k0 or k0_method, not both", ModelError)
    method = "given" if "k0" in gp else k0_method or ("iso" if set(iso_in) & set(ISO_ONLY_KEYS) else "face_width")
    for i in ("1", "2"):
        if f"r{i}" not in gp and f"d_m{i}" in iso_in:
            gp[f"r{i}"] = 0.5 * iso_in[f"d_m{i}"]
            gp_assumed.setdefault(f"r{i}", f"not given; mesh point at the mean pitch point, r{i} = d_m{i}/2")

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
        notes.append(
            f"drive_side = {gp['drive_side']} follows from hand = {gp['hand']} and pinion_rotation = {rotation}"
        )
    for k in ("xi0", "c0"):
        if k in mesh:
            gp[k] = mesh.pop(k)
            if k in mesh_assumed:
                gp_assumed[k] = mesh_assumed.pop(k)
    title = data.get("title") or gp.get("name", "")
    try:
        pair = SpiralBevelGearPair(**gp, assumed=tuple(gp_assumed.items()))
        _ = pair.resolved  # applies defaults and validates them
    except ModelError as e:
        section = "mesh" if _key_of_message(str(e)) in ("xi0", "c0", "xi0/c0") else "gear_pair"
        raise _wrap(ctx, section, e) from None
    iso_assumptions: list[Assumption] = []
    if method == "iso" or kappa_geometry:
        try:
            iso_mesh = pair_iso_mesh(pair, iso_in, rpm=op.get("rpm"), torque=op.get("torque"))
        except ModelError as e:
            raise _wrap(ctx, "gear_pair", e) from None
        iso_assumptions = [Assumption(a.name, a.value, a.unit, a.source) for a in iso_mesh.assumed if a.name != "K_v"]
    if method == "iso":
        cg = pair.c_gamma
        k0 = iso_k0(iso_mesh, cg)
        src = (
            f"ISO 10300-1: k0 = c_γ b_v,eff = {(iso_mesh.c_gamma if cg is None else cg) * 1e-9:.4g} N/(mm·µm)"
            f"{' (given)' if cg is not None else f' (C_F = {iso_mesh.C_F:.4g})'} × {iso_mesh.b_v_eff * 1e3:.5g} mm"
        )
        pair = replace(pair, k0=k0, assumed=pair.assumed + (("k0", src),))
        notes.append(f'k0 = {k0 * 1e-6:.6g} N/µm by ISO 10300-1 (k0_method = "iso"; "face_width" gives c_γ × b)')
    if kappa_geometry:
        mesh["kappa"], mesh["phi_k"] = iso_mesh.kappa.kappa, iso_mesh.kappa.phi
        notes.append(
            f'[mesh] kappa = "{KAPPA_FROM_GEOMETRY}": κ_r = '
            + ", ".join(f"{k:.4g}" for k in iso_mesh.kappa.kappa)
            + f" from ε_vα = {iso_mesh.eps_valpha:.4g}, ε_vβ = {iso_mesh.eps_vbeta:.4g}"
        )

    # ---- characteristic length
    b_c = mesh.pop("characteristic_length", None)
    if b_c is not None and b_c <= 0:
        raise ctx.error("mesh", "characteristic_length", f"must be > 0 m, got {b_c:g} m", ModelError)
    if b_c is None and pair.b_n <= 0:
        raise ctx.error(
            "gear_pair",
            "j_n",
            'is 0 (no backlash): give [mesh] characteristic_length (e.g. "1 um") to scale lengths',
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

    assumptions = list(pair.assumptions) + iso_assumptions
    for section, declared, values in (
        ("gear_pair", iso_declared, {**iso_in, "k0_method": k0_method}),
        ("operating", op_assumed, op),
        ("mesh", mesh_assumed, mesh_given),
        ("model", mo_assumed, mo),
    ):
        for key, src in declared.items():
            v = values[key]
            v = list(v) if isinstance(v, tuple) else v
            unit = _SCHEMA[section][key].kind.unit or ""
            assumptions.append(Assumption(f"model.{key}" if section == "model" else key, v, unit, src))

    return LoadedConfig(
        source=ctx.source,
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
        iso_inputs=iso_in,
        k0_method=method,
    )


def _kappa_word(ctx: _Ctx, data: dict[str, Any]) -> tuple[dict[str, Any], bool]:
    """``data`` without ``[mesh] kappa = "geometry"`` and whether it was there (κ_r from the contact ratios)."""
    mesh = data.get("mesh")
    if not isinstance(mesh, dict) or "kappa" not in mesh:
        return data, False
    raw = mesh["kappa"]
    word = raw.get("value") if isinstance(raw, dict) else raw
    if not isinstance(word, str):
        return data, False
    if word != KAPPA_FROM_GEOMETRY:
        raise ctx.error("mesh", "kappa", f'expected numbers or the word "{KAPPA_FROM_GEOMETRY}", got {word!r}')
    for other in ("phi_k", "k"):
        if other in mesh:
            raise ctx.error("mesh", other, f'not with kappa = "{KAPPA_FROM_GEOMETRY}" (it gives κ_r and φ_k)')
    return {**data, "mesh": {k: v for k, v in mesh.items() if k != "kappa"}}, True


def _load_nondimensional(ctx: _Ctx, data: Mapping[str, Any]) -> LoadedConfig:
    """A configuration without ``[gear_pair]``: the non-dimensional model of ``[mesh]``, ``[operating]`` and
    ``[model]``."""
    mesh, mesh_assumed = _read_section(ctx, data, "mesh")
    op, op_assumed = _read_section(ctx, data, "operating")
    mo, mo_assumed = _read_section(ctx, data, "model")
    for section, values in (("mesh", mesh), ("operating", op)):
        for key in _PHYSICAL_KEYS[section]:
            if key in values:
                raise ctx.error(
                    section,
                    key,
                    "needs a gear pair: add [gear_pair], or give the non-dimensional "
                    "values (xi0, xi, kappa, eps, fp in [mesh]; omega in [operating])",
                )
    notes: list[str] = ["no [gear_pair]: a non-dimensional model (speeds and torques cannot be given)"]
    default = GearModel()
    kw: dict[str, Any] = {
        "omega": op.get("omega", default.omega),
        "xi0": mesh.pop("xi0", default.xi0),
        "fp": mesh.pop("fp", default.fp),
    }
    if "omega" not in op:
        notes.append(f"no [operating] omega: ω = {kw['omega']:g} (GearModel default)")
    try:
        harmonics = MeshHarmonics(**mesh)
        model = GearModel(**kw, **harmonics.nondimensional(1.0, 1.0, 1.0, 1.0))
        if mo:
            model = model.replace(**mo)
            notes.append("[model] overrides: " + ", ".join(f"{k} = {v}" for k, v in mo.items()))
    except ModelError as e:
        raise _wrap(ctx, "model" if mo and _key_of_message(str(e)) in mo else "mesh", e) from None
    assumptions = [
        Assumption(k, list(v) if isinstance(v, tuple) else v, "", src)
        for declared, values in ((mesh_assumed, {**mesh, **kw}), (op_assumed, op), (mo_assumed, mo))
        for k, src in declared.items()
        for v in [values.get(k, "")]
    ]
    return LoadedConfig(
        source=ctx.source,
        title=str(data.get("title") or ""),
        pair=None,
        mesh=harmonics,
        b_c=float("nan"),
        model=model,
        rpm=float("nan"),
        torque=float("nan"),
        torque2=None,
        assumptions=tuple(assumptions),
        notes=tuple(notes),
        backlash_reading="no [gear_pair]: D is the model's non-dimensional backlash",
        k0_method="",
    )
