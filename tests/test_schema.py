"""One reader, line locator and validator for every TOML file geardyn reads (``geardyn._config_values``).

A configuration, a system file and a tooth-pair file with the same kind of mistake are refused with the same kind
of message: one line, the file, the line of the value, its section and key, what was expected.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from geardyn.config import load_config
from geardyn.errors import ConfigError, ModelError
from geardyn.systems import load_system
from geardyn.tooth.config import load_case

EX = Path(__file__).resolve().parents[1] / "examples"
CONFIG = (EX / "paper_table1.toml").read_text(encoding="utf-8")
SYSTEM = (EX / "systems" / "paper_torsional.toml").read_text(encoding="utf-8")
TOOTH = (EX / "tooth_healthy_spur.toml").read_text(encoding="utf-8")

LOADERS = {"config": load_config, "system": load_system, "tooth": load_case}


def _refused(tmp_path, kind: str, text: str, exc: type = ConfigError) -> tuple[str, str]:
    p = tmp_path / f"{kind}.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(exc) as e:
        LOADERS[kind](p)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{p}: line "), msg
    n = int(re.match(r".*?: line (\d+):", msg).group(1))
    return msg, text.splitlines()[n - 1]


def _sub(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


@pytest.mark.parametrize(
    "kind, text, line_has, section",
    [
        ("config", _sub(CONFIG, 'm_mn = "7.28 mm"', 'm_mn = "7.28 kg"'), "m_mn", "[gear_pair] m_mn:"),
        ("system", _sub(SYSTEM, 'backlash = "0.1 mm"', 'backlash = "0.1 kg"'), "backlash", "[[mesh]] 'mesh' backlash:"),
    ],
)
def test_a_value_of_the_wrong_unit_is_named_alike_in_every_file(tmp_path, kind, text, line_has, section):
    msg, line = _refused(tmp_path, kind, text)
    assert line_has in line and section in msg and "expected a length" in msg, msg


@pytest.mark.parametrize(
    "kind, text, key, section",
    [
        ("config", _sub(CONFIG, "[operating]", "[operating]\nspeed = 3"), "speed", "[operating] speed:"),
        ("system", _sub(SYSTEM, "[system]", "[system]\nspeed = 3"), "speed", "[system] speed:"),
        ("tooth", _sub(TOOTH, "[tooth_pair]", "[tooth_pair]\nspeed = 3"), "speed", "[tooth_pair] speed:"),
    ],
)
def test_an_unknown_key_is_named_with_its_line_in_every_file(tmp_path, kind, text, key, section):
    msg, line = _refused(tmp_path, kind, text)
    assert line.startswith(key) and section in msg and "unknown key; allowed:" in msg, msg


@pytest.mark.parametrize("kind, text", [("config", CONFIG), ("system", SYSTEM), ("tooth", TOOTH)])
def test_a_toml_syntax_error_is_one_line_with_its_line_in_every_file(tmp_path, kind, text):
    bad = text + '\nbroken = "no end\n'
    p = tmp_path / f"{kind}.toml"
    p.write_text(bad, encoding="utf-8")
    with pytest.raises(ConfigError) as e:
        LOADERS[kind](p)
    n = len(bad.splitlines())
    assert str(e.value).startswith(f"{p}: line {n}: TOML syntax error"), str(e.value)


def test_a_tooth_pair_value_of_the_wrong_type_and_a_tooth_count_out_of_range(tmp_path):
    msg, line = _refused(tmp_path, "tooth", _sub(TOOTH, 'm_n = "3.0 mm"', 'm_n = "three"'))
    assert line.startswith("m_n") and "[tooth_pair] m_n:" in msg, msg
    msg, line = _refused(tmp_path, "tooth", _sub(TOOTH, "z1 = 20", "z1 = 2000"), ModelError)
    assert line.startswith("z1") and "from 1 to 1000" in msg, msg


def test_a_fault_of_a_tooth_pair_is_placed_on_its_table(tmp_path):
    text = TOOTH + '\n[[fault]]\nkind = "crack"\ngear = 0\ntooth = 0\ndepth = "deep"\n'
    msg, line = _refused(tmp_path, "tooth", text)
    assert line.startswith("depth") and "[[fault]] 'crack' depth:" in msg, msg
    text = TOOTH + '\n[[fault]]\nkind = "crack"\ngear = 0\ntooth = 0\ndepth = 0.99\n'
    msg, line = _refused(tmp_path, "tooth", text, ModelError)
    assert line == "[[fault]]" and "depth must lie in" in msg, msg


def test_an_oversized_tooth_pair_file_is_refused_before_it_is_parsed(tmp_path):
    from geardyn._config_values import MAX_TOML_BYTES

    p = tmp_path / "big.toml"
    p.write_text(TOOTH + "#" * MAX_TOML_BYTES, encoding="utf-8")
    with pytest.raises(ConfigError, match=r"tooth-pair file of \d+ bytes; at most"):
        load_case(p)


GEARBOX = (EX / "gearbox" / "two_stage_helical.toml").read_text(encoding="utf-8")


def test_a_gearbox_file_is_placed_by_the_same_locator(tmp_path):
    i = GEARBOX.index("[[shaft]]")
    j = GEARBOX.index("\n", GEARBOX.index("name", i))
    text = GEARBOX[: j + 1] + "bogus = 1\n" + GEARBOX[j + 1 :]
    msg, line = _refused(tmp_path, "system", text)
    assert line == "bogus = 1" and re.search(r"\[\[shaft\]\] '\w+' bogus: unknown key", msg), msg
