"""Small shared pieces of the standards modules: an assumed-input record and argument checks."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from ..errors import ModelError

__all__ = ["AssumedInput"]


@dataclass(frozen=True)
class AssumedInput:
    """An input the caller did not give, the value used for it and where that value comes from.

    Parameters
    ----------
    name : str
        Input name, as in the function signature that applied the default.
    value : float or str
        The value used, in ``unit``.
    unit : str
        Unit of ``value`` ("" for words and pure numbers).
    source : str
        Where the value comes from (clause of the standard, usual design value, ...).
    """

    name: str
    value: float | str
    unit: str
    source: str

    def to_dict(self) -> dict[str, Any]:
        """Return the record as a plain dict (for JSON)."""
        return {"name": self.name, "value": self.value, "unit": self.unit, "source": self.source}


def defaults(assumed: list[AssumedInput]) -> Any:
    """``default(name, value, given, unit, source)``: ``given``, or when it is None ``value``, recorded in ``assumed``.

    Parameters
    ----------
    assumed : list of AssumedInput
        Where the defaults applied are recorded.
    """

    def default(name: str, value: Any, given: Any, unit: str, source: str) -> Any:
        if given is None:
            assumed.append(AssumedInput(name, value, unit, source))
            return value
        return given

    return default


def check_positive(name: str, value: Any, unit: str = "") -> float:
    """Return ``value`` as a float, or raise :class:`ModelError` unless it is finite and > 0.

    Parameters
    ----------
    name : str
        Input name for the message.
    value : object
        The given value.
    unit : str
        Its unit, shown in the message.
    """
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(x) or x <= 0.0:
        raise ModelError(f"{name}: must be a finite number > 0{(' ' + unit) if unit else ''}, got {value!r}")
    return x


def check_angle(name: str, value: Any, lo_deg: float, hi_deg: float) -> float:
    """Return an angle in radians, or raise :class:`ModelError` unless lo_deg <= angle < hi_deg.

    Parameters
    ----------
    name : str
        Input name for the message.
    value : object
        The given angle in rad.
    lo_deg, hi_deg : float
        The allowed range in degrees (upper bound excluded).
    """
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{name}: expected an angle in rad, got {value!r}") from None
    d = math.degrees(x) if math.isfinite(x) else float("nan")
    if not (lo_deg <= d < hi_deg):
        raise ModelError(f"{name}: must be in [{lo_deg:g}, {hi_deg:g}) deg, got {value!r} rad")
    return x


def from_fields(cls: type, values: Any) -> Any:
    """The dataclass ``cls`` from the entries of ``values`` named as its fields (the locals of the function that
    computed them)."""
    return cls(**{f.name: values[f.name] for f in fields(cls)})
