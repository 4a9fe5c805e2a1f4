"""geardyn: nonlinear dynamics of gear pairs and gear systems with backlash.

The public API is :data:`__all__`; every callable in it has a numpydoc ``Examples`` section that runs as a
doctest (``tests/test_doctests.py``).  Everything else is private by convention.

* the models and their contract: :class:`System` (what every analysis is written against),
  :class:`GearModel` (the paper's 1-DOF pair), :class:`SystemModel` and :func:`load_system` (multi-DOF
  systems from a TOML file), :class:`IntegrationOptions`, :class:`ModelError`, :data:`PAPER_DEFAULTS`;
* the gear pair and its units: :class:`SpiralBevelGearPair`, :class:`MeshHarmonics`, :func:`load_config`,
  :class:`LoadedConfig`, :class:`PhysicalScales`;
* parameter points: :class:`Grid`;
* integration: :func:`trajectory`, :func:`integrate_batch`, :func:`period_map`;
* analyses, for any System: :func:`simulate` (:class:`SteadyState`), :func:`lyapunov_spectrum`,
  :func:`bifurcation`, :func:`frequency_response`, :func:`parameter_map`, :func:`basins`, :func:`shoot`,
  :func:`continuation`, :class:`PeriodMap`, :func:`hb_solve`, :func:`hb_continuation`, :func:`runup`;
* physical outputs: :func:`add_physical`, :func:`simulate_physical`;
* results on disk: :func:`read_netcdf`, :func:`write_netcdf`; every result Dataset has the ``ds.geardyn``
  accessor (``ds.geardyn.plot()``).

Nothing heavy is imported with the package: each public name is imported on first use (and NumPy, xarray,
the numba kernels, pint and matplotlib with it), so that ``geardyn --help`` imports none of them.  The
``ds.geardyn`` accessor is registered when xarray is imported, by whoever imports it.
"""

from __future__ import annotations

from importlib import import_module as _import_module

from ._accessor_hook import register_accessor as _register_accessor

__version__ = "0.1.0"

_register_accessor()  # ds.geardyn: now if xarray is imported, else as soon as it is

#: Public names imported on first access: name -> module.
_LAZY = {
    # the models and their contract
    "System": ".system",
    "GearModel": ".model",
    "SystemModel": ".systems",
    "load_system": ".systems",
    "IntegrationOptions": ".model",
    "PAPER_DEFAULTS": ".model",
    "ModelError": ".errors",
    # the gear pair and its units
    "SpiralBevelGearPair": ".geometry",
    "MeshHarmonics": ".geometry",
    "load_config": ".config",
    "LoadedConfig": ".config",
    "PhysicalScales": ".units",
    # parameter points and integration
    "Grid": ".grid",
    "trajectory": ".integrate",
    "integrate_batch": ".integrate",
    "period_map": ".integrate",
    # analyses
    "simulate": ".analysis.steady",
    "SteadyState": ".analysis.steady",
    "lyapunov_spectrum": ".analysis.lyapunov",
    "bifurcation": ".analysis.bifurcation",
    "frequency_response": ".analysis.response",
    "parameter_map": ".analysis.maps",
    "basins": ".analysis.basins",
    "shoot": ".analysis.periodic",
    "continuation": ".analysis.periodic",
    "PeriodMap": ".analysis.periodic",
    "hb_solve": ".analysis.hb",
    "hb_continuation": ".analysis.hb",
    "runup": ".analysis.runup",
    # physical outputs and results on disk
    "add_physical": ".analysis.physical",
    "simulate_physical": ".analysis.physical",
    "read_netcdf": ".io",
    "write_netcdf": ".io",
}

__all__ = ["__version__", *_LAZY]


#: Public functions whose first argument is a System (``integrate_batch``: a sequence of them): anything else
#: is refused with a ModelError naming ``model`` (:func:`geardyn.plausible.system`), not an AttributeError.
_TAKE_A_SYSTEM = (
    "trajectory",
    "period_map",
    "simulate",
    "lyapunov_spectrum",
    "bifurcation",
    "frequency_response",
    "parameter_map",
    "basins",
    "shoot",
    "continuation",
    "hb_solve",
    "hb_continuation",
    "runup",
    "integrate_batch",
)


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        if not name.startswith("__"):  # a subpackage or module, as ``import geardyn.name`` would give it
            try:
                return _import_module(f".{name}", __name__)
            except ModuleNotFoundError as e:
                if e.name != f"{__name__}.{name}":
                    raise
        raise AttributeError(f"module 'geardyn' has no attribute {name!r}")
    value = getattr(_import_module(module, __name__), name)
    if name in _TAKE_A_SYSTEM:
        from .plausible import taking_a_system

        value = taking_a_system(value, many=name == "integrate_batch")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
