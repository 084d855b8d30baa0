"""Electro-thermal laws of seed 003 and their feedback into the film."""

import math

import numpy as np
import pytest

from twin import catalog
from twin.engine import Twin
from twin.physics import thermal, viscosity
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, ModelOptions, Thermal
from twin.validation import studies


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
    slope = (
        math.log(thermal.roelands_temperature_viscosity_pa_s(eta0, t0, t0 + h, beta))
        - math.log(thermal.roelands_temperature_viscosity_pa_s(eta0, t0, t0 - h, beta))
    ) / (2 * h)
    assert slope == pytest.approx(-beta, rel=1e-5)


def test_current_heating_eq10_by_hand():
    # seed 003 eq. 10: 1.45 I^2 R K (D + 2d) / (f_s Hc rho c alpha d^2 (D + d))
    i, r, k, big_d, d, fs, hc, rho, c, alpha = (
        10.0,
        1.0,
        3,
        28.9e-3,
        4.78e-3,
        500.0,
        3e-3,
        7700.0,
        460.0,
        math.radians(15),
    )
    hand = 1.45 * i * i * r * k * (big_d + 2 * d) / (fs * hc * rho * c * alpha * d * d * (big_d + d))
    assert thermal.current_heating_temperature_rise_k(i, r, big_d, d, k, fs, hc, rho, c, alpha) == pytest.approx(
        hand, rel=1e-12
    )
    assert 1.0 < hand < 100.0  # tens of kelvin at 10 A, as seed 003 Fig. 3
    # rises with I^2 and R, falls with shaft frequency
    assert thermal.current_heating_temperature_rise_k(2 * i, r, big_d, d, k, fs, hc, rho, c, alpha) == pytest.approx(
        4 * hand
    )
    assert thermal.current_heating_temperature_rise_k(i, 2 * r, big_d, d, k, fs, hc, rho, c, alpha) == pytest.approx(
        2 * hand
    )
    assert thermal.current_heating_temperature_rise_k(0.0, r, big_d, d, k, fs, hc, rho, c, alpha) == 0.0


def test_shear_heating_eq6_by_hand():
    u, ti, ap, h, p, b, eta, k = 2.0, 353.0, 6.4e-4, 0.3e-6, 1.0e9, 0.1e-3, 0.01, 0.145
    hand = (u * ti * ap * h * p + 2 * b * eta * u * u / h) / (b * k / h - u * ap * h * p)
    assert thermal.shear_heating_temperature_rise_k(u, ti, ap, h, p, b, eta, k) == pytest.approx(hand, rel=1e-12)
    assert math.isinf(thermal.shear_heating_temperature_rise_k(50.0, ti, ap, 5e-6, 3e9, b, eta, k))


def _ev_twin(current_a, temperature_c=40.0, resistance_ohm=None, rpm=20000.0, shear_heating=True, time_step="auto"):
    """The 6200 EV twin of seed 003 (shear and current heating on), settled for 20 ms."""
    sample, snap = studies.ev_operating_point(
        current_a,
        rpm,
        oil_temperature_c=temperature_c,
        equivalent_resistance_ohm=resistance_ohm,
        shear_heating=shear_heating,
        options=ModelOptions(time_step_s=time_step),
    )
    return sample.h_min_inner_m, snap


def test_film_falls_with_current_base_temperature_and_resistance(time_step):
    # seed 003 Figs. 4, 8 and 10 trends, through the film of the real-time loop
    h = [_ev_twin(i, time_step=time_step)[0] for i in (0.0, 10.0, 20.0)]
    assert h[0] > h[1] > h[2]
    dt = time_step
    assert _ev_twin(10.0, temperature_c=80.0, time_step=dt)[0] < _ev_twin(10.0, temperature_c=40.0, time_step=dt)[0]
    assert (
        _ev_twin(10.0, resistance_ohm=5.6e-4, time_step=dt)[0] < _ev_twin(10.0, resistance_ohm=2.92e-4, time_step=dt)[0]
    )
    _, snap = _ev_twin(10.0, time_step=time_step)
    e = snap.electrical
    assert e.current_temperature_rise_k > 0 and e.shear_temperature_rise_k > 0
    assert e.contact_temperature_rise_k == pytest.approx(e.current_temperature_rise_k + e.shear_temperature_rise_k)
    assert 0.0 < e.film_thermal_factor < 1.0
    assert snap.viscosity_pa_s < viscosity.dynamic_viscosity_pa_s(catalog.lubricant(), 40.0)


def test_loop_film_is_the_isothermal_film_times_the_thermal_factor():
    # the loop runs the laws of twin.physics.thermal: same contact, same kinematics, heating off/on;
    # factor = g(dT_current)^c_T x Murch-Wilson(L at the current-heated inlet)
    h_iso, snap_iso = _ev_twin(0.0, shear_heating=False)
    h_hot, snap_hot = _ev_twin(10.0)
    e = snap_hot.electrical
    theta0 = 40.0 + 273.15
    eta0 = viscosity.dynamic_viscosity_pa_s(catalog.lubricant(), 40.0)
    beta = viscosity.temperature_viscosity_coefficient_k_inv(catalog.lubricant(), 40.0)
    current = thermal.thermal_film_factor(
        e.current_temperature_rise_k, eta0, theta0, beta, Thermal().film_temperature_exponent
    )
    theta_c = theta0 + e.current_temperature_rise_k
    u = np.mean([b.inner.entrainment_speed_m_s for b in snap_hot.balls if b.inner.load_n > 0.0])
    loading = thermal.thermal_loading_parameter(
        thermal.roelands_temperature_viscosity_coefficient_k_inv(eta0, theta0, theta_c, beta),
        thermal.roelands_temperature_viscosity_pa_s(eta0, theta0, theta_c, beta),
        u,
        Thermal().oil_thermal_conductivity_w_m_k,
    )
    # the loop's speed is the one of its last coupling (<= 10 ms before the snapshot): 1 %
    assert e.film_thermal_factor == pytest.approx(current * thermal.murch_wilson_thermal_factor(loading), rel=0.01)
    assert snap_iso.electrical.film_thermal_factor == 1.0
    # same warm start and speed: the film differs by the factor (load and entrainment agree to
    # better than 1 %, so the film ratio matches the factor within 2 %)
    assert h_hot / h_iso == pytest.approx(e.film_thermal_factor, rel=0.02)


def test_higher_currents_need_higher_speeds_to_form_a_film_fig7():
    # seed 003 Fig. 7: "higher currents require higher shaft speeds to achieve film formation".
    # Real-time loop, 6200 EV twin, 200 N, 40 degC, current + inlet shear heating: the speed at
    # which the film with current first reaches half the film without current rises with the
    # current (measured: 20 000 rpm at 10 A, 30 000 rpm at 20 A, above 50 000 rpm at 30 A).
    # Not reproduced, with the reason: seed 003's interior maximum of the film without current
    # (Fig. 7) came from its eq. 6 applied at the inlet; with the Murch-Wilson inlet law the
    # 6200's film keeps growing up to its speed limit (L = 12, where phi_T = 3.94 / (3.94 + L^0.62)
    # turns the film down, is reached at about 31 m/s, above 60 000 rpm), only flattening:
    # 30 000 -> 50 000 rpm adds 11 % instead of the isothermal 42 %.
    rpms = (5000.0, 10000.0, 20000.0, 30000.0, 50000.0)
    films = {current: [_ev_twin(current, rpm=rpm)[0] for rpm in rpms] for current in (0.0, 10.0, 20.0)}
    ratio_speed = (rpms[-1] / rpms[-2]) ** 0.68
    assert films[0.0] == sorted(films[0.0])
    assert films[0.0][-1] / films[0.0][-2] < 0.85 * ratio_speed
    first = {}
    for current in (10.0, 20.0):
        ratios = [h / h0 for h, h0 in zip(films[current], films[0.0])]
        assert all(r < 1.0 for r in ratios)
        assert ratios == sorted(ratios)  # the current heating fades with speed (eq. 10: 1 / f_s)
        first[current] = next(rpm for rpm, r in zip(rpms, ratios) if r >= 0.5)
    assert first[10.0] < first[20.0], first


def test_shear_heating_is_on_by_default_and_off_in_the_isothermal_seed000_studies():
    # the default twin (6208, 3000 N, 500 rad/s, seed oil at 40 degC) heats its inlet: its film factor is
    # Murch and Wilson's phi_T = 3.94 / (3.94 + L^0.62), L = beta eta u^2 / k' at the mean entrainment
    # speed, within 5 % (as in test_6208_film_factor_follows_murch_wilson: measured 0.833 against the law);
    # seed 000 (section 2.3, eq. 6: isothermal Hamrock-Dowson) is reproduced with the inlet unheated
    twin = Twin("6208")
    twin.advance(0.005)
    e = twin.snapshot().electrical
    lub = twin.model.spec.lubricant
    law = thermal.murch_wilson_thermal_factor(
        thermal.thermal_loading_parameter(
            viscosity.temperature_viscosity_coefficient_k_inv(lub, 40.0),
            viscosity.dynamic_viscosity_pa_s(lub, 40.0),
            twin.mean_entrainment_speed_m_s(),
            Thermal().oil_thermal_conductivity_w_m_k,
        )
    )
    assert law < 0.9
    assert e.film_thermal_factor == pytest.approx(law, rel=0.05) and e.shear_temperature_rise_k > 0.0
    seed = Twin(studies.isothermal_spec("6208"))
    seed.advance(0.005)
    e = seed.snapshot().electrical
    assert e.shear_temperature_rise_k == 0.0 and e.film_thermal_factor == 1.0


def test_inlet_shear_heating_laws_by_hand_and_cross_check():
    # Murch and Wilson 1975: phi_T = 3.94 / (3.94 + L^0.62); Gupta et al. 1992:
    # [1 - 13.2 (p_h/E') L^0.42] / [1 + 0.213 (1 + 2.23 SRR^0.83) L^0.64]; L = beta eta0 u^2 / k_f
    lam = thermal.thermal_loading_parameter(0.047, 0.04, 7.25, 0.145)
    assert lam == pytest.approx(0.047 * 0.04 * 7.25**2 / 0.145, rel=1e-12)
    assert thermal.murch_wilson_thermal_factor(lam) == pytest.approx(3.94 / (3.94 + lam**0.62), rel=1e-12)
    assert thermal.gupta_thermal_factor(lam, 0.01, 0.2) == pytest.approx(
        (1 - 13.2 * 0.01 * lam**0.42) / (1 + 0.213 * (1 + 2.23 * 0.2**0.83) * lam**0.64), rel=1e-12
    )
    assert thermal.murch_wilson_thermal_factor(0.0) == 1.0 and thermal.gupta_thermal_factor(0.0, 0.01) == 1.0
    # the two published laws agree within 0.12 for the 6208's rolling speeds (1.45-24.6 m/s,
    # p_h = 2 GPa, pure rolling); Gupta's is the lower (measured 0.02 at 1.45 m/s, 0.12 at 24.6 m/s)
    for u in (1.45, 7.24, 14.5, 24.6):
        lam = thermal.thermal_loading_parameter(0.047, 0.04, u, 0.145)
        mw = thermal.murch_wilson_thermal_factor(lam)
        gu = thermal.gupta_thermal_factor(lam, 2.0e9 / 2.307e11)
        assert 0.0 <= mw - gu <= 0.12, (u, mw, gu)
    # the equivalent inlet temperature rise reproduces the factor through the Hamrock-Dowson ratio
    rise = thermal.equivalent_inlet_temperature_rise_k(0.8, 0.04, 313.15, 0.047)
    assert thermal.hamrock_dowson_temperature_film_ratio(rise, 0.04, 313.15, 0.047) == pytest.approx(0.8, rel=1e-5)
    # Roelands' temperature-viscosity coefficient is beta at theta0 and falls as the oil heats
    assert thermal.roelands_temperature_viscosity_coefficient_k_inv(0.04, 313.15, 313.15, 0.047) == pytest.approx(0.047)
    assert thermal.roelands_temperature_viscosity_coefficient_k_inv(0.04, 313.15, 353.15, 0.047) < 0.047


@pytest.mark.parametrize("film_factor", [0.999, 0.9, 0.8, 0.5, 0.1, 1e-3])
@pytest.mark.parametrize("eta0, theta0, beta", [(0.04, 313.15, 0.047), (0.0035, 373.15, 0.03), (0.4, 263.15, 0.07)])
def test_equivalent_inlet_rise_inverts_the_hamrock_dowson_ratio(film_factor, eta0, theta0, beta):
    # the closed Newton solve against an independent bisection of g(dT) = film_factor, with g the
    # Hamrock-Dowson film ratio under Roelands' law at ambient pressure (seed 003 eq. 3): within
    # 1e-9 K, and g of the result equals the factor to 1e-12 (relative)
    def g(rise: float) -> float:
        return thermal.hamrock_dowson_temperature_film_ratio(rise, eta0, theta0, beta)

    lo, hi = 0.0, 500.0
    while hi - lo > 1e-11:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) > film_factor else (lo, mid)
    rise = thermal.equivalent_inlet_temperature_rise_k(film_factor, eta0, theta0, beta)
    if g(500.0) > film_factor:  # not reached within the 500 K cap: the cap
        assert rise == 500.0
    else:
        assert rise == pytest.approx(0.5 * (lo + hi), abs=1e-9)
        assert g(rise) == pytest.approx(film_factor, rel=1e-12)


def test_equivalent_inlet_rise_limits():
    # no reduction: no rise; a reduction no rise up to the cap reaches: the cap
    assert thermal.equivalent_inlet_temperature_rise_k(1.0, 0.04, 313.15, 0.047) == 0.0
    assert thermal.equivalent_inlet_temperature_rise_k(1e-9, 0.04, 313.15, 0.047, max_rise_k=50.0) == 50.0
    assert thermal.equivalent_inlet_temperature_rise_k(0.0, 0.04, 313.15, 0.047) == 500.0


@pytest.mark.parametrize(
    "speed, band", [(100.0, (0.95, 1.0)), (500.0, (0.8, 0.95)), (1000.0, (0.6, 0.85)), (1700.0, (0.5, 0.8))]
)
def test_6208_film_factor_follows_murch_wilson(speed, band):
    # with inlet heating on, the loop's film factor is within the cited law's value (Murch and
    # Wilson 1975) +-5 % across 100-1700 rad/s (6208, 3000 N, seed oil at 40 degC), and in the range
    # established inlet laws give (0.8-0.95 at 500 rad/s, 0.5-0.8 at 1700 rad/s; seed 003's eq. 6, a
    # Hertz-zone temperature, applied at the inlet gives 0.41 / 0.10). Measured 0.974 / 0.833 /
    # 0.679 / 0.523. The film itself: heated / isothermal.
    base = studies.isothermal_spec("6208")  # the unheated film of seed 000's Hamrock-Dowson law
    hot = BearingSpec.model_validate({**base.model_dump(), "thermal": Thermal(shear_heating=True).model_dump()})
    films = []
    for spec in (base, hot):
        twin = Twin(spec, setpoint=Setpoint(shaft_speed_rad_s=speed, radial_load_n=3000.0))
        twin.advance(0.012)
        snap = twin.snapshot()
        ball = min(snap.balls, key=lambda b: abs(b.azimuth_rad))
        films.append(ball.inner.h_min_m)
    lub = base.lubricant
    law = thermal.murch_wilson_thermal_factor(
        thermal.thermal_loading_parameter(
            viscosity.temperature_viscosity_coefficient_k_inv(lub, 40.0),
            viscosity.dynamic_viscosity_pa_s(lub, 40.0),
            twin.mean_entrainment_speed_m_s(),
            Thermal().oil_thermal_conductivity_w_m_k,
        )
    )
    factor = snap.electrical.film_thermal_factor
    assert factor == pytest.approx(law, rel=0.05)
    assert films[1] / films[0] == pytest.approx(law, rel=0.05)
    assert band[0] <= factor <= band[1]
