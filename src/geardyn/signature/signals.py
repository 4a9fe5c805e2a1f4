"""Order tracking, order spectrum, time-synchronous average and the regular/residual/difference signals.

* Pulse times: the centroid Σ t V / Σ V of each tachometer pulse above half its height.
* Computed order tracking (Fyfe & Munck, Mech. Syst. Signal Process. 11 (1997) 187-205): the shaft
  angle is 2π k at the k-th pulse and linear in time between pulses; the signal is resampled by a
  cubic spline at N equally spaced angles per revolution of the shaft (the wheel's angle is the
  pinion's times z1/z2, a virtual tachometer).
* Order spectrum: the amplitude 2|X_k|/n of the DFT of the angle-domain record over whole
  revolutions, at orders k / revolutions of the pinion.
* Time-synchronous average (Braun, Acustica 32 (1975); McFadden, Mech. Syst. Signal Process. 1
  (1987) 83-95): the mean over the revolutions of a shaft of its angle-domain record.
* From the TSA of a shaft with z teeth, in its own orders (Lebold et al. 2000): the *regular* signal
  keeps the shaft orders 1 … S, the mesh orders k z and their first sidebands k z ± 1; the
  *difference* signal is the TSA minus the regular signal; the *residual* signal is the TSA without
  the shaft orders 1 … S and the mesh orders (its sidebands kept).  The mean is removed from all.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from ..errors import ModelError
from .acquire import Acquisition

__all__ = ["angle_resample", "order_spectrum", "pulse_times", "split_tsa", "tsa"]


def pulse_times(tach: np.ndarray, fs: float) -> np.ndarray:
    """Times (s) of the tachometer pulses (centroids of the samples above half the peak), whole pulses only.

    Parameters
    ----------
    tach : ndarray
        Tachometer samples.
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    ndarray
        Pulse times (s).
    """
    v = np.asarray(tach, dtype=float)
    on = v > 0.5 * v.max()
    edges = np.diff(on.astype(np.int8))
    starts, ends = np.flatnonzero(edges == 1) + 1, np.flatnonzero(edges == -1) + 1
    if starts.size and ends.size:
        ends = ends[ends > starts[0]]  # a pulse cut by the start of the record is dropped
    n = min(starts.size, ends.size)  # and one cut by its end
    t = np.arange(v.size) / fs
    return np.array([np.sum(t[a:b] * v[a:b]) / np.sum(v[a:b]) for a, b in zip(starts[:n], ends[:n])])


def angle_resample(acq: Acquisition, per_rev: int, ratio: float = 1.0) -> np.ndarray:
    """The signal at ``per_rev`` equal angles per revolution of a shaft turning ``ratio`` times the pinion,
    over its whole revolutions between the first and last pulse; shape (revolutions, per_rev).

    Parameters
    ----------
    acq : Acquisition
        The record.
    per_rev : int
        Samples per revolution.
    ratio : float
        Speed of the shaft over the pinion's (z1/z2 for the wheel).

    Returns
    -------
    ndarray (revolutions, per_rev)
    """
    tp = pulse_times(acq.tach, acq.fs)
    if tp.size < 2:
        raise ModelError("order tracking: fewer than two tachometer pulses in the record")
    pin_angle = np.arange(tp.size, dtype=float)  # pinion revolutions at the pulses
    span = (tp.size - 1) * ratio
    revs = int(np.floor(span + 1e-9))
    if revs < 1:
        raise ModelError("order tracking: the record holds no whole revolution of that shaft")
    shaft_rev = np.arange(revs * per_rev) / per_rev
    t = np.interp(shaft_rev / ratio, pin_angle, tp)
    return CubicSpline(acq.time, acq.accel)(t).reshape(revs, per_rev)


def order_spectrum(acq: Acquisition, per_rev: int) -> tuple[np.ndarray, np.ndarray]:
    """(orders of the pinion, amplitude) of the whole angle-domain record (whole pinion revolutions).

    Parameters
    ----------
    acq : Acquisition
        The record.
    per_rev : int
        Samples per pinion revolution.

    Returns
    -------
    (ndarray, ndarray)
        Orders and amplitudes.
    """
    x = angle_resample(acq, per_rev).ravel()
    revs = x.size // per_rev
    X = np.fft.rfft(x - x.mean())
    amp = 2.0 * np.abs(X) / x.size
    return np.arange(X.size) / revs, amp


def tsa(acq: Acquisition, per_rev: int, ratio: float = 1.0) -> np.ndarray:
    """Time-synchronous average over the whole revolutions of the shaft (``ratio`` = its speed / pinion's).

    Parameters
    ----------
    acq : Acquisition
        The record.
    per_rev : int
        Samples per revolution.
    ratio : float
        Speed of the shaft over the pinion's.

    Returns
    -------
    ndarray (per_rev,)
    """
    return angle_resample(acq, per_rev, ratio).mean(axis=0)


def split_tsa(avg: np.ndarray, z: int, shaft_orders: int = 2) -> dict[str, np.ndarray]:
    """Regular, residual and difference signals of a shaft's TSA, and its mesh and sideband amplitudes.

    Parameters
    ----------
    avg : ndarray
        The TSA of a shaft.
    z : int
        Its teeth.
    shaft_orders : int
        Shaft orders 1 … S kept in the regular signal and removed from the residual.

    Returns
    -------
    dict
        ``regular``, ``residual``, ``difference`` (arrays like ``avg``), ``mesh_amplitudes`` (orders k z),
        ``sidebands`` (amplitudes at z − 1 and z + 1).
    """
    N = avg.size
    X = np.fft.rfft(avg)
    orders = np.arange(X.size)
    mesh = orders[(orders % z == 0) & (orders > 0)]
    shaft = np.arange(1, shaft_orders + 1)
    side = np.concatenate([mesh - 1, mesh + 1])
    side = side[(side > 0) & (side < X.size)]

    kept = np.unique(np.concatenate([shaft, mesh, side]))
    Y = np.zeros_like(X)
    Y[kept] = X[kept]
    regular = np.fft.irfft(Y, N)
    Xr = X.copy()
    Xr[np.concatenate([[0], shaft, mesh])] = 0.0
    amp = 2.0 * np.abs(X) / N
    if N % 2 == 0:
        amp[-1] *= 0.5
    return {
        "regular": regular,
        "residual": np.fft.irfft(Xr, N),
        "difference": avg - avg.mean() - regular,
        "mesh_amplitudes": amp[mesh],
        "sidebands": amp[[z - 1, z + 1]] if z + 1 < X.size else amp[[z - 1]],
    }
