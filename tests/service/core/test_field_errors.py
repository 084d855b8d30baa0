"""An input error names the field and both sides of its allowed range, whichever way the input
came (service.core.errors): pydantic names only the side that was crossed, so the range is read
from the model that validated it (`declared_bounds`)."""

import pytest
from pydantic import BaseModel, Field, ValidationError

from service.core.errors import InputError, declared_bounds, field_errors
from service.core.registry import TwinRegistry
from service.settings import ServiceSettings
from service.tools.messages import error_text
from twin import catalog
from twin.spec import BearingSpec


def _bad_spec(**mounting):
    data = catalog.bearing("CWRU-DE").model_dump(mode="json")
    data["mounting"].update(mounting)
    return data


def test_declared_bounds_follow_nested_models():
    # twin.spec.Clearance: -50 .. 200 um; the accelerometer's noise density >= 0 (twin.vibration.housing)
    assert declared_bounds(BearingSpec, ("mounting", "diametral_clearance_m")) == (-50e-6, 200e-6)
    low, high = declared_bounds(BearingSpec, ("housing", "accelerometer", "noise_density_m_s2_rthz"))
    assert low == 0.0 and high is not None
    assert declared_bounds(BearingSpec, ("mounting", "no_such_field")) is None
    assert declared_bounds(BearingSpec, ("designation",)) is None  # no range declared


def test_a_spec_error_states_both_sides_of_the_range():
    with pytest.raises(ValidationError) as info:
        BearingSpec.model_validate(_bad_spec(diametral_clearance_m=1e-3))
    (error,) = field_errors(info.value.errors(), model=BearingSpec)
    assert error.field == "mounting.diametral_clearance_m"
    assert error.allowed == [-5e-05, 0.0002] and "allowed range [-5e-05, 0.0002] m" in error.message
    # the command line prints the same
    assert error_text(info.value) == f"{error.field}: {error.message}"


def test_a_twin_from_a_spec_names_the_spec_field_and_its_range():
    registry = TwinRegistry(ServiceSettings(enable_zenoh=False, enable_recording=False))
    with pytest.raises(InputError) as info:
        registry.build_twin("x", spec=_bad_spec(diametral_clearance_m=-1e-3))
    (error,) = info.value.errors
    assert error.field == "spec.mounting.diametral_clearance_m"
    assert error.allowed == [-5e-05, 0.0002], error


def test_open_bounds_read_in_parentheses():
    """gt / lt exclude the bound: '(0, 0.05]' (twin.vibration.defects width_m: gt=0, le=0.05)."""
    from service.core.errors import field_bounds, range_text
    from twin.vibration.defects import OuterRaceSpall

    bounds = field_bounds(OuterRaceSpall.model_fields["width_m"])
    assert bounds == (0.0, 0.05) and bounds.low_open and not bounds.high_open
    assert range_text(*bounds, bounds.low_open, bounds.high_open) == "(0, 0.05]"
    assert range_text(None, 3) == "(-inf, 3]" and range_text(1, None) == "[1, inf)"


def test_a_side_no_model_declares_reads_as_open_on_its_own_side():
    # a bound with no model to read the other side from (a measured temperature >= -60 degC): the
    # open side is -inf below and inf above, never -inf above
    class Measured(BaseModel):
        temperature_c: float = Field(ge=-60.0)

    with pytest.raises(ValidationError) as info:
        Measured.model_validate({"temperature_c": -300.0})
    (error,) = field_errors(info.value.errors())
    assert error.allowed == [-60.0, None]
    assert error.message.endswith("allowed range [-60, inf) degC"), error.message


def test_a_range_a_model_check_states_in_its_message_is_in_allowed():
    # a model-level check (no declared bound) that states "must be in [low, high]" or "(low, high]" gives both ends
    # in `allowed` as numbers; a message without a numeric range leaves it null
    def check(msg: str):
        return field_errors([{"loc": ("x_m",), "msg": f"Value error, {msg}", "type": "value_error"}])[0].allowed

    assert check("x_m = 0.03 m: must be in (0, 0.0255516] m for this bearing") == [0.0, 0.0255516]
    assert check("n = 20: must be in [0, 12] for this bearing") == [0.0, 12.0]
    assert check("x_m = -1e-05 m: must be in [-2.5e-05, 1.5e-4] m") == [-2.5e-05, 1.5e-4]
    assert check("contact_angle_rad = 2: must be in [0, pi/2)") is None
    assert check("the balls do not fit on the pitch circle") is None
