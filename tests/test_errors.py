"""The error hierarchy and its one-line messages."""

from __future__ import annotations

import pytest

from geardyn import errors
from geardyn.errors import ConfigError, GeardynError, ModelError, PlotError, SweepError
from geardyn.model import GearModel


@pytest.mark.parametrize("cls", [ModelError, ConfigError, SweepError, PlotError])
def test_every_error_is_a_geardyn_error(cls: type) -> None:
    assert issubclass(cls, GeardynError)


def test_value_errors_stay_value_errors() -> None:
    # callers that caught ValueError before the hierarchy existed still catch these
    for cls in (ModelError, ConfigError, PlotError):
        assert issubclass(cls, ValueError)
    assert not issubclass(SweepError, ValueError)


def test_model_error_is_importable_from_the_model() -> None:
    from geardyn import model

    assert model.ModelError is ModelError
    assert set(errors.__all__) == {"ConfigError", "GeardynError", "ModelError", "PlotError", "SweepError"}


@pytest.mark.parametrize("kwargs", [{"omega": -1.0}, {"D": float("nan")}, {"kappa": (0.7, 0.5)}])
def test_messages_are_one_line_and_name_the_parameter(kwargs: dict) -> None:
    with pytest.raises(ModelError) as err:
        GearModel(**kwargs)
    text = str(err.value)
    assert "\n" not in text
    assert text.split(":")[0].rstrip("0123456789") in {"omega", "D", "kappa"}
