"""The healthy bearing's excitation (twin.vibration.surface) and the `CWRU-DE` catalog entry."""

import json
import math

import numpy as np
import pytest
from pydantic import ValidationError

from twin import catalog
from twin.kernels import layout as L
from twin.kernels.profile import profile_drops, profile_height_m
from twin.validation.vibration_simulation import defect_for
from twin.vibration.defect_frequencies import bearing_defect_frequencies
from twin.vibration.housing import sensor_resonance
from twin.vibration.surface import ball_radius_offsets_m, race_profile_m


def test_race_profile_has_the_rms_and_the_orders_asked():
    """The profile's RMS is the one asked (1e-12 relative) and its spectrum holds exactly the
    orders 2 .. 2 pi R / lambda_min with equal amplitudes (module docstring's Fourier series)."""
    radius, lam, rms = 23.49e-3, 0.3e-3, 0.05e-6
    h = race_profile_m(rms, radius, lam, np.random.default_rng(1))
    assert math.sqrt(np.mean(h * h)) == pytest.approx(rms, rel=1e-12)
    a = np.abs(np.fft.rfft(h))
    n_max = int(2 * math.pi * radius / lam)
    assert np.all(a[:2] < 1e-9 * a.max())
    assert np.all(a[n_max + 1 :] < 1e-9 * a.max())
    assert np.ptp(a[2 : n_max + 1]) < 1e-9 * a.max()


def test_profile_interpolation_is_periodic_and_exact_on_the_grid():
    p = np.zeros(L.N_PARAMS)
    h = race_profile_m(1e-7, 0.02, 0.3e-3, np.random.default_rng(2))
    p[L.P_PROFILE_OUTER : L.P_PROFILE_OUTER + L.PROFILE_POINTS] = h
    step = 2 * math.pi / L.PROFILE_POINTS
    for i in (0, 1, 1000, L.PROFILE_POINTS - 1):
        assert profile_height_m(p, L.P_PROFILE_OUTER, i * step) == pytest.approx(h[i], abs=1e-20)
        assert profile_height_m(p, L.P_PROFILE_OUTER, i * step - 2 * math.pi) == pytest.approx(h[i], abs=1e-18)
    mid = profile_height_m(p, L.P_PROFILE_OUTER, (L.PROFILE_POINTS - 0.5) * step)
    assert mid == pytest.approx(0.5 * (h[-1] + h[0]), abs=1e-18)


def test_profile_at_a_tiny_negative_angle_is_the_height_at_zero():
    """A ball at azimuth 0 with the ring 1e-12 m off the axis reads the profile at angle -5e-17 rad,
    which wraps to exactly PROFILE_POINTS: point 0, not 4096 x the slope to point 1 (the
    CWRU-DE warm start at 1796 rpm read -110 um there and restarted at every step)."""
    p = np.zeros(L.N_PARAMS)
    h = race_profile_m(5e-8, 0.0156, 0.3e-3, np.random.default_rng(0))
    p[L.P_PROFILE_INNER : L.P_PROFILE_INNER + L.PROFILE_POINTS] = h
    for angle in (-1e-17, -5e-17, -1e-300, -0.0, 0.0):
        assert profile_height_m(p, L.P_PROFILE_INNER, angle) == pytest.approx(h[0], abs=1e-18)
    assert profile_height_m(p, L.P_PROFILE_INNER, math.atan2(-1.05e-12, 19.5e-3)) == pytest.approx(h[0], abs=1e-14)


@pytest.mark.parametrize("shaft_angle", [0.0, 2.5, -7.0, 4.0e4])
def test_profile_drops_read_each_lane_where_its_ball_is(shaft_angle):
    """`profile_drops` (one azimuth per ball, the inner lane's by the small angle between the
    lanes) against the definition lane by lane: libm's atan2 of each lane's own centre and
    `profile_height_m` (the inner race turned with the shaft), plus the ball's radius offset.
    Balls anywhere on the circle (with one at azimuth -1e-17 rad), the inner ring 80 um off the
    outer's centre: within the azimuth's 2e-8 rad times the table's steepest slope (the read point
    moves by 1e-5 of a table step)."""
    z = 9
    rng = np.random.default_rng(4)
    p = np.zeros(L.N_PARAMS)
    p[L.P_PROFILE_INNER : L.P_PROFILE_INNER + L.PROFILE_POINTS] = race_profile_m(1e-7, 0.024, 0.3e-3, rng)
    p[L.P_PROFILE_OUTER : L.P_PROFILE_OUTER + L.PROFILE_POINTS] = race_profile_m(1e-7, 0.0366, 0.3e-3, rng)
    p[L.P_BALL_SIZE : L.P_BALL_SIZE + z] = ball_radius_offsets_m(0.125e-6, z, rng)
    w = np.zeros(L.N_ROWS * L.CW)
    azimuths = np.concatenate([[-1e-17], rng.uniform(-math.pi, math.pi, z - 1)])
    offset = np.array([60e-6, -50e-6])  # the inner ring's centre relative to the outer's [m]
    for j, phi in enumerate(azimuths):
        centre = 30.3e-3 * np.array([math.cos(phi), math.sin(phi)])
        for c, xy in ((2 * j, centre - offset), (2 * j + 1, centre)):
            w[L.K_PX * L.CW + c], w[L.K_PY * L.CW + c] = xy
    step = 2 * math.pi / L.PROFILE_POINTS
    tables = p[L.P_PROFILE_INNER : L.P_PROFILE_OUTER + L.PROFILE_POINTS].reshape(2, -1)
    tol_m = 2e-8 * np.max(np.abs(np.diff(tables, axis=1, append=tables[:, :1]))) / step
    profile_drops(w, 2 * z, p, shaft_angle)
    got = w[L.G_DEFECT_DROP * L.CW : L.G_DEFECT_DROP * L.CW + 2 * z]
    for c in range(2 * z):
        x, y = w[L.K_PX * L.CW + c], w[L.K_PY * L.CW + c]
        if c % 2:
            h = profile_height_m(p, L.P_PROFILE_OUTER, math.atan2(y, x))
        else:
            h = profile_height_m(p, L.P_PROFILE_INNER, math.atan2(y, x) - shaft_angle)
        assert got[c] == pytest.approx(-(h + p[L.P_BALL_SIZE + c // 2]), abs=tol_m), c


def test_ball_offsets_have_zero_mean_and_the_spread():
    """ISO 3290-1 G10 lot variation 0.5 um taken as 4 sigma: radius offsets are half the diameter
    deviations, zero mean; over many balls their std is half the diameter spread (5 %)."""
    d = ball_radius_offsets_m(0.125e-6, 4000, np.random.default_rng(3))
    assert abs(d.mean()) < 1e-18
    assert d.std() == pytest.approx(0.5 * 0.125e-6, rel=0.05)


def test_cwru_de_defect_multiples_are_the_published_ones():
    """CWRU Bearing Data Center, 6205-2RS JEM: BPFI 5.4152, BPFO 3.5848, FTF 0.39828, 2 x BSF
    4.7135 x shaft, from d = 0.3126 in, D = 1.537 in, 9 balls, 0 deg (to the 5 digits published)."""
    spec = catalog.bearing("CWRU-DE")
    f = bearing_defect_frequencies(spec.geometry, 2 * math.pi)
    assert f.bpfi_hz == pytest.approx(5.4152, abs=1e-4)
    assert f.bpfo_hz == pytest.approx(3.5848, abs=1e-4)
    assert f.ftf_hz == pytest.approx(0.39828, abs=1e-4)
    assert 2 * f.bsf_hz == pytest.approx(4.7135, abs=1e-4)
    assert spec.housing.enabled and spec.surface_profile.enabled
    assert spec.housing.accelerometer.azimuth_deg == 180.0  # 12 o'clock, load at 6 o'clock (+x)
    assert catalog.default_radial_load_n("cwru-de") == pytest.approx(3.75 * 9.80665, rel=1e-3)
    assert catalog.default_radial_load_n("6205") is None
    assert "CWRU-DE" in catalog.designations()


def test_cwru_de_senses_the_resonance_calibrated_on_the_healthy_record():
    """The sprung mass of `CWRU-DE` senses the mode found in record 97's spectrum (3234 Hz, 0.0167:
    twin.validation.cwru.calibrate_housing; within 0.5 %)."""
    from twin.validation import cwru

    x = np.load(cwru.DATA_DIR / "97_DE_12k_5s.npy").astype(float)
    f, zeta = cwru.calibrate_housing(x)
    f_twin, zeta_twin = sensor_resonance(catalog.bearing("CWRU-DE").housing)
    assert f_twin == pytest.approx(f, rel=5e-3)
    assert zeta_twin == pytest.approx(zeta, rel=5e-3)


def test_spec_file_round_trips_and_names_the_bad_field(tmp_path):
    spec = catalog.bearing("CWRU-DE")
    path = tmp_path / "rig.json"
    path.write_text(json.dumps(spec.model_dump()))
    assert catalog.bearing_or_file(str(path)) == spec
    yml = tmp_path / "rig.yaml"
    import yaml

    data = spec.model_dump()
    data["geometry"]["ball_count"] = 40
    yml.write_text(yaml.safe_dump(data))
    with pytest.raises(ValidationError, match="ball_count"):
        catalog.bearing_or_file(str(yml))
    with pytest.raises(ValueError, match="cannot read"):
        catalog.bearing_or_file(str(tmp_path / "missing.yaml"))
    bad = tmp_path / "bad.yaml"
    bad.write_text("geometry: [1, 2\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        catalog.bearing_or_file(str(bad))


def test_defect_angle_places_the_outer_spall_from_the_load_zone():
    g = catalog.bearing("CWRU-DE").geometry
    assert defect_for("outer", g, 0.178e-3, 0.178e-3, 0.279e-3, 90.0)["azimuth_deg"] == 90.0
    assert defect_for("outer", g, angle_deg=-90.0)["azimuth_deg"] == 270.0
    assert defect_for("inner", g, angle_deg=30.0)["ring_angle_deg"] == 30.0
    with pytest.raises(ValueError, match="defect_angle_deg"):
        defect_for("outer", g, angle_deg=float("nan"))


def test_cwru_de_noise_floor_is_the_healthy_records_floor():
    """`CWRU-DE`'s sensor noise density is record 97's 2.0-2.9 kHz floor (twin.validation.cwru.
    calibrate_background, within 1 %), and that floor alone fills the record's 2.9-3.6 kHz
    resonance band to within 5 %: the healthy bearing's own excitation is below the floor, which
    bounds the race profile RMS (twin.catalog.CWRU_RACE_PROFILE_RMS_M)."""
    from twin.validation import cwru

    x = np.load(cwru.DATA_DIR / "97_DE_12k_5s.npy").astype(float) * cwru.G_M_S2
    cal = cwru.calibrate_background(x)
    acc = catalog.bearing("CWRU-DE").housing.accelerometer
    assert acc.noise_density_m_s2_rthz == pytest.approx(cal["noise_density_m_s2_rthz"], rel=0.01)
    assert cal["floor_in_resonance_band_m_s2"] == pytest.approx(cal["resonance_band_rms_m_s2"], rel=0.05)
    assert catalog.bearing("CWRU-DE").surface_profile.race_profile_rms_m == catalog.CWRU_RACE_PROFILE_RMS_M


def test_profile_azimuth_is_atan2_to_two_hundredths_of_a_microradian():
    """`azimuth_rad` (Abramowitz & Stegun 4.4.49, |error| <= 2e-8 rad on the octant) against
    math.atan2 over random points of every quadrant, the axes and the diagonals: within 3e-8 rad."""
    from twin.kernels.profile import azimuth_rad

    rng = np.random.default_rng(5)
    pts = list(rng.normal(size=(20000, 2)) * 0.02) + [
        (0.0, 1.0),
        (1.0, 0.0),
        (0.0, -1.0),
        (-1.0, 0.0),
        (1.0, 1.0),
        (-1.0, 1.0),
        (-1.0, -1.0),
        (1.0, -1.0),
    ]
    err = max(abs(azimuth_rad(y, x) - math.atan2(y, x)) for y, x in pts)
    assert err <= 3e-8
