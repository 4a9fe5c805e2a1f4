"""Inputs of a spiral bevel gear pair: defaults, their sources, validation and the resolved values.

Holds the default values used when a pair leaves an input out (each with the sentence saying
where it comes from), the checks every input goes through (finite, positive, angle in range),
:func:`drive_side_from_rotation`, :class:`Assumption` (one assumed value and its source) and
:class:`ResolvedInputs` (every optional input of a pair with its default applied).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..model import ModelError
from ..standards._common import AssumedInput

__all__ = [
    "Assumption",
    "CONE_DISTANCE_NOTE_TOL",
    "DEFAULT_C_GAMMA",
    "DEFAULT_DRIVE_SIDE",
    "DEFAULT_HAND",
    "DEFAULT_XI0",
    "FACE_WIDTH_TO_OUTER_CONE_DISTANCE",
    "HANDS",
    "ROTATIONS",
    "ResolvedInputs",
    "SIDES",
    "drive_side_from_rotation",
]

#: Default mean mesh stiffness per unit face width c_γ, in N/m² (= 20 N/(mm·µm)).  The usual
#: ISO 6336 / ISO 10300 style mean value when nothing better is known.
DEFAULT_C_GAMMA = 20.0e9
#: Face width as a fraction of the outer cone distance used when no face width is given
#: (b = 0.3 R_e, the usual upper limit for bevel gears).
FACE_WIDTH_TO_OUTER_CONE_DISTANCE = 0.3
#: Hand of spiral of the pinion used when none is given (the gear has the opposite hand).
DEFAULT_HAND = "left"
#: Loaded flank of the pinion used when none is given (pinion concave drives gear convex).
DEFAULT_DRIVE_SIDE = "concave"
#: Mean mesh damping ratio ξ0 used when neither ξ0 nor c0 is given (the paper's Table 1 value).
DEFAULT_XI0 = 0.1
#: Relative mismatch between the cone distances implied by r1/sin δ1 and r2/sin δ2 above which a
#: note is added to the summary.
CONE_DISTANCE_NOTE_TOL = 1e-3

HANDS = ("left", "right")
SIDES = ("concave", "convex")
ROTATIONS = ("clockwise", "counterclockwise")

_SOURCE_HAND = (
    "not given in the paper; hand and drive side change only the axial and radial force components, "
    "not the torsional model"
)
_SOURCE_SIDE = _SOURCE_HAND
_SOURCE_C_GAMMA = "typical value: ISO 6336/ISO 10300 style mean mesh stiffness per unit face width, 20 N/(mm·µm)"
_SOURCE_FACE_WIDTH = (
    "not given; b = 0.3·R_e (usual upper limit of the face width of bevel gears, typical value), "
    "with R_e = R_m + b/2 and R_m = r1/sin δ1"
)
_SOURCE_K0 = "not given; k0 = face width × c_γ"
_SOURCE_XI0 = "not given; ξ0 = 0.1 (the paper's Table 1 value, within the range usually assumed for gear meshes)"
_SOURCE_R = "not given; mesh point taken at the mean pitch point, r_l = m_mn z_l / (2 cos β_m)"


def _finite(name: str, value: Any, unit: str = "", of_unit: bool = False) -> float:
    """``value`` as a finite float, else a ModelError naming ``name`` (and ``unit`` if ``of_unit``)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected a number{(' in ' + unit) if unit else ''}, got {value!r}") from None
    if not math.isfinite(x):
        raise ModelError(f"{name}: must be a finite number{(' of ' + unit) if of_unit else ''}, got {value!r}")
    return x


def _positive(name: str, value: Any, unit: str) -> float:
    x = _finite(name, value, unit)
    if x <= 0:
        raise ModelError(f"{name}: must be > 0 {unit}, got {x:g} {unit}")
    return x


def _angle(name: str, value: Any, lo_deg: float, hi_deg: float, lo_closed: bool = False) -> float:
    """Validate an angle given in radians against an interval given in degrees."""
    x = _finite(name, value, "rad")
    d = math.degrees(x)
    ok_lo = d >= lo_deg if lo_closed else d > lo_deg
    if not (ok_lo and d < hi_deg):
        lb = "[" if lo_closed else "("
        raise ModelError(f"{name}: must be in {lb}{lo_deg:g}, {hi_deg:g}) deg, got {d:.6g} deg")
    return x


def drive_side_from_rotation(hand: str, rotation: str) -> str:
    """Loaded pinion flank for a pinion of the given hand turning the given way.

    Parameters
    ----------
    hand : {"left", "right"}
        Hand of spiral of the pinion (the gear has the opposite hand).
    rotation : {"clockwise", "counterclockwise"}
        Sense of rotation of the driving pinion viewed from its back, looking towards the apex.

    Returns
    -------
    str
        ``"concave"`` or ``"convex"``: the pinion flank that carries the load.  With the
        conventions of this module a left-hand pinion turning clockwise drives on its concave
        flank, a right-hand pinion turning counterclockwise too.
    """
    if hand not in HANDS:
        raise ModelError(f"hand: must be one of {', '.join(HANDS)}, got {hand!r}")
    if rotation not in ROTATIONS:
        raise ModelError(f"pinion_rotation: must be one of {', '.join(ROTATIONS)}, got {rotation!r}")
    # j1 = s·h·a1 with s = -1 (concave) / +1 (convex), h = +1 (left) / -1 (right);
    # j1 = +a1 is counterclockwise seen from the back: s = +1 when h and the sense of rotation agree.
    return "convex" if (hand == "left") == (rotation == "counterclockwise") else "concave"


class Assumption(AssumedInput):
    """An input value the paper (or the configuration) does not give, with its source.

    The same record as the standards' :class:`~geardyn.standards.AssumedInput` (fields ``name``,
    ``value``, ``unit``, ``source``; :meth:`to_dict`), named for the gear-pair geometry: ``name``
    is a parameter of :class:`SpiralBevelGearPair` or a key of the configuration file.

    Parameters
    ----------
    name : str
        Parameter name, as in :class:`SpiralBevelGearPair` or in the configuration file.
    value : float or str
        The value used, in ``unit``.
    unit : str
        Unit of ``value`` ("" for words and non-dimensional numbers).
    source : str
        Where the value comes from, or why it was chosen.
    """


@dataclass(frozen=True)
class ResolvedInputs:
    """The optional inputs of a :class:`SpiralBevelGearPair` with every default applied (SI units).

    Attributes
    ----------
    r1, r2 : float
        Distance from the mesh point to the pinion / gear axis (m).
    hand : str
        Hand of spiral of the pinion ("left" or "right").
    drive_side : str
        Loaded flank of the pinion ("concave" or "convex").
    face_width : float
        Face width b (m).
    c_gamma : float
        Mean mesh stiffness per unit face width (N/m²); ``nan`` when k0 was given directly.
    k0 : float
        Mean mesh stiffness (N/m).
    xi0 : float
        Mean mesh damping ratio ξ0 (non-dimensional).
    assumed : tuple of Assumption
        Every value not given by the user (or declared assumed by the user), with its source.
    """

    r1: float
    r2: float
    hand: str
    drive_side: str
    face_width: float
    c_gamma: float
    k0: float
    xi0: float
    assumed: tuple[Assumption, ...]


#: Units of the inputs of a :class:`~geardyn.geometry.SpiralBevelGearPair`, for the values a user declares assumed.
_UNITS = {
    "m_mn": "m",
    "beta_m": "rad",
    "alpha_n": "rad",
    "Sigma": "rad",
    "j_n": "m",
    "I1": "kg*m^2",
    "I2": "kg*m^2",
    "r1": "m",
    "r2": "m",
    "face_width": "m",
    "c_gamma": "N/m^2",
    "k0": "N/m",
    "c0": "N*s/m",
}
