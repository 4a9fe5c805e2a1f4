"""One status for every result: a point of a sweep, an orbit, a harmonic-balance solution.

Stored in Datasets as its integer value (variable ``status``, with ``flag_values``/``flag_meanings``
from :func:`flag_attrs`), shown to people as its label and its message (what it means and what to try).
"""

from __future__ import annotations

from enum import IntEnum

__all__ = ["Status", "flag_attrs"]


class Status(IntEnum):
    """Outcome of one computation.

    ``OK`` (0) and ``DIVERGED`` (1) are the values the kernel writes per point (unchanged since the first
    release, so stored files keep their meaning); the others come from iterative solvers.
    """

    OK = 0
    DIVERGED = 1
    NOT_CONVERGED = 2
    UNRESOLVED = 3

    @property
    def label(self) -> str:
        """Short name (``"ok"``, ``"diverged"``, ``"not converged"``, ``"unresolved"``)."""
        return _LABELS[self]

    @property
    def message(self) -> str:
        """What the status means and what to try."""
        return _MESSAGES[self]

    @property
    def ok(self) -> bool:
        return self is Status.OK

    @classmethod
    def parse(cls, value: Status | int | str) -> Status:
        """The status of an integer code, a label or a member (``"converged"`` is read as ``OK``)."""
        if isinstance(value, cls):
            return value
        if isinstance(value, str):
            key = value.strip().lower()
            if key == "converged":
                return cls.OK
            for s, lab in _LABELS.items():
                if lab == key:
                    return s
            raise ValueError(f"status: unknown label {value!r}; allowed: {', '.join(_LABELS.values())}")
        return cls(int(value))


_LABELS = {
    Status.OK: "ok",
    Status.DIVERGED: "diverged",
    Status.NOT_CONVERGED: "not converged",
    Status.UNRESOLVED: "unresolved",
}

_MESSAGES = {
    Status.OK: "computed",
    Status.DIVERGED: "the response grew without bound or became non-finite; the point has no attractor "
    "from this initial state (check damping and load, or try another initial state)",
    Status.NOT_CONVERGED: "the iteration did not meet its tolerance; try another initial guess, a smaller "
    "continuation step or more iterations",
    Status.UNRESOLVED: "the solver converged but could not resolve the quantity asked for (e.g. Floquet "
    "multipliers from too few harmonics); raise the resolution",
}


def flag_attrs() -> dict[str, object]:
    """CF-style attributes of a ``status`` variable: ``flag_values`` and ``flag_meanings``."""
    return {
        "flag_values": [int(s) for s in Status],
        "flag_meanings": " ".join(_LABELS[s].replace(" ", "_") for s in Status),
    }
