"""The variable registry, annotation, JSON conversion and atomic NetCDF files."""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

from geardyn import io
from geardyn.model import GearModel, IntegrationOptions


def test_registry_names_units_and_flags() -> None:
    assert io.variable("lle").units == "1/τ"
    assert io.variable("kappa2").long_name == "stiffness harmonic κ_2"  # from the parameter registry
    assert io.variable("phi_e1").units == "rad"
    assert io.variable("kappa2", "continuation").long_name == "stiffness harmonic κ_2"
    assert io.variable("section", "orbit").long_name != io.variable("section").long_name
    assert io.variable("amplitude_um").units == "µm"
    assert io.variable("no_such_variable") is None
    attrs = io.variable("status").attrs()
    assert attrs["flag_values"][:2] == [0, 1] and attrs["flag_meanings"].startswith("ok diverged")


def test_annotate_keeps_present_attributes_and_can_be_limited() -> None:
    ds = xr.Dataset({"lle": ("p", [0.1]), "amplitude": ("p", [1.0])})
    ds["lle"].attrs["long_name"] = "mine"
    io.annotate(ds, "bifurcation", names=["lle"])
    assert ds["lle"].attrs == {"long_name": "mine", "units": "1/τ"}
    assert ds["amplitude"].attrs == {}
    io.annotate(ds)
    assert ds["amplitude"].attrs["long_name"] == "half peak-to-peak displacement"


def test_json_values_convert_as_the_cli_does() -> None:
    assert io.json_values(xr.DataArray([1, 0, -1], name="period")) == [1, None, None]
    assert io.json_values(np.array([1, 3]), name="motion", period=np.array([2, 0])) == ["period-2", "chaotic"]
    assert io.json_values(xr.DataArray([0, 1], name="status")) == ["ok", "diverged"]
    assert io.json_values(np.array([np.nan, 2.5]), name="lle") == [None, 2.5]


def test_summary_json_and_atomic_netcdf(tmp_path) -> None:
    m = GearModel()
    ds = xr.Dataset(
        {"status": ("omega", np.array([0, 1])), "lle": ("omega", [0.1, np.nan])},
        coords={"omega": [0.9, 1.1]},
        attrs=io.result_attrs("bifurcation", m, IntegrationOptions()),
    )
    s = io.summary_json(ds)
    assert s["kind"] == "bifurcation" and s["status"] == {"ok": 1, "diverged": 1}
    assert s["coords"] == {"omega": [0.9, 1.1]} and s["points"]["lle"] == [0.1, None]
    assert io.model_from_attrs(ds) == m
    json.dumps(s)
    path = io.write_netcdf(ds, tmp_path / "sub" / "r.nc")
    back = io.read_netcdf(path)
    assert back["lle"].attrs["units"] == "1/τ"
    assert [p.name for p in path.parent.iterdir()] == ["r.nc"]  # no temporary file left
    io.atomic_write_bytes(tmp_path / "b.bin", b"abc")
    assert (tmp_path / "b.bin").read_bytes() == b"abc"


def test_attach_and_detach_round_trip() -> None:
    main = xr.Dataset({"u": ("point", [1.0, 2.0])}, attrs={"geardyn_kind": "continuation"})
    other = xr.Dataset({"amplitude": ("omega", [0.5])}, coords={"omega": [1.0]}, attrs={"geardyn_kind": "bifurcation"})
    both = io.attach(main, "sweep", other)
    again = io.attached(both, "sweep")
    assert again is not None and float(again["amplitude"][0]) == 0.5 and again.attrs["geardyn_kind"] == "bifurcation"
    assert set(io.detach(both).variables) == {"u"}
