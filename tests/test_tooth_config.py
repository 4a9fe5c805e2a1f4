"""The tooth-pair file: values with their units, the earlier keys with the unit in the name still read to the
same pair, and impossible pairs refused in one line naming the key."""

import math

import pytest

from geardyn.errors import ConfigError, ModelError
from geardyn.tooth.config import load_case

NEW = """
[tooth_pair]
z1 = 19
z2 = 48
m_n = "3.2 mm"
alpha_n = "20 deg"
face_width = "16 mm"
bore1 = "7.6 mm"
bore2 = "19.2 mm"
torque = "100 N*m"
E = "206 GPa"
[modifications]
tip_relief = ["5 um", "5 um"]
tip_length = ["1.5 mm", "1.5 mm"]
[signature]
rpm = "3000 rpm"
fs = "40 kHz"
backlash = "100 um"
[[fault]]
kind = "spall"
gear = 0
tooth = 0
at = 0.5
length = "1.5 mm"
width = "8 mm"
depth = "30 um"
"""

OLD = """
[tooth_pair]
z1 = 19
z2 = 48
m_n_mm = 3.2
alpha_n_deg = 20.0
face_width_mm = 16.0
bore1_mm = 7.6
bore2_mm = 19.2
torque_Nm = 100.0
E_GPa = 206.0
[modifications]
tip_relief_um = [5.0, 5.0]
tip_length_mm = [1.5, 1.5]
[signature]
rpm = 3000.0
fs_Hz = 40000.0
backlash_um = 100.0
[[fault]]
kind = "spall"
gear = 0
tooth = 0
at = 0.5
length_mm = 1.5
width_mm = 8.0
depth_um = 30.0
"""


def _case(tmp_path, text, name="pair.toml"):
    p = tmp_path / name
    p.write_text(text)
    return load_case(p)


def test_units_in_values_and_the_old_keys_read_to_the_same_pair(tmp_path):
    a, b = _case(tmp_path, NEW, "new.toml"), _case(tmp_path, OLD, "old.toml")
    ga, gb = a.geometry, b.geometry
    for name in ("m_n", "alpha_n", "face_width", "a_w", "eps_alpha"):
        assert getattr(ga, name) == pytest.approx(getattr(gb, name), rel=1e-14)
    assert [g.bore_radius for g in ga.gears] == pytest.approx([g.bore_radius for g in gb.gears], rel=1e-14)
    assert a.torque == b.torque == 100.0
    assert a.modifications.tip_relief == pytest.approx(b.modifications.tip_relief, rel=1e-14)
    assert a.faults[0].depth == pytest.approx(30e-6, rel=1e-14) and b.faults[0].depth == pytest.approx(30e-6)
    assert a.signature["fs_Hz"] == b.signature["fs_Hz"] == 40000.0
    assert a.signature["backlash"] == pytest.approx(b.signature["backlash"], rel=1e-14)
    assert a.signature["rpm"] == pytest.approx(3000.0) and b.signature["rpm"] == pytest.approx(3000.0)
    assert ga.alpha_n == pytest.approx(math.radians(20.0), rel=1e-14)


@pytest.mark.parametrize(
    "edit, key, cls",
    [
        (("z2 = 48", "z2 = 100000"), "z2", ModelError),
        (("z2 = 48", "z2 = 48\nh_f = -1"), "h_f", ModelError),
        (("z2 = 48", "z2 = 48\nx1 = -3"), "x1", ModelError),
        (('m_n = "3.2 mm"', 'm_n = "1e9 mm"'), "m_n", ModelError),
        (('m_n = "3.2 mm"', "m_n = 3.2"), "m_n", ConfigError),
        (('m_n = "3.2 mm"', 'm_n = "3.2 mm"\nm_n_mm = 3.2'), "m_n_mm", ConfigError),
        (('torque = "100 N*m"', 'torque = "1e15 N*m"'), "torque", ModelError),
        (('width = "8 mm"', 'width = "500 mm"'), "width", ModelError),
        (('length = "1.5 mm"', 'length = "500 mm"'), "length", ModelError),
        (('tip_relief = ["5 um", "5 um"]', 'tip_relief = ["1 m", "5 um"]'), "tip_relief", ModelError),
        (('tip_length = ["1.5 mm", "1.5 mm"]', 'tip_length = ["1 m", "1.5 mm"]'), "tip_length", ModelError),
        (("z2 = 48", "z2 = 48\nwhat = 1"), "what", ConfigError),
    ],
)
def test_impossible_pairs_are_refused_naming_the_key(tmp_path, edit, key, cls):
    with pytest.raises(cls) as e:
        _case(tmp_path, NEW.replace(*edit))
    msg = str(e.value)
    assert "\n" not in msg and key in msg


def test_wear_deeper_than_the_tooth_is_refused(tmp_path):
    text = NEW + '[[fault]]\nkind = "wear"\ngear = 1\ndepth = "1 m"\n'
    with pytest.raises(ModelError, match="depth"):
        _case(tmp_path, text)


@pytest.mark.parametrize("kind", ['["crack"]', "{ crack = 1 }", "3"])
def test_a_fault_kind_that_is_not_a_name_is_refused_in_one_line(tmp_path, kind):
    # a list or a table here raised a TypeError (an unhashable kind looked up among the fault kinds)
    text = NEW + f"[[fault]]\nkind = {kind}\ngear = 1\ndepth = 0.5\n"
    with pytest.raises(ModelError, match="kind must be one of crack, spall, wear, broken") as e:
        _case(tmp_path, text)
    assert "\n" not in str(e.value)
