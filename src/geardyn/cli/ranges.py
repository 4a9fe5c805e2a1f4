"""The two spellings of a sweep range every sweep command accepts: ``--param P --start a --stop b`` and
``--omega-start a --omega-stop b`` (a sweep over ω)."""

from __future__ import annotations

from typing import Any

from ..errors import ModelError
from .options import option

__all__ = ["OMEGA_RANGE", "both_spellings", "given_range"]

#: The other spelling of a sweep over ω, accepted by the commands that take --param/--start/--stop.
OMEGA_RANGE = [
    option("omega_start", float | None, help="First ω (as --param omega --start)."),
    option("omega_stop", float | None, help="Last ω (as --param omega --stop)."),
]


def both_spellings(
    param: str | None,
    start: float | None,
    stop: float | None,
    omega_start: float | None,
    omega_stop: float | None,
    only: str | None = None,
) -> tuple[str | None, float | None, float | None]:
    """One sweep range from either spelling every sweep command accepts: ``--param P --start a --stop b`` or
    ``--omega-start a --omega-stop b`` (= ``--param omega``).

    Parameters
    ----------
    param, start, stop : optional
        The ``--param/--start/--stop`` spelling.
    omega_start, omega_stop : float, optional
        The ``--omega-start/--omega-stop`` spelling.
    only : str, optional
        The one parameter the command sweeps (``"omega"`` for ``response``), if any.

    Returns
    -------
    (param, start, stop)
        ``param`` None when neither names it.

    Raises
    ------
    ModelError
        For both spellings at once, or another parameter than ``only``.
    """
    given_w = omega_start is not None or omega_stop is not None
    if given_w and (start is not None or stop is not None):
        raise ModelError("omega_start: give the range as --omega-start/--omega-stop or as --start/--stop, not both")
    if given_w:
        if param is not None and param != "omega":
            raise ModelError(f"param: --omega-start/--omega-stop sweep omega, not {param!r}")
        return "omega", omega_start, omega_stop
    if only is not None and param is not None:
        from ..params import canonical_param

        if canonical_param(param) != only:
            raise ModelError(f"param: this command sweeps {only} only, got {param!r}")
    return param, start, stop


def given_range(inp: Any, only: str | None = None) -> tuple[str | None, float | None, float | None]:
    """:func:`both_spellings` of a command's inputs.

    Parameters
    ----------
    inp : geardyn.cli.options.Inputs
        The command's inputs (``--param/--start/--stop`` and ``--omega-start/--omega-stop``).
    only : str, optional
        The one parameter the command sweeps or ramps (``"omega"`` for ``response`` and ``runup``), if any.

    Returns
    -------
    tuple
        The parameter's name (None when neither spelling names it), its start and its stop.
    """
    v = inp.values
    return both_spellings(v.get("param"), v.get("start"), v.get("stop"), inp.omega_start, inp.omega_stop, only)
