"""The pair's kernel arrays: a batch of :class:`~geardyn.model.GearModel` packed for :mod:`geardyn._kernel`.

:func:`pack_models` packs models; :func:`pack_points` packs a grid's parameter points without a model per
point, bit for bit ``pack_models`` of their models, validated as the model validates; :class:`PointModels`
is the pair's :class:`~geardyn.system.Batch` on those arrays (what :meth:`geardyn.backend.PairBackend.points`
supplies to a sweep).  The bound on the stiffness series (:func:`stiffness_minimum`, :data:`MAX_KAPPA_SUM`)
and the step count (:func:`steps_per_period`) are here because the model's validation and the packing share
them.  This module sits below :mod:`geardyn.model` and :mod:`geardyn.backend` and imports neither.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from .errors import ModelError
from .meshtable import kernel_table
from .params import slot
from .system import Batch, build_models

__all__ = [
    "MAX_KAPPA_SUM",
    "PointModels",
    "SERIES",
    "SERIES_FIELDS",
    "pack_models",
    "pack_points",
    "stiffness_minimum",
    "steps_per_period",
]

#: The harmonic series of the model, each amplitude field with its phase field (ξ_k with φ_ck, κ_r with φ_kr,
#: ε_l with φ_el), in the order of the coefficient functions C, K, F.
SERIES = (("xi", "phi_c"), ("kappa", "phi_k"), ("eps", "phi_e"))
#: Their fields, amplitudes and phases, in that order.
SERIES_FIELDS = tuple(field for pair in SERIES for field in pair)

#: Largest Σ|κ_r| accepted: the mesh stiffness 1 + Σ κ_r cos(...) must stay positive.
MAX_KAPPA_SUM = 1.0


def stiffness_minimum(kappa: Sequence[float], phi_k: Sequence[float]) -> float:
    """A certified lower bound of the relative stiffness 1 + Σ_j κ_j cos(jθ + φ_j) over a period.

    The series is sampled at M ≥ 8H equally spaced angles (an FFT, exact to rounding); between two
    samples it departs from the nearer by at most max|K′|·π/M ≤ (Σ j|κ_j|)·π/M, which is subtracted.
    M is chosen so that this margin is at most 0.02.

    Parameters
    ----------
    kappa, phi_k : sequence of float
        Amplitudes and phases (rad), j = 1 …

    Returns
    -------
    float
        min over the samples − the margin (> 0 proves the stiffness positive for every θ).
    """
    a = np.asarray(kappa, dtype=float)
    if a.size == 0:
        return 1.0
    p = np.asarray(phi_k, dtype=float)
    slope = float(np.sum(np.arange(1, a.size + 1) * np.abs(a)))
    M = 1 << int(math.ceil(math.log2(max(8 * a.size + 8, 50.0 * math.pi * slope, 64.0))))
    X = np.zeros(M // 2 + 1, dtype=complex)
    X[0] = M
    X[1 : a.size + 1] = 0.5 * M * a * np.exp(1j * p)
    values = np.fft.irfft(X, M)
    return float(values.min()) - slope * math.pi / M


def steps_per_period(omega: float | np.ndarray, dtau: float) -> np.ndarray:
    """Number of RK4 steps per forcing period, N = ceil(T/Δτ) with T = 2π/ω, so h = T/N <= Δτ.

    Parameters
    ----------
    omega : float or ndarray
        Mesh frequencies ω.
    dtau : float
        Target step Δτ.

    Returns
    -------
    ndarray of int64
        N per frequency (0-d for a scalar ω).
    """
    T = 2.0 * np.pi / np.asarray(omega, dtype=float)
    return np.ceil(T / dtau).astype(np.int64)


def pack_models(models: Iterable[Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pack models into kernel arrays.

    Parameters
    ----------
    models : iterable of GearModel
        The points of a batch.

    Returns
    -------
    coef : ndarray (P, 3, H+1, 2)
        As in :meth:`GearModel.coefficients`, H the largest harmonic count (zero-padded).
    D : ndarray (P,)
        Half backlashes.
    omega : ndarray (P,)
        Forcing frequencies ω/P (:attr:`GearModel.forcing_omega`; the mesh frequencies when P = 1).
    table : (ndarray (P, M, 7), ndarray (P,)), only when a model is evaluated as a table
        Its :func:`geardyn.meshtable.kernel_table` rows (zero-padded) and node counts (0: series); the
        stiffness and STE series of such a model are left out of ``coef`` (K = 0, F = f_p).

    Raises
    ------
    ModelError
        For no model.
    """
    models = list(models)
    if not models:
        raise ModelError("empty parameter grid: no model to integrate")
    H = max(m.n_harmonics for m in models)
    coef = np.stack([m.coefficients(H) for m in models])
    D = np.array([m.D for m in models])
    omega = np.array([m.forcing_omega for m in models])
    if all(m.evaluation == "series" for m in models):
        return np.ascontiguousarray(coef), D, omega
    rows = [kernel_table(m.table, m.cycles) if m.table else np.zeros((0, 7)) for m in models]
    tab = np.zeros((len(models), max(r.shape[0] for r in rows), 7))
    for i, r in enumerate(rows):
        tab[i, : r.shape[0]] = r
        if r.shape[0]:
            coef[i, 1] = 0.0
            coef[i, 2, 1:] = 0.0
    return np.ascontiguousarray(coef), D, omega, (tab, np.array([max(r.shape[0] - 1, 0) for r in rows]))


def _per_value(fn, x: np.ndarray) -> np.ndarray:
    """``fn`` (a ``math`` function) of every entry of ``x``, evaluated once per distinct value.

    The kernel arrays must hold the bits :meth:`GearModel.coefficients` computes with ``math``
    (libm), which NumPy's vectorised ``cos``/``sin`` do not promise; a swept column holds few
    distinct values.  A signed zero keeps its sign (``np.unique`` merges -0.0 and 0.0).
    """
    u, inv = np.unique(x, return_inverse=True)
    out = np.array([fn(float(v)) for v in u], dtype=float)[inv.ravel()]
    return np.where(x == 0.0, fn(0.0) if fn is not math.sin else x, out)


def _square(w: float) -> float:
    """ω² as :meth:`GearModel.coefficients` computes it (``w**2``), infinite where it overflows."""
    try:
        return w**2
    except OverflowError:
        return math.inf


def pack_points(base: Any, names: Sequence[str], points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Kernel arrays of parameter points without a :class:`GearModel` per point.

    Bit for bit ``pack_models(build_models(base, names, points))`` (:func:`geardyn.system.build_models`):
    ``base`` with ``names[j]`` set to ``points[i, j]`` in that order, validated as the model
    validates (a refused point raises the model's own error, for the first such point).

    Parameters
    ----------
    base : GearModel
        The model every point starts from.
    names : sequence of str
        Parameter names (any alias), one per column of ``points``.
    points : ndarray (P, len(names))
        The parameter values of each point.

    Returns
    -------
    coef, D, omega : ndarray
        As :func:`pack_models` (``omega`` the forcing frequencies ω/P of a multi-cycle ``base``).

    Raises
    ------
    ModelError
        For no point, or a point the model refuses (ω <= 0, D < 0, Σ|κ_r| >= 1, a non-finite value).
    """
    if base.torque_orders:  # the forcing's harmonics are those of ω/M: packed through the models themselves
        return pack_models(build_models(base, names, points))
    if base.evaluation != "series":
        raise ModelError(
            'evaluation "table": a parameter grid evaluates series models only; the table is '
            "evaluated as given by simulate, orbit and lyapunov with --accurate"
        )
    names = list(names)
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    P = pts.shape[0]
    if P == 0:
        raise ModelError("empty parameter grid: no model to integrate")
    # the first point's model: validates it and fixes which harmonics exist (the same for all)
    proto = build_models(base, names, pts[:1])[0]
    H = proto.n_harmonics
    # the fields of every point, in the structure of the first (series zero-padded as with_param pads them)
    val = {k: np.full(P, float(getattr(base, k))) for k in ("omega", "xi0", "fp", "D")}
    for k in SERIES_FIELDS:
        row = np.zeros(len(getattr(proto, k)))
        row[: len(getattr(base, k))] = getattr(base, k)
        val[k] = np.tile(row, (P, 1))
    ok = np.ones(P, dtype=bool)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        for j, p in enumerate(names):  # validated after every assignment, as each with_param validates its model
            attr, idx = slot(p)
            if idx is None:
                val[attr][:] = pts[:, j]
            else:
                val[attr][:, idx] = pts[:, j]
            ok &= np.isfinite(pts[:, j]) & (val["omega"] > 0) & np.isfinite(2.0 * math.pi / val["omega"])
            ok &= ~(val["D"] < 0)
            ksum = np.zeros(P)
            for r in range(val["kappa"].shape[1]):
                ksum = ksum + np.abs(val["kappa"][:, r])
            cert = False
            if base.cycles > 1 and np.any(ksum >= MAX_KAPPA_SUM):  # the model's certified minimum, per distinct row
                rows = np.hstack([val["kappa"], val["phi_k"]])
                uniq, inv = np.unique(rows, axis=0, return_inverse=True)
                H0 = val["kappa"].shape[1]
                cert = np.array([stiffness_minimum(r[:H0], r[H0:]) > 0.0 for r in uniq])[inv.ravel()]
            ok &= (ksum < MAX_KAPPA_SUM) | cert
    if not np.all(ok):
        bad = int(np.argmin(ok))
        build_models(base, names, pts[bad : bad + 1])  # raises the model's own error
        raise ModelError(f"point {bad}: refused by the model")  # pragma: no cover - the checks above are the model's
    coef = np.zeros((P, 3, H + 1, 2))
    val["omega"] = val["omega"] / base.cycles  # the series are harmonics of the forcing frequency ω/P
    w2 = _per_value(_square, val["omega"])
    with np.errstate(over="ignore", invalid="ignore"):  # a value so large that it overflows: the point diverges
        coef[:, 0, 0, 0] = 2.0 * val["xi0"]
        coef[:, 1, 0, 0] = 1.0
        coef[:, 2, 0, 0] = val["fp"]
        for i, (amp, ph) in enumerate(SERIES):
            for j in range(1, val[amp].shape[1] + 1):
                scale = (2.0, 1.0, w2 * j * j)[i]  # 2ξ, κ, ω²j²ε, as GearModel.coefficients
                a = val[amp][:, j - 1]
                phase = val[ph][:, j - 1]
                coef[:, i, j, 0] = scale * a * _per_value(math.cos, phase)
                coef[:, i, j, 1] = -scale * a * _per_value(math.sin, phase)
    return np.ascontiguousarray(coef), val["D"], val["omega"]


class PointModels(Batch):
    """The pair's :class:`~geardyn.system.Batch` of a grid's parameter points, packed without a model per point.

    A sequence of :class:`~geardyn.model.GearModel` (``base`` with ``names[j]`` set to ``points[i, j]``, as
    :func:`~geardyn.system.build_models`) that holds the kernel arrays of :func:`pack_points` and builds a
    model only when one is indexed; a slice or an index array gives the :class:`PointModels` of those points.

    Parameters
    ----------
    base : GearModel
        The model every point starts from.
    names : sequence of str
        Parameter names, one per column of ``points``.
    points : ndarray (P, len(names))
        The parameter values of each point.

    Attributes
    ----------
    base, names, points
        As given (``points`` as a float array).
    coef, D, omega : ndarray
        The kernel arrays (:func:`pack_models` of the models).

    Raises
    ------
    ModelError
        For no point or a point the model refuses.

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> b = PointModels(GearModel(), ["omega"], [[0.5], [1.0]])
    >>> len(b), b[1].omega, b.reference_gaps().tolist()
    (2, 1.0, [1.0, 1.0])
    """

    state_dim = 2
    reference = 0

    def __init__(self, base: Any, names: Sequence[str], points: np.ndarray) -> None:
        self.base = base
        self.names = tuple(str(n) for n in names)
        self.points = np.asarray(points, dtype=float).reshape(-1, len(self.names))
        self.coef, self.D, self.omega = pack_points(base, self.names, self.points)

    def __len__(self) -> int:
        return int(self.points.shape[0])

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, (int, np.integer)):
            return build_models(self.base, self.names, self.points[[int(i)]])[0]
        idx = np.arange(len(self))[i]
        sub = object.__new__(PointModels)  # the rows of arrays already packed and validated
        sub.base, sub.names, sub.points = self.base, self.names, self.points[idx]
        sub.coef, sub.D, sub.omega = self.coef[idx], self.D[idx], self.omega[idx]
        return sub

    def __repr__(self) -> str:
        return f"PointModels({len(self)} points of {', '.join(self.names)})"

    @property
    def backend(self) -> Any:
        return self.base.backend

    def packed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The kernel arrays ``(coef, D, omega)``."""
        return self.coef, self.D, self.omega

    def sampling_periods(self) -> np.ndarray:
        """Forcing periods 2π/(ω/P) of the points."""
        return 2.0 * math.pi / self.omega

    def check_step(self, options: Any) -> None:
        too_long = options.dtau >= 2.0 * math.pi / self.omega
        if np.any(too_long):
            options.check_for(float(self.omega[int(np.argmax(too_long))]))

    def element_gaps(self) -> np.ndarray:
        return self.D[:, None]

    def reference_gaps(self) -> np.ndarray:
        return self.D

    def mean_traces(self) -> np.ndarray:
        """−2ξ0 of every point, from its ξ0 column where ξ0 is swept (no model built)."""
        cols = [j for j, n in enumerate(self.names) if slot(n)[0] == "xi0"]
        if not cols:
            return np.full(len(self), float(self.base.mean_trace()))
        return -2.0 * self.points[:, cols[-1]]

    def reference_section(self, poincare: np.ndarray) -> np.ndarray:
        """The state (u, u') is the mesh's (δ, δ'): the points as they are."""
        return poincare
