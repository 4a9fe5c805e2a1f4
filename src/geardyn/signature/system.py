"""The vibration signature of a multi-DOF system: the acceleration of a translational DOF (a bearing or
housing sensor), sampled like a data acquisition with the pinion's once-per-revolution tachometer.

A system is recorded by the same acquisition as the pair (:func:`geardyn.signature.acquire.record_system`,
any system of the contract with a sensor) and read by the same order tracking, TSA and indicators
(:func:`geardyn.signature.run.record`); this module holds only what a system adds: its sensor (a DOF) and
its shafts (a mesh).

The state history of :func:`geardyn.integrate.trajectory` holds q̃' at every RK4 step; the sensor's
acceleration is its derivative, a = s_i ω_n² d q̃'_i/dτ (s_i = b_c on a translation), taken from the
cubic spline through the history (the step is < 1/200 of a mesh period, so the spline's derivative is
accurate to the step's fourth power times the signal's fourth derivative), then resampled at f_s.

The shafts are those of one mesh (default the reference mesh): its pinion turns at the mesh's frequency
r ω ω_n/2π (r its ``ratio``) over its ``teeth``; the wheel's teeth are the pinion's times the ratio of the
rotation entries of the mesh vector (the base radii of a spur or helical mesh, the mean radii of a bevel
mesh) rounded to the nearest integer within a quarter tooth, or those of a tooth-pair file.  The default
sensor is the translation of the mesh's pinion most nearly along the line of action.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from scipy.interpolate import CubicSpline

from ..errors import ModelError
from .acquire import record_system

__all__ = [
    "check_sensor",
    "default_rate",
    "default_sensor",
    "mesh_shafts",
    "settle_time",
    "system_signature",
    "system_signature_sweep",
    "with_excitation",
]

_TRANSLATIONS = ("x", "y", "z")


def _mesh(system: Any, mesh: str | None) -> Any:
    desc = system.description
    name = system.scaling.reference if mesh is None else mesh
    for m in desc.meshes:
        if m.name == name:
            return m
    raise ModelError(f"mesh: {name!r} is not a mesh of the system; meshes: {', '.join(m.name for m in desc.meshes)}")


def _translations(system: Any) -> list[str]:
    """The system's translational DOFs (accelerometer positions)."""
    return [lab for lab in system.labels if lab.rsplit(".", 1)[-1] in _TRANSLATIONS]


def mesh_shafts(system: Any, mesh: str | None = None) -> tuple[int, int | None, str | None]:
    """The pinion's teeth, the wheel's teeth (``None`` if the mesh vector does not give them) and the pinion body.

    The wheel's teeth are z1 |v_θ,wheel| / |v_θ,pinion| (the ratio of the base or mean radii) rounded, when
    that is within a quarter tooth of an integer.

    Parameters
    ----------
    system : SystemModel
    mesh : str, optional
        The mesh (default the reference mesh).

    Returns
    -------
    (int, int or None, str or None)
    """
    m = _mesh(system, mesh)
    if m.teeth is None:
        raise ModelError(f"mesh {m.name!r}: teeth: the pinion's teeth are needed for its shaft speed and orders")
    rot = [(b, abs(c)) for (b, d), c in m.vector if d == "theta" and c != 0]
    z1 = int(m.teeth)
    if len(rot) != 2:
        return z1, None, rot[0][0] if rot else None
    z2 = z1 * rot[1][1] / rot[0][1]
    return z1, (int(round(z2)) if abs(z2 - round(z2)) <= 0.25 else None), rot[0][0]


def default_sensor(system: Any, mesh: str | None = None) -> str:
    """The translation of the mesh's pinion with the largest component of the mesh vector (the bearing
    sensor most nearly along the line of action), else of its wheel, else the system's first translation.

    Parameters
    ----------
    system : SystemModel
    mesh : str, optional
        The mesh (default the reference mesh).

    Returns
    -------
    str
        A DOF label such as ``"pinion.y"``.
    """
    m = _mesh(system, mesh)
    trans = [(f"{b}.{d}", abs(c)) for (b, d), c in m.vector if d in _TRANSLATIONS]
    labels = list(system.labels)
    bodies = list(dict.fromkeys(b for (b, _d), _c in m.vector))
    for body in bodies:
        own = [(lab, c) for lab, c in trans if lab.startswith(body + ".") and lab in labels]
        if own:
            return max(own, key=lambda t: t[1])[0]
    anyt = _translations(system)
    if not anyt:
        raise ModelError(
            f"sensor: the system has no translational DOF (x, y or z) for an accelerometer; DOFs: {', '.join(labels)}"
        )
    return anyt[0]


def check_sensor(system: Any, dof: str) -> None:
    """Raise :class:`~geardyn.errors.ModelError` unless ``dof`` is a translational DOF of the system.

    Parameters
    ----------
    system : SystemModel
    dof : str
        A DOF label (``"pinion.y"``).
    """
    trans = _translations(system)
    if dof not in trans:
        what = "a rotation, not a translation" if dof in system.labels else "not a DOF of the system"
        raise ModelError(
            f"sensor: {dof!r} is {what}; the translations (accelerometer positions) are: {', '.join(trans) or 'none'}"
        )


def with_excitation(system: Any, mesh: str | None, path: str | Path, harmonics: int | None = None) -> Any:
    """The system with the stiffness and STE of ``mesh`` (default the reference mesh) from an excitation file
    (a table or a tooth-pair file, :func:`geardyn.tooth.table.read_table`) in place of its own, at the same
    pinion speed.

    Parameters
    ----------
    system : SystemModel
    mesh : str or None
        The mesh.
    path : str or Path
        The excitation file.
    harmonics : int, optional
        Harmonics of the table's period kept (default the mesh's ``excitation_harmonics``, else all).

    Returns
    -------
    SystemModel
    """
    from ..systems.assemble import assemble

    m = _mesh(system, mesh)
    name = "xi" if m.xi is not None else "c"
    damp, phc = getattr(m, name), m.phi_c
    if m.excitation is not None and m.cycles > 1 and damp:  # undo the table's spreading over P cycles
        damp, phc = damp[m.cycles - 1 :: m.cycles], phc[m.cycles - 1 :: m.cycles]
    new = dataclasses.replace(
        m,
        stiffness=None,
        kappa=(),
        phi_k=(),
        e=(),
        phi_e=(),
        cycles=1,
        excitation=str(path),
        excitation_harmonics=m.excitation_harmonics if harmonics is None else int(harmonics),
        phi_c=tuple(phc),
        **{name: (tuple(damp) if damp is not None else None)},
    )
    desc = system.description
    desc = dataclasses.replace(desc, meshes=tuple(new if x.name == m.name else x for x in desc.meshes))
    s = assemble(desc, None)
    rpm = system.scaling.rpm_from_omega(system.omega)
    return s.with_param("omega", s.scaling.omega_from_rpm(rpm))


def default_rate(system: Any, f_mesh: float) -> float:
    """The default sampling rate: 20 samples per mesh period and 5 per period of the system's highest natural
    frequency (linearised with the teeth in contact, :func:`geardyn.systems.modes.modal_analysis`), rounded up
    to 1 kHz.  The record has no anti-alias filter: a rate whose Nyquist frequency is below a mode the mesh
    excites folds that mode's response onto non-integer orders, into the difference signal.

    Parameters
    ----------
    system : SystemModel
    f_mesh : float
        The mesh frequency (Hz).

    Returns
    -------
    float
        Hz.
    """
    from ..systems.modes import modal_analysis

    f_top = float(np.max(modal_analysis(system.description).frequencies_hz))
    return 1000.0 * math.ceil(max(20.0 * f_mesh, 5.0 * f_top) / 1000.0)


def settle_time(system: Any, decays: float = 10.0, least: float = 300.0) -> float:
    """The non-dimensional time integrated and discarded before a record: ``decays`` time constants of the
    slowest-decaying mode of the system linearised with the teeth and clearances in contact (mean stiffness and
    damping of each mesh, :func:`geardyn.analysis.settle.decay_rate`), at least ``least``; rigid-body modes are
    left out, and a system with an undamped mode gets ``least``.

    Parameters
    ----------
    system : SystemModel
    decays : float
        Time constants 1/|Re λ| of the slowest mode (10: its free vibration down to e⁻¹⁰ ≈ 5e-5).
    least : float
        The least time.

    Returns
    -------
    float
        Δτ.
    """
    from ..analysis.settle import decay_rate

    try:
        decay = decay_rate(system)
    except ModelError:  # a mode undamped: no decay time
        return least
    return max(least, decays / decay)


def system_signature(
    system: Any,
    dof: str | None = None,
    *,
    mesh: str | None = None,
    revolutions: int | None = None,
    fs: float | None = None,
    z2: int | None = None,
    noise: float = 0.02,
    seed: int = 0,
    dtau: float = 0.01,
    label: str = "",
    extra: dict[str, Any] | None = None,
) -> xr.Dataset:
    """Record, order spectrum, TSA of pinion and wheel, regular/residual/difference signals and the indicators
    of a system's sensor: a ``signature`` result as the pair's (:func:`geardyn.signature.run.signature`).

    Parameters
    ----------
    system : SystemModel
    dof : str, optional
        A translational DOF (``"pinion.y"``; default :func:`default_sensor`).
    mesh : str, optional
        The mesh whose shafts are analysed (default the reference mesh).
    revolutions : int, optional
        Pinion revolutions recorded (default two wheel revolutions, at least 10, as the pair).
    fs : float, optional
        Sampling rate (default :func:`default_rate`).
    z2 : int, optional
        The wheel's teeth (default from the mesh vector, :func:`mesh_shafts`).
    noise, seed, dtau, label
        As :func:`geardyn.signature.run.signature`.
    extra : dict, optional
        More keys for the run's summary.

    Returns
    -------
    xarray.Dataset
        ``geardyn_kind = "signature"`` with the pair's variables and summary keys (``faults`` empty unless
        ``extra`` gives them); the run adds ``sensor``, ``mesh`` and ``omega``.
    """
    from .run import labelled, record

    m = _mesh(system, mesh)
    z1, zv, _body = mesh_shafts(system, mesh)
    z2 = zv if z2 is None else int(z2)
    if z2 is None:
        raise ModelError(
            f"mesh {m.name!r}: the wheel's teeth are not known (the mesh vector has no "
            f"rotation of both gears): give them (z2, or a tooth-pair file)"
        )
    dof = default_sensor(system, mesh) if dof is None else dof
    sc = system.scaling
    f_mesh = m.ratio * system.omega * sc.omega_n_rad_s / (2.0 * math.pi)
    if revolutions is None:
        revolutions = max(10, 2 * z2 // math.gcd(z1, z2))
    if fs is None:
        fs = default_rate(system, f_mesh)
    check_sensor(system, dof)
    i = list(system.labels).index(dof)

    def sensor(tr):  # the sensor's acceleration, d²q/dt² = s ω_n d(q̃′)/dt
        v = tr.x[:, system.n + i]
        t_sim = (tr.tau - tr.tau[0]) / sc.omega_n_rad_s
        if not np.all(np.isfinite(v)):
            return t_sim, v
        return t_sim, CubicSpline(t_sim, v).derivative()(t_sim) * sc.dof_scales[i] * sc.omega_n_rad_s

    acq = record_system(
        system,
        sensor,
        tau_per_rev=z1 * system.period / m.ratio,
        rpm=60.0 * f_mesh / z1,
        z1=z1,
        z2=int(z2 or z1),
        revolutions=revolutions,
        fs=fs,
        noise=noise,
        seed=seed,
        dtau=dtau,
        settle=settle_time(system),
    )
    sm = system.mesh(m.name)
    ds, ind = record(acq, z2, f"acceleration of {dof}", sm.n_harmonics / sm.cycles)
    summary = {
        "label": label,
        "rpm": acq.rpm,
        "fs_Hz": float(fs),
        "revolutions": int(revolutions),
        "z1": z1,
        "z2": z2,
        "mesh_frequency_Hz": f_mesh,
        "noise": noise,
        "excitation_cycles": int(sm.cycles),
        "harmonics": int(sm.n_harmonics),
        "omega_model": sm.ratio * system.omega,
        "omega_mesh": m.ratio * system.omega,
        "omega": system.omega,
        "omega_n_rad_s": sc.omega_n_rad_s,
        "k0_N_per_m": float(m.stiffness),
        "indicators": ind,
        "faults": [],
        "sensor": dof,
        "mesh": m.name,
        **(extra or {}),
    }
    return labelled(ds, summary, label)


def system_signature_sweep(
    make: Callable[[float], Any],
    sizes: Sequence[float],
    *,
    dof: str | None = None,
    mesh: str | None = None,
    name: str = "crack depth",
    revolutions: int | None = None,
    fs: float | None = None,
    z2: int | None = None,
    noise: float = 0.02,
    seed: int = 0,
    dtau: float = 0.01,
) -> xr.Dataset:
    """Indicators of the pinion and the wheel of a system's sensor against a fault size.

    Parameters
    ----------
    make : callable
        ``make(size) -> SystemModel`` (e.g. :func:`with_excitation` of a table per crack depth).
    sizes : sequence of float
        The fault sizes.
    dof, mesh : str, optional
        As :func:`system_signature` (the default sensor is that of the first system).
    name : str
        What the size is.
    revolutions, fs, z2, noise, seed, dtau
        As :func:`system_signature`.

    Returns
    -------
    xarray.Dataset
        ``geardyn_kind = "signature_sweep"`` as the pair's; the summary adds ``sensor`` and ``mesh``.
    """
    from .run import sweep_runs

    kw = dict(mesh=mesh, revolutions=revolutions, fs=fs, z2=z2, noise=noise, seed=seed, dtau=dtau)
    return sweep_runs(
        lambda size: system_signature(make(size), dof, **kw),
        sizes,
        name,
        lambda last: {"rpm": last["rpm"], "sensor": last["sensor"], "mesh": last["mesh"]},
    )
