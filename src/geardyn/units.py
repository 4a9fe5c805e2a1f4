"""Physical front-end: pinion speed (rpm), torque (N·m), lengths (µm) and forces (N) of a gear pair.

The non-dimensional model (:class:`~geardyn.model.GearModel`) knows nothing of a gear pair.
This module connects the two for a *configured* pair (a TOML configuration, see
:mod:`geardyn.config`; without one, the paper's Table 1 pair shipped with geardyn, whose mean mesh
stiffness k0 = 2000 N/µm is an assumption: face width 100 mm × c_γ = 20 N/(mm·µm)):

* :func:`operating_overrides` turns ``rpm`` / ``torque`` into the non-dimensional ω / f_p of a
  model (refusing a speed together with ω, or a torque together with f_p);
* :func:`omega_range` turns a pinion-speed range into an ω range for sweeps;
* :class:`PhysicalScales` holds the scales as plain numbers so that they can be stored with a
  result (the ``physical_scales`` attribute of a Dataset, :meth:`PhysicalScales.to_json`) and
  used again when the result is read back, without the configuration file.

The scales (``docs/model.md`` §3): length b_c, time 1/ω_n, force k0 b_c, frequency ω_n, with
ω = ω_e/ω_n, ω_e = 2π z1 n1/60 for a pinion speed n1 in rpm, f_p = F_p/(k0 b_c) and, for
balanced torques, F_p = T1/R1.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .model import GearModel, ModelError

if TYPE_CHECKING:  # pragma: no cover
    from .config import LoadedConfig

__all__ = [
    "PhysicalScales",
    "apply_operating_point",
    "configured_pair",
    "omega_range",
    "operating_overrides",
    "scales_of",
]

#: Name of the Dataset attribute that stores :class:`PhysicalScales` as JSON.
SCALES_ATTR = "physical_scales"
#: Assumptions of a configuration that concern its operating point, not the scales.
_OPERATING_KEYS = ("rpm", "torque", "torque2")


def _number(name: str, value: Any, unit: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected a number in {unit}, got {value!r}") from None
    if not math.isfinite(x):
        raise ModelError(f"{name}: must be a finite number of {unit}, got {value!r}")
    return x


def _speed(name: str, value: Any) -> float:
    x = _number(name, value, "rpm")
    if x <= 0:
        raise ModelError(f"{name}: pinion speed must be > 0 rpm, got {x:g} rpm")
    return x


def configured_pair(config: str | Path | None = None) -> "LoadedConfig":
    """The gear pair of a configuration file; ``None`` gives the paper's Table 1 pair (k0 assumed).

    Parameters
    ----------
    config : str or Path, optional
        TOML configuration (see :mod:`geardyn.config`).
    """
    from .config import load_config

    return load_config(config)


@dataclass(frozen=True)
class PhysicalScales:
    """The scales between the non-dimensional model and one gear pair, as plain numbers.

    Build it with :meth:`from_config`; store it with :meth:`to_json` and read it back with
    :meth:`from_json` (results keep it in their ``physical_scales`` attribute).  Every conversion
    accepts floats or NumPy arrays.

    Attributes
    ----------
    title : str
        Name of the gear pair (configuration title).
    source : str
        Configuration it came from.
    z1 : int
        Teeth of the pinion (the mesh frequency is z1 times the pinion speed).
    b_c_m : float
        Characteristic length b_c (m): u = u_n / b_c.
    k0_N_per_m : float
        Mean mesh stiffness k0 (N/m).
    m_e_kg : float
        Equivalent mass m_e (kg).
    omega_n_rad_s : float
        ω_n = √(k0/m_e) (rad/s): τ = ω_n t, ω = ω_e/ω_n.
    R1_m, R2_m : float
        Directional radii of pinion and gear (m); with balanced torques F_p = T1/R1.
    D : float
        Non-dimensional half backlash b_n/b_c of the pair.
    assumed : tuple of str
        Names of the inputs of the pair that are assumptions (e.g. ``k0``).
    k0_source : str
        Where k0 comes from (given, or face width × c_γ, and whether that is assumed).
    """

    title: str
    source: str
    z1: int
    b_c_m: float
    k0_N_per_m: float
    m_e_kg: float
    omega_n_rad_s: float
    R1_m: float
    R2_m: float
    D: float
    assumed: tuple[str, ...] = field(default=())
    k0_source: str = ""

    # ------------------------------------------------------------------ construction, storage
    @classmethod
    def from_config(cls, cfg: "LoadedConfig") -> "PhysicalScales":
        """Scales of a loaded configuration (its pair and characteristic length)."""
        pair = cfg.pair
        k0_src = "given"
        for a in cfg.assumptions:
            if a.name == "k0":
                k0_src = f"assumed: {a.source}"
                rv = pair.resolved
                if not math.isnan(rv.c_gamma):
                    k0_src += f" = {rv.face_width * 1e3:.6g} mm × {rv.c_gamma * 1e-9:.6g} N/(mm·µm)"
        return cls(
            title=cfg.title or pair.name,
            source=cfg.source,
            z1=int(pair.z1),
            b_c_m=float(cfg.b_c),
            k0_N_per_m=float(pair.k0_mean),
            m_e_kg=float(pair.m_e),
            omega_n_rad_s=float(pair.omega_n),
            R1_m=float(pair.R1),
            R2_m=float(pair.R2),
            D=float(pair.b_n / cfg.b_c),
            assumed=tuple(a for a in cfg.assumed if a not in _OPERATING_KEYS),
            k0_source=k0_src,
        )

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["assumed"] = list(self.assumed)
        return d

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> "PhysicalScales":
        d = json.loads(text)
        d["assumed"] = tuple(d.get("assumed", ()))
        return cls(**d)

    @classmethod
    def from_attrs(cls, attrs: dict[str, Any]) -> "PhysicalScales | None":
        """The scales stored in a Dataset's attributes, or ``None`` when there are none."""
        text = attrs.get(SCALES_ATTR)
        return cls.from_json(text) if text else None

    # ------------------------------------------------------------------ derived scales
    @property
    def force_scale_N(self) -> float:
        """Force scale k0 b_c (N): F = f · k0 b_c."""
        return self.k0_N_per_m * self.b_c_m

    @property
    def natural_frequency_Hz(self) -> float:
        """f_n = ω_n / 2π (Hz)."""
        return self.omega_n_rad_s / (2.0 * math.pi)

    def statement(self) -> str:
        """One line naming the pair and its k0 (and that it is assumed, when it is)."""
        return (
            f"{self.title} ({self.source}): k0 = {self.k0_N_per_m * 1e-6:.6g} N/µm ({self.k0_source}), "
            f"b_c = {self.b_c_m * 1e6:.6g} µm, f_n = {self.natural_frequency_Hz:.6g} Hz"
        )

    # ------------------------------------------------------------------ conversions
    def omega_from_rpm(self, rpm: Any) -> Any:
        """ω = 2π z1 n1 / (60 ω_n) (non-dimensional) from the pinion speed n1 (rpm)."""
        return 2.0 * np.pi * self.z1 * np.asarray(rpm, dtype=float) / 60.0 / self.omega_n_rad_s

    def rpm_from_omega(self, omega: Any) -> Any:
        """Pinion speed (rpm) from ω."""
        return np.asarray(omega, dtype=float) * self.omega_n_rad_s * 60.0 / (2.0 * np.pi * self.z1)

    def hz_from_omega(self, omega: Any) -> Any:
        """Frequency (Hz) of a non-dimensional angular frequency (in units of ω_n), e.g. the mesh frequency ω."""
        return np.asarray(omega, dtype=float) * self.omega_n_rad_s / (2.0 * np.pi)

    def s_from_tau(self, tau: Any) -> Any:
        """Seconds from non-dimensional time τ = ω_n t."""
        return np.asarray(tau, dtype=float) / self.omega_n_rad_s

    def per_s_from_per_tau(self, rate: Any) -> Any:
        """A rate per second (e.g. a Lyapunov exponent in 1/s) from a rate per unit τ."""
        return np.asarray(rate, dtype=float) * self.omega_n_rad_s

    def um_from_u(self, u: Any) -> Any:
        """Micrometres from a non-dimensional displacement u (u_n = u b_c)."""
        return np.asarray(u, dtype=float) * self.b_c_m * 1e6

    def u_from_um(self, x: Any) -> Any:
        """Non-dimensional displacement from micrometres."""
        return np.asarray(x, dtype=float) * 1e-6 / self.b_c_m

    def N_from_force(self, f: Any) -> Any:
        """Newtons from a non-dimensional force (F = f k0 b_c)."""
        return np.asarray(f, dtype=float) * self.force_scale_N

    def force_from_N(self, F: Any) -> Any:
        """Non-dimensional force F/(k0 b_c) from newtons."""
        return np.asarray(F, dtype=float) / self.force_scale_N

    def fp_from_torque(self, torque: Any) -> Any:
        """f_p = T1/(R1 k0 b_c) from the pinion torque T1 (N·m), balanced torques (F_p = T1/R1)."""
        return np.asarray(torque, dtype=float) / self.R1_m / self.force_scale_N

    def torque_from_fp(self, fp: Any) -> Any:
        """Pinion torque T1 (N·m) giving f_p with balanced torques: T1 = f_p k0 b_c R1."""
        return np.asarray(fp, dtype=float) * self.force_scale_N * self.R1_m

    def operating_point(self, model: GearModel) -> dict[str, float]:
        """Speed, frequencies, torque and static force of a model (JSON-ready).

        Keys: ``omega``, ``rpm``, ``mesh_frequency_Hz``, ``natural_frequency_Hz``, ``fp``,
        ``torque_N_m`` (pinion, balanced), ``static_force_N`` (F_p = f_p k0 b_c).
        """
        return {
            "omega": float(model.omega),
            "rpm": float(self.rpm_from_omega(model.omega)),
            "mesh_frequency_Hz": float(self.hz_from_omega(model.omega)),
            "natural_frequency_Hz": self.natural_frequency_Hz,
            "fp": float(model.fp),
            "torque_N_m": float(self.torque_from_fp(model.fp)),
            "static_force_N": float(self.N_from_force(model.fp)),
        }


def scales_of(obj: Any) -> PhysicalScales:
    """:class:`PhysicalScales` from a LoadedConfig, a PhysicalScales, a JSON string or ``None`` (paper pair)."""
    if isinstance(obj, PhysicalScales):
        return obj
    if obj is None:
        return PhysicalScales.from_config(configured_pair(None))
    if isinstance(obj, str) and obj.lstrip().startswith("{"):
        return PhysicalScales.from_json(obj)
    if isinstance(obj, (str, Path)):
        return PhysicalScales.from_config(configured_pair(obj))
    if hasattr(obj, "pair") and hasattr(obj, "b_c"):
        return PhysicalScales.from_config(obj)
    raise ModelError(f"scales: expected a configuration, PhysicalScales or None, got {type(obj).__name__}")


def operating_overrides(
    scales: PhysicalScales,
    *,
    rpm: float | None = None,
    torque: float | None = None,
    omega: float | None = None,
    fp: float | None = None,
) -> dict[str, float]:
    """Non-dimensional ω and f_p from a pinion speed and torque.

    Parameters
    ----------
    scales : PhysicalScales
        The gear pair's scales.
    rpm : float, optional
        Pinion speed (rpm, > 0); gives ω.  Not together with ``omega``.
    torque : float, optional
        Pinion torque T1 (N·m, balanced); gives f_p.  Not together with ``fp``.
    omega, fp : float, optional
        The non-dimensional values given alongside, only to refuse a clash.

    Returns
    -------
    dict
        ``{"omega": ...}`` and/or ``{"fp": ...}`` (non-dimensional), only for what was given.
    """
    out: dict[str, float] = {}
    if rpm is not None:
        if omega is not None:
            raise ModelError("rpm: give the speed either as --rpm (pinion speed) or as --omega, not both")
        out["omega"] = float(scales.omega_from_rpm(_speed("rpm", rpm)))
    if torque is not None:
        if fp is not None:
            raise ModelError("torque: give the load either as --torque (pinion torque) or as --fp, not both")
        out["fp"] = float(scales.fp_from_torque(_number("torque", torque, "N*m")))
    return out


def apply_operating_point(
    model: GearModel, scales: PhysicalScales, *, rpm: float | None = None, torque: float | None = None
) -> GearModel:
    """``model`` with ω from the pinion speed ``rpm`` and f_p from the pinion torque ``torque``."""
    ch = operating_overrides(scales, rpm=rpm, torque=torque)
    return model.replace(**ch) if ch else model


def omega_range(scales: PhysicalScales, rpm_start: float, rpm_stop: float) -> tuple[float, float]:
    """The ω range of a pinion-speed range (rpm): ``(ω(rpm_start), ω(rpm_stop))``, both > 0."""
    a, b = _speed("rpm_start", rpm_start), _speed("rpm_stop", rpm_stop)
    if a == b:
        raise ModelError(f"rpm_stop: must differ from rpm_start, got {a:g} rpm for both")
    return float(scales.omega_from_rpm(a)), float(scales.omega_from_rpm(b))


def sweep_range(
    scales: "PhysicalScales | None",
    rpm_start: float | None,
    rpm_stop: float | None,
    start: float | None = None,
    stop: float | None = None,
    *,
    param: str = "omega",
) -> tuple[float | None, float | None]:
    """The (start, stop) of a sweep given either non-dimensionally or as a pinion-speed range.

    Parameters
    ----------
    scales : PhysicalScales or None
        The gear pair's scales; only used (and only needed) when an rpm range is given.
    rpm_start, rpm_stop : float or None
        Pinion-speed range (rpm); both or neither.
    start, stop : float or None
        The non-dimensional range as given (returned unchanged when no rpm range is given).
    param : str
        The swept parameter: an rpm range only makes sense for ``omega``.

    Returns
    -------
    tuple
        ``(start, stop)`` in ω when an rpm range was given, else ``(start, stop)`` as given.
    """
    if rpm_start is None and rpm_stop is None:
        return start, stop
    if rpm_start is None or rpm_stop is None:
        raise ModelError("rpm_start: give both --rpm-start and --rpm-stop (the pinion-speed range in rpm)")
    if param != "omega":
        raise ModelError(f"rpm_start: a pinion-speed range sweeps omega, but the swept parameter is {param!r}")
    if start is not None or stop is not None:
        raise ModelError("rpm_start: give the range either in rpm (--rpm-start/--rpm-stop) or as ω, not both")
    if scales is None:
        raise ModelError("rpm_start: a pinion-speed range needs a gear pair (--config)")
    return omega_range(scales, rpm_start, rpm_stop)
