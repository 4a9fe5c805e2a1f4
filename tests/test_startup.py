"""What a short command imports: ``geardyn --help`` none of the commands, NumPy, numba or the libraries typer
imports for Markdown, tracebacks and validation; ``geardyn simulate --json`` only its own command module
and the one compiled kernel it runs.  Import discipline, not timing (the times are measured by
``benchmarks/startup.py``)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from geardyn.cli import _commands, _listing

#: Modules no command needs: typer imports them for Markdown help texts, pretty tracebacks and validation.
TYPER_EXTRAS = ("rich.markdown", "rich.traceback", "pydantic", "typer._adapters")
OTHER_COMMAND_MODULES = tuple(f"geardyn.cli.{m}" for m in _commands.MODULES if m != "point")


def _run(args: list[str], *, preload: bool = False, report: str = "") -> subprocess.CompletedProcess:
    """``geardyn ARGS`` in a fresh interpreter (with every command module imported first if ``preload``);
    ``report`` is Python code run after the command, printing on stderr."""
    code = (
        "import sys\n"
        + ("from geardyn.cli import app\n" if preload else "")
        + "from geardyn.cli import main\n"
        + f"try:\n    main({args!r})\nexcept SystemExit as e:\n    assert not e.code, e.code\n"
        + report
    )
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env={**os.environ, "COLUMNS": "100"}
    )


_WARMED: set[tuple[str, ...]] = set()


def _warm(args: list[str]) -> None:
    """Run ``geardyn ARGS`` once per test process: in a fresh checkout this compiles its kernels into numba's
    cache, which the tests then read."""
    if tuple(args) not in _WARMED:
        _run(args)
        _WARMED.add(tuple(args))


def _imported(names: tuple[str, ...]) -> str:
    return f"print(sorted(m for m in {names!r} if m in sys.modules), file=sys.stderr)\n"


def test_help_imports_no_command_nor_numpy_numba_or_typer_extras():
    names = (
        "numpy",
        "numba",
        "scipy",
        "geardyn.model",
        "geardyn.cli.options",
        "geardyn.cli.point",
        *OTHER_COMMAND_MODULES,
        *TYPER_EXTRAS,
    )
    r = _run(["--help"], report=_imported(names))
    assert r.stderr.strip().splitlines()[-1] == "[]"
    assert "simulate" in r.stdout and "signature" in r.stdout


@pytest.mark.parametrize("args", [["--help"], ["simulate", "--help"], ["hb", "--help"]])
def test_help_screens_are_those_of_the_app_with_every_command_imported(args):
    assert _run(args).stdout == _run(args, preload=True).stdout


def test_the_command_list_is_current():
    """``geardyn --help`` lists the commands from ``cli/_commands.py``: it is what the commands say
    (``python docs/gen_cli.py`` rewrites it)."""
    assert _commands.COMMANDS == _listing.table()


def test_simulate_imports_its_command_and_one_compiled_kernel_only():
    report = (
        _imported((*OTHER_COMMAND_MODULES, *TYPER_EXTRAS, "xarray", "pandas", "dask", "matplotlib", "pint"))
        + "from numba.core.dispatcher import Dispatcher\n"
        "print(sorted({v.py_func.__qualname__ for n, m in list(sys.modules.items()) if n.startswith('geardyn.')"
        " for v in vars(m).values() if isinstance(v, Dispatcher) and v.overloads}), file=sys.stderr)\n"
    )
    args = ["simulate", "--omega", "0.8", "--transient", "20", "--periods", "4", "--json"]
    _warm(args)
    r = _run(args, report=report)
    *_, modules, kernels = r.stderr.strip().splitlines()
    assert modules == "[]"
    assert kernels == "['_scalar_worker']"
    assert json.loads(r.stdout)["omega"] == 0.8


SIMULATE = ["simulate", "--omega", "0.8", "--transient", "20", "--periods", "4", "--json"]


def test_a_cached_worker_is_loaded_without_numbas_compiler():
    """From a warm cache, neither numba's lowering registries nor scipy.linalg (which they import) are imported."""
    _warm(SIMULATE)
    r = _run(SIMULATE, report=_imported(("numba.np.arraymath", "numba.np.linalg", "scipy.linalg")))
    assert r.stderr.strip().splitlines()[-1] == "[]"


@pytest.mark.parametrize(
    "args", [SIMULATE, ["lyapunov", "--omega", "0.8", "--transient", "20", "--periods", "50", "--json"]]
)
def test_the_fast_load_gives_the_bits_of_numbas_own_load(args):
    """The same output, every digit, whether the worker is read from the cache by ``fast_loads`` or by numba
    (its compiler set up first)."""
    own = "import geardyn._cache_guard as g\ng.fast_loads = lambda *workers: None\n"
    code = own + f"from geardyn.cli import main\nmain({args!r})\n"
    _warm(args)
    numba_load = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert _run(args).stdout == numba_load
    assert json.loads(numba_load)["omega"] == 0.8


def test_a_failing_fast_load_falls_back_to_numbas_own():
    from geardyn._cache_guard import fast_loads

    calls = []

    class Cache:
        def load_overload(self, sig, ctx):
            calls.append(("numba", sig))
            return "loaded"

        def _load_overload(self, sig, ctx):
            raise RuntimeError("not readable this way")

        def _guard_against_spurious_io_errors(self):
            raise AssertionError("not reached")

    class Worker:
        _cache = Cache()

    from numba.core.registry import cpu_target

    w = Worker()
    fast_loads(w)
    fast_loads(w)  # a second call: no second wrapper
    assert w._cache.load_overload("sig", cpu_target.target_context) == "loaded"
    assert calls == [("numba", "sig")]


# The conversion of option values without pydantic gives what typer's own conversion gives.
_TYPER = {}


def _typer_value(annotation: type, text: str):
    """``text`` converted by typer's own conversion for an option of type ``annotation`` (or the exception)."""
    from typer._coercion import build_runtime_param, resolve_type_descriptor
    from typer.models import OptionInfo

    if annotation not in _TYPER:
        _TYPER[annotation] = build_runtime_param(resolve_type_descriptor(annotation, OptionInfo()))
    try:
        return _TYPER[annotation]._coerce_value(text, param=None, ctx=None)
    except Exception as e:  # noqa: BLE001  (compared by type)
        return type(e)


def _check(annotation: type, value) -> bool:
    """Whether ``value`` is converted without typer's conversion (then: to what typer converts it to)."""
    app = sys.modules["geardyn.cli.app"]
    got = app._direct(annotation, value)
    if got is app._direct:
        return False  # left to typer's conversion
    want = _typer_value(annotation, value)
    assert type(got) is type(want), (value, got, want)
    if isinstance(got, float):
        assert got.hex() == want.hex() or (math.isnan(got) and math.isnan(want)), (value, got, want)
    else:
        assert got == want, (value, got, want)
    return True


NUMBERS = st.one_of(
    st.from_regex(r"-?[0-9]{1,25}(\.[0-9]{1,25})?([eE][-+]?[0-9]{1,4})?", fullmatch=True),
    st.floats(allow_nan=False).map(repr),
    st.integers(-(10**20), 10**20).map(str),
    st.text(alphabet="0123456789+-.eE_ x", max_size=12),
)


@settings(max_examples=400, derandomize=True, deadline=None)
@given(NUMBERS)
def test_numbers_are_converted_as_typer_converts_them(text):
    assert _check(str, text)
    _check(float, text)
    _check(int, text)


@pytest.mark.parametrize("text", ["0.8", "-2", "1e-3", "1E+300", "1e400", "007", "-0"])
def test_plain_numbers_are_converted_directly(text):
    assert _check(float, text)


@pytest.mark.parametrize("text", [" 0.8", "+1", "1_0", ".5", "5.", "nan", "inf", "0x10", "1,5"])
def test_other_spellings_are_left_to_typer(text):
    assert not _check(float, text) and not _check(int, text)


@pytest.mark.parametrize(
    "annotation, value, direct",
    [
        (float, 0.8, True),
        (float, 3, True),
        (float, -0.0, True),
        (int, 7, True),
        (str, "x", True),
        (bool, True, True),
        (bool, False, True),
        (float, True, False),
        (int, False, False),
        (float, None, False),
    ],
)
def test_defaults_are_kept_as_typer_keeps_them(annotation, value, direct):
    assert _check(annotation, value) is direct
