"""Meta-tests of the public API: documented parameters, no blanket keywords, a test file per module.

The public API is what the modules export in ``__all__``.  Every public function and class has a
numpydoc docstring whose ``Parameters`` section (``Attributes`` for a data class) names every
parameter of its signature; a public function takes ``**kwargs`` only where it forwards them to a
function that refuses unknown keywords, and documents them; and ``tests/`` mirrors the package.
"""

from __future__ import annotations

import enum
import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import pytest

import geardyn
from geardyn.model import GearModel

TESTS = Path(__file__).parent

# Modules whose docstrings are completed in parallel (their files are edited elsewhere); the lead
# empties this list after merging.  Everything else must pass.
KNOWN_GAPS: tuple[str, ...] = ()

# Public callables that take **kwargs, each with the function that receives them (and refuses an
# unknown keyword: TypeError, or AttributeError from matplotlib's property setters).
FORWARDING = {
    "geardyn.analysis.bifurcation.bifurcation": "geardyn.sweep.SweepOptions.merge",
    "geardyn.analysis.maps.parameter_map": "geardyn.sweep.SweepOptions.merge",
    "geardyn.analysis.basins.basins": "geardyn.sweep.SweepOptions.merge",
    "geardyn.analysis.response.frequency_response": "geardyn.sweep.SweepOptions.merge",
    "geardyn.analysis.points.sweep_function": "the decorator's keyword check",
    "geardyn.analysis.points.result_dataset": "geardyn.io.result_attrs",
    "geardyn.sweep.engine.run_chunks": "geardyn.sweep.SweepOptions.merge",
    "geardyn.cli.options.build_model": "its own check of the registry's option names",
    "geardyn.plot.common.new_figure": "matplotlib.figure.Figure",
    "geardyn.plot.common.panels": "matplotlib.pyplot.subplots",
}

# Modules whose tests live in a file named after what they test rather than after the module.
COVERED_BY = {
    "geardyn._forkserver_quiet": "test_signals_start.py",
    "geardyn.cli.ranges": "test_plausible.py",
    "geardyn.accessor": "test_plot_cli.py",
    "geardyn._accessor_hook": "test_plot_cli.py",
    "geardyn._lazy": "test_plot_cli.py",
    "geardyn.atomic": "fuzz/test_issue_items.py",
    "geardyn._packaged_quantities": "test_config.py",
    "geardyn.analysis._converted": "test_physical.py",
    "geardyn.bench": "test_kernel_perf.py",
    "geardyn.integrate": "test_core.py",
    "geardyn.model": "test_core.py",
    "geardyn.units": "test_physical.py",
    "geardyn.torque_orders": "test_orders.py",
    "geardyn.validate": "test_bad_input.py",
    "geardyn._kernel": "test_core.py",
    "geardyn._kernel_ndof": "test_ndof.py",
    "geardyn._config_values": "test_config.py",
    "geardyn.backend": "test_conformance.py",
    "geardyn.labels": "test_sweeps.py",
    "geardyn.systems.elements": "test_ndof.py",
    "geardyn.analysis": "test_sweeps.py",
    "geardyn.analysis.basins": "test_sweeps.py",
    "geardyn.analysis.bifurcation": "test_sweeps.py",
    "geardyn.analysis.maps": "test_sweeps.py",
    "geardyn.analysis.response": "test_sweeps.py",
    "geardyn.analysis.points": "test_sweeps.py",
    "geardyn.analysis.classify": "test_sweeps.py",
    "geardyn.analysis.steady": "test_sweeps.py",
    "geardyn.analysis.secant": "test_periodic.py",
    "geardyn.cli": "test_plot_cli.py",
    "geardyn.paper": "test_reproduce.py",
    "geardyn.plot": "test_figures.py",
    "geardyn.standards": "test_iso10300.py",
    "geardyn.standards.stiffness": "test_stiffness_harmonics.py",
    "geardyn.standards.iso6336": "test_iso10300.py",
    "geardyn.sweep": "test_sweep_engine.py",
}

SECTION_END = re.compile(
    r"^(Returns|Yields|Raises|Attributes|Parameters|Notes|References|Examples|See Also|Warns|Other Parameters)\n-{3,}$",
    re.M,
)


def _modules() -> list:
    out = []
    for info in pkgutil.walk_packages(geardyn.__path__, "geardyn."):
        if info.name.endswith("__main__"):
            continue
        out.append(importlib.import_module(info.name))
    return out


MODULES = _modules()


def _public() -> list[tuple[str, object]]:
    items = []
    for mod in MODULES:
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name, None)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__ == mod.__name__:
                items.append((f"{mod.__name__}.{name}", obj))
    return items


PUBLIC = _public()


def _documented(doc: str, section: str) -> set[str] | None:
    """Names listed in a numpydoc section (``a, b : type`` and ``**kw`` lines), or None if absent."""
    m = re.search(rf"^{section}\n-{{3,}}$", doc, re.M)
    if m is None:
        return None
    rest = doc[m.end() :]
    end = SECTION_END.search(rest)
    body = rest[: end.start()] if end else rest
    names: set[str] = set()
    for line in body.splitlines():
        if not line or line[0].isspace():
            continue
        head = line.split(" : ", 1)[0]
        names.update(n.strip().lstrip("*") for n in head.split(","))
    return names


def _parameters(obj: object) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p for p in sig.parameters if p not in ("self", "cls")]


def _skipped(obj: object) -> bool:
    """Enumerations and protocols: their signatures are their metaclass's, not theirs."""
    return inspect.isclass(obj) and (issubclass(obj, enum.Enum) or bool(getattr(obj, "_is_protocol", False)))


def _known_gap(qualname: str) -> bool:
    return qualname.startswith(KNOWN_GAPS)


@pytest.mark.parametrize("qualname, obj", PUBLIC, ids=[q for q, _ in PUBLIC])
def test_public_names_document_every_parameter(qualname: str, obj: object) -> None:
    if _known_gap(qualname) or _skipped(obj):
        pytest.skip("known gap (see KNOWN_GAPS)" if _known_gap(qualname) else "enum or protocol")
    doc = inspect.getdoc(obj)
    assert doc, f"{qualname}: no docstring"
    params = _parameters(obj)
    if not params:
        return
    listed = _documented(doc, "Parameters")
    if listed is None and inspect.isclass(obj):
        listed = _documented(doc, "Attributes")
    assert listed is not None, f"{qualname}: no Parameters section for {params}"
    missing = [p for p in params if p not in listed]
    assert not missing, f"{qualname}: parameters not documented: {missing}"


def test_known_gaps_are_only_files_edited_elsewhere() -> None:
    # the list names packages and modules, never single functions of the files checked here
    assert all(entry.endswith(".") for entry in KNOWN_GAPS)
    assert not any(
        entry.startswith(("geardyn.analysis.periodic", "geardyn.geometry", "geardyn.io")) for entry in KNOWN_GAPS
    )


def _var_keyword(obj: object) -> str | None:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    return next((p.name for p in sig.parameters.values() if p.kind is p.VAR_KEYWORD), None)


@pytest.mark.parametrize(
    "qualname, obj",
    [(q, o) for q, o in PUBLIC if inspect.isfunction(o)],
    ids=[q for q, o in PUBLIC if inspect.isfunction(o)],
)
def test_no_blanket_keywords_unless_forwarded_and_documented(qualname: str, obj: object) -> None:
    name = _var_keyword(obj)
    if name is None:
        return
    assert qualname in FORWARDING, f"{qualname} takes **{name} but forwards it nowhere known"
    if _known_gap(qualname):
        return
    listed = _documented(inspect.getdoc(obj) or "", "Parameters") or set()
    assert name in listed, f"{qualname}: **{name} not documented"


@pytest.mark.parametrize(
    "call",
    [
        lambda: geardyn.analysis.bifurcation.bifurcation(GearModel(), "omega", [1.0], chunks=2),
        lambda: geardyn.analysis.maps.parameter_map(GearModel(), "omega", [1.0], "xi0", [0.1], worker=1),
        lambda: geardyn.analysis.basins.basins(GearModel(), (0, 1), (0, 1), 2, 2, scheduler_address="x"),
        lambda: geardyn.analysis.response.frequency_response(GearModel(), 0.5, 1.0, 3, progres=False),
    ],
    ids=["bifurcation", "parameter_map", "basins", "frequency_response"],
)
def test_unknown_keyword_is_refused(call) -> None:
    with pytest.raises(TypeError, match="unexpected keyword argument"):
        call()


def test_a_model_refuses_an_unknown_parameter() -> None:
    from geardyn.errors import ModelError

    with pytest.raises(ModelError, match="speed"):
        GearModel().with_param("speed", 1.0)


def _test_names(module: str) -> list[str]:
    parts = module.split(".")[1:]
    if parts and parts[-1] == "__init__":
        parts = parts[:-1]
    names = [f"test_{parts[-1]}.py", f"test_{parts[-1].lstrip('_')}.py"] if parts else []  # _x: test_x.py
    if len(parts) >= 2:
        names.append(f"test_{parts[-2]}.py")  # its package
    for i in range(len(parts), 0, -1):  # the module, then each package above it
        covered = COVERED_BY.get(".".join(["geardyn"] + parts[:i]))
        if covered:
            names.append(covered)
    return names


@pytest.mark.parametrize("module", [m.__name__ for m in MODULES if m.__name__ != "geardyn"])
def test_every_module_has_a_test_file(module: str) -> None:
    candidates = _test_names(module)
    assert any((TESTS / n).is_file() for n in candidates), f"{module}: none of {candidates} in tests/"


def test_covered_by_names_existing_files() -> None:
    missing = sorted({f for f in COVERED_BY.values() if not (TESTS / f).is_file()})
    assert not missing
