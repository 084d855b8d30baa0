"""Seed 000 Fig. 7 and seed 004 section 3.1: ball spin, cage speed and defect frequencies at
500 rad/s; slide-to-roll ratio near zero in steady state, not during start-up."""

import math

import numpy as np
import pytest

from twin.engine import Twin
from twin.kernels import layout as L
from twin.setpoint import Setpoint
from twin.spec import ModelOptions
from twin.vibration.defect_frequencies import bearing_defect_frequencies

TOL = 0.01  # spin, cage speed and defect frequencies within 1 % of the kinematic relations


@pytest.fixture(scope="module")
def steady(time_step):
    twin = Twin(
        "6208",
        options=ModelOptions(time_step_s=time_step),
        setpoint=Setpoint(shaft_speed_rad_s=500.0, radial_load_n=3000.0),
    )
    twin.advance(0.02)
    return twin, twin.snapshot()


def test_ball_spin_is_952_rad_s(steady):
    # seed 000 section 3.1: omega_ball = omega Ri / (2 Rb) = 500 * 24.0 / 12.6 = 952.38 rad/s
    twin, snap = steady
    hand = 500.0 * 24.0 / (2 * 6.3)
    assert hand == pytest.approx(952.38, abs=0.01)
    for ball in snap.balls:
        assert ball.spin_rad_s == pytest.approx(hand, rel=TOL)


def test_cage_speed_and_defect_frequencies(steady):
    twin, snap = steady
    g = 6.3 / 30.3  # D cos(alpha) / dm
    fs = 500.0 / (2 * math.pi)
    ftf = 0.5 * fs * (1 - g)
    expected = {
        "ftf_hz": ftf,
        "bpfo_hz": 9 * ftf,
        "bpfi_hz": 4.5 * fs * (1 + g),
        "bsf_hz": fs * 30.3 / 12.6 * (1 - g * g),
    }
    nominal = bearing_defect_frequencies(twin.model.spec.geometry, 500.0)
    assert {k: getattr(nominal, k) for k in expected} == pytest.approx(expected, rel=1e-12)
    cage = snap.cage_speed_rad_s
    orbit = np.mean([b.orbital_speed_rad_s for b in snap.balls])
    spin_rel_cage = np.mean(np.abs(twin.state.ball_angular_velocity_rad_s[:, 2] - cage))
    simulated = {
        "ftf_hz": cage / (2 * math.pi),
        "bpfo_hz": 9 * orbit / (2 * math.pi),
        "bpfi_hz": 9 * (snap.shaft_speed_rad_s - orbit) / (2 * math.pi),
        "bsf_hz": spin_rel_cage / (2 * math.pi),
    }
    for key, value in simulated.items():
        assert value == pytest.approx(expected[key], rel=TOL), key


def test_slide_to_roll_ratio_near_zero_in_steady_state(steady):
    twin, snap = steady
    srr = [abs(c.slide_roll_ratio) for b in snap.balls for c in (b.inner, b.outer) if c.load_n > 50]
    assert len(srr) >= 6  # the loaded zone: 3-5 balls, two contacts each
    assert max(srr) < 1e-3


def test_slide_to_roll_ratio_is_large_during_start_up(time_step):
    # start from rest with the load on and a fast ramp (seed 000 Fig. 7b: SRR peaks at start-up)
    options = ModelOptions(speed_ramp_rad_s2=2e5, time_step_s=time_step)
    twin = Twin("6208", options=options, setpoint=Setpoint(shaft_speed_rad_s=500.0, radial_load_n=3000.0))
    twin.reset(shaft_speed_rad_s=0.0)  # quasi-static equilibrium under load, at rest
    peak = 0.0
    for _ in range(10):
        twin.advance(0.0002)
        c = twin.state.contacts
        loaded = c[L.C_LOAD] > 50
        peak = max(peak, float(np.max(np.abs(c[L.C_SRR][loaded]))))
    assert peak > 0.05
    twin.advance(0.03)
    assert twin.snapshot().shaft_speed_rad_s == pytest.approx(500.0)
    c = twin.state.contacts
    assert np.max(np.abs(c[L.C_SRR][c[L.C_LOAD] > 50])) < 1e-3


def test_kinetic_energy_by_hand():
    """The frame's energy balance (`Twin.kinetic_energy_j`, twin.state_measures): rigid-body
    kinetic energy 0.5 m |v|^2 + 0.5 I |omega|^2 per ball (solid sphere, I = 2/5 m r^2) plus the
    cage's 0.5 I_c omega_c^2 (its mass at the pitch radius), from the spec's density and geometry.
    Set velocities, so the sum is known exactly; relative tolerance 1e-12 (rounding)."""
    twin = Twin("6208")
    g, rho = twin.model.spec.geometry, twin.model.spec.material.density_kg_m3
    s = twin.state
    z = g.ball_count
    s.ball_velocity_m_s[:] = np.arange(3 * z, dtype=float).reshape(z, 3) * 0.1
    s.ball_angular_velocity_rad_s[:] = 100.0 + np.arange(3 * z, dtype=float).reshape(z, 3)
    s.scalars[L.X_CAGE_SPEED] = 210.0
    rb = g.ball_radius_m
    m = rho * 4.0 / 3.0 * math.pi * rb**3
    expected = (
        0.5 * m * float(np.sum(s.ball_velocity_m_s**2))
        + 0.5 * 0.4 * m * rb**2 * float(np.sum(s.ball_angular_velocity_rad_s**2))
        + 0.5 * g.cage_mass_kg * g.pitch_radius_m**2 * 210.0**2
    )
    assert twin.kinetic_energy_j() == pytest.approx(expected, rel=1e-12)
