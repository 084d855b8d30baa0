"""The friction power by source (twin.friction_power, Twin.friction_power_w) and the friction
torque's definition (twin.friction_power.frame_friction_torque_n_m)."""

import numpy as np
import pytest

from twin import catalog
from twin.engine import Twin
from twin.friction_power import boundary_dimensions_m, contact_powers_w, oil_level_m
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


def test_contact_powers_of_one_contact_by_hand():
    # the work of the DEM's forces at a contact (twin.friction_power.contact_powers_w): rolling
    # P = -F_R . (v_ball - v_ring(q)), v_ring(q) = v_ring + omega_spin e_z x q, q = p + R n;
    # sliding P = -F_t . s - M2 . (omega_ball - omega_spin e_z), F_t = F - (F . n) n - F_R;
    # spin P = |M_n omega_spin|; an open contact (delta <= 0) none, a negative power floored at 0
    rng = np.random.default_rng(7)
    rows = rng.standard_normal((L.N_ROWS, 4))
    rows[L.G_DELTA] = [1e-6, 1e-6, -1e-6, 1e-6]
    rows[L.K_SPIN] = 30.0
    radius = 6e-3
    w_ball = rng.standard_normal((2, 3)) * 100.0
    rolling, sliding, spin = contact_powers_w(rows, w_ball, radius)

    def lane(*names, k):
        return np.array([rows[getattr(L, n), k] for n in names])

    expected = np.zeros((3, 4))
    for k in (0, 1, 3):
        n = lane("G_NX", "G_NY", "G_NZ", k=k)
        f_roll = rows[L.C_ROLLING_PER_SPEED, k] * lane("O_EX", "O_EY", "O_EZ", k=k)
        q = lane("K_PX", "K_PY", "K_PZ", k=k) + radius * n
        spin_axis = np.array([0.0, 0.0, rows[L.K_SPIN, k]])
        v_ring = lane("K_OVX", "K_OVY", "K_OVZ", k=k) + np.cross(spin_axis, q)
        p_roll = -f_roll @ (lane("K_VX", "K_VY", "K_VZ", k=k) - v_ring)
        f = lane("O_FX", "O_FY", "O_FZ", k=k)
        f_t = f - (f @ n) * n - f_roll
        p_slide = -f_t @ lane("O_SX", "O_SY", "O_SZ", k=k) - lane("E_M2X", "E_M2Y", "E_M2Z", k=k) @ (
            w_ball[k // 2] - spin_axis
        )
        p_spin = abs(rows[L.E_SPIN_MOMENT, k] * rows[L.E_SPIN_RATE, k])
        expected[:, k] = [max(p_roll, 0.0), max(p_slide, 0.0), p_spin]
    for got, want in zip((rolling, sliding, spin), expected, strict=True):
        np.testing.assert_allclose(got.reshape(-1), want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    assert (expected[:2, [0, 1, 3]] == 0.0).any() and (expected[:2] > 0.0).any()  # both sides of the floor


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
