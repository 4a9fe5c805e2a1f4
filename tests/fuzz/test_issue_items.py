"""One test (or more) per numbered finding of the hostile-user review of the CLI: each failed before the fix.

1 silent wrong results, 2 Ctrl-C (see test_signals.py), 3 disk full (test_signals.py), 4 tracebacks on bad
files, 5 hangs and unbounded work, 6 litter and lost work, 7 an inconsistent contract, 8 messages that blame
the wrong thing.
"""

from __future__ import annotations

import json
import math
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from fuzz_helpers import EXAMPLES, check_contract, child_env, run, run_child, strict_json

from geardyn.model import GearModel, IntegrationOptions
from geardyn.sweep import Chunk, chunked, run_chunks
from geardyn.system import build_models

FAST = IntegrationOptions(transient=20, periods=8)
SIM = ["simulate", "--transient", "3", "--periods", "4"]
PAIR = EXAMPLES / "paper_table1.toml"
TORSIONAL = EXAMPLES / "systems" / "paper_torsional.toml"
BEVEL8 = EXAMPLES / "systems" / "paper_bevel_8dof.toml"


def refused(args, *needles, code=2):
    """Run ``args``; assert the contract, the exit code and that the one error line holds every needle."""
    c, out, err = run(args)
    check_contract(c, out, err, args=args)
    assert c == code, (c, err)
    line = next(ln for ln in err.splitlines() if ln.startswith("error:"))
    for n in needles:
        assert n in line, (n, line)
    return line


def edited(tmp_path: Path, src: Path, old: str, new: str, name: str = "x.toml", count: int = 1) -> Path:
    text = src.read_text(encoding="utf-8")
    assert old in text
    p = tmp_path / name
    p.write_text(text.replace(old, new, count), encoding="utf-8")
    return p


def te_record(path: Path, te_um=None, n: int = 400, z1: int = 14) -> Path:
    phi = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    te = te_um if te_um is not None else 2.0 * np.cos(z1 * phi)
    path.write_text("angle [rad], TE [um]\n" + "\n".join(f"{float(a)!r}, {float(b)!r}" for a, b in zip(phi, te)) + "\n")
    return path


# ---------------------------------------------------------------- 1. silent wrong results
def _chunk(models, options):
    from geardyn.analysis.steady import summarize_batch
    from geardyn.integrate import integrate_batch

    res = integrate_batch(models, (0.0, 0.0), options)
    out = summarize_batch(res)
    out["poincare"] = res.poincare
    return out


def _chunks(values):
    models = build_models(GearModel(), ["omega"], np.asarray(values, float)[:, None])
    return [Chunk(i, _chunk, (models[s], FAST)) for i, s in enumerate(chunked(len(models), 2))]


def test_1_a_chunk_of_another_sweep_is_recomputed_not_used(tmp_path, capfd):
    a, b = np.linspace(0.6, 1.2, 6), np.linspace(0.65, 1.25, 6)
    run_chunks(_chunks(a), checkpoint=tmp_path / "a", progress=False)
    reference = run_chunks(_chunks(b), checkpoint=tmp_path / "b", progress=False)
    shutil.copy(tmp_path / "a" / "chunk-000001.npz", tmp_path / "b" / "chunk-000001.npz")
    capfd.readouterr()
    resumed = run_chunks(_chunks(b), checkpoint=tmp_path / "b", resume=True, progress=False)
    err = capfd.readouterr().err
    assert "chunk-000001.npz" in err and "another sweep" in err and len(err.strip().splitlines()) == 1
    for r, q in zip(resumed, reference):
        for k in q:
            np.testing.assert_array_equal(r[k], q[k])


def test_1_a_chunk_that_does_not_verify_or_sits_under_another_index_is_recomputed(tmp_path, capfd):
    b = np.linspace(0.65, 1.25, 6)
    reference = run_chunks(_chunks(b), checkpoint=tmp_path / "b", progress=False)
    d = tmp_path / "b"
    shutil.copy(d / "chunk-000000.npz", d / "chunk-000002.npz")  # right sweep, wrong index
    with np.load(d / "chunk-000001.npz") as z:  # right identity, altered numbers
        arrays = {k: z[k] for k in z.files}
    arrays["amplitude"] = arrays["amplitude"] + 1.0
    with open(d / "chunk-000001.npz", "wb") as f:
        np.savez(f, **arrays)
    capfd.readouterr()
    resumed = run_chunks(_chunks(b), checkpoint=d, resume=True, progress=False)
    err = capfd.readouterr().err
    assert "checksum does not verify" in err and "it is chunk 0" in err
    for r, q in zip(resumed, reference):
        for k in q:
            np.testing.assert_array_equal(r[k], q[k])


def test_1_modes_refuses_a_negative_bearing_stiffness(tmp_path):
    f = edited(tmp_path, BEVEL8, '"1e9 N/m"', '"-1e9 N/m"')
    refused(["modes", "--system", f, "--json"], "kx", ">= 0", str(f))


def test_1_modes_refuses_a_statically_unstable_stiffness_matrix():
    from geardyn.errors import ModelError
    from geardyn.systems import load_description
    from geardyn.systems.modes import modal_analysis

    desc = load_description(BEVEL8)
    import dataclasses

    neg = [
        dataclasses.replace(c, stiffness=tuple(tuple(-x for x in row) for row in c.stiffness)) for c in desc.connections
    ]
    assert neg
    with pytest.raises(ModelError, match="statically unstable"):
        modal_analysis(dataclasses.replace(desc, connections=tuple(neg)), "contact")


def test_1_te_of_huge_values_is_refused_and_json_is_strict(tmp_path):
    f = te_record(tmp_path / "te.csv", te_um=np.where(np.arange(400) % 2, 1e308, -1e308))
    refused(["te", f, "--teeth", "14,39", "--json"], str(f), "line 2", "beyond")
    c, out, err = run(["te", te_record(tmp_path / "ok.csv"), "--teeth", "14,39", "--json"])
    assert c == 0, err
    assert strict_json(out)["mesh_harmonics"][0]["amplitude_um"] == pytest.approx(2.0, rel=1e-9)
    from geardyn.cli.guard import strict_json as dumps

    doc = strict_json(dumps({"amplitude_um": float("inf"), "x": [1.0, float("nan")], "ok": 2.5}))
    assert doc == {"amplitude_um": None, "x": [1.0, None], "ok": 2.5, "non_finite": ["amplitude_um", "x[1]"]}


def test_1_te_rpm_that_makes_the_angle_meaningless_is_refused(tmp_path):
    t = np.arange(400) * 1e-4
    f = tmp_path / "t.csv"
    f.write_text("time [s], TE [um]\n" + "\n".join(f"{float(a)!r}, {math.cos(900 * a)!r}" for a in t) + "\n")
    refused(["te", f, "--teeth", "14,39", "--rpm", "1e300", "--json"], "rpm")
    refused(["te", f, "--teeth", "14,39", "--rpm", "1e5", "--json"], "mesh cycles apart")


# ---------------------------------------------------------------- 4. tracebacks on bad files
@pytest.mark.parametrize(
    "old,new,needle",
    [
        ("z1 = 23", "z1 = " + "9" * 401, "z1"),
        ("z1 = 23", "z1 = 1000000000000000000000000000000", "z1"),
        ("z1 = 23", "z1 = 5000", "teeth"),
        ('r1 = "125.5 mm"', 'r1 = "1e200 m"', "r1"),
        ('I1 = "1.772 kg*m^2"', 'I1 = "1e-320 kg*m^2"', "I1"),
        ('m_mn = "7.28 mm"', 'm_mn = "9**9**9 mm"', "exponent"),
    ],
)
def test_4_and_5_bad_config_values_are_one_line(tmp_path, old, new, needle):
    f = edited(tmp_path, PAIR, old, new)
    t0 = time.monotonic()
    refused(["geometry", "--config", f, "--json"], str(f), needle)
    assert time.monotonic() - t0 < 30


@pytest.mark.parametrize(
    "old,new,needle",
    [
        ("z1 = 23", "z1 = " + "9" * 401, "z1"),
        ('r1 = "125.5 mm"', 'r1 = "1e200 m"', "r1"),
        ('inertia = "1.772 kg*m^2"', 'inertia = "1e-320 kg*m^2"', "inertia"),
        ('m_mn = "7.28 mm"', 'm_mn = "9**9**9 mm"', "exponent"),
    ],
)
def test_4_and_5_bad_system_values_are_one_line(tmp_path, old, new, needle):
    f = edited(tmp_path, TORSIONAL, old, new)
    line = refused(["modes", "--system", f, "--json"], needle)
    assert line.count(str(f)) == 1  # the place once, not a prefix repeated


@pytest.mark.parametrize("loader", ["config", "system"])
def test_4_nesting_a_hundred_thousand_deep_is_refused(tmp_path, loader):
    f = tmp_path / "deep.toml"
    f.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    args = ["geometry", "--config", f] if loader == "config" else ["modes", "--system", f]
    refused(args, "nested")


def _result(tmp_path: Path) -> Path:
    c, out, err = run([*SIM, "--out", tmp_path / "r", "--json"])
    assert c == 0, err
    return tmp_path / "r" / "simulate.nc"


def test_4_plot_of_a_mutated_result_is_one_line(tmp_path):
    nc = _result(tmp_path)
    with xr.open_dataset(nc, engine="h5netcdf") as ds:
        ds = ds.load()
    cases = {
        "dropped": ds.drop_vars(list(ds.data_vars)[0]),
        "kind": ds.assign_attrs(geardyn_kind="bifurcation"),
        "renamed": ds.assign_attrs(model=ds.attrs["model"].replace('"omega"', '"omegax"')),
        "nested": ds.assign_attrs(model="[" * 100_000 + "]" * 100_000),
        "huge": ds.assign_attrs(extra=np.zeros(1_000_000)),
    }
    for name, bad in cases.items():
        f = tmp_path / f"{name}.nc"
        bad.to_netcdf(f, engine="h5netcdf")
        t0 = time.monotonic()
        c, out, err = run(["plot", f, "--out", tmp_path / "fig", "--json"])
        check_contract(c, out, err, json_mode=True, args=["plot", name])
        assert time.monotonic() - t0 < 60, name


def test_4_a_te_record_beyond_the_read_limit_is_refused_at_once(tmp_path):
    from geardyn.te import MAX_TE_BYTES

    f = tmp_path / "big.csv"
    with open(f, "wb") as fh:
        fh.truncate(MAX_TE_BYTES + 1)
    t0 = time.monotonic()
    refused(["te", f, "--teeth", "14,39"], str(f), "MB")
    assert time.monotonic() - t0 < 10


def test_4_reproduce_with_an_absurd_worker_count():
    refused(["reproduce", "--workers", str(10**22), "--out", "never"], "workers")


@pytest.mark.parametrize("env", [{"PYTHONIOENCODING": "ascii"}, {"LC_ALL": "C", "LANG": "C"}])
@pytest.mark.parametrize("args", [["simulate", "--help"], ["geometry"]])
def test_4_non_utf8_terminals_get_ascii(env, args):
    c, out, err = run_child(args, env=child_env(**env), timeout=120)
    assert c == 0 and "Traceback" not in err, err
    if "PYTHONIOENCODING" in env:
        assert out.isascii()
        assert "Poincare" in out or "omega" in out


def test_4_a_closed_stdout_ends_quietly(tmp_path):
    import subprocess
    import sys

    p = subprocess.run(
        [
            sys.executable,
            "-c",
            "import os, runpy, sys; os.close(1); sys.argv = ['geardyn', 'geometry', "
            "'--json']; runpy.run_module('geardyn.cli', run_name='__main__')",
        ],
        env=child_env(),
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
    )
    assert p.returncode == 0 and p.stderr == "", p.stderr
    p = subprocess.run(
        f"{sys.executable} -m geardyn.cli geometry --json >&-",
        shell=True,
        env=child_env(),
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
    )
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr


# ---------------------------------------------------------------- 5. hangs and unbounded work
@pytest.mark.parametrize(
    "args,needle",
    [
        ([*SIM[:3], "--periods", "100000000"], "GB of memory"),
        (
            [
                "bifurcation",
                "--param",
                "omega",
                "--start",
                "0.5",
                "--stop",
                "1.5",
                "--num",
                "100000000",
                "--periods",
                "2",
            ],
            "memory",
        ),
        (
            [
                "bifurcation",
                "--param",
                "omega",
                "--start",
                "0.5",
                "--stop",
                "1.5",
                "--num",
                "100000",
                "--transient",
                "1000000",
            ],
            "of computing",
        ),
        (["bench", "--repeats", str(10**23)], "repeats"),
        (["simulate", "--transient", "100000000", "--periods", "2"], "of computing"),
        (
            ["runup", "--omega-start", "0.8", "--omega-stop", "0.9", "--tau-duration", "1e11", "--num", "0"],
            "of computing",
        ),
        (
            [
                "runup",
                "--omega-start",
                "0.8",
                "--omega-stop",
                "0.9",
                "--tau-duration",
                "100",
                "--num",
                "0",
                "--dtau",
                "1e-320",
            ],
            "steps per forcing period",
        ),
        (
            ["runup", "--omega-start", "0.8", "--omega-stop", "0.9", "--tau-duration", "-5", "--num", "0"],
            "tau_duration",
        ),
    ],
)
def test_5_unbounded_work_is_refused_before_computing(args, needle):
    t0 = time.monotonic()
    refused(args, needle)
    assert time.monotonic() - t0 < 60


def test_5_a_scheduler_that_is_not_dask_is_refused_in_one_line():
    import socket
    import threading

    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(1)
    talker = socket.socket()
    talker.bind(("127.0.0.1", 0))
    talker.listen(1)

    def banner():
        c, _ = talker.accept()
        c.sendall(b"HTTP/1.0 200 OK\r\n\r\nhello")
        time.sleep(1)
        c.close()

    threading.Thread(target=banner, daemon=True).start()
    base = [
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "0.8",
        "--stop",
        "1.2",
        "--num",
        "3",
        "--periods",
        "2",
        "--transient",
        "2",
        "--scheduler",
    ]
    t0 = time.monotonic()
    refused([*base, f"tcp://127.0.0.1:{silent.getsockname()[1]}"], "did not answer")
    assert time.monotonic() - t0 < 20
    refused([*base, f"tcp://127.0.0.1:{talker.getsockname()[1]}"], "not a Dask scheduler")
    silent.close()
    talker.close()


# ---------------------------------------------------------------- 6. litter and lost work
def test_6_a_corrupt_manifest_is_refused_on_resume_and_keeps_the_chunks(tmp_path):
    d = tmp_path / "ck"
    run_chunks(_chunks(np.linspace(0.6, 1.2, 4)), checkpoint=d, progress=False)
    (d / "manifest.json").write_text("{not json")
    from geardyn.errors import SweepError

    with pytest.raises(SweepError, match="cannot be read"):
        run_chunks(_chunks(np.linspace(0.6, 1.2, 4)), checkpoint=d, resume=True, progress=False)
    assert len(list(d.glob("chunk-*.npz"))) == 2
    run_chunks(_chunks(np.linspace(0.6, 1.2, 4)), checkpoint=d, progress=False)  # starting over is allowed
    assert json.loads((d / "manifest.json").read_text())["chunks"] == 2


def test_6_stale_temporaries_of_the_output_are_removed_by_the_next_write(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    stale = out / ".simulate.nc.abc123.tmp"
    stale.write_bytes(b"partial")
    c, _, err = run([*SIM, "--out", out, "--json"])
    assert c == 0, err
    assert not stale.exists() and not list(out.glob(".*.tmp"))


# ---------------------------------------------------------------- 7. one contract
@pytest.mark.parametrize(
    "cmd",
    [
        SIM,
        ["lyapunov", "--transient", "3", "--periods", "4", "--blocks", "2"],
        ["orbit", "--transient", "3"],
        ["hb", "--param", "omega", "--start", "0.8", "--stop", "0.9"],
        ["modes", "--system", str(TORSIONAL)],
        ["runup", "--omega-start", "0.8", "--omega-stop", "0.9", "--tau-duration", "50"],
        ["bifurcation", "--param", "omega", "--start", "0.8", "--stop", "1.2", "--num", "3"],
        ["basins", "--nu", "2", "--nv", "2"],
    ],
)
def test_7_a_bad_out_is_exit_2_in_every_command(tmp_path, cmd):
    a_file = tmp_path / "file"
    a_file.write_text("x")
    refused([*cmd, "--out", ""], "out", "empty")
    refused([*cmd, "--out", a_file], "out", str(a_file))
    refused(["reproduce", "--out", a_file], "out")


def test_7_out_with_an_upper_case_suffix_is_a_file(tmp_path):
    c, _, err = run([*SIM, "--out", tmp_path / "x.NC", "--json"])
    assert c == 0, err
    assert (tmp_path / "x.NC").is_file()


def test_7_resume_with_nothing_to_resume_says_so(tmp_path):
    c, out, err = run(
        [
            "bifurcation",
            "--param",
            "omega",
            "--start",
            "0.8",
            "--stop",
            "1.2",
            "--num",
            "3",
            "--transient",
            "3",
            "--periods",
            "4",
            "--settle",
            "0",
            "--out",
            tmp_path / "o",
            "--resume",
            "--json",
        ]
    )
    assert c == 0, err
    assert "nothing to resume" in err


def test_7_a_direction_in_fixed_mode_is_refused():
    refused(
        [
            "bifurcation",
            "--param",
            "omega",
            "--start",
            "0.8",
            "--stop",
            "1.2",
            "--num",
            "3",
            "--sweep",
            "down",
            "--mode",
            "fixed",
        ],
        "sweep",
        "continue",
    )


# ---------------------------------------------------------------- 8. messages that name the right thing
def test_8_messages_blame_the_right_option(tmp_path):
    refused(["simulate", "--rpm", "1e23"], "rpm:", "allowed")
    refused(["lyapunov", "--periods", "1"], "periods:", "--blocks")


def test_8_a_fifo_as_config_is_not_called_missing(tmp_path):
    import os

    f = tmp_path / "fifo"
    os.mkfifo(f)
    refused(["geometry", "--config", f], "not a regular file")


def test_8_a_byte_order_mark_is_read(tmp_path):
    f = tmp_path / "bom.toml"
    f.write_bytes(b"\xef\xbb\xbf" + PAIR.read_bytes())
    c, out, err = run(["geometry", "--config", f, "--json"])
    assert c == 0, err
    assert strict_json(out)["z1"] == 23


def test_8_system_file_messages(tmp_path):
    f = edited(tmp_path, TORSIONAL, 'backlash = "0.1 mm"', 'backlash = "-0.1 mm"')
    refused(["modes", "--system", f], "backlash", ">= 0")
    f = edited(tmp_path, TORSIONAL, 'name = "gear"', 'name = "pinion"', name="dup.toml")
    refused(["modes", "--system", f], "duplicate body name 'pinion'")


def test_8_an_out_that_is_a_directory_names_it_not_a_temporary(tmp_path):
    d = tmp_path / "r.nc"
    d.mkdir()
    line = refused([*SIM, "--out", d], str(d), "is a directory")
    assert ".tmp" not in line


# ---------------------------------------------------------------- found by the long fuzz profile
def test_lyapunov_exponents_below_double_precision_are_refused_not_a_division_by_zero():
    # ω = 1e-3 with ξ0 = 0.1: the perturbations shrink by e^-1257 in one period (the kernel divided by 0)
    refused(["lyapunov", "--transient", "3", "--periods", "8", "--blocks", "2", "--rpm", "1.0"], "omega:", "ω >=")
    refused(
        [
            "bifurcation",
            "--param",
            "omega",
            "--start",
            "0.001",
            "--stop",
            "0.0012",
            "--num",
            "2",
            "--transient",
            "3",
            "--periods",
            "8",
            "--settle",
            "0",
            "--lyapunov",
        ],
        "omega:",
    )
    c, out, err = run(["lyapunov", "--transient", "3", "--periods", "8", "--blocks", "2", "--omega", "0.002", "--json"])
    assert c == 0, err
    assert strict_json(out)["sum"] == pytest.approx(-0.2, abs=1e-6)  # trace of the Jacobian: -2 ξ0
