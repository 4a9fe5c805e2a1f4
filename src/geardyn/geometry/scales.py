"""The scales between a non-dimensional System and its physical units, and every conversion between them.

The scales (``docs/model.md`` §3): length b_c, time 1/ω_n, force k0 b_c, frequency ω_n, with
ω = ω_e/ω_n, ω_e = 2π z1 n1/60 for a pinion speed n1 in rpm, f_p = F_p/(k0 b_c) and, for
balanced torques, F_p = T1/R1.  For a system of meshes they are those of its reference mesh (k0 its
mean stiffness, m_e its equivalent mass, z1 its pinion's teeth), with the scale of every DOF
(q_i = s_i q̃_i).  :class:`Scales` holds them as plain numbers, for the pair and every system alike, so
that they can be stored with a result (the ``physical_scales`` attribute of a Dataset) and used again when
the result is read back, without the gear pair, the system or their files.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from functools import partial
from typing import Any

import numpy as np

from ..errors import ModelError

#: An array-like as a float array (every conversion takes scalars or arrays).
_floats = partial(np.asarray, dtype=float)

__all__ = ["Scales", "PhysicalScales", "SCALES_ATTR"]

#: Name of the Dataset attribute that stores :class:`Scales` as JSON.
SCALES_ATTR = "physical_scales"
#: Assumptions of a configuration that concern its operating point, not the scales.
_OPERATING_KEYS = ("rpm", "torque", "torque2")


def _number(x: Any) -> float | None:
    """A finite number as float, else None (JSON has no NaN)."""
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class Scales:
    """The scales between a non-dimensional System and its physical units, as plain numbers.

    Build it from a pair (:meth:`SpiralBevelGearPair.scales <geardyn.geometry.SpiralBevelGearPair.scales>`,
    :meth:`from_pair`), a loaded configuration (:meth:`from_config`) or a system's reference mesh
    (:meth:`of_reference_mesh`; a :class:`~geardyn.systems.SystemModel` keeps them as its ``scaling``); store it
    with :meth:`to_json` and read it back with :meth:`from_json` (results keep it in their
    ``physical_scales`` attribute).  Every conversion accepts floats or NumPy arrays.

    Attributes
    ----------
    title : str
        Name of the gear pair (configuration title).
    source : str
        Configuration it came from ("" for a pair built in Python).
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
    nondimensional : bool
        ``True`` for the unit scales of a configuration without ``[gear_pair]`` (:meth:`unit`): every
        "physical" value then repeats its non-dimensional one, and a speed or torque cannot be given.
    reference : str
        The reference mesh of a system ("" for the pair).
    dof_scales : tuple of float
        The scale s_i of every DOF of a system (q_i = s_i q̃_i, m or rad; empty for the pair).

    A system's scales have no pinion radii (R1_m, R2_m None: a system has no single pinion torque) and,
    when its reference mesh gives no teeth, z1 = 0 (speeds in rpm are then NaN, and refused as input).

    Examples
    --------
    >>> from geardyn import load_config
    >>> sc = load_config().scales
    >>> sc.z1, round(sc.k0_N_per_m / 1e6), round(sc.b_c_m * 1e6)  # teeth, k0 in N/µm, b_c in µm
    (23, 2000, 50)
    >>> round(float(sc.omega_from_rpm(3000)), 4), round(float(sc.rpm_from_omega(1.0)), 1)
    (1.002, 2993.9)
    >>> from geardyn import PhysicalScales
    >>> sc = PhysicalScales.unit()
    >>> float(sc.rpm_from_omega(0.8)), float(sc.um_from_u(2.0)), float(sc.N_from_force(0.5))
    (0.8, 2.0, 0.5)
    """

    title: str
    source: str
    z1: int
    b_c_m: float
    k0_N_per_m: float
    m_e_kg: float
    omega_n_rad_s: float
    R1_m: float | None
    R2_m: float | None
    D: float
    assumed: tuple[str, ...] = field(default=())
    k0_source: str = ""
    nondimensional: bool = False
    reference: str = ""
    dof_scales: tuple[float, ...] = field(default=())

    # ------------------------------------------------------------------ construction, storage
    @classmethod
    def from_pair(
        cls, pair: Any, b_c: float, *, title: str | None = None, source: str = "", assumptions: Any = None
    ) -> Scales:
        """Scales of a gear pair with the characteristic length ``b_c``.

        Parameters
        ----------
        pair : SpiralBevelGearPair
            The gear pair (gives z1, k0, m_e, ω_n, R1, R2, b_n and its assumptions).
        b_c : float
            Characteristic length (m), > 0 (not checked here; :meth:`SpiralBevelGearPair.scales` checks it).
        title : str, optional
            Name of the pair; default ``pair.name``.
        source : str
            Where the pair came from (a configuration file).
        assumptions : sequence of Assumption, optional
            The assumed inputs; default ``pair.assumptions``.  Those of the operating point
            (rpm, torque, torque2) are left out of :attr:`assumed`.

        Returns
        -------
        Scales
        """
        assumptions = tuple(pair.assumptions if assumptions is None else assumptions)
        k0_src = "given"
        for a in assumptions:
            if a.name == "k0":
                k0_src = f"assumed: {a.source}"
                rv = pair.resolved
                if not math.isnan(rv.c_gamma):
                    k0_src += f" = {rv.face_width * 1e3:.6g} mm × {rv.c_gamma * 1e-9:.6g} N/(mm·µm)"
        return cls(
            title=pair.name if title is None else title,
            source=source,
            z1=int(pair.z1),
            b_c_m=float(b_c),
            k0_N_per_m=float(pair.k0_mean),
            m_e_kg=float(pair.m_e),
            omega_n_rad_s=float(pair.omega_n),
            R1_m=float(pair.R1),
            R2_m=float(pair.R2),
            D=float(pair.b_n / b_c),
            assumed=tuple(a.name for a in assumptions if a.name not in _OPERATING_KEYS),
            k0_source=k0_src,
        )

    @classmethod
    def unit(cls, *, title: str = "", source: str = "", D: float = 1.0) -> Scales:
        """Unit scales of a non-dimensional configuration (no ``[gear_pair]``).

        With ω_n = 2π rad/s, z1 = 60, b_c = 1 µm, k0 = 1 N/µm and R1 = R2 = 1 m, a "speed in rpm"
        equals ω, a "frequency in Hz" equals ω, "µm" equal u and "N" and "N·m" equal the
        non-dimensional force, so the physical columns the commands add repeat the non-dimensional
        values; :attr:`nondimensional` is set and :meth:`statement` says so.

        Parameters
        ----------
        title, source : str
            The configuration's title and file.
        D : float
            The model's non-dimensional backlash.

        Returns
        -------
        Scales
        """
        w = 2.0 * math.pi
        return cls(
            title=title or "non-dimensional model",
            source=source,
            z1=60,
            b_c_m=1e-6,
            k0_N_per_m=1e6,
            m_e_kg=1e6 / w**2,
            omega_n_rad_s=w,
            R1_m=1.0,
            R2_m=1.0,
            D=float(D),
            assumed=(),
            k0_source="no [gear_pair]: unit scales, the physical values repeat the non-dimensional ones",
            nondimensional=True,
        )

    @classmethod
    def of_reference_mesh(
        cls,
        reference: str,
        k_ref: float,
        m_ref: float,
        b_c: float,
        dof_scales: tuple[float, ...],
        teeth: int | None,
        *,
        D: float = 1.0,
        title: str = "system",
        source: str = "",
    ) -> Scales:
        """The scales of a system of meshes: those of its reference mesh.

        Parameters
        ----------
        reference : str
            The reference mesh.
        k_ref, m_ref : float
            Its mean stiffness (N/m) and equivalent mass (kg); ω_n = √(k_ref/m_ref).
        b_c : float
            The characteristic length (m).
        dof_scales : tuple of float
            The scale of every DOF (q_i = s_i q̃_i).
        teeth : int or None
            Teeth of the reference mesh's pinion (None: unknown).
        D : float
            The reference mesh's half gap (non-dimensional).
        title, source : str
            The system's title and file.

        Returns
        -------
        Scales

        Examples
        --------
        >>> sc = Scales.of_reference_mesh("m", 1e8, 2.0, 1e-5, (1e-5, 1e-5), 20)
        >>> round(sc.omega_n_rad_s, 6), round(sc.force_scale_N, 9)
        (7071.067812, 1000.0)
        """
        return cls(
            title=title,
            source=source,
            z1=int(teeth or 0),
            b_c_m=float(b_c),
            k0_N_per_m=float(k_ref),
            m_e_kg=float(m_ref),
            omega_n_rad_s=math.sqrt(k_ref / m_ref),
            R1_m=None,
            R2_m=None,
            D=float(D),
            k0_source="reference mesh of the system",
            reference=reference,
            dof_scales=tuple(float(x) for x in dof_scales),
        )

    @classmethod
    def from_config(cls, cfg: Any) -> Scales:
        """Scales of a loaded configuration (its pair, characteristic length, title and source).

        Parameters
        ----------
        cfg : LoadedConfig
            A configuration from :func:`geardyn.config.load_config`.

        Returns
        -------
        Scales
            :meth:`unit` scales for a configuration without a gear pair.
        """
        if cfg.pair is None:
            return cls.unit(title=cfg.title, source=cfg.source, D=cfg.model.D)
        return cls.from_pair(
            cfg.pair, cfg.b_c, title=cfg.title or cfg.pair.name, source=cfg.source, assumptions=cfg.assumptions
        )

    def to_dict(self) -> dict[str, Any]:
        """The scales as a JSON-ready dict (the field names as keys)."""
        d = asdict(self)
        d["assumed"] = list(self.assumed)
        d["dof_scales"] = list(self.dof_scales)
        return d

    def to_json(self) -> str:
        """The scales as a JSON string (read back with :meth:`from_json`)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> Scales:
        """Scales from the JSON of :meth:`to_json`.

        Parameters
        ----------
        text : str
            The JSON text.

        Returns
        -------
        Scales
        """
        d = json.loads(text)
        d["assumed"] = tuple(d.get("assumed", ()))
        d["dof_scales"] = tuple(d.get("dof_scales", ()))
        return cls(**d)

    @classmethod
    def from_attrs(cls, attrs: dict[str, Any]) -> Scales | None:
        """The scales stored in a Dataset's attributes (:data:`SCALES_ATTR`), or ``None`` when there are none.

        Parameters
        ----------
        attrs : dict
            The attributes of a result Dataset.

        Returns
        -------
        Scales or None
        """
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
        if self.nondimensional:
            return f"{self.title} ({self.source}): non-dimensional, no [gear_pair] (the physical values repeat ω, u, f)"
        return (
            f"{self.title} ({self.source}): k0 = {self.k0_N_per_m * 1e-6:.6g} N/µm ({self.k0_source}), "
            f"b_c = {self.b_c_m * 1e6:.6g} µm, f_n = {self.natural_frequency_Hz:.6g} Hz"
        )

    # ------------------------------------------------------------------ speed and frequency
    def omega_from_rpm(self, rpm: Any) -> Any:
        """ω = 2π z1 n1 / (60 ω_n) (non-dimensional) from the pinion speed n1 (rpm).

        Raises
        ------
        ModelError
            Without the pinion's teeth (a system whose reference mesh gives none).
        """
        if not self.z1:
            raise ModelError(f"mesh {self.reference!r}: teeth: needed to convert a speed in rpm to ω; give ω (--omega)")
        return 2.0 * np.pi * self.z1 * _floats(rpm) / 60.0 / self.omega_n_rad_s

    def rpm_from_omega(self, omega: Any) -> Any:
        """Pinion speed (rpm) from ω (NaN without the pinion's teeth)."""
        if not self.z1:
            return _floats(omega) * np.nan
        return _floats(omega) * self.omega_n_rad_s * 60.0 / (2.0 * np.pi * self.z1)

    def hz_from_omega(self, omega: Any) -> Any:
        """Frequency (Hz) of a non-dimensional angular frequency (in units of ω_n), e.g. the mesh frequency ω."""
        return _floats(omega) * self.omega_n_rad_s / (2.0 * np.pi)

    # ------------------------------------------------------------------ time
    def tau_from_s(self, t: Any) -> Any:
        """Non-dimensional time τ = ω_n t from seconds."""
        return _floats(t) * self.omega_n_rad_s

    def s_from_tau(self, tau: Any) -> Any:
        """Seconds from non-dimensional time τ = ω_n t."""
        return _floats(tau) / self.omega_n_rad_s

    def per_s_from_per_tau(self, rate: Any) -> Any:
        """A rate per second (e.g. a Lyapunov exponent in 1/s) from a rate per unit τ."""
        return _floats(rate) * self.omega_n_rad_s

    # ------------------------------------------------------------------ length
    def u_from_um(self, x: Any) -> Any:
        """Non-dimensional displacement from micrometres."""
        return _floats(x) * 1e-6 / self.b_c_m

    def um_from_u(self, u: Any) -> Any:
        """Micrometres from a non-dimensional displacement u (u_n = u b_c)."""
        return _floats(u) * self.b_c_m * 1e6

    # ------------------------------------------------------------------ force and load
    def force_from_N(self, F: Any) -> Any:
        """Non-dimensional force F/(k0 b_c) from newtons (e.g. f_p from the static force F_p)."""
        return _floats(F) / self.force_scale_N

    def N_from_force(self, f: Any) -> Any:
        """Newtons from a non-dimensional force (F = f k0 b_c), e.g. the mesh force."""
        return _floats(f) * self.force_scale_N

    def fp_from_torque(self, torque: Any) -> Any:
        """f_p = T1/(R1 k0 b_c) from the pinion torque T1 (N·m), balanced torques (F_p = T1/R1).

        For unbalanced torques use :meth:`SpiralBevelGearPair.fp_from_torques
        <geardyn.geometry.SpiralBevelGearPair.fp_from_torques>`, which needs the inertias.

        Raises
        ------
        ModelError
            For scales without a pinion radius (a system: its loads are given in its file).
        """
        if self.R1_m is None:
            raise ModelError(f"torque: {self.title} has no single pinion torque; give the loads in its file")
        return _floats(torque) / self.R1_m / self.force_scale_N

    def torque_from_fp(self, fp: Any) -> Any:
        """Pinion torque T1 (N·m) giving f_p with balanced torques: T1 = f_p k0 b_c R1 (NaN without R1)."""
        if self.R1_m is None:
            return _floats(fp) * np.nan
        return _floats(fp) * self.force_scale_N * self.R1_m

    @staticmethod
    def dynamic_factor(max_force: Any, static_force: Any) -> Any:
        """The dynamic factor max F / F_static of a force over its static value (NaN where that is not > 0)."""
        f, s0 = _floats(max_force), _floats(static_force)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(s0 > 0, f / np.where(s0 > 0, s0, 1.0), np.nan)

    # ------------------------------------------------------------------ mesh coefficients
    def xi_from_c(self, c: Any) -> Any:
        """Damping ratio ξ = c/(2 m_e ω_n) from a damping coefficient (N·s/m)."""
        return _floats(c) / (2.0 * self.m_e_kg * self.omega_n_rad_s)

    def c_from_xi(self, xi: Any) -> Any:
        """Damping coefficient (N·s/m) from a damping ratio."""
        return _floats(xi) * 2.0 * self.m_e_kg * self.omega_n_rad_s

    def kappa_from_k(self, k: Any) -> Any:
        """Stiffness ratio κ = k/k0 from a stiffness (N/m)."""
        return _floats(k) / self.k0_N_per_m

    def k_from_kappa(self, kappa: Any) -> Any:
        """Stiffness (N/m) from a stiffness ratio."""
        return _floats(kappa) * self.k0_N_per_m

    # ------------------------------------------------------------------ a model's operating point
    def operating_point(self, model: Any) -> dict[str, float | None]:
        """Speed, frequencies, torque and static force of a System (JSON-ready).

        Parameters
        ----------
        model : System
            The non-dimensional system (its ``fp`` parameter, where it has one, and its
            :meth:`~geardyn.system.System.static_force`).

        Returns
        -------
        dict
            ``omega``, ``rpm`` (None without teeth), ``mesh_frequency_Hz``, ``natural_frequency_Hz``, ``fp``
            and ``torque_N_m`` (pinion, balanced; None for a system, which has no single one),
            ``static_force_N`` (the reference element's static force: F_p = f_p k0 b_c for the pair).
        """
        fp = model.parameters().get("fp")
        torque = None if fp is None else _number(self.torque_from_fp(fp))
        return {
            "omega": float(model.omega),
            "rpm": _number(self.rpm_from_omega(model.omega)),
            "mesh_frequency_Hz": float(self.hz_from_omega(model.omega)),
            "natural_frequency_Hz": self.natural_frequency_Hz,
            "fp": None if fp is None else float(fp),
            "torque_N_m": torque,
            "static_force_N": _number(self.N_from_force(model.static_force())),
        }


#: The name the pair's front end and the package's API give :class:`Scales`.
PhysicalScales = Scales
