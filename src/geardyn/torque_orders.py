"""Torque orders: constant-amplitude harmonics of the load at orders of a shaft's speed.

An engine's torque fluctuates at orders of its crankshaft speed (a four-cylinder four-stroke engine's firing
order is 2); the fluctuation keeps its amplitude in N·m whatever the speed.  In the non-dimensional pair
(:class:`geardyn.model.GearModel`) an order is a term of the forcing::

    u'' + … = f_p + ω² Σ l² ε_l cos(lθ + φ_el) + Σ_o a_o cos(q_o θ + φ_o),      θ = ω τ the mesh phase,

with q_o the order's frequency in mesh orders (a positive rational) and a_o its amplitude, non-dimensional
like f_p.  Order k of the pinion's speed is q = k/z1 (the mesh frequency is z1 times the pinion's speed), so
the forcing repeats after z1/gcd(k, z1) mesh periods: the model's forcing period becomes the least common
multiple of its own (``cycles``) and every order's denominator (:func:`period_multiple`).

A pinion torque fluctuation ΔT of a physical pair enters as the force of a torque on the pinion alone
(the gear's torque steady): ``F = m_e R1 ΔT / I1``, the relative acceleration R1 ΔT/I1 of the pinion's
mesh point times the equivalent mass (:meth:`geardyn.geometry.SpiralBevelGearPair.fp_from_torques` with
T2 = 0), made non-dimensional like f_p.

This module holds the grammar of an order (:func:`order_fraction`), the parsing of the model's tuples and of the
command line's ``ORDER:AMPLITUDE[:PHASE]``, and the arithmetic of the period; the ``{order, amplitude, phase}``
tables of a configuration or a system file are read, with their units, by the one reader of file values
(:mod:`geardyn._config_values`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

from .errors import ModelError

__all__ = [
    "MAX_ORDER_PERIOD",
    "TorqueOrder",
    "normalise",
    "order_fraction",
    "parse_cli",
    "period_multiple",
    "to_dicts",
]

#: Largest forcing period (mesh cycles) the torque orders of a pair may make: the kernels sum the series of
#: every harmonic of the forcing frequency up to the highest order's, so a longer period costs as many terms.
MAX_ORDER_PERIOD = 1024
#: Largest denominator of an order written as a decimal number (0.5 is 1/2).
MAX_ORDER_DENOMINATOR = 10_000

#: One order: (frequency in mesh orders q, amplitude (non-dimensional), phase (rad)).
TorqueOrder = tuple[Fraction, float, float]


def order_fraction(value: Any, name: str = "torque_orders.order") -> Fraction:
    """A positive order as an exact fraction: an integer, a decimal number or a text ``"a/b"``.

    Parameters
    ----------
    value : int, float, Fraction or str
        The order.
    name : str
        The key named in a message.

    Returns
    -------
    Fraction

    Raises
    ------
    ModelError
        For anything else, zero, a negative or non-finite order.
    """
    try:
        if isinstance(value, bool):
            raise TypeError  # (true and false are no orders)
        if isinstance(value, Fraction):
            q = value
        elif isinstance(value, int):
            q = Fraction(value)
        elif isinstance(value, float):
            if not math.isfinite(value):
                raise ValueError
            q = Fraction(value).limit_denominator(MAX_ORDER_DENOMINATOR)
            if float(q) != value:
                q = Fraction(repr(value))
        elif isinstance(value, str):
            q = Fraction(value.strip().replace(" ", ""))
        else:
            q = Fraction(float(value)).limit_denominator(MAX_ORDER_DENOMINATOR)
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        raise ModelError(f"{name}: expected a positive number or a fraction 'a/b', got {value!r}") from None
    if q <= 0:
        raise ModelError(f"{name}: must be > 0, got {value!r}")
    return q


def _finite(name: str, value: Any) -> float:
    try:
        if isinstance(value, bool):
            raise TypeError  # (true and false are no numbers here)
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{name}: expected a finite number, got {value!r}") from None
    if not math.isfinite(x):
        raise ModelError(f"{name}: must be a finite number, got {value!r}")
    return x


def normalise(orders: Any) -> tuple[TorqueOrder, ...]:
    """The model's torque orders as (Fraction, amplitude, phase) tuples, validated.

    Each entry is a sequence ``(order, amplitude[, phase])`` or a mapping with the keys ``order``,
    ``amplitude`` and optionally ``phase`` (rad), the order in mesh orders.  Two entries of the same order
    are refused (write one amplitude and phase).

    Parameters
    ----------
    orders : iterable or None
        The entries.

    Returns
    -------
    tuple of (Fraction, float, float)

    Raises
    ------
    ModelError
        For an entry of another form, a bad order, amplitude or phase, or an order given twice.
    """
    if orders is None:
        return ()
    if isinstance(orders, (str, bytes)) or not hasattr(orders, "__iter__"):
        raise ModelError(f"torque_orders: expected a list of (order, amplitude, phase), got {orders!r}")
    out: list[TorqueOrder] = []
    for i, entry in enumerate(orders):
        who = f"torque_orders[{i}]"
        if isinstance(entry, dict):
            if not {"order", "amplitude"} <= set(entry) <= {"order", "amplitude", "phase"}:
                raise ModelError(f"{who}: keys order, amplitude and optionally phase, got {sorted(entry)}")
            q, a, p = entry["order"], entry["amplitude"], entry.get("phase", 0.0)
        else:
            try:
                items = tuple(entry)
            except TypeError:
                raise ModelError(f"{who}: expected (order, amplitude[, phase]), got {entry!r}") from None
            if len(items) not in (2, 3):
                raise ModelError(f"{who}: expected (order, amplitude[, phase]), got {entry!r}")
            q, a, p = items[0], items[1], items[2] if len(items) == 3 else 0.0
        out.append((order_fraction(q, f"{who}.order"), _finite(f"{who}.amplitude", a), _finite(f"{who}.phase", p)))
    seen = [q for q, _, _ in out]
    for q in seen:
        if seen.count(q) > 1:
            raise ModelError(f"torque_orders: order {q} given twice; give one amplitude and phase per order")
    return tuple(out)


def period_multiple(orders: tuple[TorqueOrder, ...], cycles: int = 1) -> int:
    """Mesh cycles of the forcing period: the least common multiple of ``cycles`` and the orders' denominators.

    Parameters
    ----------
    orders : tuple of (Fraction, float, float)
        Normalised orders (:func:`normalise`).
    cycles : int
        The model's own period in mesh cycles.

    Returns
    -------
    int

    Raises
    ------
    ModelError
        When it exceeds :data:`MAX_ORDER_PERIOD` (naming the order that makes it so).
    """
    M = int(cycles)
    for q, _, _ in orders:
        M = math.lcm(M, q.denominator)
        if M > MAX_ORDER_PERIOD:
            raise ModelError(
                f"torque_orders: order {q} of the mesh frequency makes the forcing period {M} mesh cycles, "
                f"more than {MAX_ORDER_PERIOD}"
            )
    return M


def to_dicts(orders: tuple[TorqueOrder, ...]) -> list[dict[str, Any]]:
    """JSON form: ``order`` an integer or a text ``"a/b"``, ``amplitude``, ``phase`` (rad).

    Parameters
    ----------
    orders : tuple of (Fraction, float, float)
        Normalised orders.

    Returns
    -------
    list of dict
    """
    return [
        {"order": int(q) if q.denominator == 1 else f"{q.numerator}/{q.denominator}", "amplitude": a, "phase": p}
        for q, a, p in orders
    ]


def parse_cli(text: str) -> tuple[Fraction, float, float]:
    """``ORDER:AMPLITUDE[:PHASE]`` of ``--torque-order`` (PHASE in rad, default 0).

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    (Fraction, float, float)

    Raises
    ------
    ModelError
        For a text of another form, naming the option.
    """
    parts = str(text).split(":")
    if len(parts) not in (2, 3):
        raise ModelError(f"--torque-order: expected ORDER:AMPLITUDE[:PHASE], got {text!r}")
    q = order_fraction(parts[0], "--torque-order ORDER")
    a = _finite("--torque-order AMPLITUDE", parts[1])
    p = _finite("--torque-order PHASE", parts[2]) if len(parts) == 3 else 0.0
    return q, a, p
