"""Linear analysis of a system at mean mesh stiffness: modes, strain energy and Campbell diagrams.

The undamped linear system ``M q'' + K q = 0`` with

    K = K_b + Σ_m k_m0 v_m v_mᵀ (+ Σ_c k_c w_c w_cᵀ, clearance elements in contact by default)

is solved as the generalised symmetric eigenproblem ``K φ = ω² M φ`` (``scipy.linalg.eigh``): the
mode shapes are M-orthonormal (``Φᵀ M Φ = I``).  Rigid-body modes (ω² below a relative tolerance of
the largest) are reported with frequency 0.  The strain-energy fraction of element e in mode i is
``φ_iᵀ K_e φ_i / φ_iᵀ K φ_i`` (they sum to 1 over the elements); a mode is *mesh-dominated* when its
meshes hold more than half of its strain energy.

Campbell diagram: mesh m's frequency at pinion speed n (rpm) is ``f_m = r_m z n/60`` (z the
reference mesh's ``teeth``), and order k of it is ``k f_m``.  Each crossing with a natural
frequency f_i is at ``n = 60 f_i/(k r_m z)``.

References
----------
.. [1] J. Lin, R. G. Parker, "Analytical characterization of the unique properties of planetary gear
   free vibration", J. Vib. Acoust. 121 (1999) 316–321 (rotational, translational and planet modes;
   the degenerate translational pairs of equally spaced planets).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import scipy.linalg

from ..errors import ModelError
from .description import SystemDescription

__all__ = ["ModalResult", "campbell", "modal_analysis", "modes_report"]

#: Relative tolerance (on ω²/max ω²) below which a mode is a rigid-body mode.
RIGID_RTOL = 1e-9
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
    return names, mats, meshes


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
    M = desc.mass_matrix()
    names, mats, meshes = _element_stiffness(desc, clearances)
    K = np.sum(mats, axis=0) if mats else np.zeros_like(M)
    K = 0.5 * (K + K.T)
    w2, phi = scipy.linalg.eigh(K, M)
    scale = max(float(np.max(np.abs(w2))), 1e-300)
    if np.any(w2 < -RIGID_RTOL * scale):  # an unstable mode is no rigid-body mode
        raise ModelError(f"stiffness: the system is statically unstable (a mode with ω² = {float(np.min(w2)):.4g} "
                         f"rad²/s² < 0): a stiffness matrix of {desc.source or 'the system'} is not positive "
                         f"semi-definite")
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


def campbell(
    desc: SystemDescription,
    result: ModalResult | None = None,
    rpm_range: tuple[float, float] = (0.0, 10000.0),
    orders: Sequence[int] = (1, 2, 3),
) -> dict[str, Any]:
    """Campbell diagram against pinion speed: mesh-order lines and their crossings with the modes.

    Parameters
    ----------
    desc : SystemDescription
        The system; its reference mesh must give ``teeth``.
    result : ModalResult, optional
        Its modes (computed when not given).
    rpm_range : (float, float)
        Speed range (rpm) in which crossings are listed.
    orders : sequence of int
        Harmonic orders of each mesh frequency.

    Returns
    -------
    dict
        ``lines``: per mesh and order the slope in Hz per rpm (``k r_m z/60``); ``crossings``: a list
        of ``{"rpm", "mode", "order", "mesh", "frequency_hz"}`` sorted by rpm; ``rpm_range``.

    Raises
    ------
    ModelError
        When the reference mesh has no ``teeth`` or the range or orders are invalid.
    """
    z = desc.reference_mesh.teeth
    if z is None:
        raise ModelError(f"mesh {desc.reference_mesh.name!r}: teeth: needed for a Campbell diagram against pinion speed")
    lo, hi = (float(x) for x in rpm_range)
    if not (0 <= lo < hi and math.isfinite(hi)):
        raise ModelError(f"rpm_range: must be 0 <= low < high, got {rpm_range!r}")
    orders = [int(k) for k in orders]
    if not orders or any(k < 1 for k in orders):
        raise ModelError(f"orders: must be integers >= 1, got {orders!r}")
    res = result or modal_analysis(desc)
    lines, crossings = [], []
    for m in desc.meshes:
        for k in orders:
            slope = k * m.ratio * z / 60.0  # Hz per rpm
            lines.append({"mesh": m.name, "order": k, "hz_per_rpm": slope})
            for i, f in enumerate(res.frequencies_hz):
                if f <= 0:
                    continue
                rpm = f / slope
                if lo <= rpm <= hi:
                    crossings.append({"rpm": rpm, "mode": i, "order": k, "mesh": m.name, "frequency_hz": float(f)})
    crossings.sort(key=lambda c: (c["rpm"], c["mode"]))
    return {"rpm_range": [lo, hi], "teeth": z, "lines": lines, "crossings": crossings}


def modes_report(
    desc: SystemDescription,
    rpm_range: tuple[float, float] = (0.0, 10000.0),
    orders: Sequence[int] = (1, 2, 3),
    clearances: str = "contact",
) -> dict[str, Any]:
    """A JSON-ready report of the modes and the Campbell diagram.

    Parameters
    ----------
    desc : SystemDescription
        The system.
    rpm_range, orders : see :func:`campbell`
    clearances : {"contact", "open"}
        See :func:`modal_analysis`.

    Returns
    -------
    dict
        ``frequencies_hz`` (ascending, rigid-body modes 0), ``rigid`` (per mode), ``dofs`` (labels),
        ``modes`` (per mode: ``{"frequency_hz", "rigid", "mesh_dominated", "shape": {dof: value}}``),
        ``energy_fractions`` (per mode: ``{element: fraction}``), ``degenerate`` (index groups),
        ``campbell`` (:func:`campbell`, or ``None`` with a ``campbell_note`` when the reference mesh
        gives no ``teeth``), ``assumed`` (the assumptions as dicts).
    """
    res = modal_analysis(desc, clearances)
    dom = res.mesh_dominated
    modes = [
        {
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
        "energy_fractions": [{e: float(res.energy[i, j]) for j, e in enumerate(res.elements)} for i in range(len(modes))],
        "degenerate": res.degenerate_groups(),
        "assumed": [a.to_dict() for a in desc.assumptions],
    }
    if desc.reference_mesh.teeth is None:
        out["campbell"] = None
        out["campbell_note"] = "the reference mesh gives no teeth: no Campbell diagram against pinion speed"
    else:
        out["campbell"] = campbell(desc, res, rpm_range, orders)
    return out
