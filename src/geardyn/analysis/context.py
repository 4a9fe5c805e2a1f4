"""The brute-force context of a continuation: an up/down sweep of the same System over the same interval, in
continuation mode, drawn under the continued branches (what ``geardyn continuation --out`` draws and stores)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..model import DEFAULT_DTAU, DEFAULT_TRANSIENT, IntegrationOptions

__all__ = ["CONTEXT_NUM", "CONTEXT_PERIODS", "continuation_context"]

#: Points of the up/down sweep and its recorded periods.
CONTEXT_NUM = 101
CONTEXT_PERIODS = 32


def continuation_context(
    model: Any,
    param: str,
    start: float,
    stop: float,
    *,
    num: int = CONTEXT_NUM,
    dtau: float = DEFAULT_DTAU,
    transient: int = DEFAULT_TRANSIENT,
    state0: Sequence[float] | None = None,
    progress: bool | Callable[..., Any] = False,
) -> Any:
    """The up/down brute-force sweep of ``param`` from ``start`` to ``stop`` beside a continuation.

    Parameters
    ----------
    model : System
        The continued System.
    param : str
        The continuation parameter.
    start, stop : float
        Its interval (``stop`` may lie below ``start``).
    num : int
        Points of the sweep (:data:`CONTEXT_NUM`).
    dtau : float
        Target RK4 step.
    transient : int
        Forcing periods settled at each point; :data:`CONTEXT_PERIODS` are recorded.
    state0 : sequence of float, optional
        The initial state of the first point (default the System's rest state).
    progress : bool or callable
        Progress of the sweep (as :func:`geardyn.analysis.bifurcation.bifurcation`).

    Returns
    -------
    xarray.Dataset
        A bifurcation Dataset (``sweep`` = up, down).

    Examples
    --------
    >>> from geardyn import GearModel
    >>> from geardyn.analysis.context import continuation_context
    >>> ds = continuation_context(GearModel(), "omega", 0.6, 0.8, num=3, transient=50)
    >>> dict(ds.sizes)["omega"], ds["sweep"].values.tolist()
    (3, ['up', 'down'])
    """
    from .bifurcation import bifurcation, param_symbol, sweep_values

    given = {} if state0 is None else {"state0": state0}
    return bifurcation(
        model,
        param,
        sweep_values(start, stop, num),
        mode="continue",
        sweep="both",
        options=IntegrationOptions(dtau=dtau, transient=transient, periods=CONTEXT_PERIODS),
        progress=progress,
        description=f"up/down sweep {param_symbol(param)}",
        **given,
    )
