"""Backends: the kernel contract, written once.

A backend integrates a packed batch of systems of one kind.  It is the only code that calls a kernel:
:data:`PAIR` serves :class:`~geardyn.model.GearModel` (:mod:`geardyn._kernel`, the 1-DOF mesh in SIMD
lanes), :data:`MESH` serves :class:`~geardyn.systems.SystemModel` (:mod:`geardyn._kernel_ndof`, mesh-vector
systems).  Both return the same :class:`RawRun`; :mod:`geardyn.integrate` (the door every analysis uses)
turns it into one batch result.  A new kind of system is a new backend, not a new integrator module.

The contract
------------
``pack(models)``
    The kernel arrays of a batch (the models' own ``pack``).
``natural_steps(models, packed, dtau)``
    N = ceil(T_f/Δτ) RK4 steps per sampling period for each point.
``run(models, packed, nsteps, state0, transient, record, mode, accurate, ...)``
    Integrate ``transient`` sampling periods, then record ``record``; ``mode`` is one of :data:`MODES`:
    ``"none"``, ``"lyapunov"`` (Gram–Schmidt logs per recorded period), ``"monodromy"`` (the raw tangent
    product over the recorded periods), ``"continue"`` (Lyapunov from a given tangent basis; pair only).
    The kernels' arithmetic is theirs: a backend only allocates the outputs and calls ``run_batch``.
    ``watch(poincare)``, when given, receives the Poincaré output before the kernel runs, filled with NaN
    until each recorded period writes its row (mesh-vector kernel only; the pair's ignores it), so that
    another thread can follow a long run (:func:`geardyn.integrate.integrate_batch` with ``progress``).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from . import _kernel as _K1
from ._kernel import (  # the statistics' indices, statuses and bound: the same in both kernels
    DIVERGENCE_BOUND, NSTAT, S_N, S_NBACK, S_NDRIVE, S_NSEP, S_UMAX, S_UMIN, S_USQ, S_USUM, S_VMAX, S_VMIN,
    ST_DIVERGED, ST_OK,
)
from .errors import ModelError
from .labels import MAX_PERIOD

__all__ = ["RawRun", "Backend", "PairBackend", "MeshBackend", "PAIR", "MESH", "MODES",
           "S_UMIN", "S_UMAX", "S_USUM", "S_USQ", "S_VMIN", "S_VMAX", "S_NDRIVE", "S_NSEP", "S_NBACK", "S_N",
           "NSTAT", "ST_OK", "ST_DIVERGED", "DIVERGENCE_BOUND"]

#: Integration modes of :meth:`Backend.run`.
MODES = ("none", "lyapunov", "monodromy", "continue")


@dataclass
class RawRun:
    """The raw arrays of one kernel run of P points (state dimension d, E elements).

    Attributes
    ----------
    poincare : ndarray (P, record or 0, d)
    end_state : ndarray (P, d)
    stats : ndarray (P, E, NSTAT)
        Streaming statistics of every element's deflection over the recorded periods.
    tan_log : ndarray (P, record or 0, d)
    tangent : ndarray (P, d, d)
    status : ndarray (P,) int64
    hist : ndarray (P, K, d)
        The state at every step of the last (K − 1)/N periods (K = ``hist_len``).
    """

    poincare: np.ndarray
    end_state: np.ndarray
    stats: np.ndarray
    tan_log: np.ndarray
    tangent: np.ndarray
    status: np.ndarray
    hist: np.ndarray


def _buffers(P: int, d: int, record: int, record_poincare: bool, lyapunov: bool, hist_len: int):
    return (np.zeros((P, record if record_poincare else 0, d)), np.zeros((P, d)),
            np.zeros((P, record if lyapunov else 0, d)), np.zeros((P, d, d)), np.zeros(P, dtype=np.int64),
            np.zeros((P, hist_len, d)))


class Backend(abc.ABC):
    """The kernel contract (see the module docstring); subclasses call one kernel."""

    #: The backend's name.
    name = ""
    #: The state's coordinates, as messages name them.
    coords = "x"

    @staticmethod
    def pack(models: Sequence[Any]) -> Any:
        """The kernel arrays of a batch of systems of one kind."""
        models = list(models)
        return type(models[0]).pack(models)

    def natural_steps(self, models: Sequence[Any], packed: Any, dtau: float) -> np.ndarray:
        """RK4 steps per sampling period N = ceil(T_f/Δτ) of every point (int64, (P,))."""
        T = np.array([m.sampling_period for m in models], dtype=float)
        return np.ceil(T / dtau).astype(np.int64)

    def initial_states(self, models: Sequence[Any]) -> np.ndarray:
        """The (P, d) default initial states: each system's ``initial_state()``."""
        return np.ascontiguousarray(np.stack([m.initial_state() for m in models]))

    @abc.abstractmethod
    def run(self, models: Sequence[Any], packed: Any, nsteps: np.ndarray, state0: np.ndarray, transient: int,
            record: int, mode: str, accurate: bool, *, record_poincare: bool = True, hist_len: int = 0,
            adaptive_tol: float = 0.0, tangent0: np.ndarray | None = None,
            watch: Callable[[np.ndarray], None] | None = None) -> RawRun:
        """Run the batch in ``mode`` and return its raw arrays (each backend calls its own kernel)."""


class PairBackend(Backend):
    """The 1-DOF pair's kernel (:mod:`geardyn._kernel`): packed ``(coef, D, omega)``, state (u, u'), one element."""

    name = "pair"
    coords = "(u0, v0)"

    def initial_states(self, models: Sequence[Any]) -> np.ndarray:
        return np.zeros((len(models), 2))  # every pair's initial_state() is (0, 0)

    def natural_steps(self, models: Sequence[Any], packed: Any, dtau: float) -> np.ndarray:
        T = 2.0 * np.pi / np.asarray(packed[2], dtype=float)  # as geardyn.model.steps_per_period
        return np.ceil(T / dtau).astype(np.int64)

    def run(self, models, packed, nsteps, state0, transient, record, mode, accurate, *, record_poincare=True,
            hist_len=0, adaptive_tol=0.0, tangent0=None, watch=None) -> RawRun:
        K = _K1
        coef, D, omega = packed[:3]
        table = packed[3] if len(packed) > 3 else None  # models evaluated as tables (accurate mode)
        P, d = coef.shape[0], 2
        lyapunov = mode in ("lyapunov", "continue")
        poincare, end_state, tan_log, tan_out, status, hist = _buffers(P, d, record, record_poincare, lyapunov,
                                                                        hist_len)
        stats = np.zeros((P, K.NSTAT))
        if tangent0 is not None:  # K.TAN_CONTINUE: the kernel starts the tangent basis from these
            tan_out[:] = tangent0
        tan = {"none": K.TAN_NONE, "lyapunov": K.TAN_LYAPUNOV, "monodromy": K.TAN_MONODROMY,
               "continue": K.TAN_CONTINUE}[mode]
        args = (coef, D, omega, nsteps, state0, int(transient), int(record), int(tan), bool(accurate), poincare,
                end_state, stats, tan_log, tan_out, status, hist)
        if adaptive_tol > 0.0:  # the adaptive transient, seeking cycles up to MAX_PERIOD
            K.run_batch(*args, float(adaptive_tol), MAX_PERIOD, table=table)
        else:
            K.run_batch(*args, table=table)
        return RawRun(poincare, end_state, stats[:, None, :], tan_log, tan_out, status, hist)


class MeshBackend(Backend):
    """The mesh-vector kernel (:mod:`geardyn._kernel_ndof`): packed :class:`~geardyn.systems.SystemArrays`,
    state (q̃, q̃'), the meshes then the clearances.  The adaptive transient is not available
    (``adaptive_tol`` is ignored: every point runs its full transient)."""

    name = "mesh"
    coords = "(q̃, q̃')"

    def run(self, models, packed, nsteps, state0, transient, record, mode, accurate, *, record_poincare=True,
            hist_len=0, adaptive_tol=0.0, tangent0=None, watch=None) -> RawRun:
        from . import _kernel_ndof as K  # imported by the first mesh-vector run: a pair never needs it

        if mode == "continue":
            raise ModelError("tangent0: continuing a tangent basis is not available for mesh-vector systems")
        P, d = len(models), models[0].state_dim
        E = len(models[0].elements)
        lyapunov = mode == "lyapunov"
        poincare, end_state, tan_log, tan_out, status, hist = _buffers(P, d, record, record_poincare, lyapunov,
                                                                        hist_len)
        stats = np.zeros((P, E, K.NSTAT))
        tper = np.array([m.sampling_period for m in models], dtype=float)
        tan = {"none": K.TAN_NONE, "lyapunov": K.TAN_LYAPUNOV, "monodromy": K.TAN_MONODROMY}[mode]
        if watch is not None:  # every recorded row is written by the kernel (NaN after a divergence)
            poincare.fill(np.nan)
            watch(poincare)
        K.run_batch(packed, tper, nsteps, state0, int(transient), int(record), int(tan), bool(accurate),
                    poincare, end_state, stats, tan_log, tan_out, status, hist)
        return RawRun(poincare, end_state, stats, tan_log, tan_out, status, hist)


#: The backend of :class:`~geardyn.model.GearModel`.
PAIR = PairBackend()
#: The backend of :class:`~geardyn.systems.SystemModel`.
MESH = MeshBackend()
