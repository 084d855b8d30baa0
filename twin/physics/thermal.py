"""Electro-thermal laws of seed 003 (EV motor bearing under current discharge) and the inlet
shear-heating reduction of rolling contacts (Murch and Wilson 1975, Gupta et al. 1992).

Plain Python scalars (evaluated between frames, not in the hot loop), SI units, temperatures in K
unless the name says degC.
"""

from __future__ import annotations

import math

ROELANDS_T_K = 138.0  # the 138 K of Roelands' temperature term (seed 003 eq. 3)
ROELANDS_LN_ETA_INF = 9.67  # ln(eta_inf) = -9.67 with eta in Pa s (seed 003 eq. 3)
ROELANDS_PRESSURE_PA_INV = 5.1e-9  # the 1 / (1.96e8 Pa) of Roelands' pressure term (seed 003 eq. 3) [1/Pa]
MIN_CONTACT_ANGLE_RAD = math.radians(15.0)
MAX_CURRENT_HEATING_K = 250.0  # beyond this the oil has broken down; the twin caps the rise


def roelands_temperature_viscosity_pa_s(eta0_pa_s: float, theta0_k: float, theta_k: float, beta_k_inv: float) -> float:
    """Seed 003 eq. 3 at ambient pressure: eta = eta0 exp{(9.67 + ln eta0) [-1 +
    ((theta - 138) / (theta0 - 138))^(-S0)]}, S0 = beta (theta0 - 138) / (ln eta0 + 9.67), where
    beta = -d ln(eta) / d theta at theta0 is the temperature-viscosity coefficient."""
    lnk = math.log(eta0_pa_s) + ROELANDS_LN_ETA_INF
    s0 = beta_k_inv * (theta0_k - ROELANDS_T_K) / lnk
    ratio = (theta_k - ROELANDS_T_K) / (theta0_k - ROELANDS_T_K)
    return eta0_pa_s * math.exp(lnk * (-1.0 + ratio ** (-s0)))


def current_heating_temperature_rise_k(
    current_a: float,
    bearing_resistance_ohm: float,
    pitch_diameter_m: float,
    ball_diameter_m: float,
    loaded_balls: float,
    shaft_frequency_hz: float,
    crater_depth_m: float,
    ball_density_kg_m3: float,
    ball_specific_heat_j_kg_k: float,
    contact_angle_rad: float,
) -> float:
    """Instantaneous temperature rise of the race track from current discharge per shaft turn,
    seed 003 eq. 10 (eq. 9 times f_b / (2 f_s)):
    T = 1.45 I^2 R_b K (D + 2d) / (f_s H_c rho_b c_b alpha'' d^2 (D + d)) [K],
    D pitch diameter, d ball diameter, K balls in the loaded zone, alpha'' the contact angle
    [rad]. The law is written for seed 003's angular-contact EV bearing (alpha'' = 15 deg) and
    diverges for a deep-groove bearing's alpha'' = 0, so the angle is floored at 15 deg; the
    shaft frequency is floored at 1 Hz."""
    if current_a <= 0.0 or bearing_resistance_ohm <= 0.0:
        return 0.0
    f_s = max(shaft_frequency_hz, 1.0)
    alpha = max(contact_angle_rad, MIN_CONTACT_ANGLE_RAD)
    d, big_d = ball_diameter_m, pitch_diameter_m
    return (
        1.45
        * current_a**2
        * bearing_resistance_ohm
        * max(loaded_balls, 1)
        * (big_d + 2 * d)
        / (f_s * crater_depth_m * ball_density_kg_m3 * ball_specific_heat_j_kg_k * alpha * d * d * (big_d + d))
    )


def shear_heating_temperature_rise_k(
    entrainment_speed_m_s: float,
    inlet_temperature_k: float,
    thermal_expansion_k_inv: float,
    film_m: float,
    pressure_pa: float,
    half_width_m: float,
    viscosity_pa_s: float,
    conductivity_w_m_k: float,
) -> float:
    """Temperature rise of the film in the Hertz zone from compression and shear, seed 003 eq. 6:
    dT = [u theta_i alpha' h p + 2 b eta u^2 / h] / [b k' / h - u alpha' h p] [K].
    Returns inf where the conduction term no longer exceeds the compression term (the formula has
    no steady solution there)."""
    u, h = entrainment_speed_m_s, film_m
    if u <= 0.0 or h <= 0.0:
        return 0.0
    num = (
        u * inlet_temperature_k * thermal_expansion_k_inv * h * pressure_pa
        + 2.0 * half_width_m * viscosity_pa_s * u * u / h
    )
    den = half_width_m * conductivity_w_m_k / h - u * thermal_expansion_k_inv * h * pressure_pa
    return num / den if den > 0.0 else math.inf


def hamrock_dowson_temperature_film_ratio(
    temperature_rise_k: float, eta0_pa_s: float, theta0_k: float, beta_k_inv: float
) -> float:
    """g = (eta(T)/eta0)^0.68 (alpha*(T)/alpha)^0.49: the Hamrock-Dowson film ratio for a uniform
    temperature rise of the inlet, with Roelands (seed 003 eq. 3) at ambient pressure:
    ln(eta/eta0) = (ln eta0 + 9.67)(f - 1) and alpha*(T) = alpha f, f = ((T - 138)/(T0 - 138))^-S0."""
    if temperature_rise_k <= 0.0:
        return 1.0
    lnk = math.log(eta0_pa_s) + ROELANDS_LN_ETA_INF
    s0 = beta_k_inv * (theta0_k - ROELANDS_T_K) / lnk
    f = ((theta0_k + temperature_rise_k - ROELANDS_T_K) / (theta0_k - ROELANDS_T_K)) ** (-s0)
    return math.exp(0.68 * lnk * (f - 1.0)) * f**0.49


def roelands_temperature_viscosity_coefficient_k_inv(
    eta0_pa_s: float, theta0_k: float, theta_k: float, beta_k_inv: float
) -> float:
    """beta(theta) = -d ln(eta) / d theta of Roelands' law at ambient pressure (seed 003 eq. 3,
    roelands_temperature_viscosity_pa_s) [1/K]: lnk S0 ((theta - 138)/(theta0 - 138))^(-S0 - 1) /
    (theta0 - 138), equal to beta_k_inv at theta0."""
    lnk = math.log(eta0_pa_s) + ROELANDS_LN_ETA_INF
    s0 = beta_k_inv * (theta0_k - ROELANDS_T_K) / lnk
    ratio = (theta_k - ROELANDS_T_K) / (theta0_k - ROELANDS_T_K)
    return lnk * s0 * ratio ** (-s0 - 1.0) / (theta0_k - ROELANDS_T_K)


def thermal_loading_parameter(
    beta_k_inv: float, viscosity_pa_s: float, entrainment_speed_m_s: float, conductivity_w_m_k: float
) -> float:
    """L = beta eta0 u^2 / k_f [-], the thermal loading of the inlet of a rolling contact: the
    shear heat of the back-flow in the inlet (~ eta u^2) against conduction (k_f), weighted by
    the viscosity's temperature sensitivity beta = -d ln(eta)/dT (Murch and Wilson 1975; Gupta
    et al. 1992). u is the rolling (entrainment) speed."""
    u = max(entrainment_speed_m_s, 0.0)
    return beta_k_inv * viscosity_pa_s * u * u / conductivity_w_m_k


def murch_wilson_thermal_factor(thermal_loading: float) -> float:
    """phi_T = 3.94 / (3.94 + L^0.62) [-]: ratio of the film thickness of a rolling contact with
    inlet shear heating to the isothermal one (Murch and Wilson 1975, 'A thermal
    elastohydrodynamic inlet zone analysis', J. Lubr. Technol. 97(2), 212-216; as quoted by
    Hamrock, Schmid and Jacobson, Fundamentals of Machine Elements, and in the review of Marian
    et al., Lubricants 8 (2020) 95). The loop's inlet-heating law."""
    if not (thermal_loading > 0.0):
        return 1.0
    return 3.94 / (3.94 + thermal_loading**0.62)


def gupta_thermal_factor(
    thermal_loading: float, max_pressure_over_e_prime: float, slide_roll_ratio: float = 0.0
) -> float:
    """phi_T = [1 - 13.2 (p_h/E') L^0.42] / [1 + 0.213 (1 + 2.23 SRR^0.83) L^0.64] [-]: the inlet
    thermal reduction factor of Gupta, Cheng, Zhu, Forster and Schrand 1992 ('Viscoelastic
    effects in MIL-L-7808-type lubricant, Part I', Tribol. Trans. 35, 269-274; as quoted by
    Harris and Kotzalas, Advanced Concepts of Bearing Technology, 2007), with the slide-to-roll
    ratio SRR. The cross-check of murch_wilson_thermal_factor; floored at 0."""
    if not (thermal_loading > 0.0):
        return 1.0
    srr = abs(slide_roll_ratio)
    num = 1.0 - 13.2 * max_pressure_over_e_prime * thermal_loading**0.42
    den = 1.0 + 0.213 * (1.0 + 2.23 * srr**0.83) * thermal_loading**0.64
    return max(num, 0.0) / den


def equivalent_inlet_temperature_rise_k(
    film_factor: float, eta0_pa_s: float, theta0_k: float, beta_k_inv: float, max_rise_k: float = 500.0
) -> float:
    """The uniform inlet temperature rise dT whose Hamrock-Dowson film ratio g(dT)
    (hamrock_dowson_temperature_film_ratio) equals `film_factor` [K]: the temperature the
    isothermal film formula would need at the inlet to give the same film; `max_rise_k` where
    even that rise leaves a larger ratio, 0 for a factor >= 1.

    With f = ((T0 + dT - 138)/(T0 - 138))^-S0 the ratio is g = exp(0.68 lnk (f - 1)) f^0.49, so
    u = ln f solves psi(u) = 0.68 lnk (e^u - 1) + 0.49 u - ln g = 0, and dT = (T0 - 138)(e^(-u/S0) - 1).
    psi is increasing and convex, so Newton's method from u = 0 (where psi >= 0) falls monotonically
    onto the root, to machine precision in a few steps. An oil so thin that lnk <= 0 (eta0 under
    6.3e-5 Pa s) has no such root: it gets `max_rise_k`."""
    if film_factor >= 1.0:
        return 0.0
    lnk = math.log(eta0_pa_s) + ROELANDS_LN_ETA_INF
    if not (film_factor > 0.0 and lnk > 0.0):
        return max_rise_k
    s0 = beta_k_inv * (theta0_k - ROELANDS_T_K) / lnk
    a = 0.68 * lnk
    target = math.log(film_factor)
    u = 0.0
    for _ in range(60):
        eu = math.exp(u)
        step = (a * (eu - 1.0) + 0.49 * u - target) / (a * eu + 0.49)
        u -= step
        if abs(step) <= 1e-15 * (1.0 + abs(u)):
            break
    exponent = -u / s0
    if exponent >= math.log1p(max_rise_k / (theta0_k - ROELANDS_T_K)):
        return max_rise_k
    return (theta0_k - ROELANDS_T_K) * math.expm1(exponent)


def thermal_film_factor(
    temperature_rise_k: float, eta0_pa_s: float, theta0_k: float, beta_k_inv: float, temperature_exponent: float
) -> float:
    """Film-reduction factor of the current heating, h(heated inlet) / h(isothermal) = g(dT)^c:
    the Hamrock-Dowson film ratio of a uniform inlet temperature rise
    (hamrock_dowson_temperature_film_ratio) raised to the exponent c that the full thermal EHL
    solver of seed 003 gives for its current heating (twin.validation.thermal_law_fit: the solver's
    films fall faster with temperature than the isothermal formula's, c > 1)."""
    return (
        hamrock_dowson_temperature_film_ratio(temperature_rise_k, eta0_pa_s, theta0_k, beta_k_inv)
        ** temperature_exponent
    )
