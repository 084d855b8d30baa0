"""The one setpoint vocabulary (twin.setpoint): strict types, the bearing's own limits quoted in
every range error, partial updates, and the engine applying an admitted setpoint without a
second check."""

from __future__ import annotations

import math

import pytest
from pydantic import ValidationError

from twin.engine import Twin
from twin.faults import Fault, FaultKind
from twin.setpoint import FIELDS, NAMES, Admitted, Setpoint, SetpointError, SetpointLimits, SetpointUpdate


@pytest.fixture(scope="module")
def twin():
    return Twin("6208", warm=False)


@pytest.mark.parametrize("value", [True, False, "3000", "x", None, [3000.0], {"v": 1.0}])
def test_a_load_is_a_number_not_a_bool_or_a_string(value):
    with pytest.raises(ValidationError) as exc:
        SetpointUpdate.model_validate(
            {"radial_load_n": value} if value is not None else {"radial_load_n": value, "x": 1}
        )
    assert exc.value.errors()[0]["loc"][0] in ("radial_load_n", "x")
    with pytest.raises(ValidationError):
        Setpoint.model_validate({"radial_load_n": value})


def test_integers_are_numbers_and_non_finite_values_are_refused():
    assert SetpointUpdate.model_validate({"radial_load_n": 3000}).radial_load_n == 3000.0
    assert SetpointUpdate.model_validate_json('{"radial_load_n": 3000}').radial_load_n == 3000.0
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(ValidationError):
            SetpointUpdate(radial_load_n=bad)
    with pytest.raises(ValidationError):
        SetpointUpdate.model_validate({"radial_lod_n": 1.0})  # unknown field


def test_limits_are_the_bearings_own_and_errors_quote_them(twin):
    limits = twin.limits
    assert limits.bearing == "6208"
    # the model's limit (n dm rule of thumb, 1.2e6 mm/min: 2073.66 rad/s for the 6208), not the
    # vocabulary's static bound of 1e4 rad/s
    assert limits["shaft_speed_rad_s"] == (0.0, twin.model.max_shaft_speed_rad_s)
    assert twin.model.max_shaft_speed_rad_s == pytest.approx(2073.66, abs=0.005)
    with pytest.raises(SetpointError) as exc:
        limits.admit(SetpointUpdate(shaft_speed_rad_s=3000.0, radial_load_n=-1.0), twin.setpoint)
    text = str(exc.value)
    assert "shaft_speed_rad_s = 3000 rad/s is outside the allowed range [0, 2073.66] rad/s for bearing 6208" in text
    assert "radial_load_n = -1 N" in text  # every field, not only the first
    assert [p.field for p in exc.value.problems] == ["shaft_speed_rad_s", "radial_load_n"]
    assert "10000" not in text  # never the static bound


def test_static_bounds_envelope_every_bearing():
    static = SetpointLimits.static()
    for f in FIELDS:
        assert static[f.name] == (f.low, f.high) and f.low <= f.default <= f.high
    for designation in ("6200", "6208", "7208"):
        limits = Twin(designation, warm=False).limits
        for name in NAMES:
            low, high = limits[name]
            assert static[name][0] <= low < high <= static[name][1], (designation, name)
    assert Twin("7208", warm=False).limits["axial_load_n"][0] == 0.0  # angular contact: one way


def test_partial_update_keeps_the_other_fields(twin):
    base = Setpoint(radial_load_n=2000.0, oil_temperature_c=60.0)
    new = twin.limits.admit(SetpointUpdate(radial_load_n=2500.0), base).setpoint
    assert (new.radial_load_n, new.oil_temperature_c, new.shaft_speed_rad_s) == (2500.0, 60.0, 500.0)
    assert SetpointUpdate(radial_load_n=1.0).merged(SetpointUpdate(radial_load_n=2.0, axial_load_n=3.0)).fields == {
        "radial_load_n": 2.0,
        "axial_load_n": 3.0,
    }


def test_the_engine_applies_an_admitted_setpoint_without_checking_again(twin, monkeypatch):
    admitted = twin.limits.admit(SetpointUpdate(radial_load_n=4000.0), twin.setpoint)
    assert isinstance(admitted, Admitted)
    calls = []
    check = SetpointLimits.check
    monkeypatch.setattr(SetpointLimits, "check", lambda self, v: calls.append(v) or check(self, v))
    twin.set_setpoint(admitted)
    assert twin.setpoint.radial_load_n == 4000.0 and calls == []  # checked once, at admission
    twin.set_setpoint(radial_load_n=3000.0)  # the Python API path: one check
    assert len(calls) == 1
    with pytest.raises(SetpointError):
        twin.set_setpoint(Admitted(Setpoint(shaft_speed_rad_s=5000.0), SetpointLimits.static()))  # other limits


def test_faults_are_typed_values():
    f = Fault(FaultKind.RESTARTED, "overloaded: excessive contact penetration", 0.0123)
    assert f.describe() == "restarted: overloaded: excessive contact penetration at t = 0.012300 s"
    h = Fault(FaultKind.HALTED, "diverged: non-finite state", 1.0, 0.01)
    assert h.describe().startswith("halted: diverged: non-finite state again within 10 ms")
