"""Values of a TOML configuration: kinds with their units, pint parsing, and one-line errors naming file and line.

Private to :mod:`geardyn.config`, which holds the schema (the sections and keys) and builds the models;
:mod:`geardyn.systems.load` reads and parses its files with the same :func:`read_toml` and
:func:`parse_toml`.
"""

from __future__ import annotations

import math
import re
import tomllib
from functools import lru_cache
from pathlib import Path
from typing import Any, NamedTuple

from ._packaged_quantities import PACKAGED_QUANTITIES
from .errors import ConfigError, GeardynError, ModelError

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
_DENSITY = _Kind("density", "kg/m^3", '"7860 kg/m^3"')
_MASS = _Kind("mass", "kg", '"225 kg"')
_TSTIFF = _Kind("torsional stiffness", "N*m/radian", '"330 N*m/rad"')
_TDAMP = _Kind("torsional damping", "N*m*s/radian", '"23 N*m*s/rad"')
_FORCE = _Kind("force", "N", '"100 N"')


def _choice(options: tuple[str, ...]) -> _Kind:
    return _Kind("one of " + ", ".join(repr(o) for o in options), None, repr(options[0]))


class _Key(NamedTuple):
    kind: _Kind
    series: bool = False


@lru_cache(maxsize=1)
def _ureg():
    import pint

    ureg = pint.UnitRegistry()
    ureg.define("rev = revolution")
    return ureg


#: Longest quantity string, deepest parenthesis nesting of its unit and largest |exponent| accepted.
MAX_QUANTITY_CHARS = 200
MAX_UNIT_NESTING = 4
MAX_UNIT_EXPONENT = 12
_TOKEN = re.compile(
    r"\s*(?:(?P<num>[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[^\W\d][\w°]*|°|%)"
    r"|(?P<pow>\*\*|\^)|(?P<op>[*/·⋅])|(?P<open>\()|(?P<close>\)))"
)


def check_quantity(text: str) -> None:
    """Check that ``text`` is ``[number] [unit expression]`` before any unit library sees it.

    The unit expression is unit names joined by ``*``, ``/``, ``·`` or a space, each with at most one
    integer exponent (``**`` or ``^``, at most :data:`MAX_UNIT_EXPONENT` in size) and parentheses nested
    at most :data:`MAX_UNIT_NESTING` deep; the number is a plain decimal literal.  So nothing is
    evaluated: ``"9**9**9 mm"`` or ``"2**10 m"`` are refused, ``"20 N/(mm*um)"`` and ``"1.772 kg*m^2"``
    pass (and mean what pint makes of them).

    Parameters
    ----------
    text : str
        The quantity string.

    Raises
    ------
    ValueError
        Naming what is not allowed.
    """
    if len(text) > MAX_QUANTITY_CHARS:
        raise ValueError(f"longer than {MAX_QUANTITY_CHARS} characters")
    tokens = []
    pos, end = 0, len(text.rstrip())
    while pos < end:
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise ValueError(f"unexpected {text[pos:].strip()[:10]!r}")
        tokens.append((m.lastgroup, m.group(m.lastgroup)))
        pos = m.end()
    i = 1 if tokens and tokens[0][0] == "num" else 0  # (the leading number)
    depth = 0
    expect_unit = True  # a unit name or "(" must come next (or the end, after the number alone)
    last = None
    while i < len(tokens):
        kind, tok = tokens[i]
        if kind in ("name", "open"):
            if not expect_unit and last not in ("name", "close", "exp", "num"):
                raise ValueError(f"unexpected {tok!r}")
            if kind == "open":
                depth += 1
                if depth > MAX_UNIT_NESTING:
                    raise ValueError(f"units nested more than {MAX_UNIT_NESTING} deep")
                expect_unit = True
            else:
                expect_unit = False
        elif kind == "close":
            if expect_unit or depth == 0:
                raise ValueError("unbalanced ')'")
            depth -= 1
        elif kind == "op":
            if expect_unit:
                raise ValueError(f"unexpected {tok!r}")
            expect_unit = True
        elif kind == "pow":
            if last not in ("name", "close"):
                raise ValueError("an exponent must follow a unit and be a whole number (no exponent towers)")
            if i + 1 >= len(tokens) or tokens[i + 1][0] != "num" or not re.fullmatch(r"[+-]?\d+", tokens[i + 1][1]):
                raise ValueError("an exponent must be a whole number")
            if abs(int(tokens[i + 1][1])) > MAX_UNIT_EXPONENT:
                raise ValueError(f"exponent {tokens[i + 1][1]} is larger than {MAX_UNIT_EXPONENT}")
            i += 1
            kind = "exp"
        else:  # a number as a factor of the unit ("1/s"): a plain literal, never raised to a power
            if not expect_unit:
                raise ValueError(f"unexpected number {tok!r} inside the unit")
            expect_unit = False
        last = kind
        i += 1
    if depth:
        raise ValueError("unbalanced '('")
    if expect_unit and last is not None:
        raise ValueError("the unit ends with an operator")


def quantity(text: str) -> Any:
    """``text`` as a pint Quantity, after :func:`check_quantity` (raises ``ValueError`` or pint's errors)."""
    check_quantity(text)
    return _ureg().Quantity(text)


def parse_quantity(text: str, unit: str) -> float:
    """Parse ``"number unit"`` and return its magnitude in ``unit`` (raises ``ValueError``).

    The string is checked by :func:`check_quantity` first (no expression is evaluated).

    Parameters
    ----------
    text : str
        A quantity such as ``"7.28 mm"``.
    unit : str
        Target unit understood by pint, e.g. ``"m"``.
    """
    return float(quantity(text).to(unit).magnitude)


# ---------------------------------------------------------------------------- error context
_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\[\]]+?)\s*\]\]?\s*(#.*)?$")


class _Ctx:
    """Where a value of a TOML file comes from: the one line locator and message builder of every file geardyn
    reads (configurations, system files, tooth-pair files).

    A place is a section (``[name]``, or the ``index``-th ``[[name]]`` table; ``None`` for the top level) and a
    key in it; messages are one line, ``SOURCE: line N: [section] key: problem`` (``[[section]] 'element' key:``
    for an element of an array of tables).
    """

    def __init__(self, source: str, text: str):
        self.source = source
        self.lines = text.splitlines()

    def line(self, section: str | None, index: int | None = None, key: str | None = None, fallback: bool = True):
        """The line of ``key`` in ``section`` (its ``index``-th table when it repeats), else, with ``fallback``,
        the section's header (or None); the header's line when no key is given."""
        key_re = (
            re.compile(rf"^\s*(?:{re.escape(key)}|\"{re.escape(key)}\"|'{re.escape(key)}')\s*(=|\.)") if key else None
        )
        count, inside, start = -1, section is None, None
        for i, text in enumerate(self.lines, start=1):
            m = _HEADER.match(text)
            if m:
                if inside and section is not None:  # (the end of the section's table)
                    break
                if m.group(2) == section:
                    count += 1
                    if index is None or count == index:
                        inside, start = True, i
                        if key_re is None:
                            return i
                        continue
                inside = False
                continue
            if inside and key_re is not None and key_re.match(text):
                return i
        return start if fallback else None

    def head(self, ln: int | None) -> str:
        """The start of a message about line ``ln`` (None: the file only): ``SOURCE: line N: ``."""
        return f"{self.source}: " + (f"line {ln}: " if ln else "")

    def error(
        self,
        section: str | None,
        key: str | None,
        problem: str,
        cls: type[GeardynError] = ConfigError,
        *,
        index: int | None = None,
        element: str | None = None,
        fallback: bool = False,
    ) -> GeardynError:
        """The error ``cls`` (a file problem by default) with the file, line, section and key in its message:
        ``SOURCE: line N: [section] key: problem`` (as much of the place as is known)."""
        head = self.head(self.line(section, index, key or None, fallback=fallback or index is not None))
        if section is None:
            return cls(head + (f"{_shown(key)}: " if key else "") + problem)
        sec = f"[[{_shown(section)}]]" if index is not None else f"[{_shown(section)}]"
        sec += f" {element!r}" if element else ""
        return cls(head + sec + (f" {_shown(key)}: " if key else ": ") + problem)


#: Largest integer a configuration value may hold (tooth counts and the like are far below it).
MAX_INTEGER = 1_000_000
#: Smallest and largest magnitude of a dimensional value in its SI unit (0 is allowed where the sign is).
MIN_MAGNITUDE = 1e-30
MAX_MAGNITUDE = 1e30
#: Largest number of teeth of a gear (a bevel or hypoid gear has at most a few hundred).
MAX_TEETH = 1000
#: Keys that hold a number of teeth (checked against :data:`MAX_TEETH`).
TEETH_KEYS = ("z1", "z2", "teeth")


def _clip(raw: Any, n: int = 60) -> str:
    """``repr(raw)`` cut to ``n`` characters (a 400-digit value stays a one-line message)."""
    text = repr(raw) if not isinstance(raw, int) or abs(raw) < 10**40 else f"an integer of {len(str(abs(raw)))} digits"
    return text if len(text) <= n else text[: n - 3] + "..."


def _shown(name: str) -> str:
    """A section or key as written, quoted where it holds whitespace or unprintable characters (one-line messages)."""
    return name if name.isprintable() and not any(c.isspace() for c in name) else repr(name)


# ---------------------------------------------------------------------------- value parsing
def _parse_scalar(
    ctx: _Ctx,
    section: str | None,
    key: str,
    kind: _Kind,
    raw: Any,
    item: int | None = None,
    *,
    index: int | None = None,
    element: str | None = None,
    nonnegative: bool = False,
) -> Any:
    """One value of a file in its kind's unit (the one validator of every TOML file geardyn reads).

    ``item`` is the place of the value in a list (messages say "element ``item``"), ``index`` and ``element`` the
    table of an array of tables it is in; ``nonnegative`` refuses a negative value (a mass, a stiffness).
    """

    def bad(problem: str, cls: type[GeardynError] = ConfigError) -> GeardynError:
        text = (f"element {item}: " if item is not None else "") + problem
        return ctx.error(section, key, text, cls, index=index, element=element)

    if kind is _TEXT:
        if not isinstance(raw, str):
            raise bad(f"expected a string, got {raw!r}")
        return raw
    if kind.label.startswith("one of"):
        if not isinstance(raw, str) or repr(raw) not in kind.label:
            raise bad(f"expected {kind.label}, got {raw!r}")
        return raw
    if isinstance(raw, (bool, dict, list)):
        raise bad(f"expected a {kind.label} (e.g. {kind.example}), got {raw!r}")
    if kind is _INT:
        if isinstance(raw, float) and raw.is_integer():
            raw = int(raw)
        if not isinstance(raw, int):  # (a bool is refused above)
            raise bad(f"expected an integer, got {_clip(raw)}")
        if abs(raw) > MAX_INTEGER:
            raise bad(f"must be at most {MAX_INTEGER} in size, got {_clip(raw)}")
        if key in TEETH_KEYS and not 1 <= raw <= MAX_TEETH:
            raise bad(f"a number of teeth must be from 1 to {MAX_TEETH}, got {raw}", ModelError)
        return raw
    if kind.unit is None or (kind is _PHASE and isinstance(raw, (int, float))):
        # plain (non-dimensional) number; phases may be plain numbers in radians
        if isinstance(raw, str):
            try:
                q = quantity(raw)
            except Exception:
                raise bad(f"expected a {kind.label} (e.g. {kind.example}), got {_clip(raw)}") from None
            if not q.unitless:
                raise bad(f"expected a {kind.label} without unit (e.g. {kind.example}), got {raw!r}")
            raw = float(q.to("").magnitude)
        try:
            x = float(raw)
        except OverflowError:
            x = math.inf
        if not math.isfinite(x):
            raise bad(f"must be a finite number, got {_clip(raw)}")
        return x
    if not isinstance(raw, str):
        raise bad(f"expected a {kind.label} with its unit, as a string (e.g. {kind.example}), got {raw!r}")
    if (kind.label, raw) in PACKAGED_QUANTITIES:  # the packaged pair, read without importing pint
        return PACKAGED_QUANTITIES[kind.label, raw]
    try:
        q = quantity(raw)
    except ValueError as e:
        raise bad(f"cannot read {_clip(raw)} as a {kind.label} ({e}); write e.g. {kind.example}") from None
    except Exception as e:  # pint raises several error types for bad unit strings
        raise bad(
            f"cannot read {_clip(raw)} as a {kind.label} ({type(e).__name__}); write e.g. {kind.example}"
        ) from None
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
        raise bad(f"must be finite, got {_clip(raw)}")
    if nonnegative and x < 0:
        raise bad(f"must be >= 0 (a negative {kind.label} has no physical meaning), got {raw!r}", ModelError)
    if x != 0 and not MIN_MAGNITUDE <= abs(x) <= MAX_MAGNITUDE:
        raise bad(
            f"{_clip(raw)} is outside the range of physical values, {MIN_MAGNITUDE:g} to {MAX_MAGNITUDE:g} {kind.unit}",
            ModelError,
        )
    return x


def _parse_value(ctx: _Ctx, section: str, key: str, spec: _Key, raw: Any, **where: Any) -> tuple[Any, str | None]:
    """(value in SI, assumed-source or None) of a value written plainly or as ``{ value = ..., assumed = "..." }``;
    ``where`` (``index``, ``element``, ``nonnegative``) as :func:`_parse_scalar`."""
    assumed = None
    if isinstance(raw, dict):
        assumed = raw.get("assumed")
        if "value" not in raw or set(raw) - {"value", "assumed"}:
            problem = (
                "an inline table must have the keys 'value' and optionally 'assumed' "
                f'(e.g. {{ value = {spec.kind.example}, assumed = "typical value" }}), got keys {sorted(raw)}'
            )
        elif assumed is not None and (not isinstance(assumed, str) or not assumed.strip()):
            problem = "'assumed' must be a non-empty string giving the source or reason"
        else:
            problem = None
        if problem:
            raise ctx.error(section, key, problem, index=where.get("index"), element=where.get("element"))
        raw = raw["value"]
    if spec.series:
        if not isinstance(raw, list):
            raw = [raw]
        return tuple(_parse_scalar(ctx, section, key, spec.kind, r, i + 1, **where) for i, r in enumerate(raw)), assumed
    return _parse_scalar(ctx, section, key, spec.kind, raw, **where), assumed


def _order_tables(
    ctx: _Ctx, section: str, key: str, entries: list, amplitude: _Kind, phase: _Kind, **where: Any
) -> list[tuple[Any, float, float]]:
    """The torque orders written as tables ``{ order = 2, amplitude = "40 N*m", phase = "0 deg" }`` at ``key``
    (:mod:`geardyn.torque_orders`): (order as a Fraction, amplitude and phase of the kinds ``amplitude`` and
    ``phase``, the phase 0 when not given); messages count the tables from 1, as a series' elements; ``where``
    (``index``, ``element``) places them."""
    from .torque_orders import order_fraction

    out = []
    for i, entry in enumerate(entries, start=1):
        if not {"order", "amplitude"} <= set(entry) <= {"order", "amplitude", "phase"}:
            raise ctx.error(section, key, f"element {i}: keys order, amplitude and optionally phase", **where)
        try:
            q = order_fraction(entry["order"], f"element {i}: order")
        except ModelError as e:
            raise ctx.error(section, key, str(e), ModelError, **where) from None
        a = _parse_scalar(ctx, section, key, amplitude, entry["amplitude"], i, **where)
        ph = _parse_scalar(ctx, section, key, phase, entry["phase"], i, **where) if "phase" in entry else 0.0
        out.append((q, a, ph))
    return out


def regular_file_size(source: str, what: str) -> int:
    """The size in bytes of the regular file ``source``; a missing file, a directory, a pipe, socket or
    device is refused in one line naming ``source`` and ``what`` (e.g. "configuration file")."""
    import os
    import stat

    try:
        st = os.stat(source)
    except (OSError, ValueError):
        raise ConfigError(f"{source}: {what} not found") from None
    if stat.S_ISDIR(st.st_mode):
        raise ConfigError(f"{source}: {what} not found (it is a directory)")
    if not stat.S_ISREG(st.st_mode):
        raise ConfigError(f"{source}: not a regular file (a pipe, socket or device); give the {what} itself")
    return int(st.st_size)


def read_toml(path: str | Path, what: str) -> tuple[str, str]:
    """The text of a TOML file, with the name its messages give it.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file is, for the messages (``"configuration file"``, ``"system file"``).

    Returns
    -------
    source : str
        ``str(path)``, the prefix of every message about the file.
    text : str
        Its contents.

    Raises
    ------
    ConfigError
        If the file is missing, a directory, or unreadable as UTF-8 text.
    """
    source = str(path)
    size = regular_file_size(source, what)
    if size > MAX_TOML_BYTES:
        raise ConfigError(f"{source}: {what} of {size} bytes; at most {MAX_TOML_BYTES} allowed")
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_TOML_BYTES + 1)
        if len(data) > MAX_TOML_BYTES:
            raise ConfigError(f"{source}: {what} larger than {MAX_TOML_BYTES} bytes")
        return source, data.decode("utf-8-sig")  # (a byte-order mark is allowed)
    except UnicodeDecodeError as e:
        raise ConfigError(f"{source}: cannot read {what}: not UTF-8 text (byte {e.start})") from None
    except OSError as e:
        raise ConfigError(f"{source}: cannot read {what} ({e.strerror or e})") from None


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML text, a syntax error reported as a one-line :class:`ConfigError` with its line.

    Parameters
    ----------
    text : str
        The TOML text.
    source : str
        Where it comes from (the message prefix).

    Returns
    -------
    dict
        The parsed document.

    Raises
    ------
    ConfigError
        ``SOURCE: line N: TOML syntax error: … (column C)`` for a syntax error.
    """
    try:
        data = tomllib.loads(text.removeprefix("\ufeff"))
    except RecursionError:
        raise ConfigError(
            f"{source}: TOML syntax error: arrays or tables nested more than {MAX_TOML_NESTING} deep"
        ) from None
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        m = re.search(r"\(at line (\d+), column (\d+)\)", msg)
        if m:
            msg = msg[: m.start()].strip()
            raise ConfigError(f"{source}: line {m.group(1)}: TOML syntax error: {msg} (column {m.group(2)})") from None
        raise ConfigError(f"{source}: TOML syntax error: {msg}") from None
    if _depth(data) > MAX_TOML_NESTING:
        raise ConfigError(f"{source}: arrays or tables nested more than {MAX_TOML_NESTING} deep")
    return data


#: Largest configuration or system file read (bytes) and deepest nesting of its arrays and tables.
MAX_TOML_BYTES = 4_000_000
MAX_TOML_NESTING = 16


def _depth(obj: Any) -> int:
    """Nesting depth of dicts and lists (iteratively: no recursion on hostile input)."""
    deepest, stack = 0, [(obj, 0)]
    while stack:
        o, d = stack.pop()
        deepest = max(deepest, d)
        if isinstance(o, dict):
            stack.extend((v, d + 1) for v in o.values())
        elif isinstance(o, list):
            stack.extend((v, d + 1) for v in o)
    return deepest
