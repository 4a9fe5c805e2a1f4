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

Gyroscopic terms (a gearbox with ``[gearbox] gyroscopic = true``, :meth:`~geardyn.gearbox.model.
GearboxDescription.gyroscopic_matrix`): at the reference shaft's speed Ω (rad/s) the undamped equations are
``M q'' + Ω G q' + K q = 0`` with G skew-symmetric, and :func:`modal_analysis` at a speed (``rpm``) solves them
exactly: in the standstill modes Φ (``Φᵀ M Φ = I``, ``Φᵀ K Φ = Λ``) the elastic coordinates η obey
``η'' + Ω Φᵀ G Φ η' + Λ η = 0``, whose first-order form in ``z = (Λ^½ η, η')`` is ``z' = A z`` with A real
skew-symmetric: ``i A`` is Hermitian and ``scipy.linalg.eigh`` gives the frequencies ω (``A z = iω z``) to
round-off, the rigid-body modes (Λ = 0) included: they stay at 0 unless G couples them (a shaft free to tilt
precesses).
Each mode's whirl is measured on the shafts' nodes: ``w = Σ σ_s 2 Im(a b̄) / Σ (|a|² + |b|²)`` over the pairs
(a, b) = (x, y) and r (ry, −rx) of the complex shape (r the node's radius, σ_s the shaft's running sense), +1
a circular orbit turning with the shaft (forward whirl), −1 against it (backward); a mode without lateral
motion has w = 0.  The Campbell diagram then draws each natural frequency against speed (a branch, the modes
sorted by frequency at each speed) and finds its crossings with the order lines on the branches.

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
from threadpoolctl import threadpool_limits

from ..errors import ModelError
from .description import SystemDescription

__all__ = ["ModalResult", "campbell", "gyroscopic_eigen", "modal_analysis", "modes_report"]

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
    rpm : float or None
        The reference shaft's speed (rpm) of modes with gyroscopic terms; None at standstill (no gyroscopic
        terms): then ``shapes`` are real, else complex (``q(t) = Re(φ e^{iωt})``, normalised to ``φᴴ M φ = 1``).
    whirl : ndarray, shape (n,), or None
        With gyroscopic terms, the whirl measure of each mode (the module docstring): > 0 forward, < 0 backward.
    """

    labels: tuple[str, ...]
    frequencies_hz: np.ndarray
    omega2: np.ndarray
    shapes: np.ndarray
    rigid: np.ndarray
    elements: tuple[str, ...]
    mesh_elements: tuple[str, ...]
    energy: np.ndarray
    rpm: float | None = None
    whirl: np.ndarray | None = None

    @property
    def mesh_dominated(self) -> np.ndarray:
        """Per mode: whether its meshes hold more than half of its strain energy."""
        idx = [self.elements.index(m) for m in self.mesh_elements]
        return self.energy[:, idx].sum(axis=1) > 0.5

    def degenerate_groups(self, rtol: float = DEGENERATE_RTOL) -> list[list[int]]:
        """Indices of modes sharing one non-zero frequency (within ``rtol``), groups of two or more."""
        return [g for g in _groups(self.frequencies_hz, rtol) if len(g) > 1]


def _groups(f: np.ndarray, rtol: float = DEGENERATE_RTOL) -> list[list[int]]:
    """Indices of the modes of each frequency, ascending: one non-zero frequency (within ``rtol``) a group, each
    rigid-body mode its own."""
    groups: list[list[int]] = []
    i = 0
    while i < len(f):
        j = i + 1
        while j < len(f) and f[i] > 0 and abs(f[j] - f[i]) <= rtol * f[i]:
            j += 1
        groups.append(list(range(i, j)))
        i = j
    return groups


def _element_stiffness(desc: SystemDescription, clearances: str) -> tuple[list[str], list[np.ndarray], list[str]]:
    names, mats = [], []
    for c in desc.connections:
        names.append(c.name)
        mats.append(desc.connection_matrices(c)[0])
    if clearances not in ("contact", "open"):
        raise ModelError(f"clearances: must be 'contact' or 'open', got {clearances!r}")
    for e in (*(desc.clearances if clearances == "contact" else ()), *desc.meshes):  # k w wᵀ along the vector
        w = desc.vector(e)
        names.append(e.name)
        mats.append(e.stiffness * np.outer(w, w))
    meshes = [m.name for m in desc.meshes]
    if desc.rolling_bearings:  # linearised about the static deflection under the mean loads
        from .rolling import static_bearing_stiffness

        for b, kb in zip(desc.rolling_bearings, static_bearing_stiffness(desc, np.sum(mats, axis=0))):
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
    n = len(desc.labels)
    elements = len(desc.connections) + len(desc.meshes) + (len(desc.clearances) if clearances == "contact" else 0)
    return _budget(n, elements + len(desc.rolling_bearings))


def _budget(n: int, elements: int) -> float:
    from ..plausible import budget

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
    _budget(n, elements)


def modal_analysis(desc: SystemDescription, clearances: str = "contact", rpm: float | None = None) -> ModalResult:
    """Natural frequencies, M-orthonormal mode shapes and strain-energy fractions at mean stiffness.

    Parameters
    ----------
    desc : SystemDescription
        The system.
    clearances : {"contact", "open"}
        Clearance elements in contact (their stiffness counts) or open (left out).
    rpm : float, optional
        The reference shaft's speed (rpm, >= 0) of a system with gyroscopic terms: the modes of
        ``M q'' + Ω G q' + K q = 0`` (the module docstring).  Ignored (the standstill modes) without them.

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
    G = desc.gyroscopic_matrix() if rpm is not None else None
    if G is not None:
        if not (math.isfinite(rpm) and rpm >= 0):
            raise ModelError(f"rpm: must be >= 0, got {rpm!r}")
        return _gyroscopic_modes(desc, clearances, float(rpm), G)
    M = desc.mass_matrix()
    names, mats, meshes = _element_stiffness(desc, clearances)
    K = np.sum(mats, axis=0)  # every system has a mesh
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
    phi = phi * np.where(phi[np.argmax(np.abs(phi), axis=0), np.arange(phi.shape[1])] < 0, -1.0, 1.0)
    return ModalResult(desc.labels, f, w2, phi, rigid, tuple(names), tuple(meshes), _energy(phi, mats, rigid))


def _energy(shapes: np.ndarray, mats: list[np.ndarray], rigid: np.ndarray) -> np.ndarray:
    """Each mode's strain-energy fractions φᴴ K_e φ / Σ (modes, elements); 0 for the rigid-body modes."""
    energy = np.zeros((shapes.shape[1], len(mats)))
    for i in np.flatnonzero(~rigid):
        v = shapes[:, i]
        e = np.array([float(np.real(np.conj(v) @ Ke @ v)) for Ke in mats])
        tot = e.sum()
        energy[i] = e / tot if tot > 0 else 0.0
    return energy


def gyroscopic_eigen(
    omega2: np.ndarray, shapes: np.ndarray, G: np.ndarray, spin: float, vectors: bool = True
) -> tuple[np.ndarray, np.ndarray | None]:
    """The modes of ``M q'' + Ω G q' + K q = 0`` from the standstill ones (the module docstring).

    Parameters
    ----------
    omega2 : ndarray (n,)
        The standstill eigenvalues ω² (0 for a rigid-body mode).
    shapes : ndarray (n, n)
        Their M-orthonormal shapes Φ.
    G : ndarray (n, n)
        The gyroscopic matrix (skew-symmetric, per unit of ``spin``).
    spin : float
        The speed Ω (rad/s).
    vectors : bool
        Whether to compute the shapes (default True); else ``shapes`` is None.

    Returns
    -------
    omega : ndarray (n,)
        The natural frequencies (rad/s), ascending; 0 for the rigid-body modes (at or below
        √RIGID_RTOL times the highest), which come first.
    shapes : ndarray (n, n), complex
        The mode shapes, ``q(t) = Re(φ e^{iωt})``, normalised to ``φᴴ M φ = 1`` with their largest component real
        and positive; a rigid-body mode's shape is its standstill shape (the first columns of ``shapes`` whose
        ω² is 0).
    """
    n = len(omega2)
    w = np.sqrt(np.clip(omega2, 0.0, None))
    Ge = shapes.T @ G @ shapes
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.diag(w)
    A[n:, :n] = -np.diag(w)
    A[n:, n:] = -spin * Ge
    H = -1j * A  # A z = iω z: the Hermitian -iA has the eigenvalues ω, in ± pairs (0 for a rigid-body mode)
    lam, Z = scipy.linalg.eigh(H) if vectors else (scipy.linalg.eigh(H, eigvals_only=True), None)
    pos = np.argsort(lam)[n:]  # the n largest: the positive ones and half the zeros
    wk = lam[pos]
    zero = wk <= math.sqrt(RIGID_RTOL) * max(float(wk[-1]), 1e-300)
    if not vectors:
        return np.where(zero, 0.0, wk), None
    out = np.zeros((shapes.shape[0], n), dtype=complex)
    nr = int(np.sum(zero))
    out[:, :nr] = shapes[:, np.flatnonzero(omega2 <= 0.0)[:nr]]
    el = pos[~zero]
    eta = Z[n:, el] / (1j * lam[el])  # η' = iω η
    eta = eta / np.sqrt(np.sum(np.abs(eta) ** 2, axis=0))  # Φ is M-orthonormal: φᴴ M φ = |η|²
    v = shapes @ eta
    k = np.argmax(np.abs(v), axis=0)
    top = v[k, np.arange(v.shape[1])]
    out[:, nr:] = v * (np.abs(top) / top)
    return np.where(zero, 0.0, wk), out


class _Spinning:
    """The standstill modes of a system with gyroscopic terms, solved again at any speed."""

    def __init__(self, desc: SystemDescription, clearances: str, G: np.ndarray):
        self.desc, self.G = desc, G
        self.pairs = _whirl_pairs(desc)
        self.base = base = modal_analysis(desc, clearances)
        self.omega2 = np.where(base.rigid, 0.0, base.omega2)

    def at(self, rpm: float, whirl: bool = True) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """(frequencies in Hz with the rigid-body modes first at 0, complex shapes, whirl measures) at ``rpm``."""
        wk, shapes = gyroscopic_eigen(self.omega2, self.base.shapes, self.G, 2.0 * math.pi * rpm / 60.0, vectors=whirl)
        f = wk / (2.0 * math.pi)
        if shapes is None:
            return f, None, None
        return f, shapes, np.where(f > 0, _whirl(self.desc, shapes, self.pairs), 0.0)


def _gyroscopic_modes(desc: SystemDescription, clearances: str, rpm: float, G: np.ndarray) -> ModalResult:
    """The modes of ``M q'' + Ω G q' + K q = 0`` at the reference shaft's speed (the module docstring)."""
    sp = _Spinning(desc, clearances, G)
    f, shapes, whirl = sp.at(rpm)
    names, mats, _ = _element_stiffness(desc, clearances)
    rigid = np.arange(len(f)) < int(np.sum(f == 0))
    return ModalResult(
        desc.labels,
        f,
        (2.0 * math.pi * f) ** 2,
        shapes,
        rigid,
        tuple(names),
        sp.base.mesh_elements,
        _energy(shapes, mats, rigid),
        rpm=rpm,
        whirl=whirl,
    )


#: Share of a mode's lateral motion (of the squared shape) below which it has no whirl (w = 0).
WHIRL_FLOOR = 1e-12


def _whirl_pairs(desc: SystemDescription) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Row indices a, b, the factors of (a, b) and the senses of the whirl pairs (x, y) and r (ry, −rx) of every
    shaft node (the module docstring)."""
    idx = desc.index()
    rows = [
        (idx[(node, a)], idx[(node, b)], fa, fb, s.sense)
        for s in getattr(desc, "shafts", ())
        for node, r in zip(s.nodes, s.radii)
        for a, b, fa, fb in (("x", "y", 1.0, 1.0), ("ry", "rx", r, -r))
    ]
    ia, ib, fa, fb, sense = np.array(rows, dtype=float).reshape(-1, 5).T
    return ia.astype(int), ib.astype(int), fa, fb, sense


def _whirl(desc: SystemDescription, v: np.ndarray, pairs=None) -> np.ndarray:
    """The whirl measures w of complex mode shapes (columns of ``v``; the module docstring)."""
    ia, ib, fa, fb, sense = pairs if pairs is not None else _whirl_pairs(desc)
    v = v.reshape(v.shape[0], -1)
    a, b = fa[:, None] * v[ia], fb[:, None] * v[ib]
    num = np.sum(sense[:, None] * 2.0 * np.imag(a * np.conj(b)), axis=0)
    den = np.sum(np.abs(a) ** 2 + np.abs(b) ** 2, axis=0)
    total = np.sum(np.abs(v) ** 2, axis=0)
    ok = (den > WHIRL_FLOOR * total) & (den > 0)
    return np.where(ok, num / np.where(ok, den, 1.0), 0.0)


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
    speeds: int | None = None,
    clearances: str = "contact",
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
    speeds : int
        With gyroscopic terms: the number of speeds, evenly spaced over ``rpm_range``, at which the modes are
        solved for the branches (default :data:`BRANCH_SPEEDS`).
    clearances : {"contact", "open"}
        The clearance elements of those modes (see :func:`modal_analysis`).

    Returns
    -------
    dict
        ``x``: ``"rpm"`` or ``"mesh_frequency_hz"``; ``x_label``; ``x_range``; ``teeth`` (or ``None``);
        ``lines``: per distinct line ``{"label", "harmonic" (multiple of the reference mesh frequency),
        "hz_per_x", "order", "mesh", "meshes", "orders"}``; ``crossings``: ``{"x", "mode", "modes",
        "order", "mesh", "meshes", "line", "frequency_hz"}`` sorted by ``x`` (``"rpm"`` too against
        speed), modes numbered from 1; ``rpm_range`` against speed.  With gyroscopic terms (a gearbox with
        ``gyroscopic = true``) also ``gyroscopic``: True and ``branches``: ``{"rpm": the speeds,
        "frequencies_hz": per speed the natural frequencies of every mode (ascending), "whirl": per speed each
        mode's whirl measure (> 0 forward, < 0 backward)}``; the crossings are then those of the lines with the
        branches (``mode`` the branch, numbered from 1 like the modes; ``whirl``: ``"forward"``, ``"backward"``
        or ``"none"``), each solved to :data:`CROSSING_XTOL` of the speed range.

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
    fr = res.frequencies_hz  # the distinct non-zero natural frequencies with the numbers (from 1) of their modes
    groups = [(float(fr[g[0]]), [k + 1 for k in g]) for g in _groups(fr) if fr[g[0]] > 0]
    z = desc.reference_mesh.teeth
    per_x = z / 60.0 if z is not None else 1.0  # reference mesh frequency (Hz) per unit of x
    harmonics: dict[float, list[tuple[str, int]]] = {}
    for m in desc.meshes:
        for k in orders:
            key = float(f"{k * m.ratio:.12g}")
            harmonics.setdefault(key, []).append((m.name, k))
    what, given = ("rpm_range", rpm_range) if z is not None else ("mesh_hz_range", mesh_hz_range)
    if z is not None or given is not None:
        lo, hi = (float(x) for x in given)
    else:
        top = max((f for f, _ in groups), default=1.0)
        lo, hi = 0.0, float(f"{1.2 * top / min(harmonics):.2g}")
    if not (0 <= lo < hi and math.isfinite(hi)):
        raise ModelError(f"{what}: must be 0 <= low < high, got {(lo, hi)!r}")
    names = [m.name for m in desc.meshes]
    G = desc.gyroscopic_matrix()
    spinning = _Spinning(desc, clearances, G) if G is not None and z is not None else None
    if spinning is not None:
        n_sp = BRANCH_SPEEDS if speeds is None else int(speeds)
        if not 2 <= n_sp <= 10000:
            raise ModelError(f"speeds: must be from 2 to 10000, got {n_sp}")
        grid = np.linspace(lo, hi, n_sp)
        with threadpool_limits(limits=1, user_api="blas"):  # small dense eigenproblems, many of them
            solved = [spinning.at(float(x)) for x in grid]
        F = np.array([f for f, _, _ in solved])
        W = np.array([w for _, _, w in solved])
    lines, crossings = [], []
    for n, (h, pairs) in enumerate(sorted(harmonics.items())):
        slope = h * per_x
        lines.append(
            {
                "label": _line_label(pairs, names),
                "harmonic": h,
                "hz_per_x": slope,
                **_line(pairs),
                "orders": [p[1] for p in pairs],
            }
        )
        if spinning is not None:
            with threadpool_limits(limits=1, user_api="blas"):
                crossings += _branch_crossings(spinning, grid, F, slope, n, pairs)
            continue
        for f, modes in groups:
            x = f / slope
            if lo <= x <= hi:
                c = _crossing(x, modes, pairs, n, f)
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
    if spinning is not None:
        out["gyroscopic"] = True
        out["branches"] = {
            "rpm": list(map(float, grid)),
            "frequencies_hz": F.tolist(),
            "whirl": W.tolist(),
        }
    return out


#: Speeds (evenly spaced over the diagram's range) at which the branches of a Campbell diagram with gyroscopic
#: terms are solved.
BRANCH_SPEEDS = 41
#: A crossing of an order line with a branch is solved to this fraction of the speed range.
CROSSING_XTOL = 1e-10
#: |w| below this is no whirl (a torsional or axial mode).
WHIRL_NONE = 1e-3


def _branch_crossings(spinning: _Spinning, grid: np.ndarray, F: np.ndarray, slope: float, line: int, pairs) -> list:
    """The crossings of the line ``f = slope x`` with each elastic branch: bracketed on the grid, started from
    the branch's cubic spline and solved on the branch itself by Newton steps with the spline's slope (bisection
    of the bracket if a step leaves it), to :data:`CROSSING_XTOL` of the speed range."""
    from scipy.interpolate import CubicSpline
    from scipy.optimize import brentq

    out = []
    xtol = CROSSING_XTOL * float(grid[-1] - grid[0])
    for i in range(F.shape[1]):
        g = F[:, i] - slope * grid
        if not np.all(F[:, i] > 0):
            continue
        spline = None
        for j in range(len(grid) - 1):
            if not (g[j] > 0 >= g[j + 1] or g[j] >= 0 > g[j + 1]):
                continue
            a, b = float(grid[j]), float(grid[j + 1])
            if spline is None:
                spline = CubicSpline(grid, F[:, i])
            d = spline.derivative()
            fs = lambda s: float(spline(s)) - slope * s  # noqa: E731
            x = brentq(fs, a, b) if fs(a) * fs(b) < 0 else a - g[j] * (b - a) / (g[j + 1] - g[j])
            for _ in range(20):
                gx = spinning.at(x, whirl=False)[0][i] - slope * x  # the frequencies alone
                if gx > 0:
                    a = max(a, x)
                elif gx < 0:
                    b = min(b, x)
                step = -gx / (float(d(x)) - slope)
                x_new = x + step
                if not a <= x_new <= b:
                    x_new = 0.5 * (a + b)
                if abs(x_new - x) <= xtol or gx == 0:
                    x = x_new if gx != 0 else x
                    break
                x = x_new
            w = float(spinning.at(x)[2][i])
            word = "forward" if w > WHIRL_NONE else "backward" if w < -WHIRL_NONE else "none"
            out.append(_crossing(x, [int(i) + 1], pairs, line, slope * x, rpm=x, whirl=word))
    return out


def _line(pairs) -> dict[str, Any]:
    """The first (mesh, order) of a line's ``pairs`` and its meshes."""
    return {"order": pairs[0][1], "mesh": pairs[0][0], "meshes": [p[0] for p in pairs]}


def _crossing(x: float, modes: list[int], pairs, line: int, f: float, **more: Any) -> dict[str, Any]:
    """A crossing of line ``line`` (its (mesh, order) ``pairs``) with the modes ``modes`` at x, frequency f."""
    return {
        "x": x,
        "mode": modes[0],
        "modes": modes,
        **_line(pairs),
        "line": line,
        "frequency_hz": f,
        **more,
    }


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
            "shape": dict(zip(res.labels, map(float, res.shapes[:, i]))),
        }
        for i in range(len(res.frequencies_hz))
    ]
    out: dict[str, Any] = {
        "title": desc.title,
        "source": desc.source,
        "dofs": list(res.labels),
        "frequencies_hz": list(map(float, res.frequencies_hz)),
        "rigid": [bool(x) for x in res.rigid],
        "modes": modes,
        "energy_fractions": [dict(zip(res.elements, map(float, row))) for row in res.energy],
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
    out["campbell"] = campbell(desc, res, rpm_range, orders, mesh_hz_range, clearances=clearances)
    if out["campbell"].get("gyroscopic"):
        out["gyroscopic"] = True
    if desc.reference_mesh.teeth is None:
        out["campbell_note"] = (
            f"mesh {desc.reference_mesh.name!r} gives no teeth: the Campbell diagram is "
            f"against its mesh frequency (Hz), not pinion speed"
        )
    return out
