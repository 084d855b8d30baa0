"""Scenarios with an ambient temperature and measured temperatures on their timeline
(service.core.scenarios `temperature` steps, handed to the twin by the scenario driver)."""

from pathlib import Path

import pytest

from service.core.scenario_driver import ScenarioExecutor
from service.core.scenario_files import load_scenario, scenario_from_dict
from service.core.scenarios import ScenarioError
from twin.setpoint import Setpoint

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "thermal_measured_outer_ring.yaml"


def test_shipped_thermal_scenario_carries_its_measurements_in_order():
    run = load_scenario(SCENARIO).resolved_runs()[0]
    ex = ScenarioExecutor(run)
    seen = []
    for k in range(351):
        ex.updates(k * 0.01, Setpoint())
        if ex.temperature is not None:
            seen.append((round(k * 0.01, 2), ex.temperature.node, ex.temperature.temperature_c))
            ex.temperature = None
    assert seen == [
        (0.1, "outer_ring", 28.0),
        (0.3, "outer_ring", 28.0),
        (1.5, "outer_ring", 28.0),
        (2.2, "outer_ring", 48.0),
        (3.2, "outer_ring", 48.0),
    ]
    assert run.initial.fields["oil_temperature_c"] == 20.0  # the ambient


@pytest.mark.parametrize(
    "bad, field",
    [
        ({"node": "cage", "temperature_c": 40.0}, "node"),
        ({"node": "outer_ring", "temperature_c": 900.0}, "temperature_c"),
    ],
)
def test_bad_measurement_names_its_field(bad, field):
    with pytest.raises(ScenarioError, match=field):
        scenario_from_dict({"name": "t", "duration_s": 0.1, "steps": [{"at_s": 0.0, "temperature": bad}]})
