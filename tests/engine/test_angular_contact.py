"""Seed 004 section 3.1: the 7208 under combined Fr = Fa = 3000 N; load parameter
eps = (1 + delta_a tan(alpha) / delta_r) / 2 > 0.5, i.e. a loaded zone wider than half the bearing."""

import math

import numpy as np
import pytest

from twin.engine import Twin
from twin.setpoint import Setpoint
from twin.spec import ModelOptions


@pytest.fixture(scope="module")
def combined(time_step):
    twin = Twin("7208", options=ModelOptions(time_step_s=time_step),
                setpoint=Setpoint(shaft_speed_rad_s=500.0, radial_load_n=3000.0, axial_load_n=3000.0))
    twin.advance(0.02)
    return twin, twin.snapshot()


def test_catalog_7208_is_seed_004(combined):
    twin, _ = combined
    g = twin.model.spec.geometry
    assert (g.ball_count, g.cage_element_radius_m, g.ball_radius_m) == (13, 1.01e-3, 6.3e-3)
    b = (g.inner_groove_radius_m + g.outer_groove_radius_m) / (2 * g.ball_radius_m) - 1.0
    assert b == pytest.approx(0.14, rel=1e-9)  # conformity B of seed 004 section 3.1


def test_loaded_zone_wider_than_half(combined):
    twin, snap = combined
    assert snap.status == "ok"
    dx, dy, dz = snap.inner_ring_displacement_m
    delta_r = math.hypot(dx, dy)
    alpha = twin.model.contact_angle_rad
    eps = 0.5 * (1.0 + dz * math.tan(alpha) / delta_r)
    assert eps > 0.5
    loads = np.array([b.inner.load_n for b in snap.balls])
    az = np.array([b.azimuth_rad for b in snap.balls])
    loaded = loads > 1.0
    assert loaded.sum() > 13 / 2
    # the loaded zone agrees with eps: every ball inside cos(psi) > 1 - 2 eps is loaded
    inside = np.cos(az) > 1.0 - 2.0 * eps + 0.05
    assert np.all(loaded[inside])
    if eps > 1.0:
        assert loaded.all()
    # the load is highest on the radial-load side
    assert loads[np.argmax(np.cos(az))] == pytest.approx(loads.max(), rel=0.1)
    # axial equilibrium: the contact forces carry Fa
    fa = sum(b.inner.load_n * math.sin(abs(b.inner.contact_angle_rad)) for b in snap.balls)
    assert fa == pytest.approx(3000.0, rel=0.05)
