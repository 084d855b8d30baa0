"""The friction power by source (twin.friction_power, Twin.friction_power_w) and the friction
torque's definition (twin.friction_power.frame_friction_torque_n_m)."""

import numpy as np
import pytest

from twin import catalog
from twin.engine import Twin
from twin.friction_power import boundary_dimensions_m, oil_level_m
from twin.kernels import layout as L
from twin.physics import drag, starvation
from twin.physics.viscosity import density_kg_m3
from twin.setpoint import Setpoint
from twin.spec import Lubrication


def _mean_over_frames(twin, frames=10):
    torque, power = [], []
    for _ in range(frames):
        twin.advance(1e-3)
        fp = twin.friction_power_w()
        torque.append(twin.snapshot().friction_torque_n_m * float(twin.state.scalars[L.X_SHAFT_SPEED]))
        power.append(fp.rolling_w + fp.sliding_w + fp.spin_w)
    return float(np.mean(torque)), float(np.mean(power)), fp


@pytest.mark.parametrize("speed, load", [(500.0, 3000.0), (1500.0, 1000.0)])
def test_contact_powers_balance_the_shaft_power(speed, load):
    # energy balance of the DEM in steady running: the shaft's power M omega is dissipated by the
    # contacts' rolling, sliding and spin (no other sink when flooded); 10 frames of 1 ms
    twin = Twin("6208", setpoint=Setpoint(shaft_speed_rad_s=speed, radial_load_n=load))
    twin.advance(0.02)
    shaft_w, contacts_w, fp = _mean_over_frames(twin)
    assert contacts_w == pytest.approx(shaft_w, rel=0.03)
    assert fp.rolling_contact_w.shape == (twin.model.ball_count, 2)
    assert fp.drag_w == 0.0 and fp.seal_w == 0.0
    assert np.all(fp.rolling_contact_w >= 0.0) and np.all(fp.sliding_contact_w >= 0.0)
    snap = twin.snapshot()
    assert snap.friction_power_w.rolling == pytest.approx(fp.rolling_w, rel=1e-9)


def test_friction_torque_is_not_negative_from_start_to_rest():
    # seed 000 Fig. 7's start-up (0 -> 500 rad/s at 5000 rad/s^2), steady, slow-down, rest: the
    # drive torque carries the balls' and cage's inertia (negative while they slow down, down to
    # -0.04 N m); the friction torque does not
    twin = Twin("6208", setpoint=Setpoint(shaft_speed_rad_s=0.0, radial_load_n=3000.0))
    rows = []
    for t_end, speed in ((0.15, 500.0), (0.25, 500.0), (0.4, 0.0)):
        twin.set_setpoint(shaft_speed_rad_s=speed)
        while twin.time_s < t_end - 1e-9:
            s = twin.state.scalars
            before = float(s[L.X_SHAFT_SPEED])
            twin.advance(1e-3)
            rows.append(
                (
                    0.5 * (before + float(s[L.X_SHAFT_SPEED])),
                    twin.snapshot().friction_torque_n_m,
                    s[L.X_TORQUE_SUM] / s[L.X_TORQUE_COUNT],
                )
            )
    speed, friction, drive = np.array(rows).T  # speed: the frame's mean shaft speed
    turning = speed > 0.0
    assert drive.min() < -0.02  # the inertia the drive torque carries
    assert friction[turning].min() > 0.0
    # at rest: the torque the tangential springs still hold (elastic, not dissipative), within
    # +-3 mN m, 2 % of the running torque
    assert np.abs(friction[~turning]).max() < 3e-3
    steady = (np.arange(len(speed)) >= 110) & (np.arange(len(speed)) < 250)
    assert friction[steady].mean() == pytest.approx(drive[steady].mean(), rel=0.01)


def test_oil_bath_starves_the_film_and_adds_drag_and_seal():
    # the film of every contact falls by the replenishment factor (twin.physics.starvation);
    # drag and seal add their power and their torque (power / omega, M_seal)
    setpoint = Setpoint(shaft_speed_rad_s=1000.0, radial_load_n=3000.0)
    flooded = Twin("6208", setpoint=setpoint)
    bath = Twin(catalog.bearing("6208", lubrication=Lubrication(method="oil_bath", seal="2RS")), setpoint=setpoint)
    for twin in (flooded, bath):
        twin.advance(0.02)
    lub = catalog.lubricant()
    nu = flooded._oil_viscosity_pa_s / (lub.density_15c_kg_m3 * (1.0 - 6.5e-4 * 25.0))
    phi = starvation.kinematic_replenishment_factor(1000.0, nu, 40e-3, 80e-3, 3e-8, 3.1)
    assert phi < 0.8
    h_flooded = flooded.snapshot().balls[0].outer.h_min_m
    h_bath = bath.snapshot().balls[0].outer.h_min_m
    assert h_bath / h_flooded == pytest.approx(phi, rel=0.02)
    fp = bath.friction_power_w()
    assert fp.seal_w == pytest.approx(bath._seal_moment_n_m * 1000.0, rel=1e-9)
    # the bath's drag (the SKF model's drag term, twin.physics.drag) goes to the balls in the oil, shared by the part
    # of each in it; it is the bath's drag at the shaft speed (the same law as the torque's, the same instant)
    in_oil = fp.drag_ball_w > 0.0
    assert 0 < np.count_nonzero(in_oil) < bath.model.ball_count
    d, big_d = boundary_dimensions_m(bath.model.spec.geometry)
    nu = bath._oil_viscosity_pa_s / density_kg_m3(lub.density_15c_kg_m3, 40.0)
    skf = drag.oil_bath_drag_moment_n_m(d, big_d, oil_level_m(bath.model.spec), 1000.0, nu, 3.1) * 1000.0
    assert fp.drag_w == pytest.approx(skf, rel=1e-6)
    assert bath.drag_power_w == pytest.approx(skf, rel=1e-6)
    added = bath.snapshot().friction_torque_n_m - bath.contact_friction_torque_n_m
    assert added == pytest.approx(bath.drag_power_w / 1000.0 + bath._seal_moment_n_m, rel=1e-9)
