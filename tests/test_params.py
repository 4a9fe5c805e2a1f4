"""The parameter registry: name grammar, aliases, families and descriptions."""

from __future__ import annotations

import pytest

from geardyn.errors import ModelError
from geardyn.params import ALIASES, FAMILIES, MAX_HARMONICS, canonical_param, describe, family_of, slot


def test_grammar_accepts_every_harmonic_up_to_the_limit() -> None:
    assert MAX_HARMONICS == 64
    assert canonical_param("kappa64") == "kappa64"
    assert canonical_param("phi_e1") == "phi_e1"
    assert slot("kappa64") == ("kappa", 63)
    assert slot("omega") == ("omega", None)


@pytest.mark.parametrize("name", ["kappa65", "kappa0", "kappa01", "xi", "speed", "", "OMEGA"])
def test_grammar_refuses_names_outside_it(name: str) -> None:
    with pytest.raises(ModelError, match="unknown parameter"):
        canonical_param(name)


def test_aliases_map_to_canonical_names() -> None:
    for alias, name in ALIASES.items():
        assert canonical_param(alias) == name
    assert canonical_param("fe") == "eps1"
    assert canonical_param("backlash") == "D"


def test_families_and_descriptions() -> None:
    assert family_of("kappa3") is FAMILIES["kappa"]
    long_name, units = describe("kappa2")
    assert "2" in long_name and units == "1"
    assert describe("phi_e1")[1] == "rad"


def test_messages_are_one_line() -> None:
    with pytest.raises(ModelError) as err:
        canonical_param("kappa65")
    assert "\n" not in str(err.value)


def test_parameter_names_of_the_help_texts_come_from_the_registry_and_all_parse():
    import re

    from typer.testing import CliRunner

    from geardyn.cli import app
    from geardyn.params import ALIASES, FAMILIES, LISTING_ORDER, canonical_param, parameter_names

    text = parameter_names()
    assert re.sub(r" \([^)]*\)", "", text).split(", ") == [FAMILIES[n].pattern for n in LISTING_ORDER]
    for alias, target in ALIASES.items():
        assert alias in text and canonical_param(alias) == canonical_param(target)
    for pattern in (FAMILIES[n].pattern for n in LISTING_ORDER):
        canonical_param(pattern.replace("K", "1").replace("R", "1").replace("L", "1"))  # every listed family parses
    for cmd in ("bifurcation", "continuation", "hb"):
        r = CliRunner().invoke(app, [cmd, "--help"], env={"COLUMNS": "400"})
        assert " ".join(text.split()) in " ".join(r.output.split()), cmd
