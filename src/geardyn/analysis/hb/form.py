"""What harmonic balance needs of a system: its equation in mesh-vector form as Fourier series (``System.hb_form``).

Every system HB runs on is written as

    q'' + B q' + A q + Σ_e W_e s_e = G(φ; ν),      s_e = C_e(φ) δ_e' + K_e(φ) f_e(δ_e),
    δ_e = V_e·q − E_e(φ),      G = G0(φ) + ν² G2(φ),

in the slow angle φ = ντ of a period-n response, ν = ω/``periods`` (``periods`` = n times the base periods of a
forcing period).  f_e is the element's law (:data:`LAWS`; the dead zone f(δ; D) = δ − clamp(δ, −D, D)), C_e, K_e
and E_e are centred complex Fourier series in φ, A = M̃⁻¹K̃_b, B = M̃⁻¹C̃_b, W_e = M̃⁻¹V_e, and the forcing G is
already multiplied by M̃⁻¹.  The 1-DOF pair is the form with one coordinate q = u and one element, V = W = [1],
A = B = 0, E = 0 and G = f_p + ω² Σ l² ε_l cos(lθ + φ_el) (the STE as an inertial load, hence ν²) plus its torque
orders (constant amplitudes); a mesh-vector
system (:mod:`geardyn.systems`) has G0 = M̃⁻¹(F̃ + Σ_o F̃_o cos(r_o θ + φ_o)) (its loads and their torque orders,
harmonic r_o·periods of φ), G2 = 0 and its STE in E_e; a rolling bearing is two rows (its x and y, C = its dampers,
K = K̃, E = 0) whose forces are one law of (δ_x, δ_y) and of the base angle θ = periods·φ (``rule``).

:func:`pair_form` and :func:`system_form` build the form; ``GearModel.hb_form`` and ``SystemModel.hb_form`` call
them, and :mod:`.equations` is written against :class:`HBForm` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ModelError
from ...system import require_periodic

__all__ = ["FormElement", "HBForm", "LAWS", "mean", "pair_form", "system_form"]

#: Element laws harmonic balance can evaluate (each one function and its Jacobian in :mod:`.equations`) and the
#: element rows each acts on jointly (a rolling bearing: its x then its y row).
LAWS = {"dead_zone": 1, "rolling_bearing": 2}
#: A harmonic j r_e n p of a mesh series counts as an integer within this (relative) tolerance.
HARMONIC_RTOL = 1e-9


@dataclass(frozen=True)
class FormElement:
    """One element of an :class:`HBForm`: s_e = C_e δ_e' + K_e f_e(δ_e), δ_e = V_e·q − E_e.

    Attributes
    ----------
    name, kind : str
        The element's name and kind (``mesh`` or ``clearance``).
    V, W : ndarray (dofs,)
        Its direction and M̃⁻¹V.
    C, K, E : complex ndarray
        Centred Fourier series in φ of its damping, stiffness and excitation (E = 0: none).
    gap : float
        Half gap D of its law.
    static_force : float
        The static force of a mesh (units of the form; NaN for an element without one), for dynamic factors.
    law : str
        One of :data:`LAWS`.
    rule : Law, optional
        The System's law of a law that is sampled on the time grid (a rolling bearing's
        :class:`~geardyn.system.RollingBearingLaw`, its forces at the base angle θ = periods·φ, times K).
    """

    name: str
    kind: str
    V: np.ndarray
    W: np.ndarray
    C: np.ndarray
    K: np.ndarray
    E: np.ndarray
    gap: float
    static_force: float = math.nan
    law: str = "dead_zone"
    rule: Any = None


@dataclass(frozen=True)
class HBForm:
    """A system's equation for harmonic balance (see the module docstring).

    Attributes
    ----------
    periods : int
        Base periods of θ = ωτ per response period: ν = ω/periods.
    cycles : int
        Mesh cycles per forcing period (the pair's period multiple; 1 for a system, whose series are in its own
        forcing period): a start simulation's transient counts one-cycle periods.
    Mi, A, B : ndarray (dofs, dofs)
        M̃⁻¹, M̃⁻¹K̃_b, M̃⁻¹C̃_b.
    G0, G2 : complex ndarray (dofs, 2L + 1)
        The forcing G = G0 + ν² G2, centred series in φ (already times M̃⁻¹).
    elements : tuple of FormElement
    rigid : ndarray (dofs, r)
        Orthonormal rigid-body modes (free: no stiffness, damping or load along them).
    reference : int
        The element whose deflection is reported (the pair's u).
    span : int
        n times the largest harmonic (in θ) of the series plus two, for the number of time samples.
    labels : tuple of str
        Coordinate names.
    hz : float
        Hz per unit of ω (ω_n/2π; NaN for a non-dimensional model).
    """

    periods: int
    cycles: int
    Mi: np.ndarray
    A: np.ndarray
    B: np.ndarray
    G0: np.ndarray
    G2: np.ndarray
    elements: tuple[FormElement, ...]
    rigid: np.ndarray
    reference: int
    span: int
    labels: tuple[str, ...]
    hz: float = math.nan

    @property
    def dofs(self) -> int:
        return int(self.A.shape[0])

    @property
    def scalar(self) -> bool:
        """One coordinate, one dead-zone element with V = W = [1], no excitation in δ, no linear terms and no
        rigid-body mode: the 1-DOF equation u'' + C u' + K f(u) = G, for which :mod:`.equations` has compiled
        kernels."""
        if self.dofs != 1 or len(self.elements) != 1 or self.rigid.shape[1]:
            return False
        e = self.elements[0]
        linear = np.any(e.E) or np.any(self.A) or np.any(self.B)
        return e.law == "dead_zone" and float(e.V[0]) == float(e.W[0]) == 1.0 and not linear

    def mean_trace(self) -> float:
        """Mean over the period of the trace of the first-order Jacobian: −tr B − Σ_e (V_e·W_e) C̄_e."""
        return -sum((float(e.V @ e.W) * mean(e.C) for e in self.elements), float(np.trace(self.B)))


def mean(z: np.ndarray) -> float:
    """The mean (centre coefficient) of the centred series ``z``.

    Parameters
    ----------
    z : numpy.ndarray
        Centred complex coefficients, c₋ₗ … cₗ.
    """
    return float(z[(len(z) - 1) // 2].real)


def spread(cf: np.ndarray, ratio: float, periods: int) -> np.ndarray:
    """Centred complex coefficients in φ = θ/periods of Σ_j cf[j, 0] cos(j r θ) + cf[j, 1] sin(j r θ).

    Raises
    ------
    ModelError
        When a harmonic j r periods is not an integer (incommensurate mesh ratios).
    """
    qf = np.arange(cf.shape[0]) * ratio * periods
    q = np.rint(qf).astype(int)
    if np.any(np.abs(qf - q) > HARMONIC_RTOL * np.maximum(1.0, qf)):
        raise ModelError(f"ratio: mesh ratio {ratio!r} times {periods} periods is not an integer harmonic")
    L = int(q[-1]) if q.size else 0
    z = np.zeros(2 * L + 1, dtype=complex)
    z[L] = cf[0, 0]
    half = 0.5 * (cf[1:, 0] - 1j * cf[1:, 1])
    np.add.at(z, L + q[1:], half)
    np.add.at(z, L - q[1:], np.conj(half))
    return z


def pair_form(model: Any, period: int = 1) -> HBForm:
    """The :class:`HBForm` of the 1-DOF pair (:class:`~geardyn.model.GearModel`) for a period-n response.

    Parameters
    ----------
    model : GearModel
    period : int
        n, forcing periods per response period.

    Returns
    -------
    HBForm
    """
    n, M = int(period), int(model.period_multiple())  # the series are harmonics of the forcing frequency ω/M
    s = M // int(model.cycles)  # harmonic j of the mesh series is harmonic j·s of ω/M
    cf = model.coefficients()
    sts = np.zeros_like(cf[2])  # the STE's inertial load per ν²: its (ω/P)² is (n s ν)²
    for j, (e, ph) in enumerate(zip(model.eps, model.phi_e), start=1):
        sts[j * s] = (n * s * j) ** 2 * e * np.array([math.cos(ph), -math.sin(ph)])
    loads = model.replace(eps=(), phi_e=()).coefficients(cf.shape[1] - 1)[2]  # f_p, torque orders
    C, K, G2, G0 = (spread(x, 1, n) for x in (cf[0], cf[1], sts, loads))
    one, law, z = np.ones(1), model.elements[0].law.name, np.zeros((1, 1))
    el = FormElement("mesh", "mesh", one, one, C, K, np.zeros(1, complex), float(model.D), float(model.fp), law)
    span = n * (int(model.n_harmonics) + 2)
    return HBForm(M * n, M, np.eye(1), z, z, G0[None], G2[None], (el,), np.zeros((1, 0)), 0, span, ("u",))


def _system_loads(model: Any, Mi: np.ndarray, periods: int) -> np.ndarray:
    """G0 (dofs, 2L + 1): M̃⁻¹F̃ and every torque order's M̃⁻¹F̃_o cos(r_o θ + φ_o), harmonic q = r_o·periods of φ
    (an integer: the forcing period counts the orders' denominators), split as ½ e^{±iφ_o} at ±q."""
    qs = [r * periods for r, _, _ in model.orders]
    if any(q.denominator != 1 for q in qs):
        raise ModelError(f"orders: a torque order is not a harmonic of {periods} base periods")
    L = max((int(q) for q in qs), default=0)
    G0 = np.zeros((model.n, 2 * L + 1), dtype=complex)
    G0[:, L] = Mi @ np.asarray(model.F, dtype=float)
    for q, (_, Fo, ph) in zip(qs, model.orders):
        half = 0.5 * (Mi @ np.asarray(Fo, dtype=float)) * complex(math.cos(ph), math.sin(ph))
        G0[:, L + int(q)] += half
        G0[:, L - int(q)] += np.conj(half)
    return G0


def system_form(model: Any, period: int = 1) -> HBForm:
    """The :class:`HBForm` of a mesh-vector system (:class:`~geardyn.systems.SystemModel`) for a period-n response.

    Parameters
    ----------
    model : SystemModel
    period : int
        n, forcing periods per response period.

    Returns
    -------
    HBForm

    Raises
    ------
    ModelError
        For incommensurate mesh frequencies (no periodic forcing).
    """
    from ...systems.elements import rigid_modes
    from ...systems.report import static_mesh_forces

    periods = int(period) * require_periodic(model, "harmonic balance")
    Mi = np.asarray(model.Mi, dtype=float)
    forces = static_mesh_forces(model)
    rows = {e.name: e for e in model.elements}
    els = []

    def add(name: str, kind: str, V: Any, C: Any, K: Any, gap: float, E: Any = None, fs: float = math.nan) -> None:
        """The element ``name`` (C, K: a series or a constant; its System element's law, a rolling bearing's
        sampled by its ``rule``)."""
        V, row = np.asarray(V, dtype=float), rows.get(name)
        law, rule = (row.law.name, row.law if kind == "bearing" else None) if row else ("", None)
        if law not in LAWS:
            raise ModelError(f"{name}: harmonic balance has no element law {law!r} (it knows {', '.join(LAWS)})")
        C, K = (np.atleast_1d(np.asarray(z, dtype=complex)) for z in (C, K))
        E = np.zeros(1, complex) if E is None else E
        els.append(FormElement(name, kind, V, Mi @ V, C, K, E, float(gap), fs, law, rule))

    for i, m in enumerate(model.meshes):
        cf = m.coefficients()
        C, K, E = (spread(cf[r], m.ratio, periods) for r in range(3))
        add(m.name, "mesh", model.V[i], C, K, m.D, E, float(forces[i]))
    for i, nm in enumerate(model.clearance_names):
        add(nm, "clearance", model.Vc[i], model.cc[i], model.kc[i], model.Dc[i])
    for b, br in enumerate(model.bearings):  # its x and y rows, s = c δ' + K̃ f(δ_x, δ_y; θ) jointly
        for k, (nm, c) in enumerate(((f"{br.name}.x", br.cx), (f"{br.name}.y", br.cy))):
            add(nm, "bearing", model.Vb[2 * b + k], c, br.K, br.clearance)
    names = [m.name for m in model.meshes]
    mh = max([m.n_harmonics * m.ratio for m in model.meshes] + [float(r) for r, _, _ in model.orders], default=0.0)
    G0, ref = _system_loads(model, Mi, periods), model.scaling.reference
    K, C = (Mi @ np.asarray(x, dtype=float) for x in (model.Kb, model.Cb))
    i, span = names.index(ref) if ref in names else 0, periods * (int(math.ceil(mh)) + 2)
    hz, G2 = model.scaling.omega_n_rad_s / (2.0 * math.pi), np.zeros_like(G0)
    return HBForm(periods, 1, Mi, K, C, G0, G2, tuple(els), rigid_modes(model), i, span, tuple(model.labels), hz)
