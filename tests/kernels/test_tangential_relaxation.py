"""The tangential spring of the ball-raceway contacts (twin.kernels.contacts.raceway_forces)
forgets with rolling and with spin sliding (C_XI_DECAY, refreshed with the tribology in
twin.kernels.step): integrated by backward Euler, its steady force under a constant slip v is
kt v / rate at any step, a creep law, where Cundall-Strack's spring (rate 0, a contact at rest)
grows without bound until the Coulomb limit."""

import math

import numpy as np
import pytest

from twin.engine import Twin
from twin.kernels import layout as L
from twin.kernels.contacts import raceway_forces
from twin.kernels.step import SPIN_CREEP_FACTOR, evaluate
from twin.physics.friction import stribeck_line_mu
from twin.physics.rolling import asperity_load_share
from twin.setpoint import Setpoint

DT = 1e-6


def _one_contact(decay, slip, k=3e10, sqrt_delta=3e-3):
    w = np.zeros(L.N_ROWS * L.CW)
    for row, value in (
        (L.G_DELTA, sqrt_delta**2),
        (L.G_SQRT_DELTA, sqrt_delta),
        (L.G_NX, 1.0),
        (L.G_LOAD, k * sqrt_delta**3),
        (L.M_STIFFNESS, k),
        (L.C_MU, 10.0),
        (L.K_VY, slip),
        (L.C_XI_DECAY, decay),
    ):
        w[row * L.CW] = value
    return w


@pytest.mark.parametrize("dt", [1e-6, 4.4e-6, 2e-5])
def test_steady_force_under_constant_slip_is_a_creep_law(dt):
    # xi' = v - rate xi by backward Euler: the steady spring is v / rate whatever rate dt (0.2 at
    # 1 us, 0.9 at the 7208's auto step, 4 at 20 us; the spinning 40 deg contacts reach 1-15 at the
    # auto step). Decaying before adding the slip, as first written, gave v (1 / rate + dt): a
    # creep force (1 + rate dt) too large, 1.9x at the auto step against 1.2x at 1 us.
    kt_ratio, slip, rate = 0.8, 1e-3, 2e5  # [-], [m/s], [1/s]
    w = _one_contact(1.0 / (1.0 + rate * dt), slip)
    for _ in range(400):  # at least 80 relaxation times
        raceway_forces(w, 1, 6.3e-3, dt, kt_ratio, 0.08)
    kt = kt_ratio * 1.5 * 3e10 * 3e-3
    assert -w[L.O_FY * L.CW] == pytest.approx(kt * slip / rate, rel=1e-9)


def test_without_relaxation_the_spring_keeps_growing():
    kt_ratio, slip = 0.8, 1e-3
    w = _one_contact(1.0, slip)
    for _ in range(200):
        raceway_forces(w, 1, 6.3e-3, DT, kt_ratio, 0.08)
    kt = kt_ratio * 1.5 * 3e10 * 3e-3
    assert -w[L.O_FY * L.CW] == pytest.approx(kt * slip * 200 * DT, rel=1e-9)


def test_refresh_rate_is_rolling_plus_spin_sliding():
    # rate = u / sqrt(a b) + kt |w_spin| sqrt(a b) / (1.3 mu Q) for every loaded contact of a
    # 7208 (40 deg: the balls spin against the rings). mu is the limiting coefficient of the fully
    # sliding traction that tests/physics/test_spin_creep.py linearises: with the friction over
    # the ellipse (the default) the traction capacity over Q, Qa/Q mu(Lambda) + (1 - Qa/Q) gamma
    # (seed 001 eq. A2, seed 000 section 2.3, Bair-Winer gamma), refreshed with the tribology; not
    # the effective |F_t| / Q the snapshot publishes (~1e-3 in rolling) nor seed 000's line alone.
    twin = Twin("7208", setpoint=Setpoint(shaft_speed_rad_s=500.0, radial_load_n=0.0, axial_load_n=3000.0))
    twin.advance(0.002)
    m = twin.model
    evaluate(*twin._kernel_args())
    c = twin.state.contacts
    gamma = m.spec.lubricant.limiting_shear_coefficient
    snap = twin.snapshot()
    published = [b.inner.mu for b in snap.balls] + [b.outer.mu for b in snap.balls]
    checked, spins = 0, []
    for k in range(2 * m.ball_count):
        q = c[L.C_LOAD, k]
        if q <= 0.0:
            continue
        lam = c[L.C_LAMBDA, k]
        share = asperity_load_share(lam)
        mu = share * stribeck_line_mu(lam) + (1.0 - share) * gamma
        assert c[L.C_MU, k] == pytest.approx(mu, rel=1e-12)
        ab = math.sqrt(c[L.C_SEMI_MAJOR, k] * c[L.C_SEMI_MINOR, k])
        kt = m.options.tangential_stiffness_ratio * 1.5 * c[L.M_STIFFNESS, k] * c[L.G_SQRT_DELTA, k]
        spin = abs(
            c[L.K_WX, k] * c[L.G_NX, k] + c[L.K_WY, k] * c[L.G_NY, k] + (c[L.K_WZ, k] - c[L.K_SPIN, k]) * c[L.G_NZ, k]
        )
        rate = c[L.C_ENTRAINMENT, k] / ab + kt * spin * ab / (SPIN_CREEP_FACTOR * mu * q)
        assert c[L.C_XI_DECAY, k] == pytest.approx(1.0 / (1.0 + rate * m.dt_s), rel=1e-12)
        spins.append(spin)
        checked += 1
    assert checked == 26
    assert max(spins) > 100.0  # rad/s: a 40 deg ball spins against its rings
    assert 0.0 < max(published) < 0.1 * gamma  # the published (effective) mu is another quantity
