"""The readings of the paper: what it leaves open, and the batched sweeps that try them.

The paper leaves open the phases of the stiffness and damping variation (geardyn's default 0), how
its backlash b in mm becomes the non-dimensional D, and the ω of its damping and backlash studies.
A **reading** fixes them: phases (φ_c1, φ_k1) from {0, π/2, π, 3π/2}, one of the backlash readings
of :data:`BACKLASH_READINGS` (f_p, ε1 and b_n of Table 1 kept), and ω from a grid of step 0.01.

Two batched sweeps try the readings, each one call of the sweep engine:

- :func:`screen`: independent points (any parameters) from one initial state, through
  :func:`geardyn.analysis.bifurcation.grid_chunk` on a curve grid;
- :func:`lockstep_responses`: up and down frequency responses of many readings at once, each ω
  step one batch of every reading's point continuing from its own end state
  (:func:`lockstep_chunk`), so the continuation costs what its kernel work costs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from ..analysis.bifurcation import grid_chunk
from ..analysis.points import run_slices
from ..analysis.response import detect_jumps
from ..grid import Grid, point_models
from ..integrate import integrate_batch
from ..model import GearModel, IntegrationOptions
from ..sweep import Chunk, SweepOptions, chunk_slices, run_chunks
from .verdicts import section_spread

__all__ = [
    "BACKLASH_READINGS",
    "DEFAULT_BACKLASH",
    "PHASES",
    "Reading",
    "lockstep_chunk",
    "lockstep_responses",
    "phase_pairs",
    "phase_text",
    "screen",
]

#: The phases tried for φ_c1 and φ_k1 (rad).
PHASES: tuple[float, ...] = (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)
#: The backlash readings: name → the length (mm) b is divided by to give D.  "b/2": D = b/(2 mm), the
#: pairing of the paper's Table 3 (geardyn's default); "b": D = b/(1 mm); "b/0.1": D = b/(0.1 mm), i.e.
#: the length scale is Table 1's normal backlash 0.1 mm (its D = 1), f_p, ε1 and b_n of Table 1 kept.
BACKLASH_READINGS: dict[str, float] = {"b/2": 2.0, "b": 1.0, "b/0.1": 0.1}
#: geardyn's declared default backlash reading.
DEFAULT_BACKLASH = "b/2"


def phase_text(x: float) -> str:
    """A phase as the report writes it (``0``, ``π/2``, ``π``, ``3π/2``).

    Parameters
    ----------
    x : float
        The phase (rad).

    Returns
    -------
    str
    """
    k = round(2 * x / math.pi)
    if abs(x - k * math.pi / 2) > 1e-9:
        return f"{x:.3g}"
    return {0: "0", 1: "π/2", 2: "π", 3: "3π/2"}.get(k, f"{x:.3g}")


def phase_pairs(full: bool) -> list[tuple[float, float]]:
    """(φ_c1, φ_k1) pairs: all 16 of :data:`PHASES` (``full``), or each phase varied alone (7).

    Parameters
    ----------
    full : bool

    Returns
    -------
    list of (float, float)
        The default (0, 0) first.
    """
    if full:
        return [(a, b) for a in PHASES for b in PHASES]
    return [(0.0, 0.0)] + [(a, 0.0) for a in PHASES[1:]] + [(0.0, b) for b in PHASES[1:]]


@dataclass(frozen=True)
class Reading:
    """One reading of what the paper leaves open.

    Parameters
    ----------
    phi_c, phi_k : float
        Phases of the damping and stiffness harmonics (rad).
    backlash : str
        A key of :data:`BACKLASH_READINGS` (or ``""`` where b is not involved).
    omega : float, optional
        ω where the study's ω is unstated (NaN: the claim's own ω or a sweep over ω).
    """

    phi_c: float = 0.0
    phi_k: float = 0.0
    backlash: str = ""
    omega: float = float("nan")

    @property
    def is_default(self) -> bool:
        """Phases 0, the default backlash reading (or none) and ω = 1 (or none)."""
        return not self.changes()

    def D(self, b_mm: float) -> float:
        """D of a backlash b (mm) under this reading."""
        return b_mm / BACKLASH_READINGS[self.backlash or DEFAULT_BACKLASH]

    @property
    def text(self) -> str:
        """``"ω = 1.23, φ_c1 = π/2, φ_k1 = 0, D = b/(2 mm)"``."""
        parts = [] if math.isnan(self.omega) else [f"ω = {self.omega:.2f}"]
        parts += [f"φ_c1 = {phase_text(self.phi_c)}", f"φ_k1 = {phase_text(self.phi_k)}"]
        if self.backlash:
            parts.append(f"D = b/({BACKLASH_READINGS[self.backlash]:g} mm)")
        return ", ".join(parts)

    def changes(self) -> str:
        """What this reading changes from the default, in words (empty for the default)."""
        out = []
        if not math.isnan(self.omega) and abs(self.omega - 1.0) > 1e-9:
            out.append(f"ω = {self.omega:.2f} instead of 1")
        if self.phi_c:
            out.append(f"damping phase φ_c1 = {phase_text(self.phi_c)}")
        if self.phi_k:
            out.append(f"stiffness phase φ_k1 = {phase_text(self.phi_k)}")
        if self.backlash and self.backlash != DEFAULT_BACKLASH:
            out.append(f"backlash read as D = b/({BACKLASH_READINGS[self.backlash]:g} mm)")
        return ", ".join(out)


#: The variables a screen keeps per point.
SCREEN_KEEP = (
    "motion",
    "period",
    "lle",
    "lle_err",
    "amplitude",
    "impact",
    "u_min",
    "u_max",
    "poincare",
    "end",
    "status",
)


def screen(
    base: GearModel,
    names: Sequence[str],
    points: np.ndarray,
    options: IntegrationOptions,
    settle: int,
    executor: Any = None,
    *,
    lyapunov: bool = False,
) -> dict[str, np.ndarray]:
    """Independent points from u = u' = 0, in one call of the sweep engine (a curve grid).

    Parameters
    ----------
    base : GearModel
        The model every point starts from.
    names : sequence of str
        The parameters set at each point (columns of ``points``).
    points : ndarray (P, len(names))
        Their values.
    options : IntegrationOptions
        Transient and recorded periods.
    settle : int
        Settling periods of non-periodic points (exponents there).
    executor : concurrent.futures.Executor, optional
        Where the chunks run (``None``: this process).
    lyapunov : bool
        Exponents for every point.

    Returns
    -------
    dict of ndarray
        One row per point: :data:`SCREEN_KEEP`.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    grid = Grid.curve({n: pts[:, i] for i, n in enumerate(names)})
    engine = SweepOptions(executor=executor)
    gp = grid.points()
    return run_slices(
        grid_chunk,
        lambda sl: (base, grid.names, gp[sl], (0.0, 0.0), options, lyapunov, settle, False, SCREEN_KEEP),
        chunk_slices(grid, base, options, engine, lyapunov=lyapunov),
        engine,
        "readings screen",
    )


def lockstep_chunk(
    base: GearModel, names: Sequence[str], points: np.ndarray, omegas: np.ndarray, options: IntegrationOptions
) -> dict[str, np.ndarray]:
    """Up and down frequency responses of several readings, every ω step one batch (chunk function).

    Each reading's point at ω_i starts from its own end state at ω_{i−1} (the previous ω of its
    sweep); the first point of each sweep starts from u = u' = 0.  A point that diverges restarts
    from zero at the next ω.

    Parameters
    ----------
    base : GearModel
    names : sequence of str
        The parameters of a reading (not ω).
    points : ndarray (R, len(names))
        The readings.
    omegas : ndarray (n,)
        The ω grid, ascending.
    options : IntegrationOptions
        Transient and recorded periods per point.

    Returns
    -------
    dict of ndarray
        ``amplitude`` (half peak-to-peak) and ``spread`` (:func:`geardyn.paper.verdicts.section_spread`): each
        (R, 2, n), sweep 0 up and 1 down, in ascending ω.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    R, n = pts.shape[0], len(omegas)
    out = {k: np.full((R, 2, n), np.nan) for k in ("amplitude", "spread")}
    full = tuple(names) + ("omega",)
    for s, order in enumerate((np.arange(n), np.arange(n)[::-1])):
        state = np.zeros((R, 2))
        for i in order:
            state[~np.all(np.isfinite(state), axis=1)] = 0.0
            res = integrate_batch(
                point_models(base, full, np.column_stack([pts, np.full(R, omegas[i])])), state, options
            )
            out["amplitude"][:, s, i] = res.amplitude
            out["spread"][:, s, i] = [section_spread(p) for p in res.poincare]
            state = res.end_state.copy()
    return {k: v.reshape(R, -1) for k, v in out.items()}


def lockstep_responses(
    base: GearModel,
    names: Sequence[str],
    points: np.ndarray,
    omegas: Sequence[float],
    options: IntegrationOptions,
    executor: Any = None,
) -> dict[str, np.ndarray]:
    """:func:`lockstep_chunk` over many readings, cut into four chunks for the sweep engine (large kernel batches).

    Parameters
    ----------
    base, names, points, options
        As :func:`lockstep_chunk`.
    omegas : sequence of float
        The ω grid (sorted here).
    executor : concurrent.futures.Executor, optional

    Returns
    -------
    dict of ndarray
        ``amplitude``, ``spread`` (R, 2, n) and ``omega`` (n,).
    """
    pts = np.asarray(points, dtype=float).reshape(-1, len(names))
    w = np.sort(np.asarray(omegas, dtype=float))
    chunk = max(1, -(-pts.shape[0] // 4))
    chunks = [
        Chunk(i, lockstep_chunk, (base, tuple(names), pts[a : a + chunk], w, options))
        for i, a in enumerate(range(0, pts.shape[0], chunk))
    ]
    res = run_chunks(chunks, SweepOptions(executor=executor), description="readings responses")
    out = {k: np.concatenate([r[k] for r in res], axis=0).reshape(pts.shape[0], 2, w.size) for k in res[0]}
    out["omega"] = w
    return out


def response_jumps(omega: np.ndarray, amplitude: np.ndarray) -> list[dict[str, Any]]:
    """The jumps of one lockstep response (up and down amplitudes) by the rule of
    :func:`geardyn.analysis.response.detect_jumps`.

    Parameters
    ----------
    omega : ndarray (n,)
    amplitude : ndarray (2, n)
        Up and down sweeps.

    Returns
    -------
    list of dict
    """
    ds = xr.Dataset(
        {"amplitude": (("sweep", "omega"), np.asarray(amplitude, float))},
        coords={"sweep": ["up", "down"], "omega": np.asarray(omega, float)},
        attrs={"param": "omega"},
    )
    return detect_jumps(ds)
