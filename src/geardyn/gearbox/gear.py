"""Gears on shafts: tooth data, radii and the inertia of the blank.

A cylindrical gear (spur when β = 0) has ``teeth`` z, normal module m_n, normal pressure angle α_n, helix
angle β, face width b and profile shift x.  Its transverse module is m_t = m_n/cos β, the reference radius
r = z m_t/2, the transverse pressure angle α_t = atan(tan α_n/cos β) and the base radius r_b = r cos α_t.

Unless mass and inertias are given, the blank is a solid disk of the reference radius r and width b on a
bore of the shaft's outer diameter d_s at the gear (a standard approximation of a solid gear body):

    m = ρ π (r² − (d_s/2)²) b,    I_p = m (r² + (d_s/2)²)/2,    I_d = m ((r² + (d_s/2)²)/4 + b²/12),

the mass, polar and diametral moments of inertia.  A gear with a web and a rim gives ``web_width`` and
``rim_inner_diameter``: the rim (from that diameter to r, width b) and the web (from the bore to it, width
``web_width``) are added as two such disks.

A gear spinning at Ω about the shaft's axis (+z) is a rigid disc with the gyroscopic moment of its polar
inertia on its two tilts (:func:`disc_gyroscopic`): with the tilts rx, ry of a shaft node,

    I_d rx'' + Ω I_p ry' = M_x,    I_d ry'' − Ω I_p rx' = M_y,

the rate of change of the angular momentum I_p Ω (ry, −rx, 1) + I_d (rx', ry', 0) of the tilted disc
(Friswell et al. 2010, ch. 5: G = [[0, I_p], [−I_p, 0]] over the rotations (θ, ψ) about x and y).

References
----------
.. [1] M. I. Friswell, J. E. T. Penny, S. D. Garvey, A. W. Lees, *Dynamics of Rotating Machines*,
   Cambridge University Press, 2010, ch. 5 (the rigid disc and its gyroscopic matrix).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..validate import integer

__all__ = ["Gear", "disk", "disc_gyroscopic"]


def disk(rho: float, r_out: float, r_in: float, width: float) -> tuple[float, float, float]:
    """(mass, polar inertia, diametral inertia about its centre) of an annular disk.

    Parameters
    ----------
    rho : float
        Density (kg/m³).
    r_out, r_in : float
        Outer and inner radius (m).
    width : float
        Axial width (m).

    Returns
    -------
    tuple of float
        Mass (kg), polar and diametral moments of inertia (kg·m²).
    """
    m = rho * math.pi * (r_out**2 - r_in**2) * width
    ip = 0.5 * m * (r_out**2 + r_in**2)
    idia = m * ((r_out**2 + r_in**2) / 4.0 + width**2 / 12.0)
    return m, ip, idia


def disc_gyroscopic(polar_inertia: float) -> np.ndarray:
    """The gyroscopic matrix (6 × 6, per unit spin speed in rad/s about +z) of a rigid disc at a shaft node.

    Over the node's DOFs ``x, y, z, rx, ry, theta`` (:data:`geardyn.gearbox.shaft.NODE_DOFS`): ``G[rx, ry] = I_p``
    and ``G[ry, rx] = −I_p``, the rest 0 (see the module docstring); it enters ``M q'' + Ω G q' + K q = f``.

    Parameters
    ----------
    polar_inertia : float
        The disc's polar moment of inertia I_p (kg·m²).
    """
    G = np.zeros((6, 6))
    G[3, 4] = polar_inertia
    G[4, 3] = -polar_inertia
    return G


@dataclass(frozen=True)
class Gear:
    """A cylindrical gear on a shaft (SI units, angles in rad).

    Attributes
    ----------
    name : str
        Unique name of the gear.
    shaft : str
        Name of the shaft it is mounted on.
    position : float
        Position along the shaft from its start (m).
    teeth : int
        Number of teeth z (>= 1).
    module : float
        Normal module m_n (m, > 0).
    face_width : float
        Face width b (m, > 0).
    pressure_angle : float
        Normal pressure angle α_n (rad, in (0, 45) deg); default 20 deg.
    helix_angle : float
        Helix angle β (rad, in [0, 60) deg); 0 (default) is a spur gear.
    profile_shift : float
        Profile shift coefficient x (dimensionless); default 0.
    hand : str
        Hand of the helix, ``"right"`` (default) or ``"left"``.
    mass : float | None
        Mass (kg, > 0); from the blank when None.
    inertia : float | None
        Polar moment of inertia (kg·m², > 0); from the blank when None.
    diametral_inertia : float | None
        Diametral moment of inertia (kg·m², > 0); from the blank when None.
    web_width : float | None
        Width of the web (m) of a web-and-rim blank; given together with ``rim_inner_diameter``.
    rim_inner_diameter : float | None
        Inner diameter of the rim (m) of a web-and-rim blank, between the bore and the reference diameter.
    """

    name: str
    shaft: str
    position: float
    teeth: int
    module: float
    face_width: float
    pressure_angle: float = math.radians(20.0)
    helix_angle: float = 0.0
    profile_shift: float = 0.0
    hand: str = "right"
    mass: float | None = None
    inertia: float | None = None
    diametral_inertia: float | None = None
    web_width: float | None = None
    rim_inner_diameter: float | None = None

    def __post_init__(self) -> None:
        who = f"gear {self.name!r}"
        integer(f"{who}: teeth", self.teeth, 1)
        for key in ("module", "face_width"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0):
                raise ModelError(f"{who}: {key}: must be > 0 m, got {v!r}")
        if not 0 < self.pressure_angle < math.radians(45):
            raise ModelError(
                f"{who}: pressure_angle: must be in (0, 45) deg, got {math.degrees(self.pressure_angle):g} deg"
            )
        if not 0 <= self.helix_angle < math.radians(60):
            raise ModelError(f"{who}: helix_angle: must be in [0, 60) deg, got {math.degrees(self.helix_angle):g} deg")
        if self.hand not in ("right", "left"):
            raise ModelError(f"{who}: hand: must be 'right' or 'left', got {self.hand!r}")
        for key in ("mass", "inertia", "diametral_inertia"):
            v = getattr(self, key)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise ModelError(f"{who}: {key}: must be > 0, got {v!r}")

    @property
    def transverse_pressure_angle(self) -> float:
        return math.atan(math.tan(self.pressure_angle) / math.cos(self.helix_angle))

    @property
    def reference_radius(self) -> float:
        return self.teeth * self.module / (2.0 * math.cos(self.helix_angle))

    @property
    def base_radius(self) -> float:
        return self.reference_radius * math.cos(self.transverse_pressure_angle)

    def blank(self, rho: float, bore_diameter: float) -> tuple[float, float, float]:
        """(mass, polar inertia, diametral inertia) of the gear: given, or from the blank (module docstring)."""
        r, rb, b = self.reference_radius, bore_diameter / 2.0, self.face_width
        if rb >= r:
            raise ModelError(
                f"gear {self.name!r}: the shaft's diameter {bore_diameter * 1e3:g} mm is not inside the gear's "
                f"reference diameter {2 * r * 1e3:g} mm"
            )
        if self.rim_inner_diameter is not None or self.web_width is not None:
            if self.rim_inner_diameter is None or self.web_width is None:
                raise ModelError(f"gear {self.name!r}: a web and rim blank needs web_width and rim_inner_diameter")
            ri = self.rim_inner_diameter / 2.0
            if not rb < ri < r:
                raise ModelError(
                    f"gear {self.name!r}: rim_inner_diameter: must lie between the bore {2 * rb * 1e3:g} mm and "
                    f"the reference diameter {2 * r * 1e3:g} mm"
                )
            parts = [disk(rho, r, ri, b), disk(rho, ri, rb, self.web_width)]
            m, ip, idia = (sum(p[k] for p in parts) for k in range(3))
        else:
            m, ip, idia = disk(rho, r, rb, b)
        return (
            self.mass if self.mass is not None else m,
            self.inertia if self.inertia is not None else ip,
            self.diametral_inertia if self.diametral_inertia is not None else idia,
        )
