"""Physical outputs of a result: transmission error in µm, mesh force in N, dynamic factor, Hz, rpm.

Everything here post-processes a result Dataset with the scales of a gear pair
(:class:`~geardyn.units.PhysicalScales`); nothing is integrated again.

Mesh force
----------
The normal mesh force is F_n = c_n(t) u_n′ + k_n(t) f(u_n) (``docs/model.md`` §2).  With
u_n = b_c u, d/dt = ω_n d/dτ, c_n = 2 m_e ω_n ξ(θ), k_n = k0 K(θ) and m_e ω_n² = k0:

    c_n u_n′ = 2 ξ(θ) m_e ω_n · b_c ω_n u′ = k0 b_c · 2 ξ(θ) u′,
    k_n f(u_n) = k0 K(θ) · b_c f(u; D),

so F_n / (k0 b_c) = 2 ξ(θ) u′ + K(θ) f(u; D) = C(θ) u′ + K(θ) f(u; D), with C and K the first two
coefficient functions of :meth:`GearModel.coefficients` and θ = ω τ.  The static mesh force is
F_p = f_p k0 b_c, and the **dynamic factor** is max F_n / F_p over the time history kept.  As in the
model, the viscous term acts whenever the teeth move relative to each other, also in separation.

Dynamic transmission error
--------------------------
The DTE is u_n = b_c u, the mesh deflection along the line of action relative to the rigid-body
motion with the static transmission error removed (the model's coordinate); ``dte_rms_um`` is its
RMS about the mean over all recorded periods, ``dte_amplitude_um`` half its peak-to-peak value.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from .._lazy import lazy_module
from ..io import PHYSICAL_SUFFIX, VARIABLES, Variable, json_attr, model_from_attrs, physical_long_name
from ..model import GearModel
from ..series import series_values
from ..units import SCALES_ATTR, PhysicalScales, scales_of

xr = lazy_module("xarray")

__all__ = [
    "add_physical",
    "contact_force",
    "mesh_force",
    "physical_json",
    "simulate_physical",
    "spectrum_peaks",
    "steady_physical",
]

#: Number of spectral lines listed by :func:`spectrum_peaks`.
N_PEAKS = 5
#: Lines smaller than this fraction of the largest line are not listed as peaks.
PEAK_REL_THRESHOLD = 1e-3

#: Keys of JSON summaries that hold non-dimensional displacements (a ``<key>_um`` copy is added).
JSON_DISPLACEMENT_KEYS = ("u_min", "u_max", "amplitude", "rms", "mean", "size", "amplitude_from", "amplitude_to")
#: Keys of JSON summaries that hold rates per unit τ (a ``<key>_per_s`` copy is added).
JSON_RATE_KEYS = ("exponents", "lle", "uncertainty")
#: Keys of JSON summaries that hold a mesh frequency ω (an ``rpm`` copy is added, ``omega_from`` → ``rpm_from``…).
JSON_OMEGA_KEYS = {"omega": "rpm", "omega_from": "rpm_from", "omega_to": "rpm_to"}

#: Non-dimensional variables of sweep results that are displacements (converted to µm).
DISPLACEMENT_VARIABLES = ("amplitude", "rms", "mean", "u_min", "u_max", "poincare_u", "amplitude_up", "amplitude_down")


def mesh_force(model: GearModel, tau: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Non-dimensional mesh force F_n/(k0 b_c) = C(θ) u′ + K(θ) f(u; D) at θ = ω τ.

    Parameters
    ----------
    model : GearModel
        The model that produced the trajectory.
    tau : ndarray
        Non-dimensional time, with θ = ω τ ≡ 0 (mod 2π) at τ = 0 (as in the ``simulate`` Dataset).
    u, v : ndarray
        Displacement u and velocity u′ = du/dτ (non-dimensional) at ``tau``.

    Returns
    -------
    ndarray
        The force in units of k0 b_c (multiply by :attr:`PhysicalScales.force_scale_N` for N).
    """
    u, v = (np.asarray(x, dtype=float) for x in (u, v))
    return model.element_forces(tau, np.stack([u, v], axis=-1)[:, None, :])[:, 0]


def contact_force(model: GearModel, tau: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Non-dimensional elastic contact force K(θ) f(u; D) at θ = ω τ (units k0 b_c).

    The force the teeth carry through contact: positive on the drive flank (u > D), zero in separation
    (|u| <= D), negative only on the back flank (u < −D).  :func:`mesh_force` adds the viscous term C(θ) u′,
    which the model applies also in separation (where it is no contact force and can be negative).

    Parameters
    ----------
    model : GearModel
    tau, u : ndarray
        Non-dimensional time (θ = ω τ) and displacement.

    Returns
    -------
    ndarray
    """
    tau, u = (np.asarray(x, dtype=float) for x in (tau, u))
    th = model.forcing_omega * tau
    if model.evaluation == "table":
        from ..meshtable import table_values

        K = table_values(model.table, model.cycles, th)[0]
    else:
        (K,) = series_values(model.coefficients(), th, (1,))
    return K * model.restoring(u)


def spectrum_peaks(
    order: np.ndarray, amplitude: np.ndarray, scales: PhysicalScales, omega: float, n: int = N_PEAKS
) -> list[dict[str, float]]:
    """The largest lines of an amplitude spectrum of u (order 0, the mean, excluded).

    Parameters
    ----------
    order : ndarray
        Frequencies as orders of the mesh frequency.
    amplitude : ndarray
        Amplitudes of u (non-dimensional).
    scales : PhysicalScales
        The pair's scales.
    omega : float
        Mesh frequency ω of the run.
    n : int
        Largest number of lines; default :data:`N_PEAKS` (lines below :data:`PEAK_REL_THRESHOLD`
        of the largest are left out).

    Returns
    -------
    list of dict
        ``{"order", "frequency_Hz", "amplitude", "amplitude_um"}``, largest first: the frequency
        as an order of the mesh frequency and in Hz, the amplitude non-dimensional and in µm.
    """
    order = np.asarray(order, dtype=float)
    amp = np.asarray(amplitude, dtype=float)
    keep = (order > 0) & np.isfinite(amp)
    if not np.any(keep):
        return []
    o, a = order[keep], amp[keep]
    top = float(np.max(a))
    idx = [i for i in np.argsort(-a)[:n] if a[i] > PEAK_REL_THRESHOLD * top]
    f_mesh = float(scales.hz_from_omega(omega))
    return [
        {
            "order": float(o[i]),
            "frequency_Hz": float(o[i] * f_mesh),
            "amplitude": float(a[i]),
            "amplitude_um": float(scales.um_from_u(a[i])),
        }
        for i in idx
    ]


def _set(ds: xr.Dataset, name: str, dims: Any, data: Any, coord: bool = False, meta: Variable | None = None) -> None:
    """Add a float variable (or coordinate) with its registry attributes (or those of ``meta``)."""
    from ._converted import Converted

    if isinstance(data, Converted):
        data = xr.core.indexing.LazilyIndexedArray(data)
    else:
        data = np.asarray(data, dtype=float)
    var = xr.Variable(dims, data, attrs=(meta or VARIABLES[name]).attrs())
    if coord:
        ds.coords[name] = var
    else:
        ds[name] = var


def simulate_physical(ds: xr.Dataset, scales: Any = None) -> dict[str, Any]:
    """Physical summary of a ``simulate`` Dataset (JSON-ready).

    Parameters
    ----------
    ds : xarray.Dataset
        A ``simulate`` result (variables ``u``, ``v`` on ``tau``; ``spectrum`` on ``order``; the
        model and the non-dimensional summary in its attributes).
    scales : PhysicalScales, LoadedConfig or None
        The gear pair's scales; ``None`` uses the scales stored in ``ds`` if any, else the
        paper's Table 1 pair (k0 assumed).

    Returns
    -------
    dict
        ``omega``, ``rpm``, ``mesh_frequency_Hz``, ``natural_frequency_Hz``, ``fp``,
        ``torque_N_m``, ``static_force_N``; ``dynamic_factor`` (max mesh force / F_p; ``None`` if
        F_p <= 0), ``mesh_force_max_N``, ``mesh_force_min_N``, ``mesh_force_mean_N`` (the model's mesh force,
        elastic and viscous: its minimum can be negative in separation), ``contact_force_max_N``,
        ``contact_force_min_N`` (the elastic contact force, negative only in back-flank contact);
        ``dte_rms_um``, ``dte_amplitude_um``, ``dte_mean_um``, ``dte_min_um``, ``dte_max_um``,
        ``backlash_um`` (half backlash D b_c); ``spectrum_peaks``; ``history_periods`` (how many
        periods the force extremes are taken over); ``pair`` (the statement of the pair and its
        k0) and ``assumed``.  ``None`` for values of a diverged run.  A model without a gear pair
        (unit scales, :attr:`~geardyn.units.PhysicalScales.nondimensional`) gets only ``pair`` and
        ``physical`` = None: no speed, torque, force or length exists to report.

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, add_physical, load_config, simulate, simulate_physical
    >>> ds = simulate(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=8)).to_dataset()
    >>> out = simulate_physical(add_physical(ds, load_config()))
    >>> round(out["rpm"]), round(out["static_force_N"]), round(out["dynamic_factor"], 2)
    (2395, 20000, 3.78)
    """
    return _simulate_summary(
        _resolve_scales(ds, scales),
        model_from_attrs(ds),
        json.loads(ds.attrs.get("summary", "{}")),
        ds["tau"].values,
        ds["u"].values,
        ds["v"].values,
        ds["order"].values,
        ds["spectrum"].values,
        int(ds.attrs.get("history_periods", 0)),
    )


def steady_physical(res: Any, scales: Any = None) -> dict[str, Any]:
    """The physical summary of a steady state without building its Dataset.

    The values of ``simulate_physical(add_physical(res.to_dataset(), scales))``: the model, the
    summary and the scales are read back from the same JSON as the Dataset's attributes.

    Parameters
    ----------
    res : SteadyState
        The result of :func:`geardyn.analysis.steady.simulate`.
    scales : PhysicalScales, LoadedConfig or None
        The gear pair's scales (``None``: the paper's Table 1 pair, k0 assumed).

    Returns
    -------
    dict
        The keys of :func:`simulate_physical`.
    """
    from .steady import _jsonable, amplitude_spectrum

    t = res.traj
    order, spec = amplitude_spectrum(t.u, t.history_periods * (res.model.period_multiple() or 1))
    return _simulate_summary(
        PhysicalScales.from_json(scales_of(scales).to_json()),
        GearModel.from_dict(json.loads(json_attr(res.model))),
        json.loads(json_attr(_jsonable(res.summary))),
        t.tau,
        t.u,
        t.v,
        order,
        spec,
        int(t.history_periods),
    )


def _simulate_summary(
    sc: PhysicalScales,
    model: GearModel,
    summ: dict[str, Any],
    tau: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    order: np.ndarray,
    spectrum: np.ndarray,
    history_periods: int,
) -> dict[str, Any]:
    if getattr(sc, "nondimensional", False):  # no gear pair: no physical value exists to report
        return {"pair": sc.statement(), "physical": None}
    force = mesh_force(model, tau, u, v)
    ok = bool(np.all(np.isfinite(force))) and summ.get("status", "ok") == "ok"
    out: dict[str, Any] = dict(sc.operating_point(model))
    out["dynamic_factor"] = (float(np.max(force)) / model.fp) if (ok and model.fp > 0) else None
    contact = contact_force(model, tau, u)
    for key, f, a in (
        ("mesh_force_max_N", np.max, force),
        ("mesh_force_min_N", np.min, force),
        ("mesh_force_mean_N", np.mean, force[:-1]),
        ("contact_force_max_N", np.max, contact),
        ("contact_force_min_N", np.min, contact),
    ):
        out[key] = float(sc.N_from_force(f(a))) if ok else None
    for key, nd in (
        ("dte_rms_um", "rms"),
        ("dte_amplitude_um", "amplitude"),
        ("dte_mean_um", "mean"),
        ("dte_min_um", "u_min"),
        ("dte_max_um", "u_max"),
    ):
        x = summ.get(nd)  # None where not finite (the JSON summary)
        out[key] = None if x is None or not np.isfinite(x) else float(sc.um_from_u(float(x)))
    out["backlash_um"] = float(sc.um_from_u(model.D))
    out["spectrum_peaks"] = spectrum_peaks(order, spectrum, sc, model.omega) if ok else []
    out["history_periods"] = history_periods or None
    out["pair"] = sc.statement()
    out["assumed"] = list(sc.assumed)
    return out


def _resolve_scales(ds: xr.Dataset, scales: Any) -> PhysicalScales:
    if scales is None:
        stored = PhysicalScales.from_attrs(ds.attrs)
        if stored is not None:
            return stored
    return scales_of(scales)


def add_physical(ds: xr.Dataset, scales: Any = None, *, lazy: bool = False) -> xr.Dataset:
    """A copy of a result Dataset with physical coordinates and variables added.

    Whatever the kind of result:

    * an ``omega`` coordinate gains ``rpm`` (pinion speed) and ``mesh_frequency_Hz``;
    * an ``fp`` coordinate gains ``torque_N_m`` (pinion torque, balanced);
    * displacement variables (:data:`DISPLACEMENT_VARIABLES`) gain ``<name>_um`` copies in µm;
    * ``lle`` gains ``lle_per_s`` (1/s);
    * a frequency response gains the attributes ``jumps_physical`` (its jumps with ``rpm``,
      ``rpm_from``, ``rpm_to``, ``size_um``, ``amplitude_from_um``, ``amplitude_to_um``) and
      ``hysteresis_rpm`` (JSON);
    * the scales are stored as the JSON attribute ``physical_scales``.

    A ``simulate`` result further gains ``time_s`` (on ``tau``), ``dte_um``, ``mesh_force``
    (units k0 b_c) and ``mesh_force_N`` (on ``tau``), ``frequency_Hz`` (on ``order``),
    ``spectrum_um`` and the attribute ``physical_summary`` (:func:`simulate_physical`, JSON).

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.
    scales : PhysicalScales, LoadedConfig or None
        The gear pair's scales (``None``: stored ones, else the paper's Table 1 pair).
    lazy : bool
        The physical copies of the per-point variables (``<name>_um``, ``lle_per_s``) computed
        when they are read (loaded, or written to NetCDF one at a time) rather than held: for
        sweeps too large to hold twice.  The values are the same.

    Returns
    -------
    xarray.Dataset
        The copy (the data of ``ds`` shared, not copied).

    Examples
    --------
    >>> from geardyn import GearModel, IntegrationOptions, add_physical, load_config, simulate
    >>> ds = simulate(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=8)).to_dataset()
    >>> ds = add_physical(ds, load_config())  # the paper's pair: µm, N, rpm
    >>> ds["dte_um"].attrs["units"], ds["mesh_force_N"].attrs["units"]
    ('µm', 'N')
    """
    from ._converted import Converted

    sc = _resolve_scales(ds, scales)
    if getattr(sc, "nondimensional", False):  # no gear pair: nothing physical to add
        return ds.copy()

    def per_point(values: np.ndarray, fn: Any) -> Any:
        return Converted(values, fn) if lazy else fn(values)

    out = ds.copy()
    out.attrs[SCALES_ATTR] = sc.to_json()
    if "omega" in out.coords or "omega" in out.dims:
        w = out["omega"]
        _set(out, "rpm", w.dims, sc.rpm_from_omega(w.values), coord=True)
        _set(out, "mesh_frequency_Hz", w.dims, sc.hz_from_omega(w.values), coord=True)
    if "fp" in out.coords:
        f = out["fp"]
        _set(out, "torque_N_m", f.dims, sc.torque_from_fp(f.values), coord=True)
    for name in DISPLACEMENT_VARIABLES:
        if name in out.data_vars:
            da = out[name]
            long_name = physical_long_name(str(da.attrs.get("long_name", name)))
            _set(
                out,
                f"{name}{PHYSICAL_SUFFIX}",
                da.dims,
                per_point(da.values, sc.um_from_u),
                meta=Variable("µm", long_name),
            )
    if "lle" in out.data_vars:
        _set(out, "lle_per_s", out["lle"].dims, per_point(out["lle"].values, sc.per_s_from_per_tau))
    if "jumps" in out.attrs and str(out.attrs.get("param", "omega")) == "omega":
        conv = _walk(
            {
                "jumps": json.loads(out.attrs["jumps"]),
                "hysteresis": json.loads(out.attrs.get("hysteresis", "[]")),
            },
            sc,
            "omega",
        )
        out.attrs["jumps_physical"] = json.dumps(conv["jumps"])
        out.attrs["hysteresis_rpm"] = json.dumps(conv["hysteresis_rpm"])
    if out.attrs.get("geardyn_kind") == "simulate" and {"tau", "u", "v"} <= set(out.variables):
        model = model_from_attrs(out)
        tau = out["tau"].values
        if "delta" in out.variables:  # every element's deflection: the reference mesh's force among the meshes'
            deltas = np.stack([out["delta"].values, out["delta_rate"].values], axis=-1)
            f = model.element_forces(tau, deltas)[:, model.reference]
        else:
            f = mesh_force(model, tau, out["u"].values, out["v"].values)
        _set(out, "time_s", ("tau",), sc.s_from_tau(tau), coord=True)
        _set(out, "dte_um", ("tau",), sc.um_from_u(out["u"].values))
        _set(out, "mesh_force", ("tau",), f)
        _set(out, "mesh_force_N", ("tau",), sc.N_from_force(f))
        if "order" in out.coords:
            _set(out, "frequency_Hz", ("order",), sc.hz_from_omega(model.omega * out["order"].values), coord=True)
        if "spectrum" in out.data_vars:
            _set(out, "spectrum_um", ("order",), sc.um_from_u(out["spectrum"].values))
        if "fp" in model.parameters():  # the pair's (a system's physical summary is its System.report, in "summary")
            out.attrs["physical_summary"] = json.dumps(simulate_physical(out, sc), sort_keys=True)
    return out


#: Element types of a nested list that :func:`_convert` converts as one array (None: a missing value).
_ARRAY_TYPES = frozenset((float, int, type(None)))


def _convert(x: Any, fn) -> Any:
    """Apply ``fn`` to every number of a nested list (None and non-numbers kept as they are).

    A nested list of numbers and None with the shape of an array is converted at once
    (:func:`_convert_array`), anything else element by element; the values are the same.
    """
    if isinstance(x, (list, tuple)):
        out = _convert_array(x, fn)
        return out if out is not None else [_convert(v, fn) for v in x]
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return x
    y = float(fn(float(x)))
    return y if np.isfinite(y) else None


def _convert_array(x: list | tuple, fn) -> list | None:
    """:func:`_convert` of a rectangular nested list of floats, ints and None, as one array; None otherwise.

    ``fn`` is one of the scale conversions (products and quotients by constants), which give the
    same bits on an array as on each number; None becomes NaN on the way in and every non-finite
    result None on the way out, as element by element.
    """
    a = np.array(x, dtype=object)
    if a.size == 0 or not set(map(type, a.ravel().tolist())) <= _ARRAY_TYPES:
        return None
    none = np.equal(a, None)
    vals = np.where(none, np.nan, a).astype(float)
    y = np.asarray(fn(vals), dtype=float)
    out = y.astype(object)
    out[~np.isfinite(y)] = None
    return out.tolist()


def _walk(d: dict[str, Any], sc: PhysicalScales, param: str | None) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in d.items():
        out[k] = (
            _walk(v, sc, param)
            if isinstance(v, dict)
            else ([_walk(e, sc, param) if isinstance(e, dict) else e for e in v] if isinstance(v, list) else v)
        )
    for k, v in d.items():
        if isinstance(v, dict):
            continue
        if k in JSON_OMEGA_KEYS and JSON_OMEGA_KEYS[k] not in d:
            out[JSON_OMEGA_KEYS[k]] = _convert(v, sc.rpm_from_omega)
        elif k in JSON_DISPLACEMENT_KEYS and f"{k}_um" not in d:
            out[f"{k}_um"] = _convert(v, sc.um_from_u)
        elif k in JSON_RATE_KEYS and f"{k}_per_s" not in d:
            out[f"{k}_per_s"] = _convert(v, sc.per_s_from_per_tau)
    # the values of ω that gain their speeds: a 2-D map's ω axis, a sweep's over ω (key, its copy, its type)
    speeds = [(f"{axis}_values", f"{axis}_values_rpm", list) for axis in ("x", "y") if d.get(axis) == "omega"]
    if param == "omega":
        speeds += [
            ("values", "values_rpm", list),
            ("start", "rpm_start", (int, float)),
            ("stop", "rpm_stop", (int, float)),
            ("hysteresis", "hysteresis_rpm", list),
        ]
    for key, copy, kind in speeds:
        if isinstance(d.get(key), kind) and copy not in d:
            out[copy] = _convert(d[key], sc.rpm_from_omega)
    return out


def physical_json(
    summary: dict[str, Any], model: GearModel, scales: Any = None, *, param: str | None = None
) -> dict[str, Any]:
    """A command's JSON summary with physical values added alongside the non-dimensional ones.

    Added, wherever they occur in the (nested) summary: ``rpm`` next to every ``omega`` (and
    ``rpm_from``/``rpm_to`` next to ``omega_from``/``omega_to``); ``<key>_um`` next to every
    displacement (:data:`JSON_DISPLACEMENT_KEYS`: u_min, u_max, amplitude, rms, mean, jump sizes);
    ``<key>_per_s`` next to Lyapunov exponents and their uncertainty.  When the swept parameter
    ``param`` is ω: ``values_rpm`` next to ``values``, ``rpm_start``/``rpm_stop`` next to ``start``/``stop``
    and ``hysteresis_rpm`` next to ``hysteresis``; a map whose ``x`` (``y``) is ω gains ``x_values_rpm``
    (``y_values_rpm``).  At the
    top level: ``physical`` with the operating point of ``model`` (speed, mesh frequency, torque,
    static force; for a sweep over ω the speed is that of the base model), the pair's statement
    (``pair``) and its assumed inputs (``assumed``).

    Parameters
    ----------
    summary : dict
        The non-dimensional JSON summary (left unchanged; a new dict is returned).
    model : GearModel
        The (base) model of the command.
    scales : PhysicalScales, LoadedConfig or None
        The gear pair (``None``: the paper's Table 1 pair, k0 assumed).
    param : str, optional
        The swept parameter, if any.
    """
    sc = scales_of(scales)
    if getattr(sc, "nondimensional", False):  # no gear pair: the physical values would repeat ω, f_p and u
        return {**summary, "physical": None}
    out = _walk(summary, sc, param)
    phys = dict(sc.operating_point(model))
    phys["pair"] = sc.statement()
    phys["assumed"] = list(sc.assumed)
    phys["scales"] = sc.to_dict()
    out.setdefault("physical", phys)
    return out
