"""The ball's speeds under outer raceway control and its gyroscopic moment
(twin.validation.analytic.outer_control_kinematics, gyroscopic_moment_n_m), by hand against the
closed forms of Harris and Kotzalas (Rolling Bearing Analysis, 5th ed. 2007, vol. 1 ch. 8 and
vol. 2 ch. 2-3) for equal inner and outer contact angles alpha, gamma = D / d_m, the inner ring at
omega and the outer fixed:

- the orbit omega_m = omega (1 - gamma cos(alpha)) / 2;
- the pitch of the spin axis in the cage's frame tan(beta) = sin(alpha) / (cos(alpha) + gamma);
- the spin omega_R / omega = -(1 - gamma^2 cos^2(alpha)) / (2 gamma cos(alpha - beta));
- M_g = J omega_R omega_m sin(beta), J = m D^2 / 10.

A deep-groove ball (alpha = 0) spins about an axis parallel to the bearing's: beta = 0, no
gyroscopic moment, and omega_R / omega = -(1 - gamma^2) / (2 gamma) (vol. 1 ch. 8)."""

import math

import numpy as np
import pytest

from twin.validation.analytic import gyroscopic_moment_n_m, outer_control_kinematics

PITCH_RADIUS_M = 0.0303  # the 7208's d_m / 2
BALL_RADIUS_M = 0.0063
GAMMA = BALL_RADIUS_M / PITCH_RADIUS_M
OMEGA = 1500.0  # inner ring [rad/s]


def _normals(alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """(ball -> inner groove centre, outer groove centre -> ball) in (z, rho) for equal contact angles:
    the inner contact at (-cos, +sin) and the outer at (+cos, -sin) from the ball's centre in (rho, z)."""
    n = np.array([-math.sin(alpha), math.cos(alpha)])
    return n, n.copy()


@pytest.mark.parametrize("alpha_deg", [0.0, 15.0, 25.0, 40.0])
def test_outer_raceway_control_speeds_by_hand(alpha_deg):
    alpha = math.radians(alpha_deg)
    w_rho, w_z, w_m = outer_control_kinematics(PITCH_RADIUS_M, BALL_RADIUS_M, *_normals(alpha), OMEGA)
    assert w_m == pytest.approx(OMEGA * (1.0 - GAMMA * math.cos(alpha)) / 2.0, rel=1e-12)
    beta = math.atan(math.sin(alpha) / (math.cos(alpha) + GAMMA))
    w_r = -OMEGA * (1.0 - (GAMMA * math.cos(alpha)) ** 2) / (2.0 * GAMMA * math.cos(alpha - beta))
    # the spin vector in the cage's frame: omega_R (sin(beta) e_rho + cos(beta) e_z)
    assert w_rho == pytest.approx(w_r * math.sin(beta), rel=1e-12, abs=1e-9)
    assert w_z == pytest.approx(w_r * math.cos(beta), rel=1e-12)
    # no spin at the outer contact: the absolute angular velocity is normal to the outer contact's direction
    assert w_rho * math.cos(alpha) - (w_z + w_m) * math.sin(alpha) == pytest.approx(0.0, abs=1e-9)
    mass = 7850.0 * 4.0 / 3.0 * math.pi * BALL_RADIUS_M**3
    inertia = 0.4 * mass * BALL_RADIUS_M**2
    m_g = gyroscopic_moment_n_m(inertia, w_rho, w_m)
    assert m_g == pytest.approx(inertia * w_r * w_m * math.sin(beta), rel=1e-12, abs=1e-15)
    if alpha_deg == 0.0:
        assert m_g == 0.0
