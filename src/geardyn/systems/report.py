"""What a :class:`~geardyn.systems.SystemModel` adds to a result's summary: per-mesh and per-clearance entries.

The analyses are written once against the System contract; their ``--json`` keys are those of the 1-DOF pair
(the reference element's), and :meth:`SystemModel.report` adds ``meshes`` (each mesh's DTE, non-dimensional
and in µm, mesh force in N and dynamic factor, contact fractions and impact state), ``clearances`` likewise,
and the DOF labels.

Mesh force ``s_m = C_m(θ) δ_m' + K_m(θ) f(δ_m; D_m)`` (units k_ref b_c); the dynamic factor is its
largest value over the history divided by the static mesh force (the mesh force of the static
equilibrium at mean stiffness in drive contact, ``K̄ q̃ = F̃ + Σ k_m D_m V_m``, least-norm for
rigid-body modes; for the paper's torsional pair exactly f_p).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..labels import IMPACT_LABELS, impact_state
from ..series import series_values

__all__ = ["static_mesh_forces", "mesh_forces", "report", "result_meshes", "physical_scales"]


def _num(x: Any) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


def static_mesh_forces(model: Any) -> np.ndarray:
    """Static mesh force of every mesh (units k_ref b_c), see the module docstring.

    Parameters
    ----------
    model : SystemModel

    Returns
    -------
    ndarray (meshes,)
        k_m (V_m·q̃ − D_m) at the static equilibrium K̄ q̃ = F̃ + Σ k_m D_m V_m (least-norm solution; with rolling
        bearings their forces at the cage's θ = 0 angle join K̄ q̃, solved by Newton's method); a force
        within the rounding of that solve (1e-9 of the largest k_m max(D_m, 1) or |F̃|) is 0: an unloaded mesh.
    """
    Kt = np.array(model.Kb, dtype=float)
    rhs = np.array(model.F, dtype=float)
    for m, v in zip(model.meshes, model.V):
        Kt += m.k * np.outer(v, v)
        rhs += m.k * m.D * v
    if model.bearings:  # rolling bearings: the nonlinear static problem, cage at θ = 0
        from .rolling import static_deflection

        items = [
            (model.Vb[2 * b : 2 * b + 2], br.elements, br.K, br.exponent, br.clearance, br.phase)
            for b, br in enumerate(model.bearings)
        ]
        q = static_deflection(Kt, rhs, items)[0]
    else:
        q = np.linalg.lstsq(Kt, rhs, rcond=1e-12)[0]
    f = np.array([m.k * (v @ q - m.D) for m, v in zip(model.meshes, model.V)])
    scale = max([1.0, float(np.max(np.abs(model.F), initial=0.0))] + [m.k * max(m.D, 1.0) for m in model.meshes])
    f[np.abs(f) <= 1e-9 * scale] = 0.0
    return f


def mesh_forces(model: Any, tau: np.ndarray, deltas: np.ndarray, viscous: bool = True) -> np.ndarray:
    """Mesh forces s_m = C_m(θ) δ_m' + K_m(θ) f(δ_m; D_m) from the element deflections.

    Parameters
    ----------
    model : SystemModel
    tau : ndarray (K,)
        Times τ.
    deltas : ndarray (K, elements, 2)
        Deflection δ and its rate δ' of every element (meshes first) at those times.
    viscous : bool
        False: the elastic contact forces K_m(θ) f(δ_m; D_m) alone, without the viscous term, which acts in
        separation too (the pair's :func:`geardyn.analysis.physical.contact_force`).

    Returns
    -------
    ndarray (K, meshes)
        Mesh forces in units k_ref b_c.
    """
    th = model.omega * np.asarray(tau, dtype=float)
    out = []
    for i, m in enumerate(model.meshes):
        C, Kk = series_values(m.coefficients(), th, (0, 1), ratio=m.ratio)
        d = deltas[:, i, 0]
        f = Kk * (d - np.clip(d, -m.D, m.D))
        out.append(C * deltas[:, i, 1] + f if viscous else f)
    return np.stack(out, axis=1)  # a system has at least one mesh


def _fractions(res: Any, e: int, point: int) -> dict[str, float | None]:
    """The time fractions of element e's law counters at one point, by the law's names."""
    return {name: _num(f[point]) for name, f in res.law_fractions(e).items()}


def _mesh_entries(
    model: Any, res: Any, point: int, tau: np.ndarray | None, deltas: np.ndarray | None, extrema: np.ndarray | None
) -> list[dict[str, Any]]:
    sc = model.scaling
    um = sc.b_c_m * 1e6
    fs = static_mesh_forces(model)
    ok = bool(res.ok[point]) if res is not None else extrema is not None
    force = (
        mesh_forces(model, tau, deltas)
        if (tau is not None and deltas is not None and ok and np.all(np.isfinite(deltas)))
        else None
    )
    contact = mesh_forces(model, tau, deltas, False) if force is not None and res is not None else None
    out = []
    for i, m in enumerate(model.meshes):
        lo, hi = map(float, extrema[i]) if extrema is not None else _extremes(res, i, point)
        e: dict[str, Any] = {"name": m.name, "backlash_um": _num(m.D * um), **_span(lo, hi, m.D)}
        if res is not None:
            e.update(
                rms=_num(res.element_rms(i)[point]),
                mean=_num(res.element_mean(i)[point]),
                contact_fractions=_fractions(res, i, point),
                dte_min_um=_num(lo * um),
                dte_max_um=_num(hi * um),
            )
        e["dte_amplitude_um"] = _num(0.5 * (hi - lo) * um)
        if res is not None:
            e.update(static_force_N=_num(sc.N_from_force(fs[i])), dynamic_factor=None)
        if force is not None:
            fmax = float(np.max(force[:, i]))
            e["mesh_force_max_N"] = _num(sc.N_from_force(fmax))
            if res is not None:
                e["mesh_force_min_N"] = _num(sc.N_from_force(np.min(force[:, i])))
            e["dynamic_factor"] = _num(sc.dynamic_factor(fmax, fs[i]))
        elif extrema is not None:
            e.update(mesh_force_max_N=None, dynamic_factor=None)
        if contact is not None:
            e["contact_force_max_N"] = _num(sc.N_from_force(np.max(contact[:, i])))
            e["contact_force_min_N"] = _num(sc.N_from_force(np.min(contact[:, i])))
        out.append(e)
    return out


def _clearance_entries(model: Any, res: Any, point: int) -> list[dict[str, Any]]:
    M = len(model.meshes)
    return [
        {"name": name, **_span(*_extremes(res, M + c, point), D), "contact_fractions": _fractions(res, M + c, point)}
        for c, (name, D) in enumerate(zip(model.clearance_names, model.Dc))
    ]


def _extremes(res: Any, e: int, point: int) -> tuple[float, float]:
    """Element e's smallest and largest deflection at one point."""
    return float(res.element_u_min(e)[point]), float(res.element_u_max(e)[point])


def _span(lo: float, hi: float, D: float) -> dict[str, Any]:
    """The entries of an element's deflection range: its extremes, half their difference, the impact state."""
    return {
        "u_min": _num(lo),
        "u_max": _num(hi),
        "amplitude": _num(0.5 * (hi - lo)),
        "impact": IMPACT_LABELS[impact_state(lo, D)],
    }


def _bearing_entries(model: Any, res: Any, point: int) -> list[dict[str, Any]]:
    """Per rolling bearing: its rows' displacement extremes (non-dimensional and µm) and how often each row's
    deflection is beyond the clearance (the law's counters ``plus``, ``free``, ``minus``)."""
    e0 = len(model.meshes) + len(model.clearance_names)
    bc_um = float(model.scaling.b_c_m) * 1e6
    out = []
    for b, br in enumerate(model.bearings):
        entry: dict[str, Any] = {"name": br.name, "type": br.kind, "radial_clearance_um": _num(br.clearance * bc_um)}
        for k, axis in enumerate("xy"):
            e = e0 + 2 * b + k
            lo, hi = _extremes(res, e, point)
            entry[axis] = {
                "min_um": _num(lo * bc_um),
                "max_um": _num(hi * bc_um),
                "fractions": _fractions(res, e, point),
            }
        out.append(entry)
    return out


def report(
    model: Any,
    res: Any = None,
    point: int = 0,
    tau: np.ndarray | None = None,
    deltas: np.ndarray | None = None,
    extrema: np.ndarray | None = None,
) -> dict[str, Any]:
    """The keys a system adds to an analysis summary.

    Parameters
    ----------
    model : SystemModel
    res : BatchResult, optional
        A batch with the point's per-element statistics (a steady response, a Lyapunov run).
    point : int
        The point of ``res``.
    tau, deltas : ndarray, optional
        A time history and every element's (δ, δ') on it (mesh forces and dynamic factors come from it).
    extrema : ndarray (elements, 2), optional
        Each element's (δ_min, δ_max) on a periodic orbit (Hermite-refined), instead of ``res``.

    Returns
    -------
    dict
        ``reference_mesh``, ``labels``, ``forcing_period_multiple``, ``meshes`` and (with ``res``) ``clearances``
        and, for a system with rolling bearings, ``bearings``.
    """
    out: dict[str, Any] = {
        "reference_mesh": model.meshes[model.reference].name,
        "labels": list(model.labels),
        "forcing_period_multiple": model.period_multiple(),
        "meshes": _mesh_entries(model, res, point, tau, deltas, extrema),
    }
    if res is not None:
        out["clearances"] = _clearance_entries(model, res, point)
        if model.bearings:
            out["bearings"] = _bearing_entries(model, res, point)
    return out


def result_meshes(ds: Any) -> list[dict[str, Any]]:
    """The ``meshes`` entries of a sweep, map or basin result of a system (its Dataset, any kind).

    Per mesh: ``name``, ``backlash_um`` (D b_c), and over the result's points (the layout of its reference
    variables: a list, ``{sweep: list}`` for two sweeps, nested lists for a grid) ``u_min``, ``u_max``,
    ``amplitude`` (non-dimensional), ``dte_amplitude_um`` and ``impact``; ``dynamic_factor`` None (the sweeps
    keep no histories).  The element variables of a system of several elements, else the reference
    variables (one mesh).

    Parameters
    ----------
    ds : xarray.Dataset
        A result written for a system (its ``system`` attribute).

    Returns
    -------
    list of dict
    """
    import json

    info = json.loads(ds.attrs["system"])
    um = float(info.get("b_c_um") or float("nan"))
    els = info.get("elements") or [{"name": n, "kind": "mesh", "gap": float("nan")} for n in info["meshes"]]
    dims = ds["amplitude"].dims
    two = "sweep" in ds.dims and ds.sizes["sweep"] > 1

    def values(a: np.ndarray, f: Any) -> Any:
        def conv(x: np.ndarray) -> Any:
            return [conv(r) for r in x] if x.ndim > 1 else [f(v) for v in x]

        if "sweep" in dims:
            labs = [str(s) for s in ds["sweep"].values]
            per = {lab: conv(a[i]) for i, lab in enumerate(labs)}
            return per if two else per[labs[0]]
        return conv(a)

    out = []
    for i, e in enumerate(els):
        if e["kind"] != "mesh":
            continue
        if "element_u_min" in ds:
            lo, hi = ds["element_u_min"].values[..., i], ds["element_u_max"].values[..., i]
            imp = ds["element_impact"].values[..., i]
        elif "u_min" in ds:
            lo, hi, imp = ds["u_min"].values, ds["u_max"].values, ds["impact"].values
        else:  # a basin map of one mesh keeps its amplitude only
            lo = hi = np.full(ds["amplitude"].shape, np.nan)
            imp = ds["impact"].values
        amp = 0.5 * (hi - lo) if "u_min" in ds or "element_u_min" in ds else ds["amplitude"].values
        out.append(
            {
                "name": e["name"],
                "backlash_um": _num(e["gap"] * um),
                "u_min": values(lo, _num),
                "u_max": values(hi, _num),
                "amplitude": values(amp, _num),
                "dte_min_um": values(lo * um, _num),
                "dte_max_um": values(hi * um, _num),
                "dte_amplitude_um": values(amp * um, _num),
                "impact": values(imp, lambda c: IMPACT_LABELS.get(int(c), "unknown")),
                "dynamic_factor": None,
            }
        )
    return out


def physical_scales(model: Any) -> Any:
    """The physical scales of a system: its :class:`~geardyn.geometry.scales.Scales` (those of its reference mesh)
    with D the reference element's half gap now, so that :func:`geardyn.analysis.physical.add_physical` and
    :func:`~geardyn.analysis.physical.physical_json` give a system's results the pair's physical keys (rpm, µm, N).

    Without teeth on the reference mesh the speeds are NaN; a system has no single pinion torque (``fp``,
    ``torque_N_m`` None) and its static force is the reference mesh's (:func:`static_mesh_forces`).

    Parameters
    ----------
    model : SystemModel

    Returns
    -------
    Scales
    """
    from dataclasses import replace

    return replace(model.scaling, D=float(model.elements[model.reference].gap))
