"""Which mesh a figure of a system shows: its labels name the reference mesh.

A system's result stores the values of its reference mesh under the pair's names (``u``, ``amplitude``,
``omega`` …); its ``system`` attribute says which mesh that is.  Every plot function draws from a copy of
the result whose reference-mesh variables have long names naming the mesh (:func:`mesh_labels`, applied by
:func:`geardyn.plot.common.plot_function`), and labels written out in a plot function pass through
:func:`of_mesh`, so that one code draws the pair's figures and a system's, each label saying which mesh it
shows ("dynamic transmission error u of mesh 'bevel' (non-dimensional)", "half peak-to-peak DTE of mesh
'bevel' [µm]").
"""

from __future__ import annotations

import json
import re

import xarray as xr

__all__ = ["MESH_VARIABLES", "json_list", "mesh_labels", "of_mesh", "reference_mesh", "system_info"]


def system_info(ds: xr.Dataset) -> dict:
    """The ``system`` attribute of a system's result (title, meshes, reference mesh, scales), ``{}`` for the pair.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.

    Returns
    -------
    dict
    """
    return json_attr(ds, "system")


def json_attr(ds: xr.Dataset, name: str) -> dict:
    """The JSON object of attribute ``name`` of a result, ``{}`` when it has none (or not an object)."""
    try:
        return dict(json.loads(ds.attrs[name]))
    except (KeyError, ValueError, TypeError):
        return {}


def json_list(ds: xr.Dataset, name: str) -> list:
    """The JSON list of attribute ``name`` of a result (jumps, marks, intervals …), ``[]`` when it has none.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.
    name : str
        The attribute.

    Returns
    -------
    list
    """
    return json.loads(ds.attrs.get(name, "[]"))


#: Variables of a result that are values of its reference mesh (a system's figures name the mesh in their labels),
#: with their copies in µm (``<name>_um``).
MESH_VARIABLES = frozenset(
    (
        "u v poincare_u poincare_v amplitude rms mean u_min u_max spectrum start_u start_v end_u end_v "
        "bifurcation_u bifurcation_v bifurcation_amplitude attractor_u attractor_v attractor_amplitude dte_um "
        "mesh_force mesh_force_N spectrum_um omega rpm mesh_frequency_Hz order_amplitude dynamic_factor"
    ).split()
)
#: The symbol of a reference-mesh quantity in a label, after which the mesh is named ("u of mesh 'bevel'").
_MESH_SYMBOL = re.compile(r"(?<![\w/'])(u_n|du/dτ|dδ/dτ|u|δ)(?![\w/'])")


def reference_mesh(ds: xr.Dataset) -> str | None:
    """The name of a system result's reference mesh (the mesh its u, amplitudes and ω are of); ``None`` for the pair.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.

    Returns
    -------
    str or None
    """
    name = system_info(ds).get("reference_mesh")
    return str(name) if name else None


def of_mesh(text: str, ds: xr.Dataset) -> str:
    """``text`` naming the reference mesh of a system's result: "mesh 'NAME'" after the first symbol u, u_n, du/dτ,
    δ or dδ/dτ of the text, or at its end ("half peak-to-peak DTE of mesh 'bevel'"); unchanged for the pair.

    Parameters
    ----------
    text : str
        A label or its long name.
    ds : xarray.Dataset
        The result.

    Returns
    -------
    str
    """
    mesh = reference_mesh(ds)
    if mesh is None or f"mesh '{mesh}'" in text:
        return text
    named = f"mesh '{mesh}'"
    if "the reference mesh" in text:
        return text.replace("the reference mesh", named, 1)
    m = _MESH_SYMBOL.search(text)
    if m is None:
        return f"{text} of {named}"
    return f"{text[: m.end()]} of {named}{text[m.end() :]}"


def mesh_labels(ds: xr.Dataset) -> xr.Dataset:
    """A system's result whose reference-mesh variables (:data:`MESH_VARIABLES`) have long names naming the mesh
    (:func:`of_mesh`), so that every axis label drawn from them says which mesh it shows; the pair's result as it is.

    Parameters
    ----------
    ds : xarray.Dataset
        A geardyn result.

    Returns
    -------
    xarray.Dataset
        A shallow copy (the data are shared) for a system, ``ds`` itself otherwise.
    """
    if reference_mesh(ds) is None:
        return ds
    out = ds.copy(deep=False)
    for name, var in out.variables.items():
        base = str(name)[: -len("_um")] if str(name).endswith("_um") else str(name)
        if (name in MESH_VARIABLES or base in MESH_VARIABLES) and "long_name" in var.attrs:
            var.attrs["long_name"] = of_mesh(str(var.attrs["long_name"]), ds)
    return out
