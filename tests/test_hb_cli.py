"""``geardyn hb`` and ``geardyn response --method hb``: JSON against the library, NetCDF + figure redrawn by
``geardyn plot``, jumps and hysteresis at the HB folds, bad input refused in one line."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.analysis.hb import hb_continuation
from geardyn.cli import app, main
from geardyn.io import attached, read_netcdf
from geardyn.model import GearModel

#: A small case with a hysteresis loop: two folds and a grazing in ω ∈ [0.5, 0.65] at H = 8.
SMALL = ["--param", "omega", "--start", "0.5", "--stop", "0.65", "--harmonics", "8"]


def _run(args):
    return CliRunner().invoke(app, args)


def _main(argv):
    """Exit code and stderr of the real entry point."""
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            main(argv)
            code = 0
        except SystemExit as e:
            code = e.code
    return code, err.getvalue()


@pytest.fixture(scope="module")
def small_json():
    r = _run(["hb", *SMALL, "--json"])
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


@pytest.fixture(scope="module")
def small_lib():
    return hb_continuation(GearModel(), "omega", 0.5, 0.65, harmonics=8)


def test_hb_json_keys_and_values_match_the_library(small_json, small_lib):
    s, res = small_json, small_lib
    assert {"branch", "bifurcations", "harmonics", "converged", "param", "period", "end"} <= set(s)
    assert s["harmonics"] == 8 and s["period"] == 1 and s["param"] == "omega" and s["converged"] is True
    assert len(s["branch"]) == res.values.size
    for p, v, lo, hi, st, mu in zip(s["branch"], res.values, res.u_min, res.u_max, res.stable, res.multipliers):
        assert {"omega", "amplitude", "u_min", "u_max", "stable", "multipliers"} <= set(p)
        assert p["omega"] == v and p["u_min"] == lo and p["u_max"] == hi
        assert p["amplitude"] == pytest.approx(0.5 * (hi - lo), rel=1e-15)
        assert p["stable"] in (bool(st), None)
        np.testing.assert_array_equal(np.array(p["multipliers"]), np.column_stack([mu.real, mu.imag]))
        assert "rpm" in p  # physical values beside the non-dimensional ones
    types = [b["type"] for b in s["bifurcations"]]
    assert types == [b.type for b in res.bifurcations] and types.count("fold") == 2 and "grazing" in types
    for b, ref in zip(s["bifurcations"], res.bifurcations):
        assert b["omega"] == ref.value


def test_hb_out_writes_netcdf_and_figure_and_plot_redraws_them(tmp_path):
    out = tmp_path / "run"
    r = _run(["hb", *SMALL, "--compare-shooting", "--default-mode", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    drawn = {p.name for p in out.iterdir() if p.suffix == ".png"}
    assert drawn == {"hb.png"} and (out / "hb.nc").is_file()
    assert sorted(s["files"]) == sorted([str(out / "hb.nc"), str(out / "hb.png")])
    assert (out / "hb.png").stat().st_size > 10_000
    ds = read_netcdf(out / "hb.nc")
    assert ds.attrs["geardyn_kind"] == "hb" and ds.sizes["point"] == len(s["branch"])
    sh = attached(ds, "shooting")
    assert sh is not None and sh.attrs["geardyn_kind"] == "continuation" and sh.sizes["point"] > 10
    # shooting and HB agree on the folds (default mode at Δτ = 0.01: within 1e-3)
    hb_f = sorted(b["omega"] for b in s["bifurcations"] if b["type"] == "fold")
    sh_f = sorted(b["omega"] for b in s["shooting"]["bifurcations"] if b["type"] == "fold")
    assert len(hb_f) == len(sh_f) == 2 and np.allclose(hb_f, sh_f, atol=1e-3)
    re = tmp_path / "re"
    r = _run(["plot", str(out / "hb.nc"), "--out", str(re), "--json"])
    assert r.exit_code == 0, r.output
    assert {p.name for p in re.iterdir() if p.suffix == ".png"} == drawn
    assert json.loads(r.stdout)["kind"] == "hb"


def test_response_method_hb_has_jumps_and_hysteresis_at_the_folds(small_lib):
    args = ["response", "--omega-start", "0.5", "--omega-stop", "0.65", "--num", "16", "--json"]
    r = _run([*args, "--method", "hb"])
    assert r.exit_code == 0, r.output
    s = json.loads(r.stdout)
    # the same keys as the brute-force response
    ref = json.loads(_run([*args, "--transient", "20", "--periods", "8", "--settle", "0"]).stdout)
    assert set(s) == set(ref) and set(s["up"]) == set(ref["up"])
    res16 = hb_continuation(GearModel(), "omega", 0.5, 0.65)  # the command's default H = 16
    f = sorted(b.value for b in res16.of_type("fold"))
    assert len(f) == 2
    jumps = {j["sweep"]: j for j in s["jumps"]}
    assert set(jumps) == {"up", "down"} and len(s["jumps"]) == 2
    assert jumps["up"]["omega"] == pytest.approx(f[1], abs=1e-12) and jumps["up"]["direction"] == "up"
    assert jumps["down"]["omega"] == pytest.approx(f[0], abs=1e-12) and jumps["down"]["direction"] == "down"
    for j in s["jumps"]:
        assert min(j["omega_from"], j["omega_to"]) <= j["omega"] <= max(j["omega_from"], j["omega_to"])
    assert s["hysteresis"] == [pytest.approx(f, abs=1e-12)]
    # inside the loop the sweeps are on different branches, outside on the same
    w = np.array(s["omega"])
    up, down = np.array(s["up"]["amplitude"], float), np.array(s["down"]["amplitude"], float)
    inside = (w > f[0]) & (w < f[1])
    assert np.all(up[inside] < down[inside]) and np.allclose(up[~inside], down[~inside], rtol=1e-9)


@pytest.mark.parametrize(
    "args, name",
    [
        (["--harmonics", "0"], "harmonics"),
        (["--period", "0"], "period"),
        (["--harmonics", "100000"], "harmonics"),
        (["--ds-max", "0"], "ds-max"),
        (["--system", "bevel.toml"], "system"),
        (["--start", "nan"], "start"),
        (["--omega", "0.7"], "omega"),
        (["--param", "zeta"], "param"),
    ],
)
def test_bad_input_is_one_line(args, name):
    base = {"--param": "omega", "--start": "0.5", "--stop": "0.6"}
    for i in range(0, len(args), 2):
        base[args[i]] = args[i + 1]
    flat = [x for kv in base.items() for x in kv]
    code, err = _main(["hb", *flat])
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ") and name in lines[0], err


def test_response_method_is_checked():
    code, err = _main(["response", "--omega-start", "0.5", "--omega-stop", "0.6", "--method", "shooting"])
    assert code == 2 and err.strip().splitlines() == ["error: method: must be one of sweep, hb, got 'shooting'"]
