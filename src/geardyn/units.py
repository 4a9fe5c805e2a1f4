"""Physical front-end: pinion speed (rpm), torque (N·m), lengths (µm) and forces (N) of a gear pair.

The non-dimensional model (:class:`~geardyn.model.GearModel`) knows nothing of a gear pair.
This module connects the two for a *configured* pair (a TOML configuration, see
:mod:`geardyn.config`; without one, the paper's Table 1 pair shipped with geardyn, whose mean mesh
stiffness k0 = 2000 N/µm is an assumption: face width 100 mm × c_γ = 20 N/(mm·µm)):

* :func:`operating_overrides` turns ``rpm`` / ``torque`` into the non-dimensional ω / f_p of a
  model (refusing a speed together with ω, or a torque together with f_p);
* :func:`omega_range` turns a pinion-speed range into an ω range for sweeps;
* :func:`scales_of` gives the :class:`PhysicalScales` of a configuration, of a stored result or
  of the paper's pair.

:class:`PhysicalScales` (defined in :mod:`geardyn.geometry.scales`, importable from here) holds
the scales as plain numbers and every conversion: length b_c, time 1/ω_n, force k0 b_c,
frequency ω_n, with ω = ω_e/ω_n, ω_e = 2π z1 n1/60 for a pinion speed n1 in rpm,
f_p = F_p/(k0 b_c) and, for balanced torques, F_p = T1/R1 (``docs/model.md`` §3).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .geometry.inputs import _finite
from .geometry.scales import SCALES_ATTR, PhysicalScales
from .model import ModelError

__all__ = [
    "PhysicalScales",
    "SCALES_ATTR",
    "omega_range",
    "operating_overrides",
    "scales_of",
    "sweep_range",
]


def _speed(name: str, value: Any) -> float:
    x = _finite(name, value, "rpm", of_unit=True)
    if x <= 0:
        raise ModelError(f"{name}: pinion speed must be > 0 rpm, got {x:g} rpm")
    return x


#: Range of ω a pinion speed may give: from 10⁻⁴ to 10³ times the natural frequency of the mesh.
MIN_OMEGA, MAX_OMEGA = 1e-4, 1e3


def _omega_of(scales: Any, name: str, rpm: float) -> float:
    """ω of pinion speed ``rpm``, refused (naming ``name`` and the allowed speeds) outside
    [:data:`MIN_OMEGA`, :data:`MAX_OMEGA`]."""
    w = float(scales.omega_from_rpm(rpm))
    if not MIN_OMEGA <= w <= MAX_OMEGA:
        lo, hi = (float(scales.rpm_from_omega(x)) for x in (MIN_OMEGA, MAX_OMEGA))
        raise ModelError(
            f"{name}: {rpm:g} rpm is ω = {w:.4g} for this gear pair; allowed {lo:.4g} to {hi:.4g} rpm "
            f"(ω from {MIN_OMEGA:g} to {MAX_OMEGA:g})"
        )
    return w


def _physical_needed(scales: Any, name: str | None) -> None:
    """Refuse a speed or torque for the unit scales of a configuration without a gear pair."""
    if name is not None and getattr(scales, "nondimensional", False):
        raise ModelError(
            f"{name}: the configuration {scales.source} has no [gear_pair], so a pinion speed or torque "
            "has no meaning; give ω (--omega) and f_p (--fp) instead"
        )


def scales_of(obj: Any) -> PhysicalScales:
    """:class:`PhysicalScales` from a LoadedConfig, a PhysicalScales, a JSON string or ``None`` (paper pair).

    Parameters
    ----------
    obj : LoadedConfig, PhysicalScales, str, Path or None
        A loaded configuration, scales (returned as they are), their JSON (:meth:`PhysicalScales.to_json`),
        the path of a configuration file, or ``None`` for the paper's Table 1 pair (k0 assumed).

    Returns
    -------
    PhysicalScales

    Raises
    ------
    ConfigError
        For a configuration file that cannot be read (see :func:`geardyn.config.load_config`).
    ModelError
        For an object of another type, or invalid values in the configuration.
    """
    from .config import load_config

    if isinstance(obj, PhysicalScales):
        return obj
    if isinstance(obj, str) and obj.lstrip().startswith("{"):
        return PhysicalScales.from_json(obj)
    if obj is None or isinstance(obj, (str, Path)):
        return PhysicalScales.from_config(load_config(obj))
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
    _physical_needed(scales, "rpm" if rpm is not None else "torque" if torque is not None else None)
    if rpm is not None:
        if omega is not None:
            raise ModelError("rpm: give the speed either as --rpm (pinion speed) or as --omega, not both")
        out["omega"] = _omega_of(scales, "rpm", _speed("rpm", rpm))
    if torque is not None:
        if fp is not None:
            raise ModelError("torque: give the load either as --torque (pinion torque) or as --fp, not both")
        out["fp"] = float(scales.fp_from_torque(_finite("torque", torque, "N*m", of_unit=True)))
    return out


def omega_range(scales: PhysicalScales, rpm_start: float, rpm_stop: float) -> tuple[float, float]:
    """The ω range of a pinion-speed range (rpm): ``(ω(rpm_start), ω(rpm_stop))``, both > 0.

    Parameters
    ----------
    scales : PhysicalScales
        The gear pair's scales.
    rpm_start, rpm_stop : float
        Pinion speeds (rpm), > 0 and different.

    Returns
    -------
    tuple of float
        ``(omega_start, omega_stop)``.
    """
    a, b = _speed("rpm_start", rpm_start), _speed("rpm_stop", rpm_stop)
    if a == b:
        raise ModelError(f"rpm_stop: must differ from rpm_start, got {a:g} rpm for both")
    return _omega_of(scales, "rpm_start", a), _omega_of(scales, "rpm_stop", b)


def sweep_range(
    scales: PhysicalScales | None,
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
    _physical_needed(scales, "rpm_start")
    return omega_range(scales, rpm_start, rpm_stop)
