"""Opening a system file: a system of bodies (:mod:`geardyn.systems.load`) or a gearbox from its geometry
(:mod:`geardyn.gearbox.build`, a file with ``[[shaft]]`` tables), read once and assembled.

Both readers share :mod:`geardyn.systems.load`'s tables and checks; this module is the one door above them, so
that neither imports the other's entry point.
"""

from __future__ import annotations

from pathlib import Path

from .._config_values import parse_toml, read_toml
from ..errors import ConfigError, GeardynError, ModelError
from .assemble import SystemModel, assemble
from .description import SystemDescription
from .load import _Ctx, build

__all__ = ["load_description", "load_system"]


def load_description(path: str | Path) -> SystemDescription:
    """Read and check a system file.

    Parameters
    ----------
    path : str or Path
        The TOML file (format: the module docstring).

    Returns
    -------
    SystemDescription

    Raises
    ------
    ConfigError
        Missing or unreadable file, TOML syntax, unknown sections or keys, wrong types or units.
    ModelError
        Bad values: non-positive masses, unknown bodies, singular mass matrices, unconnected bodies.
    """
    source, text = read_toml(path, "system file")
    ctx = _Ctx(source, text)
    data = parse_toml(text, source)
    try:
        if isinstance(data, dict) and "shaft" in data:  # a gearbox from its geometry: geardyn.gearbox.build
            from ..gearbox.build import build_description

            return build_description(ctx, data)
        return build(ctx, data)
    except GeardynError:
        raise
    except (TypeError, KeyError, AttributeError, IndexError) as e:  # malformed structure the checks missed
        raise ConfigError(f"{source}: malformed system file ({type(e).__name__}: {e})") from None


def load_system(path: str | Path, omega: float | None = None) -> SystemModel:
    """Read a system file and assemble its non-dimensional :class:`SystemModel`.

    Parameters
    ----------
    path : str or Path
        The TOML file.
    omega : float, optional
        Base frequency ω (default: the file's operating point, else 1).

    Raises
    ------
    ConfigError, ModelError
        As :func:`load_description`.

    Examples
    --------
    >>> from geardyn import load_system
    >>> system = load_system("examples/systems/paper_torsional.toml", omega=0.8)
    >>> system.omega, system.state_dim, [e.name for e in system.elements]
    (0.8, 4, ['mesh'])
    """
    desc = load_description(path)
    try:
        return assemble(desc, omega)
    except ModelError as e:
        raise ModelError(f"{desc.source}: {e}") from None
