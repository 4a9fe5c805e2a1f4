"""Timoshenko beam finite elements for shafts: bending in two planes, torsion and axial motion.

A shaft lies along the global z axis.  Each node has six degrees of freedom, in this order::

    x, y, z, rx, ry, theta

the translations (m), the small rotations about the global x and y axes (rad, the section's tilt), and the
rotation about the shaft's own axis (rad, positive in the shaft's running direction).  Bending in the x–z
plane uses (x, ry) with ry the section rotation (≈ dx/dz); bending in the y–z plane uses (y, rx) with
rx ≈ −dy/dz.  An element of length L is uniform (outer diameter d_o, inner d_i) with

    A = π(d_o² − d_i²)/4,   I = π(d_o⁴ − d_i⁴)/64,   J = 2I,   Φ = 12 E I/(κ G A L²),

and the matrices of the Timoshenko element with shear deformation and rotary inertia (cubic
interpolation consistent with the static solution, Przemieniecki 1968; Friswell et al. 2010, §5.4):

    K_bending = E I/((1+Φ)L³) [[12, 6L, −12, 6L], [6L, (4+Φ)L², −6L, (2−Φ)L²], ...]
    M_translation = ρ A L/(840 (1+Φ)²) [[m1, m2, m3, m4], ...],   M_rotary = ρ I/(30 (1+Φ)² L) [[m7, m8, ...], ...]

torsion and axial motion with linear interpolation (stiffness G J/L and E A/L, consistent masses
ρ J L/6 [[2, 1], [1, 2]] and ρ A L/6 [[2, 1], [1, 2]]), and the gyroscopic matrix (spin Ω about +z)
``G = (J/I) (T_Aᵀ M_r T_B − T_Bᵀ M_r T_A)``, skew-symmetric, entering as ``M q'' + Ω G q' + K q``
(forward whirl stiffens).

The shear coefficient κ of a hollow circular section is Cowper's (1966),
``κ = 6(1+ν)(1+m²)² / ((7+6ν)(1+m²)² + (20+12ν) m²)`` with m = d_i/d_o (6(1+ν)/(7+6ν) for a solid one).

References
----------
.. [1] J. S. Przemieniecki, *Theory of Matrix Structural Analysis*, McGraw-Hill, 1968, §5.6.
.. [2] M. I. Friswell, J. E. T. Penny, S. D. Garvey, A. W. Lees, *Dynamics of Rotating Machines*,
   Cambridge University Press, 2010, §5.4 (the Timoshenko shaft element and its gyroscopic matrix).
.. [3] G. R. Cowper, "The shear coefficient in Timoshenko's beam theory", J. Appl. Mech. 33 (1966) 335–340.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = [
    "NODE_DOFS",
    "Material",
    "STEEL",
    "Section",
    "shear_coefficient",
    "element_matrices",
    "ShaftMesh",
    "shaft_matrices",
]

#: The six DOFs of a shaft node, in order.
NODE_DOFS = ("x", "y", "z", "rx", "ry", "theta")
_X, _Y, _Z, _RX, _RY, _T = range(6)


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material: Young's modulus E (Pa), Poisson's ratio ν, density ρ (kg/m³).

    Attributes
    ----------
    E : float
        Young's modulus (Pa, > 0); default 210 GPa.
    nu : float
        Poisson's ratio, in (−1, 0.5); default 0.3.
    rho : float
        Density (kg/m³, > 0); default 7850.
    """

    E: float = 2.1e11
    nu: float = 0.3
    rho: float = 7850.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.E) and self.E > 0):
            raise ModelError(f"material: E must be > 0 Pa, got {self.E!r}")
        if not (math.isfinite(self.nu) and -1.0 < self.nu < 0.5):
            raise ModelError(f"material: nu must be in (-1, 0.5), got {self.nu!r}")
        if not (math.isfinite(self.rho) and self.rho > 0):
            raise ModelError(f"material: rho must be > 0 kg/m^3, got {self.rho!r}")

    @property
    def G(self) -> float:
        """Shear modulus E/(2(1+ν)) (Pa)."""
        return self.E / (2.0 * (1.0 + self.nu))


#: Structural steel (E = 210 GPa, ν = 0.3, ρ = 7850 kg/m³), the default of a ``[[shaft]]``.
STEEL = Material()


def shear_coefficient(nu: float, outer: float, inner: float = 0.0) -> float:
    """Cowper's (1966) shear coefficient κ of a hollow circular section (see the module docstring).

    Parameters
    ----------
    nu : float
        Poisson's ratio ν.
    outer : float
        Outer diameter d_o (m, > 0).
    inner : float
        Inner diameter d_i (m, same unit as ``outer``); 0 (default) for a solid section.
    """
    m2 = (inner / outer) ** 2
    return 6.0 * (1.0 + nu) * (1.0 + m2) ** 2 / ((7.0 + 6.0 * nu) * (1.0 + m2) ** 2 + (20.0 + 12.0 * nu) * m2)


@dataclass(frozen=True)
class Section:
    """A uniform hollow circular section: outer and inner diameter (m).

    Attributes
    ----------
    outer : float
        Outer diameter d_o (m, > 0).
    inner : float
        Inner diameter d_i (m, >= 0 and < ``outer``); 0 (default) for a solid section.
    """

    outer: float
    inner: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.outer) and self.outer > 0):
            raise ModelError(f"outer diameter: must be > 0 m, got {self.outer!r}")
        if not (math.isfinite(self.inner) and 0 <= self.inner < self.outer):
            raise ModelError(
                f"inner diameter: must be >= 0 and < the outer diameter {self.outer:g} m, got {self.inner!r}"
            )

    @property
    def area(self) -> float:
        return math.pi * (self.outer**2 - self.inner**2) / 4.0

    @property
    def I(self) -> float:  # noqa: E743
        """Second moment of area about a diameter (m⁴)."""
        return math.pi * (self.outer**4 - self.inner**4) / 64.0

    @property
    def J(self) -> float:
        """Polar second moment of area (m⁴)."""
        return 2.0 * self.I


def _bending(E: float, G: float, rho: float, kappa: float, A: float, I: float, L: float):  # noqa: E741
    """(K, M_translation, M_rotary) 4×4 of one bending plane over (w1, ψ1, w2, ψ2), ψ ≈ dw/dz."""
    phi = 12.0 * E * I / (kappa * G * A * L**2)
    p1 = 1.0 + phi
    K = (E * I / (p1 * L**3)) * np.array(
        [
            [12.0, 6 * L, -12.0, 6 * L],
            [6 * L, (4 + phi) * L**2, -6 * L, (2 - phi) * L**2],
            [-12.0, -6 * L, 12.0, -6 * L],
            [6 * L, (2 - phi) * L**2, -6 * L, (4 + phi) * L**2],
        ]
    )
    m1 = 312 + 588 * phi + 280 * phi**2
    m2 = (44 + 77 * phi + 35 * phi**2) * L
    m3 = 108 + 252 * phi + 140 * phi**2
    m4 = -(26 + 63 * phi + 35 * phi**2) * L
    m5 = (8 + 14 * phi + 7 * phi**2) * L**2
    m6 = -(6 + 14 * phi + 7 * phi**2) * L**2
    Mt = (rho * A * L / (840.0 * p1**2)) * np.array(
        [[m1, m2, m3, m4], [m2, m5, -m4, m6], [m3, -m4, m1, -m2], [m4, m6, -m2, m5]]
    )
    m7 = 36.0
    m8 = (3 - 15 * phi) * L
    m9 = (4 + 5 * phi + 10 * phi**2) * L**2
    m10 = (-1 - 5 * phi + 5 * phi**2) * L**2
    Mr = (rho * I / (30.0 * p1**2 * L)) * np.array(
        [[m7, m8, -m7, m8], [m8, m9, -m8, m10], [-m7, -m8, m7, -m8], [m8, m10, -m8, m9]]
    )
    return K, Mt, Mr


def _plane_maps() -> tuple[np.ndarray, np.ndarray]:
    """T_A (x, ry) and T_B (y, −rx): the 4×12 maps from the element's DOFs to each plane's (w1, ψ1, w2, ψ2)."""
    TA = np.zeros((4, 12))
    TB = np.zeros((4, 12))
    for k, off in enumerate((0, 6)):
        TA[2 * k, off + _X] = 1.0
        TA[2 * k + 1, off + _RY] = 1.0
        TB[2 * k, off + _Y] = 1.0
        TB[2 * k + 1, off + _RX] = -1.0
    return TA, TB


_TA, _TB = _plane_maps()


def element_matrices(
    length: float, section: Section, material: Material = STEEL, *, shear: bool = True, rotary: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness, consistent mass and gyroscopic matrices (12 × 12) of one Timoshenko shaft element.

    Parameters
    ----------
    length : float
        Element length L (m), > 0.
    section : Section
        Its cross-section.
    material : Material
        Its material (default steel).
    shear, rotary : bool
        Shear deformation (Φ ≠ 0) and rotary inertia; both ``False`` gives the Euler–Bernoulli element.

    Returns
    -------
    K, M, G : ndarray (12, 12)
        Over the DOFs ``NODE_DOFS`` of node 1, then of node 2; ``G`` is the gyroscopic matrix per unit spin
        speed (rad/s) about +z.
    """
    if not (math.isfinite(length) and length > 0):
        raise ModelError(f"element length: must be > 0 m, got {length!r}")
    E, G, rho = material.E, material.G, material.rho
    A, I = section.area, section.I  # noqa: E741
    kappa = shear_coefficient(material.nu, section.outer, section.inner) if shear else math.inf
    Kb, Mt, Mr = _bending(E, G, rho, kappa, A, I, length)
    if not rotary:
        Mr = np.zeros_like(Mr)
    K = _TA.T @ Kb @ _TA + _TB.T @ Kb @ _TB
    M = _TA.T @ (Mt + Mr) @ _TA + _TB.T @ (Mt + Mr) @ _TB
    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    cons = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    for d, k, m in ((_Z, E * A / length, rho * A * length), (_T, G * section.J / length, rho * section.J * length)):
        ii = [d, 6 + d]
        K[np.ix_(ii, ii)] += k * bar
        M[np.ix_(ii, ii)] += m * cons
    Gy = (section.J / I) * (_TA.T @ Mr @ _TB - _TB.T @ Mr @ _TA)  # 0 without rotary inertia (Mr = 0)
    return K, M, Gy


@dataclass(frozen=True)
class ShaftMesh:
    """The finite-element mesh of a shaft: node positions along the axis and the elements' sections.

    Attributes
    ----------
    nodes : tuple[float, ...]
        Node positions along the shaft (m), increasing.
    sections : tuple[Section, ...]
        Section of each element (between node i and i+1).
    """

    #: Node positions along the shaft (m), increasing.
    nodes: tuple[float, ...]
    #: Section of each element (between node i and i+1).
    sections: tuple[Section, ...]


def shaft_matrices(mesh: ShaftMesh, material: Material = STEEL) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Assembled K, M, G (6N × 6N) of a shaft over its nodes' DOFs (node by node, ``NODE_DOFS`` each).

    Parameters
    ----------
    mesh : ShaftMesh
        Node positions (m) and the elements' sections.
    material : Material
        The shaft's material (default steel).
    """
    n = len(mesh.nodes)
    K = np.zeros((6 * n, 6 * n))
    M = np.zeros_like(K)
    Gy = np.zeros_like(K)
    for e, sec in enumerate(mesh.sections):
        L = mesh.nodes[e + 1] - mesh.nodes[e]
        sl = slice(6 * e, 6 * e + 12)
        for A, a in zip((K, M, Gy), element_matrices(L, sec, material)):
            A[sl, sl] += a
    return K, M, Gy
