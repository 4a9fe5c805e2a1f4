"""Integration of multi-DOF systems (:class:`~geardyn.systems.SystemModel`): batches, trajectories, period maps.

The N-DOF counterpart of :mod:`geardyn.integrate`, with results of the same shapes along the state
axis (length 2n: the state ``x = (q̃, q̃')``), and the only module that talks to
:mod:`geardyn._kernel_ndof`.  :func:`integrate_batch`, :func:`trajectory`, :func:`period_map`,
:func:`state_dim` and :func:`natural_steps` also take a :class:`~geardyn.model.GearModel` and then
hand it to :mod:`geardyn.integrate` unchanged, so code written against the System protocol (the
period map, the orbit tools) works on either kind of system.

Sampling: the step is h = T_f/N with T_f the forcing period (:func:`forcing_period`: p·2π/ω with p
from :meth:`SystemModel.period_multiple`; the base period 2π/ω when the mesh frequencies are
incommensurate, where the samples are then only stroboscopic in the base frequency) and
N = ceil(T_f/Δτ) unless given.

Per-element outputs: element e is mesh e for e < meshes, then the clearances; its deflection is
``δ_m = V[m]·q̃ − E_m(θ)`` (the dynamic transmission error over b_c) or ``δ_c = Vc[c]·q̃``.  The
reference mesh's δ is the 1-DOF model's u: ``u_min``, ``u_max``, ``amplitude``, ``contact_fractions``
and a trajectory's ``u``, ``v`` are those of the reference mesh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from . import _kernel_ndof as K
from ._docfill import MODEL, OPTIONS, POINT, SYSTEM, fill, parameters
from . import integrate as _one
from .integrate import using_threads
from .model import IntegrationOptions

__all__ = [
    "SystemBatchResult", "SystemTrajectory", "forcing_period", "natural_steps", "state_dim",
    "element_names", "initial_state", "element_series", "integrate_batch", "trajectory", "period_map",
]


@parameters(MODEL)
def is_system(model: Any) -> bool:
    """Whether ``model`` is a multi-DOF system (integrated by this module's kernel).

    Returns
    -------
    bool
        True for a :class:`~geardyn.systems.SystemModel`, False for a :class:`~geardyn.model.GearModel`.
    """
    from .systems.assemble import SystemModel

    return isinstance(model, SystemModel)


@parameters(MODEL)
def forcing_period(model: Any) -> float:
    """The sampling period T_f: p·2π/ω (commensurate meshes) or 2π/ω (incommensurate).

    Returns
    -------
    float
        T_f in units of τ (the forcing period 2π/ω of a GearModel).
    """
    if not is_system(model):
        return float(model.period)
    p = model.period_multiple()
    return (p or 1) * model.period


@parameters(MODEL)
def state_dim(model: Any) -> int:
    """Length of the state the kernel integrates: 2n for a system, 2 for the 1-DOF model.

    Returns
    -------
    int
        The length of ``state0`` for this model.
    """
    return int(model.state_dim) if is_system(model) else _one.state_dim(model)


def natural_steps(model: Any, dtau: float) -> int:
    """RK4 steps per forcing period, N = ceil(T_f/Δτ).

    Parameters
    ----------
    model : SystemModel or GearModel
        The model (a GearModel is passed to :func:`geardyn.integrate.natural_steps`).
    dtau : float
        Target step Δτ.

    Returns
    -------
    int
    """
    if not is_system(model):
        return _one.natural_steps(model, dtau)
    return int(math.ceil(forcing_period(model) / dtau))


@fill(SYSTEM)
def element_names(model: Any) -> tuple[str, ...]:
    """The elements of the statistics: the meshes, then the clearances.

    Parameters
    ----------
    {{model}}

    Returns
    -------
    tuple of str
        Mesh names, then clearance names.
    """
    return tuple(m.name for m in model.meshes) + tuple(model.clearance_names)


def _ref_index(model: Any) -> int:
    names = [m.name for m in model.meshes]
    return names.index(model.scaling.reference) if model.scaling.reference in names else 0


@fill(SYSTEM)
def element_series(model: Any, x: np.ndarray, tau: np.ndarray | float) -> np.ndarray:
    """δ and δ' of every element for states x at times τ.

    A mesh's δ is V_m·q̃ minus its transmission error e_m(θ); a clearance's is Vc·q̃.

    Parameters
    ----------
    {{model}}
    x : ndarray (..., 2n)
        States (q̃, q̃').
    tau : ndarray or float
        Times τ, broadcast against the leading axes of ``x``.

    Returns
    -------
    ndarray (..., elements, 2)
        δ and δ' of the meshes, then the clearances.
    """
    x = np.asarray(x, dtype=float)
    n = model.n
    q, v = x[..., :n], x[..., n:]
    theta = model.omega * np.asarray(tau, dtype=float)
    out = []
    for i, m in enumerate(model.meshes):
        c = m.coefficients()
        E = np.zeros_like(theta) + c[2, 0, 0]
        Ed = np.zeros_like(theta)
        for j in range(1, c.shape[1]):
            ph = j * m.ratio * theta
            E = E + c[2, j, 0] * np.cos(ph) + c[2, j, 1] * np.sin(ph)
            Ed = Ed + j * m.ratio * (c[2, j, 1] * np.cos(ph) - c[2, j, 0] * np.sin(ph))
        out.append(np.stack([q @ model.V[i] - E, v @ model.V[i] - model.omega * Ed], axis=-1))
    for i in range(len(model.clearance_names)):
        out.append(np.stack([q @ model.Vc[i], v @ model.Vc[i]], axis=-1))
    return np.stack(out, axis=-2)


def initial_state(model: Any, u0: float = 0.0, v0: float = 0.0) -> np.ndarray:
    """The state at θ = 0 with the reference mesh's (δ, δ') = (u0, v0) and every other mesh's (0, 0).

    The least-norm q̃, q̃' solving ``V q̃ = E(0) + target``, ``V q̃' = ω E'(0) + target'`` (for the
    paper's torsional pair, exactly the 1-DOF start (u0, v0) with the rigid-body coordinate at rest).

    Parameters
    ----------
    model : SystemModel
    u0, v0 : float
        Reference mesh's deflection and its rate at θ = 0.

    Returns
    -------
    ndarray (2n,)
    """
    n = model.n
    M = len(model.meshes)
    zero = np.zeros(2 * n)
    ev = element_series(model, zero, 0.0)[:M]  # (M, 2) = (−E, −ωE')
    tq = -ev[:, 0]
    tv = -ev[:, 1]
    r = _ref_index(model)
    tq[r] += u0
    tv[r] += v0
    pinv = np.linalg.pinv(np.asarray(model.V))
    return np.concatenate([pinv @ tq, pinv @ tv])


def _of_reference(per_element: Any) -> property:
    """The read-only property of the reference mesh's value of the per-element method ``per_element``."""
    return property(lambda self: per_element(self, self.reference),
                    doc=f"``{per_element.__name__}`` of the reference mesh (the 1-DOF model's u).")


@dataclass
@fill(OPTIONS)
class SystemBatchResult(_one._Batch):
    """Results for P points of one system structure (non-dimensional); shapes as :class:`geardyn.integrate.BatchResult`.

    Attributes
    ----------
    poincare : ndarray (P, periods, 2n)
        Full state at the end of each recorded forcing period; NaN where diverged.
    end_state : ndarray (P, 2n)
        State at the end of the integration.
    status : ndarray (P,)
        Kernel status per point (:data:`~geardyn._kernel_ndof.ST_OK` or ``ST_DIVERGED``).
    stats : ndarray (P, elements, NSTAT)
        Statistics of every element's δ (meshes, then clearances), sampled at every step.
    nsteps : ndarray (P,)
        RK4 steps per forcing period of each point.
    lyapunov_log : ndarray (P, periods, 2n) or None
        Logs of the Gram–Schmidt stretch factors per recorded period (Lyapunov runs only).
    tangent : ndarray (P, 2n, 2n) or None
        Tangent matrix at the end (monodromy runs only).
    models : list of SystemModel
        The P points.
    {{options}}
    elements : tuple of str
        Names of the elements of ``stats``: the meshes, then the clearances.
    reference : int
        Index of the reference mesh (whose δ is the 1-DOF model's u).
    """

    elements: tuple[str, ...] = field(default=())
    reference: int = 0

    def _el(self, k: int, e: int | None) -> np.ndarray:
        x = self.stats[:, :, k]
        x = np.where(self.ok[:, None], x, np.nan)
        return x if e is None else x[:, e]

    def _per_sample(self, k: int, e: int | None) -> np.ndarray:
        n = self.stats[:, :, K.S_N]
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.where(n > 0, self.stats[:, :, k] / np.where(n > 0, n, 1.0), np.nan)
        r = np.where(self.ok[:, None], r, np.nan)
        return r if e is None else r[:, e]

    def element_u_min(self, e: int | None = None) -> np.ndarray:
        """Smallest δ (P,) of element e, or (P, elements) for e None."""
        return self._el(K.S_UMIN, e)

    def element_u_max(self, e: int | None = None) -> np.ndarray:
        return self._el(K.S_UMAX, e)

    def element_mean(self, e: int | None = None) -> np.ndarray:
        return self._per_sample(K.S_USUM, e)

    def element_rms(self, e: int | None = None) -> np.ndarray:
        m = self._per_sample(K.S_USUM, e)
        return np.sqrt(np.maximum(self._per_sample(K.S_USQ, e) - m * m, 0.0))

    def element_fractions(self, e: int | None = None) -> np.ndarray:
        """(P, 3) (or (P, elements, 3)) fractions in drive contact, separation, back contact."""
        f = np.stack([self._per_sample(k, None) for k in (K.S_NDRIVE, K.S_NSEP, K.S_NBACK)], axis=-1)
        return f if e is None else f[:, e]

    u_min = _of_reference(element_u_min)
    u_max = _of_reference(element_u_max)
    mean = _of_reference(element_mean)
    rms = _of_reference(element_rms)
    contact_fractions = _of_reference(element_fractions)


@dataclass
@fill(POINT, OPTIONS)
class SystemTrajectory:
    """One trajectory of a system: the full state at every step of its last periods and its batch summary.

    ``u``, ``v`` are the reference mesh's δ and δ'; ``x`` the full state (K, 2n); ``deltas`` (K, elements, 2).

    Attributes
    ----------
    {{model, options}}
    tau : ndarray (K,)
        Times τ of the kept history.
    x : ndarray (K, 2n)
        Full state (q̃, q̃') at those times.
    deltas : ndarray (K, elements, 2)
        δ and δ' of every element (:func:`element_series`).
    summary : SystemBatchResult
        The batch result of the point (Poincaré points and statistics over all recorded periods).
    history_periods : int
        Forcing periods of history kept.
    """

    model: Any
    options: IntegrationOptions
    tau: np.ndarray
    x: np.ndarray
    deltas: np.ndarray
    summary: SystemBatchResult
    history_periods: int = 0

    @property
    def u(self) -> np.ndarray:
        """δ of the reference mesh (K,)."""
        return self.deltas[:, self.summary.reference, 0]

    @property
    def v(self) -> np.ndarray:
        """δ' of the reference mesh (K,)."""
        return self.deltas[:, self.summary.reference, 1]

    @property
    def poincare(self) -> np.ndarray:
        """Poincaré points (periods, 2n)."""
        return self.summary.poincare[0]


def _state_array(models: list[Any], state0: Any) -> np.ndarray:
    if state0 is None:
        return np.ascontiguousarray(np.stack([initial_state(m) for m in models]))
    return _one._state_array(state0, len(models), models[0].state_dim, "(q̃, q̃')")


def _prepare(models: Sequence[Any], options: IntegrationOptions, steps: Any):
    from .systems.assemble import SystemModel

    models = list(models)
    arrays = SystemModel.pack(models)
    tper = np.array([forcing_period(m) for m in models], dtype=float)
    if steps is None:
        for m in models:
            options.check_for(2.0 * math.pi / forcing_period(m))
        nsteps = np.ceil(tper / options.dtau).astype(np.int64)
    else:
        nsteps = _one._steps_array(steps, len(models))
    return models, arrays, tper, nsteps


def _run(models, arrays, tper, nsteps, state0, n_transient, n_record, tangent, accurate, record_poincare=True,
         hist_len=0, lyapunov=False, threads=None):
    P = len(models)
    d = models[0].state_dim
    E = len(element_names(models[0]))
    poincare = np.zeros((P, n_record if record_poincare else 0, d))
    end_state = np.zeros((P, d))
    stats = np.zeros((P, E, K.NSTAT))
    tan_log = np.zeros((P, n_record if lyapunov else 0, d))
    tan_out = np.zeros((P, d, d))
    status = np.zeros(P, dtype=np.int64)
    hist = np.zeros((P, hist_len, d))
    with using_threads(threads if P > 1 else None):
        K.run_batch(arrays, tper, nsteps, state0, int(n_transient), int(n_record), int(tangent), bool(accurate),
                    poincare, end_state, stats, tan_log, tan_out, status, hist)
    return poincare, end_state, stats, tan_log, tan_out, status, hist


def integrate_batch(models: Sequence[Any], state0: Any = None, options: IntegrationOptions = IntegrationOptions(), *,
                    lyapunov: bool = False, record_poincare: bool = True, steps: Any = None,
                    threads: int | None = None, monodromy: bool = False):
    """Integrate P points through ``options.transient + options.periods`` forcing periods.

    Parameters
    ----------
    models : sequence of SystemModel (or of GearModel: handed to :func:`geardyn.integrate.integrate_batch`)
    state0 : (2n,) or (P, 2n), optional
        Initial (q̃, q̃') at θ = 0; default :func:`initial_state` of each point.
    options : IntegrationOptions
    lyapunov : bool
        Propagate all 2n tangent vectors over the recorded periods with Gram–Schmidt each period.
    record_poincare : bool
    steps : int or (P,) ints, optional
        RK4 steps per forcing period (default ceil(T_f/Δτ)).
    threads : int, optional
    monodromy : bool
        Propagate the raw tangent matrix over the recorded periods (``tangent``: the monodromy).

    Returns
    -------
    SystemBatchResult

    Raises
    ------
    ModelError
        For an empty batch, systems of different structure, a bad state, steps or threads.
    """
    models = list(models)
    if models and not is_system(models[0]):
        return _one.integrate_batch(models, state0, options, lyapunov=lyapunov, record_poincare=record_poincare,
                                    steps=steps, threads=threads)
    models, arrays, tper, nsteps = _prepare(models, options, steps)
    s0 = _state_array(models, state0)
    tangent = K.TAN_LYAPUNOV if lyapunov else (K.TAN_MONODROMY if monodromy else K.TAN_NONE)
    pc, end, stats, tl, tout, status, _ = _run(models, arrays, tper, nsteps, s0, options.transient, options.periods,
                                               tangent, options.accurate, record_poincare, 0, lyapunov, threads)
    return SystemBatchResult(models, options, pc, end, status, stats, nsteps,
                             lyapunov_log=tl if lyapunov else None,
                             tangent=tout if (lyapunov or monodromy) else None,
                             elements=element_names(models[0]), reference=_ref_index(models[0]))


def trajectory(model: Any, state0: Any = None, options: IntegrationOptions = IntegrationOptions(), *,
               history_periods: int = 32, steps: int | None = None, threads: int | None = None):
    """One point with the state at every step of its last ``history_periods`` forcing periods.

    Parameters
    ----------
    model : SystemModel (or GearModel: :func:`geardyn.integrate.trajectory`)
    state0 : (2n,), optional
        Default :func:`initial_state`.
    options : IntegrationOptions
    history_periods : int
    steps, threads : int, optional

    Returns
    -------
    SystemTrajectory
    """
    if not is_system(model):
        return _one.trajectory(model, (0.0, 0.0) if state0 is None else state0, options,
                               history_periods=history_periods, steps=steps, threads=threads)
    models, arrays, tper, nsteps = _prepare([model], options, steps)
    hp = int(min(max(history_periods, 1), options.periods))
    N = int(nsteps[0])
    s0 = _state_array(models, state0)
    pc, end, stats, _, _, status, hist = _run(models, arrays, tper, nsteps, s0, options.transient, options.periods,
                                              K.TAN_NONE, options.accurate, True, hp * N + 1, False, threads)
    summary = SystemBatchResult(models, options, pc, end, status, stats, nsteps, elements=element_names(model),
                                reference=_ref_index(model))
    tau = np.arange(hp * N + 1) * (tper[0] / N)
    x = hist[0]
    if status[0] != K.ST_OK:
        x = np.full_like(x, np.nan)
    deltas = element_series(model, x, tau)
    return SystemTrajectory(model, options, tau, x, deltas, summary, hp)


def period_map(model: Any, state: Sequence[float], n: int = 1, *, dtau: float = IntegrationOptions().dtau,
               accurate: bool = False, steps: int | None = None, threads: int | None = None):
    """The n-forcing-period stroboscopic map and its Jacobian (as :func:`geardyn.integrate.period_map`).

    Parameters
    ----------
    model : SystemModel or GearModel
        The model (a GearModel is passed to :func:`geardyn.integrate.period_map`).
    state : (2n,)
        State (q̃, q̃') at θ = 0.
    n : int
        Forcing periods of the map P^n.
    dtau : float
        Target step Δτ (default :data:`~geardyn.model.DEFAULT_DTAU`); N = ceil(T_f/Δτ) steps per
        period unless ``steps`` is given.
    accurate : bool
        Split steps at the contact boundaries.
    steps : int, optional
        RK4 steps per forcing period (``dtau`` is then not used).
    threads : int, optional
        Threads for this call (numba's setting is left as it was).

    Returns
    -------
    points : ndarray (n, 2n)
    monodromy : ndarray (2n, 2n)
    stats : ndarray (elements, NSTAT)
    ok : bool
    """
    if not is_system(model):
        return _one.period_map(model, state, n, dtau=dtau, accurate=accurate, steps=steps, threads=threads)
    opts = IntegrationOptions(dtau=dtau, transient=0, periods=int(n), accurate=accurate)
    models, arrays, tper, nsteps = _prepare([model], opts, steps)
    s0 = _state_array(models, state)
    pc, end, stats, _, tout, status, _ = _run(models, arrays, tper, nsteps, s0, 0, int(n), K.TAN_MONODROMY, accurate,
                                              threads=threads)
    return pc[0], tout[0], stats[0], bool(status[0] == K.ST_OK)
