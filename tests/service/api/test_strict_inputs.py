"""Every input model is strict: a value of the wrong JSON type is refused with the field named,
never coerced ("5e-4" is not a size, true is not 1.0, "2" is not ball 2, "off" is not False);
a JSON integer is still a valid float (1 for 1.0). One case per field type and input model:
the HTTP bodies (BearingCreate with its housing and thermal options, defects, scenarios,
recordings), the setpoint and the scenario files."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from service.api.routers.defects import DefectsRequest
from service.api.schemas import BearingCreate, RecordingRequest, ScenarioRequest
from service.core.defects import parse_defects
from service.core.errors import InputError
from service.core.scenario_files import scenario_from_dict
from twin import catalog
from twin.setpoint import SetpointUpdate
from twin.vibration.housing import Housing
from twin.yaml_numbers import load_yaml

GEOMETRY = catalog.bearing("6208").geometry
SPALL = {"kind": "outer", "width_m": 5e-4, "length_m": 6e-4, "depth_m": 5e-5, "azimuth_deg": 0.0}
BALL = {"kind": "ball", "width_m": 5e-4, "length_m": 5e-4, "depth_m": 5e-5, "ball_index": 2}


def _refused(model, data: dict, field: str) -> None:
    with pytest.raises(ValidationError) as info:
        model.model_validate(data)
    locs = [".".join(str(p) for p in e["loc"]) for e in info.value.errors()]
    assert any(loc.endswith(field) for loc in locs), locs


@pytest.mark.parametrize(
    ("data", "field"),
    [
        ({"diametral_clearance_m": "1e-5"}, "diametral_clearance_m"),  # str for float
        ({"diametral_clearance_m": True}, "diametral_clearance_m"),  # bool for float
        ({"designation": 6208}, "designation"),  # int for str
        ({"housing": {"enabled": "off"}}, "housing.enabled"),  # str for bool
        ({"housing": {"enabled": 1}}, "housing.enabled"),  # int for bool
        ({"housing": {"enabled": True, "pedestal_mass_kg": "6.6"}}, "housing.pedestal_mass_kg"),
        (
            {"housing": {"enabled": True, "accelerometer": {"sample_rate_hz": "51200"}}},
            "housing.accelerometer.sample_rate_hz",
        ),  # nested model
        ({"thermal": {"shear_heating": "yes"}}, "thermal.shear_heating"),
        ({"setpoint": {"radial_load_n": "3000"}}, "setpoint.radial_load_n"),
    ],
)
def test_bearing_create_refuses_wrong_types(data, field):
    _refused(BearingCreate, data, field)


def test_bearing_create_takes_integers_for_floats_and_types_the_housing():
    body = BearingCreate.model_validate(
        {
            "diametral_clearance_m": 0,
            "housing": {"enabled": True, "pedestal_mass_kg": 7},
            "setpoint": {"radial_load_n": 3000},
        }
    )
    assert isinstance(body.housing, Housing) and body.housing.enabled is True
    assert body.housing.pedestal_mass_kg == 7.0 and body.diametral_clearance_m == 0.0
    assert body.setpoint.radial_load_n == 3000.0
    # the OpenAPI carries the housing's fields (was an untyped object)
    schema = BearingCreate.model_json_schema()
    assert "pedestal_mass_kg" in schema["$defs"]["Housing"]["properties"]


@pytest.mark.parametrize(
    ("defect", "field"),
    [
        ({**SPALL, "width_m": "5e-4"}, "defects[0].width_m"),  # str for float
        ({**SPALL, "azimuth_deg": True}, "defects[0].azimuth_deg"),  # bool for float
        ({**BALL, "ball_index": "2"}, "defects[0].ball_index"),  # str for int
        ({**BALL, "ball_index": 2.0}, "defects[0].ball_index"),  # float for int
        ({**SPALL, "kind": 1}, "defects[0]"),  # int for the discriminator
    ],
)
def test_defects_refuse_wrong_types(defect, field):
    with pytest.raises(InputError) as info:
        parse_defects([defect], GEOMETRY)
    fields = [e.field for e in info.value.errors]
    assert any(f.startswith(field) for f in fields), fields


def test_defects_take_integers_for_floats():
    (spall,) = parse_defects([{**SPALL, "azimuth_deg": 30}], GEOMETRY)
    assert spall.azimuth_deg == 30.0
    (ball,) = parse_defects([BALL], GEOMETRY)
    assert ball.ball_index == 2


def test_other_bodies_are_strict():
    _refused(DefectsRequest, {"defects": "none"}, "defects")
    _refused(RecordingRequest, {"action": "start", "path": 5}, "path")
    _refused(ScenarioRequest, {"name": "x", "restart": "true"}, "restart")
    _refused(SetpointUpdate, {"shaft_speed_rad_s": "500"}, "shaft_speed_rad_s")


SCENARIO = {
    "name": "s",
    "duration_s": 0.01,
    "initial": {"radial_load_n": 2000.0},
    "steps": [{"at_s": 0.0, "set": {"radial_load_n": 3000.0}}],
}


@pytest.mark.parametrize(
    ("patch", "field"),
    [
        ({"duration_s": "0.01"}, "duration_s"),
        ({"diametral_clearance_m": False}, "diametral_clearance_m"),
        ({"steps": [{"at_s": "0", "set": {"radial_load_n": 3000.0}}]}, "at_s"),
    ],
)
def test_scenarios_are_strict(patch, field):
    with pytest.raises(Exception) as info:
        scenario_from_dict({**SCENARIO, **patch})
    assert field in str(info.value)


def test_scenario_files_read_exponents_as_numbers():
    """YAML 1.2 numbers: `5e-4` in a scenario file is a float, `1` an int (a valid float); the
    loader of scenario and spec files (twin.yaml_numbers)."""
    data = load_yaml("name: s\nduration_s: 1e-2\nsample_every_s: 1\ninitial: {radial_load_n: 2e3}\n")
    scenario = scenario_from_dict(data)
    assert scenario.duration_s == 0.01 and scenario.sample_every_s == 1.0
