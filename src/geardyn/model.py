"""The non-dimensional gear-pair model.

The equation of motion (see ``docs/model.md``) is, with ``θ = ω τ``::

    u'' + 2[ξ0 + Σ_k ξ_k cos(kθ + φ_ck)] u' + [1 + Σ_r κ_r cos(rθ + φ_kr)] f(u; D)
        = f_p + ω² Σ_l l² ε_l cos(lθ + φ_el)

with the dead-zone (backlash) function ``f(u; D) = u - D`` for ``u > D``, ``0`` for ``|u| <= D``
and ``u + D`` for ``u < -D``.  Every quantity here is non-dimensional: displacements are in units
of the characteristic length ``b_c``, time in units of ``1/ω_n``.

:class:`GearModel` is frozen and validated on construction.  Sweeps address its parameters by
name (:data:`PARAMETER_HELP` lists them): ``omega``, ``xi0``, ``xi1``…, ``kappa1``…, ``fp``,
``eps1``… (alias ``fe`` for ``eps1``), ``D`` (alias ``backlash``), ``phi_c1``…, ``phi_k1``…,
``phi_e1``….
"""

from __future__ import annotations

import dataclasses
import json
import math
import numbers
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any, ClassVar

import numpy as np

from ._docfill import attributes
from .errors import ModelError
from .meshtable import EVALUATIONS, check_table, table_values
from .pairpack import MAX_KAPPA_SUM, SERIES, SERIES_FIELDS, pack_models, stiffness_minimum
from .params import FAMILIES, MAX_HARMONICS, PARAMETER_HELP, canonical_param, slot
from .series import series_values
from .system import Element
from .torque_orders import normalise as _normalise_orders
from .torque_orders import period_multiple as _orders_multiple
from .torque_orders import to_dicts as _orders_to_dicts

__all__ = [
    "Boundary",
    "GearModel",
    "IntegrationOptions",
    "ModelError",
    "PAPER_DEFAULTS",
    "PARAMETER_HELP",
    "canonical_param",
]

#: Default non-dimensional step Δτ (the paper's value).
DEFAULT_DTAU = 0.01
#: Default number of forcing periods discarded as transient before recording.
DEFAULT_TRANSIENT = 300
#: Default number of forcing periods recorded (Poincaré points).
DEFAULT_PERIODS = 200


def _check_finite(name: str, value: Any, *, real_only: bool = False, describe: Any = repr) -> float:
    """``value`` as a finite float, else :class:`ModelError` naming ``name`` (the one finite-number check).

    Parameters
    ----------
    name : str
        The parameter's name, for the message.
    value : object
        The raw value; bool is refused, and with ``real_only`` anything that is not a real number
        (strings, NumPy bools, complex, None) too.
    real_only : bool
        Refuse values that are not :class:`numbers.Real` instead of trying ``float(value)``
        (the stricter check of :func:`geardyn.validate.number`).
    describe : callable
        How the value is shown in the message (default ``repr``).

    Returns
    -------
    float
        The value converted.

    Raises
    ------
    ModelError
        "expected a (finite) number" for the wrong type, "must be a finite number" for NaN or ±inf.
    """
    refused = (bool, np.bool_) if real_only else bool
    if isinstance(value, refused) or (real_only and not isinstance(value, numbers.Real)):
        raise ModelError(f"{name}: expected {'a finite' if real_only else 'a'} number, got {describe(value)}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        what = "must be" if real_only else "expected"
        raise ModelError(f"{name}: {what} a finite number, got {describe(value)}") from None
    if not math.isfinite(x):
        raise ModelError(f"{name}: must be a finite number, got {describe(value)}")
    return x


def _whole_number(value: Any, at_least: float = -math.inf) -> bool:
    """Whether ``value`` is a whole number >= ``at_least`` (a float such as 3.0 included; a bool, a string, NaN or
    ±inf not)."""
    try:
        return not isinstance(value, bool) and float(value).is_integer() and value >= at_least
    except (TypeError, ValueError, OverflowError):
        return False


def series_change(obj: Any, attr: str, idx: int, value: float) -> dict[str, tuple[float, ...]]:
    """The changes that set member ``idx`` of the series ``attr`` of ``obj`` (a model or a mesh) to ``value``: the
    series extended by zeros, and for a phase of a harmonic not yet present that harmonic with amplitude 0."""
    seq = list(getattr(obj, attr))
    seq.extend([0.0] * (idx + 1 - len(seq)))
    seq[idx] = value
    changes = {attr: tuple(seq)}
    amp_name = FAMILIES[attr].amplitude
    if amp_name is not None and len(amp := getattr(obj, amp_name)) < len(seq):
        changes[amp_name] = tuple(amp) + (0.0,) * (len(seq) - len(amp))
    return changes


def _as_tuple(name: str, values: Any, cycles: int = 1) -> tuple[float, ...]:
    if values is None:
        return ()
    if np.isscalar(values):
        values = (values,)
    out = tuple(_check_finite(f"{name}{i + 1}", v) for i, v in enumerate(values))
    cap = MAX_HARMONICS * cycles
    if len(out) > cap:
        raise ModelError(
            f"{name}: at most {cap} harmonics, got {len(out)}"
            + (f" (mesh orders up to {MAX_HARMONICS} over a period of {cycles} mesh cycles)" if cycles > 1 else "")
        )
    return out


@dataclass(frozen=True)
@attributes
class Boundary:
    """A contact boundary of a non-smooth element: the surfaces ``vector · x = ±gap`` in the state space."""

    #: The element's name (``"mesh"`` for the 1-DOF model).
    element: str
    #: The row vector (length ``state_dim``) giving the element's relative displacement from the state.
    vector: tuple[float, ...]
    #: Half clearance (non-dimensional); contact is ``|vector · x| > gap``.
    gap: float


@dataclass(frozen=True)
class GearModel:
    """Frozen, validated non-dimensional gear-pair model.

    Parameters
    ----------
    omega : float
        Mesh frequency ω = ω_e/ω_n (non-dimensional, > 0).  The forcing period is T = 2π/ω in τ.
    xi0 : float
        Mean damping ratio ξ0 (non-dimensional).  Negative values are accepted (they model an
        energy source and usually diverge; sweeps mark such points ``diverged``).
    xi : tuple of float
        Damping harmonics ξ_k, k = 1, 2, …  (``xi[0]`` is ξ1).
    phi_c : tuple of float
        Phases φ_ck of the damping harmonics in radians; padded with zeros to ``len(xi)``.
    kappa : tuple of float
        Stiffness harmonics κ_r = k_r/k0 (non-dimensional); Σ|κ_r| < 1 keeps the stiffness positive.
    phi_k : tuple of float
        Phases φ_kr of the stiffness harmonics (rad).
    eps : tuple of float
        Static-transmission-error harmonics ε_l = e_l/b_c (non-dimensional); harmonic l enters the
        forcing as ω² l² ε_l cos(lθ + φ_el).  The paper's "f_e = 0.5 ω² cos θ" is ``eps=(0.5,)``.
    phi_e : tuple of float
        Phases φ_el of the STE harmonics (rad).
    fp : float
        Mean load f_p = F_p/(k0 b_c) (non-dimensional).
    D : float
        Half backlash b_n/b_c (non-dimensional, >= 0; ``D = 0`` means no backlash, a linear mesh).
    cycles : int
        P, the mesh cycles of one forcing period (default 1).  With P > 1 (a tooth fault, the hunting
        period; :mod:`geardyn.tooth.excitation`) ω stays the mesh frequency, the series ξ, κ, ε are
        harmonics of the forcing frequency ω/P (member j is mesh order j/P, at most
        ``MAX_HARMONICS``·P of them), the forcing period is P·2π/ω (:attr:`sampling_period`,
        :meth:`period_multiple`) and the stiffness must be positive for every θ (Σ|κ_j| < 1, or a
        certified minimum > 0: :func:`geardyn.pairpack.stiffness_minimum`).
    evaluation : str
        ``"series"`` (default): the kernels evaluate the series κ, ε.  ``"table"``: the accurate mode
        evaluates ``table`` as given (piecewise linear, with its jumps; :mod:`geardyn.meshtable`) and ends
        a sub-step at every node; the series stay the model's for the tools that take series.
    table : (phase, k, e)
        With ``evaluation = "table"``: node phases in mesh cycles over [0, ``cycles``), k/k0 and e/b_c
        (e may be empty).
    torque_orders : tuple of (order, amplitude, phase)
        Torque orders (:mod:`geardyn.torque_orders`): forcing terms a cos(qθ + φ) of constant amplitude a
        (non-dimensional like f_p) at q times the mesh frequency, q a positive rational (a ``Fraction``, an
        integer, a decimal or ``"a/b"``; order k of the pinion's speed is q = k/z1), φ in rad.  The forcing
        period becomes the least common multiple of ``cycles`` and the orders' denominators, in mesh cycles
        (:meth:`period_multiple`); the series ξ, κ, ε keep their meaning.  Default none.

    The defaults are the paper's Table 1 values with ω = 1.

    Examples
    --------
    >>> from geardyn import GearModel
    >>> m = GearModel(omega=0.8)
    >>> m.omega, m.xi0, m.kappa, m.eps, m.fp, m.D
    (0.8, 0.1, (0.2,), (0.5,), 0.2, 1.0)
    >>> m.with_param("kappa2", 0.1).kappa
    (0.2, 0.1)
    >>> GearModel(omega=0.0)
    Traceback (most recent call last):
        ...
    geardyn.errors.ModelError: omega: ...
    """

    omega: float = FAMILIES["omega"].default
    xi0: float = FAMILIES["xi0"].default
    xi: tuple[float, ...] = FAMILIES["xi"].default
    phi_c: tuple[float, ...] = FAMILIES["phi_c"].default
    kappa: tuple[float, ...] = FAMILIES["kappa"].default
    phi_k: tuple[float, ...] = FAMILIES["phi_k"].default
    eps: tuple[float, ...] = FAMILIES["eps"].default
    phi_e: tuple[float, ...] = FAMILIES["phi_e"].default
    fp: float = FAMILIES["fp"].default
    D: float = FAMILIES["D"].default
    cycles: int = 1
    evaluation: str = "series"
    table: tuple = ()
    torque_orders: tuple = ()

    #: Dimension of the state (u, u') — the 1-DOF model's physics: one relative coordinate.
    state_dim: ClassVar[int] = 2
    #: Names of the state's coordinates (a result's ``state`` coordinate).
    state_labels: ClassVar[tuple[str, str]] = ("u", "u'")

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        P = self.cycles
        if not isinstance(P, numbers.Real) or not _whole_number(P, 1):
            raise ModelError(f"cycles: the mesh cycles of a forcing period must be an integer >= 1, got {P!r}")
        set_(self, "cycles", int(P))
        for name in ("omega", "xi0", "fp", "D"):
            set_(self, name, _check_finite(name, getattr(self, name)))
        if self.omega <= 0:
            raise ModelError(f"omega: must be > 0 (mesh frequency ω_e/ω_n), got {self.omega!r}")
        if not math.isfinite(2.0 * math.pi / self.omega):
            raise ModelError(f"omega: too small, the forcing period 2π/ω is not finite (got {self.omega!r})")
        if self.D < 0:
            raise ModelError(f"D (backlash): must be >= 0 (0 means no backlash), got {self.D!r}")
        for amp, ph in SERIES:
            a = _as_tuple(amp, getattr(self, amp), self.cycles)
            p = _as_tuple(ph, getattr(self, ph), self.cycles)
            if len(p) > len(a) or 0 < len(p) < len(a):
                raise ModelError(
                    f"{ph}: {len(p)} phases given for {len(a)} {amp} harmonics; give one phase per harmonic, "
                    "or none (all 0)"
                )
            set_(self, amp, a)
            set_(self, ph, p + (0.0,) * (len(a) - len(p)))
        if self.evaluation not in EVALUATIONS:
            raise ModelError(f"evaluation: one of {', '.join(EVALUATIONS)}, got {self.evaluation!r}")
        if (self.evaluation == "table") != bool(self.table):
            raise ModelError('table: evaluation = "table" takes a table (phase, k, e), and a table needs it')
        if self.table:
            set_(self, "table", check_table(self.table, self.cycles))
        set_(self, "torque_orders", _normalise_orders(self.torque_orders))
        if self.torque_orders:
            M = _orders_multiple(self.torque_orders, self.cycles)
            if self.table and M != self.cycles:
                raise ModelError(
                    f"torque_orders: a table evaluated as given spans {self.cycles} mesh cycle(s); orders whose "
                    f"forcing period is {M} mesh cycles need the series evaluation"
                )
        if sum(abs(k) for k in self.kappa) >= MAX_KAPPA_SUM and not (
            (self.cycles > 1 or self.table) and stiffness_minimum(self.kappa, self.phi_k) > 0.0
        ):
            raise ModelError(
                f"kappa: sum of |kappa_r| must be < {MAX_KAPPA_SUM} so the mesh stiffness stays positive, "
                f"got {sum(abs(k) for k in self.kappa):g}"
            )

    # ------------------------------------------------------------------ derived quantities
    @property
    def period(self) -> float:
        """Mesh period T = 2π/ω in non-dimensional time τ (the forcing period when ``cycles`` is 1)."""
        return 2.0 * math.pi / self.omega

    @property
    def forcing_omega(self) -> float:
        """The forcing frequency ω/P whose harmonics the series are (ω itself when ``cycles`` is 1); with torque
        orders ω/M, M the mesh cycles of the forcing period (:meth:`period_multiple`)."""
        return self.omega / self.period_multiple()

    def forcing_model(self) -> GearModel:
        """The same equation with one forcing period as its unit: frequency ω/P, ``cycles`` 1 (itself when P = 1).

        For tools written for one-cycle models (the 1-DOF harmonic balance): its ω is the forcing frequency
        ω/P, so a value of ``omega`` there is P times smaller than the mesh frequency.
        """
        M = self.period_multiple()
        if M == 1:
            return self
        s = M // self.cycles  # series harmonic j (of ω/P) is harmonic j·s of ω/M (s = 1 without torque orders)
        spread = {}
        for k in SERIES_FIELDS:
            row = [0.0] * (s * len(getattr(self, k)))
            row[s - 1 :: s] = getattr(self, k)
            spread[k] = tuple(row)
        orders = tuple((q * M, a, p) for q, a, p in self.torque_orders)
        return self.replace(omega=self.forcing_omega, cycles=1, torque_orders=orders, **spread)

    @property
    def n_harmonics(self) -> int:
        """Largest number of harmonics among the damping, stiffness and STE series (with torque orders: the
        highest harmonic of the forcing frequency ω/M that any series or order reaches)."""
        n = max(len(self.xi), len(self.kappa), len(self.eps))
        if self.torque_orders:
            M = self.period_multiple()
            return max(n * (M // self.cycles), max(int(q * M) for q, _, _ in self.torque_orders))
        return n

    # ------------------------------------------------------------------ the system protocol
    def parameters(self) -> dict[str, float]:
        """Every parameter by its canonical name (scalars, and each harmonic and phase present)."""
        out: dict[str, float] = {}
        for name, fam in FAMILIES.items():
            value = getattr(self, name)
            if fam.series:
                out.update({f"{name}{k + 1}": v for k, v in enumerate(value)})
            else:
                out[name] = value
        return out

    def contact_boundaries(self) -> tuple[Boundary, ...]:
        """The switching surfaces of the non-smooth element: the mesh's dead zone at u = ±D."""
        return (Boundary("mesh", (1.0, 0.0), self.D),)

    @property
    def sampling_period(self) -> float:
        """The stroboscopic sampling period: the forcing period 2π/(ω/P) = P·T."""
        return 2.0 * math.pi / self.forcing_omega

    def period_multiple(self) -> int:
        """The forcing repeats after P = ``cycles`` mesh periods (1 unless an excitation spans several); with
        torque orders after M, the least common multiple of P and the orders' denominators."""
        if self.torque_orders:
            return _orders_multiple(self.torque_orders, self.cycles)
        return self.cycles

    @property
    def elements(self) -> tuple[Element, ...]:
        """The one non-smooth element: the mesh, half backlash D."""
        return (Element("mesh", self.D, "mesh"),)

    #: The reference element (the mesh).
    reference: ClassVar[int] = 0

    def element_series(self, x: np.ndarray, tau: np.ndarray | float) -> np.ndarray:
        """(u, u') of the mesh for states x (..., 2): shape (..., 1, 2)."""
        return np.asarray(x, dtype=float)[..., None, :]

    def rigid_basis(self) -> np.ndarray:
        """No rigid-body mode: an empty (1, 0) basis."""
        return np.zeros((1, 0))

    def initial_state(self, u0: float = 0.0, v0: float = 0.0) -> np.ndarray:
        """The state (u0, v0)."""
        return np.array([u0, v0], dtype=float)

    def element_forces(self, tau: np.ndarray, deltas: np.ndarray) -> np.ndarray:
        """The mesh force F_n/(k0 b_c) = C(θ) u′ + K(θ) f(u; D) at θ = ω τ, from (u, u') of the mesh.

        Parameters
        ----------
        tau : ndarray (K,)
            Times τ, with θ ≡ 0 at τ = 0.
        deltas : ndarray (K, 1, 2)
            u and u′ at those times (:meth:`element_series`).

        Returns
        -------
        ndarray (K, 1)
            The force in units of k0 b_c (a table evaluated as given where the model has one).
        """
        tau = np.asarray(tau, dtype=float)
        d = np.asarray(deltas, dtype=float)
        u, v = d[:, 0, 0], d[:, 0, 1]
        th = self.forcing_omega * tau
        if self.evaluation == "table":  # the stiffness the accurate mode evaluates: the table as given
            (C,) = series_values(self.coefficients(), th, (0,))
            K = table_values(self.table, self.cycles, th)[0]
        else:
            C, K = series_values(self.coefficients(), th, (0, 1))
        return (C * v + K * self.restoring(u))[:, None]

    def static_force(self) -> float:
        """The static mesh force: the mean load f_p."""
        return self.fp

    def mean_trace(self) -> float:
        """Mean trace of the Jacobian over a period: −2ξ0 (the damping harmonics average to zero)."""
        return -2.0 * self.xi0

    def hb_form(self, period: int = 1) -> Any:
        """The equation for harmonic balance (:func:`geardyn.analysis.hb.form.pair_form`): one coordinate u, one
        element with V = [[1]]."""
        from .analysis.hb.form import pair_form

        return pair_form(self, period)

    def report(
        self, res: Any = None, point: int = 0, tau: Any = None, deltas: Any = None, extrema: Any = None
    ) -> dict[str, Any]:
        """Nothing beyond the summary's own keys (they are the mesh's)."""
        return {}

    @property
    def backend(self) -> Any:
        """The 1-DOF kernel's backend, :data:`geardyn.backend.PAIR`."""
        from .backend import PAIR

        return PAIR

    @staticmethod
    def pack(models: Iterable[GearModel]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Kernel arrays of a batch of models (see :func:`pack_models`)."""
        return pack_models(models)

    def replace(self, **changes: Any) -> GearModel:
        """Return a copy with fields changed (validated anew).

        A series whose amplitudes change while its phases do not keeps its phases, extended by zeros to the new
        harmonic count (or cut to it where the phases cut off are all zero): the phases a model holds were
        padded for its amplitudes, not given for the new ones.
        """
        for amp, ph in SERIES:
            if amp in changes and ph not in changes:
                v = changes[amp]
                n = 0 if v is None else 1 if np.isscalar(v) else len(v)
                old = getattr(self, ph)
                if n >= len(old):
                    changes[ph] = old + (0.0,) * (n - len(old))
                elif not any(old[n:]):
                    changes[ph] = old[:n]
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ parameters by name
    def get(self, name: str) -> float:
        """Value of the parameter ``name`` (see :data:`PARAMETER_HELP`); missing harmonics are 0."""
        attr, idx = slot(name)
        if idx is None:
            return getattr(self, attr)
        seq = getattr(self, attr)
        return seq[idx] if idx < len(seq) else 0.0

    def with_param(self, name: str, value: float) -> GearModel:
        """Copy with the parameter ``name`` set to ``value`` (harmonic series extended as needed)."""
        attr, idx = slot(name)
        return self.replace(**({attr: value} if idx is None else series_change(self, attr, idx, value)))

    # ------------------------------------------------------------------ evaluation
    def coefficients(self, n_harmonics: int | None = None) -> np.ndarray:
        """Fourier coefficients of the three periodic coefficient functions.

        Returns an array ``c`` of shape ``(3, H + 1, 2)`` with
        ``X(θ) = Σ_j c[i, j, 0] cos(jθ) + c[i, j, 1] sin(jθ)`` for
        ``X = C`` (i = 0, the full damping term 2ξ(θ)), ``K`` (i = 1, stiffness 1 + Σκ cos) and
        ``F`` (i = 2, forcing f_p + ω² Σ l² ε_l cos), θ the phase of the forcing frequency
        :attr:`forcing_omega` (ω/P; the mesh phase when ``cycles`` is 1).
        """
        H = self.n_harmonics if n_harmonics is None else n_harmonics
        M = self.period_multiple()  # with torque orders the harmonics are of ω/M, M = period_multiple()
        s = M // self.cycles  # series harmonic j (of ω/P) is harmonic j·s of ω/M
        c = np.zeros((3, H + 1, 2))
        c[0, 0, 0] = 2.0 * self.xi0
        c[1, 0, 0] = 1.0
        c[2, 0, 0] = self.fp
        w2 = (self.omega / self.cycles) ** 2
        for i, (amp, phase) in enumerate(SERIES):
            for j, (a, ph) in enumerate(zip(getattr(self, amp), getattr(self, phase)), 1):
                scale = (2.0, 1.0, w2 * j * j)[i]  # 2ξ, κ, ω²j²ε
                c[i, j * s, 0] = scale * a * math.cos(ph)
                c[i, j * s, 1] = -scale * a * math.sin(ph)
        for q, a, ph in self.torque_orders:
            idx = int(q * M)
            c[2, idx, 0] += a * math.cos(ph)
            c[2, idx, 1] -= a * math.sin(ph)
        return c

    def restoring(self, u: np.ndarray | float) -> np.ndarray:
        """Dead-zone function f(u; D) (non-dimensional)."""
        u = np.asarray(u, dtype=float)
        return u - np.clip(u, -self.D, self.D)

    def rhs(self, tau: float, y: Sequence[float]) -> np.ndarray:
        """Right-hand side of the first-order system y = (u, u') at time τ (plain NumPy, for references; a table
        evaluated as given: between its nodes, where F = f_p, the STE acting at the nodes only)."""
        th = self.forcing_omega * tau
        cf = pack_models([self])[0][0] if self.table else self.coefficients()
        j = np.arange(cf.shape[1])
        cj, sj = np.cos(j * th), np.sin(j * th)
        C, K, F = (cf[i, :, 0] @ cj + cf[i, :, 1] @ sj for i in range(3))
        if self.table:
            K = K + float(table_values(self.table, self.cycles, np.array(th))[0])
        u, v = y
        return np.array([v, F - C * v - K * float(self.restoring(u))])

    def to_dict(self) -> dict[str, Any]:
        """Plain-dict form (JSON-serialisable)."""
        d = asdict(self)
        if d["cycles"] == 1:  # the form of every model without a multi-cycle excitation
            del d["cycles"]
        if d["evaluation"] == "series":  # likewise without a table evaluated as given
            del d["evaluation"], d["table"]
        elif d["table"]:
            d["table"] = [list(c) for c in d["table"]]
        if d["torque_orders"]:
            d["torque_orders"] = _orders_to_dicts(self.torque_orders)
        else:  # the form of every model without torque orders
            del d["torque_orders"]
        return {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)

    def to_attrs(self) -> str:
        """The model as a result stores it (its JSON, :meth:`to_json`); :meth:`from_attrs` is the inverse."""
        return self.to_json()

    @classmethod
    def from_attrs(cls, text: str) -> GearModel:
        """The model of :meth:`to_attrs` text.

        Examples
        --------
        >>> m = GearModel(omega=0.8, kappa=(0.2, 0.05))
        >>> GearModel.from_attrs(m.to_attrs()) == m
        True
        """
        return cls.from_dict(json.loads(text))

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> GearModel:
        known = {f.name for f in fields(cls)}
        if unknown := set(d) - known:
            raise ModelError(f"unknown model field(s) {sorted(unknown)}; allowed: {sorted(known)}")
        return cls(**d)


#: The paper's Table 1 non-dimensional values (ω not given there).
PAPER_DEFAULTS = GearModel()


@dataclass(frozen=True)
class IntegrationOptions:
    """How a trajectory is integrated and sampled.

    Parameters
    ----------
    dtau : float
        Target step Δτ (non-dimensional); the step used is h = T/ceil(T/Δτ) so that each forcing
        period holds a whole number of steps and the Poincaré section is sampled exactly.
    transient : int
        Forcing periods integrated and discarded before recording.
    periods : int
        Forcing periods recorded (one Poincaré point each).
    accurate : bool
        Locate the contact-boundary crossings u = ±D inside each step and split the step there
        (4th order through contact changes; slower).  The default mode steps straight through the
        kink of f(u), which lowers the order (see ``docs/model.md``).
    adaptive : bool
        Adaptive transient: ``transient`` becomes a maximum.  Each point stops its transient as
        soon as its Poincaré sequence has converged onto a period-n cycle (n up to
        ``geardyn.analysis.classify.MAX_PERIOD``) to within :attr:`ADAPTIVE_TOL`, at a period
        count congruent to ``transient`` modulo n, so that its recorded periods are those of the
        fixed-transient run; a converged point records one cycle and repeats it over ``periods``
        (without exponents).  Points that do not converge run the full transient
        (``docs/performance.md``).

    Attributes
    ----------
    ADAPTIVE_TOL : float
        Tolerance of the adaptive transient: the estimated distance of a Poincaré point to its
        cycle (the Aitken estimate d²/(e − d) of two successive n-period differences e, d), relative
        to max(1, |u|, |u'|).

    Examples
    --------
    >>> from geardyn import IntegrationOptions
    >>> IntegrationOptions(transient=100, periods=50)
    IntegrationOptions(dtau=0.01, transient=100, periods=50, accurate=False, adaptive=False)
    >>> IntegrationOptions(periods=50).replace(accurate=True).accurate
    True
    """

    #: Tolerance of the adaptive transient (estimated distance to the cycle, relative to max(1, |point|)).
    ADAPTIVE_TOL: ClassVar[float] = 1.0e-10

    dtau: float = DEFAULT_DTAU
    transient: int = DEFAULT_TRANSIENT
    periods: int = DEFAULT_PERIODS
    accurate: bool = False
    adaptive: bool = False

    def __post_init__(self) -> None:
        dt = _check_finite("dtau", self.dtau)
        if dt <= 0:
            raise ModelError(f"dtau: must be > 0 and smaller than the forcing period, got {self.dtau!r}")
        object.__setattr__(self, "dtau", dt)
        for name, lo in (("transient", 0), ("periods", 1)):
            v = getattr(self, name)
            if not _whole_number(v, lo):
                raise ModelError(f"{name}: must be an integer >= {lo}, got {v!r}")
            object.__setattr__(self, name, int(v))
        object.__setattr__(self, "accurate", bool(self.accurate))
        object.__setattr__(self, "adaptive", bool(self.adaptive))
        if self.adaptive and self.accurate:
            raise ModelError(
                "adaptive: the adaptive transient runs in the default mode only; drop --accurate or --adaptive"
            )

    def check_for(self, omega: float) -> None:
        """Refuse a step that is not smaller than the forcing period 2π/ω."""
        T = 2.0 * math.pi / omega
        if self.dtau >= T:
            raise ModelError(f"dtau: must be smaller than the forcing period T = 2π/ω = {T:.6g}, got {self.dtau!r}")

    def replace(self, **changes: Any) -> IntegrationOptions:
        return dataclasses.replace(self, **changes)
