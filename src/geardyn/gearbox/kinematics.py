"""Exact kinematics of a gear train from its tooth counts.

Every speed is a :class:`fractions.Fraction` of the reference shaft's speed (the shaft of the reference
mesh's pinion): across a mesh the gear's shaft turns ``z_pinion/z_gear`` times as fast as the pinion's.
The frequency of mesh m is ``z_m n_m`` (its pinion's teeth times its pinion's speed); its ratio to the
reference mesh's frequency is the exact rational ``r_m = z_m n_m/(z_ref n_ref)``.  The forcing of all
meshes repeats after the least common period: ``p`` reference mesh cycles, the least common multiple of the
denominators of the r_m.  Shaft orders (a torque fluctuation at order k of a shaft's speed, frequency
``k n_s/(z_ref n_ref)`` of the reference mesh frequency) enter the same least common multiple.

A period beyond ``max_period`` reference mesh cycles is refused naming the period, unless the file asks to
round: each ratio is then replaced by the nearest fraction with the denominator ``max_period``.
"""

from __future__ import annotations

import math
from fractions import Fraction

from ..errors import ModelError

__all__ = ["solve_speeds", "forcing_period", "round_ratio"]

#: Default bound on the forcing period, in reference mesh cycles (the denominators a system's ratio may have).
DEFAULT_MAX_PERIOD = 1000


def solve_speeds(
    shafts: list[str],
    meshes: list[tuple[str, str, str, int, int]],
    reference_shaft: str,
    reference_sense: int = 1,
) -> tuple[dict[str, Fraction], dict[str, int]]:
    """Shaft speeds from the meshes ``(name, pinion shaft, gear shaft, z_pinion, z_gear)``.

    Parameters
    ----------
    shafts : list of str
        Names of all shafts; each must be reached from the reference shaft through the meshes.
    meshes : list of tuple
        ``(name, pinion shaft, gear shaft, z_pinion, z_gear)`` of each mesh.
    reference_shaft : str
        The shaft whose speed is 1.
    reference_sense : int
        Running sense of the reference shaft (+1 counterclockwise seen from +z, −1 clockwise); default +1.

    Returns
    -------
    speeds, senses : dict
        Each shaft's speed relative to the reference shaft (exact :class:`~fractions.Fraction`) and its
        running sense (±1, alternating across each mesh).

    Raises
    ------
    ModelError
        A shaft no mesh reaches, a mesh between gears of one shaft, or a loop whose tooth ratios disagree.
    """
    speeds: dict[str, Fraction] = {reference_shaft: Fraction(1)}
    senses: dict[str, int] = {reference_shaft: reference_sense}
    changed = True
    while changed:
        changed = False
        for name, sp, sg, zp, zg in meshes:
            if sp == sg:
                raise ModelError(f"mesh {name!r}: pinion and gear are on the same shaft {sp!r}")
            for a, b, za, zb in ((sp, sg, zp, zg), (sg, sp, zg, zp)):
                if a in speeds:
                    n = speeds[a] * Fraction(za, zb)
                    if b not in speeds:
                        speeds[b], senses[b] = n, -senses[a]
                        changed = True
                    elif speeds[b] != n or senses[b] != -senses[a]:
                        raise ModelError(
                            f"mesh {name!r}: the teeth give shaft {b!r} the speed {n} of the reference shaft, "
                            f"another path {speeds[b]}: the gear train is locked"
                        )
    missing = [s for s in shafts if s not in speeds]
    if missing:
        raise ModelError(f"shaft {missing[0]!r}: no mesh connects it to the reference shaft {reference_shaft!r}")
    return speeds, senses


def forcing_period(ratios) -> int:
    """The least common multiple of the denominators of the exact ratios (reference mesh cycles).

    Parameters
    ----------
    ratios : iterable of Fraction, int or str
        The exact frequency ratios to the reference mesh frequency (anything :class:`~fractions.Fraction`
        accepts).
    """
    return math.lcm(*(Fraction(r).denominator for r in ratios))


def round_ratio(r: Fraction, denominator: int) -> Fraction:
    """The nearest fraction with the given denominator (never 0).

    Parameters
    ----------
    r : Fraction
        The exact ratio (positive).
    denominator : int
        The denominator of the result (the ``max_period`` of rounding), >= 1.
    """
    q = Fraction(round(r * denominator), denominator)
    return q if q > 0 else Fraction(1, denominator)
