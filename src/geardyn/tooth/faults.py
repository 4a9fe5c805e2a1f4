"""Tooth faults and profile modifications as data.

Every fault names its gear (0 pinion, 1 wheel) and its tooth (0 … z − 1); any number of faults on any
teeth of either gear may be given at once.  Positions on a tooth's flank are fractions of its active
profile, 0 at the lowest point of contact (start of active profile) and 1 at the tip.  How each
enters the mesh (:mod:`geardyn.tooth.mesh`):

* :class:`Crack` — reduces the sections of the cracked tooth (:mod:`geardyn.tooth.energy`, Wu, Zuo
  & Parey 2008; Chen & Shao 2011) over the slices of the face it covers;
* :class:`Spall` — a rectangular pit of the given depth: the contact inside it (profile interval ×
  face interval) separates by that depth, so a deep spall takes those slices out of contact (as the
  loss of contact length of Chaari, Baccar, Abbes & Haddar 2008, Eur. J. Mech. A 27, 691-705);
* :class:`Wear` — material removed from the flank, a profile deviation of the given depth, uniform
  or proportional to the sliding distance, |s − s_C| (zero at the pitch point C, largest at the
  ends of the path; Archard's law at uniform pressure, as in Flodin & Andersson 1997);
* :class:`Broken` — the tooth broken off above a fraction of its active profile (0: missing tooth);
  no contact above it.

Profile modifications (:class:`Modifications`) are separations along the line of action before load:
tip and root relief of each gear, linear or parabolic over a given length of the path of contact
(ISO 21771:2007, 7.4; Velex & Maatar 1996), and a parabolic lead crowning C_β (4 C_β (y/b − ½)²).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from ..errors import ModelError
from ..model import _whole_number

__all__ = ["Broken", "Crack", "FAULT_KINDS", "Modifications", "Spall", "Wear", "fault_from_dict"]


def _check_tooth(kind: str, gear: int, tooth: int | None) -> None:
    if gear not in (0, 1):
        raise ModelError(f"{kind}: gear must be 0 (pinion) or 1 (wheel), got {gear!r}")
    if tooth is not None and not _whole_number(tooth, 0):
        raise ModelError(f"{kind}: tooth must be a whole number >= 0, got {tooth!r}")


def _fraction(kind: str, name: str, v: float, lo: float = 0.0, hi: float = 1.0) -> None:
    if not (lo <= v <= hi):
        raise ModelError(f"{kind}: {name} must lie in [{lo:g}, {hi:g}], got {v!r}")


@dataclass(frozen=True)
class Crack:
    """A straight root crack.

    Attributes
    ----------
    gear, tooth : int
        Where it is.
    depth : float
        Crack level: the fraction of the root half thickness the crack has cut (1 reaches the centre
        line); the crack tip lies at h_q = (1 − depth) h_root from the centre line, the crack length
        along its path is q = depth h_root / sin ν.
    angle_deg : float
        Angle ν of the crack path to the centre line (enters only the reported length q).
    length : float
        Fraction of the face width the crack runs across, from the face y = 0 (1: through).
    """

    gear: int
    tooth: int
    depth: float
    angle_deg: float = 45.0
    length: float = 1.0

    def __post_init__(self) -> None:
        _check_tooth("crack", self.gear, self.tooth)
        _fraction("crack", "depth", self.depth, 0.0, 0.95)
        _fraction("crack", "length", self.length)
        _fraction("crack", "angle_deg", self.angle_deg, 1.0, 89.0)


@dataclass(frozen=True)
class Spall:
    """A rectangular spall (pit) on a flank.

    Attributes
    ----------
    gear, tooth : int
        Where it is.
    at : float
        Centre of the spall along the active profile (fraction, 0 root … 1 tip).
    length : float
        Its extent along the profile, as a length of the path of contact (m).
    width : float
        Its extent across the face (m).
    depth : float
        Its depth (m).
    y0 : float
        Where it starts across the face (fraction of b; the spall spans [y0 b, y0 b + width]).
    """

    gear: int
    tooth: int
    at: float
    length: float
    width: float
    depth: float = 50e-6
    y0: float = 0.0

    def __post_init__(self) -> None:
        _check_tooth("spall", self.gear, self.tooth)
        _fraction("spall", "at", self.at)
        _fraction("spall", "y0", self.y0)
        for name in ("length", "width", "depth"):
            if not getattr(self, name) >= 0:
                raise ModelError(f"spall: {name} must be >= 0 (m), got {getattr(self, name)!r}")

    @property
    def empty(self) -> bool:
        """A spall of zero length, width or depth: the healthy flank."""
        return self.length == 0 or self.width == 0 or self.depth == 0


@dataclass(frozen=True)
class Wear:
    """Flank wear: ``depth`` (m) removed, ``"uniform"`` or ``"sliding"`` (∝ sliding distance).

    Attributes
    ----------
    gear : int
        0 pinion, 1 wheel.
    depth : float
        Largest depth removed (m).
    kind : str
        ``uniform`` or ``sliding``.
    tooth : int or None
        The tooth; None: every tooth of the gear.

    ``tooth = None`` wears every tooth of the gear.
    """

    gear: int
    depth: float
    kind: str = "uniform"
    tooth: int | None = None

    def __post_init__(self) -> None:
        _check_tooth("wear", self.gear, self.tooth)
        if self.kind not in ("uniform", "sliding"):
            raise ModelError(f"wear: kind must be 'uniform' or 'sliding', got {self.kind!r}")
        if not self.depth >= 0:
            raise ModelError(f"wear: depth must be >= 0 (m), got {self.depth!r}")


@dataclass(frozen=True)
class Broken:
    """A tooth broken off above ``remaining`` of its active profile (0: the tooth is missing).

    Attributes
    ----------
    gear, tooth : int
        Where it is.
    remaining : float
        Share of the active profile left (0: the tooth is missing).
    """

    gear: int
    tooth: int
    remaining: float = 0.0

    def __post_init__(self) -> None:
        _check_tooth("broken", self.gear, self.tooth)
        _fraction("broken", "remaining", self.remaining)


#: Fault classes by the ``kind`` of their dict form.
FAULT_KINDS = {"crack": Crack, "spall": Spall, "wear": Wear, "broken": Broken}


def fault_from_dict(d: dict[str, Any]) -> Any:
    """A fault from ``{"kind": "crack", "gear": 0, "tooth": 3, "depth": 0.5, ...}`` (TOML/JSON form).

    Parameters
    ----------
    d : dict
        ``kind`` and the fault's fields.

    Returns
    -------
    Crack, Spall, Wear or Broken
    """
    d = dict(d)
    kind = d.pop("kind", None)
    if not isinstance(kind, str) or kind not in FAULT_KINDS:
        raise ModelError(f"fault: kind must be one of {', '.join(FAULT_KINDS)}, got {kind!r}")
    try:
        return FAULT_KINDS[kind](**d)
    except TypeError as exc:
        raise ModelError(f"fault ({kind}): {exc}") from None


def fault_to_dict(f: Any) -> dict[str, Any]:
    """The dict form of a fault (inverse of :func:`fault_from_dict`)."""
    kind = next(k for k, c in FAULT_KINDS.items() if isinstance(f, c))
    return {"kind": kind, **asdict(f)}


@dataclass(frozen=True)
class Modifications:
    """Profile and lead modifications (m), as separations along the line of action.

    Attributes
    ----------
    tip_relief, tip_length : tuple of float
        Tip relief C_a of pinion and wheel and the length of the path of contact it spans from
        each gear's tip end of the path.
    root_relief, root_length : tuple of float
        Root relief C_f and its length from each gear's root end of the path.
    shape : str
        ``"linear"`` or ``"parabolic"`` (relief ∝ (distance into the zone / length)^1 or ^2).
    crowning : float
        Lead crowning C_β: separation 4 C_β (y/b − ½)² across the face.
    """

    tip_relief: tuple[float, float] = (0.0, 0.0)
    tip_length: tuple[float, float] = (0.0, 0.0)
    root_relief: tuple[float, float] = (0.0, 0.0)
    root_length: tuple[float, float] = (0.0, 0.0)
    shape: str = "linear"
    crowning: float = 0.0

    def __post_init__(self) -> None:
        if self.shape not in ("linear", "parabolic"):
            raise ModelError(f"modifications: shape must be 'linear' or 'parabolic', got {self.shape!r}")
        for name in ("tip_relief", "tip_length", "root_relief", "root_length"):
            v = tuple(map(float, getattr(self, name)))
            if len(v) != 2 or min(v) < 0:
                raise ModelError(f"modifications: {name} takes two values >= 0 (pinion, wheel), got {v!r}")
            object.__setattr__(self, name, v)
        for c, l, what in ((self.tip_relief, self.tip_length, "tip"), (self.root_relief, self.root_length, "root")):
            for g in (0, 1):
                if c[g] > 0 and l[g] <= 0:
                    raise ModelError(f"modifications: {what} relief of gear {g} needs a length > 0")
        if self.crowning < 0:
            raise ModelError(f"modifications: crowning must be >= 0, got {self.crowning!r}")

    @property
    def exponent(self) -> int:
        return 1 if self.shape == "linear" else 2
