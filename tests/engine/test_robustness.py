"""Long and hard runs stay finite; bad specs and setpoints are refused by name."""

import math

import pytest
from pydantic import ValidationError

from twin import catalog
from twin.engine import Twin
from twin.setpoint import Setpoint, SetpointError
from twin.spec import BearingSpec, Geometry, ModelOptions


def test_one_second_at_1700_rad_s_and_7500_n(time_step):
    twin = Twin(
        "6208",
        setpoint=Setpoint(shaft_speed_rad_s=1700.0, radial_load_n=7500.0),
        options=ModelOptions(time_step_s=time_step),
    )
    worst = 0.0
    for _ in range(20):
        twin.advance(0.05)
        snap = twin.snapshot()
        assert snap.status == "ok" and snap.restarts == 0
        for b in snap.balls:
            for c in (b.inner, b.outer):
                assert math.isfinite(c.load_n)
        worst = max(worst, float(twin.state.scalars[10]))  # X_MAX_PENETRATION
    assert twin.time_s == pytest.approx(1.0, abs=1e-9)
    # bounded penetration: Hertz approach at the ~3.7 kN peak is ~40 um, far below 1 % of Rb... of
    # the model's status limit (63 um); a few microns of dynamic overshoot at most
    assert 10e-6 < worst < 45e-6
    snap.to_json()  # serialises without NaN


@pytest.mark.parametrize(
    "field, value",
    [
        ("shaft_speed_rad_s", -1.0),
        ("shaft_speed_rad_s", float("nan")),
        ("radial_load_n", -5.0),
        ("radial_load_n", float("inf")),
        ("oil_temperature_c", 400.0),
    ],
)
def test_setpoint_refused_with_the_field_name(field, value):
    twin = Twin("6208")
    # a non-finite number is a type error (ValidationError), a finite one out of range a
    # SetpointError naming the bearing's range: both are ValueErrors naming the field
    with pytest.raises((ValidationError, SetpointError)) as err:
        twin.set_setpoint(**{field: value})
    assert field in str(err.value)
    assert twin.setpoint == Setpoint()  # nothing applied


def test_loads_beyond_what_the_model_holds_are_refused_with_range():
    twin = Twin("6208")
    with pytest.raises(SetpointError) as err:
        twin.set_setpoint(radial_load_n=5e5)
    text = str(err.value)
    assert "radial_load_n" in text and "allowed range" in text
    with pytest.raises(SetpointError, match="shaft_speed_rad_s"):
        twin.set_setpoint(shaft_speed_rad_s=5000.0)
    with pytest.raises(SetpointError, match="axial_load_n"):
        Twin("7208").set_setpoint(axial_load_n=-100.0)


def test_ball_that_does_not_fit_its_groove_is_refused():
    g = catalog.bearing("6208").geometry.model_dump()
    g["inner_groove_radius_m"] = 6.0e-3  # smaller than the 6.3 mm ball
    with pytest.raises(ValidationError, match="inner_groove_radius_m"):
        Geometry(**g)


@pytest.mark.parametrize(
    "field, value", [("ball_radius_m", -1.0), ("ball_count", 2), ("cage_element_radius_m", float("nan"))]
)
def test_bad_geometry_fields_named(field, value):
    g = catalog.bearing("6208").geometry.model_dump()
    g[field] = value
    with pytest.raises(ValidationError, match=field):
        Geometry(**g)


def test_unknown_designation_and_bad_clearance():
    with pytest.raises(ValueError, match="designation"):
        catalog.bearing("9999")
    with pytest.raises(ValidationError, match="diametral_clearance_m"):
        catalog.bearing("6208", diametral_clearance_m=-1e-3)


def test_every_catalog_bearing_builds_and_runs(time_step):
    for name in catalog.designations():
        spec = catalog.bearing(name)
        assert isinstance(spec, BearingSpec)
        # an angular-contact bearing needs an axial load to seat its balls (a single row cannot
        # carry a pure radial load without an axial reaction)
        twin = Twin(
            name,
            setpoint=Setpoint(
                shaft_speed_rad_s=300.0, radial_load_n=1000.0, axial_load_n=500.0 if name.startswith("7208") else 0.0
            ),
            options=ModelOptions(time_step_s=time_step),
        )
        twin.advance(0.002)
        assert twin.snapshot().status == "ok", name


def test_6208_catalog_is_seed_000_table_1():
    g = catalog.bearing("6208").geometry
    assert (
        g.ball_radius_m,
        g.inner_raceway_radius_m,
        g.outer_raceway_radius_m,
        g.inner_groove_radius_m,
        g.outer_groove_radius_m,
        g.ball_count,
        g.cage_element_radius_m,
    ) == (6.3e-3, 24.0e-3, 36.6e-3, 6.552e-3, 6.552e-3, 9, 4.19e-3)
