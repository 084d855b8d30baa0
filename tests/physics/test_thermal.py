"""Electro-thermal laws of seed 003 and their feedback into the film."""

import math

import pytest

from twin import catalog
from twin.engine import Twin
from twin.physics import thermal, viscosity
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, Thermal


def test_roelands_temperature_law_by_hand():
    # seed 003 eq. 3 at p = 0: eta = eta0 exp{(9.67 + ln eta0)[-1 + ((T - 138)/(T0 - 138))^-S0]}
    eta0, t0, t, beta = 0.04, 313.15, 333.15, 0.03
    lnk = math.log(eta0) + 9.67
    s0 = beta * (t0 - 138) / lnk
    hand = eta0 * math.exp(lnk * (-1 + ((t - 138) / (t0 - 138)) ** -s0))
    assert thermal.roelands_temperature_viscosity_pa_s(eta0, t0, t, beta) == pytest.approx(hand, rel=1e-12)
    assert thermal.roelands_temperature_viscosity_pa_s(eta0, t0, t0, beta) == pytest.approx(eta0, rel=1e-12)
    # its slope at T0 is -beta by construction of S0
    h = 1e-3
    slope = (math.log(thermal.roelands_temperature_viscosity_pa_s(eta0, t0, t0 + h, beta))
             - math.log(thermal.roelands_temperature_viscosity_pa_s(eta0, t0, t0 - h, beta))) / (2 * h)
    assert slope == pytest.approx(-beta, rel=1e-5)


def test_current_heating_eq10_by_hand():
    # seed 003 eq. 10: 1.45 I^2 R K (D + 2d) / (f_s Hc rho c alpha d^2 (D + d))
    i, r, k, big_d, d, fs, hc, rho, c, alpha = 10.0, 1.0, 3, 28.9e-3, 4.78e-3, 500.0, 3e-3, 7700.0, 460.0, math.radians(15)
    hand = 1.45 * i * i * r * k * (big_d + 2 * d) / (fs * hc * rho * c * alpha * d * d * (big_d + d))
    assert thermal.current_heating_temperature_rise_k(i, r, big_d, d, k, fs, hc, rho, c, alpha) == pytest.approx(hand, rel=1e-12)
    assert 1.0 < hand < 100.0  # tens of kelvin at 10 A, as seed 003 Fig. 3
    # rises with I^2 and R, falls with shaft frequency
    assert thermal.current_heating_temperature_rise_k(2 * i, r, big_d, d, k, fs, hc, rho, c, alpha) == pytest.approx(4 * hand)
    assert thermal.current_heating_temperature_rise_k(i, 2 * r, big_d, d, k, fs, hc, rho, c, alpha) == pytest.approx(2 * hand)
    assert thermal.current_heating_temperature_rise_k(0.0, r, big_d, d, k, fs, hc, rho, c, alpha) == 0.0


def test_shear_heating_eq6_by_hand():
    u, ti, ap, h, p, b, eta, k = 2.0, 353.0, 6.4e-4, 0.3e-6, 1.0e9, 0.1e-3, 0.01, 0.145
    hand = (u * ti * ap * h * p + 2 * b * eta * u * u / h) / (b * k / h - u * ap * h * p)
    assert thermal.shear_heating_temperature_rise_k(u, ti, ap, h, p, b, eta, k) == pytest.approx(hand, rel=1e-12)
    assert math.isinf(thermal.shear_heating_temperature_rise_k(50.0, ti, ap, 5e-6, 3e9, b, eta, k))


def _ev_twin(current_a, temperature_c=40.0, resistance_ohm=1.0, rpm=20000.0):
    base = catalog.bearing("6200")
    spec = BearingSpec.model_validate({**base.model_dump(),
                                       "thermal": Thermal(equivalent_resistance_ohm=resistance_ohm).model_dump()})
    twin = Twin(spec, setpoint=Setpoint(shaft_speed_rad_s=rpm * math.pi / 30, radial_load_n=200.0,
                                        shaft_current_a=current_a, oil_temperature_c=temperature_c))
    twin.advance(0.025)
    snap = twin.snapshot()
    ball = min(snap.balls, key=lambda b: abs(b.azimuth_rad))
    return ball.inner.h_min_m, snap


def test_film_falls_with_current_base_temperature_and_resistance():
    # seed 003 Figs. 4, 8 and 10 trends, through the inlet viscosity of the real-time loop
    h = [_ev_twin(i)[0] for i in (0.0, 10.0, 20.0)]
    assert h[0] > h[1] > h[2]
    assert _ev_twin(10.0, temperature_c=80.0)[0] < _ev_twin(10.0, temperature_c=40.0)[0]
    assert _ev_twin(10.0, resistance_ohm=2.0)[0] < _ev_twin(10.0, resistance_ohm=1.0)[0]
    _, snap = _ev_twin(10.0)
    assert snap.electrical.contact_temperature_rise_k > 0
    assert snap.viscosity_pa_s < viscosity.dynamic_viscosity_pa_s(catalog.lubricant(), 40.0)
