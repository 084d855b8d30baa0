"""ISO 15312:2018 reference conditions in the thermal network with the standard's dissipation:
P = 0.05 C0 radial, ISO VG 32, ambient 20 degC, the catalogue's thermal reference speed; the
standard states the outer ring runs at 70 degC there. The twin's own friction heat, with the
standard's dissipation q_r A_r per 50 K (twin.thermal.correlations), must settle the outer ring at
70 +- 10 degC (the network's half of the check; the friction's magnitude at these
speeds is the friction laws' half).

Reference speeds (twin.catalog.thermal_reference_speed_rad_s): SKF Rolling bearings catalogue PUB
BU/P1 17000/1 EN (2018), product tables of the 62 series (SKF Explorer): 6205 28 000 r/min, 6208
20 000 r/min, 6210 17 000 r/min. The
twin's speed limit (n d_m <= 1.2e6 mm r/min, twin.model) stops the seed 6208 (d_m = 60.6 mm) at
19 800 r/min: it runs there, 1 % below its reference speed.

The contacts' inlet is shear-heated (Thermal.shear_heating, the Murch-Wilson factor of
twin.physics.thermal: at these speeds and VG 32 at 70 degC it takes 24-29 % off the contacts'
friction; the SKF model's phi_ish takes 31-34 % off its rolling moment there) and no ball churns oil ('flooded'): the
standard's heat flow is the
bearing's whole friction, and with the standard's own oil level (to the centre of the lowest
ball) the drag of the balls alone exceeds it at these speeds, by the SKF model's drag term
(twin.physics.drag.oil_bath_drag_moment_n_m: 6208 at 19 800 r/min and 70 degC, 195 W against
q_r A_r = 110 W; `test_skf_drag_alone_exceeds_the_reference_heat_flow`)."""

import pytest

from twin import catalog
from twin.friction_power import boundary_dimensions_m, oil_level_m
from twin.model import make_model
from twin.physics import drag, viscosity
from twin.spec import BearingSpec, Lubrication, Thermal
from twin.thermal.network import network_geometry
from twin.thermal.settings import ThermalNetworkSettings
from twin.validation.thermal_steady import steady_operating_point

pytestmark = pytest.mark.slow

BEARINGS = ("6205", "6208", "6210")


def _reference_speed_rad_s(designation):
    return min(
        catalog.thermal_reference_speed_rad_s(designation),
        make_model(catalog.bearing(designation)).max_shaft_speed_rad_s,
    )


def _reference_point(designation):
    c0 = catalog.load_ratings(designation).static_load_rating_n
    base = catalog.bearing(designation, lubricant=catalog.lubricant("ISO VG 32"))
    spec = BearingSpec.model_validate({**base.model_dump(), "thermal": Thermal(shear_heating=True).model_dump()})
    settings = ThermalNetworkSettings(dissipation="iso_15312")
    r = steady_operating_point(
        designation, _reference_speed_rad_s(designation), 0.05 * c0, 0.0, 20.0, settings, spec=spec
    )
    phi_r = network_geometry(spec, settings).iso_15312_dissipation_w_k * 50.0
    return r, phi_r


@pytest.mark.parametrize("designation", BEARINGS)
def test_network_carries_the_standards_rise_for_the_heat_it_gets(designation):
    # the network's half: with the standard's dissipation the outer ring rises 50 K x heat / (q_r A_r) over the
    # ambient (ISO 15312 clauses 4-5), within 5 % (the rings' and balls' internal gradients)
    r, phi_r = _reference_point(designation)
    assert r["converged"]
    rise = r["temperatures_c"]["outer_ring"] - 20.0
    assert rise == pytest.approx(50.0 * r["heat_total_w"] / phi_r, rel=0.05), (rise, r["heat_total_w"], phi_r)


@pytest.mark.parametrize("designation", BEARINGS)
def test_outer_ring_settles_at_70_with_the_standard_dissipation(designation):
    # the acceptance band (ISO 15312 clause 4: the outer ring at 70 degC at the reference speed), 70 +- 10 degC, and
    # the friction power at the reference point against the reference heat flow q_r A_r within 30 % (measured 1.01 /
    # 1.11 / 1.04 x for the 6205 / 6208 / 6210)
    r, phi_r = _reference_point(designation)
    assert r["converged"]
    assert r["heat_total_w"] == pytest.approx(phi_r, rel=0.3), (r["heat_total_w"], phi_r)
    assert r["temperatures_c"]["outer_ring"] == pytest.approx(70.0, abs=10.0), r


@pytest.mark.parametrize("designation", BEARINGS)
def test_skf_drag_alone_exceeds_the_reference_heat_flow(designation):
    # why the reference point runs without churning: the SKF model's drag term (SKF catalogue 2018, 'Drag losses in
    # oil bath lubrication'; twin.physics.drag) at the standard's oil level (the centre of the lowest ball) and its
    # oil (ISO VG 32 at the outer ring's 70 degC) dissipates more than the whole reference heat flow q_r A_r
    # (ISO 15312 clause 5, 0.016 W/mm^2) at each reference speed, or nearly: VG 32 at 70 degC is 11.2 mm^2/s; 6205
    # at 28 000 r/min 55.5 W against 58.1 W (0.96 x), 6208 at 19 800 r/min 194.5 W against 109.7 W (1.77 x), 6210 at
    # 17 000 r/min 239.3 W against 140.7 W (1.70 x); with the contacts' friction on top no bath meets the standard
    spec = catalog.bearing(designation, lubrication=Lubrication(method="oil_bath"))
    lub = catalog.lubricant("ISO VG 32")
    nu = viscosity.kinematic_viscosity_m2_s(lub.kinematic_viscosity_40c_m2_s, lub.kinematic_viscosity_100c_m2_s, 70.0)
    speed = _reference_speed_rad_s(designation)
    d, big_d = boundary_dimensions_m(spec.geometry)
    drag_w = drag.oil_bath_drag_moment_n_m(d, big_d, oil_level_m(spec), speed, nu, 3.1) * speed
    _, phi_r = _reference_point_geometry(designation)
    assert drag_w / phi_r > 0.9, (drag_w, phi_r)


def _reference_point_geometry(designation):
    settings = ThermalNetworkSettings(dissipation="iso_15312")
    return None, network_geometry(catalog.bearing(designation), settings).iso_15312_dissipation_w_k * 50.0
