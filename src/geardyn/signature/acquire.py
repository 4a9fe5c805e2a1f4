"""The vibration a sensor sees, sampled like a data acquisition, with a once-per-revolution tachometer.

The 1-DOF pair's coordinate is u = x − e (x the dynamic transmission error along the line of action,
e the STE), so the relative acceleration along the line of action is

    x'' = u'' + e'' = f_p − 2ξ(θ) u' − k(θ) f(u)            (non-dimensional; the STE forcing cancels)

— the net force on the equivalent mass over that mass — and in SI units a = x'' b_c ω_n², t = τ/ω_n.
The simulated history (every RK4 step) is resampled at the acquisition rate f_s by a cubic spline
(the step is < 1/200 of a mesh period); Gaussian noise of a given share of the signal's RMS may be
added.  The tachometer is a magnetic pickup on the pinion shaft: one pulse per revolution,
5 V exp(−½ (Δφ/σ)²) around the shaft angle φ1 ≡ 0 with σ four samples wide, sampled at the same rate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline

from ..errors import ModelError
from ..integrate import trajectory
from ..model import GearModel, IntegrationOptions
from ..plausible import budget
from ..series import series_values

__all__ = ["Acquisition", "acquire", "acceleration", "check_record", "record_system"]


@dataclass(frozen=True)
class Acquisition:
    """A sampled record: time (s), acceleration (m/s²), tachometer (V), rate (Hz), speed (rpm), teeth.

    Attributes
    ----------
    time : ndarray
        Sample times (s).
    accel : ndarray
        Acceleration along the line of action (m/s²).
    tach : ndarray
        Tachometer voltage (V).
    fs : float
        Sampling rate (Hz).
    rpm : float
        Pinion speed.
    z1, z2 : int
        Teeth of pinion and wheel.
    """

    time: np.ndarray
    accel: np.ndarray
    tach: np.ndarray
    fs: float
    rpm: float
    z1: int
    z2: int


def acceleration(model: GearModel, tau: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Non-dimensional x'' = f_p − C(θ) u' − K(θ) f(u) along a history (θ = (ω/P) τ, the forcing phase).

    Parameters
    ----------
    model : GearModel
        The model.
    tau, u, v : ndarray
        Its history: τ, u and u'.

    Returns
    -------
    ndarray
        x'' at each instant.
    """
    C, K = series_values(model.coefficients(), model.forcing_omega * np.asarray(tau, dtype=float), (0, 1))
    return model.fp - C * v - K * model.restoring(u)


#: Largest record (samples) and simulation (integration steps) a signature may plan for; larger requests are
#: refused before computing (each sample or step holds some ten float64 values).
MAX_SAMPLES = 50_000_000
MAX_STEPS = 50_000_000


def check_record(fs: float, f_mesh: float, revolutions: int, rpm: float, noise: float) -> None:
    """Refuse a sampling rate, record length or noise level a record cannot have, before computing.

    Parameters
    ----------
    fs : float
        Sampling rate (Hz): finite, at least 8 samples per mesh period.
    f_mesh : float
        Mesh frequency (Hz).
    revolutions : int
        Pinion revolutions (≥ 1).
    rpm : float
        Pinion speed.
    noise : float
        Noise RMS relative to the signal's: finite, in [0, 1] (beyond, the indicators are those of the noise).

    Raises
    ------
    ModelError
        One line naming the option and the bound (with the estimate for a record too large).
    """
    if not (isinstance(fs, (int, float)) and math.isfinite(fs) and fs > 0):
        raise ModelError(f"fs: a sampling rate > 0 Hz, got {fs!r}")
    if fs < 8 * f_mesh:
        raise ModelError(f"fs: {fs:g} Hz is below 8 samples per mesh period (mesh frequency {f_mesh:g} Hz)")
    if int(revolutions) != revolutions or revolutions < 1:
        raise ModelError(f"revolutions: a whole number of at least 1, got {revolutions!r}")
    n = revolutions * 60.0 / rpm * fs
    budget(f"a record at {fs:g} Hz over {revolutions} revolutions", n, MAX_SAMPLES, "samples", "fs x revolutions")
    if not (isinstance(noise, (int, float)) and math.isfinite(noise) and 0.0 <= noise <= 1.0):
        raise ModelError(f"noise: a share of the signal RMS in [0, 1], got {noise!r}")


def record_system(
    system: Any,
    sensor: Callable[[Any], tuple[np.ndarray, np.ndarray]],
    *,
    tau_per_rev: float,
    rpm: float,
    z1: int,
    z2: int,
    revolutions: int,
    fs: float,
    noise: float = 0.0,
    seed: int = 0,
    dtau: float = 0.01,
    settle: float = 300.0,
    state0: Any = None,
) -> Acquisition:
    """Simulate any system of the contract (:mod:`geardyn.system`) and sample what its sensor reads, with the
    pinion's tachometer: the one acquisition of the pair and of every multi-DOF system.

    Parameters
    ----------
    system : System
        The model (a :class:`~geardyn.model.GearModel` or a :class:`~geardyn.systems.SystemModel`).
    sensor : callable
        ``sensor(trajectory) -> (t, a)``: the times (s) and the acceleration (m/s²) the sensor reads along
        the simulated history (every RK4 step).
    tau_per_rev : float
        Non-dimensional time of one pinion revolution.
    rpm : float
        Pinion speed (the same revolution in minutes).
    z1, z2 : int
        Teeth of the pinion (the tachometer's shaft) and of the wheel.
    revolutions : int
        Pinion revolutions recorded.
    fs : float
        Sampling rate (Hz), at least 8 samples per mesh period.
    noise, seed : float, int
        Gaussian noise RMS as a share of the signal's RMS, and its seed.
    dtau : float
        Target RK4 step Δτ.
    settle : float
        Non-dimensional time integrated and discarded first (at least, in whole sampling periods).
    state0 : array-like, optional
        Initial state (default the system's).

    Returns
    -------
    Acquisition
    """
    f_mesh = rpm / 60.0 * z1
    check_record(fs, f_mesh, revolutions, rpm, noise)
    Tf = system.sampling_period
    periods = int(math.ceil(revolutions * tau_per_rev / Tf * (1.0 - 1e-12))) + 1
    transient = max(2, int(math.ceil(settle / Tf)))
    steps = (periods + transient) * Tf / dtau
    what = f"{revolutions} pinion revolutions"
    if transient > periods:  # the settling dominates: say so (a lightly damped mode decays slowly)
        what += (
            f" after settling for τ = {transient * Tf:.3g} (the least damped mode's decay; the record: "
            f"{periods * Tf:.3g})"
        )
    budget(what, steps, MAX_STEPS, "integration steps", "revolutions")
    tr = trajectory(
        system, state0, IntegrationOptions(dtau=dtau, transient=transient, periods=periods), history_periods=periods
    )
    t_sim, a = sensor(tr)
    if not np.all(np.isfinite(a)):
        raise ModelError("signature: the simulation diverged")
    # sampled at fs (cubic spline through the simulated points), with noise and the tachometer's pulse (5 V
    # Gaussian, 4 samples wide) at the pinion's zero angle
    t = np.arange(int(math.floor(revolutions * 60.0 / rpm * fs)) + 1) / fs
    sig = CubicSpline(t_sim, a)(t)
    if noise > 0:
        sig = sig + noise * np.sqrt(np.mean(sig**2)) * np.random.default_rng(seed).normal(size=sig.size)
    phi = 2.0 * math.pi * rpm / 60.0 * t
    wrapped = np.mod(phi + math.pi, 2.0 * math.pi) - math.pi
    sigma = 4.0 * 2.0 * math.pi * rpm / 60.0 / fs
    tach = 5.0 * np.exp(-0.5 * (wrapped / sigma) ** 2)
    return Acquisition(time=t, accel=sig, tach=tach, fs=float(fs), rpm=rpm, z1=z1, z2=z2)


def acquire(
    model: GearModel,
    scales: dict,
    revolutions: int,
    fs: float,
    *,
    noise: float = 0.0,
    seed: int = 0,
    dtau: float = 0.01,
    settle: float = 300.0,
) -> Acquisition:
    """The pair with its sensor, the relative acceleration along the line of action (:func:`acceleration`),
    through :func:`record_system`.

    Parameters
    ----------
    model : GearModel
        The pair's model (:func:`geardyn.tooth.excitation.pair_model`); its period is
        ``scales["cycles"]`` mesh cycles.
    scales : dict
        ``omega_n``, ``b_c``, ``rpm``, ``z1``, ``z2``, ``cycles`` (from ``pair_model``).
    revolutions, fs, noise, seed, dtau, settle
        As :func:`record_system`.

    Returns
    -------
    Acquisition
    """
    z1, z2, P = int(scales["z1"]), int(scales["z2"]), int(scales["cycles"])
    wn, b_c = float(scales["omega_n"]), float(scales["b_c"])

    def sensor(tr):
        return tr.tau / wn, acceleration(model, tr.tau, tr.u, tr.v) * b_c * wn * wn

    return record_system(
        model,
        sensor,
        tau_per_rev=z1 * model.sampling_period / P,
        rpm=float(scales["rpm"]),
        z1=z1,
        z2=z2,
        revolutions=revolutions,
        fs=fs,
        noise=noise,
        seed=seed,
        dtau=dtau,
        settle=settle,
        state0=(model.fp, 0.0),
    )
