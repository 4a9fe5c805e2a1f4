r"""Measured transmission error: read a single-flank tester export and find its mesh-order harmonics and sidebands.

A measured transmission error (TE) record is two columns: the pinion angle (or the time, at a stated
pinion speed) and the TE, a length along the line of action (µm).  Its spectrum over the pinion angle
φ1 holds, in pinion orders (cycles per pinion revolution):

* the mesh orders ``k z1`` (k = 1, 2, …): the part repeated by every tooth pair, the static
  transmission error the model's forcing ``Σ e_l cos(lθ + φ_l)`` describes (θ = z1 φ1, the mesh angle);
* the shaft orders of the pinion ``j`` and of the gear ``j z1/z2`` (eccentricity, pitch errors) and
  their sidebands around the mesh orders, ``k z1 ± j`` and ``k z1 ± j z1/z2``.  These repeat only
  after the hunting period, ``lcm(z1, z2)`` mesh cycles, so with them the forcing is not periodic over
  one mesh cycle, and the model (whose forcing has period 2π in θ) cannot take them.

Method: the record is converted to the pinion angle (time × speed for a time record), and the
amplitude and phase of every order above are fitted at once by linear least squares
(``TE(φ1) ≈ c + Σ_o a_o cos(o φ1) + b_o sin(o φ1)``).  Least squares needs no whole number of
revolutions and no uniform sampling, and separates orders closer than the record's resolution as long
as the system stays well conditioned; orders of the gear are fitted only when the record covers at
least one gear revolution (otherwise they are not separable from the pinion orders and are reported
as left out).  The amplitude ``A_o = √(a_o² + b_o²)`` and the phase of ``A_o cos(o φ1 + φ_o)`` are
returned, with θ = 0 at the first sample.

The shares reported: ``sideband_share`` = RMS of the shaft orders and sidebands / RMS of every fitted
order, and ``residual_share`` = RMS of the residual / RMS of the signal about its mean.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ._docfill import attributes
from .errors import ConfigError

__all__ = [
    "ANGLE_UNITS",
    "LENGTH_UNITS",
    "TIME_UNITS",
    "TEAnalysis",
    "TESignal",
    "analyse_te",
    "mesh_section",
    "read_te",
]

#: Units of the first column: angle (to rad) ...
ANGLE_UNITS = {
    "deg": math.pi / 180.0,
    "degree": math.pi / 180.0,
    "degrees": math.pi / 180.0,
    "rad": 1.0,
    "rev": math.tau,
    "turn": math.tau,
}
#: ... or time (to s).
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}
#: Units of the TE column (to µm).
LENGTH_UNITS = {"um": 1.0, "µm": 1.0, "micron": 1.0, "mm": 1e3, "nm": 1e-3, "m": 1e6}
#: Sideband share above which the forcing is reported as not periodic over one mesh cycle.
PERIODIC_SHARE = 0.05
#: Largest TE file read (bytes) and most samples used: the record is read in a bounded way.
MAX_TE_BYTES = 64_000_000
MAX_TE_ROWS = 2_000_000
#: Largest |TE| accepted (µm): 1 m along the line of action is no transmission error.
MAX_TE_UM = 1.0e6
#: Largest pinion speed of a time record (rpm).
MAX_TE_RPM = 1.0e6
#: Largest number of teeth, mesh harmonics and shaft orders.
MAX_TEETH = 10_000
MAX_ORDERS = 1_000
#: Largest least-squares matrix of the fit (bytes): samples × 2 × fitted orders × 8.
MAX_FIT_BYTES = 2_000_000_000
_SPLIT = re.compile(r"[,;\t]|\s+")
_UNIT_IN_NAME = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]|[_/ ]([A-Za-zµ]+)\s*$")


@dataclass(frozen=True)
@attributes
class TESignal:
    """A measured TE record: the pinion angle of every sample and the TE there."""

    #: The file.
    source: str
    #: Pinion angle φ1 of every sample (rad), strictly increasing.
    angle: np.ndarray
    #: Transmission error (µm).
    te_um: np.ndarray
    #: ``"angle"`` or ``"time"`` (converted to angle with ``rpm``).
    abscissa: str
    #: The pinion speed used for a time record.
    rpm: float | None = None


def _unit_of(name: str) -> str | None:
    m = _UNIT_IN_NAME.search(name.strip())
    if not m:
        return None
    return (m.group(1) or m.group(2)).strip().lower().replace("μ", "µ")


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def read_te(
    path: str | Path, *, x_unit: str | None = None, te_unit: str | None = None, rpm: float | None = None
) -> TESignal:
    """Read a two-column TE record (angle or time, TE), with an optional header stating the units.

    Parameters
    ----------
    path : str or Path
        The file: two columns separated by commas, semicolons, tabs or spaces; lines starting with
        ``#`` are comments.  An optional first line names the columns with their units, e.g.
        ``angle [deg], TE [um]``, ``time_s,te_um`` or ``t (ms); TE (µm)``.
    x_unit : str, optional
        Unit of the first column (deg, rad, rev; s, ms, us) when the header does not state it (or to
        check it against the header).
    te_unit : str, optional
        Unit of the TE column (um, mm, nm, m).
    rpm : float, optional
        Pinion speed (rpm) of a time record (required for one).

    Returns
    -------
    TESignal

    Raises
    ------
    ConfigError
        With one line naming the file and the line: a missing or unreadable file, no numbers,
        one column, a value that is not a finite number, a first column that does not increase, a
        unit that is not an angle or time (first column) or a length (TE), or no units stated.
    """
    src = str(path)
    lines = _read_lines(src)

    def bad(lineno: int, problem: str) -> ConfigError:
        return ConfigError(f"{src}: line {lineno}: {problem}")

    header_units: tuple[str | None, str | None] = (None, None)
    header_line = 0
    rows: list[tuple[int, float, float]] = []
    for i, raw in enumerate(lines, start=1):
        text = raw.split("#", 1)[0].strip()
        if not text:
            continue
        parts = [f for f in _SPLIT.split(text) if f]
        nums = [_number(f) for f in parts]
        if not rows and header_line == 0 and all(v is None for v in nums):
            if len(parts) < 2:
                raise bad(i, f"expected two columns (angle or time, TE) in the header, got {text!r}")
            header_line = i
            names = [s.strip() for s in re.split(r"[,;\t]", text)] if re.search(r"[,;\t]", text) else parts
            header_units = (_unit_of(names[0]), _unit_of(names[-1]))
            continue
        if len(parts) < 2:
            raise bad(i, f"expected two columns (angle or time, TE), got {len(parts)}: {text[:60]!r}")
        if len(parts) > 2:
            raise bad(i, f"expected two columns (angle or time, TE), got {len(parts)}: {text!r}")
        if any(v is None for v in nums):
            raise bad(i, f"expected two numbers, got {text!r}")
        if not all(math.isfinite(v) for v in nums):
            raise bad(i, f"not a finite number: {text[:60]!r}")
        if len(rows) >= MAX_TE_ROWS:
            raise bad(i, f"more than {MAX_TE_ROWS} samples; at most {MAX_TE_ROWS} are read (resample the record)")
        rows.append((i, *nums))
    if not rows:
        raise bad(max(len(lines), 1), "no numeric rows (angle or time, TE) in the file")
    if len(rows) < 16:
        raise bad(rows[-1][0], f"only {len(rows)} rows: at least 16 samples are needed")

    where = header_line or rows[0][0]
    xu = _pick_unit(src, where, "first column", header_units[0], x_unit)
    tu = _pick_unit(src, where, "TE column", header_units[1], te_unit)
    if tu not in LENGTH_UNITS:
        raise bad(where, f"TE unit {tu!r} is not a length along the line of action (use um, mm, nm or m)")
    if xu in ANGLE_UNITS:
        kind, scale = "angle", ANGLE_UNITS[xu]
    elif xu in TIME_UNITS:
        kind, scale = "time", TIME_UNITS[xu]
    else:
        raise bad(where, f"first-column unit {xu!r} is neither an angle (deg, rad, rev) nor a time (s, ms, us)")
    _, x, te = np.array(rows).T
    x, te = x * scale, te * LENGTH_UNITS[tu]
    big = ~(np.abs(te) <= MAX_TE_UM)
    if np.any(big):
        k = int(np.argmax(big))
        raise bad(rows[k][0], f"TE {rows[k][2]:g} {tu} is beyond {MAX_TE_UM:g} µm (1 m): not a transmission error")
    if not np.all(np.isfinite(x)):
        k = int(np.argmax(~np.isfinite(x)))
        raise bad(rows[k][0], f"{rows[k][1]:g} {xu} is out of range")
    steps = np.diff(x)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0)) + 1
        raise bad(
            rows[k][0],
            f"the {kind} must increase strictly: {rows[k][1]:g} follows {rows[k - 1][1]:g} (line {rows[k - 1][0]})",
        )
    used_rpm = None
    if kind == "time":
        if rpm is None:
            raise bad(where, "a time record needs the pinion speed (--rpm) to give the pinion angle")
        if not (math.isfinite(rpm) and 0 < rpm <= MAX_TE_RPM):
            raise ConfigError(
                f"rpm: the pinion speed of the time record {src} must be in (0, {MAX_TE_RPM:g}] rpm, got {rpm!r}"
            )
        used_rpm = float(rpm)
        x = (x - x[0]) * used_rpm * math.pi / 30.0
    return TESignal(source=src, angle=x - x[0], te_um=te, abscissa=kind, rpm=used_rpm)


def _read_lines(src: str) -> list[str]:
    """The lines of a TE file, read in a bounded way (at most :data:`MAX_TE_BYTES`)."""
    from ._config_values import regular_file_size

    size = regular_file_size(src, "TE file")
    if size > MAX_TE_BYTES:
        raise ConfigError(
            f"{src}: TE file of {size / 1e6:.1f} MB; at most {MAX_TE_BYTES / 1e6:.0f} MB are read "
            f"(at most {MAX_TE_ROWS} samples; resample the record)"
        )
    try:
        with open(src, "rb") as f:
            data = f.read(MAX_TE_BYTES + 1)
    except OSError as e:
        raise ConfigError(f"{src}: cannot read the TE file ({e.strerror or e})") from None
    if len(data) > MAX_TE_BYTES:
        raise ConfigError(f"{src}: TE file larger than {MAX_TE_BYTES / 1e6:.0f} MB")
    try:
        return data.decode("utf-8-sig").splitlines()
    except UnicodeDecodeError as e:
        raise ConfigError(f"{src}: cannot read the TE file: not UTF-8 text (byte {e.start})") from None


def _pick_unit(src: str, line: int, what: str, header: str | None, given: str | None) -> str:
    given = None if given is None else given.strip().lower().replace("μ", "µ")
    if header is not None and given is not None and header != given:
        raise ConfigError(f"{src}: line {line}: the header gives the {what} in {header!r}, the option {given!r}")
    unit = header or given
    if unit is None:
        raise ConfigError(
            f"{src}: line {line}: units not stated for the {what}: write them in a header "
            "(e.g. 'angle [deg], TE [um]') or give --x-unit and --te-unit"
        )
    return unit


@dataclass(frozen=True)
class TEAnalysis:
    """Orders of a measured TE record (amplitudes in µm, phases in rad of ``A cos(o φ1 + φ)``).

    Attributes
    ----------
    z1, z2 : int
        Teeth of pinion and gear.
    mesh : list of dict
        Mesh harmonics ``l`` = 1 … L: ``order`` (l z1, pinion orders), ``amplitude_um``, ``phase_rad``
        (phase in the mesh angle θ = z1 φ1, θ = 0 at the first sample).
    sidebands : list of dict
        Shaft orders and sidebands: ``order``, ``kind`` (``pinion``/``gear`` shaft order or
        ``sideband``), ``mesh_harmonic`` (0 for a shaft order), ``shaft`` (pinion or gear), ``j``
        (the shaft order), ``amplitude_um``, ``phase_rad``.
    mean_um : float
        The mean TE (not part of the forcing).
    sideband_share, residual_share : float
        See the module docstring.
    hunting_mesh_cycles : int
        lcm(z1, z2): mesh cycles after which the pattern of tooth pairs repeats.
    revolutions : float
        Pinion revolutions in the record.
    source : str
        Where the record came from (file name), for the summary.
    left_out : list of str
        Orders not fitted (gear orders in a record shorter than one gear revolution).
    """

    z1: int
    z2: int
    mesh: list[dict[str, Any]]
    sidebands: list[dict[str, Any]]
    mean_um: float
    sideband_share: float
    residual_share: float
    hunting_mesh_cycles: int
    revolutions: float
    source: str = ""
    left_out: list[str] = field(default_factory=list)

    @property
    def periodic_over_mesh_cycle(self) -> bool:
        """Whether the sidebands are small enough (share < :data:`PERIODIC_SHARE`) to take the forcing as periodic."""
        return self.sideband_share < PERIODIC_SHARE

    def to_json(self) -> dict[str, Any]:
        """JSON summary (phases also in degrees)."""

        def with_deg(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
            return [{**r, "phase_deg": math.degrees(r["phase_rad"])} for r in rows]

        return {
            "source": self.source,
            "z1": self.z1,
            "z2": self.z2,
            "mesh_harmonics": with_deg(self.mesh),
            "sidebands": with_deg(self.sidebands),
            "mean_um": self.mean_um,
            "sideband_share": self.sideband_share,
            "residual_share": self.residual_share,
            "hunting_period_mesh_cycles": self.hunting_mesh_cycles,
            "hunting_period_pinion_revolutions": self.hunting_mesh_cycles / self.z1,
            "periodic_over_mesh_cycle": self.periodic_over_mesh_cycle,
            "periodic_share_threshold": PERIODIC_SHARE,
            "record_pinion_revolutions": self.revolutions,
            "left_out": list(self.left_out),
        }


def analyse_te(signal: TESignal, z1: int, z2: int, *, harmonics: int = 3, shaft_orders: int = 2) -> TEAnalysis:
    """Mesh harmonics, shaft orders and sidebands of a TE record by linear least squares.

    Parameters
    ----------
    signal : TESignal
        The record (:func:`read_te`).
    z1, z2 : int
        Teeth of pinion and gear (>= 1).
    harmonics : int, optional
        Mesh harmonics L fitted (orders l z1, l = 1 … L).
    shaft_orders : int, optional
        Shaft orders J of each shaft fitted on their own and as sidebands ``l z1 ± j`` (pinion) and
        ``l z1 ± j z1/z2`` (gear), j = 1 … J.

    Returns
    -------
    TEAnalysis

    Raises
    ------
    ConfigError
        For bad teeth counts, a record shorter than one mesh cycle, or too few samples for the orders.
    """
    src = signal.source
    for name, z in (("z1", z1), ("z2", z2)):
        if isinstance(z, bool) or not isinstance(z, (int, np.integer)) or not 1 <= z <= MAX_TEETH:
            raise ConfigError(f"teeth: {name} must be a whole number from 1 to {MAX_TEETH}, got {z!r}")
    z1, z2 = int(z1), int(z2)
    if not 1 <= harmonics <= MAX_ORDERS:
        raise ConfigError(f"harmonics: must be from 1 to {MAX_ORDERS}, got {harmonics}")
    if not 0 <= shaft_orders <= MAX_ORDERS:
        raise ConfigError(f"shaft-orders: must be from 0 to {MAX_ORDERS}, got {shaft_orders}")
    phi = np.asarray(signal.angle, dtype=float)
    y = np.asarray(signal.te_um, dtype=float)
    fitted = 2 * harmonics * (1 + 4 * shaft_orders) + 4 * shaft_orders
    if y.size * 2 * fitted * 8 > MAX_FIT_BYTES:
        raise ConfigError(
            f"harmonics: {y.size} samples × {2 * fitted} columns take {y.size * 16 * fitted / 1e9:.3g} GB; "
            f"at most {MAX_FIT_BYTES / 1e9:g} GB (fewer --harmonics or --shaft-orders)"
        )
    step = float(np.max(np.diff(phi))) if phi.size > 1 else 0.0
    if not (math.isfinite(step) and step * z1 * harmonics < math.pi):
        what = f" at {signal.rpm:g} rpm" if signal.rpm is not None else ""
        raise ConfigError(
            f"{src}: the samples{what} are {step * z1 / (2 * math.pi):.3g} mesh cycles apart: mesh harmonic "
            f"{harmonics} needs more than 2 samples per cycle (a smaller --rpm, a denser record or fewer --harmonics)"
        )
    revs = float(phi[-1] / (math.tau))
    if revs * z1 < 1.0:
        raise ConfigError(f"{src}: the record covers {revs * z1:.3g} mesh cycles: at least one is needed")
    gear_ok = revs >= z2 / z1
    left_out = (
        []
        if gear_ok
        else [
            f"gear orders: the record covers {revs:.3g} pinion revolutions, less than one "
            f"gear revolution ({z2 / z1:.3g})"
        ]
    )
    orders: list[dict[str, Any]] = [
        {"order": float(l * z1), "kind": "mesh", "mesh_harmonic": l} for l in range(1, harmonics + 1)
    ]
    shafts = [("pinion", 1.0)] + ([("gear", z1 / z2)] if gear_ok else [])
    for shaft, unit in shafts:
        for j in range(1, shaft_orders + 1):
            orders.append(
                {"order": j * unit, "kind": f"{shaft} shaft order", "mesh_harmonic": 0, "shaft": shaft, "j": j}
            )
            for l in range(1, harmonics + 1):
                for sgn in (-1, 1):
                    o = l * z1 + sgn * j * unit
                    if o > 0:
                        orders.append(
                            {"order": o, "kind": "sideband", "mesh_harmonic": l, "shaft": shaft, "j": sgn * j}
                        )
    # merge orders that coincide (e.g. z2 = z1: the gear orders are the pinion orders)
    uniq: list[dict[str, Any]] = []
    for o in orders:
        if not any(abs(o["order"] - u["order"]) < 1e-9 for u in uniq):
            uniq.append(o)
    omega = np.array([o["order"] for o in uniq])
    if y.size < 2 * omega.size + 8:
        raise ConfigError(f"{src}: {y.size} samples are too few for {omega.size} orders (need {2 * omega.size + 8})")
    a = np.empty((y.size, 1 + 2 * omega.size))
    a[:, 0] = 1.0
    arg = phi[:, None] * omega[None, :]
    a[:, 1::2] = np.cos(arg)
    a[:, 2::2] = np.sin(arg)
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    resid = y - a @ coef
    rows_mesh, rows_side = [], []
    part_side = np.zeros_like(y)
    part_all = a[:, 1:] @ coef[1:]
    for i, o in enumerate(uniq):
        c, s = coef[1 + 2 * i], coef[2 + 2 * i]
        # c cos + s sin = A cos(x + ph)
        row = {**o, "amplitude_um": float(math.hypot(c, s)), "phase_rad": float(math.atan2(-s, c))}
        (rows_mesh if o["kind"] == "mesh" else rows_side).append(row)
        if o["kind"] != "mesh":
            part_side += c * a[:, 1 + 2 * i] + s * a[:, 2 + 2 * i]
    rms_all = float(np.sqrt(np.mean(part_all**2)))
    dev = float(np.std(y))
    return TEAnalysis(
        z1=z1,
        z2=z2,
        mesh=rows_mesh,
        sidebands=rows_side,
        mean_um=float(coef[0]),
        sideband_share=float(np.sqrt(np.mean(part_side**2)) / rms_all) if rms_all > 0 else 0.0,
        residual_share=float(np.sqrt(np.mean(resid**2)) / dev) if dev > 0 else 0.0,
        hunting_mesh_cycles=math.lcm(z1, z2),
        revolutions=revs,
        source=src,
        left_out=left_out,
    )


def mesh_section(res: TEAnalysis) -> str:
    """A ``[mesh]`` section (TOML) with the mesh orders as STE harmonics ``e``/``phi_e``.

    Parameters
    ----------
    res : TEAnalysis
        The analysed record.

    Returns
    -------
    str
        TOML text; its comments state the source, that only the mesh orders are kept and the
        sidebands' share of the signal.  Add it to a configuration with a ``[gear_pair]`` (the
        lengths need the pair's characteristic length).
    """
    e = ", ".join(f'"{r["amplitude_um"]:.6g} um"' for r in res.mesh)
    ph = ", ".join(f'"{math.degrees(r["phase_rad"]):.6g} deg"' for r in res.mesh)
    verdict = (
        "small enough to take the forcing as periodic over one mesh cycle"
        if res.periodic_over_mesh_cycle
        else "NOT negligible: the measured forcing is not periodic over one mesh cycle"
    )
    return (
        f"# STE harmonics from the measured transmission error {res.source} (z1 = {res.z1}, z2 = {res.z2}).\n"
        f"# Mesh orders only; the shaft orders and sidebands are {100 * res.sideband_share:.3g} % of the RMS of the\n"
        f"# fitted orders ({verdict}); hunting period {res.hunting_mesh_cycles} mesh cycles.\n"
        f"# Phases: e(θ) = Σ e_l cos(lθ + φ_l) with θ = 0 at the first sample of the record.\n"
        "[mesh]\n"
        f'e = {{ value = [{e}], assumed = "measured TE taken as the static transmission error" }}\n'
        f"phi_e = [{ph}]\n"
    )
