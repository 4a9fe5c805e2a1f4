"""The mesh excitation as a periodic function: a table over P mesh cycles and its Fourier series.

The 1-DOF model takes the stiffness and the STE as Fourier series (``docs/model.md``):
k/k0 = 1 + Σ_j κ_j cos(jθ + φ_kj) and e/b_c = Σ_j ε_j cos(jθ + φ_ej), each harmonic with its phase.  A
table of N equally spaced values over one period is *exactly* its trigonometric interpolant with
⌊N/2⌋ harmonics (the discrete Fourier transform, Nyquist term halved):

    x_n = c_0 + Σ_{j=1}^{⌊N/2⌋} A_j cos(2π j n / N + φ_j),  A_j = 2|X_j|/N (|X_{N/2}|/N),  φ_j = arg X_j,

so the kernel evaluates, at every θ, the smooth periodic function through the table's points.

**Tables with jumps, evaluated as given.**  A table may also give its node phases (``phase``, mesh
cycles, non-decreasing; a phase given twice is a jump: left value, then right value).  Its series is
then the Fourier series of its piecewise-linear function (:func:`piecewise_series`, exact integrals).
``excitation_model(..., evaluation="table")`` makes a model whose accurate-mode kernel evaluates the
table itself, piecewise linear with its jumps, and ends a sub-step at every node
(:mod:`geardyn.meshtable`); its series stay for the tools that take series.

**Periods of several mesh cycles (a tooth fault, the hunting period).**  The forcing period of a
fault on one pinion tooth is z1 mesh cycles, in general lcm(z1, z2).  The model carries P, the mesh
cycles of one forcing period (:attr:`geardyn.model.GearModel.cycles`): ω stays the mesh frequency
(``--omega 0.8`` and the reported rpm mean the mesh), the series are harmonics of the forcing frequency
ω/P (member j is mesh order j/P; the STE forcing (ω/P)² j² ε_j is that order's), and the forcing period
P·2π/ω is the sampling period of every analysis (Poincaré sections, shooting, Lyapunov exponents,
continuation; a system's HB through its period multiple).  A damping harmonic ξ_k of a base model is
mesh order k, so it becomes member k·P.  Limits: at most MAX_HARMONICS·P harmonics (mesh orders up to
64); the stiffness must stay positive: Σ|κ_j| < 1, or, for P > 1, a certified minimum
(:func:`geardyn.pairpack.stiffness_minimum`).

**Files** (:func:`read_table`, :func:`load_excitation`): the NetCDF that ``geardyn stiffness --out
FILE.nc`` writes, the CSV/JSON tables of ``geardyn stiffness --table FILE.csv|.json`` (columns or keys
``phase`` in mesh cycles, ``stiffness`` in N/m, ``ste`` in m; P = the phase span), or a tooth-pair
TOML file (``examples/tooth_*.toml``), whose stiffness and STE are computed here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model import GearModel, _whole_number
from ..params import MAX_HARMONICS

__all__ = ["Excitation", "excitation_model", "fourier_series", "pair_model", "piecewise_series", "series_table"]


def fourier_series(values: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Mean, amplitudes A_j and phases φ_j (j = 1 … ⌊N/2⌋) of a table over one period.

    Parameters
    ----------
    values : ndarray (N,)
        Equally spaced samples of one period, the first at phase 0.

    Returns
    -------
    (mean, amplitude, phase)
        ``x_n = mean + Σ_j A_j cos(2π j n/N + φ_j)`` exactly (to rounding).
    """
    x = np.asarray(values, dtype=float)
    N = x.size
    if N < 2 or not np.all(np.isfinite(x)):
        raise ModelError("excitation table: needs at least 2 finite values")
    X = np.fft.rfft(x)
    amp = 2.0 * np.abs(X[1:]) / N
    if N % 2 == 0:
        amp[-1] *= 0.5
    return float(X[0].real / N), amp, np.angle(X[1:])


def piecewise_series(phase: np.ndarray, values: np.ndarray, harmonics: int) -> tuple[float, np.ndarray, np.ndarray]:
    """Mean, amplitudes A_j and phases φ_j (j = 1 … ``harmonics``) of a piecewise-linear periodic function.

    The coefficients c_j = ∫_0^1 y(x) e^{−2πijx} dx are integrated exactly segment by segment:
    ∫_a^b (y_a + s(x − a)) e^{−iwx} dx = [(i/w) y(x) e^{−iwx} + (s/w²) e^{−iwx}]_a^b, w = 2πj; then
    y = c_0 + Σ_j 2|c_j| cos(2πjx + arg c_j).

    Parameters
    ----------
    phase : ndarray (n,)
        Node positions as fractions of the period, non-decreasing in [0, 1); a position given twice is a
        jump (left value, then right value).
    values : ndarray (n,)
        The value at each node.
    harmonics : int
        Harmonics returned.

    Returns
    -------
    (mean, amplitude, phase)
    """
    from ..meshtable import node_values, segments

    x, left, right = node_values(phase, values)
    slope = segments(x, left, right, 1.0)
    b = np.r_[x[1:], x[0] + 1.0]
    yb = np.r_[left[1:], left[0]]
    mean = float(np.sum(0.5 * (right + yb) * (b - x)))
    w = 2.0 * np.pi * np.arange(1, int(harmonics) + 1)[:, None]

    def prim(xx, yy):
        ex = np.exp(-1j * w * xx[None, :])
        return (1j / w) * yy[None, :] * ex + (slope[None, :] / w**2) * ex

    c = (prim(b, yb) - prim(x, right)).sum(axis=1)
    return mean, 2.0 * np.abs(c), np.angle(c)


def series_table(mean: float, amplitude: np.ndarray, phase: np.ndarray, n: int) -> np.ndarray:
    """The table of ``n`` equally spaced values over one period of ``mean + Σ A_j cos(jθ + φ_j)``.

    Parameters
    ----------
    mean : float
        Constant term.
    amplitude, phase : ndarray
        A_j and φ_j, j = 1 …
    n : int
        Number of values.

    Returns
    -------
    ndarray
    """
    th = 2.0 * np.pi * np.arange(n) / n
    j = np.arange(1, len(amplitude) + 1)
    return mean + (np.asarray(amplitude)[None, :] * np.cos(np.outer(th, j) + np.asarray(phase)[None, :])).sum(axis=1)


@dataclass(frozen=True)
class Excitation:
    """A mesh excitation over ``cycles`` mesh cycles: stiffness table (N/m) and STE table (m).

    Attributes
    ----------
    stiffness : ndarray
        Mesh stiffness over the period (N/m), equally spaced from phase 0.
    ste : ndarray or None
        STE over the same phases (m).
    cycles : int
        Mesh cycles the tables span.
    phase : ndarray or None
        Node phases in mesh cycles, non-decreasing over [0, cycles), a phase twice at a jump (left value,
        then right value); None: equally spaced from 0.
    """

    stiffness: np.ndarray
    ste: np.ndarray | None = None
    cycles: int = 1
    phase: np.ndarray | None = None

    def __post_init__(self) -> None:
        k = np.asarray(self.stiffness, dtype=float)
        object.__setattr__(self, "stiffness", k)
        if self.ste is not None:
            e = np.asarray(self.ste, dtype=float)
            if e.shape != k.shape:
                raise ModelError(f"excitation: {e.size} STE values for {k.size} stiffness values")
            object.__setattr__(self, "ste", e)
        P = self.cycles
        if not _whole_number(P, 1):
            raise ModelError(f"excitation: cycles must be an integer >= 1, got {P!r}")
        object.__setattr__(self, "cycles", int(P))
        if k.ndim != 1 or k.size < 2 or not np.all(np.isfinite(k)) or np.any(k <= 0):
            raise ModelError("excitation: the stiffness table needs at least 2 finite values > 0")
        if self.phase is not None:
            from ..meshtable import check_table

            ph = np.asarray(self.phase, dtype=float)
            if ph.shape != k.shape:
                raise ModelError(f"excitation: {ph.size} phases for {k.size} stiffness values")
            check_table((ph, k, ()), self.cycles)
            object.__setattr__(self, "phase", ph)

    def nodes(self) -> np.ndarray:
        """The node phases in mesh cycles (equally spaced from 0 unless given)."""
        n = self.stiffness.size
        return self.cycles * np.arange(n) / n if self.phase is None else self.phase

    def _series(self, values: np.ndarray, harmonics: int | None) -> tuple[float, np.ndarray, np.ndarray]:
        if self.phase is None:
            return fourier_series(values)
        return piecewise_series(self.phase / self.cycles, values, harmonics)

    def default_harmonics(self, cap: int) -> int:
        """⌊n/2⌋ for n distinct phases, at most ``cap``."""
        n = self.stiffness.size if self.phase is None else np.unique(self.phase).size
        return min(n // 2, cap)

    def series(
        self, harmonics: int | None = None, b_c: float = 1.0, cap: int | None = None
    ) -> dict[str, tuple[float, ...] | float]:
        """``k0`` and the model's ``kappa``, ``phi_k``, ``eps``, ``phi_e`` (harmonics of ω/cycles).

        ``harmonics`` (default all of the table's) is refused above ``cap`` (default MAX_HARMONICS·cycles)
        and above the table's ⌊N/2⌋."""
        cap = MAX_HARMONICS * self.cycles if cap is None else int(cap)
        if self.phase is not None and harmonics is None:
            harmonics = self.default_harmonics(cap)
        k0, ka, kp = self._series(self.stiffness, harmonics)
        if k0 <= 0:
            raise ModelError("excitation: the mean stiffness must be > 0")
        H = len(ka) if harmonics is None else int(harmonics)
        if H < 1 or H > len(ka):
            raise ModelError(f"excitation: harmonics must be 1 … {len(ka)} (the table's), got {H}")
        if H > cap:
            raise ModelError(
                f"excitation: {H} harmonics asked; the model takes at most {cap} "
                f"(mesh orders up to {cap / self.cycles:g} for a period of {self.cycles} "
                f"cycles): pass harmonics <= {cap}"
            )
        out: dict = {"k0": k0, "kappa": tuple(ka[:H] / k0), "phi_k": tuple(kp[:H])}
        if self.ste is not None:
            _, ea, ep = self._series(self.ste, harmonics)
            out.update(eps=tuple(ea[:H] / b_c), phi_e=tuple(ep[:H]))
        return out


def excitation_model(
    base: GearModel, exc: Excitation, *, harmonics: int | None = None, b_c: float = 1.0, evaluation: str = "series"
) -> GearModel:
    """``base`` with the stiffness and STE of ``exc`` over its P = ``exc.cycles`` mesh cycles.

    Parameters
    ----------
    base : GearModel
        Mesh frequency ω, damping, load and backlash (a base with ``cycles`` > 1 is refused).
    exc : Excitation
        The tables.
    harmonics : int, optional
        Harmonics of ω/P kept (default: the full series of the table, at most MAX_HARMONICS·P).
    b_c : float
        Characteristic length the STE table is divided by (same unit as the table).
    evaluation : {"series", "table"}
        ``"table"``: the model carries the table (k/k0 with k0 the series' mean, e/b_c) and the accurate
        mode evaluates it as given (:mod:`geardyn.meshtable`).

    Returns
    -------
    GearModel
        ``cycles = P``; the stiffness series relative to the table's own mean; base damping harmonic
        ξ_k (mesh order k) moved to member k·P.
    """
    P = int(exc.cycles)
    if base.cycles != 1:
        raise ModelError(f"excitation: the base model already spans {base.cycles} mesh cycles")
    if harmonics is None:
        harmonics = exc.default_harmonics(MAX_HARMONICS * P)
    s = exc.series(harmonics, b_c, cap=MAX_HARMONICS * P)
    changes: dict = {
        "cycles": P,
        "kappa": s["kappa"],
        "phi_k": s["phi_k"],
        "eps": s.get("eps", ()),
        "phi_e": s.get("phi_e", ()),
    }
    if evaluation != "series":
        e = () if exc.ste is None else tuple(exc.ste / b_c)
        changes.update(evaluation=evaluation, table=(tuple(exc.nodes()), tuple(exc.stiffness / s["k0"]), e))
    if P != 1 and base.xi:
        changes["xi"], changes["phi_c"] = spread_harmonics(base.xi, base.phi_c, P)
    return base.replace(**changes)


def spread_harmonics(amps, phases, P: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Harmonic k of the mesh frequency as member k·P of a series over P mesh cycles: (amplitudes, phases),
    a phase not given 0."""
    a, ph = [0.0] * (P * len(amps)), [0.0] * (P * len(amps))
    for k, x in enumerate(amps):
        a[k * P + P - 1], ph[k * P + P - 1] = x, phases[k] if k < len(phases) else 0.0
    return tuple(a), tuple(ph)


def pair_model(
    ms,
    rpm: float,
    *,
    b_c: float = 10e-6,
    backlash: float = 100e-6,
    xi0: float = 0.05,
    density: float = 7850.0,
    harmonics: int | None = None,
) -> tuple[GearModel, dict[str, float]]:
    """The non-dimensional model of a pair from its :class:`~geardyn.tooth.mesh.MeshStiffness`.

    Scales: k0 the mean tangent mesh stiffness; the equivalent mass along the line of action
    m_e = I1 I2 / (I1 r_b2² + I2 r_b1²) of solid disks (I = ½ ρ π b r⁴ at the reference radii);
    ω_n = √(k0/m_e); ω = (rpm · 2π/60 · z1)/ω_n; f_p = F/(k0 b_c); D = (backlash/2)/b_c (backlash along
    the line of action); the STE is ``ms.ste_equivalent``.

    Parameters
    ----------
    ms : MeshStiffness
        The mesh (:func:`geardyn.tooth.mesh.mesh_stiffness`).
    rpm : float
        Pinion speed.
    b_c : float
        Characteristic length (m).
    backlash : float
        Backlash along the line of action (m).
    xi0 : float
        Mean damping ratio.
    density : float
        Density of the gear bodies (kg/m³).
    harmonics : int, optional
        Harmonics of the excitation's period kept (default all of the table's, at most MAX_HARMONICS·P).

    Returns
    -------
    (GearModel, scales)
        The model (mesh frequency ω, ``cycles`` = P) and ``{"k0", "m_e", "omega_n", "b_c",
        "mesh_omega", "cycles", "z1", "z2", "rpm"}``.
    """
    geo = ms.geometry
    if not (math.isfinite(rpm) and rpm > 0):
        raise ModelError(f"rpm: must be > 0, got {rpm!r}")
    I1, I2 = (0.5 * density * math.pi * geo.face_width * r**4 for r in geo.r)
    m_e = I1 * I2 / (I1 * geo.r_b[1] ** 2 + I2 * geo.r_b[0] ** 2)
    exc = Excitation(ms.stiffness, ms.ste_equivalent, ms.cycles)
    k0 = fourier_series(exc.stiffness)[0]
    omega_n = math.sqrt(k0 / m_e)
    w_mesh = rpm * 2.0 * math.pi / 60.0 * geo.gears[0].teeth / omega_n
    base = GearModel(
        omega=w_mesh,
        xi0=xi0,
        xi=(),
        phi_c=(),
        kappa=(),
        phi_k=(),
        eps=(),
        phi_e=(),
        fp=ms.force / (k0 * b_c),
        D=0.5 * backlash / b_c,
    )
    model = excitation_model(base, exc, harmonics=harmonics, b_c=b_c)
    return model, {
        "k0": k0,
        "m_e": m_e,
        "omega_n": omega_n,
        "b_c": b_c,
        "mesh_omega": w_mesh,
        "cycles": ms.cycles,
        "z1": geo.gears[0].teeth,
        "z2": geo.gears[1].teeth,
        "rpm": float(rpm),
    }
