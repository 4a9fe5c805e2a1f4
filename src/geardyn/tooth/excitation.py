"""The mesh excitation as a periodic function: a table over P mesh cycles and its Fourier series.

The 1-DOF model takes the stiffness and the STE as Fourier series in the mesh angle θ = ωτ
(``docs/model.md``): k/k0 = 1 + Σ_r κ_r cos(rθ + φ_kr) and e/b_c = Σ_l ε_l cos(lθ + φ_el), any
number of harmonics (up to :data:`geardyn.params.MAX_HARMONICS`), each with its phase.  A table of N
equally spaced values over one period is *exactly* its trigonometric interpolant with ⌊N/2⌋
harmonics (the discrete Fourier transform, Nyquist term halved):

    x_n = c_0 + Σ_{j=1}^{⌊N/2⌋} A_j cos(2π j n / N + φ_j),  A_j = 2|X_j|/N (|X_{N/2}|/N),  φ_j = arg X_j,

so a table with N ≤ 2·MAX_HARMONICS points per period goes through the existing inputs unchanged:
the kernel evaluates, at every θ, the smooth periodic function through the table's points.

**Periods of several mesh cycles (a tooth fault, the hunting period).**  The forcing period of a
fault on one pinion tooth is z1 mesh cycles, in general lcm(z1, z2).  Without touching the kernel the
model is *reparametrised*: with P cycles per period, the model's frequency becomes ω' = ω/P (its
period 2π/ω' = P·2π/ω) and mesh order r/P becomes the model's harmonic j = r.  The STE forcing
ω'² j² ε_j = ω² (j/P)² ε_j is then exactly the forcing of that order, the damping and stiffness
series carry no ω, so the equation is the same; every analysis (Poincaré sections, shooting,
Lyapunov exponents, continuation, harmonic balance) sees the forcing period P·2π/ω because that is
the model's period.  Limits: the series holds MAX_HARMONICS (64) harmonics of ω', i.e. mesh orders
up to 64/P; the model refuses Σ|κ_j| ≥ 1 (a sufficient positivity test), so a table whose full
series breaks that is passed with fewer harmonics (``harmonics=``).  A sweep over ``omega`` of such
a model sweeps ω' (multiply by P for the mesh frequency).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model import GearModel
from ..params import MAX_HARMONICS

__all__ = ["Excitation", "excitation_model", "fourier_series", "pair_model", "series_table"]


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
    """

    stiffness: np.ndarray
    ste: np.ndarray | None = None
    cycles: int = 1

    def series(self, harmonics: int | None = None, b_c: float = 1.0) -> dict[str, tuple[float, ...] | float]:
        """``k0`` and the model's ``kappa``, ``phi_k``, ``eps``, ``phi_e`` (harmonics of ω/cycles)."""
        k0, ka, kp = fourier_series(self.stiffness)
        if k0 <= 0:
            raise ModelError("excitation: the mean stiffness must be > 0")
        H = len(ka) if harmonics is None else int(harmonics)
        if H > MAX_HARMONICS:
            raise ModelError(f"excitation: {H} harmonics asked; the model takes at most {MAX_HARMONICS} "
                             f"(mesh orders up to {MAX_HARMONICS / self.cycles:g} for a period of {self.cycles} "
                             f"cycles): pass harmonics=<= {MAX_HARMONICS}")
        out: dict = {"k0": k0, "kappa": tuple(ka[:H] / k0), "phi_k": tuple(kp[:H])}
        if self.ste is not None:
            _, ea, ep = fourier_series(self.ste)
            out.update(eps=tuple(ea[:H] / b_c), phi_e=tuple(ep[:H]))
        return out


def excitation_model(base: GearModel, exc: Excitation, *, harmonics: int | None = None, b_c: float = 1.0,
                     mesh_omega: float | None = None) -> GearModel:
    """``base`` with the stiffness and STE of ``exc`` (its other parameters kept).

    Parameters
    ----------
    base : GearModel
        Damping, load, backlash and (unless ``mesh_omega``) the mesh frequency ω.
    exc : Excitation
        The tables; a period of P = ``exc.cycles`` mesh cycles sets the model's ω' = ω/P.
    harmonics : int, optional
        Harmonics of ω' kept (default: the full series of the table).
    b_c : float
        Characteristic length the STE table is divided by (same unit as the table).
    mesh_omega : float, optional
        Mesh frequency ω (default ``base.omega``).

    Returns
    -------
    GearModel
    """
    s = exc.series(harmonics, b_c)
    w = base.omega if mesh_omega is None else float(mesh_omega)
    changes = {"omega": w / exc.cycles, "kappa": s["kappa"], "phi_k": s["phi_k"]}
    if "eps" in s:
        changes.update(eps=s["eps"], phi_e=s["phi_e"])
    else:
        changes.update(eps=(), phi_e=())
    if exc.cycles != 1 and base.xi:
        raise ModelError("excitation: damping harmonics of a base model are mesh orders; give xi = () with a "
                         "multi-cycle excitation")
    return base.replace(**changes)


def pair_model(ms, rpm: float, *, b_c: float = 10e-6, backlash: float = 100e-6, xi0: float = 0.05,
               density: float = 7850.0, harmonics: int | None = None) -> tuple[GearModel, dict[str, float]]:
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
        Harmonics of the excitation's period kept (default all of the table's).

    Returns
    -------
    (GearModel, scales)
        The model (frequency ω/P for a period of P cycles) and ``{"k0", "m_e", "omega_n", "b_c",
        "mesh_omega", "cycles", "z1", "z2", "rpm"}``.
    """
    geo = ms.geometry
    if not (math.isfinite(rpm) and rpm > 0):
        raise ModelError(f"rpm: must be > 0, got {rpm!r}")
    I1, I2 = (0.5 * density * math.pi * geo.face_width * r**4 for r in geo.r)
    m_e = I1 * I2 / (I1 * geo.r_b[1] ** 2 + I2 * geo.r_b[0] ** 2)
    exc = Excitation(ms.stiffness, ms.ste_equivalent, ms.cycles)
    s = exc.series(harmonics, b_c)
    k0 = float(s["k0"])
    omega_n = math.sqrt(k0 / m_e)
    w_mesh = rpm * 2.0 * math.pi / 60.0 * geo.gears[0].teeth / omega_n
    base = GearModel(omega=w_mesh, xi0=xi0, xi=(), phi_c=(), kappa=(), phi_k=(), eps=(), phi_e=(),
                     fp=ms.force / (k0 * b_c), D=0.5 * backlash / b_c)
    model = excitation_model(base, exc, harmonics=harmonics, b_c=b_c)
    return model, {"k0": k0, "m_e": m_e, "omega_n": omega_n, "b_c": b_c, "mesh_omega": w_mesh,
                   "cycles": ms.cycles, "z1": geo.gears[0].teeth, "z2": geo.gears[1].teeth, "rpm": float(rpm)}
