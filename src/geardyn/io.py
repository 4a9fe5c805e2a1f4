"""Dataset conventions and NetCDF input/output.

Every result is one :class:`xarray.Dataset`: dimensions named after what they index (swept
parameters by their canonical names), variables with ``units`` and ``long_name`` attributes, the
full model and options as JSON attributes (``model``, ``options``), the kind of result in
``geardyn_kind``, and a per-point ``status`` where there are points.  Files are written
atomically: to a temporary file in the same directory, then renamed.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import asdict, is_dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from ._lazy import lazy_module
from .atomic import atomic_write_bytes, write_netcdf_bytes
from .errors import ModelError
from .labels import IMPACT_LABELS, MOTION_LABELS, motion_label
from .model import GearModel, canonical_param
from .params import describe
from .status import Status

xr = lazy_module("xarray")


class Variable(NamedTuple):
    """Metadata of one variable: ``units`` ("1" = non-dimensional), ``long_name``, for coded
    variables ``flags`` (code → meaning, written as CF ``flag_values``/``flag_meanings``), and ``text``
    for a variable that holds names (a sweep's direction, a bifurcation's type), not numbers."""

    units: str
    long_name: str
    flags: Mapping[int, str] | None = None
    text: bool = False

    def attrs(self) -> dict[str, Any]:
        """The variable's attributes as geardyn writes them."""
        out: dict[str, Any] = {"units": self.units, "long_name": self.long_name}
        if self.flags:
            out["flag_values"] = list(self.flags)
            out["flag_meanings"] = " ".join(v.replace(" ", "_") for v in self.flags.values())
        return out


_STATUS_FLAGS = {int(s): s.label for s in Status}
_ONE = "1"


def _v(long_name: str, units: str = _ONE, flags: Mapping[int, str] | None = None, text: bool = False) -> Variable:
    return Variable(units, long_name, flags, text)


def _table(entries: Mapping[str, Any]) -> dict[str, Variable]:
    """The Variables of a registry table whose entries are written as a Variable, a long name alone
    (non-dimensional) or (long name, units)."""
    return {k: v if isinstance(v, Variable) else _v(v) if isinstance(v, str) else _v(*v) for k, v in entries.items()}


#: Every variable and coordinate geardyn writes, by name (kinds that mean something else by a name
#: override it in :data:`KIND_VARIABLES`).  :func:`annotate` writes their attributes.
VARIABLES: dict[str, Variable] = _table(
    {
        # time histories and spectra
        "tau": "non-dimensional time τ = ω_n t",
        "u": "dynamic transmission error u (non-dimensional)",
        "v": "velocity du/dτ (non-dimensional)",
        "poincare_u": "Poincaré section u at θ ≡ 0",
        "poincare_v": "Poincaré section du/dτ at θ ≡ 0",
        "order": "order of the mesh frequency",
        "spectrum": "single-sided amplitude spectrum of u",
        "section": "index of the recorded Poincaré point",
        # steady-response measures and classes
        "amplitude": "half peak-to-peak displacement",
        "rms": "RMS of u about its mean",
        "mean": "mean displacement",
        "u_min": "smallest displacement",
        "u_max": "largest displacement",
        "period": "period of the Poincaré sequence (0 not periodic, -1 diverged)",
        "impact": _v("impact state (0 none, 1 single-sided, 2 double-sided, -1 unknown)", flags=IMPACT_LABELS),
        "motion": _v(
            "motion class (-1 diverged, 0 unresolved, 1 periodic, 2 quasi-periodic, 3 chaotic)", flags=MOTION_LABELS
        ),
        "fraction_drive": "time fraction in drive-side contact",
        "fraction_separation": "time fraction in separation",
        "fraction_back": "time fraction in back-side contact",
        "status": _v("point status (0 ok, 1 diverged)", flags=_STATUS_FLAGS),
        "lle": ("largest Lyapunov exponent", "1/τ"),
        "lle_err": ("standard error of the largest Lyapunov exponent (block statistics)", "1/τ"),
        "lambda2": ("second Lyapunov exponent", "1/τ"),
        "loops": "closed curves of a quasi-periodic Poincaré section (0 otherwise)",
        "settled": "settling passes run for the point before classification (0: periodic after the transient)",
        "settle_ratio": "contraction of the Poincaré sequence onto a cycle over the record (1: stationary)",
        "curve_dim": "correlation dimension of the Poincaré section of a non-periodic point (1: closed curves)",
        # sweeps
        "restarted": "1 where a continuation restarted from the initial state after a diverged point",
        "start_state": "initial state of the point ((u, u') for the pair, (q̃, q̃') for a system)",
        "end_state": "final state of the point (the start of the next continuation point)",
        "state": "state coordinate ((u, u') for the pair, (q̃, q̃') for a system)",
        "sweep": _v(
            "sweep direction (up: increasing parameter, down: decreasing, fixed: same initial state)", text=True
        ),
        # model parameters: their long names and units come from the registry (geardyn.params, see variable())
        # Lyapunov spectrum
        "log_r": "log of the Gram–Schmidt diagonal per forcing period",
        "running": ("running Lyapunov exponent estimate", "1/τ"),
        "exponents": ("Lyapunov exponents", "1/τ"),
        "uncertainty": ("standard error of the exponents (block statistics)", "1/τ"),
        "exponent": "exponent index (1 largest)",
        # basins
        "u0": "initial displacement u0 at θ = 0",
        "v0": "initial velocity u0' at θ = 0",
        "attractor": "attractor reached (index into attractor_index; -1 diverged)",
        "attractor_period": "period of the attractor (0 not periodic)",
        "attractor_motion": "motion class of the attractor",
        "attractor_fraction": "fraction of the grid in the attractor's basin",
        "attractor_amplitude": "half peak-to-peak displacement on the attractor",
        "attractor_u": "Poincaré points u of the attractor (its cycle)",
        "attractor_v": "Poincaré points u' of the attractor (its cycle)",
        "attractor_index": "attractor number (0: largest basin)",
        "cycle_point": "index of a Poincaré point of the attractor",
        # periodic orbits and continuation
        "multiplier_re": "Floquet multiplier, real part",
        "multiplier_im": "Floquet multiplier, imaginary part",
        "floquet_exponent": ("Floquet exponent ln|μ|/(nT)", "1/τ"),
        "monodromy": "monodromy matrix (Jacobian of the n-period map)",
        "multiplier": "multiplier index (largest modulus first)",
        "row": "row of the monodromy matrix",
        "col": "column of the monodromy matrix",
        "branch": "branch index",
        "stable": "orbit stable (1) or unstable (0)",
        "point": "index of the branch point",
        "bifurcation": "index of the bifurcation",
        "bifurcation_type": _v("bifurcation type", text=True),
        "bifurcation_period": "period of the branch the bifurcation lies on",
        "bifurcation_branch": "branch index of the bifurcation",
        "bifurcation_u": "orbit u at θ = 0 at the bifurcation",
        "bifurcation_v": "orbit du/dτ at θ = 0 at the bifurcation",
        "bifurcation_amplitude": "orbit amplitude at the bifurcation",
        "bifurcation_detail": _v("which multiplier or boundary", text=True),
        # stability boundaries
        "xi0_critical": "ξ0 below which the period-n response loses stability",
        "xi0_critical_linear": "ξ0 above which the linear contact model (D = 0, unforced) is stable",
        "xi0_paper": "paper's condition ½√(1 − κ1²)",
        # physical units (geardyn.analysis.physical.add_physical)
        "rpm": ("pinion speed", "rpm"),
        "mesh_frequency_Hz": ("mesh frequency", "Hz"),
        "torque_N_m": ("pinion torque (balanced)", "N·m"),
        "lle_per_s": ("largest Lyapunov exponent per second", "1/s"),
        "time_s": ("time", "s"),
        "dte_um": ("dynamic transmission error u_n", "µm"),
        "mesh_force": "mesh force F_n/(k0 b_c)",
        "mesh_force_N": ("dynamic mesh force F_n", "N"),
        "frequency_Hz": ("frequency", "Hz"),
        "spectrum_um": ("amplitude spectrum of the dynamic transmission error", "µm"),
    }
)

_ORBIT_SECTION = "index of the section point along the orbit"
_FORCING_PERIOD = "index of the recorded forcing period"
_BOUNDARY_TYPE = {"bifurcation_type": _v("bifurcation at the stability boundary", text=True)}

#: What a name means in one kind of result where it differs from :data:`VARIABLES`.
KIND_VARIABLES: dict[str, dict[str, Variable]] = {
    kind: _table(table)
    for kind, table in {
        "simulate": {"section": _FORCING_PERIOD},
        "lyapunov": {"section": _FORCING_PERIOD},
        "orbit": {"section": _ORBIT_SECTION},
        "continuation": {
            "section": _ORBIT_SECTION,
            "amplitude": "half peak-to-peak displacement of the orbit",
            "period": "period of the orbit (forcing periods)",
            "u": "orbit displacement u at θ = 0",
            "v": "orbit velocity du/dτ at θ = 0",
            "poincare_u": "section points u of the orbit (θ ≡ 0)",
            "poincare_v": "section points du/dτ of the orbit (θ ≡ 0)",
            "status": _v("point status (0 ok)", flags=_STATUS_FLAGS),
        },
        "stability_boundary": _BOUNDARY_TYPE,
        "stability_comparison": _BOUNDARY_TYPE,
        "mathieu_boundary": {"xi0_critical": "ξ0 above which the linear contact model is stable"},
        "runup": {
            "order_amplitude": "order-tracked DTE amplitude |u_l| over a speed block",
            "order_amplitude_um": ("order-tracked DTE amplitude over a speed block", "µm"),
            "amplitude": "half peak-to-peak displacement over a speed block",
            "amplitude_um": ("half peak-to-peak DTE over a speed block", "µm"),
            "dynamic_factor": "dynamic factor max F_n / F_p over a speed block",
            "omega": "mesh frequency ω = ω_e/ω_n of a speed block",
            "tau": "non-dimensional time τ = ω_n t at the middle of a speed block",
            "time_s": ("time at the middle of a speed block", "s"),
        },
        "rattle": {
            "impact": "index of the impact",
            "impact_time": "time τ of an impact (start of a contact)",
            "impact_flank": _v("flank of an impact", flags={1: "drive", -1: "back"}),
            "impact_velocity": "relative velocity du/dτ at an impact",
        },
        "rattle_map": {
            "amplitude_scale": "scale of the torque orders' amplitudes",
            "impacts_drive": "drive-flank impacts per forcing cycle",
            "impacts_back": "back-flank impacts per forcing cycle",
            "impact_velocity_max": "largest relative impact velocity |du/dτ|",
            "impact_velocity_max_m_s": ("largest relative impact velocity", "m/s"),
            "rattle_index": "rattle index: impact kinetic-energy loss per cycle (k b_c²)",
            "rattle_index_J": ("rattle index: impact kinetic-energy loss per cycle", "J"),
            "status": "point status (0 ok, 1 diverged)",
        },
        "hb": {
            "coefficients": "Fourier coefficients [a0, a1..aH, b1..bH] of u(φ), φ = ωτ/n",
            "coefficient": "index of the Fourier coefficient",
            "dof": _v("coordinate whose Fourier coefficients these are (u for the pair, q̃ for a system)", text=True),
            "stable": "solution stable (1) or unstable (0) by Hill's multipliers",
        },
    }.items()
}

#: Metadata of the variables of the results of mesh-vector systems (entered in :data:`KIND_VARIABLES` for
#: every ``system_*`` kind, so that :func:`annotate` fills them in).
SYSTEM_VARIABLES: dict[str, Variable] = _table(
    {
        "element": "element (meshes, then clearances)",
        "mesh": "gear mesh",
        "coordinate": "state coordinate (q̃, then q̃')",
        "state": "state coordinate (q̃, then q̃')",
        "delta": "deflection δ of the element (DTE over b_c for a mesh)",
        "delta_rate": "rate dδ/dτ of the element",
        "u": "deflection δ of the reference mesh",
        "v": "rate dδ/dτ of the reference mesh",
        "mesh_force": "mesh force over k_ref b_c",
        "mesh_force_N": ("dynamic mesh force", "N"),
        "poincare": "Poincaré points of the full state at θ ≡ 0",
        "points": "section points of the orbit (full state)",
        "elastic": "elastic multiplier index (largest modulus first)",
        "elastic_re": "elastic Floquet multiplier, real part",
        "elastic_im": "elastic Floquet multiplier, imaginary part",
        "poincare_u": "Poincaré section δ of the reference mesh at θ ≡ 0",
        "poincare_v": "Poincaré section dδ/dτ of the reference mesh at θ ≡ 0",
        "poincare_coordinate": "Poincaré section of the chosen state coordinate",
        "mesh_u_min": "smallest deflection δ of the mesh",
        "mesh_u_max": "largest deflection δ of the mesh",
        "mesh_amplitude": "half peak-to-peak deflection δ of the mesh",
        "mesh_impact": "impact state of the mesh (0 none, 1 single-sided, 2 double-sided)",
        "mesh_mean": "mean deflection δ of the mesh",
        "mesh_rms": "RMS of δ of the mesh about its mean",
        "u0": "initial value of the first slice coordinate at θ = 0",
        "v0": "initial value of the second slice coordinate at θ = 0",
        "value": "continuation parameter value",
        "element_u_min": "smallest deflection δ of the element",
        "element_u_max": "largest deflection δ of the element",
        "bifurcation_value": "continuation parameter at the bifurcation",
        "element_mean": "mean deflection δ of the element",
        "element_rms": "RMS of δ of the element about its mean",
        "element_impact": "impact state of the element (0 none, 1 single-sided, 2 double-sided)",
    }
)
#: The kinds the previous versions wrote for systems (``system_<analysis>``); their files stay readable.
SYSTEM_KINDS = tuple(
    f"system_{k}" for k in ("simulate", "lyapunov", "orbit", "bifurcation", "response", "map", "basins", "continuation")
)
for _k in SYSTEM_KINDS:
    KIND_VARIABLES.setdefault(_k, {}).update(SYSTEM_VARIABLES)
#: Every kind: the variables that only a system's results have (per element, full states).
_SYSTEM_ONLY = (
    "element",
    "mesh",
    "coordinate",
    "delta",
    "delta_rate",
    "mesh_force",
    "mesh_force_N",
    "element_u_min",
    "element_u_max",
    "element_mean",
    "element_rms",
    "element_impact",
    "elastic",
    "elastic_re",
    "elastic_im",
    "poincare",
    "points",
)

#: Suffix of the copy of a displacement variable in µm (``amplitude_um``; see :func:`physical_long_name`).
PHYSICAL_SUFFIX = "_um"
#: Name of the global attribute listing the Datasets attached to a result (see :func:`attach`).
CONTEXT_ATTR = "geardyn_context"
#: Separator between an attached Dataset's name and its variables' names.
CONTEXT_SEPARATOR = "__"


def _is_parameter(name: str) -> bool:
    try:
        return canonical_param(name) == name
    except ModelError:
        return False


def variable(name: str, kind: str | None = None) -> Variable | None:
    """The metadata of variable ``name`` in a result of ``kind``, or ``None`` if geardyn does not know it.

    Looks in :data:`KIND_VARIABLES` for ``kind``, then :data:`VARIABLES`; a model parameter
    without an entry (``xi1``, ``kappa2``, ``phi_e1`` …) is "parameter <name>" (radians for phases);
    ``bifurcation_<parameter>`` is the parameter at a bifurcation; ``<name>_um`` is the copy in µm of
    a non-dimensional displacement variable.

    Parameters
    ----------
    name : str
        Variable or coordinate name.
    kind : str, optional
        The result's ``geardyn_kind``.

    Returns
    -------
    Variable or None
    """
    meta = KIND_VARIABLES.get(kind or "", {}).get(name) or VARIABLES.get(name)
    if meta is None and name in _SYSTEM_ONLY:
        meta = SYSTEM_VARIABLES[name]
    if meta is not None:
        return meta
    if _is_parameter(name):
        return _v(*describe(name))
    if name.startswith("fraction_"):  # a counter of another element law than the dead zone
        return _v(f"time fraction counted as {name[len('fraction_') :]} by the reference element's law")
    if name.startswith("bifurcation_") and _is_parameter(name[len("bifurcation_") :]):
        return _v(f"parameter {name[len('bifurcation_') :]} at the bifurcation")
    if name.endswith(PHYSICAL_SUFFIX):
        base = variable(name[: -len(PHYSICAL_SUFFIX)], kind)
        if base is not None and base.units == _ONE:
            return _v(physical_long_name(base.long_name), "µm")
    return None


def physical_long_name(long_name: str) -> str:
    """Long name of the µm copy of a displacement variable: "displacement" read as "DTE", else "(DTE)" added."""
    return long_name.replace("displacement", "DTE") if "displacement" in long_name else f"{long_name} (DTE)"


def json_attr(obj: Any) -> str:
    """Serialise a System (its ``to_attrs``), options dataclass or plain value to a JSON attribute string."""
    to_attrs = getattr(obj, "to_attrs", None)
    if callable(to_attrs):
        return to_attrs()
    return json.dumps(asdict(obj) if is_dataclass(obj) else obj, sort_keys=True, default=_default)


def _default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def annotate(ds: xr.Dataset, kind: str | None = None, *, names: Iterable[str] | None = None) -> xr.Dataset:
    """Fill in the registry's attributes (:func:`variable`) for every known variable lacking them.

    ``units``, ``long_name`` and, for coded variables, ``flag_values``/``flag_meanings`` are set
    where missing (attributes already present are kept).  Variables of an attached Dataset
    (:func:`attach`) are looked up under their own name and that Dataset's kind.

    Parameters
    ----------
    ds : xarray.Dataset
        A result, annotated in place.
    kind : str, optional
        Its kind; default the ``geardyn_kind`` attribute.
    names : iterable of str, optional
        Annotate only these variables (default: all).

    Returns
    -------
    xarray.Dataset
        ``ds``.
    """
    kind = kind or ds.attrs.get("geardyn_kind")
    ctx = _contexts(ds)
    for name in list(ds.variables) if names is None else list(names):
        base, k = str(name), kind
        head, sep, tail = base.partition(CONTEXT_SEPARATOR)
        if sep and head in ctx:
            base, k = tail, ctx[head].get("geardyn_kind")
        meta = variable(base, k)
        if meta is None:
            continue
        attrs = ds[name].attrs
        for key, val in meta.attrs().items():
            attrs.setdefault(key, val)
    return ds


def _contexts(ds: xr.Dataset) -> dict[str, dict[str, Any]]:
    raw = ds.attrs.get(CONTEXT_ATTR)
    return json.loads(raw) if raw else {}


def attach(ds: xr.Dataset, name: str, other: xr.Dataset) -> xr.Dataset:
    """A copy of ``ds`` carrying ``other`` (e.g. the brute-force sweep drawn under a continuation).

    ``other``'s variables, coordinates and dimensions are added as ``<name>__<their name>`` and
    its global attributes are kept in the JSON attribute :data:`CONTEXT_ATTR`, so that one NetCDF
    file holds everything its figures need; :func:`attached` gives ``other`` back.

    Parameters
    ----------
    ds : xarray.Dataset
        The main result.
    name : str
        Name of the attached Dataset (no ``__`` in it).
    other : xarray.Dataset
        The Dataset to attach.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ValueError
        If ``name`` contains the separator.
    """
    if CONTEXT_SEPARATOR in name or not name:
        raise ValueError(f"attach: name must be non-empty without {CONTEXT_SEPARATOR!r}, got {name!r}")
    ren = {str(k): f"{name}{CONTEXT_SEPARATOR}{k}" for k in list(other.variables) + list(other.dims)}
    prefixed = other.rename(ren)
    prefixed.attrs = {}
    out = xr.merge([ds, prefixed], combine_attrs="override")
    out.attrs = dict(ds.attrs)
    ctx = _contexts(ds)
    ctx[name] = {str(k): (v if isinstance(v, str) else json_attr(v)) for k, v in other.attrs.items()}
    out.attrs[CONTEXT_ATTR] = json.dumps(ctx, sort_keys=True)
    return out


def attached(ds: xr.Dataset, name: str) -> xr.Dataset | None:
    """The Dataset attached to ``ds`` under ``name`` by :func:`attach`, or ``None``.

    Parameters
    ----------
    ds : xarray.Dataset
        A result, e.g. read from a NetCDF file.
    name : str
        Name given to :func:`attach`.

    Returns
    -------
    xarray.Dataset or None
    """
    ctx = _contexts(ds)
    if name not in ctx:
        return None
    pre = f"{name}{CONTEXT_SEPARATOR}"
    names = [k for k in ds.variables if str(k).startswith(pre)]
    sub = ds[names] if names else xr.Dataset()
    sub = sub.drop_vars([c for c in sub.coords if not str(c).startswith(pre)])
    ren = {str(k): str(k)[len(pre) :] for k in list(sub.variables) + list(sub.dims) if str(k).startswith(pre)}
    out = sub.rename(ren)
    out.attrs = dict(ctx[name])
    return out


def detach(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` without the Datasets attached by :func:`attach`."""
    ctx = _contexts(ds)
    if not ctx:
        return ds
    pre = tuple(f"{n}{CONTEXT_SEPARATOR}" for n in ctx)
    out = ds.drop_vars([k for k in ds.variables if str(k).startswith(pre)])
    out = out.drop_dims([d for d in out.dims if str(d).startswith(pre)])
    out.attrs = {k: v for k, v in ds.attrs.items() if k != CONTEXT_ATTR}
    return out


def json_number(x: Any) -> float | None:
    """A finite number as float, else ``None`` (JSON has no NaN)."""
    x = float(x)
    return x if np.isfinite(x) else None


def json_values(
    da: xr.DataArray | np.ndarray, kind: str | None = None, *, name: str | None = None, period: Any = None
) -> Any:
    """JSON-ready nested lists of a per-point variable, converted as geardyn's ``--json`` outputs do.

    Coded variables (with flags in the registry) become their labels; ``motion`` of a periodic point
    becomes "period-n" when ``period`` is given; ``period`` and ``attractor_period`` become the
    period or ``None`` (not periodic, diverged); other numbers become floats or ``None`` (not finite).

    Parameters
    ----------
    da : xarray.DataArray or ndarray
        The values (any shape).
    kind : str, optional
        The result's kind (for :func:`variable`).
    name : str, optional
        The variable's name; default ``da.name``.
    period : array_like, optional
        Periods of the same shape, for ``motion``.

    Returns
    -------
    list (nested as the array) or a scalar for a 0-d array
    """
    name = str(name if name is not None else getattr(da, "name", ""))
    vals = np.asarray(getattr(da, "values", da))
    meta = variable(name, kind)
    flat = vals.ravel()
    if name == "motion":
        per = np.broadcast_to(np.asarray(period), vals.shape) if period is not None else np.full(vals.shape, None)
        out = [motion_label(int(c), None if p is None else int(p)) for c, p in zip(flat, per.ravel())]
    elif meta is not None and meta.flags:
        out = [meta.flags.get(int(c), "unknown") for c in flat]
    elif name in ("period", "attractor_period"):
        out = [int(p) if p > 0 else None for p in flat]
    else:
        out = [json_number(x) for x in flat]
    return np.array(out, dtype=object).reshape(vals.shape).tolist()


def status_counts(ds: xr.Dataset) -> dict[str, int]:
    """Number of points of each status label (``{"ok": n, "diverged": m, …}``, labels present only)."""
    if "status" not in ds.variables:
        return {}
    codes, counts = np.unique(np.asarray(ds["status"].values).astype(int), return_counts=True)
    return {Status(int(c)).label: int(n) for c, n in zip(codes, counts)}


def summary_json(ds: xr.Dataset, variables: Any = None) -> dict[str, Any]:
    """The part every ``--json`` summary of a Dataset shares: kind, model, options, status counts,
    coordinates and per-point arrays.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.
    variables : sequence of str, optional
        The per-point variables to include (converted by :func:`json_values`; ``motion`` with the
        Dataset's ``period``); default every data variable with the ``status`` dimensions.

    Returns
    -------
    dict
        ``kind``, ``model`` and ``options`` (dicts, ``None`` if absent), ``status`` (counts by
        label), ``coords`` (each dimension coordinate of the per-point grid as a list) and
        ``points`` (name → nested lists over the grid).
    """
    kind = ds.attrs.get("geardyn_kind")
    dims = ds["status"].dims if "status" in ds.variables else ()
    if variables is None:
        variables = [str(k) for k, v in ds.data_vars.items() if v.dims == dims and dims]
    period = ds["period"] if "period" in ds.variables else None
    motion = period is not None and "motion" in ds.variables and period.shape == ds["motion"].shape
    points = {
        str(k): json_values(ds[k], kind, period=period.values if k == "motion" and motion else None) for k in variables
    }
    return {
        "kind": kind,
        "model": json.loads(ds.attrs["model"]) if "model" in ds.attrs else None,
        "options": json.loads(ds.attrs["options"]) if "options" in ds.attrs else None,
        "status": status_counts(ds),
        "coords": {str(d): json_values(ds[d], kind) for d in dims if d in ds.coords and ds[d].dtype.kind in "fiu"},
        "points": points,
    }


def result_attrs(kind: str, model: Any, options: Any = None, **extra: Any) -> dict[str, str]:
    """Standard global attributes of a result computed on any System.

    ``geardyn_kind``, ``geardyn_version``, ``geardyn_system`` (the name of the System's backend: ``pair`` or
    ``mesh``; :func:`model_from_attrs` rebuilds the System from it), the options and ``extra`` as JSON, and the
    System: the pair's model whole in ``model``; a system's as :func:`_system_attrs` stores it.

    Examples
    --------
    >>> from geardyn.model import GearModel
    >>> a = result_attrs("simulate", GearModel())
    >>> a["geardyn_kind"], a["geardyn_system"]
    ('simulate', 'pair')
    """
    from . import __version__

    attrs = {"geardyn_kind": kind, "geardyn_version": __version__, "geardyn_system": model.backend.name}
    attrs |= {"model": model.to_attrs()} if model.backend.name == "pair" else _system_attrs(model)
    if options is not None:
        attrs["options"] = json_attr(options)
    for k, v in extra.items():
        attrs[k] = v if isinstance(v, str) else json_attr(v)
    return attrs


def _system_attrs(model: Any) -> dict[str, str]:
    """A system result's own attributes: the system whole and described.

    ``system_model`` is the non-dimensional system whole (its ``to_attrs``: what :func:`model_from_attrs`
    rebuilds), ``system`` describes it for the figures and summaries (file, title, labels, meshes, elements,
    scales), ``model`` gives its ω and the reference element's gap.
    """
    desc = model.description
    sysinfo = {
        "labels": list(model.labels),
        "meshes": [m.name for m in model.meshes],
        "clearances": list(model.clearance_names),
        "reference_mesh": model.scaling.reference,
        "omega": model.omega,
        "title": getattr(desc, "title", None),
        "source": str(getattr(desc, "source", "") or "") or None,
        "elements": [{"name": e.name, "kind": e.kind, "gap": e.gap} for e in model.elements],
    }
    sc = model.scaling  # the scales of the physical units (µm, N, rpm)
    sysinfo.update(b_c_um=sc.b_c_m * 1e6, force_scale_N=sc.force_scale_N, omega_n=sc.omega_n_rad_s, teeth=sc.z1 or None)
    return {
        "system": json.dumps(sysinfo),
        "system_model": model.to_attrs(),
        "model": json.dumps({"omega": model.omega, "D": model.elements[model.reference].gap}),
    }


def model_from_attrs(ds: xr.Dataset) -> Any:
    """The System a result was computed on, rebuilt from its attributes.

    A :class:`~geardyn.model.GearModel` for the pair's results (``model``), a
    :class:`~geardyn.systems.SystemModel` for a system's (``system_model``; without its physical description).

    Raises
    ------
    ModelError
        For a system result written before the system was stored with it (0.1.x), or no model at all.

    Examples
    --------
    >>> import xarray as xr
    >>> from geardyn.model import GearModel
    >>> ds = xr.Dataset(attrs=result_attrs("simulate", GearModel(omega=0.8)))
    >>> model_from_attrs(ds) == GearModel(omega=0.8)
    True
    """
    attrs = ds.attrs
    kind = attrs.get("geardyn_system") or ("mesh" if "system" in attrs else "pair")
    if kind == "pair":
        if "model" not in attrs:
            raise ModelError("model: the result stores no model (not a geardyn result?)")
        return GearModel.from_attrs(attrs["model"])
    if "system_model" not in attrs:
        src = json.loads(attrs.get("system", "{}")).get("source")
        raise ModelError(
            "model: this system result was written by an earlier geardyn, which did not store the system; "
            f"load it with geardyn.load_system({src!r})"
        )
    from .systems.assemble import SystemModel

    return SystemModel.from_attrs(attrs["system_model"])


#: The names of the full start and end states of a sweep's points in results written by 0.1.0, where the
#: pair's were written as components (read as ``start_state``/``end_state`` over ``state`` = u, u').
LEGACY_STATES = {"start_state": ("start_u", "start_v"), "end_state": ("end_u", "end_v")}


def upgrade(ds: xr.Dataset) -> xr.Dataset:
    """A result written by an earlier geardyn in today's schema (itself when it already is).

    The pair's ``start_u``, ``start_v``, ``end_u``, ``end_v`` of 0.1.0 become ``start_state`` and
    ``end_state`` over ``state`` = (u, u'), in the main Dataset and in the Datasets attached to it.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> old = xr.Dataset({k: ("D", np.zeros(2)) for k in ("start_u", "start_v", "end_u", "end_v")})
    >>> new = upgrade(old)
    >>> sorted(new.data_vars), new["state"].values.tolist()
    (['end_state', 'start_state'], ['u', "u'"])
    """
    prefixes = [""] + [f"{n}{CONTEXT_SEPARATOR}" for n in _contexts(ds)]
    out = ds
    for pre in prefixes:
        for new, (a, b) in LEGACY_STATES.items():
            if pre + a not in out.variables or pre + b not in out.variables:
                continue
            state = f"{pre}state"
            st = xr.concat([out[pre + a], out[pre + b]], dim=state).transpose(..., state)
            st.attrs = dict(VARIABLES[new].attrs())
            out = out.drop_vars([pre + a, pre + b]).assign({pre + new: st})
            if state not in out.coords:
                out = out.assign_coords({state: ["u", "u'"]})
                out[state].attrs = dict(VARIABLES["state"].attrs())
    return out


def write_netcdf(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to NetCDF (h5netcdf) atomically, its variables annotated (:func:`annotate`).

    The file is produced in memory and then written (:mod:`geardyn.atomic`): a full disk or a
    file-size limit is an :class:`OSError` naming ``path``, and nothing is left.

    Parameters
    ----------
    ds : xarray.Dataset
        The result.
    path : str or Path
        The file (its directory is created if missing).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from geardyn import GearModel, IntegrationOptions, read_netcdf, simulate, write_netcdf
    >>> ds = simulate(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=8)).to_dataset()
    >>> path = write_netcdf(ds, pathlib.Path(tempfile.mkdtemp()) / "simulate.nc")
    >>> read_netcdf(path)["poincare_u"].shape == ds["poincare_u"].shape
    True
    """
    data = write_netcdf_bytes(lambda buf: annotate(ds).to_netcdf(buf, engine="h5netcdf"))
    return atomic_write_bytes(path, data)


def read_netcdf(path: str | Path) -> xr.Dataset:
    """Read a geardyn NetCDF file fully into memory, in today's schema (:func:`upgrade`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from geardyn import GearModel, IntegrationOptions, read_netcdf, simulate, write_netcdf
    >>> ds = simulate(GearModel(omega=0.8), IntegrationOptions(transient=50, periods=8)).to_dataset()
    >>> again = read_netcdf(write_netcdf(ds, pathlib.Path(tempfile.mkdtemp()) / "simulate.nc"))
    >>> again.attrs["geardyn_kind"], again.geardyn.model.omega
    ('simulate', 0.8)
    """
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return upgrade(ds.load())


#: Dimensions of the variables a figure draws, by result kind (a variable of another shape is refused).
RESULT_DIMS: dict[str, dict[str, tuple[str, ...]]] = {
    "simulate": {
        "u": ("tau",),
        "v": ("tau",),
        "tau": ("tau",),
        "poincare_u": ("section",),
        "poincare_v": ("section",),
        "spectrum": ("order",),
        "order": ("order",),
    },
}
#: Variables that must share their dimensions in every kind (a point's u beside its v).
SAME_DIMS = (("u", "v"), ("poincare_u", "poincare_v"))
#: Coordinates that hold names (text) in a result (variables that do are marked ``text`` in the registry).
TEXT_COORDINATES = (
    "element",
    "state",
    "mesh",
    "coordinate",
    "body",
    "dof",
    "side",
    "variable",
    "claim",
)


def result_variables(ds: Any, where: str = "", error: type[Exception] = ModelError) -> None:
    """The variables of a result read back have a numeric type (:data:`NUMERIC_VARIABLES`) and the dimensions
    they are drawn on (:data:`RESULT_DIMS`, :data:`SAME_DIMS`).

    A NetCDF file edited by hand (a variable turned to text, an array of another shape) is refused before
    anything is drawn or computed from it.

    Parameters
    ----------
    ds : xarray.Dataset
        The result.
    where : str
        The file, named in the message (none by default).
    error : type
        The error raised.

    Raises
    ------
    ModelError (or ``error``)
        ``<file>: variable <name> ...`` naming what was expected.
    """
    where = f"{where}: " if where else ""
    kind = ds.attrs.get("geardyn_kind") if hasattr(ds, "attrs") else None
    registered = {**VARIABLES, **SYSTEM_VARIABLES, **KIND_VARIABLES.get(str(kind), {})}
    for name, var in ds.variables.items():
        name = str(name)
        if name not in registered or registered[name].text or name in TEXT_COORDINATES:
            continue
        if getattr(var.dtype, "kind", "O") not in "biuf":
            raise error(f"{where}variable {name!r} holds {var.dtype} values; a geardyn result stores numbers there")
    expected = RESULT_DIMS.get(str(kind), {})
    for name, dims in expected.items():
        if name in ds.variables and tuple(ds[name].dims) != dims:
            raise error(f"{where}variable {name!r} has dimensions {tuple(ds[name].dims)}, expected {dims}")
    for a, b in SAME_DIMS:
        if a in ds.variables and b in ds.variables and ds[a].shape != ds[b].shape:
            raise error(f"{where}variables {a!r} {tuple(ds[a].dims)} and {b!r} {tuple(ds[b].dims)} must have one shape")
