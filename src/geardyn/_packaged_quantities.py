"""The quantities of the packaged configuration (``data/*.toml``) as pint reads them, to read that file without pint.

Importing pint and building its unit registry costs about 0.3 s, more than a short command's own
work; every command reads the packaged gear pair when no ``--config`` is given.  This table holds,
for each "number unit" string of the packaged files and the kind it is read as, the value that
pint's parse gives in the kind's unit (:func:`geardyn._config_values._parse_scalar`), so the
packaged pair is read without importing pint; any other string goes through pint.
``tests/test_config.py`` parses every entry with pint and checks the bits, and checks that the
packaged files need nothing else.
"""

from __future__ import annotations

__all__ = ["PACKAGED_QUANTITIES"]

#: (kind label, text) -> value in the kind's unit, as pint gives it.
PACKAGED_QUANTITIES: dict[tuple[str, str], float] = {
    ("length", "7.28 mm"): 0.00728,
    ("angle", "35 deg"): 0.6108652381980153,
    ("angle", "20 deg"): 0.3490658503988659,
    ("angle", "90 deg"): 1.5707963267948966,
    ("length", "0.1 mm"): 0.0001,
    ("moment of inertia", "1.772 kg*m^2"): 1.772,
    ("moment of inertia", "1.873 kg*m^2"): 1.873,
    ("length", "125.5 mm"): 0.1255,
    ("length", "256 mm"): 0.256,
    ("length", "100 mm"): 0.1,
    ("stiffness per unit face width", "20 N/(mm*um)"): 20000000000.0,
    ("phase (angle, or a number in rad)", "0 deg"): 0.0,
    ("rotational speed", "3000 rpm"): 3000.0,
}
