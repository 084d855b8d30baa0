"""Defect frequencies (twin.vibration.defect_frequencies) against published numbers."""

import math

import numpy as np
import pytest

from twin import catalog
from twin.vibration.defect_frequencies import (
    bearing_defect_frequencies,
    defect_frequencies,
    loaded_contact_angle_rad,
)

INCH = 0.0254


@pytest.mark.parametrize(
    "name, z, d_in, dm_in, published",
    [
        # Case Western Reserve University Bearing Data Center, bearing information page: SKF deep-groove
        # bearings of the test rig, defect frequencies as multiples of the running speed; its "rolling
        # element" column is 2 x BSF.
        (
            "6205-2RS JEM (drive end)",
            9,
            0.3126,
            1.537,
            {"bpfi": 5.4152, "bpfo": 3.5848, "ftf": 0.39828, "two_bsf": 4.7135},
        ),
        (
            "6203-2RS JEM (fan end)",
            8,
            0.2656,
            1.122,
            {"bpfi": 4.9469, "bpfo": 3.0530, "ftf": 0.3817, "two_bsf": 3.9874},
        ),
    ],
)
def test_orders_match_the_published_cwru_table(name, z, d_in, dm_in, published):
    """Randall & Antoni 2011 eqs. 1-4 reproduce the published orders to their 5 digits (2e-4)."""
    f = defect_frequencies(d_in * INCH, dm_in * INCH, z, shaft_speed_rad_s=2 * math.pi * 29.95)
    orders = f.orders()
    for key, value in published.items():
        assert orders[key] == pytest.approx(value, rel=2e-4), (name, key)


def test_ball_pass_frequencies_sum_to_z_times_shaft_frequency():
    """BPFO + BPFI = Z f_s and BPFO = Z FTF (eqs. 1-3), for any contact angle."""
    for alpha_deg in (0.0, 15.0, 40.0):
        f = defect_frequencies(12.6e-3, 60.6e-3, 13, 500.0, math.radians(alpha_deg))
        assert f.bpfo_hz + f.bpfi_hz == pytest.approx(13 * 500.0 / (2 * math.pi), rel=1e-14)
        assert f.bpfo_hz == pytest.approx(13 * f.ftf_hz, rel=1e-14)


def test_6208_bpfo_by_hand():
    """The catalog 6208 at 500 rad/s (nominal angle 0): BPFO = Z / 2 f_s (1 - D / d_m) (eq. 1)."""
    spec = catalog.bearing("6208")
    ours = bearing_defect_frequencies(spec.geometry, 500.0)
    # 6208 at 500 rad/s: BPFO = 4.5 f_s (1 - 12.6/60.6) = 283.7 Hz
    assert ours.bpfo_hz == pytest.approx(4.5 * 500 / (2 * math.pi) * (1 - 12.6 / 60.6), rel=1e-12)


def test_angular_contact_frequencies_follow_the_loaded_angle():
    """7208: a larger loaded contact angle lowers gamma = D cos(alpha)/d_m: BPFO, FTF and BSF
    (1 - gamma^2) rise, BPFI falls; at 40 deg BPFO = Z f_s / 2 (1 - D cos 40 / d_m) exactly."""
    g = catalog.bearing("7208C").geometry
    f15 = bearing_defect_frequencies(g, 500.0)  # 7208C: nominal 15 deg
    f40 = bearing_defect_frequencies(g, 500.0, math.radians(40.0))
    assert f40.bpfo_hz > f15.bpfo_hz and f40.ftf_hz > f15.ftf_hz and f40.bsf_hz > f15.bsf_hz
    assert f40.bpfi_hz < f15.bpfi_hz
    gamma = 2 * g.ball_radius_m * math.cos(math.radians(40.0)) / (2 * g.pitch_radius_m)
    assert f40.bpfo_hz == pytest.approx(13 / 2 * 500 / (2 * math.pi) * (1 - gamma), rel=1e-14)
    assert f15.contact_angle_rad == pytest.approx(math.radians(15.0))


def test_loaded_contact_angle_is_the_mean_over_loaded_balls():
    z = 9
    nz = np.zeros(2 * z)
    load = np.zeros(2 * z)
    loaded = [0, 1, 2, 8]
    for j in loaded:
        nz[2 * j] = -math.sin(math.radians(18.0 + j))  # inner normal points down
        nz[2 * j + 1] = math.sin(math.radians(20.0 + j))  # outer up
        load[2 * j : 2 * j + 2] = 100.0 + j
    nz[2 * 4 : 2 * 4 + 2] = 0.9  # an unloaded ball's geometry must not count
    load[2 * 5] = 50.0  # loaded at one raceway only: not a loaded ball
    expected = np.mean([math.radians(19.0 + j) for j in loaded])
    assert loaded_contact_angle_rad(nz, load) == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ValueError, match="no loaded contact"):
        loaded_contact_angle_rad(nz, np.zeros(2 * z))


def test_bad_geometry_is_refused():
    with pytest.raises(ValueError, match="ball_diameter_m"):
        defect_frequencies(0.07, 0.06, 9, 100.0)
    with pytest.raises(ValueError, match="contact_angle_rad"):
        defect_frequencies(0.01, 0.06, 9, 100.0, 2.0)
