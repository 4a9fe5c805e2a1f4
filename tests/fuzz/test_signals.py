"""Interruption (SIGINT, SIGTERM), a full disk (a file-size limit) and kill -9 with resume, in child processes.

Every command stops within about a second of the signal, says "interrupted", exits 130 (143 for SIGTERM)
and never reports success; a sweep keeps its finished chunks for ``--resume``.  A write that fails
(``RLIMIT_FSIZE``) is one line naming the file, exit code 1, and leaves no temporary or partial file.
The default run covers one command of each kind; ``-m slow`` covers every command.
"""

from __future__ import annotations

import resource
import signal
import time

import numpy as np
import pytest
import xarray as xr
from fuzz_helpers import EXAMPLES, datasets_equal, interrupt, run_child, start

#: Seconds from the signal to the end of the process allowed (the contract's "about a second", with
#: room for a loaded machine).
STOP_SECONDS = 2.5
#: Seconds a command runs before it is signalled (start-up, imports and kernel compilation included).
WARM = 6.0

BIF = ["bifurcation", "--param", "omega", "--start", "0.5", "--stop", "1.5", "--transient", "300", "--periods", "64"]
LONG = {
    "simulate": ["simulate", "--periods", "3000000", "--transient", "10"],
    "simulate-accurate": ["simulate", "--periods", "2000000", "--transient", "10", "--accurate"],
    "lyapunov": ["lyapunov", "--periods", "3000000", "--transient", "10", "--blocks", "2"],
    "orbit": ["orbit", "--transient", "3000000"],
    "bifurcation": [*BIF, "--num", "20000"],
    "bifurcation-continue-both": [*BIF, "--num", "4000", "--mode", "continue", "--sweep", "both"],
    "continuation": [
        "continuation",
        "--param",
        "omega",
        "--start",
        "0.5",
        "--stop",
        "3",
        "--transient",
        "100",
        "--ds-max",
        "0.0005",
        "--max-period",
        "64",
    ],
    "response": ["response", "--omega-start", "0.5", "--omega-stop", "1.5", "--num", "4000"],
    "map": [
        "map",
        "--x",
        "omega",
        "--y",
        "xi0",
        "--x-start",
        "0.5",
        "--x-stop",
        "1.5",
        "--y-start",
        "0.02",
        "--y-stop",
        "0.2",
        "--x-num",
        "200",
        "--y-num",
        "100",
    ],
    "basins": ["basins", "--nu", "150", "--nv", "150"],
    "hb": ["hb", "--param", "omega", "--start", "0.3", "--stop", "3", "--harmonics", "256", "--period", "4"],
    "runup": ["runup", "--omega-start", "0.5", "--omega-stop", "1.5", "--tau-duration", "3e6", "--num", "0"],
    "bench": ["bench", "--repeats", "100"],
}
DEFAULT = ("simulate", "bifurcation")
#: A command's progress line once it has computed something (a count above zero: its kernel is running, not
#: still loading or compiling): it is signalled then; a command without one after WARM seconds.
_COUNT = r"(?:[1-9][\d.]*|0\.\d*[1-9][\d.]*)/[\d.]+ "
PROGRESS = {
    name: _COUNT + unit
    for name, unit in {
        "bifurcation": "points",
        "bifurcation-continue-both": "points",
        "response": "points",
        "map": "points",
        "basins": "points",
        "lyapunov": "periods",
        "continuation": "Δω traced",
        "hb": "Δω traced",
        "simulate": "periods",
        "simulate-accurate": "periods",
        "orbit": "periods",
        "runup": "blocks",
        "bench": "runs",
    }.items()
}


def _interrupted(name: str, sig: int) -> None:
    code, out, err, took = interrupt(LONG[name], after=WARM, sig=sig, marker=PROGRESS.get(name))
    assert code == (130 if sig == signal.SIGINT else 143), (code, err[-1500:])
    assert took < STOP_SECONDS, took
    assert "Traceback" not in err, err[-2000:]
    last = [ln for ln in err.splitlines() if ln.strip()][-1]
    assert last.startswith("interrupted"), err[-1500:]
    assert out.strip() == "" or "wrote" not in out  # no success reported


@pytest.mark.parametrize("name", [pytest.param("simulate", marks=pytest.mark.slow), "bifurcation"])
def test_sigint_stops_the_command_within_a_second(name):  # simulate: SIGTERM in the default run
    _interrupted(name, signal.SIGINT)


def test_sigterm_exits_143():
    _interrupted("simulate", signal.SIGTERM)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(LONG) - set(DEFAULT)))
def test_sigint_stops_every_command(name):
    _interrupted(name, signal.SIGINT)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["bifurcation", "map", "hb"])
def test_sigterm_stops_every_kind_of_command(name):
    _interrupted(name, signal.SIGTERM)


# ---------------------------------------------------------------- a full disk
def _limit(nbytes: int):
    def pre() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))

    return pre


WRITERS = {
    "simulate": ["simulate", "--transient", "3", "--periods", "4"],
    "bifurcation": [
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "0.8",
        "--stop",
        "1.2",
        "--num",
        "5",
        "--transient",
        "3",
        "--periods",
        "8",
        "--settle",
        "0",
    ],
    "hb": ["hb", "--param", "omega", "--start", "0.8", "--stop", "0.9", "--harmonics", "4"],
    "lyapunov": ["lyapunov", "--transient", "3", "--periods", "8", "--blocks", "2"],
    "orbit": ["orbit", "--transient", "3"],
    "basins": ["basins", "--nu", "3", "--nv", "3", "--transient", "3", "--periods", "8", "--settle", "0"],
    "runup": ["runup", "--omega-start", "0.8", "--omega-stop", "0.9", "--tau-duration", "200", "--num", "0"],
    "modes": ["modes", "--system", str(EXAMPLES / "systems" / "paper_torsional.toml")],
}


def _full_disk(tmp_path, name: str, limit: int) -> None:
    # The command first runs without the limit, so that numba's cache of its kernels is written (in a fresh
    # checkout nothing is cached yet) and the limited run fails where the test looks: at the output.
    code, _, err = run_child([*WRITERS[name], "--json"], timeout=600)
    assert code == 0, err[-2000:]
    out = tmp_path / "out"
    code, stdout, err = run_child([*WRITERS[name], "--out", out, "--json"], preexec_fn=_limit(limit), timeout=600)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 1, (code, err[-2000:])
    assert "Traceback" not in err and len(lines) <= 3, err[-2000:]
    assert str(out) in lines[-1] and "File too large" in lines[-1], lines[-1]
    assert not list(out.rglob("*.tmp")), list(out.rglob("*"))
    for f in out.rglob("*.nc"):  # whatever is there is complete
        xr.open_dataset(f, engine="h5netcdf").close()
    for f in out.rglob("*.png"):
        import matplotlib.image

        matplotlib.image.imread(f)


@pytest.mark.parametrize("name,limit", [("simulate", 4096), ("bifurcation", 30_000)])
def test_a_full_disk_is_one_line_naming_the_file_and_leaves_nothing_partial(tmp_path, name, limit):
    _full_disk(tmp_path, name, limit)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(WRITERS) - {"simulate", "bifurcation"}))
@pytest.mark.parametrize("limit", [2048, 60_000])
def test_a_full_disk_in_every_command_that_writes(tmp_path, name, limit):
    out = tmp_path / "out"
    code, _, err = run_child([*WRITERS[name], "--out", out, "--json"], preexec_fn=_limit(limit), timeout=600)
    assert code in (0, 1) and "Traceback" not in err, err[-2000:]
    if code == 1:
        _full_disk(tmp_path / "again", name, limit)
    assert not list(out.rglob("*.tmp"))


def test_te_out_on_a_full_disk_leaves_no_empty_file(tmp_path):
    phi = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    rec = tmp_path / "te.csv"
    rec.write_text("angle [rad], TE [um]\n" + "\n".join(f"{float(a)!r}, {float(np.cos(14 * a))!r}" for a in phi))
    out = tmp_path / "mesh.toml"
    code, _, err = run_child(["te", rec, "--teeth", "14,39", "--out", out], preexec_fn=_limit(16), timeout=300)
    assert code == 1 and str(out) in err and "Traceback" not in err, err
    assert not out.exists() and not list(tmp_path.glob(".*.tmp"))


# ---------------------------------------------------------------- kill -9 and resume
def _kill9_then_resume(tmp_path, args, stem: str) -> None:
    ref_dir, out = tmp_path / "ref", tmp_path / "out"
    code, _, err = run_child([*args, "--out", ref_dir, "--json"], timeout=900)
    assert code == 0, err[-2000:]
    p = start([*args, "--out", out, "--json"])
    chunks = out / f"{stem}.nc.chunks"
    t0 = time.monotonic()
    while len(list(chunks.glob("chunk-*.npz"))) < 2 and time.monotonic() - t0 < 300 and p.poll() is None:
        time.sleep(0.05)
    assert p.poll() is None, "the sweep ended before it could be killed"
    p.send_signal(signal.SIGKILL)
    p.communicate()
    (out / f".{stem}.nc.killed.tmp").write_bytes(b"partial")  # as a kill during the final write leaves
    code, _, err = run_child([*args, "--out", out, "--json", "--resume"], timeout=900)
    assert code == 0 and "Traceback" not in err, err[-2000:]
    assert not list(out.glob(".*.tmp")) and not chunks.exists()
    with (
        xr.open_dataset(ref_dir / f"{stem}.nc", engine="h5netcdf") as a,
        xr.open_dataset(out / f"{stem}.nc", engine="h5netcdf") as b,
    ):
        datasets_equal(a, b)


def test_kill_9_then_resume_gives_the_uninterrupted_result(tmp_path):
    _kill9_then_resume(tmp_path, [*BIF, "--num", "300", "--chunk-size", "16"], "bifurcation")


@pytest.mark.slow
@pytest.mark.parametrize(
    "args,stem",
    [
        (["basins", "--nu", "30", "--nv", "30", "--chunk-size", "16"], "basins"),
        (
            [
                "map",
                "--x",
                "omega",
                "--y",
                "xi0",
                "--x-start",
                "0.5",
                "--x-stop",
                "1.5",
                "--y-start",
                "0.02",
                "--y-stop",
                "0.2",
                "--x-num",
                "30",
                "--y-num",
                "20",
                "--chunk-size",
                "16",
            ],
            "map",
        ),
        (["response", "--omega-start", "0.5", "--omega-stop", "1.5", "--num", "300"], "response"),
        ([*BIF, "--num", "300", "--mode", "continue", "--sweep", "both"], "bifurcation"),
    ],
)
def test_kill_9_then_resume_every_sweep(tmp_path, args, stem):
    _kill9_then_resume(tmp_path, args, stem)


@pytest.mark.slow
def test_resume_of_a_finished_chunk_directory_survives_sigint(tmp_path):
    """SIGINT in the middle of a sweep with --out: the chunks saved then complete it with --resume."""
    out = tmp_path / "out"
    args = [*BIF, "--num", "3000", "--out", out, "--json"]
    code, _, err, _ = interrupt(args, after=WARM)
    assert code == 130 and "--resume" in err, err[-1500:]
    assert (out / "bifurcation.nc.chunks" / "manifest.json").exists()
