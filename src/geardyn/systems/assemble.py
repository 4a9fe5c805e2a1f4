"""The assembled, non-dimensional multi-DOF system and its kernel arrays.

Physical model (SI, :class:`~geardyn.systems.description.SystemDescription`)::

    M q'' + C_b q' + K_b q + Σ_m v_m [c_m(t) δ_m' + k_m(t) f(δ_m; b_m)]
                           + Σ_c w_c [c_c δ_c' + k_c f(δ_c; g_c)] = F,
    δ_m = v_mᵀ q − e_m(t)    (mesh deflection, STE included),     δ_c = w_cᵀ q   (clearance element),

with the dead zone ``f(δ; b) = δ − b (δ > b), 0 (|δ| <= b), δ + b (δ < −b)``.

Scales (one reference mesh, default the first): ``m_ref = 1/(v_refᵀ M⁻¹ v_ref)`` (by default with only
the rotation entries of v_ref: the torsional m_e, see ``SystemDescription.equivalent_mass``), ``k_ref`` its mean
stiffness, ``ω_n = √(k_ref/m_ref)``, ``b_c`` (default half its backlash), ``τ = ω_n t``,
``θ = ω τ`` with ``ω = ω_e/ω_n`` the base frequency, mesh m running at ``θ_m = r_m θ``.
Coordinates ``q = S q̃`` with ``S = diag(s_i)``: ``s_i = b_c`` on a translation and ``s_i = b_c/ρ_i`` on a
rotation, ρ_i the largest |v_m,i| of the meshes on that DOF (a directional radius; 1 m if none), so
that a two-gear torsional pair has ``Ṽ = (1, −1)`` and ``u = q̃1 − q̃2`` is the 1-DOF coordinate.
Multiplying by ``S/(k_ref b_c²)`` gives the non-dimensional system the kernel integrates::

    q̃'' = Mi [ F − Cb q̃' − Kb q̃ − Σ_m V[m] (C_m(θ) δ_m' + K_m(θ) f(δ_m; D[m]))
                                   − Σ_c Vc[c] (cc[c] δ_c' + kc[c] f(δ_c; Dc[c])) ]
    δ_m  = V[m]·q̃ − E_m(θ),        δ_m' = V[m]·q̃' − ω E_m'(θ)      (E_m' = dE_m/dθ)
    δ_c  = Vc[c]·q̃,                δ_c' = Vc[c]·q̃'

and the reference mesh, alone between two rotating bodies, is exactly ``geardyn.model.GearModel``:
``C = 2ξ(θ)``, ``K = 1 + Σκ cos``, the relative coordinate's forcing ``−E'' = ω² Σ l² ε_l cos(lθ + φ)``
and ``V Mi F = f_p`` (``V Mi Vᵀ = 1`` for a reference mesh between rotations only).

Array contract (:meth:`SystemModel.arrays`, one system; :meth:`SystemModel.pack` stacks a batch of
systems of one structure along a new leading axis P), all C-contiguous float64:

========  ====================  ===========================================================
name      shape                 meaning
========  ====================  ===========================================================
Mi        (n, n)                M̃⁻¹, symmetric positive definite
Kb        (n, n)                K̃_b, linear connections (symmetric)
Cb        (n, n)                C̃_b, linear connections (symmetric), plus ω G̃ with gyroscopic terms
V         (meshes, n)           mesh vectors Ṽ_m (rows)
coef      (meshes, 3, H+1, 2)   X_m(θ) = Σ_j coef[m,i,j,0] cos(j r_m θ) + coef[m,i,j,1] sin(j r_m θ)
                                for i = 0: C_m (the full damping coefficient, 2ξ for the
                                reference mesh), i = 1: K_m (stiffness, mean k_m0/k_ref),
                                i = 2: E_m (STE displacement / b_c, mean 0).  Note: slot 2 is
                                the STE itself, not the 1-DOF model's forcing f_p + ω² Σ l² ε cos.
D         (meshes,)             half backlash / b_c
ratio     (meshes,)             r_m, mesh frequency / base frequency
F         (n,)                  mean loads F̃ = S F/(k_ref b_c²): forces/(k_ref b_c),
                                torques/(ρ_i k_ref b_c)
Vc        (clearances, n)       clearance vectors (rows), scaled like V
kc, cc    (clearances,)         clearance stiffness and damping (non-dimensional)
Dc        (clearances,)         half gaps / b_c (SI magnitudes: f is homogeneous)
omega     ()                    base frequency ω; the stroboscopic section is θ ≡ 0 mod 2π
Fo        (orders, n)           torque orders' load amplitudes, scaled like F: the load is
                                F + Σ_o Fo[o] cos(ro[o] θ + po[o])
ro, po    (orders,)             the orders' frequencies over ω and phases (rad)
Vb        (2·bearings, n)       rolling bearings' x and y vectors (rows 2b, 2b+1), scaled like V
bq        (bearings, 8)         their parameters: Z, K̃, n, c̃, cx̃, cỹ, cage radians per radian of θ,
                                cage phase (:mod:`geardyn._kernel_ndof.core`, ``BQ_Z`` …)
========  ====================  ===========================================================

Rolling bearings (:mod:`geardyn.systems.rolling`) are the second element law: bearing b is the elements
``<name>.x`` and ``<name>.y`` after the meshes and clearances, with force
``K̃ Σ_j max(δ_j, 0)^n (cos ψ_j, sin ψ_j) + (cx̃ δ_x', cỹ δ_y')`` (δ_j = δ_x cos ψ_j + δ_y sin ψ_j − c̃).

The state is ``x = (q̃, q̃')`` (length 2n).  With several meshes the forcing is periodic in the base
period T = 2π/ω only if every r_m is an integer; :meth:`SystemModel.period_multiple` gives the
smallest p with p·r_m integer for all m (the forcing period is p·T), or ``None`` when the ratios
are incommensurate.

Gyroscopic terms (a gearbox with ``[gearbox] gyroscopic = true``): the description's
``gyroscopic_matrix()`` G (SI, per rad/s of the reference shaft, each shaft at its exact speed ratio) adds
``Ω G`` to the damping, Ω = ω_e/z the reference shaft's speed (z the reference mesh's pinion teeth), so
``Cb = C̃_b + ω G̃`` with ``G̃ = S G S ω_n²/(z k_ref b_c²)`` (skew-symmetric, :attr:`SystemModel.gyro`); a change
of ω (:meth:`SystemModel.with_param`) moves that term with it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Any, NamedTuple

import numpy as np

from .._docfill import attributes
from ..errors import ModelError
from ..geometry.scales import Scales
from ..model import Boundary, series_change
from ..params import MAX_HARMONICS, canonical_param, slot
from ..system import Element
from . import elements as _el
from .balance import check_balance
from .description import Mesh, SystemDescription, check_kappa
from .rolling import BearingND

__all__ = ["MeshND", "SystemArrays", "SystemModel", "assemble"]

#: Largest denominator tried when reading a mesh-frequency ratio as a fraction.
MAX_RATIO_DENOMINATOR = 1000
#: Relative tolerance for a ratio to count as that fraction.
RATIO_RTOL = 1e-12


@dataclass(frozen=True)
@attributes
class MeshND:
    """One mesh in the non-dimensional system."""

    #: Mesh name.
    name: str
    #: Mean stiffness k_m0/k_ref.
    k: float
    #: Mean damping c_m0/(2 m_ref ω_n) (the 1-DOF model's ξ0 for the reference mesh).
    xi0: float
    #: Harmonics: damping c_k/(2 m_ref ω_n), stiffness κ_r (relative to the mesh's own k0),
    #: STE ε_l = e_l/b_c, and their phases (rad).
    xi: tuple[float, ...]
    phi_c: tuple[float, ...]
    kappa: tuple[float, ...]
    phi_k: tuple[float, ...]
    eps: tuple[float, ...]
    phi_e: tuple[float, ...]
    #: Half backlash / b_c.
    D: float
    #: Frequency of the series' fundamental / base frequency (the mesh's ratio / its cycles P).
    ratio: float
    #: P, the mesh cycles of the series' period (:attr:`~geardyn.systems.description.Mesh.cycles`).
    cycles: int = 1

    def __post_init__(self) -> None:
        who = f"{self.name}"
        for amp, ph in (("xi", "phi_c"), ("kappa", "phi_k"), ("eps", "phi_e")):
            a, p = tuple(map(float, getattr(self, amp))), tuple(map(float, getattr(self, ph)))
            if len(a) > MAX_HARMONICS * self.cycles:
                raise ModelError(f"{who}.{amp}: at most {MAX_HARMONICS * self.cycles} harmonics")
            if len(p) > len(a):
                raise ModelError(f"{who}.{ph}: {len(p)} phases for {len(a)} harmonics")
            object.__setattr__(self, amp, a)
            object.__setattr__(self, ph, p + (0.0,) * (len(a) - len(p)))
        for name in ("k", "xi0", "D", "ratio"):
            x = float(getattr(self, name))
            if not math.isfinite(x):
                raise ModelError(f"{who}.{name}: must be finite, got {x!r}")
            object.__setattr__(self, name, x)
        if self.k <= 0 or self.ratio <= 0:
            raise ModelError(f"{who}: stiffness and ratio must be > 0")
        if self.D < 0:
            raise ModelError(f"{who}.D: must be >= 0, got {self.D!r}")
        check_kappa(f"{who}.kappa", self.kappa, self.phi_k, self.cycles)

    @property
    def n_harmonics(self) -> int:
        return max(len(self.xi), len(self.kappa), len(self.eps), 0)

    def coefficients(self, n_harmonics: int | None = None) -> np.ndarray:
        """(3, H+1, 2): damping C, stiffness K, STE E in the harmonics of θ_m (see the module docstring)."""
        H = self.n_harmonics if n_harmonics is None else n_harmonics
        c = np.zeros((3, H + 1, 2))
        c[0, 0, 0] = 2.0 * self.xi0
        c[1, 0, 0] = self.k
        for i, amps, phases, scale in (
            (0, self.xi, self.phi_c, 2.0),
            (1, self.kappa, self.phi_k, self.k),
            (2, self.eps, self.phi_e, 1.0),
        ):
            for j0, (a, ph) in enumerate(zip(amps, phases)):
                c[i, j0 + 1, 0] = scale * a * math.cos(ph)
                c[i, j0 + 1, 1] = -scale * a * math.sin(ph)
        return c


class SystemArrays(NamedTuple):
    """Kernel arrays of one system (or, from :meth:`SystemModel.pack`, a batch with a leading P axis).

    Shapes and meanings are the array contract of the module docstring (one system; a batch adds
    the leading axis P).

    Attributes
    ----------
    Mi : ndarray (n, n)
        M̃⁻¹.
    Kb, Cb : ndarray (n, n)
        Stiffness and damping of the linear connections.
    V : ndarray (meshes, n)
        Mesh vectors.
    coef : ndarray (meshes, 3, H+1, 2)
        Fourier coefficients of C_m, K_m and E_m.
    D : ndarray (meshes,)
        Half backlash / b_c.
    ratio : ndarray (meshes,)
        Mesh frequency / base frequency.
    F : ndarray (n,)
        Mean loads.
    Vc : ndarray (clearances, n)
        Clearance vectors.
    kc, cc : ndarray (clearances,)
        Clearance stiffness and damping.
    Dc : ndarray (clearances,)
        Half gaps / b_c.
    omega : ndarray ()
        Base frequency ω.
    Fo : ndarray (orders, n)
        Torque orders' load amplitudes (scaled like F).
    ro, po : ndarray (orders,)
        Their frequencies over ω and phases (rad).
    Vb : ndarray (2·bearings, n)
        Rolling bearings' x and y vectors.
    bq : ndarray (bearings, 8)
        Rolling bearings' kernel parameters (:meth:`~geardyn.systems.rolling.BearingND.row`).
    """

    Mi: np.ndarray
    Kb: np.ndarray
    Cb: np.ndarray
    V: np.ndarray
    coef: np.ndarray
    D: np.ndarray
    ratio: np.ndarray
    F: np.ndarray
    Vc: np.ndarray
    kc: np.ndarray
    cc: np.ndarray
    Dc: np.ndarray
    omega: np.ndarray
    Fo: np.ndarray
    ro: np.ndarray
    po: np.ndarray
    Vb: np.ndarray
    bq: np.ndarray


def _ro(a) -> np.ndarray:
    a = np.array(a, dtype=np.float64, order="C")
    a.setflags(write=False)
    return a


_MESH_PARAMS = ("k", "xi0", "D", "ratio")
#: What :meth:`SystemModel.to_attrs` always stores, in this order.
_ATTRS = ("labels", "Mi", "Kb", "Cb", "V", "meshes", "F", "omega", "scaling", "clearance_names", "Vc", "kc", "cc", "Dc")
#: A rolling bearing's parameters by name (``<bearing>.clearance`` …; non-dimensional, :class:`BearingND`).
_BEARING_PARAMS = ("clearance", "K", "cx", "cy")


@dataclass(frozen=True, eq=False)
class SystemModel:
    """A frozen non-dimensional multi-DOF system (implements :class:`geardyn.system.System`).

    Build it with :func:`assemble` (or :func:`geardyn.systems.load_system`).  Parameters by name:
    ``omega``; per mesh ``<mesh>.<p>`` with p one of ``k``, ``xi0``, ``xiK``, ``kappaK``, ``epsK``,
    ``phi_cK``, ``phi_kK``, ``phi_eK``, ``D`` (alias ``backlash``, ``fe`` = ``eps1``), ``ratio``; per
    clearance ``<name>.D``; per rolling bearing ``<bearing>.clearance`` (c̃), ``.K`` (K̃), ``.cx``, ``.cy``.  An
    unqualified mesh parameter (``kappa1``) means the reference mesh's.

    Attributes
    ----------
    labels : tuple of str
        DOF names (``<body>.<dof>``), n of them.
    Mi, Kb, Cb : ndarray (n, n)
        M̃⁻¹ and the linear connections' stiffness and damping (non-dimensional, read-only).
    V : ndarray (meshes, n)
        Mesh vectors (rows).
    meshes : tuple of MeshND
        The meshes with their non-dimensional coefficients (the reference mesh among them).
    F : ndarray (n,)
        Mean loads.
    omega : float
        Base frequency ω = ω_e/ω_n (> 0).
    scaling : Scales
        The scales linking to SI units: those of the reference mesh (k0, m_e, ω_n, b_c, its pinion's teeth),
        and the scale of every DOF (:class:`~geardyn.geometry.scales.Scales`, the pair's kind of scales).
    clearance_names : tuple of str
        Names of the clearance elements.
    Vc : ndarray (clearances, n)
        Clearance vectors (rows).
    kc, cc, Dc : tuple of float
        Clearance stiffness, damping and half gaps (non-dimensional).
    description : SystemDescription or None
        The physical description it was assembled from.
    gyro : ndarray (n, n) or None
        G̃, the gyroscopic matrix per unit ω (skew-symmetric; see the module docstring): ``Cb`` is
        ``damping_static + omega * gyro``; None (default) without gyroscopic terms.
    damping_static : ndarray (n, n) or None
        C̃_b without the gyroscopic term (given with ``gyro``).
    orders : tuple of (Fraction, ndarray (n,), float)
        Torque orders of the loads: frequency r over the base frequency ω, the load vector's amplitude (scaled
        like ``F``) and the phase (rad); the forcing adds Σ F̃_o cos(r_o θ + φ_o).  The forcing period counts
        their denominators (:meth:`period_multiple`).  The kernel evaluates the load at every RK4 stage's time.
    bearings : tuple of BearingND
        Rolling-element bearings (:mod:`geardyn.systems.rolling`); their ball-pass ratios count in the forcing
        period like the meshes' ratios.
    Vb : ndarray (2·bearings, n)
        Their x and y vectors (rows 2b, 2b+1).

    Raises
    ------
    ModelError
        If an array has the wrong shape, ω is not positive, or a clearance gap is negative.

    Examples
    --------
    >>> from geardyn import SystemModel, load_system
    >>> system = load_system("examples/systems/paper_torsional.toml")
    >>> isinstance(system, SystemModel), system.labels
    (True, ('pinion.theta', 'gear.theta'))
    >>> round(system.omega, 6), system.with_param("omega", 0.8).omega
    (1.002046, 0.8)
    """

    labels: tuple[str, ...]
    Mi: np.ndarray
    Kb: np.ndarray
    Cb: np.ndarray
    V: np.ndarray
    meshes: tuple[MeshND, ...]
    F: np.ndarray
    omega: float
    scaling: Scales
    clearance_names: tuple[str, ...] = ()
    Vc: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    kc: tuple[float, ...] = ()
    cc: tuple[float, ...] = ()
    Dc: tuple[float, ...] = ()
    description: SystemDescription | None = None
    orders: tuple = ()
    bearings: tuple[BearingND, ...] = ()
    Vb: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    gyro: np.ndarray | None = None
    damping_static: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.labels)

        def shaped(name: str, shape: tuple) -> None:
            a = _ro(getattr(self, name))
            if a.shape != shape:
                raise ModelError(f"{name}: expected shape {shape}, got {a.shape}")
            object.__setattr__(self, name, a)

        for name, shape in (("Mi", (n, n)), ("Kb", (n, n)), ("Cb", (n, n)), ("V", (len(self.meshes), n)), ("F", (n,))):
            shaped(name, shape)
        nc = len(self.clearance_names)
        object.__setattr__(self, "Vc", _ro(np.reshape(self.Vc, (nc, n))))
        object.__setattr__(self, "bearings", tuple(self.bearings))
        object.__setattr__(self, "Vb", _ro(np.reshape(self.Vb, (2 * len(self.bearings), n))))
        for name in ("kc", "cc", "Dc"):
            v = tuple(map(float, getattr(self, name)))
            if len(v) != nc:
                raise ModelError(f"{name}: expected {nc} values, got {len(v)}")
            object.__setattr__(self, name, v)
        om = float(self.omega)
        if not (math.isfinite(om) and om > 0 and math.isfinite(2 * math.pi / om)):
            raise ModelError(f"omega: must be > 0 (base frequency ω_e/ω_n), got {self.omega!r}")
        object.__setattr__(self, "omega", om)
        if any(d < 0 for d in self.Dc):
            raise ModelError("clearance D: must be >= 0")
        if (self.gyro is None) != (self.damping_static is None):
            raise ModelError("gyro: give it together with damping_static (the damping without it)")
        for name in ("gyro", "damping_static"):
            if getattr(self, name) is not None:
                shaped(name, (n, n))

    # ------------------------------------------------------------------ the system protocol
    @property
    def n(self) -> int:
        """Number of degrees of freedom."""
        return len(self.labels)

    @property
    def state_dim(self) -> int:  # type: ignore[override]
        """2n: the state is (q̃, q̃')."""
        return 2 * self.n

    @property
    def period(self) -> float:
        """Base period T = 2π/ω (the stroboscopic sampling time); see :meth:`period_multiple`."""
        return 2.0 * math.pi / self.omega

    def period_multiple(self) -> int | None:
        """Smallest p >= 1 with p·r_m an integer for every mesh (forcing period p·T), or ``None``.

        ``None`` means the mesh frequencies are incommensurate (no ratio is a fraction with a
        denominator up to :data:`MAX_RATIO_DENOMINATOR`): the forcing is quasi-periodic, and the
        periodic tools (shooting, continuation) cannot be used.
        """
        p = 1
        for m in (*self.meshes, *self.bearings):  # a bearing's ratio: its ball-pass frequency
            f = Fraction(m.ratio).limit_denominator(MAX_RATIO_DENOMINATOR)
            if abs(float(f) - m.ratio) > RATIO_RTOL * m.ratio:
                return None
            p = math.lcm(p, f.denominator)
        return math.lcm(p, *(r.denominator for r, _, _ in self.orders))

    @property
    def forcing_period(self) -> float:
        """The forcing period p·T; raises :class:`ModelError` for incommensurate mesh frequencies."""
        p = self.period_multiple()
        if p is None:
            ratios = ", ".join(f"{m.name}: {m.ratio:.12g}" for m in self.meshes)
            raise ModelError(f"the mesh frequencies are incommensurate (ratios {ratios}): the forcing is not periodic")
        return p * self.period

    def mesh(self, name: str) -> MeshND:
        for m in self.meshes:
            if m.name == name:
                return m
        raise ModelError(f"unknown mesh {name!r}; meshes: {', '.join(m.name for m in self.meshes)}")

    def _where(self, name: str) -> tuple[Any, str, int | None]:
        """Where parameter ``name`` is held: the object (this system for ω and the clearances' gaps, else a mesh or
        a rolling bearing), its attribute and the index in that series (None for a single value); an unqualified
        mesh parameter is the reference mesh's."""
        if name == "omega":
            return self, "omega", None
        if not isinstance(name, str):
            raise ModelError(f"unknown parameter {name!r}")
        elem, p = name.rsplit(".", 1) if "." in name else (self.scaling.reference, name)
        if elem in self.clearance_names:
            if p != "D":
                raise ModelError(f"{name}: a clearance has only the parameter D")
            return self, "Dc", self.clearance_names.index(elem)
        b = next((x for x in self.bearings if x.name == elem), None)
        if b is not None:
            if p not in _BEARING_PARAMS:
                raise ModelError(f"{elem}.{p}: a rolling bearing's parameters are {', '.join(_BEARING_PARAMS)}")
            return b, p, None
        m = self.mesh(elem)
        if p in _MESH_PARAMS:
            return m, p, None
        attr, idx = slot(canonical_param(p))
        if attr in ("omega", "fp"):
            raise ModelError(f"{attr}: not a mesh parameter")
        return m, attr, idx

    def get(self, name: str) -> float:
        """Value of a parameter by name (see the class docstring); missing harmonics are 0."""
        obj, attr, idx = self._where(name)
        v = getattr(obj, attr)
        return v if idx is None else v[idx] if idx < len(v) else 0.0

    def with_param(self, name: str, value: float) -> SystemModel:
        """Copy with one parameter changed (validated anew)."""
        obj, attr, idx = self._where(name)
        if obj is self and attr == "Dc":
            return replace(self, Dc=(*self.Dc[:idx], value, *self.Dc[idx + 1 :]))
        if obj is self:
            if self.gyro is not None:  # the gyroscopic damping follows the speed
                return replace(self, omega=value, Cb=self.damping_static + float(value) * self.gyro)
            return replace(self, omega=value)
        new = replace(obj, **({attr: value} if idx is None else series_change(obj, attr, idx, value)))
        field = "bearings" if isinstance(obj, BearingND) else "meshes"
        return replace(self, **{field: tuple(new if x.name == obj.name else x for x in getattr(self, field))})

    def parameters(self) -> dict[str, float]:
        """Every parameter by its qualified name."""
        out: dict[str, float] = {"omega": self.omega}
        for m in self.meshes:
            for p in _MESH_PARAMS:
                out[f"{m.name}.{p}"] = getattr(m, p)
            for series in ("xi", "kappa", "eps", "phi_c", "phi_k", "phi_e"):
                for k, v in enumerate(getattr(m, series)):
                    out[f"{m.name}.{series}{k + 1}"] = v
        for name, D in zip(self.clearance_names, self.Dc):
            out[f"{name}.D"] = D
        for b in self.bearings:
            for p in _BEARING_PARAMS:
                out[f"{b.name}.{p}"] = getattr(b, p)
        return out

    def contact_boundaries(self) -> tuple[Boundary, ...]:
        """One boundary per mesh and per clearance: ``vector·x = ±gap`` with vector = (V[m], 0…0).

        A mesh's switching surface is ``V[m]·q̃ − E_m(θ) = ±D[m]``; with a static transmission error
        it moves with θ (the ``vector`` gives the state part, E_m is in the coefficients).
        """
        zero = (0.0,) * self.n  # the elements' first rows: the meshes' V, then the clearances' Vc
        return tuple(Boundary(e.name, tuple(v) + zero, e.gap) for e, v in zip(self.elements, (*self.V, *self.Vc)))

    # ------------------------------------------------------------------ the System contract
    @property
    def sampling_period(self) -> float:
        """The stroboscopic sampling period: p·T, or T for incommensurate mesh frequencies."""
        return (self.period_multiple() or 1) * self.period

    @property
    def elements(self) -> tuple[Element, ...]:
        """The meshes, then the clearances, then each rolling bearing's x and y rows."""
        from ..system import RollingBearingLaw

        out = tuple(Element(m.name, m.D, "mesh") for m in self.meshes) + tuple(
            Element(n, d, "clearance") for n, d in zip(self.clearance_names, self.Dc)
        )
        for b in self.bearings:
            law = RollingBearingLaw(b.elements, b.exponent, b.clearance, b.ratio, b.phase)
            out += tuple(Element(f"{b.name}.{a}", b.clearance, "bearing", law) for a in "xy")
        return out

    @property
    def reference(self) -> int:
        """Index of the reference mesh among the elements."""
        names = [m.name for m in self.meshes]
        return names.index(self.scaling.reference) if self.scaling.reference in names else 0

    def element_series(self, x: np.ndarray, tau: np.ndarray | float) -> np.ndarray:
        """δ and δ' of every element (..., elements, 2), :func:`geardyn.systems.elements.element_series`."""
        return _el.element_series(self, x, tau)

    def initial_state(self, u0: float = 0.0, v0: float = 0.0) -> np.ndarray:
        """The state at θ = 0 with the reference mesh at (u0, v0), :func:`geardyn.systems.elements.initial_state`."""
        return _el.initial_state(self, u0, v0)

    def rigid_basis(self) -> np.ndarray:
        """The rigid-body modes (n, r), :func:`geardyn.systems.elements.rigid_modes`."""
        return _el.rigid_modes(self)

    def mean_trace(self) -> float:
        """Mean trace of the Jacobian over a forcing period, :func:`geardyn.systems.elements.mean_trace`."""
        return _el.mean_trace(self)

    def hb_form(self, period: int = 1) -> Any:
        """The equation for harmonic balance in mesh-vector form (:func:`geardyn.analysis.hb.form.system_form`)."""
        from ..analysis.hb.form import system_form

        return system_form(self, period)

    def element_forces(self, tau: np.ndarray, deltas: np.ndarray) -> np.ndarray:
        """The mesh forces (K, meshes) in units k_ref b_c, :func:`geardyn.systems.report.mesh_forces`."""
        from .report import mesh_forces

        return mesh_forces(self, tau, deltas)

    def static_force(self) -> float:
        """The reference mesh's static force, :func:`geardyn.systems.report.static_mesh_forces`."""
        from .report import static_mesh_forces

        return float(static_mesh_forces(self)[self.reference])

    def report(
        self, res: Any = None, point: int = 0, tau: Any = None, deltas: Any = None, extrema: Any = None
    ) -> dict[str, Any]:
        """Per-mesh and per-clearance summary entries, :func:`geardyn.systems.report.report`."""
        from .report import report

        return report(self, res, point, tau, deltas, extrema)

    @property
    def backend(self) -> Any:
        """The mesh-vector kernel's backend, :data:`geardyn.backend.MESH`."""
        from ..backend import MESH

        return MESH

    @property
    def n_harmonics(self) -> int:
        return max(m.n_harmonics for m in self.meshes)

    def arrays(self, n_harmonics: int | None = None) -> SystemArrays:
        """The kernel arrays of this system (see the module docstring for the contract)."""
        H = self.n_harmonics if n_harmonics is None else n_harmonics
        c = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
        return SystemArrays(
            **{f: c(getattr(self, f)) for f in ("Mi", "Kb", "Cb", "V", "F", "Vc", "kc", "cc", "Dc", "Vb")},
            coef=c(np.stack([m.coefficients(H) for m in self.meshes])),
            D=c([m.D for m in self.meshes]),
            ratio=c([m.ratio for m in self.meshes]),
            omega=np.float64(self.omega),
            Fo=c(np.reshape([F for _, F, _ in self.orders], (len(self.orders), self.n))),
            ro=c([float(r) for r, _, _ in self.orders]),
            po=c([ph for _, _, ph in self.orders]),
            bq=c(np.reshape([b.row() for b in self.bearings], (len(self.bearings), 8))),
        )

    @staticmethod
    def pack(systems: Iterable[SystemModel]) -> SystemArrays:
        """Arrays of a batch of systems of one structure, stacked along a leading axis P.

        Raises
        ------
        ModelError
            For an empty batch or systems of different structure (DOFs, meshes, clearances).
        """
        systems = list(systems)
        if not systems:
            raise ModelError("empty parameter grid: no system to integrate")
        s0 = systems[0]

        def key(s):
            return (
                s.labels,
                tuple(m.name for m in s.meshes),
                s.clearance_names,
                tuple(b.name for b in s.bearings),
                len(s.orders),
            )

        if any(key(s) != key(s0) for s in systems[1:]):
            raise ModelError(
                "pack: every system of a batch must have the same DOFs, meshes, clearances, bearings and torque orders"
            )
        H = max(s.n_harmonics for s in systems)
        each = [s.arrays(H) for s in systems]
        return SystemArrays(
            *(np.ascontiguousarray(np.stack([getattr(a, f) for a in each])) for f in SystemArrays._fields)
        )

    # ------------------------------------------------------------------ a result's attributes
    def to_attrs(self) -> str:
        """The non-dimensional system as JSON text (a result's ``system_model`` attribute): its DOF labels,
        matrices, meshes, loads (with their torque orders), ω, scales and clearances, every float exactly.
        :meth:`from_attrs` is the inverse (without the physical description, which is not stored)."""
        import json
        from dataclasses import asdict

        d = {k: getattr(self, k) for k in _ATTRS}
        if self.orders:  # [numerator, denominator] of the ratio, the load vector, the phase
            d["orders"] = [[[r.numerator, r.denominator], F, ph] for r, F, ph in self.orders]
        if self.bearings:
            d |= {"bearings": self.bearings, "Vb": self.Vb}
        if self.gyro is not None:
            d |= {"gyro": self.gyro, "damping_static": self.damping_static}
        # arrays as nested lists, the meshes, scales and bearings (dataclasses) as dicts
        return json.dumps(d, default=lambda o: o.tolist() if isinstance(o, np.ndarray) else asdict(o))

    @classmethod
    def from_attrs(cls, text: str) -> SystemModel:
        """The system of :meth:`to_attrs` text (``description`` None)."""
        import json

        d = json.loads(text)
        d["scaling"] = Scales.from_json(json.dumps(d.pop("scaling")))
        d["meshes"] = tuple(MeshND(**m) for m in d["meshes"])
        d["labels"] = tuple(d["labels"])
        d["clearance_names"] = tuple(d["clearance_names"])
        d["orders"] = tuple((Fraction(*r), _ro(F), float(ph)) for r, F, ph in d.get("orders", ()))
        if "bearings" in d:
            d["bearings"] = tuple(BearingND(**b) for b in d["bearings"])
        return cls(**d)


# ---------------------------------------------------------------------------- assembly
def _dof_scales(desc: SystemDescription, b_c: float) -> np.ndarray:
    s = np.full(desc.n, b_c)
    for i, (_, d) in enumerate(desc.dof_list):
        if d == "theta":
            rho = max((abs(desc.vector(m)[i]) for m in desc.meshes), default=0.0)
            s[i] = b_c / (rho if rho > 0 else 1.0)
    return s


def _mesh_nd(desc: SystemDescription, m: Mesh, k_ref: float, m_ref: float, b_c: float) -> MeshND:
    unit_c = 2.0 * math.sqrt(k_ref * m_ref)  # c / unit_c = the non-dimensional ξ
    if m.c0 is not None or m.c is not None:
        xi0 = (m.c0 or 0.0) / unit_c
        xi = tuple(c / unit_c for c in (m.c or ()))
    else:
        own = 2.0 * math.sqrt(m.stiffness * desc.mesh_mass(m)) / unit_c
        xi0 = (m.xi0 or 0.0) * own
        xi = tuple(x * own for x in (m.xi or ()))
    return MeshND(
        m.name,
        m.stiffness / k_ref,
        xi0,
        xi,
        m.phi_c,
        m.kappa,
        m.phi_k,
        tuple(e / b_c for e in m.e),
        m.phi_e,
        m.backlash / 2.0 / b_c,
        m.ratio / m.cycles,
        m.cycles,
    )


def assemble(desc: SystemDescription, omega: float | None = None) -> SystemModel:
    """Assemble and scale a system description (see the module docstring).

    Parameters
    ----------
    desc : SystemDescription
        The physical system.
    omega : float, optional
        Base frequency ω; default ``desc.omega``, else from ``desc.rpm``, else 1.

    Returns
    -------
    SystemModel

    Raises
    ------
    ModelError
        When the assembled mass matrix is singular, a speed in rpm cannot be converted, or the loads drive a free
        rigid-body motion (:func:`geardyn.systems.balance.check_balance`).
    """
    M = desc.mass_matrix()
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ModelError("mass matrix: singular or not positive definite") from None
    ref = desc.reference_mesh
    m_ref = desc.mesh_mass(ref)
    k_ref = ref.stiffness
    omega_n = math.sqrt(k_ref / m_ref)
    b_c = desc.b_c
    s = _dof_scales(desc, b_c)
    scaling = Scales.of_reference_mesh(
        ref.name,
        k_ref,
        m_ref,
        b_c,
        tuple(map(float, s)),
        ref.teeth,
        D=ref.backlash / 2.0 / b_c,
        title=desc.title or "system",
        source=str(desc.source or ""),
    )
    S = np.diag(s)
    Kb, Cb = desc.bearing_matrices()
    den = k_ref * b_c**2
    Mt = S @ M @ S / (m_ref * b_c**2)
    Mi = np.linalg.inv(Mt)
    Mi = 0.5 * (Mi + Mi.T)
    Kbt = S @ Kb @ S / den
    Cbt = S @ Cb @ S * omega_n / den
    V = np.array([s * desc.vector(m) / b_c for m in desc.meshes])
    F = s * desc.load_vector() / den
    idx = desc.index()
    orders = []
    for ld in desc.loads:
        j = idx[(ld.body, ld.dof)]
        for k, amp, ph in ld.orders:
            vec = np.zeros(desc.n)
            vec[j] = s[j] * amp / den
            orders.append((k * ld.speed, _ro(vec), float(ph)))
    meshes = tuple(_mesh_nd(desc, m, k_ref, m_ref, b_c) for m in desc.meshes)
    cl = desc.clearances
    Vc = [s * desc.vector(c) / b_c for c in cl]  # (clearances, n), shaped by SystemModel
    bearings, Vb = [], []
    for rb in desc.rolling_bearings:
        br = rb.bearing
        K, cl_ = br.nondimensional(b_c, k_ref)
        bearings.append(
            BearingND(
                rb.name,
                br.kind,
                br.elements,
                K,
                br.exponent,
                cl_,
                rb.cx * omega_n / k_ref,
                rb.cy * omega_n / k_ref,
                rb.ratio,
                rb.phase,
            )
        )
        Vb.append(s * rb.vectors(idx) / b_c)  # its x and y rows, stacked by SystemModel
    if omega is None:
        omega = desc.omega or (scaling.omega_from_rpm(desc.rpm) if desc.rpm is not None else 1.0)
    gyro = static = None
    G = desc.gyroscopic_matrix()
    if G is not None:  # Ω G with Ω = ω ω_n / z the reference shaft's speed (rad/s)
        if ref.teeth is None:
            raise ModelError(f"gyroscopic: the reference mesh {ref.name!r} needs teeth to give the shaft speed")
        gyro = S @ G @ S * omega_n**2 / (den * ref.teeth)
        static, Cbt = Cbt, Cbt + float(omega) * gyro
    model = SystemModel(
        desc.labels,
        Mi,
        Kbt,
        Cbt,
        V,
        meshes,
        F,
        omega,
        scaling,
        tuple(c.name for c in cl),
        Vc,
        tuple(c.stiffness / k_ref for c in cl),
        tuple(c.damping * omega_n / k_ref for c in cl),
        tuple(c.gap / b_c for c in cl),
        desc,
        tuple(orders),
        tuple(bearings),
        Vb,
        gyro,
        static,
    )
    check_balance(model, desc)  # loads on a free rigid-body motion: refused, the balancing load named
    return model
