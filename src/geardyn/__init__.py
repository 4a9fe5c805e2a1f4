"""geardyn: nonlinear dynamics of gear pairs with backlash.

The main entry points, importable from here:

* the non-dimensional model: :class:`GearModel`, :class:`IntegrationOptions`, :class:`ModelError`;
* the gear pair and its units: :class:`SpiralBevelGearPair`, :func:`load_config`,
  :class:`PhysicalScales`;
* analyses: :func:`simulate` (steady response), :func:`trajectory`, :func:`integrate_batch`,
  :func:`period_map`, :class:`PeriodMap`, :func:`lyapunov_spectrum`, :func:`bifurcation`,
  :func:`shoot`, :func:`continuation`;
* physical outputs: :func:`add_physical`, :func:`simulate_physical`;
* results on disk: :func:`read_netcdf`, :func:`write_netcdf`; every result Dataset has the
  ``ds.geardyn`` accessor (``ds.geardyn.plot()``).

Nothing heavy is imported with the package: the model (and NumPy with it), xarray, the numba
kernel, pint and matplotlib are imported on first use, so that ``geardyn --help`` imports none of them.  The ``ds.geardyn`` accessor is registered when xarray is
imported, by whoever imports it.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

__version__ = "0.1.0"

from ._accessor_hook import register_accessor as _register_accessor  # noqa: E402
from .errors import ModelError  # noqa: E402

_register_accessor()  # ds.geardyn: now if xarray is imported, else as soon as it is

#: Public names imported on first access: name -> module.
_LAZY = {
    "GearModel": ".model",
    "IntegrationOptions": ".model",
    "PAPER_DEFAULTS": ".model",
    "SpiralBevelGearPair": ".geometry",
    "MeshHarmonics": ".geometry",
    "load_config": ".config",
    "LoadedConfig": ".config",
    "PhysicalScales": ".units",
    "simulate": ".analysis.steady",
    "SteadyState": ".analysis.steady",
    "trajectory": ".integrate",
    "integrate_batch": ".integrate",
    "period_map": ".integrate",
    "lyapunov_spectrum": ".analysis.lyapunov",
    "bifurcation": ".analysis.bifurcation",
    "shoot": ".analysis.periodic",
    "continuation": ".analysis.periodic",
    "PeriodMap": ".analysis.periodic",
    "add_physical": ".analysis.physical",
    "simulate_physical": ".analysis.physical",
    "read_netcdf": ".io",
    "write_netcdf": ".io",
}

__all__ = ["ModelError", "__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'geardyn' has no attribute {name!r}")
    value = getattr(import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
