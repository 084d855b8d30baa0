"""Temperature alarms of service.core.alarms from the snapshot's thermal block: zone, rate of rise,
and heat the dissipation estimator cannot explain."""

import pytest

from service.core.alarm_inputs import AlarmInputs, inputs_from_snapshot
from service.core.alarm_rules import ALARM_IDS
from service.core.alarms import AlarmEvaluator
from service.settings import AlarmSettings


def _thermal(t_outer, rate=0.0, unexplained=False, residual=None):
    return {
        "time_s": 0.0,
        "seq": 1,
        "balls": [],
        "thermal": {
            "temperatures_c": {"outer_ring": t_outer},
            "outer_ring_rate_k_per_min": rate,
            "unexplained_heating": unexplained,
            "residual_k": residual,
        },
    }


def test_inputs_from_the_thermal_block_and_none_without_it():
    x = inputs_from_snapshot(_thermal(71.5, 2.0, True, 20.3))
    assert (x.outer_ring_c, x.outer_ring_rate_k_per_min, x.unexplained_heating, x.residual_k) == (71.5, 2.0, True, 20.3)
    y = inputs_from_snapshot({"time_s": 0.0, "seq": 1, "balls": []})
    assert (y.outer_ring_c, y.outer_ring_rate_k_per_min, y.unexplained_heating) == (None, None, None)
    assert {"temperature_zone", "temperature_rate", "temperature_unexplained"} <= set(ALARM_IDS)


def test_zone_rate_and_unexplained_heating_raise_and_clear():
    s = AlarmSettings(clear_hold_s=0.0)
    ev = AlarmEvaluator("b", s)

    def feed(t, **kw):
        return {e.alarm_id: e for e in ev.update(AlarmInputs(time_s=t, **kw)) if e.alarm_id.startswith("temperature")}

    assert feed(0.0, outer_ring_c=70.0, outer_ring_rate_k_per_min=1.0, unexplained_heating=False) == {}
    e = feed(1.0, outer_ring_c=84.0, outer_ring_rate_k_per_min=6.0, unexplained_heating=False)
    assert e["temperature_zone"].severity == "warning" and e["temperature_zone"].threshold == 82.0
    assert e["temperature_rate"].severity == "warning" and e["temperature_rate"].threshold == 5.0
    e = feed(2.0, outer_ring_c=96.0, outer_ring_rate_k_per_min=12.0, unexplained_heating=True, residual_k=20.0)
    assert e["temperature_zone"].severity == "critical" and e["temperature_rate"].severity == "critical"
    assert e["temperature_unexplained"].severity == "critical"
    assert "+20.0 K" in e["temperature_unexplained"].message
    e = feed(3.0, outer_ring_c=60.0, outer_ring_rate_k_per_min=0.0, unexplained_heating=False)
    assert {k: v.transition for k, v in e.items()} == {
        "temperature_zone": "cleared",
        "temperature_rate": "cleared",
        "temperature_unexplained": "cleared",
    }


@pytest.mark.parametrize("field", ["temperature_warning_c", "temperature_rate_warning_k_per_min"])
def test_settings_refuse_nonsense(field):
    with pytest.raises(ValueError, match=field):
        AlarmSettings(**{field: -1000.0})
