"""Bad input is refused with one line naming the parameter (or file and line), exit code 2 (DESIGN §7).

Property-based tests throw random values, parameter names and configuration files at the
validation layer: it either accepts them or raises ModelError naming what is wrong, never
another exception.  The command-line cases check the one-line message and the exit code.
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_run import run_cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from geardyn import validate
from geardyn.config import LoadedConfig, load_config, packaged_config_path
from geardyn.errors import ConfigError
from geardyn.grid import param_name
from geardyn.model import GearModel, IntegrationOptions, ModelError, canonical_param

SETTINGS = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
CONFIG_SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture]
)

VALID_NAMES = [
    "omega",
    "xi0",
    "xi1",
    "xi2",
    "kappa1",
    "kappa3",
    "fp",
    "eps1",
    "eps2",
    "fe",
    "D",
    "backlash",
    "b",
    "phi_c1",
    "phi_k2",
    "phi_e1",
    "phi_e3",
    "xi64",
    "xi65",
    "kappa0",
    "eps",
    "phi_c0",
]
TEXT = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=12)
NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-3, max_value=3),
    st.integers(min_value=-(10**400), max_value=10**400),
    st.integers(min_value=-5, max_value=5),
)
ANY_VALUE = st.one_of(
    NUMBERS,
    TEXT,
    st.none(),
    st.booleans(),
    st.complex_numbers(max_magnitude=10),
    st.lists(st.floats(allow_nan=True), max_size=3),
    st.dictionaries(TEXT, st.integers(), max_size=2),
    st.just(np.float64("nan")),
    st.just(np.int64(3)),
    st.just(np.bool_(True)),
)


def family(name: str) -> set[str]:
    """Words a message about parameter ``name`` may use to name it."""
    words = {name}
    try:
        c = canonical_param(name)
    except ModelError:
        return words
    words.add(c)
    words.add(re.sub(r"\d+$", "", c))
    if c == "D":
        words.add("backlash")
    return words


def names_parameter(msg: str, words: set[str]) -> bool:
    head = msg.split(":", 1)[0]
    return any(w in head for w in words) or any(repr(w) in msg for w in words)


def _by_name(values: dict) -> GearModel:
    """The paper's model with ``values`` set by parameter name, as the command line sets its model options."""
    m = GearModel()
    for name, value in values.items():
        m = m.with_param(name, value)
    return m


@pytest.mark.parametrize(
    "amp, ph, label", [("xi", "phi_c", "xi"), ("kappa", "phi_k", "kappa"), ("eps", "phi_e", "eps")]
)
def test_phases_for_fewer_harmonics_than_amplitudes_are_refused(amp, ph, label):
    with pytest.raises(ModelError, match=rf"^{ph}: 1 phases given for 2 {label} harmonics") as e:
        GearModel(**{amp: (0.2, 0.1), ph: (0.0,)})
    assert "\n" not in str(e.value)


def test_phases_left_out_are_zero_and_follow_the_amplitudes_a_copy_changes():
    assert GearModel(kappa=(0.2, 0.1)).phi_k == (0.0, 0.0)  # none given: every phase 0
    m = GearModel(kappa=(0.2, 0.1), phi_k=(0.3, -0.4))
    assert m.replace(kappa=(0.1, 0.05, 0.02)).phi_k == (0.3, -0.4, 0.0)  # kept, the new harmonic at 0
    assert GearModel().replace(kappa=(0.2, 0.1)).phi_k == (0.0, 0.0)
    assert GearModel(kappa=(0.2, 0.1)).replace(kappa=(0.3,)).phi_k == (0.0,)  # zero phases cut with their harmonic
    with pytest.raises(ModelError, match="^phi_k: 2 phases given for 1 kappa harmonics"):
        m.replace(kappa=(0.3,))  # a phase of its own is never dropped silently
    assert GearModel().with_param("kappa3", 0.05).phi_k == (0.0, 0.0, 0.0)


# ---------------------------------------------------------------------------------- property tests
@SETTINGS
@given(st.dictionaries(st.one_of(st.sampled_from(VALID_NAMES), TEXT), ANY_VALUE, max_size=4))
def test_model_values_accepted_or_refused_by_name(params):
    try:
        m = _by_name(params)
    except ModelError as e:
        msg = str(e)
        assert "\n" not in msg
        words = set().union(*(family(n) for n in params)) if params else set()
        assert names_parameter(msg, words), msg
        return
    assert isinstance(m, GearModel)
    for name, value in params.items():  # what was accepted is what was asked for
        assert math.isclose(m.get(canonical_param(name)), float(value), rel_tol=0, abs_tol=0)


@SETTINGS
@given(st.sampled_from(VALID_NAMES[:13]), NUMBERS)
def test_one_parameter_at_a_time(name, value):
    try:
        m = _by_name({name: value})
    except ModelError as e:
        assert names_parameter(str(e), family(name)), str(e)
    else:
        assert m.get(canonical_param(name)) == float(value)


@SETTINGS
@given(
    ANY_VALUE,
    ANY_VALUE,
    ANY_VALUE,
    ANY_VALUE,
    st.lists(st.one_of(st.floats(min_value=1e-12, max_value=1e12), st.floats(allow_nan=True)), max_size=3),
)
def test_options_accepted_or_refused_by_name(dtau, transient, periods, accurate, omegas):
    try:
        o = validate.options(dtau, transient, periods, accurate, omegas)
    except ModelError as e:
        assert str(e).split(":", 1)[0] in ("dtau", "transient", "periods", "accurate", "omega"), str(e)
        return
    assert isinstance(o, IntegrationOptions)
    assert o.dtau > 0 and o.transient >= 0 and o.periods >= 1
    for w in omegas:
        assert o.dtau < 2 * math.pi / w


@SETTINGS
@given(st.one_of(st.sampled_from(VALID_NAMES), TEXT, st.none(), st.integers()), ANY_VALUE, ANY_VALUE, ANY_VALUE)
def test_sweep_axis_accepted_or_refused_by_name(param, start, stop, num):
    try:
        name, values = validate.axis(param, start, stop, num)
    except ModelError as e:
        head = str(e).split(":", 1)[0]
        assert head in ("param", "start", "stop", "num", "start/stop") or "unknown parameter" in str(e), str(e)
        return
    assert values.size == int(num) >= 1 and np.all(np.isfinite(values))
    assert name == param_name(param)  # the pair's canonical name, or a system's <element>.<name>
    if "." in param:  # both parts given (not ".", "a." or ".b")
        elem, _, p = param.rpartition(".")
        assert elem.strip() and p.strip(), param


@pytest.mark.parametrize("param", [".", "a.", ".kappa1", " . ", "m 1.kappa1"])
def test_a_qualified_name_needs_both_parts(param):
    with pytest.raises(ModelError, match="^param: "):
        validate.axis(param, 3, 3, 3)


@SETTINGS
@given(
    st.lists(
        st.tuples(
            st.sampled_from(["omega", "xi0", "kappa1", "D", "fp", "phi_e2"]),
            st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3),
        ),
        max_size=2,
    ),
    st.sampled_from([None, IntegrationOptions(), IntegrationOptions(dtau=2.0)]),
)
def test_grid_accepted_or_refused_by_name(axes, opts):
    try:
        models = validate.grid(GearModel(), axes, opts)
    except ModelError as e:
        words = {"grid", "dtau", "omega"}.union(*(family(p) for p, _ in axes)) if axes else {"grid"}
        assert names_parameter(str(e), words), str(e)
        return
    assert len(models) == int(np.prod([len(v) for _, v in axes]))


@SETTINGS
@given(ANY_VALUE, ANY_VALUE)
def test_engine_settings_accepted_or_refused_by_name(workers, address):
    for fn, name, value in (
        (validate.workers, "workers", workers),
        (validate.scheduler, "scheduler", address),
        (validate.chunk_points, "chunk size", workers),
    ):
        try:
            fn(value)
        except ModelError as e:
            assert str(e).startswith(name + ":"), str(e)


# ---------------------------------------------------------------------------------- configuration files
PAPER = tomllib.loads(packaged_config_path().read_text(encoding="utf-8"))
SECTIONS = ["gear_pair", "mesh", "operating", "model", "title", "bogus"]
KEYS = sorted(
    {k for s in PAPER.values() if isinstance(s, dict) for k in s}
    | {"omega", "D", "xi", "c0", "k0", "torque", "rpm", "characteristic_length", "unknown_key"}
)
TOML_VALUES = st.recursive(
    st.one_of(
        NUMBERS.filter(lambda x: not isinstance(x, int) or abs(x) < 2**63),
        st.booleans(),
        TEXT,
        st.sampled_from(
            [
                "7 mm",
                "35 deg",
                "1 kg*m^2",
                "3000 rpm",
                "0.5 rad",
                "-1 mm",
                "nan mm",
                "1 N*m",
                "20 N/(mm*um)",
                "2 s",
                "x mm",
                "0 rpm",
                "1e999 m",
                "",
            ]
        ),
    ),
    lambda inner: st.one_of(
        st.lists(inner, max_size=3), st.fixed_dictionaries({"value": inner}, optional={"assumed": TEXT})
    ),
    max_leaves=4,
)


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{json.dumps(str(k))} = {toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))


def toml_text(doc: dict) -> str:
    top = [f"{json.dumps(k)} = {toml_value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    tables = [
        f"[{json.dumps(k)}]\n" + "\n".join(f"{json.dumps(kk)} = {toml_value(vv)}" for kk, vv in v.items())
        for k, v in doc.items()
        if isinstance(v, dict)
    ]
    return "\n".join(top + tables) + "\n"


mutations = st.lists(
    st.tuples(
        st.sampled_from(SECTIONS),
        st.one_of(st.sampled_from(KEYS), TEXT.filter(bool)),
        st.one_of(st.just("delete"), TOML_VALUES),
    ),
    max_size=4,
)


def mutate(doc: dict, changes) -> dict:
    doc = json.loads(json.dumps(doc))
    for section, key, value in changes:
        if section == "title":
            doc["title"] = value if value != "delete" else doc.pop("title", None)
            continue
        table = doc.setdefault(section, {})
        if not isinstance(table, dict):
            continue
        if value == "delete":
            table.pop(key, None)
        else:
            table[key] = value
    return {k: v for k, v in doc.items() if v is not None}


def refused_with_file_and_one_line(msg: str, path: Path) -> bool:
    return "\n" not in msg and msg.startswith(str(path) + ":")


@CONFIG_SETTINGS
@given(mutations)
def test_random_configs_accepted_or_refused_naming_the_file(tmp_path, changes):
    path = tmp_path / "pair.toml"
    path.write_text(toml_text(mutate(PAPER, changes)), encoding="utf-8")
    try:
        cfg = load_config(path)
    except (ConfigError, ModelError) as e:
        assert refused_with_file_and_one_line(str(e), path), str(e)
        return
    assert isinstance(cfg, LoadedConfig) and isinstance(cfg.model, GearModel)


@CONFIG_SETTINGS
@given(st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=80))
def test_random_text_as_config_is_refused_naming_the_file(tmp_path, text):
    path = tmp_path / "junk.toml"
    path.write_text(text, encoding="utf-8")
    try:
        load_config(path)
    except (ConfigError, ModelError) as e:
        assert refused_with_file_and_one_line(str(e), path), str(e)


@CONFIG_SETTINGS
@given(mutations)
def test_random_configs_through_the_cli(tmp_path, changes):
    path = tmp_path / "pair.toml"
    path.write_text(toml_text(mutate(PAPER, changes)), encoding="utf-8")
    code, out, err = run_cli(["geometry", "--config", str(path), "--json"])
    assert code in (0, 2), err
    if code == 2:
        assert one_line(err).startswith(f"error: {path}:"), err
    else:
        assert json.loads(out)["source"] == str(path)


# ---------------------------------------------------------------------------------- command line


def one_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture(scope="module")
def configs(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("configs")
    paper = packaged_config_path().read_text(encoding="utf-8")
    files = {
        "unknown_key": paper.replace("[operating]", "[operating]\nspeed = 3000"),
        "unknown_section": paper + "\n[gearbox]\nstages = 2\n",
        "syntax": paper.replace("z2 = 47", "z2 = = 47"),
        "unclosed": "[model\nomega = 1\n",
        "wrong_unit": paper.replace('m_mn = "7.28 mm"', 'm_mn = "7.28 kg"'),
        "nonfinite": paper.replace("xi0 = 0.1 ", "xi0 = nan "),
        "negative_backlash": paper.replace('j_n = "0.1 mm"', 'j_n = "-0.1 mm"'),
        "bad_model_omega": paper + "\n[model]\nomega = -1\n",
        "bad_model_key": paper + "\n[model]\nomegaa = 1\n",
        "short_phases": paper.replace("kappa = [0.2] ", "kappa = [0.2, 0.1]"),
    }
    out = {}
    for k, text in files.items():
        out[k] = d / f"{k}.toml"
        out[k].write_text(text, encoding="utf-8")
    out["directory"] = d
    out["missing"] = d / "missing.toml"
    return out


SIM = ["simulate", "--transient", "5", "--periods", "2"]
BIF = ["bifurcation", "--num", "3", "--transient", "5", "--periods", "2", "--settle", "0", "--json"]

# (argv, words the one line must contain)
CLI_CASES = {
    "omega_nan": (SIM + ["--omega", "nan"], ["omega", "finite"]),
    "omega_inf": (SIM + ["--omega", "inf"], ["omega", "finite"]),
    "xi0_inf": (SIM + ["--xi0", "-inf"], ["xi0", "finite"]),
    "fp_nan": (SIM + ["--fp", "nan"], ["fp", "finite"]),
    "u0_nan": (SIM + ["--u0", "nan"], ["u0", "finite"]),
    "omega_zero": (SIM + ["--omega", "0"], ["omega", "> 0"]),
    "omega_negative": (SIM + ["--omega", "-1"], ["omega", "> 0"]),
    "omega_tiny": (SIM + ["--omega", "1e-12"], ["dtau", "steps per forcing period"]),
    "dtau_zero": (SIM + ["--dtau", "0"], ["dtau", "> 0"]),
    "dtau_negative": (SIM + ["--dtau", "-0.01"], ["dtau", "> 0"]),
    "dtau_ge_period": (SIM + ["--omega", "2", "--dtau", "3.2"], ["dtau", "forcing period"]),
    "periods_negative": (["simulate", "--periods", "-3"], ["periods", ">= 1"]),
    "periods_zero": (["simulate", "--periods", "0"], ["periods", ">= 1"]),
    "transient_negative": (["simulate", "--transient", "-1"], ["transient", ">= 0"]),
    "backlash_negative": (SIM + ["--backlash", "-0.5"], ["backlash", ">= 0"]),
    "kappa_too_large": (SIM + ["--kappa1", "1.2"], ["kappa", "< 1"]),
    "omega_not_a_number": (SIM + ["--omega", "abc"], ["--omega", "number"]),
    "transient_not_an_integer": (["simulate", "--transient", "1.5"], ["--transient", "integer"]),
    "unknown_option": (SIM + ["--omgea", "1"], ["--omgea"]),
    "missing_value": (SIM + ["--omega"], ["--omega", "argument"]),
    "unknown_command": (["simulat"], ["simulat"]),
    "unknown_parameter": (BIF + ["--param", "omegaa", "--start", "0.5", "--stop", "1"], ["omegaa", "allowed"]),
    "unknown_map_axis": (
        ["map", "--x", "omega", "--x-start", "0.5", "--x-stop", "1", "--y", "zeta", "--y-start", "0", "--y-stop", "1"],
        ["zeta", "unknown parameter"],
    ),
    "empty_grid": (BIF + ["--param", "omega", "--start", "0.5", "--stop", "1", "--num", "0"], ["num", ">= 1"]),
    "grid_crosses_omega_zero": (BIF + ["--param", "omega", "--start", "-0.5", "--stop", "1"], ["omega", "> 0"]),
    "grid_start_nan": (BIF + ["--param", "xi0", "--start", "nan", "--stop", "1"], ["start", "finite"]),
    "workers_zero": (
        BIF + ["--param", "omega", "--start", "0.5", "--stop", "1", "--workers", "0"],
        ["workers", ">= 1"],
    ),
    "chunk_size_zero": (
        BIF + ["--param", "omega", "--start", "0.5", "--stop", "1", "--chunk-size", "0"],
        ["chunk size", ">= 1"],
    ),
    "scheduler_garbage": (
        BIF + ["--param", "omega", "--start", "0.5", "--stop", "1", "--scheduler", "not an address"],
        ["scheduler", "tcp://HOST:PORT"],
    ),
    "resume_without_out": (
        BIF + ["--param", "omega", "--start", "0.5", "--stop", "1", "--resume"],
        ["resume", "--out"],
    ),
}


@pytest.mark.parametrize("case", sorted(CLI_CASES))
def test_cli_refuses_bad_values_in_one_line(case):
    argv, words = CLI_CASES[case]
    code, out, err = run_cli(argv)
    assert code == 2, (code, err)
    line = one_line(err)
    assert line.startswith("error: ")
    for w in words:
        assert w in line, line


CONFIG_CASES = {
    "missing": ["not found"],
    "directory": ["not found", "directory"],
    "unknown_key": ["line", "[operating]", "speed", "unknown key", "allowed"],
    "unknown_section": ["gearbox", "allowed"],
    "syntax": ["line {z2}", "TOML syntax error"],
    "unclosed": ["line 1", "TOML syntax error"],
    "wrong_unit": ["m_mn", "length"],
    "nonfinite": ["xi0", "finite"],
    "negative_backlash": ["j_n"],
    "bad_model_omega": ["[model]", "omega", "> 0"],
    "bad_model_key": ["[model]", "omegaa", "unknown key"],
    "short_phases": ["[mesh]", "phi_k", "1 phases given for 2 kappa harmonics"],
}


@pytest.mark.parametrize("case", sorted(CONFIG_CASES))
@pytest.mark.parametrize("command", [["simulate", "--transient", "5", "--periods", "2"], ["geometry"]])
def test_cli_refuses_bad_config_files_in_one_line(configs, case, command):
    path = configs[case]
    code, out, err = run_cli(command + ["--config", str(path)])
    assert code == 2, (code, err)
    line = one_line(err)
    assert line.startswith(f"error: {path}:"), line
    z2 = 1 + packaged_config_path().read_text(encoding="utf-8").splitlines().index(
        next(ln for ln in packaged_config_path().read_text(encoding="utf-8").splitlines() if ln.startswith("z2 ="))
    )
    for w in CONFIG_CASES[case]:
        assert w.format(z2=z2) in line, line


def test_cli_bad_config_lines_point_at_the_right_line(configs):
    text = configs["unknown_key"].read_text().splitlines()
    code, out, err = run_cli(["geometry", "--config", str(configs["unknown_key"])])
    n = int(re.search(r": line (\d+):", one_line(err)).group(1))
    assert text[n - 1].startswith("speed")


def test_cli_errors_are_not_wrapped_on_narrow_terminals(monkeypatch):
    monkeypatch.setenv("COLUMNS", "40")
    code, out, err = run_cli(SIM + ["--omega", "-1", "--xi0", "0.1"])
    assert code == 2 and len(one_line(err)) > 40


@pytest.mark.parametrize(
    "args, message",
    [
        (["--dtau", "0"], "dtau: must be > 0 and smaller than the forcing period 2π/ω, got 0.0"),
        (["--transient", "-1"], "transient: must be an integer >= 0 and <= 100000000, got -1"),
        (["--periods", "0"], "periods: must be an integer >= 1 and <= 100000000, got 0"),
        (["--transient", "-1", "--periods", "2"], "transient: must be an integer >= 0 and <= 100000000, got -1"),
    ],
)
def test_impossible_counts_of_a_long_forcing_period_are_refused_before_any_note(args, message):
    # the gearbox's forcing period spans 1472 mesh cycles: its notes (the forcing period, the long run's counts)
    # were said first, built on the impossible count ("transient: -1 forcing periods (-1,472 mesh cycles)")
    system = str(Path(__file__).resolve().parents[1] / "examples" / "gearbox" / "two_stage_helical.toml")
    code, out, err = run_cli(["simulate", "--system", system, *args])
    assert code == 2
    assert err.strip().splitlines() == [f"error: {message}"], err
