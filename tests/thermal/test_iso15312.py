"""ISO 15312:2018 reference conditions in the thermal network with the standard's dissipation:
P = 0.05 C0 radial, ISO VG 32, ambient 20 degC, the catalogue's thermal reference speed; the
standard states the outer ring runs at 70 degC there. The twin's own friction heat, with the
standard's dissipation q_r A_r per 50 K (twin.thermal.correlations), must settle the outer ring at
70 +- 10 degC (the network's half of the issue's acceptance; the friction's magnitude at these
speeds is the friction laws' half).

Reference speeds: SKF Rolling bearings catalogue PUB BU/P1 17000/1 EN (2018), product tables of
the 62 series (SKF Explorer): 6205 28 000 r/min, 6208 20 000 r/min, 6210 17 000 r/min. The
twin's speed limit (n d_m <= 1.2e6 mm r/min, twin.model) stops the seed 6208 (d_m = 60.6 mm) at
19 800 r/min: it runs there, 1 % below its reference speed."""

import math

import pytest

from twin import catalog
from twin.thermal.settings import ThermalNetworkSettings
from twin.thermal.steady import steady_operating_point

pytestmark = pytest.mark.slow

REFERENCE_SPEED_RPM = {"6205": 28_000.0, "6208": 20_000.0, "6210": 17_000.0}


FRICTION_TOO_HIGH = pytest.mark.xfail(
    strict=True, reason="the friction laws' heat at 19 800 r/min is 137 W against the standard's reference heat flow "
    "q_r A_r = 110 W (+25 %): the outer ring settles at 82.9 degC. The network carries the standard's 50 K per "
    "q_r A_r (63 K for 137 W); the excess is the friction's, which the friction laws' branch addresses.")


@pytest.mark.parametrize("designation", ["6205", pytest.param("6208", marks=FRICTION_TOO_HIGH), "6210"])
def test_outer_ring_settles_at_70_with_the_standard_dissipation(designation):
    c0 = catalog.load_ratings(designation).static_load_rating_n
    spec = catalog.bearing(designation)
    limit_rpm = 1.2e6 / (2.0 * spec.geometry.pitch_radius_m * 1e3)
    speed = min(REFERENCE_SPEED_RPM[designation], limit_rpm) * 2.0 * math.pi / 60.0
    r = steady_operating_point(designation, speed, 0.05 * c0, 0.0, 20.0,
                               ThermalNetworkSettings(dissipation="iso_15312"), catalog.lubricant("ISO VG 32"))
    assert r["converged"]
    assert r["temperatures_c"]["outer_ring"] == pytest.approx(70.0, abs=10.0), r
