"""Status codes: labels, messages and parsing."""

from __future__ import annotations

import pytest

from geardyn.status import Status, flag_attrs


@pytest.mark.parametrize("status", list(Status))
def test_label_parse_round_trip(status: Status) -> None:
    assert Status.parse(status.label) is status
    assert Status.parse(int(status)) is status
    assert Status.parse(status) is status
    assert status.message and "\n" not in status.message


def test_kernel_codes_are_stable() -> None:
    assert (int(Status.OK), int(Status.DIVERGED)) == (0, 1)
    assert Status.OK.ok and not Status.DIVERGED.ok
    assert Status.parse("converged") is Status.OK
    assert Status.parse("  Not Converged ") is Status.NOT_CONVERGED


def test_unknown_label_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown label"):
        Status.parse("fine")


def test_flag_attrs_follow_the_cf_convention() -> None:
    attrs = flag_attrs()
    assert attrs["flag_values"] == [0, 1, 2, 3]
    assert attrs["flag_meanings"].split() == ["ok", "diverged", "not_converged", "unresolved"]
