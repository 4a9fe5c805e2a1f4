"""A multi-DOF gear system described in physical (SI) units.

The description is what a system file (:mod:`geardyn.systems.load`) or a Python script gives; it is
frozen and checked on construction (:meth:`SystemDescription.validate`).  Its pieces:

* :class:`Body` — a rigid body with some of the degrees of freedom ``x, y, z`` (translations in the
  global frame, m) and ``theta`` (the rotation about the body's own axis, rad, positive in its running
  direction), with a mass and a moment of inertia, or a full mass matrix over its DOFs.
* :class:`Connection` — a linear spring-damper: a bearing to ground or a coupling between bodies,
  given as a stiffness and damping *matrix* over a list of DOFs (a spring along a coupling vector ``w``
  is the matrix ``k w wᵀ``).
* :class:`Clearance` — a spring-damper along a coupling vector with a dead zone ``|w·q| <= gap``.
* :class:`Mesh` — a gear mesh: its mesh vector ``v`` (the deflection along the line of action is
  ``v·q − e(t)``: direction cosines on translations, directional radii n·(j × r) on rotations),
  half backlash, mean stiffness, and the Fourier series of stiffness, damping and static
  transmission error with phases, and its frequency as a multiple (``ratio``) of the base frequency.
* :class:`Load` — a mean force (N) or torque (N·m) on one DOF, with torque orders: harmonics of constant
  amplitude at orders of that body's shaft speed (:mod:`geardyn.torque_orders`).

Units: forces N, lengths m, angles rad, masses kg, inertias kg·m², translational stiffness N/m,
torsional N·m/rad (mixed entries of a matrix in N/rad), damping likewise with an extra s.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from .._docfill import attributes
from ..errors import ModelError
from ..geometry import Assumption
from ..validate import integer

__all__ = ["DOFS", "MESH_SERIES_KEYS", "Dof", "Body", "Clearance", "Connection", "Load", "Mesh", "SystemDescription"]

#: The degrees of freedom a body may have, in their canonical order.
DOFS = ("x", "y", "z", "theta")
#: A degree of freedom: (body name, DOF name).
Dof = tuple[str, str]
#: The keys of a mesh's backlash and its stiffness, damping and error series in a system or gearbox file, with
#: the kind of value each takes (the files' one reading of them).
MESH_SERIES_KEYS = {
    "backlash": "length",
    "kappa": "number*",
    "k": "stiffness*",
    "phi_k": "phase*",
    "xi0": "number",
    "xi": "number*",
    "c0": "damping",
    "c": "damping*",
    "phi_c": "phase*",
    "eps": "number*",
    "e": "length*",
    "phi_e": "phase*",
    "ratio": "number",
}


def _finite(what: str, value, unit: str = "") -> float:
    if isinstance(value, bool):
        raise ModelError(f"{what}: expected a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a number, got {value!r}") from None
    if not math.isfinite(x):
        raise ModelError(f"{what}: must be finite, got {value!r}" + (f" {unit}" if unit else ""))
    return x


def _bounded(what: str, value, unit: str = "", strict: bool = True) -> float:
    """``value`` checked finite and > 0 (``strict``) or >= 0, the error naming ``what`` and the unit."""
    x = _finite(what, value, unit)
    if x < 0 or (strict and x == 0):
        u = f" {unit}" if unit else ""
        raise ModelError(f"{what}: must be {'>' if strict else '>='} 0{u}, got {x:g}{u}")
    return x


def check_kappa(what: str, kappa: tuple[float, ...], phi_k: tuple[float, ...], cycles: int) -> None:
    """Refuse stiffness harmonics that can make the mesh stiffness non-positive: Σ|κ_r| >= 1, unless the series
    is a table's over P > 1 mesh cycles whose certified minimum (:func:`geardyn.pairpack.stiffness_minimum`) is > 0."""
    from ..pairpack import stiffness_minimum

    if sum(abs(x) for x in kappa) >= 1.0 and not (cycles > 1 and stiffness_minimum(kappa, phi_k) > 0.0):
        raise ModelError(f"{what}: sum of |kappa_r| must be < 1 so the mesh stiffness stays positive")


def _series(what: str, values: Iterable) -> tuple[float, ...]:
    return tuple(_finite(f"{what}{i + 1}", v) for i, v in enumerate(values or ()))


@dataclass(frozen=True)
@attributes
class Body:
    """A rigid body."""

    #: Unique name.
    name: str
    #: Its degrees of freedom, a subset of :data:`DOFS` (stored in canonical order).
    dofs: tuple[str, ...]
    #: Mass (kg, > 0); needed when the body has a translation and no ``mass_matrix``.
    mass: float | None = None
    #: Moment of inertia about its rotation axis (kg·m², > 0); needed with ``theta``.
    inertia: float | None = None
    #: A full symmetric mass matrix over ``dofs`` (SI), instead of ``mass``/``inertia``.
    mass_matrix: tuple[tuple[float, ...], ...] | None = None

    def __post_init__(self) -> None:
        who = f"body {self.name!r}"
        dofs = tuple(self.dofs)
        bad = [d for d in dofs if d not in DOFS]
        if bad:
            raise ModelError(f"{who}: dofs: unknown DOF(s) {bad}; allowed: {', '.join(DOFS)}")
        if len(set(dofs)) != len(dofs):
            raise ModelError(f"{who}: dofs: a DOF is listed twice: {list(dofs)}")
        if not dofs:
            raise ModelError(f"{who}: dofs: a body needs at least one DOF (x, y, z, theta)")
        object.__setattr__(self, "dofs", tuple(d for d in DOFS if d in dofs))
        if self.mass_matrix is not None:
            if self.mass is not None or self.inertia is not None:
                raise ModelError(f"{who}: give mass and inertia, or mass_matrix, not both")
            mm = np.array(self.mass_matrix, dtype=float)
            n = len(self.dofs)
            if mm.shape != (n, n):
                raise ModelError(f"{who}: mass_matrix: must be {n}x{n} (one row per DOF), got shape {mm.shape}")
            if not np.all(np.isfinite(mm)) or not np.allclose(mm, mm.T, rtol=1e-12, atol=0.0):
                raise ModelError(f"{who}: mass_matrix: must be finite and symmetric")
            # reorder to canonical order
            order = [dofs.index(d) for d in self.dofs]
            mm = mm[np.ix_(order, order)]
            object.__setattr__(self, "mass_matrix", tuple(map(tuple, mm.tolist())))
            return
        has_t = any(d != "theta" for d in self.dofs)
        for attr, needed, unit in (("mass", has_t, "kg"), ("inertia", "theta" in self.dofs, "kg*m^2")):
            v = getattr(self, attr)
            if v is None:
                if needed:
                    raise ModelError(
                        f"{who}: {attr}: missing (needed for its {'translations' if attr == 'mass' else 'rotation'})"
                    )
                continue
            object.__setattr__(self, attr, _bounded(f"{who}: {attr}", v, unit))

    def matrix(self) -> np.ndarray:
        """The body's mass matrix over its DOFs (SI)."""
        if self.mass_matrix is not None:
            return np.array(self.mass_matrix, dtype=float)
        return np.diag([self.inertia if d == "theta" else self.mass for d in self.dofs]).astype(float)


def _matrix(who: str, what: str, values, n: int) -> tuple[tuple[float, ...], ...]:
    a = np.array(values, dtype=float)
    if a.shape != (n, n):
        raise ModelError(f"{who}: {what}: must be {n}x{n} (one row per DOF), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ModelError(f"{who}: {what}: must be finite")
    if not np.allclose(a, a.T, rtol=1e-12, atol=1e-12 * max(1.0, float(np.abs(a).max()))):
        raise ModelError(f"{who}: {what}: must be symmetric")
    return tuple(map(tuple, a.tolist()))


@dataclass(frozen=True)
@attributes
class Connection:
    """A linear spring-damper over some DOFs: a bearing (to ground) or a coupling between bodies."""

    #: Unique element name (used in the strain-energy fractions).
    name: str
    #: The DOFs it acts on, ``(body, dof)``.
    dofs: tuple[Dof, ...]
    #: Symmetric stiffness matrix over ``dofs`` (SI).
    stiffness: tuple[tuple[float, ...], ...]
    #: Symmetric damping matrix over ``dofs`` (SI); default zero.
    damping: tuple[tuple[float, ...], ...] | None = None

    def __post_init__(self) -> None:
        who = f"connection {self.name!r}"
        dofs = tuple((str(b), str(d)) for b, d in self.dofs)
        if not dofs or len(set(dofs)) != len(dofs):
            raise ModelError(f"{who}: dofs: must list distinct (body, dof) pairs, got {list(self.dofs)}")
        object.__setattr__(self, "dofs", dofs)
        n = len(dofs)
        object.__setattr__(self, "stiffness", _matrix(who, "stiffness", self.stiffness, n))
        c = np.zeros((n, n)) if self.damping is None else self.damping
        object.__setattr__(self, "damping", _matrix(who, "damping", c, n))

    @classmethod
    def along(cls, name: str, vector: dict[Dof, float], stiffness: float, damping: float = 0.0) -> Connection:
        """A spring-damper along the coupling vector ``w``: stiffness matrix ``k w wᵀ``, damping ``c w wᵀ``."""
        dofs = tuple(vector)
        w = np.array([vector[d] for d in dofs], dtype=float)
        return cls(name, dofs, np.outer(w, w) * float(stiffness), np.outer(w, w) * float(damping))

    @classmethod
    def diagonal(
        cls, name: str, body: str, stiffness: dict[str, float], damping: dict[str, float] | None = None, order=DOFS
    ):
        """A bearing to ground with independent springs on some of one body's DOFs (taken in ``order``)."""
        damping = damping or {}
        dofs = tuple(d for d in order if d in stiffness or d in damping)
        return cls(
            name,
            tuple((body, d) for d in dofs),
            np.diag([float(stiffness.get(d, 0.0)) for d in dofs]),
            np.diag([float(damping.get(d, 0.0)) for d in dofs]),
        )


class _AlongVector:
    """An element acting along a vector of ``((body, dof), coefficient)`` pairs."""

    @property
    def dofs(self) -> tuple[Dof, ...]:
        """The DOFs of the vector, in its order."""
        return tuple(d for d, _ in self.vector)

    def _set_vector(self, who: str) -> tuple:
        """Store the vector with its names as text and its coefficients checked finite, and return it."""
        vec = tuple(((str(b), str(d)), _finite(f"{who}: vector", c)) for (b, d), c in self.vector)
        object.__setattr__(self, "vector", vec)
        return vec


@dataclass(frozen=True)
@attributes
class Clearance(_AlongVector):
    """A spring-damper along a coupling vector with a dead zone (e.g. a bearing clearance).

    The deflection is ``δ = w·q``; the force along ``w`` is ``c δ' + k f(δ; gap)`` with the dead zone
    ``f(δ; g) = δ − g (δ > g), 0 (|δ| <= g), δ + g (δ < −g)`` (the damper acts throughout, as the mesh's).
    """

    #: Unique element name.
    name: str
    #: The coupling vector as ((body, dof), coefficient) pairs (SI: numbers on translations,
    #: lengths on rotations for a translational element).
    vector: tuple[tuple[Dof, float], ...]
    #: Contact stiffness k (N/m, or N·m/rad for a torsional element), > 0.
    stiffness: float
    #: Half clearance g (m or rad), >= 0.
    gap: float
    #: Damping coefficient c (>= 0).
    damping: float = 0.0

    def __post_init__(self) -> None:
        who = f"clearance {self.name!r}"
        if not self._set_vector(who):
            raise ModelError(f"{who}: vector: must act on at least one DOF")
        for attr, key in (("stiffness", "stiffness"), ("gap", "clearance"), ("damping", "damping")):
            object.__setattr__(self, attr, _bounded(f"{who}: {key}", getattr(self, attr), strict=attr == "stiffness"))


@dataclass(frozen=True)
@attributes
class Mesh(_AlongVector):
    """A gear mesh (SI)."""

    #: Unique name (parameters are addressed as ``<name>.kappa1`` etc.).
    name: str
    #: The mesh vector v: the deflection along the line of action is ``v·q − e(t)``, positive when
    #: the teeth are pressed together (pinion into gear).
    vector: tuple[tuple[Dof, float], ...]
    #: Mean mesh stiffness k0 (N/m), > 0.
    stiffness: float
    #: Normal backlash j (m), >= 0; the dead zone is ``|δ| <= j/2``.
    backlash: float = 0.0
    #: Stiffness harmonics k_r/k0 and their phases (rad): k(t) = k0 [1 + Σ κ_r cos(r θ_m + φ_kr)].
    kappa: tuple[float, ...] = ()
    phi_k: tuple[float, ...] = ()
    #: Damping as ratios, c = 2 ξ √(k0 m_e) with the mesh's own equivalent mass
    #: m_e = 1/(vᵀ M⁻¹ v) (for a two-gear torsional pair the 1-DOF model's ξ).  Give these or
    #: ``c0``/``c``, not both.
    xi0: float | None = None
    xi: tuple[float, ...] | None = None
    #: Damping coefficients (N·s/m).
    c0: float | None = None
    c: tuple[float, ...] | None = None
    #: Phases of the damping harmonics (rad).
    phi_c: tuple[float, ...] = ()
    #: Static-transmission-error harmonics (m) and phases: e(t) = Σ e_l cos(l θ_m + φ_el).
    e: tuple[float, ...] = ()
    phi_e: tuple[float, ...] = ()
    #: Mesh frequency / base frequency (> 0): θ_m = ratio · θ.
    ratio: float = 1.0
    #: Teeth of the body whose speed is the pinion speed, to convert rpm to the mesh frequency.
    teeth: int | None = None
    #: P, the mesh cycles of the series' period (an excitation table over a tooth fault or the hunting
    #: period, :mod:`geardyn.tooth.table`): with P > 1 the harmonics of ``kappa``, ``e`` and the damping
    #: are of θ_m/P (member j is mesh order j/P), and the stiffness must stay positive (Σ|κ| < 1 or a
    #: certified minimum > 0, :func:`geardyn.pairpack.stiffness_minimum`).
    cycles: int = 1
    #: An excitation file (:func:`geardyn.tooth.table.read_table`) giving ``stiffness``, ``kappa``, ``phi_k``,
    #: ``e``, ``phi_e`` and ``cycles`` (then not given); damping harmonic k (mesh order k) becomes member k·P.
    excitation: str | None = None
    #: Harmonics of the table kept (default all, at most MAX_HARMONICS·P).
    excitation_harmonics: int | None = None

    def __post_init__(self) -> None:
        who = f"mesh {self.name!r}"
        set_ = object.__setattr__
        if self.excitation is not None:
            self._from_table(who)
        if not any(c != 0 for _, c in self._set_vector(who)):
            raise ModelError(f"{who}: vector: the mesh vector must not be zero")
        set_(self, "stiffness", _bounded(f"{who}: stiffness", self.stiffness, "N/m"))
        set_(self, "backlash", _bounded(f"{who}: backlash", self.backlash, "m", strict=False))
        r = _finite(f"{who}: ratio", self.ratio)
        if r <= 0:
            raise ModelError(f"{who}: ratio: the mesh-frequency ratio must be > 0, got {r:g}")
        set_(self, "ratio", r)
        if (self.xi0 is not None or self.xi is not None) and (self.c0 is not None or self.c is not None):
            raise ModelError(f"{who}: damping: give ratios (xi0, xi) or coefficients (c0, c), not both")
        for name in ("kappa", "phi_k", "phi_c", "e", "phi_e"):
            set_(self, name, _series(f"{who}: {name}", getattr(self, name)))
        for name, check in (("xi", _series), ("c", _series), ("xi0", _finite), ("c0", _finite)):
            if getattr(self, name) is not None:
                set_(self, name, check(f"{who}: {name}", getattr(self, name)))
                if name in ("xi0", "c0") and getattr(self, name) < 0:
                    raise ModelError(
                        f"{who}: {name}: must be >= 0 (a negative damping feeds energy in), got {getattr(self, name):g}"
                    )
        damping = self.xi if self.xi is not None else (self.c or ())
        for amp, a, ph in (("kappa", self.kappa, "phi_k"), ("e", self.e, "phi_e"), ("damping", damping, "phi_c")):
            p = getattr(self, ph)
            if len(p) not in (0, len(a)):
                raise ModelError(
                    f"{who}: {ph}: {len(p)} phases for {len(a)} {amp} harmonics; give one phase per harmonic, "
                    "or none (all 0)"
                )
            set_(self, ph, p + (0.0,) * (len(a) - len(p)))
        set_(self, "cycles", integer(f"{who}: cycles", self.cycles, 1))
        check_kappa(f"{who}: kappa", self.kappa, self.phi_k, self.cycles)
        if self.teeth is not None:
            set_(self, "teeth", integer(f"{who}: teeth", self.teeth, 1))

    def _from_table(self, who: str) -> None:
        from ..errors import ConfigError
        from ..params import MAX_HARMONICS
        from ..tooth.excitation import spread_harmonics
        from ..tooth.table import read_table

        given = [k for k in ("kappa", "phi_k", "e", "phi_e") if getattr(self, k)]
        if self.stiffness is not None or given or self.cycles != 1:
            raise ModelError(f"{who}: excitation: give the table or stiffness/kappa/e/cycles, not both")
        try:
            exc = read_table(self.excitation)
        except ConfigError as err:
            raise ModelError(f"{who}: excitation: {err}") from None
        P = exc.cycles
        H = self.excitation_harmonics
        s = exc.series(min(exc.stiffness.size // 2, MAX_HARMONICS * P) if H is None else H, 1.0, cap=MAX_HARMONICS * P)
        vals = {
            "stiffness": s["k0"],
            "kappa": s["kappa"],
            "phi_k": s["phi_k"],
            "e": s.get("eps", ()),
            "phi_e": s.get("phi_e", ()),
            "cycles": P,
        }
        name = "xi" if self.xi is not None else "c"
        damp = getattr(self, name) or ()
        if P > 1 and damp:
            vals[name], vals["phi_c"] = spread_harmonics(damp, self.phi_c, P)
        for k, v in vals.items():
            object.__setattr__(self, k, v)


@dataclass(frozen=True)
@attributes
class Load:
    """A mean force (N, on a translation) or torque (N·m, on ``theta``) on one DOF, and its torque orders.

    Raises
    ------
    ModelError
        If ``value`` is not finite, an order is not a positive number, or orders are given without ``speed``.
    """

    #: Name of the body loaded.
    body: str
    #: Its DOF (``theta`` or a translation).
    dof: str
    #: The force in N or torque in N·m.
    value: float
    #: Torque orders (order k of the body's shaft speed as a ``Fraction``, amplitude in N·m or N, phase in rad):
    #: the load adds Σ amplitude cos(k Ω t + phase), Ω the body's speed.
    orders: tuple = ()
    #: The body's shaft speed over the base frequency ω (a ``Fraction``; θ = ω τ): order k runs at k·speed·θ.
    speed: object = None

    def __post_init__(self) -> None:
        from fractions import Fraction

        from ..torque_orders import normalise

        who = f"load on {self.body}.{self.dof}"
        object.__setattr__(self, "value", _finite(who, self.value))
        try:
            orders = normalise(self.orders)
        except ModelError as e:
            raise ModelError(f"{who}: orders: {e}") from None
        object.__setattr__(self, "orders", orders)
        if orders:
            if self.speed is None:
                raise ModelError(f"{who}: orders: the speed of body {self.body!r} is unknown (no mesh gives its teeth)")
            sp = Fraction(self.speed)
            if sp <= 0:
                raise ModelError(f"{who}: orders: the body's speed ratio must be > 0, got {self.speed!r}")
            object.__setattr__(self, "speed", sp)


@dataclass(frozen=True)
class SystemDescription:
    """A multi-DOF gear system in SI units, validated on construction.

    Parameters
    ----------
    bodies, connections, clearances, meshes, loads : tuples of the element classes
        The elements; names are unique across connections, clearances and meshes.
    reference : str, optional
        The mesh whose ω_n = √(k0/m_e) and backlash set the scales; default the first mesh.
    characteristic_length : float, optional
        b_c (m); default half the reference mesh's backlash (then its D = 1).
    rpm : float, optional
        Pinion speed (rpm) of the operating point: ω_e = 2π z rpm/60 with z the reference mesh's ``teeth``.
    omega : float, optional
        The non-dimensional base frequency ω directly (overrides ``rpm``).
    equivalent_mass : {"rotational", "full"}
        How a mesh's equivalent mass m_e = 1/(vᵀ M⁻¹ v) is taken (for the scales and for damping
        ratios): ``"rotational"`` (default) uses only the rotation entries of v, the torsional m_e
        of the 1-DOF model, so that ω and ξ mean the same as there and the rigid-bearing limit
        is the 1-DOF model; ``"full"`` uses the whole vector (translations too).  A mesh without
        rotation entries always uses the full vector.
    title, source : str
        For reports.
    assumptions : tuple of Assumption
        Every value the description assumes, with its source.
    rolling_bearings : tuple of RollingElementBearing
        The rolling-element bearings (:mod:`geardyn.systems.rolling`), the second element law.

    Raises
    ------
    ModelError
        Unknown bodies or DOFs, duplicate names, a body with no connection, a singular mass matrix,
        a missing mesh, a non-positive speed.
    """

    bodies: tuple[Body, ...]
    meshes: tuple[Mesh, ...]
    connections: tuple[Connection, ...] = ()
    clearances: tuple[Clearance, ...] = ()
    loads: tuple[Load, ...] = ()
    reference: str | None = None
    characteristic_length: float | None = None
    rpm: float | None = None
    omega: float | None = None
    equivalent_mass: str = "rotational"
    title: str = ""
    source: str = ""
    assumptions: tuple[Assumption, ...] = field(default=())
    #: Rolling-element bearings (:class:`geardyn.systems.rolling.RollingElementBearing`), the second element law.
    rolling_bearings: tuple = ()

    def __post_init__(self) -> None:
        for name in ("bodies", "meshes", "connections", "clearances", "loads", "assumptions", "rolling_bearings"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        self.validate()

    # ------------------------------------------------------------------ structure
    @property
    def dof_list(self) -> tuple[Dof, ...]:
        """Every DOF of the system in order: bodies in their order, each body's DOFs in canonical order."""
        return tuple((b.name, d) for b in self.bodies for d in b.dofs)

    @property
    def labels(self) -> tuple[str, ...]:
        """``"body.dof"`` label of every DOF."""
        return tuple(f"{b}.{d}" for b, d in self.dof_list)

    @property
    def n(self) -> int:
        return len(self.dof_list)

    def index(self) -> dict[Dof, int]:
        return {d: i for i, d in enumerate(self.dof_list)}

    @property
    def reference_mesh(self) -> Mesh:
        name = self.reference or self.meshes[0].name
        return next(m for m in self.meshes if m.name == name)

    def validate(self) -> None:
        """Check the structure (see the class docstring); raises :class:`ModelError`."""
        names = [b.name for b in self.bodies]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ModelError(f"body {dup[0]!r}: the name is used twice")
        if not self.bodies:
            raise ModelError("system: no bodies")
        if not self.meshes:
            raise ModelError("system: no gear mesh; a system needs at least one [[mesh]]")
        elems = [e.name for e in (*self.connections, *self.clearances, *self.meshes, *self.rolling_bearings)]
        dup = sorted({n for n in elems if elems.count(n) > 1})
        if dup:
            raise ModelError(
                f"element {dup[0]!r}: the name is used twice (connections, clearances and meshes share names)"
            )
        idx = self.index()
        bodies = {b.name: b for b in self.bodies}
        used: set[str] = set()
        kinds = (
            ("connection", self.connections),
            ("clearance", self.clearances),
            ("mesh", self.meshes),
            ("bearing", self.rolling_bearings),
        )
        for kind, items in kinds:
            for e in items:
                for b, d in e.dofs:
                    if b not in bodies:
                        raise ModelError(f"{kind} {e.name!r}: unknown body {b!r}; bodies: {', '.join(names)}")
                    if (b, d) not in idx:
                        raise ModelError(
                            f"{kind} {e.name!r}: body {b!r} has no DOF {d!r} (its DOFs: {', '.join(bodies[b].dofs)})"
                        )
                    used.add(b)
        for ld in self.loads:
            if (ld.body, ld.dof) not in idx:
                what = (
                    f"unknown body {ld.body!r}" if ld.body not in bodies else f"body {ld.body!r} has no DOF {ld.dof!r}"
                )
                raise ModelError(f"load on {ld.body}.{ld.dof}: {what}")
        for b in self.bodies:
            if b.name not in used:
                raise ModelError(f"body {b.name!r}: has no connection or mesh; every body must be connected")
        for b in self.bodies:
            ev = np.linalg.eigvalsh(b.matrix())
            if ev.min() <= 1e-12 * max(abs(ev.max()), 1e-300):
                key = "mass_matrix" if b.mass_matrix is not None else "mass"
                raise ModelError(
                    f"body {b.name!r}: {key}: the mass matrix is singular or not positive definite (eigenvalues "
                    f"{ev.tolist()})"
                )
        if self.reference is not None and self.reference not in {m.name for m in self.meshes}:
            raise ModelError(
                f"reference: unknown mesh {self.reference!r}; meshes: {', '.join(m.name for m in self.meshes)}"
            )
        if self.characteristic_length is not None and not self.characteristic_length > 0:
            raise ModelError(f"characteristic_length: must be > 0 m, got {self.characteristic_length!r}")
        if self.characteristic_length is None and self.reference_mesh.backlash <= 0:
            raise ModelError(
                f"mesh {self.reference_mesh.name!r}: backlash is 0: give characteristic_length to scale lengths"
            )
        if self.equivalent_mass not in ("rotational", "full"):
            raise ModelError(f"equivalent_mass: must be 'rotational' or 'full', got {self.equivalent_mass!r}")
        for name in ("rpm", "omega"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise ModelError(f"{name}: must be > 0, got {v!r}")

    # ------------------------------------------------------------------ physical matrices
    def mass_matrix(self) -> np.ndarray:
        """M (n × n, SI), block diagonal over the bodies."""
        M = np.zeros((self.n, self.n))
        i = 0
        for b in self.bodies:
            k = len(b.dofs)
            M[i : i + k, i : i + k] = b.matrix()
            i += k
        return M

    def _scatter(self, dofs, mat) -> np.ndarray:
        idx = self.index()
        out = np.zeros((self.n, self.n))
        ii = [idx[d] for d in dofs]
        out[np.ix_(ii, ii)] += np.asarray(mat, dtype=float)
        return out

    def connection_matrices(self, conn: Connection) -> tuple[np.ndarray, np.ndarray]:
        """(K, C) of one linear connection, n × n (SI)."""
        return self._scatter(conn.dofs, conn.stiffness), self._scatter(conn.dofs, conn.damping)

    def vector(self, element: Mesh | Clearance) -> np.ndarray:
        """The element's vector over all DOFs (n,)."""
        idx = self.index()
        v = np.zeros(self.n)
        for d, c in element.vector:
            v[idx[d]] += c
        return v

    def gyroscopic_matrix(self) -> np.ndarray | None:
        """The gyroscopic matrix G (SI): None here, a gearbox's shafts give one
        (:meth:`geardyn.gearbox.model.GearboxDescription.gyroscopic_matrix`)."""
        return None

    def bearing_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """K_b, C_b: the sum over the linear connections (n × n, SI)."""
        kc = [self.connection_matrices(c) for c in self.connections]
        return tuple(sum((m[i] for m in kc), np.zeros((self.n, self.n))) for i in (0, 1))

    def load_vector(self) -> np.ndarray:
        """F (n,): the mean loads (SI)."""
        idx = self.index()
        F = np.zeros(self.n)
        for ld in self.loads:
            F[idx[(ld.body, ld.dof)]] += ld.value
        return F

    def mesh_mass(self, mesh: Mesh) -> float:
        """Equivalent mass m_e = 1/(vᵀ M⁻¹ v) of a mesh (kg), taken as :attr:`equivalent_mass` says."""
        v = self.vector(mesh)
        if self.equivalent_mass == "rotational":
            rot = np.array([d == "theta" for _, d in self.dof_list])
            if np.any(v[rot] != 0):
                v = np.where(rot, v, 0.0)
        return 1.0 / float(v @ np.linalg.solve(self.mass_matrix(), v))

    @property
    def b_c(self) -> float:
        """Characteristic length b_c (m)."""
        if self.characteristic_length is not None:
            return self.characteristic_length
        return self.reference_mesh.backlash / 2.0
