"""The thermal network in the loop of a Twin (twin.thermal.coupling): heat from the engine's own
friction, temperatures back into the viscosity and the clearance, measurements, options."""

import math

import pytest

from twin import catalog
from twin.engine import Twin
from twin.physics.thermal import roelands_temperature_viscosity_pa_s
from twin.physics.viscosity import dynamic_viscosity_pa_s, temperature_viscosity_coefficient_k_inv
from twin.setpoint import Setpoint
from twin.spec import ModelOptions
from twin.thermal.settings import ThermalNetworkSettings

ACCELERATED = ModelOptions(thermal="network", thermal_network=ThermalNetworkSettings(heat_capacity_scale=1e-3))


def heated_inlet_viscosity_pa_s(lub, inlet_c: float, shear_rise_k: float) -> float:
    """The oil's viscosity at the inlet temperature (ASTM D341), heated by the inlet's shear by Roelands
    (seed 003 eq. 3 with the oil's beta there): the viscosity the film reads with Thermal.shear_heating on."""
    t0 = inlet_c + 273.15
    return roelands_temperature_viscosity_pa_s(
        dynamic_viscosity_pa_s(lub, inlet_c),
        t0,
        t0 + shear_rise_k,
        temperature_viscosity_coefficient_k_inv(lub, inlet_c),
    )


@pytest.fixture(scope="module")
def warmed():
    twin = Twin(
        "6208",
        options=ACCELERATED,
        setpoint=Setpoint(shaft_speed_rad_s=1000.0, radial_load_n=3000.0, oil_temperature_c=20.0),
    )
    start = twin.snapshot()
    twin.advance(0.3)  # 300 s of thermal time
    return twin, start, twin.snapshot()


def test_starts_at_the_set_temperature_with_its_viscosity(warmed):
    _, start, _ = warmed
    th = start.thermal
    assert th.accelerated and th.heat_capacity_scale == 1e-3
    assert all(t == pytest.approx(20.0, abs=1e-9) for t in th.temperatures_c.values())
    lub = catalog.bearing("6208").lubricant
    # the film starts at the set temperature's viscosity (ASTM D341), as with the fixed oil temperature,
    # heated at the inlet by its shear (Thermal.shear_heating, on by default: Murch-Wilson)
    fixed = Twin(
        "6208",
        options=ModelOptions(thermal="fixed"),
        setpoint=Setpoint(shaft_speed_rad_s=1000.0, radial_load_n=3000.0, oil_temperature_c=20.0),
    )
    assert start.viscosity_pa_s == pytest.approx(fixed.snapshot().viscosity_pa_s, rel=1e-12)
    rise = fixed.snapshot().electrical.shear_temperature_rise_k
    assert rise > 0.0
    assert heated_inlet_viscosity_pa_s(lub, 20.0, rise) == pytest.approx(fixed.snapshot().viscosity_pa_s, rel=1e-12)
    assert fixed.snapshot().thermal is None


def test_friction_heats_the_bearing_and_thins_the_oil(warmed):
    twin, start, end = warmed
    th = end.thermal
    t = th.temperatures_c
    # heat flows from the contacts outwards: balls > rings > housing > ambient
    assert t["balls"] > t["inner_ring"] > 20.5 and t["balls"] > t["outer_ring"] > t["housing"] > 20.0
    # energy: the heat is the drive power (friction torque x shaft speed over the period), split by source
    assert sum(th.heat_w.values()) == pytest.approx(th.heat_inner_contacts_w + th.heat_outer_contacts_w, rel=1e-9)
    assert 20.0 < sum(th.heat_w.values()) < 1000.0
    # the warmer inlet thins the film: viscosity at the network's inlet temperature (ASTM D341), shear-heated
    lub = twin.model.spec.lubricant
    assert th.inlet_temperature_c > 25.0
    assert end.viscosity_pa_s == pytest.approx(
        heated_inlet_viscosity_pa_s(lub, th.inlet_temperature_c, end.electrical.shear_temperature_rise_k), rel=1e-9
    )
    assert end.viscosity_pa_s < 0.7 * start.viscosity_pa_s
    # expansion: the hotter balls and inner ring close the clearance
    assert th.clearance_change_m < 0.0
    assert th.network_time_s == pytest.approx(300.0, rel=0.01)


def test_the_heat_is_split_by_source_as_the_friction_power(warmed):
    # one reading of rolling, sliding and spin (twin.friction_power.contact_powers_w): the network's
    # heat by source has the shares of the snapshot's friction_power_w (both from the contact lanes;
    # the network's at its last step, the snapshot's at the frame's end: 0.03 of the total apart)
    _twin, _start, end = warmed
    heat, power = end.thermal.heat_w, end.friction_power_w.model_dump()
    contact_heat = sum(heat[k] for k in ("rolling", "sliding", "spin"))
    contact_power = sum(power[k] for k in ("rolling", "sliding", "spin"))
    assert heat["sliding"] / contact_heat > 0.05  # the DEM's sliding carries heat
    for source in ("rolling", "sliding", "spin"):
        assert heat[source] / contact_heat == pytest.approx(power[source] / contact_power, abs=0.03), source


def test_ambient_change_shifts_every_node_and_bad_measurements_are_refused(warmed):
    twin, _, _ = warmed
    now = twin.snapshot().thermal  # the shared twin as the other tests of the module left it
    before, shift = dict(now.temperatures_c), 25.0 - now.ambient_c
    assert shift != 0.0
    twin.set_setpoint(oil_temperature_c=25.0)
    after = twin.snapshot().thermal
    assert after.ambient_c == 25.0
    for k, v in before.items():
        assert after.temperatures_c[k] == pytest.approx(v + shift, abs=1e-9)
    with pytest.raises(ValueError, match="node"):
        twin.measure_temperature("cage", 50.0)
    with pytest.raises(ValueError, match="temperature_c"):
        twin.measure_temperature("outer_ring", math.nan)
    fixed = Twin("6208", options=ModelOptions(thermal="fixed"), warm=False)
    with pytest.raises(ValueError, match="thermal"):
        fixed.measure_temperature("outer_ring", 50.0)


def test_measurement_is_assimilated_and_published(warmed):
    twin, _, _ = warmed
    pred = twin.snapshot().thermal.temperatures_c["outer_ring"]
    twin.measure_temperature("outer_ring", pred + 0.5)
    twin.advance(0.06)
    th = twin.snapshot().thermal
    assert th.measured_node == "outer_ring" and th.measured_c == pytest.approx(pred + 0.5)
    assert th.residual_k is not None and th.residual_sigma_k is not None and th.residual_sigma_k > 0.0
    assert not th.unexplained_heating
    assert math.isfinite(th.dissipation_factor) and th.dissipation_factor_sigma > 0.0
    # the snapshot stays valid JSON with the block (no NaN)
    assert '"thermal"' in twin.snapshot().to_json()


def test_the_block_is_made_again_exactly_when_the_network_changes():
    """ThermalCoupling.block: a snapshot comes every frame, the network steps every period; the
    block is the last one while the network's state is unchanged, and a fresh one equal to a
    block made from scratch after a step, a new ambient, held temperatures or an assimilated
    measurement."""
    twin = Twin(
        "6208",
        options=ACCELERATED,
        setpoint=Setpoint(shaft_speed_rad_s=1000.0, radial_load_n=3000.0, oil_temperature_c=20.0),
    )
    th = twin.thermal
    assert th is not None
    twin.advance(0.01)
    first = th.block()
    assert th.block() is first  # nothing changed between the two
    assert first == th._make_block()
    steps = 0
    while th.network_time_s == first.network_time_s:  # frames until the next network step
        twin.advance(0.0005)
        steps += 1
        assert steps < 1000
    stepped = th.block()
    assert stepped is not first and stepped == th._make_block()
    assert stepped.network_time_s > first.network_time_s
    twin.set_setpoint(twin.setpoint.model_copy(update={"oil_temperature_c": 25.0}))
    shifted = th.block()
    assert shifted is not stepped and shifted == th._make_block() and shifted.ambient_c == 25.0
    twin.hold_thermal_state(th.temperature_c + 1.0)
    held = th.block()
    assert held is not shifted and held == th._make_block()
    assert held.temperatures_c["outer_ring"] == pytest.approx(shifted.temperatures_c["outer_ring"] + 1.0, abs=1e-9)
    twin.measure_temperature("outer_ring", held.temperatures_c["outer_ring"] + 8.0)
    assert th.block() is held  # assimilated at the next network step, not before
    network_time_s = th.network_time_s
    while th.network_time_s == network_time_s:
        twin.advance(0.0005)
    measured = th.block()
    assert measured.measured_node == "outer_ring" and measured == th._make_block()


def test_the_rate_of_rise_is_over_a_minute_from_the_start():
    """`thermal.outer_ring_rate_k_per_min` is the rise over the last minute of thermal time; within
    the first minute, the rise since the start over a minute (the bearing stood at its starting
    temperature before it): a cold start's first seconds are not extrapolated into a runaway."""
    twin = Twin(
        "6208",
        options=ACCELERATED,
        setpoint=Setpoint(shaft_speed_rad_s=1000.0, radial_load_n=3000.0, oil_temperature_c=20.0),
    )
    t0 = twin.snapshot().thermal.temperatures_c["outer_ring"]
    twin.advance(0.01)  # 10 s of thermal time
    early = twin.snapshot().thermal
    rise = early.temperatures_c["outer_ring"] - t0
    assert rise > 0.0
    assert early.outer_ring_rate_k_per_min == pytest.approx(rise, rel=1e-6)  # [K per 60 s]
    twin.advance(0.11)  # 120 s: a full minute behind, the rise over the last 60 s (+- one network step)
    hist = twin.thermal._rate_history
    late = twin.snapshot().thermal
    assert hist[-1][0] - hist[0][0] >= 60.0
    assert late.outer_ring_rate_k_per_min == pytest.approx(
        60.0 * (hist[-1][1] - hist[0][1]) / (hist[-1][0] - hist[0][0]), rel=1e-9
    )


def test_the_network_steps_at_its_period_whatever_the_callers_frames():
    """The network steps every `thermal_period_s` of thermal time (1 s; ModelOptions, docs/physics.md
    "Thermal network") also when the caller's frames are longer than that period: the service's
    runner advances a twin in 20 ms frames, which at x1000 are 20 s of thermal time. A frame
    ends where the network is due (Twin.advance), so 1 ms and 20 ms frames give the same
    temperatures (to 1e-9 K). Stepped 20 s at a time instead, the balls' node ran up to 2.5 K
    ahead within the first 100 s (the period study, twin.validation.thermal_studies: 20 s
    steps move the nodes by 1.4 K over the whole start-up)."""

    def run(frame_s: float):
        twin = Twin(
            "6208",
            options=ACCELERATED,
            setpoint=Setpoint(shaft_speed_rad_s=1000.0, radial_load_n=3000.0, oil_temperature_c=20.0),
        )
        temps = []
        for _ in range(3):  # 60 s of thermal time
            twin.advance(0.02, frame_steps=round(frame_s / twin.model.dt_s))
            temps.append(twin.thermal.temperature_c.copy())
        return temps, twin.thermal.network_time_s

    fine, t_fine = run(0.001)  # 1 ms frames: one network step per frame at x1000
    coarse, t_coarse = run(0.02)  # the runner's frame
    assert t_coarse == pytest.approx(t_fine, abs=1e-9) == pytest.approx(60.0, abs=1e-6)
    for a, b in zip(fine, coarse, strict=True):
        assert abs(a - b).max() < 1e-9
