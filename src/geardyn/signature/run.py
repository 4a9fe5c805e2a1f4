"""A pair's vibration signature as a Dataset: record, order spectrum, TSA per shaft, the signals
derived from it and the condition indicators; and indicators over a fault-size sweep."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import xarray as xr

from ..errors import ModelError
from ..tooth.excitation import pair_model
from ..tooth.mesh import MeshStiffness, faults_json
from .acquire import Acquisition, acquire
from .indicators import crest_factor, energy_ratio, fm0, fm4, kurtosis, m6a, m8a, na4, rms, sideband_level
from .signals import order_spectrum, split_tsa, tsa

__all__ = [
    "INDICATORS",
    "default_fs",
    "per_rev",
    "SIGNATURE_HARMONICS",
    "combine",
    "indicators",
    "labelled",
    "record",
    "signature",
    "signature_sweep",
    "sweep_runs",
]

#: Harmonics of the excitation's period a signature run keeps by default (the full table: ``harmonics=``).
SIGNATURE_HARMONICS = 64
#: The indicators reported, in order.
INDICATORS = tuple("rms crest_factor kurtosis fm0 fm4 na4 m6a m8a sideband_level energy_ratio".split())


def indicators(avg: np.ndarray, z: int, shaft_orders: int = 2) -> dict[str, float]:
    """Every indicator of :data:`INDICATORS` from the TSA of a shaft with ``z`` teeth.

    Parameters
    ----------
    avg : ndarray
        The TSA of a shaft.
    z : int
        Its teeth.
    shaft_orders : int
        As :func:`~geardyn.signature.signals.split_tsa`.

    Returns
    -------
    dict
        Indicator name → value.
    """
    p = split_tsa(avg, z, shaft_orders)
    x = avg - avg.mean()
    d = p["difference"]
    values = (
        rms(x),
        crest_factor(x),
        kurtosis(x),
        fm0(avg, p["mesh_amplitudes"]),
        fm4(d),
        na4(p["residual"]),
        m6a(d),
        m8a(d),
        sideband_level(avg, p["sidebands"]),
        energy_ratio(d, p["regular"]),
    )
    return dict(zip(INDICATORS, values))  # in the order of INDICATORS


def per_rev(z: int, top_order: float = 0.0) -> int:
    """Angle-domain points per revolution of a shaft with ``z`` teeth: at least 16 per period of every mesh
    harmonic the model holds (the highest, ``top_order`` mesh orders, and the mesh frequency itself), rounded up
    to a power of 2.  Each shaft gets its own: one count for both would resolve the gear with more teeth too
    coarsely and fold its mesh harmonics into its difference signal.

    Parameters
    ----------
    z : int
        Teeth of the shaft's gear.
    top_order : float
        Highest mesh order in the model's excitation (harmonics / cycles of its period).

    Returns
    -------
    int

    Examples
    --------
    >>> per_rev(19), per_rev(48), per_rev(48, top_order=3.37)
    (512, 1024, 4096)
    """
    return int(2 ** math.ceil(math.log2(16.0 * z * max(1.0, top_order))))


def default_fs(f_mesh: float, top_order: float = 0.0) -> float:
    """The default sampling rate: 20 samples per mesh period and 2.5 per period of the highest mesh harmonic
    the model holds, rounded up to 1 kHz (Hz).

    Parameters
    ----------
    f_mesh : float
        The mesh frequency (Hz).
    top_order : float, optional
        The highest mesh harmonic the model holds (0: only the 20 samples per mesh period apply).

    Returns
    -------
    float
        The sampling rate (Hz).

    Examples
    --------
    >>> default_fs(950.0), default_fs(950.0, top_order=32.0)
    (19000.0, 76000.0)
    """
    return 1000.0 * math.ceil(max(20.0, 2.5 * top_order) * f_mesh / 1000.0)


def signature(
    ms: MeshStiffness,
    rpm: float,
    *,
    revolutions: int | None = None,
    fs: float | None = None,
    noise: float = 0.02,
    seed: int = 0,
    harmonics: int | None = None,
    b_c: float = 10e-6,
    backlash: float = 100e-6,
    xi0: float = 0.05,
    dtau: float = 0.01,
    label: str = "",
) -> xr.Dataset:
    """Simulate the pair with the excitation of ``ms`` and read its signature.

    Parameters
    ----------
    ms : MeshStiffness
        The mesh (healthy or with faults); its period sets the model's forcing period.
    rpm : float
        Pinion speed.
    revolutions : int, optional
        Pinion revolutions recorded (default: two wheel revolutions, at least 10 pinion revolutions).
    fs : float, optional
        Sampling rate (default 20 samples per mesh period, rounded up to 1 kHz).
    noise, seed : float, int
        Measurement noise (share of the signal RMS) and its seed.
    harmonics : int, optional
        Harmonics of the excitation's period kept (default :data:`SIGNATURE_HARMONICS`: mesh orders up to
        64/P, the band where the noise of the record does not bury the fault's sidebands).
    b_c, backlash, xi0, dtau : float
        As :func:`geardyn.tooth.excitation.pair_model` and the RK4 step.
    label : str
        Name of the run (``healthy``, ``crack 50 %``).

    Returns
    -------
    xarray.Dataset
        ``geardyn_kind = "signature"``: ``accel`` and ``tach`` over ``time`` (the first pinion
        revolutions), ``order_amplitude`` over ``order``, ``tsa_pinion`` / ``regular`` / ``residual`` /
        ``difference`` over ``angle_pinion``, ``tsa_wheel`` over ``angle_wheel``; the indicators of each
        shaft in the ``summary`` attribute.
    """
    geo = ms.geometry
    z1, z2 = geo.gears[0].teeth, geo.gears[1].teeth
    H = min(SIGNATURE_HARMONICS, ms.stiffness.size // 2) if harmonics is None else harmonics
    model, sc = pair_model(ms, rpm, b_c=b_c, backlash=backlash, xi0=xi0, harmonics=H)
    if revolutions is None:
        revolutions = max(10, 2 * z2 // math.gcd(z1, z2))
    top, f_mesh = H / ms.cycles, rpm / 60.0 * z1
    if fs is None:
        fs = default_fs(f_mesh, top)
    acq = acquire(model, sc, revolutions, fs, noise=noise, seed=seed, dtau=dtau)
    ds, ind = record(acq, z2, "relative acceleration along the line of action", top)
    summary = {
        "label": label,
        "rpm": float(rpm),
        "fs_Hz": float(fs),
        "revolutions": int(revolutions),
        "z1": z1,
        "z2": z2,
        "mesh_frequency_Hz": f_mesh,
        "noise": noise,
        "excitation_cycles": ms.cycles,
        "harmonics": H,
        "omega_model": model.forcing_omega,
        "omega_mesh": sc["mesh_omega"],
        "omega_n_rad_s": sc["omega_n"],
        "k0_N_per_m": sc["k0"],
        "indicators": ind,
        "faults": faults_json(ms.faults),
    }
    return labelled(ds, summary, label)


def record(
    acq: Acquisition, z2: int | None, what: str, top_order: float = 0.0
) -> tuple[xr.Dataset, dict[str, dict[str, float]]]:
    """The variables of a ``signature`` result from a record, and the indicators of each shaft's TSA.

    Parameters
    ----------
    acq : Acquisition
        The record (its ``z1`` the teeth of the shaft the tachometer is on).
    z2 : int or None
        The wheel's teeth (None: no wheel TSA).
    what : str
        What the acceleration is (its ``long_name``).
    top_order : float
        Highest mesh order of the model's excitation (for :func:`per_rev`).

    Returns
    -------
    (xarray.Dataset, dict)
        ``accel`` and ``tach`` over ``time`` (the first three pinion revolutions), ``order_amplitude`` over
        ``order`` (up to 3.5 mesh orders), ``tsa_pinion`` / ``regular`` / ``residual`` / ``difference`` over
        ``angle_pinion``, ``tsa_wheel`` over ``angle_wheel``; shaft → indicator name → value.
    """
    z1, rpm = acq.z1, acq.rpm
    N = per_rev(z1, top_order)
    orders, amp = order_spectrum(acq, N)
    t1 = tsa(acq, N)
    p1 = split_tsa(t1, z1)
    ind = {"pinion": indicators(t1, z1)}
    keep = min(acq.time.size, int(3 * 60.0 / rpm * acq.fs))
    top = orders <= 3.5 * z1
    ds = xr.Dataset(
        {
            "accel": ("time", acq.accel[:keep], {"units": "m/s^2", "long_name": what}),
            "tach": ("time", acq.tach[:keep], {"units": "V", "long_name": "tachometer (pinion, once per revolution)"}),
            "order_amplitude": ("order", amp[top], {"units": "m/s^2", "long_name": "order spectrum amplitude"}),
            "tsa_pinion": ("angle_pinion", t1, {"units": "m/s^2", "long_name": "TSA of the pinion"}),
            **{k: ("angle_pinion", p1[k], {"units": "m/s^2"}) for k in ("regular", "residual", "difference")},
        },
        coords={
            "time": ("time", acq.time[:keep], {"units": "s"}),
            "order": ("order", orders[top], {"units": "1", "long_name": "pinion order"}),
            "angle_pinion": ("angle_pinion", 360.0 * np.arange(N) / N, {"units": "deg"}),
        },
    )
    if z2:
        try:
            N2 = per_rev(z2, top_order)
            t2 = tsa(acq, N2, z1 / z2)
        except ModelError:
            revs = int(round(acq.time[-1] * rpm / 60.0))
            raise ModelError(
                f"revolutions: {revs} pinion revolutions hold no whole revolution of the wheel "
                f"(z2/z1 = {z2}/{z1}); record at least {math.ceil(z2 / z1) + 2}"
            ) from None
        ind["wheel"] = indicators(t2, z2)
        ds["tsa_wheel"] = xr.DataArray(
            t2, dims="angle_wheel", attrs={"units": "m/s^2", "long_name": "TSA of the wheel"}
        )
        ds = ds.assign_coords(angle_wheel=("angle_wheel", 360.0 * np.arange(N2) / N2, {"units": "deg"}))
    return ds, ind


def labelled(ds: xr.Dataset, summary: dict[str, Any], label: str) -> xr.Dataset:
    """One run of a ``signature`` result: ``ds`` along ``run`` = [label] with its summary.

    Parameters
    ----------
    ds : xarray.Dataset
        As :func:`record` returns it.
    summary : dict
        The run's summary.
    label : str
        Its name.

    Returns
    -------
    xarray.Dataset
    """
    ds = ds.expand_dims(run=[label or "run"])
    ds.attrs.update(geardyn_kind="signature", summary=json.dumps({"runs": [summary]}))
    return ds


def combine(runs: Sequence[xr.Dataset]) -> xr.Dataset:
    """Runs of :func:`signature` side by side along ``run`` (healthy beside faulty).

    Parameters
    ----------
    runs : sequence of xarray.Dataset
        Results of :func:`signature`.

    Returns
    -------
    xarray.Dataset
    """
    ds = xr.concat(list(runs), dim="run", join="outer")
    ds.attrs.update(
        geardyn_kind="signature",
        summary=json.dumps({"runs": [json.loads(r.attrs["summary"])["runs"][0] for r in runs]}),
    )
    return ds


def signature_sweep(
    make: Callable[[float], MeshStiffness],
    sizes: Sequence[float],
    rpm: float,
    *,
    name: str = "crack depth",
    revolutions: int | None = None,
    fs: float | None = None,
    noise: float = 0.02,
    seed: int = 0,
    harmonics: int | None = None,
    b_c: float = 10e-6,
    backlash: float = 100e-6,
    xi0: float = 0.05,
    dtau: float = 0.01,
) -> xr.Dataset:
    """Indicators of the pinion and the wheel against a fault size.

    Parameters
    ----------
    make : callable
        ``make(size) -> MeshStiffness``.
    sizes : sequence of float
        Fault sizes (e.g. crack depths 0, 0.1 … 0.5).
    rpm : float
        Pinion speed.
    name : str
        What the size is.
    revolutions, fs, noise, seed, harmonics, b_c, backlash, xi0, dtau
        As :func:`signature`.

    Returns
    -------
    xarray.Dataset
        ``geardyn_kind = "signature_sweep"``: one variable per indicator over (``size``, ``shaft``).
    """

    kw = dict(
        revolutions=revolutions,
        fs=fs,
        noise=noise,
        seed=seed,
        harmonics=harmonics,
        b_c=b_c,
        backlash=backlash,
        xi0=xi0,
        dtau=dtau,
    )
    return sweep_runs(lambda size: signature(make(size), rpm, **kw), sizes, name, lambda last: {"rpm": rpm})


def sweep_runs(
    run: Callable[[float], xr.Dataset],
    sizes: Sequence[float],
    name: str,
    extra: Callable[[dict[str, Any]], dict[str, Any]],
) -> xr.Dataset:
    """A ``signature_sweep`` result from one ``signature`` run per fault size: the one sweep of the pair and
    of every system.

    The sizes in the order given are a run's history: each record's NA4 takes as its denominator the residual
    signal's variance averaged over the records up to it (Zakrajsek, Townsend & Decker 1993), as NA4 was
    defined for a trend; a single record's NA4 is its residual's kurtosis.

    Parameters
    ----------
    run : callable
        ``run(size) -> xarray.Dataset``, a ``signature`` result.
    sizes : sequence of float
        The fault sizes.
    name : str
        What the size is.
    extra : callable
        ``extra(last_run_summary) -> dict``: what the sweep's summary adds (``rpm``, ``sensor`` …).

    Returns
    -------
    xarray.Dataset
        One variable per indicator over (``size``, ``shaft``); the summary holds ``size_name``, what ``extra`` adds
        and ``sizes``.
    """
    rows, last = [], {}
    history: dict[str, list[np.ndarray]] = {"pinion": [], "wheel": []}
    for size in sizes:
        ds = run(float(size))
        last = json.loads(ds.attrs["summary"])["runs"][0]
        ind = last["indicators"]
        residual = {"pinion": np.asarray(ds["residual"].values[0], dtype=float)}
        if "wheel" in ind and "tsa_wheel" in ds:
            residual["wheel"] = split_tsa(np.asarray(ds["tsa_wheel"].values[0], dtype=float), int(last["z2"]))[
                "residual"
            ]
        for shaft, r in residual.items():
            ind[shaft]["na4"] = na4(r, history[shaft])
            history[shaft].append(r)
        rows.append(ind)
    shafts = [sh for sh in ("pinion", "wheel") if sh in rows[0]]
    a = np.array([[[r[sh][k] for k in INDICATORS] for sh in shafts] for r in rows])  # (size, shaft, indicator)
    ds = xr.Dataset(
        {k: (("size", "shaft"), a[:, :, i]) for i, k in enumerate(INDICATORS)},
        coords={"size": ("size", np.asarray(sizes, dtype=float), {"long_name": name}), "shaft": shafts},
    )
    summary = {"size_name": name, **extra(last), "sizes": [float(s) for s in sizes]}
    ds.attrs.update(geardyn_kind="signature_sweep", summary=json.dumps(summary))
    return ds
