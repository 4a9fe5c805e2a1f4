"""Linear analysis of a system at mean mesh stiffness: modes, strain energy and Campbell diagrams.

The undamped linear system ``M q'' + K q = 0`` with

    K = K_b + Σ_m k_m0 v_m v_mᵀ (+ Σ_c k_c w_c w_cᵀ, clearance elements in contact by default)
        (+ Σ_b K_b,lin: each rolling bearing's tangent stiffness at the static deflection under the mean loads,
         the cage at its θ = 0 angle, :func:`geardyn.systems.rolling.static_bearing_stiffness`)

is solved as the generalised symmetric eigenproblem ``K φ = ω² M φ`` (``scipy.linalg.eigh``): the
mode shapes are M-orthonormal (``Φᵀ M Φ = I``).  Rigid-body modes (ω² below a relative tolerance of
the largest) are reported with frequency 0.  The strain-energy fraction of element e in mode i is
``φ_iᵀ K_e φ_i / φ_iᵀ K φ_i`` (they sum to 1 over the elements); a mode is *mesh-dominated* when its
meshes hold more than half of its strain energy.

Campbell diagram: mesh m's frequency at pinion speed n (rpm) is ``f_m = r_m z n/60`` (z the
reference mesh's ``teeth``), and order k of it is ``k f_m``.  Each crossing with a natural
frequency f_i is at ``n = 60 f_i/(k r_m z)``.  Without ``teeth`` the diagram is drawn against the
reference mesh frequency f_ref itself: order k of mesh m is ``k r_m f_ref``, crossing f_i at
``f_ref = f_i/(k r_m)``.  Orders of meshes with the same ``k r_m`` are one line, and modes of one
(degenerate) frequency one crossing.

Modes are numbered from 1 in ascending frequency (the rigid-body modes first) wherever they are
shown: tables, crossings, JSON, figures; the arrays of :class:`ModalResult` are indexed from 0 (mode
``i`` is column ``i - 1``).

References
----------
.. [1] J. Lin, R. G. Parker, "Analytical characterization of the unique properties of planetary gear
   free vibration", J. Vib. Acoust. 121 (1999) 316–321 (rotational, translational and planet modes;
   the degenerate translational pairs of equally spaced planets).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from ..errors import ModelError
from .description import SystemDescription

__all__ = ["ModalResult", "campbell", "modal_analysis", "modes_report"]

#: Relative tolerance (on ω²/max ω²) below which a mode is a rigid-body mode.
RIGID_RTOL = 1e-9
#: The groups of a gearbox's strain energy, by element kind.
_GROUPS = {"shaft": "shafts", "bearing": "bearings", "coupling": "couplings", "mesh": "meshes"}
#: Relative tolerance for two frequencies to count as one repeated (degenerate) frequency.
DEGENERATE_RTOL = 1e-6


@dataclass(frozen=True, eq=False)
class ModalResult:
    """Natural frequencies and modes of a system at mean mesh stiffness.

    Attributes
    ----------
    labels : tuple of str
        The DOFs (``body.dof``), the rows of ``shapes``.
    frequencies_hz : ndarray, shape (n,)
        Natural frequencies in Hz, ascending; rigid-body modes 0.
    omega2 : ndarray, shape (n,)
        Eigenvalues ω² (rad²/s²) as computed (rigid-body ones near 0).
    shapes : ndarray, shape (n, n)
        M-orthonormal mode shapes, one per column (SI coordinates: m and rad).
    rigid : ndarray of bool, shape (n,)
        Which modes are rigid-body modes.
    elements : tuple of str
        Element names (connections, clearances, meshes) of ``energy``'s columns.
    mesh_elements : tuple of str
        The meshes among them.
    energy : ndarray, shape (n, elements)
        Modal strain-energy fraction per element (rows of rigid-body modes are 0).
    """

    labels: tuple[str, ...]
    frequencies_hz: np.ndarray
    omega2: np.ndarray
    shapes: np.ndarray
    rigid: np.ndarray
    elements: tuple[str, ...]
    mesh_elements: tuple[str, ...]
    energy: np.ndarray

    @property
    def mesh_dominated(self) -> np.ndarray:
        """Per mode: whether its meshes hold more than half of its strain energy."""
        idx = [self.elements.index(m) for m in self.mesh_elements]
        return self.energy[:, idx].sum(axis=1) > 0.5

    def degenerate_groups(self, rtol: float = DEGENERATE_RTOL) -> list[list[int]]:
        """Indices of modes sharing one non-zero frequency (within ``rtol``), groups of two or more."""
        groups: list[list[int]] = []
        f = self.frequencies_hz
        i = 0
        while i < len(f):
            j = i + 1
            while j < len(f) and f[i] > 0 and abs(f[j] - f[i]) <= rtol * f[i]:
                j += 1
            if j - i > 1:
                groups.append(list(range(i, j)))
            i = j
        return groups


def _element_stiffness(desc: SystemDescription, clearances: str) -> tuple[list[str], list[np.ndarray], list[str]]:
    names, mats = [], []
    for c in desc.connections:
        names.append(c.name)
        mats.append(desc.connection_matrices(c)[0])
    if clearances == "contact":
        for c in desc.clearances:
            w = desc.vector(c)
            names.append(c.name)
            mats.append(c.stiffness * np.outer(w, w))
    elif clearances != "open":
        raise ModelError(f"clearances: must be 'contact' or 'open', got {clearances!r}")
    meshes = []
    for m in desc.meshes:
        v = desc.vector(m)
        names.append(m.name)
        meshes.append(m.name)
        mats.append(m.stiffness * np.outer(v, v))
    rolling = getattr(desc, "rolling_bearings", ())
    if rolling:  # linearised about the static deflection under the mean loads
        from .rolling import static_bearing_stiffness

        for b, kb in zip(rolling, static_bearing_stiffness(desc, np.sum(mats, axis=0))):
            names.append(b.name)
            mats.append(kb)
    return names, mats, meshes


#: Memory a modal analysis may take (bytes): its dense matrices (one stiffness matrix per element, K, M and the
#: mode shapes) and the report's table of mode shapes.
MODES_MEMORY_BUDGET = 2.0e9


def modes_budget(desc: SystemDescription, clearances: str = "contact") -> float:
    """The memory a modal analysis of ``desc`` takes, refused above :data:`MODES_MEMORY_BUDGET` before it starts.

    n DOFs and E elements: E + 3 dense n × n matrices of 8 bytes, and n² mode-shape entries in the report
    (about 100 bytes each).

    Returns
    -------
    float
        The estimate (bytes).

    Raises
    ------
    ModelError
        ``system: a modal analysis of n DOFs and E elements would need X GB, above the budget of 2 GB``.
    """
    from ..plausible import budget

    n = len(desc.labels)
    elements = len(desc.connections) + len(desc.meshes) + (len(desc.clearances) if clearances == "contact" else 0)
    elements += len(getattr(desc, "rolling_bearings", ()))
    estimate = (elements + 3) * n * n * 8.0 + n * n * 100.0
    budget(
        f"a modal analysis of {n} DOFs and {elements} elements (dense matrices)",
        estimate,
        MODES_MEMORY_BUDGET,
        key="system",
    )
    return estimate


def modes_budget_of_file(path: Any) -> None:
    """The budget of :func:`modes_budget` checked on a system file's own tables before the file is loaded (its
    units parsed, its bodies built: about 15 ms per body): the DOFs its ``[[body]]`` tables list and its
    ``[[connection]]``, ``[[mesh]]`` and ``[[clearance]]`` elements, a lower bound of the loaded system's.
    A file that cannot be read this way is left to the loader, which says what is wrong with it.

    Parameters
    ----------
    path : str or Path
        The system file.

    Raises
    ------
    ModelError
        As :func:`modes_budget`.
    """
    import tomllib

    from ..plausible import budget

    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
        bodies = data.get("body", [])
        n = sum(len(b.get("dofs", ())) for b in bodies if isinstance(b, dict) and isinstance(b.get("dofs"), list))
        elements = sum(
            len(data.get(k, [])) for k in ("connection", "mesh", "clearance") if isinstance(data.get(k), list)
        )
    except (OSError, ValueError, TypeError, AttributeError):
        return
    budget(
        f"a modal analysis of {n} DOFs and {elements} elements (dense matrices)",
        (elements + 3) * n * n * 8.0 + n * n * 100.0,
        MODES_MEMORY_BUDGET,
        key="system",
    )


def modal_analysis(desc: SystemDescription, clearances: str = "contact") -> ModalResult:
    """Natural frequencies, M-orthonormal mode shapes and strain-energy fractions at mean stiffness.

    Parameters
    ----------
    desc : SystemDescription
        The system.
    clearances : {"contact", "open"}
        Clearance elements in contact (their stiffness counts) or open (left out).

    Returns
    -------
    ModalResult

    Raises
    ------
    ModelError
        For an unknown ``clearances`` value.

    References
    ----------
    J. Lin, R. G. Parker, J. Vib. Acoust. 121 (1999) 316–321 (the published natural frequencies and
    mode types of a planetary gear, which this analysis reproduces).
    """
    modes_budget(desc, clearances)
    M = desc.mass_matrix()
    names, mats, meshes = _element_stiffness(desc, clearances)
    K = np.sum(mats, axis=0) if mats else np.zeros_like(M)
    K = 0.5 * (K + K.T)
    w2, phi = scipy.linalg.eigh(K, M)
    scale = max(float(np.max(np.abs(w2))), 1e-300)
    if np.any(w2 < -RIGID_RTOL * scale):  # an unstable mode is no rigid-body mode
        raise ModelError(
            f"stiffness: the system is statically unstable (a mode with ω² = {float(np.min(w2)):.4g} "
            f"rad²/s² < 0): a stiffness matrix of {desc.source or 'the system'} is not positive "
            f"semi-definite"
        )
    rigid = w2 <= RIGID_RTOL * scale
    f = np.where(rigid, 0.0, np.sqrt(np.clip(w2, 0.0, None)) / (2.0 * math.pi))
    order = np.argsort(f, kind="stable")
    f, w2, phi, rigid = f[order], w2[order], phi[:, order], rigid[order]
    # a sign convention: the largest component of each shape is positive
    for i in range(phi.shape[1]):
        k = int(np.argmax(np.abs(phi[:, i])))
        if phi[k, i] < 0:
            phi[:, i] = -phi[:, i]
    energy = np.zeros((len(f), len(names)))
    for i in range(len(f)):
        if rigid[i]:
            continue
        e = np.array([phi[:, i] @ Ke @ phi[:, i] for Ke in mats])
        tot = e.sum()
        energy[i] = e / tot if tot > 0 else 0.0
    return ModalResult(desc.labels, f, w2, phi, rigid, tuple(names), tuple(meshes), energy)


def _frequency_groups(res: ModalResult) -> list[tuple[float, list[int]]]:
    """The distinct non-zero natural frequencies with the numbers (from 1) of the modes at each."""
    degenerate = {g[0]: g for g in res.degenerate_groups()}
    out, i = [], 0
    f = res.frequencies_hz
    while i < len(f):
        g = degenerate.get(i, [i])
        if f[i] > 0:
            out.append((float(f[i]), [k + 1 for k in g]))
        i = g[-1] + 1
    return out


def _line_label(pairs: list[tuple[str, int]], meshes: Sequence[str]) -> str:
    """ "order 2", or "order 2 of m1 = order 1 of m2" when the line is not every mesh's order."""
    by_order: dict[int, list[str]] = {}
    for name, k in pairs:
        by_order.setdefault(k, []).append(name)
    if len(by_order) == 1 and len(next(iter(by_order.values()))) == len(meshes):
        return f"order {next(iter(by_order))}"
    return " = ".join(f"order {k} of {', '.join(names)}" for k, names in sorted(by_order.items()))


def campbell(
    desc: SystemDescription,
    result: ModalResult | None = None,
    rpm_range: tuple[float, float] = (0.0, 10000.0),
    orders: Sequence[int] = (1, 2, 3),
    mesh_hz_range: tuple[float, float] | None = None,
) -> dict[str, Any]:
    """Campbell diagram: the mesh-order lines and their crossings with the natural frequencies.

    Against pinion speed (rpm) when the reference mesh gives ``teeth``, else against the reference
    mesh frequency (Hz).  Mesh orders of equal frequency (``k r_m``, e.g. the six meshes of a
    planetary set) are one line; the modes of one degenerate frequency are one crossing.

    Parameters
    ----------
    desc : SystemDescription
        The system (at least one mesh).
    result : ModalResult, optional
        Its modes (computed when not given).
    rpm_range : (float, float)
        Speed range (rpm) of the diagram when the reference mesh gives ``teeth``.
    orders : sequence of int
        Harmonic orders of each mesh frequency.
    mesh_hz_range : (float, float), optional
        Range of the reference mesh frequency (Hz) of the diagram without ``teeth`` (default up to
        1.2 times the frequency at which the lowest line crosses the highest mode).

    Returns
    -------
    dict
        ``x``: ``"rpm"`` or ``"mesh_frequency_hz"``; ``x_label``; ``x_range``; ``teeth`` (or ``None``);
        ``lines``: per distinct line ``{"label", "harmonic" (multiple of the reference mesh frequency),
        "hz_per_x", "order", "mesh", "meshes", "orders"}``; ``crossings``: ``{"x", "mode", "modes",
        "order", "mesh", "meshes", "line", "frequency_hz"}`` sorted by ``x`` (``"rpm"`` too against
        speed), modes numbered from 1; ``rpm_range`` against speed.

    Raises
    ------
    ModelError
        When the system has no mesh or the range or orders are invalid.
    """
    if not desc.meshes:
        raise ModelError("campbell: the system has no mesh, so no mesh orders to draw")
    orders = [int(k) for k in orders]
    if not orders or any(k < 1 for k in orders):
        raise ModelError(f"orders: must be integers >= 1, got {orders!r}")
    res = result or modal_analysis(desc)
    groups = _frequency_groups(res)
    z = desc.reference_mesh.teeth
    per_x = z / 60.0 if z is not None else 1.0  # reference mesh frequency (Hz) per unit of x
    harmonics: dict[float, list[tuple[str, int]]] = {}
    for m in desc.meshes:
        for k in orders:
            key = float(f"{k * m.ratio:.12g}")
            harmonics.setdefault(key, []).append((m.name, k))
    if z is not None:
        lo, hi = (float(x) for x in rpm_range)
        what = "rpm_range"
    elif mesh_hz_range is not None:
        lo, hi = (float(x) for x in mesh_hz_range)
        what = "mesh_hz_range"
    else:
        top = max((f for f, _ in groups), default=1.0)
        lo, hi, what = 0.0, float(f"{1.2 * top / min(harmonics):.2g}"), "mesh_hz_range"
    if not (0 <= lo < hi and math.isfinite(hi)):
        raise ModelError(f"{what}: must be 0 <= low < high, got {(lo, hi)!r}")
    names = [m.name for m in desc.meshes]
    lines, crossings = [], []
    for n, (h, pairs) in enumerate(sorted(harmonics.items())):
        label = _line_label(pairs, names)
        slope = h * per_x
        lines.append(
            {
                "label": label,
                "harmonic": h,
                "hz_per_x": slope,
                "order": pairs[0][1],
                "mesh": pairs[0][0],
                "meshes": [p[0] for p in pairs],
                "orders": [p[1] for p in pairs],
            }
        )
        for f, modes in groups:
            x = f / slope
            if lo <= x <= hi:
                c = {
                    "x": x,
                    "mode": modes[0],
                    "modes": modes,
                    "order": pairs[0][1],
                    "mesh": pairs[0][0],
                    "meshes": [p[0] for p in pairs],
                    "line": n,
                    "frequency_hz": f,
                }
                if z is not None:
                    c["rpm"] = x
                crossings.append(c)
    crossings.sort(key=lambda c: (c["x"], c["mode"]))
    out: dict[str, Any] = {
        "x": "rpm" if z is not None else "mesh_frequency_hz",
        "x_label": (
            "pinion speed [rpm]"
            if z is not None
            else f"mesh frequency of {desc.reference_mesh.name} [Hz]"
            if desc.reference_mesh.ratio == 1.0
            else "base mesh frequency ω_e/2π [Hz]"
        ),
        "x_range": [lo, hi],
        "teeth": z,
        "lines": lines,
        "crossings": crossings,
    }
    if z is not None:
        out["rpm_range"] = [lo, hi]
    return out


def modes_report(
    desc: SystemDescription,
    rpm_range: tuple[float, float] = (0.0, 10000.0),
    orders: Sequence[int] = (1, 2, 3),
    clearances: str = "contact",
    mesh_hz_range: tuple[float, float] | None = None,
) -> dict[str, Any]:
    """A JSON-ready report of the modes and the Campbell diagram.

    Parameters
    ----------
    desc : SystemDescription
        The system.
    rpm_range, orders, mesh_hz_range : see :func:`campbell`
    clearances : {"contact", "open"}
        See :func:`modal_analysis`.

    Returns
    -------
    dict
        ``frequencies_hz`` (ascending, rigid-body modes 0), ``rigid`` (per mode), ``dofs`` (labels),
        ``modes`` (per mode: ``{"mode" (its number, from 1), "frequency_hz", "rigid", "mesh_dominated",
        "shape": {dof: value}}``), ``energy_fractions`` (per mode: ``{element: fraction}``),
        ``degenerate`` (groups of mode numbers), ``campbell`` (:func:`campbell`, or ``None`` with a
        ``campbell_note`` when the system has no mesh; a ``campbell_note`` also says when it is drawn
        against the mesh frequency), ``assumed`` (the assumptions as dicts).  A gearbox
        (:class:`~geardyn.gearbox.model.GearboxDescription`) adds to each mode ``energy``: its strain-energy
        fractions grouped as ``shafts``, ``bearings``, ``couplings`` and ``meshes``, and ``gearbox``: the
        shafts (their nodes and positions, speed ratios) and the exact kinematics.
    """
    res = modal_analysis(desc, clearances)
    dom = res.mesh_dominated
    modes = [
        {
            "mode": i + 1,
            "frequency_hz": float(res.frequencies_hz[i]),
            "rigid": bool(res.rigid[i]),
            "mesh_dominated": bool(dom[i]) and not bool(res.rigid[i]),
            "shape": {lab: float(res.shapes[k, i]) for k, lab in enumerate(res.labels)},
        }
        for i in range(len(res.frequencies_hz))
    ]
    out: dict[str, Any] = {
        "title": desc.title,
        "source": desc.source,
        "dofs": list(res.labels),
        "frequencies_hz": [float(x) for x in res.frequencies_hz],
        "rigid": [bool(x) for x in res.rigid],
        "modes": modes,
        "energy_fractions": [
            {e: float(res.energy[i, j]) for j, e in enumerate(res.elements)} for i in range(len(modes))
        ],
        "degenerate": [[i + 1 for i in g] for g in res.degenerate_groups()],
        "assumed": [a.to_dict() for a in desc.assumptions],
    }
    kinds = getattr(desc, "element_kinds", None)
    if kinds:  # a gearbox: each mode's strain energy per shaft, bearing, coupling and mesh; the shafts' nodes
        for m, e in zip(modes, out["energy_fractions"]):
            grouped: dict[str, dict[str, float]] = {}
            for name, frac in e.items():
                grouped.setdefault(_GROUPS.get(kinds.get(name, ""), "others"), {})[name] = frac
            m["energy"] = grouped
        out["gearbox"] = desc.gearbox_summary()
    if not desc.meshes:
        out["campbell"] = None
        out["campbell_note"] = "the system has no mesh: no Campbell diagram"
        return out
    out["campbell"] = campbell(desc, res, rpm_range, orders, mesh_hz_range)
    if desc.reference_mesh.teeth is None:
        out["campbell_note"] = (
            f"mesh {desc.reference_mesh.name!r} gives no teeth: the Campbell diagram is "
            f"against its mesh frequency (Hz), not pinion speed"
        )
    return out
