"""Physical plausibility: the named bounds every door of geardyn applies, written once.

A finite number can still be impossible: a normal pressure angle of 89.9°, a backlash of 5 m, a face width
of 50 m, a transmission error of 1e300 m.  Each rule below is a function that returns the value it checked,
or raises the package's typed error (:class:`~geardyn.errors.ModelError` for a model input,
:class:`~geardyn.errors.ConfigError` for a file) with one line naming the key, the value and the bound.
The pair's geometry (:class:`~geardyn.geometry.SpiralBevelGearPair`, also behind a system's bevel mesh),
excitation tables (:class:`~geardyn.tooth.excitation.Excitation`, every file format) and the run budgets
(:func:`budget`) call them; result files read back are checked beside the variable registry
(:func:`geardyn.io.result_variables`).

The bounds are those of gears that are made, not of the formulas: ``docs/engineering.md`` lists them with
their reasons.  What is unusual but possible (an undercut pinion) is a note, not a refusal
(:func:`undercut_note`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import ConfigError, ModelError

__all__ = [
    "ALPHA_N_DEG",
    "BETA_M_MAX_DEG",
    "FACE_WIDTH_MAX_CONE",
    "BACKLASH_MAX_MODULES",
    "MAX_TABLE_BYTES",
    "MODULE_M",
    "RADIUS_RATIO_TOL",
    "PITCH_RADIUS_FACTOR",
    "STIFFNESS_N_PER_M",
    "STE_MAX_M",
    "UNDERCUT_ADDENDUM",
    "budget",
    "system",
    "taking_a_system",
    "pair_geometry",
    "excitation_table",
    "file_size",
    "undercut_note",
]

#: Normal pressure angle α_n (deg): gears are cut with 14.5° to 30°; below 10° every tooth is undercut, above
#: 40° the teeth are pointed before they reach a working depth.
ALPHA_N_DEG = (10.0, 40.0)
#: Mean spiral angle β_m (deg): zerol gears 0°, spiral bevel gears 20°–45°, hypoid pinions up to about 60°.
BETA_M_MAX_DEG = 70.0
#: Mean normal module (m): 0.05 mm (instrument gears) to 100 mm (the largest cut gears).
MODULE_M = (0.05e-3, 0.1)
#: r2/r1 of the mesh point against z2/z1: the pitch radii of a bevel pair are in the ratio of the teeth, those
#: of a hypoid pair in that ratio times cos β_m1/cos β_m2 (between cos β_m and 1); this tolerance beyond.
RADIUS_RATIO_TOL = 0.05
#: A given r_l against the mean pitch radius m_mn z_l/(2 cos β_m): the mesh point lies on the tooth, between
#: half and twice that radius.
PITCH_RADIUS_FACTOR = (0.5, 2.0)
#: Normal backlash j_n at most this many modules (set-up backlash is a few hundredths of a module; a
#: backlash of half a module leaves half a tooth).
BACKLASH_MAX_MODULES = 0.5
#: Face width b at most this fraction of the outer cone distance R_e (0.3 is the usual design limit, beyond
#: 0.5 the inner end of the tooth nears the apex).
FACE_WIDTH_MAX_CONE = 0.5
#: Mesh stiffness of an excitation table (N/m): 1 N/mm to 10⁶ N/µm (a gear mesh is 10–10⁴ N/µm).
STIFFNESS_N_PER_M = (1.0e3, 1.0e12)
#: |STE| of an excitation table (m): 1 mm; a transmission error is of µm (tens of µm with faults).
STE_MAX_M = 1.0e-3
#: Largest excitation table file read (bytes), as a TE record (:data:`geardyn.te.MAX_TE_BYTES`).
MAX_TABLE_BYTES = 64_000_000
#: Addendum coefficient of the undercut limit 2·h_a*/sin²α_n (full-depth teeth without profile shift).
UNDERCUT_ADDENDUM = 1.0


def pair_geometry(
    *,
    z1: int,
    z2: int,
    m_mn: float,
    beta_m: float,
    alpha_n: float,
    j_n: float,
    r1: float | None = None,
    r2: float | None = None,
    face_width: float | None = None,
    delta1: float | None = None,
) -> None:
    """The plausibility rules of a bevel pair's geometry (SI units, angles in rad).

    Parameters
    ----------
    z1, z2 : int
        Teeth.
    m_mn, beta_m, alpha_n, j_n : float
        Mean normal module (m), mean spiral angle, normal pressure angle (rad), normal backlash (m).
    r1, r2 : float, optional
        Given distances of the mesh point to the axes (m).
    face_width : float, optional
        Given face width (m).
    delta1 : float, optional
        Pinion pitch cone angle (rad), for the face width against the cone distance.

    Raises
    ------
    ModelError
        Naming the key and its bound: :data:`ALPHA_N_DEG`, :data:`BETA_M_MAX_DEG`, :data:`MODULE_M`,
        :data:`BACKLASH_MAX_MODULES`, :data:`RADIUS_RATIO_TOL`, :data:`PITCH_RADIUS_FACTOR`,
        :data:`FACE_WIDTH_MAX_CONE`.
    """
    a = math.degrees(alpha_n)
    lo, hi = ALPHA_N_DEG
    if not lo <= a <= hi:
        raise ModelError(
            f"alpha_n: normal pressure angle alpha_n = {a:.6g} deg is outside [{lo:g}, {hi:g}] deg of cut gears",
        )
    b = math.degrees(beta_m)
    if b > BETA_M_MAX_DEG:
        raise ModelError(f"beta_m: mean spiral angle beta_m = {b:.6g} deg is above {BETA_M_MAX_DEG:g} deg")
    lo, hi = MODULE_M
    if not lo <= m_mn <= hi:
        raise ModelError(
            f"m_mn: mean normal module m_mn = {m_mn * 1e3:.6g} mm is outside [{lo * 1e3:g}, {hi * 1e3:g}] mm"
        )
    if j_n > BACKLASH_MAX_MODULES * m_mn:
        raise ModelError(
            f"j_n: normal backlash j_n = {j_n * 1e3:.6g} mm is above {BACKLASH_MAX_MODULES:g} x the module m_mn "
            f"({BACKLASH_MAX_MODULES * m_mn * 1e3:.6g} mm)",
        )
    pitch = [m_mn * z / (2.0 * math.cos(beta_m)) for z in (z1, z2)]
    flo, fhi = PITCH_RADIUS_FACTOR
    for key, r, rp in (("r1", r1, pitch[0]), ("r2", r2, pitch[1])):
        if r is not None and not flo * rp <= r <= fhi * rp:
            raise ModelError(
                f"{key}: {key} = {r * 1e3:.6g} mm is outside [{flo:g}, {fhi:g}] x the mean pitch radius "
                f"m_mn z/(2 cos beta_m) = {rp * 1e3:.6g} mm",
            )
    if r1 is not None and r2 is not None:
        q = (r2 / r1) / (z2 / z1)
        qlo = math.cos(beta_m) * (1.0 - RADIUS_RATIO_TOL)
        if not qlo <= q <= 1.0 + RADIUS_RATIO_TOL:
            raise ModelError(
                f"r2: r2/r1 = {r2 / r1:.6g} against z2/z1 = {z2 / z1:.6g}: their quotient {q:.4g} is outside "
                f"[{qlo:.4g}, {1.0 + RADIUS_RATIO_TOL:g}] (the pitch radii of a bevel pair are in the ratio of the "
                f"teeth, a hypoid's by cos beta_m1/cos beta_m2 >= cos beta_m; tolerance {100 * RADIUS_RATIO_TOL:g} %)",
            )
    if face_width is not None and delta1 is not None:
        r_m = (r1 if r1 is not None else pitch[0]) / math.sin(delta1)  # mean cone distance
        r_e = r_m + 0.5 * face_width
        if face_width > FACE_WIDTH_MAX_CONE * r_e:
            raise ModelError(
                f"face_width: face_width = {face_width * 1e3:.6g} mm is above {FACE_WIDTH_MAX_CONE:g} x the outer "
                f"cone distance R_e = {r_e * 1e3:.6g} mm",
            )


def undercut_note(z1: int, delta1: float, beta_m: float, alpha_n: float) -> str | None:
    """A note when the pinion's virtual number of teeth is below the undercut limit, else None.

    The virtual spur pinion of the normal section has z_vn = z1/(cos δ1 cos³β_m) teeth; full-depth teeth
    without profile shift are undercut below 2 h_a*/sin²α_n (h_a* = :data:`UNDERCUT_ADDENDUM`).

    Parameters
    ----------
    z1 : int
    delta1, beta_m, alpha_n : float
        Pitch cone, mean spiral and normal pressure angles (rad).

    Returns
    -------
    str or None
    """
    zvn = z1 / (math.cos(delta1) * math.cos(beta_m) ** 3)
    limit = 2.0 * UNDERCUT_ADDENDUM / math.sin(alpha_n) ** 2
    if zvn >= limit:
        return None
    return (
        f"pinion: virtual number of teeth z_vn = z1/(cos δ1 cos³β_m) = {zvn:.3g} is below the undercut limit "
        f"2/sin²α_n = {limit:.3g}: its teeth are undercut unless cut with a profile shift (the mesh stiffness "
        "and contact ratio of the model assume unweakened teeth)"
    )


def excitation_table(stiffness: Any, ste: Any = None, *, where: str = "excitation") -> None:
    """A stiffness table (N/m) and STE table (m) within the ranges of gear meshes.

    Parameters
    ----------
    stiffness, ste : array_like
        The tables (``ste`` optional).
    where : str
        What to name in the message (the file).

    Raises
    ------
    ModelError
        For a stiffness outside :data:`STIFFNESS_N_PER_M` or an |STE| above :data:`STE_MAX_M`.
    """
    k = np.asarray(stiffness, dtype=float)
    lo, hi = STIFFNESS_N_PER_M
    if k.size and np.all(np.isfinite(k)) and (float(np.min(k)) < lo or float(np.max(k)) > hi):
        bad = float(np.min(k)) if float(np.min(k)) < lo else float(np.max(k))
        raise ModelError(
            f"{where}: stiffness {bad:.6g} N/m is outside [{lo:g}, {hi:g}] N/m "
            f"({lo * 1e-6:g} to {hi * 1e-6:g} N/um; a gear mesh is 10 to 1e4 N/um)"
        )
    if ste is not None:
        e = np.asarray(ste, dtype=float)
        if e.size and not np.all(np.isfinite(e)):
            raise ModelError(f"{where}: the STE table must hold finite numbers (m)")
        if e.size and float(np.max(np.abs(e))) > STE_MAX_M:
            raise ModelError(
                f"{where}: |STE| {float(np.max(np.abs(e))):.6g} m is above {STE_MAX_M:g} m "
                "(a transmission error is of micrometres)"
            )


def file_size(path: Any, limit: int, what: str, hint: str = "") -> int:
    """The size of a file to be read whole, refused above ``limit`` bytes before it is read.

    Parameters
    ----------
    path : str or Path
        The file (a missing one gives 0: its reader says what is wrong).
    limit : int
        Largest size read (bytes).
    what : str
        What the file holds, for the message (``"excitation table"``).
    hint : str
        What to do instead, appended in parentheses.

    Returns
    -------
    int
        The size (bytes).

    Raises
    ------
    ConfigError
        ``<file>: <what> of X MB; at most Y MB are read`` (and ``hint``).
    """
    import os

    try:
        size = int(os.stat(path).st_size)
    except OSError:
        return 0  # the reader says what is wrong with a missing file
    if size > limit:
        raise ConfigError(
            f"{path}: {what} of {size / 1e6:.1f} MB; at most {limit / 1e6:.0f} MB are read"
            + (f" ({hint})" if hint else "")
        )
    return size


def budget(what: str, estimate: float, limit: float, unit: str = "bytes", key: str = "") -> None:
    """Refuse a run whose estimated size exceeds its budget, before it starts.

    Parameters
    ----------
    what : str
        What is estimated (``"memory of the eigenproblem"``).
    estimate, limit : float
        The estimate and the budget.
    unit : str
        ``"bytes"`` (printed in MB/GB) or a word (``"samples"``).
    key : str
        The option or key that sets the size.

    Raises
    ------
    ModelError
        ``<key>: <what> would need <estimate>, above the budget of <limit>``.
    """
    if not estimate > limit:
        return

    def show(x: float) -> str:
        if unit == "bytes":
            return f"{x / 1e9:.3g} GB" if x >= 1e9 else f"{x / 1e6:.3g} MB"
        return f"{x:.3g} {unit}"

    raise ModelError(
        f"{key + ': ' if key else ''}{what} would need {show(estimate)}, above the budget of {show(limit)}"
    )


def system(obj: Any, key: str = "model") -> Any:
    """``obj`` if it is a System (:class:`geardyn.system.System`: a GearModel, a SystemModel), else a ModelError.

    Parameters
    ----------
    obj : object
        What a public function was given as its model.
    key : str
        The argument's name, for the message.

    Returns
    -------
    System

    Raises
    ------
    ModelError
        ``model: expected a geardyn System (GearModel or SystemModel), got NoneType``.
    """
    from .system import System

    if not isinstance(obj, System):
        raise ModelError(
            f"{key}: expected a geardyn System (GearModel or SystemModel, e.g. geardyn.GearModel()), "
            f"got {type(obj).__name__}"
        )
    return obj


def taking_a_system(fn: Any, many: bool = False) -> Any:
    """``fn`` checking that its first argument (``model``) is a System (``many``: a sequence of them) first.

    Parameters
    ----------
    fn : callable
        A public function whose first argument is a model.
    many : bool
        The first argument is a sequence of models (``integrate_batch``).

    Returns
    -------
    callable
        ``fn`` with the check, its name and docstring kept.
    """
    import functools

    @functools.wraps(fn)
    def checked(*args: Any, **kwargs: Any) -> Any:
        first = args[0] if args else kwargs.get("model", kwargs.get("models"))
        if many and isinstance(first, (list, tuple)):
            if not first:
                raise ModelError("models: expected at least one System")
            for m in first:
                system(m, "models")
        elif not many or not hasattr(first, "__len__"):
            system(first, "models" if many else "model")
        return fn(*args, **kwargs)

    return checked
