"""Gear rattle: the impacts of an unloaded (loose) gear pair driven within its backlash by engine orders.

An unselected gear of a manual transmission turns with almost no load (a drag torque) while the engine's
torque fluctuation (its firing orders, :mod:`geardyn.torque_orders`) shakes the driving gear; the loose gear
flies through the backlash and strikes the driving gear's flanks — rattle (R. Singh, H. Xie, R. J. Comparin,
"Analysis of automotive neutral gear rattle", J. Sound Vib. 131 (1989) 177–196).  In the pair's coordinate
u (the relative displacement along the line of action over b_c) an **impact** is the start of a contact:
u crossing +D upwards (the drive flank) or −D downwards (the back, coast flank) from free flight; it ends
where u crosses back into the backlash (the rebound).

Measures over the recorded forcing periods (a *cycle* is one forcing period, :meth:`System.period_multiple`
mesh periods; :attr:`RattleResult.cycle_mesh_periods`):

* impacts per cycle on each flank;
* impact velocities |u'| at the impacts (mean and largest, per flank), and the rebound velocities;
* the **rattle index**: the kinetic energy of the relative motion lost in the impacts per cycle,
  R = Σ_i ½ (v_in,i² − v_out,i²) / cycles (non-dimensional in k b_c², in J with the pair's scales), the
  impact kinetic-energy loss of the restitution picture of rattle, ½ m_e (1 − e²) v_in² per impact
  with the impact kinetic energy Σ_i ½ v_in,i² / cycles beside it (the index is negative where the mesh's own
  excitation, STE or varying stiffness, does more work during the contacts than the damping takes);
* the regime: no impact, single-sided (drive flank only) or double-sided rattle.

The crossings are located on the stored steps by the cubic Hermite interpolant of (u, u') and Newton, so a
crossing's time and velocity are 4th-order accurate in the step (the accurate mode, the default here, makes
the trajectory itself 4th order through the contact changes).  ``tests/test_rattle.py`` checks them against
scipy's DOP853 with events.

:func:`rattle_map` is a 2-D sweep over the mesh frequency (or pinion speed) and a scale of every torque order's
amplitude; its Dataset has kind ``rattle_map`` (figure ``rattle_map``).  :func:`pair_of_system` turns a system
file of two gears on their rotations (the usual idle-rattle model) into its pair, orders included.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._lazy import lazy_module
from ..errors import ModelError
from ..integrate import trajectory
from ..io import annotate, result_attrs
from ..model import GearModel, IntegrationOptions
from ..torque_orders import to_dicts

xr = lazy_module("xarray")

__all__ = ["RattleResult", "crossings", "pair_of_system", "rattle", "rattle_map"]

#: Default options of a rattle run: the accurate mode (4th order through the impacts), a long transient (the
#: free flight is lightly damped) and a few recorded cycles.
RATTLE_OPTIONS = IntegrationOptions(dtau=0.005, transient=200, periods=20, accurate=True)
#: Largest number of samples of the history a ``rattle`` Dataset keeps.
HISTORY_SAMPLES = 20_000
#: Newton iterations on the Hermite interpolant of a step.
_NEWTON = 30


def _physical(scales: Any) -> Any:
    """The scales of the physical values (:class:`geardyn.geometry.scales.Scales`, a configured pair's or a
    system's ``scaling``), or None: none given, or the unit scales of a non-dimensional configuration."""
    return None if scales is None or getattr(scales, "nondimensional", False) else scales


def _scales_dict(sc: Any) -> dict[str, Any]:
    """The scales a rattle result states: b_c, ω_n, the mean mesh stiffness k and the teeth of the gear whose
    speed sets the mesh frequency (None when unknown)."""
    return {
        "b_c_m": sc.b_c_m,
        "omega_n_rad_s": sc.omega_n_rad_s,
        "k_N_per_m": sc.k0_N_per_m,
        "teeth": int(sc.z1) or None,
    }


# ---------------------------------------------------------------------------- crossings
def _hermite(u0, v0, u1, v1, h, s):
    """u and u' of the cubic Hermite interpolant on a step of length h at the fraction s."""
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2
    d00, d10, d01, d11 = 6 * s2 - 6 * s, 3 * s2 - 4 * s + 1, -6 * s2 + 6 * s, 3 * s2 - 2 * s
    u = h00 * u0 + h10 * h * v0 + h01 * u1 + h11 * h * v1
    v = (d00 * u0 + d01 * u1) / h + d10 * v0 + d11 * v1
    return u, v


def _locate(level, u0, v0, u1, v1, h):
    """(s, v) at the crossing of u = level inside the step (a sign change of u − level between its ends)."""
    lo, hi = 0.0, 1.0
    flo = u0 - level
    s = flo / (flo - (u1 - level)) if u1 != u0 else 0.5
    for _ in range(_NEWTON):
        u, v = _hermite(u0, v0, u1, v1, h, s)
        f = u - level
        if (f < 0) == (flo < 0):
            lo = s
        else:
            hi = s
        step = f / (v * h) if v != 0 else math.inf
        s_new = s - step
        if not lo < s_new < hi:
            s_new = 0.5 * (lo + hi)
        if abs(s_new - s) < 1e-15:
            s = s_new
            break
        s = s_new
    return s, _hermite(u0, v0, u1, v1, h, s)[1]


def crossings(tau: np.ndarray, u: np.ndarray, v: np.ndarray, D: float) -> dict[str, np.ndarray]:
    """Impacts and rebounds of a trajectory sampled at every step.

    Parameters
    ----------
    tau, u, v : ndarray (K,)
        Times and the state (u, u') at every step.
    D : float
        Half backlash (> 0).

    Returns
    -------
    dict
        ``time``, ``flank`` (+1 drive, −1 back), ``velocity`` (u' at the impact: > 0 on the drive flank, < 0 on
        the back) of the impacts, and ``rebound_time``, ``rebound_flank``, ``rebound_velocity`` of the ends of the
        contacts (u crossing back into |u| <= D).
    """
    tau, u, v = (np.asarray(a, dtype=float) for a in (tau, u, v))
    out = {p + k: [] for p in ("", "rebound_") for k in ("time", "flank", "velocity")}
    for flank in (1, -1):  # u > D on the drive flank, u < -D on the back
        inside = flank * u > D
        change = np.flatnonzero(inside[1:] != inside[:-1])
        for i in change:
            h = tau[i + 1] - tau[i]
            s, vc = _locate(flank * D, u[i], v[i], u[i + 1], v[i + 1], h)
            key = "" if inside[i + 1] else "rebound_"
            out[key + "time"].append(tau[i] + s * h)
            out[key + "flank"].append(flank)
            out[key + "velocity"].append(vc)
    for prefix in ("", "rebound_"):  # in the order of time
        order = np.argsort(np.asarray(out[prefix + "time"], dtype=float), kind="stable")
        for k, dtype in (("time", float), ("flank", np.int8), ("velocity", float)):
            out[prefix + k] = np.asarray(out[prefix + k], dtype=dtype)[order]
    return out


# ---------------------------------------------------------------------------- one point
@dataclass
class RattleResult:
    """Rattle measures of one steady response (non-dimensional; physical with ``scales``).

    Attributes
    ----------
    model : GearModel
    options : IntegrationOptions
    tau, u, v : ndarray
        The recorded history (every step of the recorded cycles).
    events : dict
        :func:`crossings` of the history.
    cycles : int
        Forcing periods recorded.
    cycle_mesh_periods : int
        Mesh periods of one forcing period (a cycle).
    scales : Scales or None
        Physical scales (velocities in m/s = b_c ω_n u', energies in J = k b_c² · ½u'², speeds in rpm).
    status : str
        ``"ok"`` or ``"diverged"``.
    extra : dict
        Further keys of the JSON summary.
    """

    model: GearModel
    options: IntegrationOptions
    tau: np.ndarray
    u: np.ndarray
    v: np.ndarray
    events: dict[str, np.ndarray]
    cycles: int
    cycle_mesh_periods: int
    scales: Any = None
    status: str = "ok"
    extra: dict[str, Any] = field(default_factory=dict)

    # -------------------------------------------------------------- measures
    def _flank(self, flank: int) -> tuple[np.ndarray, np.ndarray]:
        e = self.events
        vin = np.abs(e["velocity"][e["flank"] == flank])
        vout = np.abs(e["rebound_velocity"][e["rebound_flank"] == flank])
        return vin, vout

    def impacts_per_cycle(self, flank: int) -> float:
        return float(self._flank(flank)[0].size / self.cycles)

    def rattle_index(self) -> float:
        """Impact kinetic-energy loss per cycle, Σ ½ (v_in² − v_out²)/cycles (non-dimensional, k b_c²).

        Each impact is paired with the rebound that ends its contact; a contact still open at the end of the
        record (or open at its start) counts with the rebounds that the record holds.
        """
        e = self.events
        total = 0.5 * float(np.sum(e["velocity"] ** 2)) - 0.5 * float(np.sum(e["rebound_velocity"] ** 2))
        return total / self.cycles

    def regime(self) -> str:
        nd, nb = (self._flank(f)[0].size for f in (1, -1))
        if nd == 0 and nb == 0:
            return "no impact"
        return "double-sided rattle" if nd and nb else "single-sided rattle"

    def to_json(self) -> dict[str, Any]:
        """The summary (``geardyn rattle --json``)."""
        out: dict[str, Any] = {
            "omega": self.model.omega,
            "status": self.status,
            "regime": self.regime() if self.status == "ok" else None,
            "cycles": self.cycles,
            "cycle_mesh_periods": self.cycle_mesh_periods,
            "cycle": f"one forcing period: {self.cycle_mesh_periods} mesh period(s), the common period of the mesh "
            "and the torque orders",
            "torque_orders": to_dicts(self.model.torque_orders),
            "fp": self.model.fp,
            "D": self.model.D,
        }
        if self.status != "ok":
            return out
        sc = self.scales
        per = {}
        for name, flank in (("drive", 1), ("back", -1)):
            vin, vout = self._flank(flank)
            d = {
                "impacts_per_cycle": self.impacts_per_cycle(flank),
                "impact_velocity_mean": float(vin.mean()) if vin.size else None,
                "impact_velocity_max": float(vin.max()) if vin.size else None,
                "rebound_velocity_mean": float(vout.mean()) if vout.size else None,
            }
            if sc is not None:
                for k in ("impact_velocity_mean", "impact_velocity_max", "rebound_velocity_mean"):
                    d[k + "_m_s"] = None if d[k] is None else d[k] * (sc.b_c_m * sc.omega_n_rad_s)
            per[name] = d
        out["flanks"] = per
        out["impacts_per_cycle"] = float(self.events["time"].size / self.cycles)
        out["impact_energy"] = 0.5 * float(np.sum(self.events["velocity"] ** 2)) / self.cycles
        out["rattle_index"] = self.rattle_index()
        out["rattle_index_definition"] = "impact kinetic-energy loss per cycle, sum of (v_in^2 - v_out^2)/2 / cycles"
        if sc is not None:
            energy = sc.k0_N_per_m * sc.b_c_m**2
            out["rattle_index_J"] = out["rattle_index"] * energy
            out["impact_energy_J"] = out["impact_energy"] * energy
            out["scales"] = _scales_dict(sc)
            if sc.z1:
                out["rpm"] = float(sc.rpm_from_omega(self.model.omega))
        out.update(self.extra)
        return out

    def to_dataset(self) -> Any:
        """Dataset of kind ``rattle``: the history u, u' over τ (every k-th step, at most :data:`HISTORY_SAMPLES`
        samples) and every impact (located on the full history)."""
        e = self.events
        k = max(1, -(-self.tau.size // HISTORY_SAMPLES))
        ds = xr.Dataset(
            {
                "u": ("tau", self.u[::k]),
                "v": ("tau", self.v[::k]),
                "impact_time": ("impact", e["time"]),
                "impact_flank": ("impact", e["flank"].astype(np.int8)),
                "impact_velocity": ("impact", e["velocity"]),
            },
            coords={"tau": self.tau[::k], "impact": np.arange(e["time"].size)},
        )
        ds.attrs.update(result_attrs("rattle", self.model, self.options, summary=json.dumps(self.to_json())))
        return annotate(ds, "rattle")


def _check(model: Any) -> GearModel:
    if not hasattr(model, "torque_orders") or model.state_dim != 2:
        raise ModelError("rattle: takes the pair (a GearModel); a system of two gears: see pair_of_system")
    if not model.D > 0:
        raise ModelError(f"D (backlash): rattle needs a backlash, D > 0, got {model.D!r}")
    return model


def rattle(
    model: GearModel,
    options: IntegrationOptions = RATTLE_OPTIONS,
    state0: Sequence[float] | None = None,
    *,
    scales: Any = None,
) -> RattleResult:
    """Rattle measures of the steady response of ``model`` (see the module docstring).

    Parameters
    ----------
    model : GearModel
        The pair, with backlash (D > 0); its torque orders drive it.
    options : IntegrationOptions
        ``transient`` forcing periods discarded, ``periods`` recorded (every step kept); default
        :data:`RATTLE_OPTIONS` (accurate mode).
    state0 : (u, u'), optional
        Start (default the middle of the backlash at rest, u = 0).
    scales : Scales, optional
        For the physical values (m/s, J, rpm).

    Returns
    -------
    RattleResult
    """
    model = _check(model)
    sc = _physical(scales)
    tr = trajectory(model, state0, options, history_periods=options.periods)
    ok = np.all(np.isfinite(tr.x))
    ev = crossings(*((tr.tau, tr.u, tr.v) if ok else ([],) * 3), model.D)  # a diverged run: no events
    M = int(model.period_multiple())
    return RattleResult(model, options, tr.tau, tr.u, tr.v, ev, options.periods, M, sc, "ok" if ok else "diverged")


# ---------------------------------------------------------------------------- the map
def rattle_map(
    model: GearModel,
    omegas: Sequence[float],
    amplitude_scales: Sequence[float],
    options: IntegrationOptions = RATTLE_OPTIONS,
    *,
    scales: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """Rattle over a grid of mesh frequencies × scales of every torque order's amplitude.

    The amplitudes stay those of the model times the scale at every speed (a torque in N·m keeps its value
    over the speed range).

    Parameters
    ----------
    model : GearModel
        The pair with its torque orders (at least one) and backlash.
    omegas : sequence of float
        Mesh frequencies ω (> 0).
    amplitude_scales : sequence of float
        Factors (>= 0) on the torque orders' amplitudes.
    options : IntegrationOptions
    scales : optional
        Physical scales (adds the ``rpm`` coordinate, the velocities in m/s and the index in J).
    progress : callable, optional
        ``progress(done, total)`` in points.

    Returns
    -------
    xarray.Dataset
        Kind ``rattle_map``: ``impacts_drive``, ``impacts_back`` (per cycle), ``impact_velocity_max``,
        ``rattle_index`` over (``omega``, ``amplitude_scale``), and ``status`` (0 ok, 1 diverged).
    """
    model = _check(model)
    if not model.torque_orders:
        raise ModelError("torque_orders: a rattle map scales the torque orders' amplitudes; the model has none")
    om = np.asarray(omegas, dtype=float).ravel()
    sa = np.asarray(amplitude_scales, dtype=float).ravel()
    if om.size == 0 or sa.size == 0:
        raise ModelError("rattle map: give at least one speed and one amplitude scale")
    if not np.all(np.isfinite(om)) or np.any(om <= 0):
        raise ModelError("omega: the speeds of a rattle map must be > 0")
    if not np.all(np.isfinite(sa)) or np.any(sa < 0):
        raise ModelError("amplitude_scale: the amplitude scales of a rattle map must be finite and >= 0")
    sc = _physical(scales)
    shape = (om.size, sa.size)
    vals = {k: np.full(shape, np.nan) for k in ("impacts_drive", "impacts_back", "impact_velocity_max", "rattle_index")}
    status = np.zeros(shape, dtype=np.int8)
    for done, (i, j) in enumerate(np.ndindex(shape), 1):
        orders = tuple((q, a * sa[j], p) for q, a, p in model.torque_orders)
        r = rattle(model.replace(omega=float(om[i]), torque_orders=orders), options, scales=sc)
        if r.status != "ok":
            status[i, j] = 1
        else:
            vals["impacts_drive"][i, j] = r.impacts_per_cycle(1)
            vals["impacts_back"][i, j] = r.impacts_per_cycle(-1)
            v = np.abs(r.events["velocity"])
            vals["impact_velocity_max"][i, j] = float(v.max()) if v.size else 0.0
            vals["rattle_index"][i, j] = r.rattle_index()
        if progress is not None:
            progress(done, om.size * sa.size)
    dims = ("omega", "amplitude_scale")
    ds = xr.Dataset({k: (dims, a) for k, a in vals.items()}, coords={"omega": om, "amplitude_scale": sa})
    ds["status"] = (dims, status)
    if sc is not None:
        ds["impact_velocity_max_m_s"] = ds["impact_velocity_max"] * (sc.b_c_m * sc.omega_n_rad_s)
        ds["rattle_index_J"] = ds["rattle_index"] * (sc.k0_N_per_m * sc.b_c_m**2)
        if sc.z1:
            ds = ds.assign_coords(rpm=("omega", sc.rpm_from_omega(om)))
    extra = {"torque_orders": json.dumps(to_dicts(model.torque_orders))}
    if sc is not None:
        extra["rattle_scales"] = json.dumps(_scales_dict(sc))
    ds.attrs.update(result_attrs("rattle_map", model, options, **extra))
    return annotate(ds, "rattle_map")


# ---------------------------------------------------------------------------- a system of two gears
def pair_of_system(system: Any) -> GearModel:
    """The pair of a system of two gears on their rotations, one mesh and no bearing: its relative coordinate.

    With ``a = V M̃⁻¹ Vᵀ`` the relative coordinate u = V q̃ − E obeys u'' + a(C u' + K f(u)) = V M̃⁻¹ F − E'' (the
    loads and their torque orders projected by V M̃⁻¹), the pair's equation when a·k = 1 (a reference mesh
    between two rotations).

    Parameters
    ----------
    system : SystemModel or GearModel
        The system (a pair is returned as it is).

    Returns
    -------
    GearModel

    Raises
    ------
    ModelError
        For any other system (bearings, clearances, several meshes, a mesh off the base frequency).
    """
    meshes = getattr(system, "meshes", None)
    if meshes is None:
        return system
    if len(meshes) != 1 or len(system.clearance_names) or np.any(system.Kb != 0) or np.any(system.Cb != 0):
        raise ModelError(
            "system: rattle runs on the pair; a system file for it holds two gears on their rotations, one mesh, "
            "no bearing or clearance"
        )
    m = meshes[0]
    v = system.V[0]
    a = float(v @ system.Mi @ v)
    if abs(a * m.k - 1.0) > 1e-9 or m.ratio != 1.0 or m.cycles != 1:
        raise ModelError(
            f"mesh {m.name!r}: the pair needs the reference mesh at the base frequency (a·k = {a * m.k:.6g}, "
            f"ratio {m.ratio:g})"
        )
    w = v @ system.Mi
    orders = tuple((r, float(w @ F), ph) for r, F, ph in system.orders)
    return GearModel(
        omega=system.omega,
        xi0=a * m.xi0,
        xi=tuple(a * x for x in m.xi),
        phi_c=m.phi_c,
        kappa=m.kappa,
        phi_k=m.phi_k,
        eps=m.eps,
        phi_e=m.phi_e,
        fp=float(w @ system.F),
        D=m.D,
        torque_orders=orders,
    )
