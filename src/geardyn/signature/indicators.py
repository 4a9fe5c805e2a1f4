"""Condition indicators of gear vibration, each with its defining reference.

Notation: x the signal (one record), x̄ its mean, N its length; a TSA (time-synchronous average) and
the regular, residual and difference signals of :mod:`geardyn.signature.signals`.  The definitions are
those collected by Lebold, McClintic, Campbell, Byington & Maynard, "Review of vibration analysis
methods for gearbox diagnostics and prognostics", Proc. 54th MFPT (2000), and by Večeř, Kreidl & Šmíd,
"Condition indicators for gearbox condition monitoring systems", Acta Polytechnica 45 (2005) 35-43,
with the original source named in each function.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "crest_factor",
    "energy_ratio",
    "fm0",
    "fm4",
    "kurtosis",
    "m6a",
    "m8a",
    "na4",
    "normalised_moment",
    "rms",
    "sideband_level",
]


def rms(x: np.ndarray) -> float:
    """Root mean square √(Σ x² / N) (Lebold et al. 2000, eq. 1).

    Parameters
    ----------
    x : ndarray
        The signal.

    Returns
    -------
    float
    """
    x = np.asarray(x, dtype=float)
    return float(np.sqrt(np.mean(x * x)))


def crest_factor(x: np.ndarray) -> float:
    """Crest factor max|x| / RMS(x) (Lebold et al. 2000; a sine gives √2).

    Parameters
    ----------
    x : ndarray
        The signal.

    Returns
    -------
    float
    """
    x = np.asarray(x, dtype=float)
    return float(np.max(np.abs(x)) / rms(x))


def normalised_moment(x: np.ndarray, k: int) -> float:
    """N^{k/2−1} Σ (x − x̄)^k / (Σ (x − x̄)²)^{k/2}: the k-th central moment over the variance^{k/2}.

    Parameters
    ----------
    x : ndarray
        The signal.
    k : int
        The order of the moment.

    Returns
    -------
    float
    """
    d = np.asarray(x, dtype=float)
    d = d - d.mean()
    m2 = np.mean(d * d)
    return float(np.mean(d**k) / m2 ** (k / 2))


def kurtosis(x: np.ndarray) -> float:
    """Kurtosis N Σ(x − x̄)⁴ / (Σ(x − x̄)²)² (Lebold et al. 2000, eq. 5; a sine gives 1.5, Gaussian noise 3).

    Parameters
    ----------
    x : ndarray
        The signal.

    Returns
    -------
    float
    """
    return normalised_moment(x, 4)


def fm0(tsa: np.ndarray, mesh_amplitudes: np.ndarray) -> float:
    """FM0 = peak-to-peak of the TSA / Σ of the amplitudes of the mesh-frequency harmonics in it
    (Stewart, "Some useful data analysis techniques for gearbox diagnostics", ISVR report MHM/R/10/77,
    1977; Lebold et al. 2000, eq. 8).

    Parameters
    ----------
    tsa : ndarray
        The TSA.
    mesh_amplitudes : ndarray
        Amplitudes of the mesh harmonics in the TSA.

    Returns
    -------
    float
    """
    tsa = np.asarray(tsa, dtype=float)
    return float((tsa.max() - tsa.min()) / np.sum(mesh_amplitudes))


def fm4(difference: np.ndarray) -> float:
    """FM4 = kurtosis of the difference signal (Stewart 1977; Lebold et al. 2000, eq. 9).

    Parameters
    ----------
    difference : ndarray
        The difference signal.

    Returns
    -------
    float
    """
    return kurtosis(difference)


def na4(residual: np.ndarray, previous: list[np.ndarray] | None = None) -> float:
    """NA4 = N Σ(r − r̄)⁴ / [(1/M) Σ_j Σ_i (r_ij − r̄_j)²]² of the residual signal r, the denominator the
    variance averaged over the M records up to this one (Zakrajsek, Townsend & Decker, NASA TM-105950,
    1993; Lebold et al. 2000, eq. 11).  With no earlier records (M = 1) it is the residual's kurtosis.

    Parameters
    ----------
    residual : ndarray
        The residual signal of this record.
    previous : list of ndarray, optional
        The residual signals of the earlier records of the run.

    Returns
    -------
    float
    """
    r = np.asarray(residual, dtype=float)
    records = [np.asarray(p, dtype=float) for p in (previous or [])] + [r]
    var = np.mean([np.mean((p - p.mean()) ** 2) for p in records])
    d = r - r.mean()
    return float(np.mean(d**4) / var**2)


def m6a(difference: np.ndarray) -> float:
    """M6A = N² Σ(d − d̄)⁶ / (Σ(d − d̄)²)³ of the difference signal (Martin, "Statistical moments
    based diagnostics of helicopter gearboxes", 1989; Lebold et al. 2000, eq. 15; a sine gives 2.5).

    Parameters
    ----------
    difference : ndarray
        The difference signal.

    Returns
    -------
    float
    """
    return normalised_moment(difference, 6)


def m8a(difference: np.ndarray) -> float:
    """M8A = N³ Σ(d − d̄)⁸ / (Σ(d − d̄)²)⁴ of the difference signal (Martin 1989; Lebold et al. 2000,
    eq. 16; a sine gives 35/8 = 4.375).

    Parameters
    ----------
    difference : ndarray
        The difference signal.

    Returns
    -------
    float
    """
    return normalised_moment(difference, 8)


def sideband_level(tsa: np.ndarray, sideband_amplitudes: np.ndarray) -> float:
    """Sideband level factor: the sum of the first-order sidebands about the fundamental mesh frequency
    over the standard deviation of the TSA (Lebold et al. 2000, eq. 13).

    Parameters
    ----------
    tsa : ndarray
        The TSA.
    sideband_amplitudes : ndarray
        Amplitudes of the first-order sidebands about the fundamental mesh order.

    Returns
    -------
    float
    """
    return float(np.sum(sideband_amplitudes) / np.std(np.asarray(tsa, dtype=float)))


def energy_ratio(difference: np.ndarray, regular: np.ndarray) -> float:
    """Energy ratio RMS(difference) / RMS(regular) (Swansson, "A comparison of vibration signal analysis
    techniques applied to gearbox condition monitoring", ARL report 1980; Lebold et al. 2000, eq. 12).

    Parameters
    ----------
    difference : ndarray
        The difference signal.
    regular : ndarray
        The regular signal.

    Returns
    -------
    float
    """
    return rms(np.asarray(difference) - np.mean(difference)) / rms(np.asarray(regular) - np.mean(regular))
