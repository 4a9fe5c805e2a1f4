"""What an axis label adds to a variable's name: the unit b_c of the model's displacements, subscripts."""

from __future__ import annotations

import re

__all__ = ["IN_B_C", "subscripts"]


#: Non-dimensional displacements (u = u_n / b_c): their axes carry the unit b_c.
IN_B_C = tuple(
    (
        "u poincare_u amplitude rms mean u_min u_max amplitude_up "
        "amplitude_down delta element_u_min element_u_max element_mean element_rms"
    ).split()
)
_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def subscripts(text: str) -> str:
    """``ξ_1`` → ``ξ₁``: an index written after an underscore as subscript digits (a figure shows no literal
    underscore).

    Parameters
    ----------
    text : str
        A label.

    Returns
    -------
    str
    """
    return re.sub(r"_\{?(\d+)\}?", lambda m: m.group(1).translate(_SUB), text)
