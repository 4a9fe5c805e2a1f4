"""Property-based fuzzing of the commands in process: whatever the input, the failure contract holds.

Generated: option values (extreme floats and integers, strings, empty, unicode) for every cheap command;
configuration and system files mutated from the shipped examples; TE records; result files of the
commands, mutated (variables dropped, kinds and attributes changed).  Each run must exit 0, 1 or 2, print
no traceback and no warning, at most a few lines on stderr, and strict JSON with ``--json``.

The default profile runs a few dozen cases per target (CI, about a minute); ``-m slow`` runs the long
profile (``pytest -m slow tests/fuzz/test_fuzz.py --hypothesis-show-statistics``).  The estimated work of
a run is capped by ``GEARDYN_TIME_BUDGET`` (a few seconds here), as for a user.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from fuzz_helpers import EXAMPLES, check_contract, run
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

FAST = settings(
    max_examples=40, deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck)
)
FAST_FILES = settings(FAST, max_examples=6)
LONG = settings(max_examples=400, deadline=None, database=None, suppress_health_check=list(HealthCheck))


@pytest.fixture(autouse=True)
def small_budget(monkeypatch):
    monkeypatch.setenv("GEARDYN_TIME_BUDGET", "3")


# ---------------------------------------------------------------- values
FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["1e308", "-1e308", "1e-320", "5e-324", "-0", "nan", "inf", "-inf", "1e400", "0x10", "1_0"]),
    st.floats(min_value=-3, max_value=3).map(lambda x: f"{x:.6g}"),
)
INTS = st.one_of(
    st.integers(min_value=-(10**30), max_value=10**30).map(str),
    st.sampled_from(["0", "-1", "1", "2", "3", "9" * 401, "1e8", "2**64", "+5"]),
)
TEXT = st.one_of(
    st.text(max_size=24),
    st.sampled_from(
        [
            "",
            " ",
            "--json",
            "-",
            "µm",
            "ω",
            "\u202e",
            "a" * 5000,
            "../../x",
            "\x00",
            "1,2",
            "14,39",
            "9**9**9 mm",
            "tcp://127.0.0.1:1",
            "fixed",
            "continue",
            "both",
            "down",
            "omega",
            "xi0",
        ]
    ),
)
VALUES = st.one_of(FLOATS, INTS, TEXT)

SMALL = ["--transient", "3", "--periods", "4"]
CHEAP = {
    "simulate": ["simulate", *SMALL],
    "lyapunov": ["lyapunov", "--transient", "3", "--periods", "8", "--blocks", "2"],
    "orbit": ["orbit", "--transient", "3"],
    "geometry": ["geometry"],
    "bifurcation": [
        "bifurcation",
        "--param",
        "omega",
        "--start",
        "0.8",
        "--stop",
        "1.2",
        "--num",
        "3",
        *SMALL,
        "--settle",
        "0",
    ],
    "response": ["response", "--omega-start", "0.8", "--omega-stop", "1.2", "--num", "3", *SMALL, "--settle", "0"],
    "map": [
        "map",
        "--x",
        "omega",
        "--y",
        "xi0",
        "--x-start",
        "0.8",
        "--x-stop",
        "1.2",
        "--y-start",
        "0.05",
        "--y-stop",
        "0.1",
        "--x-num",
        "2",
        "--y-num",
        "2",
        *SMALL,
        "--settle",
        "0",
    ],
    "basins": ["basins", "--nu", "2", "--nv", "2", *SMALL, "--settle", "0"],
    "modes": ["modes", "--system", str(EXAMPLES / "systems" / "paper_torsional.toml")],
    "runup": ["runup", "--omega-start", "0.8", "--omega-stop", "0.9", "--tau-duration", "100", "--num", "0"],
}
#: Options left out of the option fuzz: output places (the fuzz writes no files there), engines.
SKIP = {"--out", "--processes", "--scheduler", "--workers", "--resume", "--help", "--json", "--system", "--config"}


def _options(cmd: str) -> list[tuple[str, bool]]:
    import typer.main

    from geardyn.cli import app

    group = typer.main.get_command(app)
    c = group.commands[cmd]
    out = []
    for p in c.params:
        for flag in p.opts:
            if flag.startswith("--") and flag not in SKIP:
                out.append((flag, bool(getattr(p, "is_flag", False))))
    return out


OPTIONS = {cmd: _options(args[0]) for cmd, args in CHEAP.items()}


def _one_line_errors(args, json_mode=True):
    code, out, err = run(args)
    check_contract(code, out, err, json_mode=json_mode, args=args)
    event(f"exit {code}")
    return code, out, err


def options_case(data) -> None:
    cmd = data.draw(st.sampled_from(sorted(CHEAP)), label="command")
    args = list(CHEAP[cmd])
    for _ in range(data.draw(st.integers(1, 3), label="options")):
        flag, is_flag = data.draw(st.sampled_from(OPTIONS[cmd]), label="option")
        if is_flag:
            args.append(flag)
            continue
        value = data.draw(VALUES, label=flag)
        if flag in args:
            args[args.index(flag) + 1] = value
        else:
            args += [flag, value]
    _one_line_errors([*args, "--json"])


@FAST
@given(data=st.data())
def test_option_values(data):
    options_case(data)


@pytest.mark.slow
@LONG
@given(data=st.data())
def test_option_values_long(data):
    options_case(data)


# ---------------------------------------------------------------- configuration and system files
TOML_VALUES = st.one_of(
    st.integers(min_value=-(10**400), max_value=10**400).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(
        lambda x: "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf") if math.isinf(x) else repr(x)
    ),
    st.sampled_from(
        [
            '"9**9**9 mm"',
            '"1e200 m"',
            '"1e-320 kg*m^2"',
            '"-5 N/um"',
            '"2**10 m"',
            '"mm**m"',
            '""',
            '"((((((m))))))"',
            "[]",
            "{}",
            "true",
            '"µm"',
            '"20 deg"',
            '"3000 rpm"',
            '"7 N*m"',
            "[[1]]",
            '"' + "9" * 300 + ' mm"',
            "1979-05-27",
            '"m^99"',
            '"-0.1 mm"',
            "0",
            "-1",
            '"1 inch"',
        ]
    ),
    st.text(max_size=20).map(json.dumps),
)
EXAMPLE_FILES = sorted(p for p in EXAMPLES.glob("*.toml")) + sorted((EXAMPLES / "systems").glob("*.toml"))
ASSIGN = re.compile(r"^(\s*[A-Za-z_][\w]*\s*=\s*)(.+?)(\s*(#.*)?)$")


def mutate_toml(data, text: str) -> str:
    lines = text.splitlines()
    for _ in range(data.draw(st.integers(1, 3), label="mutations")):
        kind = data.draw(
            st.sampled_from(["value", "value", "value", "delete", "duplicate", "unknown", "truncate", "bom", "nest"]),
            label="mutation",
        )
        candidates = [i for i, ln in enumerate(lines) if ASSIGN.match(ln)]
        if kind == "value" and candidates:
            i = data.draw(st.sampled_from(candidates), label="line")
            m = ASSIGN.match(lines[i])
            lines[i] = m.group(1) + data.draw(TOML_VALUES, label="value")
        elif kind == "delete" and candidates:
            del lines[data.draw(st.sampled_from(candidates), label="line")]
        elif kind == "duplicate" and lines:
            i = data.draw(st.integers(0, len(lines) - 1), label="line")
            lines.insert(i, lines[i])
        elif kind == "unknown":
            lines.insert(data.draw(st.integers(0, len(lines)), label="line"), "zzz_unknown = 1")
        elif kind == "truncate":
            joined = "\n".join(lines)
            lines = joined[: data.draw(st.integers(0, len(joined)), label="cut")].splitlines()
        elif kind == "bom":
            lines = ["\ufeff" + (lines[0] if lines else "")] + lines[1:]
        elif kind == "nest":
            depth = data.draw(st.sampled_from([20, 1000, 100_000]), label="depth")
            lines.append("deep = " + "[" * depth + "]" * depth)
    return "\n".join(lines) + "\n"


def file_case(data, tmp_path: Path) -> None:
    src = data.draw(st.sampled_from(EXAMPLE_FILES), label="example")
    f = tmp_path / "mutated.toml"
    f.write_text(mutate_toml(data, src.read_text(encoding="utf-8")), encoding="utf-8")
    if src.parent.name == "systems":
        _one_line_errors(["modes", "--system", f, "--json"])
    else:
        cmd = data.draw(st.sampled_from(["geometry", "simulate"]), label="command")
        _one_line_errors([*(CHEAP[cmd]), "--config", f, "--json"])


@FAST
@given(data=st.data())
def test_config_and_system_files(data, tmp_path_factory):
    file_case(data, tmp_path_factory.mktemp("toml"))


@pytest.mark.slow
@LONG
@given(data=st.data())
def test_config_and_system_files_long(data, tmp_path_factory):
    file_case(data, tmp_path_factory.mktemp("toml"))


# ---------------------------------------------------------------- TE records
NUMBER_TEXT = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["1e308", "-1e308", "", "x", "1,5", "0x1p3", "1e-320"]),
)


def te_case(data, tmp_path: Path) -> None:
    n = data.draw(st.integers(0, 300), label="rows")
    phi = np.linspace(0.0, data.draw(st.sampled_from([0.1, 6.3, 100.0, 1e6]), label="span"), max(n, 1))
    rows = [f"{float(a)!r}, {float(np.cos(14 * a))!r}" for a in phi[:n]]
    for _ in range(data.draw(st.integers(0, 3), label="edits")):
        if rows:
            i = data.draw(st.integers(0, len(rows) - 1), label="row")
            rows[i] = data.draw(
                st.one_of(NUMBER_TEXT, st.tuples(NUMBER_TEXT, NUMBER_TEXT).map(", ".join), st.text(max_size=30)),
                label="new row",
            )
    header = data.draw(
        st.sampled_from(
            ["angle [rad], TE [um]", "time [s], TE [um]", "a, b", "", "t (ms); TE (µm)", "angle [furlong], TE [um]"]
        ),
        label="header",
    )
    f = tmp_path / "te.csv"
    f.write_text(header + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    args = [
        "te",
        f,
        "--teeth",
        data.draw(st.sampled_from(["14,39", "1,1", "0,3", "10001,2", "a,b", "14"]), label="teeth"),
    ]
    if data.draw(st.booleans(), label="rpm"):
        args += ["--rpm", data.draw(FLOATS, label="rpm value")]
    if data.draw(st.booleans(), label="harmonics"):
        args += ["--harmonics", data.draw(INTS, label="harmonics value")]
    _one_line_errors([*args, "--json"])


@FAST
@given(data=st.data())
def test_te_records(data, tmp_path_factory):
    te_case(data, tmp_path_factory.mktemp("te"))


@pytest.mark.slow
@LONG
@given(data=st.data())
def test_te_records_long(data, tmp_path_factory):
    te_case(data, tmp_path_factory.mktemp("te"))


# ---------------------------------------------------------------- result files
RESULT_COMMANDS = ["simulate", "orbit", "bifurcation", "map"]


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict[str, xr.Dataset]:
    d = tmp_path_factory.mktemp("results")
    out = {}
    for cmd in RESULT_COMMANDS:
        code, _, err = run([*CHEAP[cmd], "--out", d / cmd, "--json"])
        assert code == 0, err
        nc = sorted((d / cmd).glob("*.nc"))[0]
        with xr.open_dataset(nc, engine="h5netcdf") as ds:
            out[cmd] = ds.load()
    return out


KINDS = st.sampled_from(
    [
        "simulate",
        "bifurcation",
        "response",
        "map",
        "basins",
        "orbit",
        "continuation",
        "lyapunov",
        "runup",
        "hb",
        "reproduce",
        "",
        "x" * 300,
        "ω",
    ]
)
ATTR_VALUES = st.one_of(
    st.text(max_size=30),
    KINDS,
    st.integers(-(10**18), 10**18),
    st.floats(allow_nan=True),
    st.sampled_from(["{", "[]", "{}", "null", '{"omega": "x"}', "[" * 5000 + "]" * 5000, '{"a": 1e999}']),
    st.just(np.zeros(20_000)),
)


def result_case(data, results, tmp_path: Path) -> None:
    cmd = data.draw(st.sampled_from(RESULT_COMMANDS), label="result")
    ds = results[cmd].copy()
    for _ in range(data.draw(st.integers(1, 3), label="mutations")):
        kind = data.draw(st.sampled_from(["drop", "kind", "attr", "attr", "rename", "retype"]), label="mutation")
        names = list(ds.data_vars)
        if kind == "drop" and names:
            ds = ds.drop_vars(data.draw(st.sampled_from(names), label="variable"))
        elif kind == "kind":
            ds.attrs["geardyn_kind"] = data.draw(KINDS, label="kind")
        elif kind == "attr":
            keys = sorted(ds.attrs) or ["model"]
            key = data.draw(st.sampled_from(keys), label="attribute")
            ds.attrs[key] = data.draw(ATTR_VALUES, label="attribute value")
        elif kind == "rename" and names:
            v = data.draw(st.sampled_from(names), label="variable")
            ds = ds.rename({v: v + "_x"})
        elif kind == "retype" and names:
            v = data.draw(st.sampled_from(names), label="variable")
            try:
                ds[v] = ds[v].astype("U4") if data.draw(st.booleans(), label="to text") else ds[v].astype("int8")
            except (ValueError, TypeError):  # (text that is no number stays text)
                pass
    f = tmp_path / "mutated.nc"
    try:
        ds.to_netcdf(f, engine="h5netcdf")
    except (ValueError, TypeError, OverflowError):  # not writable as NetCDF: nothing to read back
        return
    _one_line_errors(["plot", f, "--out", tmp_path / "fig", "--json"])


@FAST_FILES
@given(data=st.data())
def test_result_files(data, results, tmp_path_factory):
    result_case(data, results, tmp_path_factory.mktemp("nc"))


@pytest.mark.slow
@LONG
@given(data=st.data())
def test_result_files_long(data, results, tmp_path_factory):
    result_case(data, results, tmp_path_factory.mktemp("nc"))
