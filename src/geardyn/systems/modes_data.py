"""The ``modes`` Dataset: the report of :func:`~geardyn.systems.modes.modes_report` as a result that
``geardyn plot`` redraws (its Campbell figure is in :mod:`geardyn.plot.registry`).

Modes are numbered from 1 (coordinate ``mode``), as in the report's tables and JSON.  The Campbell
lines and crossings are variables along ``line`` and ``crossing``; the diagram's axis (pinion speed,
or the mesh frequency when the reference mesh gives no ``teeth``) is in the attributes
``campbell_x``, ``campbell_x_label`` and ``campbell_x_range``.  A system without a Campbell diagram
gives the modes alone.  A gearbox adds its shaft nodes along ``node``
(``node_shaft``, an index into the attribute ``shafts``, ``node_position``, ``node_radius``; their names in the
attribute ``nodes``) and each element's kind (``element_kind``), from which the figure of the deflection along
each shaft is drawn.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from ..io import KIND_VARIABLES, Variable, json_attr
from ..io import _v as _V

__all__ = ["MODES_VARIABLES", "modes_dataset"]

#: Metadata of the variables of a ``modes`` result (entered in :data:`geardyn.io.KIND_VARIABLES`).
MODES_VARIABLES: dict[str, Variable] = {
    "mode": _V("mode number (from 1, ascending frequency; rigid-body modes first)"),
    "dof": _V("degree of freedom (body.dof)"),
    "element": _V("stiffness element (connections, clearances, meshes)"),
    "frequency_Hz": _V("natural frequency (rigid-body modes 0)", "Hz"),
    "rigid": _V("rigid-body mode (1) or elastic (0)"),
    "mesh_dominated": _V("meshes hold more than half of the mode's strain energy (1)"),
    "shape": _V("M-orthonormal mode shape (SI coordinates: m and rad)"),
    "energy_fraction": _V("modal strain-energy fraction of the element"),
    "line": _V("index of the Campbell line"),
    "line_label": _V("mesh orders of the Campbell line", text=True),
    "line_harmonic": _V("line frequency as a multiple of the base mesh frequency (k r_m)"),
    "line_slope": _V("line frequency per unit of the Campbell axis (Hz per rpm, or per Hz)"),
    "crossing": _V("index of the crossing of a Campbell line with a natural frequency"),
    "crossing_x": _V("crossing on the Campbell axis (pinion speed in rpm, or mesh frequency in Hz)"),
    "crossing_frequency_Hz": _V("natural frequency of the crossing", "Hz"),
    "crossing_mode": _V("first mode number of the crossing"),
    "crossing_modes": _V("mode numbers of the crossing (a degenerate frequency lists several)", text=True),
    "crossing_line": _V("Campbell line of the crossing (index along line)"),
    "crossing_whirl": Variable(
        "1", "whirl of the crossing's mode (gyroscopic terms)", {-1: "backward", 0: "none", 1: "forward"}
    ),
    "speed": _V("reference shaft speed of the Campbell branches (gyroscopic terms)", "rpm"),
    "branch_frequency_Hz": _V("natural frequency of each mode at each speed (gyroscopic terms)", "Hz"),
    "branch_whirl": _V("whirl measure of each mode at each speed: +1 circular forward, -1 circular backward"),
    "node_shaft": _V("shaft of the node (index into the attribute 'shafts')"),
    "node_position": _V("position of the node along its shaft", "m"),
    "node_radius": _V("radius of the node: its gear's reference radius, else the shaft's outer radius", "m"),
    "element_kind": Variable(
        "1", "kind of the element (a gearbox)", {0: "other", 1: "shaft", 2: "bearing", 3: "coupling", 4: "mesh"}
    ),
}
KIND_VARIABLES.setdefault("modes", {}).update(MODES_VARIABLES)


def _col(dim: str, rows: list[dict[str, Any]], key: str, dtype: Any = float) -> tuple[str, np.ndarray]:
    """The variable over ``dim`` of entry ``key`` of each row."""
    return dim, np.array([r[key] for r in rows], dtype=dtype)


def modes_dataset(report: dict[str, Any]) -> xr.Dataset:
    """The ``modes`` Dataset of a modes report.

    Parameters
    ----------
    report : dict
        :func:`geardyn.systems.modes.modes_report`.

    Returns
    -------
    xarray.Dataset
        Kind ``modes``: ``frequency_Hz``, ``rigid``, ``mesh_dominated`` over ``mode``; ``shape`` over
        (``dof``, ``mode``); ``energy_fraction`` over (``mode``, ``element``); with a Campbell diagram
        ``line_*`` over ``line`` and ``crossing_*`` over ``crossing``.  The report is the ``summary``
        attribute (JSON).
    """
    from .. import __version__

    modes = report["modes"]
    dofs = list(report["dofs"])
    elements = list(report["energy_fractions"][0]) if report["energy_fractions"] else []
    n = len(modes)
    data: dict[str, Any] = {
        "frequency_Hz": _col("mode", modes, "frequency_hz"),
        "rigid": _col("mode", modes, "rigid", np.int8),
        "mesh_dominated": _col("mode", modes, "mesh_dominated", np.int8),
        "shape": (("dof", "mode"), np.array([[m["shape"][d] for m in modes] for d in dofs], dtype=float)),
        "energy_fraction": (
            ("mode", "element"),
            np.array([[e[k] for k in elements] for e in report["energy_fractions"]], dtype=float).reshape(
                n, len(elements)
            ),
        ),
    }
    coords: dict[str, Any] = {
        "mode": np.arange(1, n + 1),
        "dof": np.array(dofs, dtype=object),
        "element": np.array(elements, dtype=object),
    }
    attrs = {
        "geardyn_kind": "modes",
        "geardyn_version": __version__,
        "title": report.get("title") or "",
        "source": report.get("source") or "",
        "summary": json_attr(report),
    }
    gb = report.get("gearbox")
    if gb:  # a gearbox: its shaft nodes (names in the attributes), for the deflection along each shaft
        shafts = [s["name"] for s in gb["shafts"]]
        shaft_of, nodes = zip(*((k, n) for k, s in enumerate(gb["shafts"]) for n in s["nodes"]))
        data["node_shaft"] = ("node", np.array(shaft_of, dtype=np.int64))
        data["node_position"] = _col("node", nodes, "position_m")
        data["node_radius"] = _col("node", nodes, "radius_m")
        codes = {v: k for k, v in MODES_VARIABLES["element_kind"].flags.items()}
        kinds: dict[str, int] = {}
        for m in modes[:1]:
            for group, members in m.get("energy", {}).items():
                kinds.update({name: codes[{"meshes": "mesh"}.get(group, group[:-1])] for name in members})
        data["element_kind"] = ("element", np.array([kinds.get(e, 0) for e in elements], dtype=np.int8))
        attrs["shafts"] = json.dumps(shafts)
        attrs["nodes"] = json.dumps([n["name"] for n in nodes])
    camp = report.get("campbell")
    if camp:
        lines, cr = camp["lines"], camp["crossings"]
        coords["line"] = np.arange(len(lines))
        coords["crossing"] = np.arange(len(cr))
        data.update(
            {
                "line_label": _col("line", lines, "label", object),
                "line_harmonic": _col("line", lines, "harmonic"),
                "line_slope": _col("line", lines, "hz_per_x"),
                "crossing_x": _col("crossing", cr, "x"),
                "crossing_frequency_Hz": _col("crossing", cr, "frequency_hz"),
                "crossing_mode": _col("crossing", cr, "mode", np.int64),
                "crossing_modes": ("crossing", np.array([", ".join(map(str, c["modes"])) for c in cr], dtype=object)),
                "crossing_line": _col("crossing", cr, "line", np.int64),
            }
        )
        attrs.update(
            {
                "campbell_x": camp["x"],
                "campbell_x_label": camp["x_label"],
                "campbell_x_range": json.dumps(list(camp["x_range"])),
            }
        )
        if camp.get("teeth") is not None:
            attrs["teeth"] = int(camp["teeth"])
        br = camp.get("branches")
        if br:
            coords["speed"] = np.array(br["rpm"], dtype=float)
            data["branch_frequency_Hz"] = (("speed", "mode"), np.array(br["frequencies_hz"], dtype=float))
            data["branch_whirl"] = (("speed", "mode"), np.array(br["whirl"], dtype=float))
            codes = {"backward": -1, "none": 0, "forward": 1}
            data["crossing_whirl"] = ("crossing", np.array([codes[c["whirl"]] for c in cr], dtype=np.int8))
    if report.get("campbell_note"):
        attrs["campbell_note"] = report["campbell_note"]
    return xr.Dataset(data, coords=coords, attrs=attrs)
