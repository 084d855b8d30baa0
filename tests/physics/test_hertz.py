"""Seed 000 eq. 2 (elliptic Hertz stiffness, README reading) and eq. 3 (ball-cage)."""

import math

import pytest

from twin.catalog import bearing
from twin.kernels import layout as L
from twin.model import make_model
from twin.physics import hertz


def test_inner_contact_stiffness_of_the_6208_by_hand():
    # seed 000 Table 1: Rb 6.3, Ri 24.0, groove 6.552 mm; eq. 2 with E' = E / (1 - nu^2)
    rx = 6.3 * 24.0 / (24.0 + 6.3) * 1e-3
    ry = 6.3 * 6.552 / (6.552 - 6.3) * 1e-3
    alpha = ry / rx
    k = alpha ** (2 / math.pi)
    f = 1 + (math.pi / 2 - 1) * math.log(alpha)
    e = 1 + (math.pi / 2 - 1) / alpha
    r = rx * ry / (rx + ry)
    e_prime = 210e9 / (1 - 0.3 ** 2)
    hand = math.pi * k * e_prime * math.sqrt(2 * e * r / (9 * f ** 3))
    assert hand == pytest.approx(4.277e10, rel=1e-3)  # hand value, 4 significant digits
    model = make_model(bearing("6208"))
    assert model.race_params[0, L.R_STIFFNESS] == pytest.approx(hand, rel=1e-12)
    assert model.race_params[0, L.R_RX] == pytest.approx(4.99010e-3, rel=1e-5)
    assert model.race_params[1, L.R_RX] == pytest.approx(6.3 * 36.6 / (36.6 - 6.3) * 1e-3, rel=1e-12)


def test_design_constant_is_the_seed_constant_over_one_minus_nu():
    # README: pi k E' == 2 pi k G / (1 - nu) (seed 004 eq. 2); the seed 000 print lacks 1/(1-nu)
    e, nu = 210e9, 0.3
    g = hertz.shear_modulus_pa(e, nu)
    assert math.pi * hertz.effective_modulus_pa(e, nu) == pytest.approx(2 * math.pi * g / (1 - nu), rel=1e-12)


def test_ball_cage_stiffness_eq3_by_hand():
    # seed 000 eq. 3: K = 4 G sqrt(Req) / (3 (1 - nu)), Req = 6.3 * 4.19 / 10.49 mm
    g = 210e9 / 2.6
    req = 6.3 * 4.19 / (6.3 + 4.19) * 1e-3
    hand = 4 * g * math.sqrt(req) / (3 * 0.7)
    assert hand == pytest.approx(7.724e9, rel=1e-3)
    assert hertz.ball_ball_stiffness_n_m15(6.3e-3, 4.19e-3, g, 0.3) == pytest.approx(hand, rel=1e-12)


def test_contact_ellipse_and_pressure_at_the_stribeck_load():
    # Hamrock-Brewe semi-axes: at Q = 1457 N (seed 000 eq. A3) the inner contact of a 6208 is a
    # long ellipse, a/b = k = 9.23, a = 1.717 mm, b = 0.186 mm, p_max = 2.18 GPa
    rx = 6.3 * 24.0 / 30.3 * 1e-3
    ry = 6.3 * 6.552 / 0.252 * 1e-3
    ep = 210e9 / 0.91
    a = hertz.semi_major_axis_m(1457.0, rx, ry, ep)
    b = hertz.semi_minor_axis_m(1457.0, rx, ry, ep)
    assert a / b == pytest.approx(hertz.ellipticity(rx, ry), rel=1e-9)
    k = (ry / rx) ** (2 / math.pi)
    e = 1 + (math.pi / 2 - 1) * rx / ry
    r = rx * ry / (rx + ry)
    assert a == pytest.approx((6 * k * k * e * 1457.0 * r / (math.pi * ep)) ** (1 / 3), rel=1e-12)
    assert a == pytest.approx(1.717e-3, rel=1e-3)
    assert b == pytest.approx(0.186e-3, rel=2e-3)
    p = hertz.max_pressure_pa(1457.0, a, b)
    assert p == pytest.approx(2.18e9, rel=2e-3)
    assert 1.5 * 1457.0 / (math.pi * a * b) == pytest.approx(p, rel=1e-12)
