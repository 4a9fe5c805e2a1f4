"""The spiral bevel gear pair: its inputs, pitch cones, directional radii, m_e, k0, F_p and model."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import cached_property

import numpy as np

from ..model import GearModel, ModelError
from .harmonics import MeshHarmonics
from .inputs import (
    _SOURCE_C_GAMMA,
    _SOURCE_FACE_WIDTH,
    _SOURCE_HAND,
    _SOURCE_K0,
    _SOURCE_R,
    _SOURCE_SIDE,
    _SOURCE_XI0,
    _UNITS,
    DEFAULT_C_GAMMA,
    DEFAULT_DRIVE_SIDE,
    DEFAULT_HAND,
    DEFAULT_XI0,
    FACE_WIDTH_TO_OUTER_CONE_DISTANCE,
    HANDS,
    SIDES,
    Assumption,
    ResolvedInputs,
    _angle,
    _finite,
    _positive,
)
from .scales import PhysicalScales
from .vectors import MeshVectors, mesh_vectors

__all__ = ["SpiralBevelGearPair"]


@dataclass(frozen=True)
class SpiralBevelGearPair:
    """A spiral bevel gear pair (all inputs in SI units: m, rad, kg·m², N/m, N/m²).

    Parameters
    ----------
    z1, z2 : int
        Numbers of teeth of the pinion (driver, 1) and the gear (driven, 2), >= 1.
    m_mn : float
        Mean normal module (m), > 0.
    beta_m : float
        Mean spiral angle β_m (rad), in [0°, 90°).
    alpha_n : float
        Normal pressure angle α_n (rad), in (0°, 90°).
    j_n : float
        Normal backlash (m), >= 0.  The half backlash b_n = j_n/2 is the dead zone of the mesh.
    I1, I2 : float
        Mass moments of inertia of pinion and gear about their axes (kg·m²), > 0.
    Sigma : float
        Shaft angle Σ (rad), in (0°, 180°); default 90°.
    r1, r2 : float, optional
        Distance from the mesh point to the pinion / gear axis (m).  Default: the mean pitch
        radius m_mn z_l/(2 cos β_m) (marked assumed).
    hand : {"left", "right"}, optional
        Hand of spiral of the pinion; the gear has the opposite hand.  Default ``"left"``
        (assumed).  Does not change the torsional model.
    drive_side : {"concave", "convex"}, optional
        Loaded flank of the pinion (the gear's loaded flank is the other one).  Default
        ``"concave"`` (assumed).  Changes the axial and radial force components only.
    face_width : float, optional
        Face width b (m).  Default 0.3 R_e (assumed).  Used only to estimate k0.
    c_gamma : float, optional
        Mean mesh stiffness per unit face width (N/m²; 20 N/(mm·µm) = 2e10 N/m²).  Default
        :data:`DEFAULT_C_GAMMA` (assumed).  Ignored when ``k0`` is given.
    k0 : float, optional
        Mean mesh stiffness along the line of action (N/m).  Default face_width × c_gamma.
    xi0 : float, optional
        Mean mesh damping ratio ξ0 = c0/(2 m_e ω_n) (non-dimensional, >= 0).
    c0 : float, optional
        Mean mesh damping coefficient (N·s/m, >= 0); give ``xi0`` or ``c0``, not both.  Default
        ξ0 = :data:`DEFAULT_XI0` (assumed).
    name : str
        A label for reports.
    assumed : sequence of (str, str)
        ``(parameter name, source)`` pairs for given values that are themselves assumptions
        (e.g. a face width chosen by the user); they appear in :attr:`assumed`.

    Examples
    --------
    >>> import math
    >>> from geardyn import SpiralBevelGearPair
    >>> pair = SpiralBevelGearPair(z1=23, z2=47, m_mn=7.28e-3, beta_m=math.radians(35), alpha_n=math.radians(20),
    ...                            j_n=0.1e-3, I1=1.772, I2=1.873, r1=0.1255, r2=0.256)
    >>> round(pair.mesh_frequency(3000) / (2 * math.pi), 6)  # ω_e = 2π z1 n1 / 60 (rad/s), in Hz
    1150.0
    """

    z1: int
    z2: int
    m_mn: float
    beta_m: float
    alpha_n: float
    j_n: float
    I1: float
    I2: float
    Sigma: float = math.pi / 2
    r1: float | None = None
    r2: float | None = None
    hand: str | None = None
    drive_side: str | None = None
    face_width: float | None = None
    c_gamma: float | None = None
    k0: float | None = None
    xi0: float | None = None
    c0: float | None = None
    name: str = ""
    assumed: tuple[tuple[str, str], ...] = field(default=())

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        for zname in ("z1", "z2"):
            z = getattr(self, zname)
            if isinstance(z, bool) or not isinstance(z, (int, np.integer, float)) or not float(z).is_integer() or z < 1:
                raise ModelError(f"{zname}: number of teeth must be an integer >= 1, got {z!r}")
            set_(self, zname, int(z))
        set_(self, "m_mn", _positive("m_mn", self.m_mn, "m"))
        set_(self, "beta_m", _angle("beta_m", self.beta_m, 0.0, 90.0, lo_closed=True))
        set_(self, "alpha_n", _angle("alpha_n", self.alpha_n, 0.0, 90.0))
        set_(self, "Sigma", _angle("Sigma", self.Sigma, 0.0, 180.0))
        jn = _finite("j_n", self.j_n, "m")
        if jn < 0:
            raise ModelError(f"j_n: normal backlash must be >= 0 m, got {jn:g} m")
        set_(self, "j_n", jn)
        for name in ("I1", "I2", "r1", "r2", "face_width", "c_gamma", "k0"):  # the inertias required, the rest optional
            if getattr(self, name) is not None or name[0] == "I":
                set_(self, name, _positive(name, getattr(self, name), _UNITS[name]))
        for name, unit in (("xi0", ""), ("c0", "N*s/m")):
            v = getattr(self, name)
            if v is not None:
                v = _finite(name, v, unit)
                if v < 0:
                    raise ModelError(f"{name}: mean mesh damping must be >= 0{(' ' + unit) if unit else ''}, got {v:g}")
                set_(self, name, v)
        if self.xi0 is not None and self.c0 is not None:
            raise ModelError("xi0/c0: give the mean mesh damping as a ratio (xi0) or a coefficient (c0), not both")
        if self.hand is not None and self.hand not in HANDS:
            raise ModelError(f"hand: must be one of {', '.join(HANDS)} (pinion hand of spiral), got {self.hand!r}")
        if self.drive_side is not None and self.drive_side not in SIDES:
            raise ModelError(
                f"drive_side: must be one of {', '.join(SIDES)} (loaded pinion flank), got {self.drive_side!r}"
            )
        from ..plausible import pair_geometry

        checked = ("z1", "z2", "m_mn", "beta_m", "alpha_n", "j_n", "r1", "r2", "face_width", "delta1")
        pair_geometry(**{n: getattr(self, n) for n in checked})
        assumed = tuple((str(n), str(s)) for n, s in (self.assumed or ()))
        known = {f.name for f in fields(self)} - {"name", "assumed"}
        for n, _ in assumed:
            if n not in known:
                raise ModelError(f"assumed: unknown parameter {n!r}; allowed: {', '.join(sorted(known))}")
        set_(self, "assumed", assumed)

    # ------------------------------------------------------------------ pitch cones
    @property
    def ratio(self) -> float:
        """Gear ratio z2/z1 (non-dimensional)."""
        return self.z2 / self.z1

    @property
    def delta1(self) -> float:
        """Pinion pitch cone angle δ1 (rad): tan δ1 = sin Σ / (z2/z1 + cos Σ)."""
        return math.atan2(math.sin(self.Sigma), self.ratio + math.cos(self.Sigma))

    @property
    def delta2(self) -> float:
        """Gear pitch cone angle δ2 = Σ − δ1 (rad)."""
        return self.Sigma - self.delta1

    @property
    def b_n(self) -> float:
        """Half normal backlash b_n = j_n/2 (m)."""
        return 0.5 * self.j_n

    # ------------------------------------------------------------------ defaults applied
    @cached_property
    def resolved(self) -> ResolvedInputs:
        """Every optional input with its default applied, and the list of assumed values."""
        assumed: list[Assumption] = []
        declared = dict(self.assumed)

        def note(name: str, value: float | str, unit: str, default_source: str | None) -> None:
            if name in declared:
                assumed.append(Assumption(name, value, unit, declared[name]))
            elif default_source is not None:
                assumed.append(Assumption(name, value, unit, default_source))

        def pick(name: str, default: float | str, unit: str, source: str | None) -> float | str:
            """The input ``name``, else ``default`` (noted as assumed, from ``source`` when one is given)."""
            given = getattr(self, name)
            note(name, default if given is None else given, unit, None if given is not None else source)
            return default if given is None else given

        r_pitch = [self.m_mn * z / (2.0 * math.cos(self.beta_m)) for z in (self.z1, self.z2)]
        r1 = pick("r1", r_pitch[0], "m", _SOURCE_R)
        r2 = pick("r2", r_pitch[1], "m", _SOURCE_R)
        hand = pick("hand", DEFAULT_HAND, "", _SOURCE_HAND)
        side = pick("drive_side", DEFAULT_DRIVE_SIDE, "", _SOURCE_SIDE)
        f = FACE_WIDTH_TO_OUTER_CONE_DISTANCE  # b = f R_e, R_e = R_m + b/2, R_m = r1/sin δ1
        src_b = _SOURCE_FACE_WIDTH if self.k0 is None else None  # with k0 given, b only places the force components
        b = pick("face_width", f * (r1 / math.sin(self.delta1)) / (1.0 - 0.5 * f), "m", src_b)
        if self.k0 is not None:
            k0 = self.k0
            c_gamma = float("nan")
            note("k0", k0, "N/m", None)
            if self.c_gamma is not None:
                note("c_gamma", self.c_gamma, "N/m^2", None)
        else:
            c_gamma = pick("c_gamma", DEFAULT_C_GAMMA, "N/m^2", _SOURCE_C_GAMMA)
            k0 = b * c_gamma
            assumed.append(Assumption("k0", k0, "N/m", _SOURCE_K0))
        if self.c0 is not None:
            lam = math.cos(self.alpha_n) * math.cos(self.beta_m)
            m_e = self._m_e_from(lam * r1, lam * r2)
            xi0 = self.c0 / (2.0 * m_e * math.sqrt(k0 / m_e))
            note("c0", self.c0, "N*s/m", None)
        else:
            xi0 = pick("xi0", DEFAULT_XI0, "", _SOURCE_XI0)
        # values declared assumed that no branch above covered (e.g. z1 or I1)
        covered = {a.name for a in assumed}
        for n, src in self.assumed:
            if n not in covered:
                v = getattr(self, n)
                assumed.append(Assumption(n, v if v is not None else "", _UNITS.get(n, ""), src))
        return ResolvedInputs(r1, r2, hand, side, b, c_gamma, k0, xi0, tuple(assumed))

    @property
    def assumptions(self) -> tuple[Assumption, ...]:
        """Every value not given (defaulted) or declared assumed, with its source."""
        return self.resolved.assumed

    # ------------------------------------------------------------------ vectors
    def mesh_vectors(self) -> MeshVectors:
        """Mesh-point vectors r_l, j_l, n_l of this pair (see :func:`geardyn.geometry.vectors.mesh_vectors`).

        Returns
        -------
        MeshVectors
            Built from (α_n, β_m, δ_l, Σ) and the resolved r_l, hand of spiral and drive side.
        """
        rv = self.resolved
        return mesh_vectors(
            alpha_n=self.alpha_n,
            beta_m=self.beta_m,
            Sigma=self.Sigma,
            delta1=self.delta1,
            delta2=self.delta2,
            r1=rv.r1,
            r2=rv.r2,
            hand=rv.hand,
            drive_side=rv.drive_side,
        )

    def rotation_sense(self) -> tuple[str, str]:
        """Running sense of (pinion, gear), each viewed from its back looking towards the apex."""
        return self.mesh_vectors().rotation_sense()

    # ------------------------------------------------------------------ torsional model
    @cached_property
    def _R(self) -> tuple[float, float]:
        mv = self.mesh_vectors()
        return mv.R1, mv.R2

    @property
    def R1(self) -> float:
        """Directional radius of the pinion R1 = n·(j1 × r1) (m); equals r1 cos α_n cos β_m."""
        return self._R[0]

    @property
    def R2(self) -> float:
        """Directional radius of the gear R2 = n·(j2 × r2) (m); equals r2 cos α_n cos β_m."""
        return self._R[1]

    def _m_e_from(self, R1: float, R2: float) -> float:
        return self.I1 * self.I2 / (self.I2 * R1**2 + self.I1 * R2**2)

    @property
    def m_e(self) -> float:
        """Equivalent mass m_e = I1 I2 / (I2 R1² + I1 R2²) (kg)."""
        return self._m_e_from(*self._R)

    @property
    def k0_mean(self) -> float:
        """Mean mesh stiffness k0 along the line of action (N/m), given or face width × c_γ."""
        return self.resolved.k0

    @property
    def omega_n(self) -> float:
        """Natural frequency of the mesh ω_n = √(k0/m_e) (rad/s)."""
        return math.sqrt(self.k0_mean / self.m_e)

    @property
    def c0_mean(self) -> float:
        """Mean mesh damping coefficient c0 = 2 ξ0 m_e ω_n (N·s/m)."""
        return self.c0 if self.c0 is not None else 2.0 * self.resolved.xi0 * self.m_e * self.omega_n

    @property
    def xi0_mean(self) -> float:
        """Mean mesh damping ratio ξ0 (non-dimensional)."""
        return self.resolved.xi0

    def balanced_torque2(self, T1: float) -> float:
        """Gear (output) torque T2 = T1 R2/R1 that balances the pinion torque T1 in steady state (N·m)."""
        return T1 * self.R2 / self.R1

    def static_force(self, T1: float, T2: float | None = None) -> float:
        """Mean mesh force F_p = (I2 R1 T1 + I1 R2 T2)/(I2 R1² + I1 R2²) (N).

        Parameters
        ----------
        T1 : float
            Pinion (input) torque (N·m).
        T2 : float, optional
            Gear (output, load) torque (N·m); default the balanced value T1 R2/R1, for which
            F_p = T1/R1.
        """
        T1 = _finite("torque", T1, "N*m")
        T2 = self.balanced_torque2(T1) if T2 is None else _finite("torque2", T2, "N*m")
        R1, R2 = self._R
        return (self.I2 * R1 * T1 + self.I1 * R2 * T2) / (self.I2 * R1**2 + self.I1 * R2**2)

    def mesh_frequency(self, rpm: float) -> float:
        """Mesh (tooth-passing) angular frequency ω_e = 2π z1 n1/60 (rad/s) for pinion speed n1 (rpm)."""
        return 2.0 * math.pi * self.z1 * _positive("rpm", rpm, "rpm") / 60.0

    def scales(self, b_c: float | None = None) -> PhysicalScales:
        """Scales between physical and non-dimensional quantities.

        Parameters
        ----------
        b_c : float, optional
            Characteristic length (m); default b_n = j_n/2 (then D = 1).  The paper's Table 3
            reading of backlash uses b_c = 1 mm (D = j_n/(2·1 mm)).

        Returns
        -------
        PhysicalScales
            With the pair's name as title and its assumed inputs.

        Raises
        ------
        ModelError
            If ``b_c`` is not a positive length, or is not given and the backlash j_n is 0.
        """
        if b_c is None:
            if self.b_n <= 0:
                raise ModelError("b_c: the backlash j_n is 0, so a characteristic length b_c > 0 must be given")
            b_c = self.b_n
        return PhysicalScales.from_pair(self, _positive("b_c", b_c, "m"))

    def fp_from_torques(self, T1: float, T2: float | None = None, b_c: float | None = None) -> float:
        """Non-dimensional load f_p = F_p/(k0 b_c) with the static force F_p of :meth:`static_force`.

        Parameters
        ----------
        T1 : float
            Pinion torque (N·m).
        T2 : float, optional
            Gear torque (N·m); default balanced, T1 R2/R1.
        b_c : float, optional
            Characteristic length (m); default b_n.

        Returns
        -------
        float
            f_p.  With balanced torques it equals :meth:`PhysicalScales.fp_from_torque` up to rounding.
        """
        sc = self.scales(b_c)
        return float(sc.force_from_N(self.static_force(T1, T2)))

    def gear_model(
        self,
        rpm: float,
        torque: float,
        *,
        torque2: float | None = None,
        mesh: MeshHarmonics | None = None,
        b_c: float | None = None,
    ) -> GearModel:
        """Non-dimensional model at an operating point.

        Parameters
        ----------
        rpm : float
            Pinion speed n1 (rpm), > 0.
        torque : float
            Pinion torque T1 (N·m).
        torque2 : float, optional
            Gear torque T2 (N·m); default balanced, T1 R2/R1.
        mesh : MeshHarmonics, optional
            Harmonics of damping, stiffness and STE; default none (constant coefficients).
        b_c : float, optional
            Characteristic length (m); default b_n.

        Returns
        -------
        GearModel
            With ω = ω_e/ω_n, ξ0, f_p = F_p/(k0 b_c), D = b_n/b_c and the harmonics made
            non-dimensional (ξ_k = c_k/(2 m_e ω_n), κ_r = k_r/k0, ε_l = e_l/b_c).
        """
        sc = self.scales(b_c)
        harmonics = (mesh or MeshHarmonics()).nondimensional(self.m_e, self.omega_n, self.k0_mean, sc.b_c_m)
        return GearModel(
            omega=sc.omega_from_rpm(rpm),
            xi0=self.xi0_mean,
            fp=self.fp_from_torques(torque, torque2, sc.b_c_m),
            D=self.b_n / sc.b_c_m,
            **harmonics,
        )
