"""The vibration signature of a multi-DOF system: the acceleration of a translational DOF (a bearing or
housing sensor), sampled like a data acquisition with the pinion's once-per-revolution tachometer.

The state history of :func:`geardyn.integrate.trajectory` holds q̃' at every RK4 step; the sensor's
acceleration is its derivative, a = s_i ω_n² d q̃'_i/dτ (s_i = b_c on a translation), taken from the
cubic spline through the history (the step is < 1/200 of a mesh period, so the spline's derivative is
accurate to the step's fourth power times the signal's fourth derivative), then resampled at f_s.
Shaft speeds: the reference mesh's frequency ω ω_n/2π over its pinion's teeth (``teeth``).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import xarray as xr
from scipy.interpolate import CubicSpline

from ..errors import ModelError
from ..integrate import trajectory
from ..model import IntegrationOptions
from .acquire import Acquisition, sampled
from .signals import order_spectrum, split_tsa, tsa

__all__ = ["system_acquire", "system_signature"]


def system_acquire(system: Any, dof: str, revolutions: int, fs: float, *, z2: int | None = None,
                   noise: float = 0.0, seed: int = 0, dtau: float = 0.01, settle: float = 300.0) -> Acquisition:
    """Simulate a system and sample the acceleration of one translational DOF and the pinion's tachometer.

    Parameters
    ----------
    system : SystemModel
        The system (its reference mesh's ``teeth`` give the pinion speed).
    dof : str
        The sensor, ``"body.x"`` (a translation: x, y or z).
    revolutions : int
        Pinion revolutions recorded.
    fs : float
        Sampling rate (Hz); at least 8 samples per mesh period.
    z2 : int, optional
        The wheel's teeth (for its TSA).
    noise, seed : float, int
        Gaussian noise RMS as a share of the signal's RMS, and its seed.
    dtau, settle : float
        RK4 step target and the non-dimensional time discarded first.

    Returns
    -------
    Acquisition
    """
    sc = system.scaling
    if dof not in system.labels or dof.rsplit(".", 1)[-1] not in ("x", "y", "z"):
        raise ModelError(f"sensor: {dof!r} is not a translational DOF of the system; DOFs: {', '.join(system.labels)}")
    if sc.teeth is None:
        raise ModelError("sensor: the reference mesh needs teeth = ... (the pinion's) for the shaft speed")
    i = list(system.labels).index(dof)
    z1 = int(sc.teeth)
    f_mesh = system.omega * sc.omega_n / (2.0 * math.pi)
    rpm = 60.0 * f_mesh / z1
    if fs < 8 * f_mesh:
        raise ModelError(f"fs: {fs:g} Hz is below 8 samples per mesh period (mesh frequency {f_mesh:g} Hz)")
    Tf = system.sampling_period
    periods = int(math.ceil(revolutions * z1 * system.period / Tf)) + 1
    transient = max(2, int(math.ceil(settle / Tf)))
    tr = trajectory(system, None, IntegrationOptions(dtau=dtau, transient=transient, periods=periods),
                    history_periods=periods)
    v = tr.x[:, system.n + i]
    if not np.all(np.isfinite(v)):
        raise ModelError("signature: the simulation diverged")
    t_sim = (tr.tau - tr.tau[0]) / sc.omega_n
    a = CubicSpline(t_sim, v).derivative()(t_sim) * sc.s[i] * sc.omega_n  # d²q/dt² = s ω_n d(q̃′)/dt
    return sampled(t_sim, a, rpm=rpm, revolutions=revolutions, fs=fs, noise=noise, seed=seed, z1=z1, z2=int(z2 or z1))


def system_signature(system: Any, dof: str, *, revolutions: int = 10, fs: float | None = None, z2: int | None = None,
                     noise: float = 0.02, seed: int = 0, dtau: float = 0.01, label: str = "") -> xr.Dataset:
    """Order spectrum, TSA of the pinion (and of the wheel with ``z2``) and the indicators of a system's sensor.

    Parameters
    ----------
    system : SystemModel
    dof : str
        A translational DOF (``"pinion.y"``).
    revolutions : int
        Pinion revolutions recorded.
    fs : float, optional
        Sampling rate (default 20 samples per mesh period, rounded up to 1 kHz).
    z2 : int, optional
        The wheel's teeth.
    noise, seed, dtau, label
        As :func:`geardyn.signature.run.signature`.

    Returns
    -------
    xarray.Dataset
        ``geardyn_kind = "signature"`` with ``order_amplitude`` over ``order`` (pinion orders) and
        ``tsa_pinion``; the indicators in the ``summary`` attribute.
    """
    from .run import indicators

    sc = system.scaling
    f_mesh = system.omega * sc.omega_n / (2.0 * math.pi)
    if fs is None:
        fs = 1000.0 * math.ceil(20 * f_mesh / 1000.0)
    acq = system_acquire(system, dof, revolutions, fs, z2=z2, noise=noise, seed=seed, dtau=dtau)
    z1 = acq.z1
    N = int(2 ** math.ceil(math.log2(8 * max(z1, z2 or z1))))
    orders, amp = order_spectrum(acq, N)
    t1 = tsa(acq, N)
    ind = {"pinion": indicators(t1, z1)}
    if z2:
        ind["wheel"] = indicators(tsa(acq, N, z1 / z2), z2)
    top = orders <= 3.5 * z1
    p1 = split_tsa(t1, z1)
    ds = xr.Dataset(
        {"order_amplitude": ("order", amp[top], {"units": "m/s^2", "long_name": f"order spectrum of {dof}"}),
         "tsa_pinion": ("angle_pinion", t1, {"units": "m/s^2", "long_name": "TSA of the pinion"}),
         "difference": ("angle_pinion", p1["difference"], {"units": "m/s^2"})},
        coords={"order": ("order", orders[top], {"units": "1", "long_name": "pinion order"}),
                "angle_pinion": ("angle_pinion", 360.0 * np.arange(N) / N, {"units": "deg"})},
    )
    summary = {"label": label, "sensor": dof, "rpm": acq.rpm, "fs_Hz": float(fs), "revolutions": int(revolutions),
               "z1": z1, "z2": z2, "mesh_frequency_Hz": f_mesh, "noise": noise,
               "excitation_cycles": system.period_multiple(), "indicators": ind}
    ds = ds.expand_dims(run=[label or "run"])
    ds.attrs.update(geardyn_kind="signature", summary=json.dumps({"runs": [summary]}))
    return ds
