r"""Run-up and run-down: a System (the gear pair, or any system file) driven through a speed ramp, order-tracked.

During a ramp the mesh frequency changes with time and the forcing is no longer periodic: the mesh
angle is the integral of the speed, θ(τ) = ∫ ω(s) ds.  The ramp is integrated here with the same
RK4 kernel as every other analysis (:func:`geardyn.integrate.trajectory`), with the speed held
constant over a *block* of ``m`` whole mesh cycles and stepped from block to block:

* block b runs at ω_b = ω(τ_b + m π/ω(τ_b)) (the ramp's speed at the block's midpoint, τ_b its
  start), for exactly m periods 2π/ω_b, starting from the end state of block b − 1;
* every block starts and ends at θ ≡ 0 (mod 2π), so the mesh phase is continuous and equals the
  integral of the piecewise-constant speed; it differs from the integral of the linear ramp by at
  most a quarter of a block's speed change times its duration (second order in the block length);
* the STE forcing keeps the form ω² Σ l² ε_l cos(lθ + φ_l) of constant speed: the term e′(θ) ω′
  that a speed change adds to d²e/dτ² is left out (it is ω′/ω² times the kept term, 1e-4 or less for
  the ramps of a run-up test).

An excitation of P > 1 mesh cycles (``GearModel.cycles``, a tooth fault, the hunting period) repeats only
after P cycles: the blocks are then whole forcing periods (m a multiple of P), so every block starts and ends at
the excitation's phase 0 (mod 2π) and its phase stays continuous through the ramp; the RK4 step is the one-cycle
model's, T/ceil(T/Δτ) with T the mesh period (P·ceil(T/Δτ) steps a forcing period), the settling and the
quasi-static response count mesh periods (rounded up to whole forcing periods) and the order tracking stays in
mesh orders, with the spectrum of the orders j/P (the shaft-order sidebands) beside it.  A one-cycle series
written over P cycles gives the one-cycle model's run-up to rounding (``tests/test_runup_cycles.py``).

No Python loop runs per time step: each block is one call of the compiled kernel (the loop over
blocks, a few hundred, is in Python).  The error of the piecewise-constant speed is measured by
:func:`block_error` against a reference that steps the speed every mesh cycle.

Per block the result holds the order-tracked DTE (amplitude of mesh orders 1 … L of u over the
block, by a DFT over its whole periods; u the reference element's deflection, the pair's DTE), the half
peak-to-peak amplitude of u, and the dynamic factor max F_n / F_p (the reference element's force,
``System.element_forces``, over its static force ``System.static_force``).  A system's forcing period spans
``period_multiple()`` reference mesh cycles (its meshes' and torque orders' least common period): the blocks are
whole forcing periods as for a pair's excitation of P cycles.  With a slow enough ramp these equal the steady
(quasi-static) frequency response at the block's speed; faster ramps delay the jumps of a run-up past those of the
steady sweep.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from ..errors import ModelError
from ..integrate import integrate_batch, trajectory
from ..io import annotate, json_values, result_attrs
from ..model import DEFAULT_DTAU, IntegrationOptions

__all__ = ["MAX_BLOCKS", "RunupResult", "block_error", "runup", "steady_response"]

#: Default number of speed blocks of a ramp (the cycles per block follow from it).
MAX_BLOCKS = 400
#: Largest number of mesh cycles a run-up may integrate (bounds the run time).
MAX_CYCLES = 5_000_000


@dataclass(frozen=True)
class RunupResult:
    """A ramp integrated block by block (non-dimensional).

    Attributes
    ----------
    model : System
        The model (its ω is replaced by the ramp's).
    omega : numpy.ndarray
        Speed ω_b of each block.
    tau : numpy.ndarray
        Time τ at the middle of each block.
    cycles : int
        Mesh cycles per block (a multiple of the model's P).
    order_amplitude : numpy.ndarray
        (blocks, L): amplitude of mesh order l = 1 … L of u over each block.
    spectrum : numpy.ndarray or None
        With an excitation of P > 1 mesh cycles, (blocks, (L + 1)P − 1): amplitude of the orders j/P,
        j = 1 … (L + 1)P − 1 (mesh orders and their shaft-order sidebands, up to L + 1 − 1/P); None when P = 1.
    amplitude : numpy.ndarray
        Half peak-to-peak of u over each block.
    dynamic_factor : numpy.ndarray
        max F_n / F_p over each block (NaN without a static load).
    omega_start, omega_stop, duration : float
        The ramp (τ units).
    diverged : bool
        Whether the integration diverged (the blocks after it are NaN).
    options : IntegrationOptions
        The integration options the ramp used.
    """

    model: Any
    omega: np.ndarray
    tau: np.ndarray
    cycles: int
    order_amplitude: np.ndarray
    amplitude: np.ndarray
    dynamic_factor: np.ndarray
    omega_start: float
    omega_stop: float
    duration: float
    diverged: bool = False
    options: IntegrationOptions = field(default_factory=IntegrationOptions)
    spectrum: np.ndarray | None = None

    @property
    def spectrum_orders(self) -> np.ndarray:
        """The mesh orders j/P of :attr:`spectrum` (empty when it is None)."""
        if self.spectrum is None:
            return np.zeros(0)
        return np.arange(1, self.spectrum.shape[1] + 1) / self.excitation_cycles

    @property
    def excitation_cycles(self) -> int:
        """P, the mesh cycles of the model's forcing period (its excitation's and torque orders')."""
        return int(self.model.period_multiple() or 1)

    @property
    def ramp_rate(self) -> float:
        """dω/dτ of the ramp."""
        return (self.omega_stop - self.omega_start) / self.duration

    def to_dataset(self) -> xr.Dataset:
        """The result as a Dataset of kind ``runup`` (dims ``block`` and ``order``)."""
        orders = np.arange(1, self.order_amplitude.shape[1] + 1)
        ds = xr.Dataset(
            {
                "order_amplitude": (("block", "order"), self.order_amplitude),
                "amplitude": (("block",), self.amplitude),
                "dynamic_factor": (("block",), self.dynamic_factor),
            },
            coords={"omega": (("block",), self.omega), "tau": (("block",), self.tau), "order": (("order",), orders)},
            attrs={
                "geardyn_kind": "runup",
                "cycles_per_block": int(self.cycles),
                "omega_start": self.omega_start,
                "omega_stop": self.omega_stop,
                "duration_tau": self.duration,
                "ramp_rate_per_tau": self.ramp_rate,
                "diverged": int(self.diverged),
                **_model_attrs(self.model),
            },
        )
        if self.spectrum is not None:
            ds["spectrum"] = (("block", "spectrum_order"), self.spectrum)
            ds = ds.assign_coords(spectrum_order=("spectrum_order", self.spectrum_orders))
            ds.attrs["excitation_cycles"] = self.excitation_cycles
        return annotate(ds)

    def to_json(self) -> dict[str, Any]:
        """JSON summary (lists per block)."""
        out = {
            "omega_start": self.omega_start,
            "omega_stop": self.omega_stop,
            "duration_tau": self.duration,
            "ramp_rate_per_tau": self.ramp_rate,
            "cycles_per_block": self.cycles,
            "blocks": int(self.omega.size),
            **{k: json_values(getattr(self, k)) for k in ("omega", "tau", "amplitude", "dynamic_factor")},
            "order_amplitude": json_values(self.order_amplitude.T),
            "diverged": self.diverged,
        }
        if self.spectrum is not None:
            out["excitation_cycles"] = self.excitation_cycles
            out["spectrum_orders"] = json_values(self.spectrum_orders)
            out["spectrum"] = json_values(self.spectrum.T)
        return out


def _block_speeds(w0: float, w1: float, duration: float, cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """Speeds and midpoint times of the blocks of m = ``cycles`` mesh cycles covering the ramp."""
    rate = (w1 - w0) / duration
    speeds, mids = [], []
    t = 0.0
    while t < duration:
        w = w0 + rate * t
        mid = t + cycles * math.pi / w
        wb = w0 + rate * min(mid, duration)
        speeds.append(wb)
        mids.append(t + cycles * math.pi / wb)
        t += cycles * 2.0 * math.pi / wb
    return np.array(speeds), np.array(mids)


def runup(
    model: Any,
    omega_start: float,
    omega_stop: float,
    duration: float,
    *,
    cycles_per_block: int | None = None,
    max_blocks: int = MAX_BLOCKS,
    orders: int = 3,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = False,
    settle: int = 200,
    state0: Any = (0.0, 0.0),
    progress: Callable[[int, int], None] | None = None,
) -> RunupResult:
    """Integrate the model through a linear speed ramp ω(τ) from ``omega_start`` to ``omega_stop``.

    Parameters
    ----------
    model : System
        The model (its ω is not used): the pair, or a system (its reference mesh's cycles count).
    omega_start, omega_stop : float
        Speeds at the start and end of the ramp (> 0; a run-down has omega_stop < omega_start).
    duration : float
        Duration of the ramp in τ (> 0).
    cycles_per_block : int, optional
        Mesh cycles per speed block, a multiple of the excitation's P mesh cycles (``model.cycles``); default so
        that there are about ``max_blocks`` blocks (rounded up to a multiple of P).
    max_blocks : int
        Blocks of the default block length.
    orders : int
        Mesh orders tracked (1 … orders).
    dtau : float
        Target RK4 step (the step is T/ceil(T/Δτ) in every block).
    accurate : bool
        Split the steps at the contact crossings.
    settle : int
        Mesh periods integrated at ``omega_start`` before the ramp, so that it starts on a steady state (rounded
        up to whole forcing periods of P mesh periods).
    state0 : (u0, u0') or a full state
        State at the start of the settling (the reference element's (u0, u0'): ``model.initial_state(u0, u0')``).
    progress : callable, optional
        Called as ``progress(done, total)`` in blocks: (0, blocks) once the settling is done, then after each
        block (and (blocks, blocks) at the end, also after a divergence); the result does not depend on it.

    Returns
    -------
    RunupResult

    Raises
    ------
    ModelError
        For non-positive speeds or duration, equal speeds, a step not below a block's period, a block that is
        not a whole number of forcing periods, or more than :data:`MAX_CYCLES` mesh cycles.

    Examples
    --------
    >>> from geardyn import GearModel, runup
    >>> res = runup(GearModel(), 0.5, 0.6, 200.0)  # ω from 0.5 to 0.6 over τ = 200
    >>> res.omega_start, res.omega_stop, bool(res.diverged)
    (0.5, 0.6, False)
    """
    w0, w1, T = float(omega_start), float(omega_stop), float(duration)
    for name, v in (("omega_start", w0), ("omega_stop", w1), ("duration", T)):
        if not (math.isfinite(v) and v > 0):
            raise ModelError(f"{name}: must be a finite number > 0, got {v!r}")
    if w0 == w1:
        raise ModelError(f"omega_stop: must differ from omega_start, got {w0:g} for both")
    total = 0.5 * (w0 + w1) * T / (2.0 * math.pi)
    if total > MAX_CYCLES:
        raise ModelError(
            f"duration: the ramp spans {total:.3g} mesh cycles, more than the {MAX_CYCLES:.0e} allowed "
            "(shorten it, or lower the speeds)"
        )
    if orders < 1:
        raise ModelError(f"orders: must be >= 1, got {orders!r}")
    P = int(model.period_multiple() or 1)  # mesh cycles of the forcing period (excitation, torque orders)
    m = int(cycles_per_block) if cycles_per_block is not None else max(1, math.ceil(total / max(1, max_blocks)))
    if m < 1:
        raise ModelError(f"cycles_per_block: must be >= 1, got {cycles_per_block!r}")
    if P > 1:
        if cycles_per_block is None:
            m = P * -(-m // P)
        elif m % P:
            raise ModelError(
                f"cycles_per_block: a block is whole forcing periods, a multiple of the excitation's {P} "
                f"mesh cycles; got {m}"
            )
    speeds, mids = _block_speeds(w0, w1, T, m)
    IntegrationOptions(dtau=dtau).check_for(max(w0, w1))
    s = np.asarray(state0, dtype=float).ravel()  # a full state, or the reference element's (u0, u0')
    state0 = model.initial_state(float(s[0]), float(s[1])) if s.size == 2 and model.state_dim != 2 else s
    start = integrate_batch(  # settle mesh periods rounded up to forcing periods, at the one-cycle model's step
        [model.with_param("omega", w0)],
        state0,
        IntegrationOptions(dtau=dtau, transient=-(-max(int(settle), 0) // P), periods=1, accurate=accurate),
        record_poincare=False,
        steps=_steps(w0, dtau, P),
    )
    state = np.asarray(start.end_state[0], dtype=float)
    nb = speeds.size
    amp_o = np.full((nb, orders), np.nan)
    amp = np.full(nb, np.nan)
    kdyn = np.full(nb, np.nan)
    spec = np.full((nb, (orders + 1) * P - 1), np.nan) if P > 1 else None
    diverged = not np.all(np.isfinite(state))
    opts = IntegrationOptions(dtau=dtau, transient=0, periods=m // P, accurate=accurate)
    report = progress or (lambda done, total: None)
    report(0, nb)
    for b in range(0 if diverged else nb):
        out = _block(model.with_param("omega", float(speeds[b])), state, opts, m, orders, spec is not None)
        if out is None:
            diverged = True
            break
        amp_o[b], amp[b], kdyn[b], state = out[:4]
        if spec is not None:
            spec[b] = out[4]
        report(b + 1, nb)
    report(nb, nb)
    return RunupResult(
        model=model,
        omega=speeds,
        tau=mids,
        cycles=m,
        order_amplitude=amp_o,
        amplitude=amp,
        dynamic_factor=kdyn,
        omega_start=w0,
        omega_stop=w1,
        duration=T,
        diverged=diverged,
        options=opts,
        spectrum=spec,
    )


def _steps(omega: float, dtau: float, P: int) -> int | None:
    """RK4 steps a forcing period of P mesh periods at the one-cycle model's step T/ceil(T/Δτ), T = 2π/ω
    (None for P = 1: the integrator's own default, the same)."""
    return None if P == 1 else P * int(math.ceil(2.0 * math.pi / omega / dtau))


def _model_attrs(model: Any) -> dict[str, str]:
    """The model as a run-up result stores it: the pair's ``model``, a system's ``system_model`` (its backend's)."""
    a = result_attrs("runup", model, IntegrationOptions())
    return {k: a[k] for k in ("model", "system_model", "geardyn_system") if k in a}


def _block(mb: Any, state: np.ndarray, opts: IntegrationOptions, m: int, orders: int, spectrum: bool = False):
    """Order amplitudes, half peak-to-peak, dynamic factor and end state of m recorded mesh periods (None: diverged);
    with ``spectrum`` also the amplitudes of the orders j/P, j = 1 … (orders + 1)P − 1."""
    P = int(round(mb.sampling_period * mb.omega / (2.0 * math.pi)))  # mesh cycles of a sampling period
    k = m // P  # forcing periods
    tr = trajectory(mb, tuple(state), opts, history_periods=k, steps=_steps(mb.omega, opts.dtau, P))
    u = tr.u[:-1]
    if not np.all(np.isfinite(u)):
        return None
    n = u.size
    theta = 2.0 * np.pi * m * np.arange(n) / n  # the mesh phase
    amp_o = 2.0 * np.abs(np.exp(-1j * np.outer(np.arange(1, orders + 1), theta)) @ u) / n
    f0 = float(mb.static_force())
    force = mb.element_forces(tr.tau[:-1], tr.deltas[:-1])
    kdyn = float(np.max(force[:, tr.summary.reference])) / f0 if f0 > 0 else np.nan
    out = (amp_o, 0.5 * (u.max() - u.min()), kdyn, np.array(tr.x[-1]))
    if spectrum:  # order j/P is the DFT bin j·k of the k forcing periods
        X = np.fft.rfft(u)
        out += (2.0 * np.abs(X[k * np.arange(1, (orders + 1) * P)]) / n,)
    return out


def steady_response(
    model: Any,
    omegas: Any,
    *,
    orders: int = 3,
    periods: int = 32,
    transient: int = 200,
    dtau: float = DEFAULT_DTAU,
    accurate: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """The quasi-static counterpart of a run-up: steady states swept up and down with state continuation.

    Parameters
    ----------
    model : System
        The model.
    omegas : array_like
        Speeds ω (increasing).
    orders, periods, transient, dtau, accurate
        Tracked orders, recorded and discarded mesh periods per point (rounded up to whole forcing periods of P
        mesh periods), RK4 step, contact splitting.
    progress : callable, optional
        Called as ``progress(done, total)`` in points after each point of the two sweeps (total: twice the
        speeds); the result does not depend on it.

    Returns
    -------
    dict
        ``x`` (= ω), and for ``up`` and ``down``: ``order_amplitude`` (first order), ``amplitude`` and
        ``dynamic_factor`` per point (None where diverged), measured as in :func:`runup`.
    """
    w = np.asarray(omegas, dtype=float)
    P = int(model.period_multiple() or 1)  # mesh cycles of the forcing period (excitation, torque orders)
    opts = IntegrationOptions(
        dtau=dtau, transient=-(-int(transient) // P), periods=-(-int(periods) // P), accurate=accurate
    )
    out: dict[str, Any] = {"x": [float(x) for x in w]}
    done = 0
    for lab, seq in (("up", range(w.size)), ("down", range(w.size - 1, -1, -1))):
        rows: dict[int, Any] = {}
        state = model.initial_state()
        for i in seq:
            r = _block(model.with_param("omega", float(w[i])), state, opts, opts.periods * P, orders)
            rows[i] = r
            done += 1
            if progress is not None:
                progress(done, 2 * w.size)
            state = model.initial_state() if r is None else r[3]

        def col(k: int) -> list[float | None]:  # the first order of the order amplitudes
            return json_values(
                np.array([np.nan if rows[i] is None else np.ravel(rows[i][k])[0] for i in range(w.size)])
            )

        out[lab] = {"order_amplitude": col(0), "amplitude": col(1), "dynamic_factor": col(2)}
    return out


def _jump(r: RunupResult) -> tuple[float, float]:
    """Speed and size of the largest change of the mesh-order amplitude between two blocks."""
    d = np.abs(np.diff(r.order_amplitude[:, 0]))
    if d.size == 0 or not np.any(np.isfinite(d)):
        return float("nan"), 0.0
    i = int(np.nanargmax(d))
    return float(0.5 * (r.omega[i] + r.omega[i + 1])), float(d[i])


def block_error(result: RunupResult, reference: RunupResult) -> dict[str, float]:
    """Differences between a run-up and the same ramp with shorter blocks (e.g. one mesh cycle per block).

    Parameters
    ----------
    result, reference : RunupResult
        The same ramp with longer and shorter blocks.

    Returns
    -------
    dict
        ``amplitude``: max |A_1 − A_1,ref| / max A_1,ref of the mesh-order amplitude, the reference
        interpolated at the result's block speeds, leaving out the speeds within five blocks of the
        largest jump of either (there a shift of the jump dominates); ``jump_shift_omega``: the
        difference of the speeds of their largest jumps (0 when neither jumps).
    """
    ref_w, ref_a = reference.omega, reference.order_amplitude[:, 0]
    order = np.argsort(ref_w)
    a_ref = np.interp(result.omega, ref_w[order], ref_a[order])
    ok = np.isfinite(result.order_amplitude[:, 0]) & np.isfinite(a_ref)
    (wj, dj), (wr, dr) = _jump(result), _jump(reference)
    scale = float(np.nanmax(ref_a))
    jumps = dj > 0.2 * scale or dr > 0.2 * scale
    if jumps:
        width = 5.0 * float(np.max(np.abs(np.diff(result.omega)))) if result.omega.size > 1 else 0.0
        for w in (wj, wr):
            ok &= np.abs(result.omega - w) > width
    err = float(np.max(np.abs(result.order_amplitude[ok, 0] - a_ref[ok])) / scale) if np.any(ok) else float("nan")
    return {"amplitude": err, "jump_shift_omega": float(wj - wr) if jumps else 0.0}
